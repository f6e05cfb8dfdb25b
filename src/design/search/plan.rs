//! Where the local searches start (docs/ALGORITHMS.md §8.1, §8.3, §8.6).
//!
//! 1. The first starts: as HIFOO 3.5, `nrand` standard-normal points, or an initial controller
//!    and `nrand` perturbations of it ([`crate::design::starts`]); then the open-loop start K = 0
//!    (`open_loop_start`) and the central-controller starts (`central_gammas`). They are always
//!    made (unless a budget ends the run first). The given controllers' local searches (a warm
//!    start, a chained start, [`super::given`]) come first, lowest objective first, except that a
//!    chained start that is not to be first (`chained_first` false) comes after all the others.
//! 2. If none of them was stabilised and gradient sampling is on: gradient sampling on f_s from
//!    the point with the smallest f_s (HIFOO's fallback, [`super::local`]).
//! 3. The continued search (`stall_starts > 0`): further local searches, cycling through one
//!    basin-hopping perturbation x* + ξ ∘ (‖x*‖·r) of the best point x* for each r in
//!    `hop_scales`, then one fresh random start σ·ξ, ξ ~ N(0, I), with σ cycling through
//!    `random_scales` (small σ: small gains, see `starts::open_loop_controller`). x* is the best
//!    point of f_h, or of f_s while no stable point has been found. If the f_h local search that
//!    produced the current best point ended on `maxit` (or a budget) rather than at a minimiser,
//!    the next start is that point itself (`continue_at_maxit`, recorded as a hop of size 0):
//!    its local search goes on with a fresh inverse-Hessian approximation. This uses no random
//!    numbers and leaves the cycle's draws unchanged. The f_h local searches of the continued
//!    search have their own iteration limit `continued_maxit`
//!    ([`crate::design::DEFAULT_CONTINUED_MAXIT`]; 0: `maxit`), so that HIFOO's first starts and
//!    every stabilisation keep HIFOO's `maxit`.
//!
//! # Coordinates
//! Each local search runs either on the controller's parameters x or, if the plant's channels
//! are scaled (`design::scaling`), on plant-scaled variables x̃ (x = d ∘ x̃), by
//! `variable_scaling`: `Off`, x only; `Always`, x̃ only; `Alternate` (the default), HIFOO's first
//! starts and the open-loop start in x, each central start in x and then in x̃ (a reduced
//! full-order design is the one start that carries the plant's dynamics, and which coordinates
//! let BFGS keep them is not known beforehand), then whole hop cycles (one hop per `hop_scales`
//! entry and one random start): the 1st, 5th, 9th, … ([`ALTERNATE_PERIOD`] = 4) in the
//! coordinates the current incumbent was *not* found in, the others in those it was found in. A
//! cycle's basin hops perturb the best point in its own coordinates (x̃* + ξ ∘ (‖x̃*‖·r) for a
//! scaled cycle) and its random start σ·ξ is drawn in them. The incumbents are kept in x whatever
//! coordinates found them (x ↔ x̃ is exact: d holds powers of two), so each coordinate system hops
//! around the best point either found; resuming a cut search, gradient-sampling stabilisation and
//! the final gradient sampling use the coordinates of the local search that produced their point.
//! On a plant that is not scaled every mode is the unscaled search, bit for bit (no random number
//! is drawn differently).

use super::{Coords, Search, State};
use crate::design::options::VariableScaling;
use crate::design::outcome::StartKind;
use crate::design::starts::{perturb, scaled_random_start};

/// `variable_scaling = "alternate"`: one hop cycle in this many runs in the coordinates (x or
/// x̃) the incumbent was not found in, the others in those it was (module docs).
pub const ALTERNATE_PERIOD: usize = 4;

/// The sequence of local searches of one search, in the order of the module docs: the first
/// starts, then gradient sampling on f_s if none of them was stabilised, then the continued
/// search. It keeps what comes next and the kind and coordinates of every local search made.
pub(super) struct StartPlan {
    /// The first starts' local searches: (index into the first starts, coordinates, kind).
    first: Vec<(usize, Coords, StartKind)>,
    /// Whether the gradient-sampling fallback was made.
    fallback_done: bool,
    /// Continued starts drawn from the hop / random cycle so far.
    cycle: usize,
    /// Coordinates of the current hop cycle.
    cycle_coords: Coords,
    /// Kind of each local search made, in order.
    pub kinds: Vec<StartKind>,
    /// Coordinates of each local search made.
    pub coords: Vec<Coords>,
}

/// The next local search of a [`StartPlan`].
pub(super) enum NextStart {
    /// First start number `i`, in coordinates `c`.
    First(usize, Coords),
    /// Gradient sampling on f_s from the point with the smallest f_s (HIFOO's fallback).
    Fallback,
    /// A start of the continued search, drawn by [`Search::continued_start`].
    Continued,
}

impl StartPlan {
    /// The position in the plan of the local search from first start `i` (`i` itself if it has
    /// none).
    pub(super) fn position_of(&self, i: usize) -> usize {
        self.first.iter().position(|s| s.0 == i).unwrap_or(i)
    }

    /// The kind of local search number `k`: of the one made, else of the first start planned
    /// there (a given point is an incumbent before its local search is made, module `given`).
    pub(super) fn kind_at(&self, k: usize) -> Option<StartKind> {
        self.kinds.get(k).or_else(|| self.first.get(k).map(|s| &s.2)).copied()
    }

    /// The coordinates of local search number `k`, as [`Self::kind_at`].
    pub(super) fn coords_at(&self, k: usize) -> Option<Coords> {
        self.coords.get(k).or_else(|| self.first.get(k).map(|s| &s.1)).copied()
    }

    /// Local searches made (or begun) so far.
    pub(super) fn made(&self) -> usize {
        self.kinds.len()
    }

    /// What comes next after the local searches made; a first start or the fallback is recorded
    /// as made (a continued start is recorded when [`Search::continued_start`] draws it).
    pub(super) fn next(&mut self, st: &State<'_>) -> NextStart {
        if let Some(&(i, c, kind)) = self.first.get(self.made()) {
            self.kinds.push(kind);
            self.coords.push(c);
            return NextStart::First(i, c);
        }
        if !st.stabilised && st.opts.gradient_sampling && !self.fallback_done {
            self.fallback_done = true;
            self.kinds.push(StartKind::GradientSampling);
            self.coords.push(st.stab.as_ref().map_or(Coords::Raw, |b| b.coords));
            return NextStart::Fallback;
        }
        NextStart::Continued
    }
}

impl Search<'_, '_, '_> {
    /// The coordinates of HIFOO's first starts (`continued` None) or of the hop cycle that begins
    /// with continued start number `j` (`continued` = (j, hop cycle length, coordinates of the
    /// incumbent's local search)), module docs: `Alternate` runs one hop cycle in [`ALTERNATE_PERIOD`] (the first one
    /// included) in the coordinates the incumbent was not found in, the others in those it was.
    pub(super) fn coords_of(&self, mode: VariableScaling, continued: Option<(usize, usize, Coords)>) -> Coords {
        if self.scaled.is_none() {
            return Coords::Raw;
        }
        let other = |c| if c == Coords::Raw { Coords::Scaled } else { Coords::Raw };
        match (mode, continued) {
            (VariableScaling::Off, _) => Coords::Raw,
            (VariableScaling::Always, _) => Coords::Scaled,
            (VariableScaling::Alternate, None) => Coords::Raw,
            (VariableScaling::Alternate, Some((j, cycle, inc))) if (j / cycle).is_multiple_of(ALTERNATE_PERIOD) => {
                other(inc)
            }
            (VariableScaling::Alternate, Some((_, _, inc))) => inc,
        }
    }

    /// The plan of a search whose first starts have the kinds `kinds` (`n` of them; a start
    /// without a kind is a random one), the first `given_order.len()` of them the given
    /// controllers, made in the order `given_order` ([`super::given`]), the others in theirs;
    /// without `chained_first`, the chained starts' local searches are made after all the others
    /// (in their own order).
    /// Every first start is made in the coordinates of [`Self::coords_of`]; with `Alternate` on a
    /// scaled plant each central start is made twice, first in x, then in x̃ (module docs,
    /// "Coordinates").
    pub(super) fn start_plan(
        &self,
        mode: VariableScaling,
        kinds: &[StartKind],
        given_order: &[usize],
        n: usize,
        chained_first: bool,
    ) -> StartPlan {
        let c = self.coords_of(mode, None);
        let both = self.scaled.is_some() && mode == VariableScaling::Alternate;
        let mut first = Vec::with_capacity(2 * n);
        for i in given_order.iter().copied().chain(given_order.len()..n) {
            let kind = kinds.get(i).copied().unwrap_or(StartKind::Random);
            first.push((i, c, kind));
            if both && kind == StartKind::Central {
                first.push((i, Coords::Scaled, kind));
            }
        }
        if !chained_first {
            let (chained, own): (Vec<_>, Vec<_>) = first.into_iter().partition(|s| s.2 == StartKind::Chained);
            first = own;
            first.extend(chained);
        }
        StartPlan {
            first,
            fallback_done: false,
            cycle: 0,
            cycle_coords: Coords::Raw,
            kinds: Vec::new(),
            coords: Vec::new(),
        }
    }

    /// The start of continued local search number `j` (0-based after the first starts), in
    /// coordinates `c` (hops of the best point and random starts are drawn in them).
    /// The c-th fresh random start (c counts them) is at scale `random_scales[c mod len]`.
    pub(super) fn next_start(&mut self, st: &State<'_>, j: usize, nvar: usize, c: Coords) -> (Vec<f64>, StartKind) {
        let scales = &st.opts.hop_scales;
        let centre = st.perf.as_ref().or(st.stab.as_ref()).filter(|b| b.x.iter().all(|v| v.is_finite()));
        let cycle = scales.len() + 1;
        match (j % cycle, centre) {
            (i, Some(b)) if i < scales.len() => {
                let centre = self.to_coords(&b.x, c);
                (perturb(&centre, scales[i], self.rng), StartKind::Hop)
            }
            _ => {
                let sigmas = &st.opts.random_scales;
                let sigma = sigmas[(j / cycle) % sigmas.len()];
                (scaled_random_start(nvar, sigma, self.rng), StartKind::Random)
            }
        }
    }

    /// The next start of the continued search, recorded in `plan`, and its coordinates: the
    /// incumbent itself if its local search was cut (`continue_at_maxit`, recorded as a hop),
    /// else the next start of the hop / random cycle (a hop cycle's coordinates are chosen at its
    /// first start).
    pub(super) fn continued_start(
        &mut self,
        st: &mut State<'_>,
        plan: &mut StartPlan,
        nvar: usize,
    ) -> (Vec<f64>, Coords) {
        let opts = st.opts;
        let (x0, kind, c) = match st.take_continuation() {
            Some((x, c)) => (self.to_coords(&x, c), StartKind::Hop, c),
            None => {
                plan.cycle += 1;
                let len = opts.hop_scales.len() + 1;
                if (plan.cycle - 1).is_multiple_of(len) {
                    let inc = st.perf.as_ref().or(st.stab.as_ref()).map_or(Coords::Raw, |b| b.coords);
                    plan.cycle_coords = self.coords_of(opts.variable_scaling, Some((plan.cycle - 1, len, inc)));
                }
                let c = plan.cycle_coords;
                let (x0, kind) = self.next_start(st, plan.cycle - 1, nvar, c);
                (x0, kind, c)
            }
        };
        plan.kinds.push(kind);
        plan.coords.push(c);
        (x0, c)
    }
}
