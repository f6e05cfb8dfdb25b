//! The multi-start search of a design run: local searches until a budget or the stall rule ends
//! it, then gradient sampling from the best point.
//!
//! # One local search (docs/ALGORITHMS.md §8.3, §8.4)
//! From a start x₀: BFGS on f_s = max(α(Acl), ε·α(Ak)) with fvalquit = 0 (it stops as soon as
//! f_s < 0: Acl and Ak Hurwitz; a start that is already stable costs one evaluation); if the end
//! point is stable, BFGS on f_h = max(‖Tzw‖∞, ε·‖K‖∞) from it. Each local search has a fresh
//! inverse-Hessian approximation — restarting BFGS is itself useful on nonsmooth functions.
//!
//! # The starts
//! 1. The first starts: as HIFOO 3.5, `nrand` standard-normal points, or an initial controller
//!    and `nrand` perturbations of it ([`super::starts`]); then the open-loop start K = 0
//!    (`open_loop_start`) and the central-controller starts (`central_gammas`). They are always
//!    made (unless a budget ends the run first).
//! 2. If none of them was stabilised and gradient sampling is on: gradient sampling on f_s
//!    (fvalquit = 0) from the point with the smallest f_s (HIFOO's fallback), then BFGS on f_h
//!    from its end point if stable.
//! 3. The continued search (`stall_starts > 0`): further local searches, cycling through one
//!    basin-hopping perturbation x* + ξ ∘ (‖x*‖·r) of the best point x* for each r in
//!    `hop_scales`, then one fresh random start σ·ξ, ξ ~ N(0, I), with σ cycling through
//!    `random_scales` (small σ: small gains, see `starts::open_loop_controller`). x* is the best
//!    point of f_h, or of f_s while no stable point has been found: stabilisation is restarted,
//!    never given up, until a budget ends the run (the stall rule applies only once a stable point is known, or when no
//!    budget — cpumax, maxevals, max_starts — is finite).
//!    If the f_h local search that produced the current best point ended on `maxit` rather than at a
//!    minimiser, the next start is that point itself (`continue_at_maxit`, recorded as a hop of
//!    size 0): its local search goes on with a fresh inverse-Hessian approximation instead of
//!    being left unfinished. This uses no random numbers and leaves the cycle's draws unchanged.
//!    It matters for many variables: Enns n_K = 8 (81 variables; ε = 1e-3, seed 1, 60 CPU s) ended
//!    at 1.13167 without it and at 1.13112 and 1.13144 (two runs) with it; with `maxit = 3000`
//!    instead, 1.12986. The f_h local searches of the continued search (resumptions, hops and
//!    random starts) have their own iteration limit `continued_maxit` (default
//!    [`crate::design::DEFAULT_CONTINUED_MAXIT`]; 0: `maxit`), so that HIFOO's first starts and
//!    every stabilisation keep HIFOO's `maxit`.
//!
//! # Refining near-misses (docs/ALGORITHMS.md §8.3)
//! The incumbent is judged after gradient sampling, other local searches after BFGS alone, which
//! stalls above the floor of a basin on a ridge of max(‖Tzw‖∞, ε‖K‖∞). An f_h local search of the
//! continued search that ends uncertified (dnorm > normtol, not cut by a budget) at most a
//! relative `refine_rtol` above the incumbent gets gradient sampling from its end point (same
//! options and coordinates) before it is offered; it draws from the run's generator, so the run
//! stays reproducible. The first starts are unchanged.
//!
//! # Coordinates (docs/ALGORITHMS.md §8.6)
//! Each local search runs either on the controller's parameters x or, if the plant's channels
//! are scaled (`design::scaling`), on plant-scaled variables x̃ (x = d ∘ x̃), by
//! `variable_scaling`: `Off`, x only; `Always`, x̃ only; `Alternate` (the default), HIFOO's first
//! starts and the open-loop start in x, each central start in x and then in x̃ (a reduced
//! full-order design is the one start that carries the plant's dynamics, and which coordinates
//! let BFGS keep them is not known beforehand: on AC10 n_K = 1 it does not stabilise in x and
//! reaches γ 10.40–10.60 in x̃ within 20 CPU s), then whole hop cycles (one hop per
//! `hop_scales` entry and one random start): the 1st, 5th, 9th, … ([`ALTERNATE_PERIOD`] = 4) in
//! the coordinates the current incumbent was *not* found in, the others in those it was found
//! in. Both keep being tried, and the one that works on the plant gets three cycles in four
//! (AC10: x̃; BDT2: x). A cycle's basin hops perturb the best point in its own
//! coordinates (x̃* + ξ ∘ (‖x̃*‖·r) for a scaled cycle) and its random start σ·ξ is drawn in them.
//! The incumbents are kept in x whatever coordinates found them (x ↔ x̃ is exact: d holds
//! powers of two), so each coordinate system hops around the best point either found; resuming a
//! cut search, gradient-sampling stabilisation and the final gradient sampling use the
//! coordinates of the local search that produced their point. On a plant that is not scaled
//! every mode is the unscaled search, bit for bit (no random number is drawn differently).
//!
//! # When it stops
//! Before each new local search (and within one, between evaluations) the run stops on the CPU
//! budget `cpumax`, the evaluation budget `maxevals`, a cancel request, or when `max_starts`
//! local searches were made. The **stall rule**: after the first starts, the search stops once
//! `stall_starts` consecutive local searches have not lowered the best objective by at least
//! `stall_rtol`·|best| (f_h once a stable point exists; before that, f_s, whose improvements count
//! at least `stall_rtol` in absolute terms near 0, and only if no budget is finite).
//! `stall_starts = 0` is HIFOO's search. With `spend_budget` (the default) the stall rule ends
//! only runs that no budget bounds: a run with a finite `cpumax`, `maxevals` or `max_starts`
//! goes on until that budget ends it, since more local searches can only lower the best
//! objective, and on small plants the stall rule used to end a 60-s job after 1–4 s.
//!
//! # Gradient sampling on the incumbent
//! If gradient sampling is on, [`GS_RESERVE`] of each budget (CPU and evaluations) is kept for
//! it once a stable point is known: from then on the local searches run under the remaining
//! part, then gradient sampling on f_h runs from the best point (HANSO 2.0's rule: only if its
//! certificate dnorm > normtol) under the whole budget, and replaces the best point if it lowers
//! f_h. It often needs much less than the reserve (HE1 left about 5 of 60 CPU s unused). With
//! `return_gs_reserve` (the default) gradient sampling runs on the incumbent where HIFOO's search
//! runs it — right after HIFOO's `nrand` first starts, with the generator in the same state, so
//! the incumbent is from then on HIFOO's own result, bit for bit, and the search can only end
//! below it — and the search goes on under the whole budget less [`GS_RESERVE_FACTOR`] times
//! what that gradient sampling took (CPU seconds and evaluations; the most measured so far, at
//! most the first reserve; this gradient sampling itself gets at most the first reserve, so that
//! a small evaluation budget is not spent on it). Whenever the search's share is spent, gradient sampling runs again
//! from the incumbent if it changed, and the search goes on with what that leaves, first resuming
//! the incumbent's local search if the budget or `maxit` cut it (`continue_at_maxit`), until a
//! round gives nothing back; at the end gradient sampling runs from the incumbent only if it
//! changed since the last one. While nothing was measured (no stable point after the first
//! starts, or a certified incumbent) the first reserve stays. The final incumbent thus always had
//! its gradient sampling (or a certificate), as without the option.
//!
//! # Reproducibility
//! All randomness comes from the run's ChaCha8 generator, drawn in a fixed order. With
//! `maxevals`, `max_starts` or the stall rule ending the run, and the CPU budget not binding, the
//! run's path — and the returned controller, bit for bit — does not depend on timing, threads or
//! load. A run ended by `cpumax` depends on the machine's speed.

use std::rc::Rc;

use rand::RngCore;

use crate::lti::is_stable;
use crate::optim::{bfgs, gradient_sampling, OptimError, OptimResult, RunControl, Termination};

use super::objective::{DesignObjective, ObjectivePhase, ObserverAdapter};
use super::options::{DesignOptions, VariableScaling};
use super::outcome::{DesignError, Phase, PhaseStats, SearchStop, SearchSummary, StartKind};
use super::phases::{bfgs_options, gradsamp_options, optim_error, perf_bfgs_options};
use super::scaling::{from_scaled, to_scaled};
use super::starts::{perturb, scaled_random_start};

/// Share of the CPU and evaluation budgets kept for the final gradient sampling (when enabled).
pub const GS_RESERVE: f64 = 0.1;

/// With `return_gs_reserve`: the reserve kept after a gradient sampling on the incumbent is this
/// many times what it took (CPU seconds and evaluations), at most [`GS_RESERVE`] of the budget.
pub const GS_RESERVE_FACTOR: f64 = 2.0;

/// `variable_scaling = "alternate"`: one hop cycle in this many runs in the coordinates (x or
/// x̃) the incumbent was not found in, the others in those it was (module docs).
pub const ALTERNATE_PERIOD: usize = 4;

/// Relative tolerance of "first reached" for [`SearchSummary::cpu_to_best_s`].
pub const TIME_TO_BEST_RTOL: f64 = 1e-6;

/// The best point of one objective, with where it came from.
#[derive(Debug, Clone)]
pub(crate) struct Best {
    /// The point.
    pub x: Vec<f64>,
    /// Its objective value.
    pub f: f64,
    /// Its certificate (f_h only).
    pub dnorm: f64,
    /// See `dnorm`.
    pub evaldist: f64,
    /// The local search that produced it.
    pub start: usize,
    /// The stable point its f_h local search started from (to tell whether it moved).
    pub from: Vec<f64>,
    /// The coordinates of the local search that produced it.
    pub coords: Coords,
}

/// The coordinates of one local search (docs/ALGORITHMS.md §8.6): the controller's parameters x,
/// or the plant-scaled variables x̃ (x = d ∘ x̃). Points outside a local search (the incumbents)
/// are always kept in x; x ↔ x̃ is exact (d holds powers of two).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Coords {
    /// x.
    Raw,
    /// x̃.
    Scaled,
}

/// The objectives in plant-scaled variables (`DesignObjective::with_scaling(Some(d))`) and d.
pub(crate) struct ScaledObjectives<'r, 'o> {
    pub stab_obj: &'r mut DesignObjective<'o>,
    pub perf_obj: &'r mut DesignObjective<'o>,
    pub d: Rc<[f64]>,
}

/// What the search produced.
#[derive(Debug, Clone)]
pub(crate) struct SearchResult {
    /// Best stable point by f_h (None if none was stabilised or f_h was never finite).
    pub perf: Option<Best>,
    /// Best point by f_s.
    pub stab: Best,
    /// Whether any stable point was found.
    pub stabilised: bool,
    /// Per-phase counters: stabilisation, optimisation (if a stable point was found), gradient
    /// sampling (if it ran).
    pub phases: Vec<PhaseStats>,
    /// The search summary (time to best filled in by the caller's adapter).
    pub summary: SearchSummary,
    /// True if a budget ended the run before HIFOO's first starts (the `nrand` random or init
    /// starts, not the open-loop or central-controller ones) were all made.
    pub truncated: bool,
}

fn stop_of(t: Termination) -> Option<SearchStop> {
    match t {
        Termination::CpuBudget => Some(SearchStop::Budget),
        Termination::EvalBudget => Some(SearchStop::Maxevals),
        Termination::Interrupted => Some(SearchStop::Interrupted),
        _ => None,
    }
}

fn ctl_stop(ctl: &RunControl) -> Option<SearchStop> {
    if ctl.cancelled() {
        Some(SearchStop::Interrupted)
    } else if ctl.cpu_exhausted() {
        Some(SearchStop::Budget)
    } else if ctl.evals_exhausted() {
        Some(SearchStop::Maxevals)
    } else {
        None
    }
}

/// True if `new` improves on `old` by the stall rule's tolerance.
fn improves(new: f64, old: f64, rtol: f64, abs_floor: f64) -> bool {
    new.is_finite() && (!old.is_finite() || new < old - rtol * old.abs().max(abs_floor))
}

/// Mutable state of the search.
struct State<'s> {
    opts: &'s DesignOptions,
    stats: [PhaseStats; 3],
    perf: Option<Best>,
    stab: Option<Best>,
    stabilised: bool,
    stall: usize,
    /// The f_h local search that produced `perf` ended on `maxit` or a budget (not at a
    /// minimiser): the next continued start resumes it (`continue_at_maxit`).
    perf_cut: bool,
    /// The continued search has begun: its f_h local searches use `continued_maxit`.
    continued: bool,
    /// Near-misses refined by gradient sampling so far (`refine_rtol`).
    refinements: usize,
}

impl State<'_> {
    fn evals(&self) -> usize {
        self.stats.iter().map(|s| s.evals).sum()
    }

    fn add(&mut self, which: usize, r: &OptimResult, cpu0: f64, cpu1: f64) {
        let s = &mut self.stats[which];
        s.iters += r.iters;
        s.evals += r.evals;
        s.cpu_s += cpu1 - cpu0;
    }

    /// Records an f_s end point; returns whether it improved the best f_s (stall sense).
    fn offer_stab(&mut self, x: Vec<f64>, f: f64, start: usize, coords: Coords) -> bool {
        let f = if f.is_nan() { f64::INFINITY } else { f };
        let old = self.stab.as_ref().map_or(f64::INFINITY, |b| b.f);
        let better = improves(f, old, self.opts.stall_rtol, 1.0);
        if self.stab.is_none() || f < old {
            self.stab = Some(Best { from: x.clone(), x, f, dnorm: f64::NAN, evaldist: f64::NAN, start, coords });
        }
        better
    }

    /// Records an f_h end point; returns whether it improved the best f_h (stall sense).
    fn offer_perf(&mut self, r: &OptimResult, from: &[f64], start: usize, coords: Coords) -> bool {
        let old = self.perf.as_ref().map_or(f64::INFINITY, |b| b.f);
        let better = improves(r.f, old, self.opts.stall_rtol, 0.0);
        if r.f.is_finite() && r.f < old {
            let (x, from) = (r.x.clone(), from.to_vec());
            self.perf = Some(Best { x, f: r.f, dnorm: r.dnorm, evaldist: r.evaldist, start, from, coords });
            // Cut by `maxit`, or by the search's share of a budget (`return_gs_reserve` may give
            // the search more).
            self.perf_cut =
                matches!(r.termination, Termination::MaxIters | Termination::CpuBudget | Termination::EvalBudget);
        }
        better
    }

    /// Whether the f_h local search that ended at `r` is a near-miss to refine (module docs,
    /// "Refining near-misses"): a local search of the continued search, not certified
    /// (dnorm > normtol), not cut by a budget, and within a relative `refine_rtol` above the
    /// incumbent (a point below it becomes the incumbent and has its gradient sampling anyway).
    fn refines(&self, r: &OptimResult) -> bool {
        let o = self.opts;
        let Some(inc) = self.perf.as_ref().map(|b| b.f) else { return false };
        self.continued
            && o.gradient_sampling
            && o.refine_rtol > 0.0
            && r.dnorm > o.normtol
            && stop_of(r.termination).is_none()
            && r.f >= inc
            && r.f <= inc + o.refine_rtol * inc.abs()
    }

    /// The start that resumes the incumbent's local search if `maxit` cut it (and
    /// `continue_at_maxit`): the incumbent itself, once, in its local search's coordinates.
    fn take_continuation(&mut self) -> Option<(Vec<f64>, Coords)> {
        if !(self.opts.continue_at_maxit && self.perf_cut) {
            return None;
        }
        self.perf_cut = false;
        self.perf.as_ref().map(|b| (b.x.clone(), b.coords))
    }
}

/// What `return_gs_reserve` has done so far (module docs).
#[derive(Debug, Default)]
struct GsRounds {
    /// The first reserve (CPU seconds, evaluations): the most that is ever kept.
    first: (f64, usize),
    /// The reserve kept now.
    kept: (f64, usize),
    /// The incumbent as the last gradient sampling left it.
    at: Option<Vec<f64>>,
    /// Gradient sampling ran at least once.
    ran: bool,
    /// The incumbent as the last gradient sampling that actually ran left it.
    treated: Option<Vec<f64>>,
    /// The step after HIFOO's first starts was taken.
    after_first: bool,
    /// No round is left to give.
    done: bool,
}

/// Everything one search needs besides its state.
pub(crate) struct Search<'r, 'o, 'a> {
    pub stab_obj: &'r mut DesignObjective<'o>,
    pub perf_obj: &'r mut DesignObjective<'o>,
    pub adapter: &'r mut ObserverAdapter<'a, 'o>,
    pub rng: &'r mut dyn RngCore,
    /// The whole run's control.
    pub ctl: &'r RunControl,
    /// The objectives in plant-scaled variables, if the plant is scaled (`design::scaling`) and
    /// the run's [`VariableScaling`] mode is not off.
    pub scaled: Option<ScaledObjectives<'r, 'o>>,
}

/// The objective of `phase` (stabilisation, or performance if `perf`) in coordinates `c`.
fn pick<'s, 'o>(
    raw: &'s mut DesignObjective<'o>,
    scaled: &'s mut Option<ScaledObjectives<'_, 'o>>,
    perf: bool,
    c: Coords,
) -> &'s mut DesignObjective<'o> {
    match (c, scaled) {
        (Coords::Scaled, Some(s)) => {
            if perf {
                s.perf_obj
            } else {
                s.stab_obj
            }
        }
        _ => raw,
    }
}

impl Search<'_, '_, '_> {
    /// `x` (controller parameters) in coordinates `c`.
    fn to_coords(&self, x: &[f64], c: Coords) -> Vec<f64> {
        match (c, &self.scaled) {
            (Coords::Scaled, Some(s)) => to_scaled(x, Some(&s.d)),
            _ => x.to_vec(),
        }
    }

    /// The controller parameters of `x` given in coordinates `c`.
    fn to_raw(&self, x: &[f64], c: Coords) -> Vec<f64> {
        match (c, &self.scaled) {
            (Coords::Scaled, Some(s)) => from_scaled(x, Some(&s.d)),
            _ => x.to_vec(),
        }
    }

    /// The coordinates of HIFOO's first starts (`continued` None) or of the hop cycle that begins
    /// with continued start number `j` (`continued` = (j, hop cycle length, coordinates of the
    /// incumbent's local search)), module docs: `Alternate` runs one hop cycle in [`ALTERNATE_PERIOD`] (the first one
    /// included) in the coordinates the incumbent was not found in, the others in those it was.
    fn coords_of(&self, mode: VariableScaling, continued: Option<(usize, usize, Coords)>) -> Coords {
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

    /// The first starts' local searches, in order: (index into the first starts, coordinates).
    /// Every start is made in the coordinates of [`Self::coords_of`]; with `Alternate` on a scaled
    /// plant each central start is made twice, first in x, then in x̃ (module docs, "Coordinates").
    fn first_plan(&self, mode: VariableScaling, kinds: &[StartKind], n: usize) -> Vec<(usize, Coords)> {
        let c = self.coords_of(mode, None);
        let both = self.scaled.is_some() && mode == VariableScaling::Alternate;
        let mut plan = Vec::with_capacity(2 * n);
        for i in 0..n {
            plan.push((i, c));
            if both && kinds.get(i) == Some(&StartKind::Central) {
                plan.push((i, Coords::Scaled));
            }
        }
        plan
    }

    /// One local search from `x0`, given in coordinates `c` (module docs). Returns the stop
    /// reason if a budget or an interrupt ended it, and whether it improved the incumbent (stall
    /// sense).
    fn local(
        &mut self,
        st: &mut State<'_>,
        x0: &[f64],
        k: usize,
        c: Coords,
        ctl: &RunControl,
    ) -> Result<(Option<SearchStop>, bool), DesignError> {
        let opts = st.opts;
        let obj = pick(self.stab_obj, &mut self.scaled, false, c);
        self.adapter.switch(obj, Phase::Stabilisation);
        self.adapter.set_evals_base(st.evals());
        let c0 = ctl.cpu_elapsed();
        let (xs, fs) = match bfgs(obj, x0, k, &bfgs_options(opts, 0.0), ctl, self.adapter) {
            Ok(r) => {
                st.add(0, &r, c0, ctl.cpu_elapsed());
                if let Some(stop) = stop_of(r.termination) {
                    let better = st.offer_stab(self.to_raw(&r.x, c), r.f, k, c);
                    return Ok((Some(stop), better));
                }
                (r.x, r.f)
            }
            Err(OptimError::NonFiniteStart { f }) => {
                st.stats[0].evals += 1;
                (x0.to_vec(), f)
            }
            Err(e) => return Err(optim_error(e)),
        };
        let stab_better = st.offer_stab(self.to_raw(&xs, c), fs, k, c);
        if !is_stable(fs) {
            // Not stabilised: progress only counts while no stable point is known.
            return Ok((None, !st.stabilised && stab_better));
        }
        st.stabilised = true;
        self.optimise_from(st, &xs, k, c, ctl)
    }

    /// BFGS on f_h from the stable point `xs`, given in coordinates `c`.
    fn optimise_from(
        &mut self,
        st: &mut State<'_>,
        xs: &[f64],
        k: usize,
        c: Coords,
        ctl: &RunControl,
    ) -> Result<(Option<SearchStop>, bool), DesignError> {
        let opts = st.opts;
        let obj = pick(self.perf_obj, &mut self.scaled, true, c);
        self.adapter.switch(obj, Phase::Optimisation);
        self.adapter.set_evals_base(st.evals());
        let c0 = ctl.cpu_elapsed();
        match bfgs(obj, xs, k, &perf_bfgs_options(opts, st.continued), ctl, self.adapter) {
            Ok(mut r) => {
                st.add(1, &r, c0, ctl.cpu_elapsed());
                if st.refines(&r) {
                    r = self.refine(st, r, c, ctl)?;
                }
                r.x = self.to_raw(&r.x, c);
                let better = st.offer_perf(&r, &self.to_raw(xs, c), k, c);
                Ok((stop_of(r.termination), better))
            }
            // f_h = +∞ at a point with α just below 0 (the norm's stability test has a margin):
            // nothing to optimise from here.
            Err(OptimError::NonFiniteStart { .. }) => {
                st.stats[1].evals += 1;
                Ok((None, false))
            }
            Err(e) => Err(optim_error(e)),
        }
    }

    /// Gradient sampling on f_h from the end point `r` of a continued local search that
    /// [`State::refines`] (module docs, "Refining near-misses"), in its coordinates `c`, under
    /// `ctl`; returns its end point if it lowered f_h, else `r`.
    fn refine(
        &mut self,
        st: &mut State<'_>,
        r: OptimResult,
        c: Coords,
        ctl: &RunControl,
    ) -> Result<OptimResult, DesignError> {
        let Some(g) = self.gs_perf(st, &r.x, c, ctl)? else { return Ok(r) };
        st.refinements += 1;
        Ok(if g.f < r.f { g } else { r })
    }

    /// Gradient sampling on f_h from `x0`, in coordinates `c` (its end point too), under `ctl`,
    /// counted in the gradient-sampling statistics; `None` if f_h is not finite at `x0`. Serves
    /// the incumbent's gradient sampling ([`Self::gs_incumbent`]) and the near-misses'
    /// ([`Self::refine`]).
    fn gs_perf(
        &mut self,
        st: &mut State<'_>,
        x0: &[f64],
        c: Coords,
        ctl: &RunControl,
    ) -> Result<Option<OptimResult>, DesignError> {
        let obj = pick(self.perf_obj, &mut self.scaled, true, c);
        self.adapter.switch(obj, Phase::Optimisation);
        self.adapter.set_evals_base(st.evals());
        let c0 = ctl.cpu_elapsed();
        let gopts = gradsamp_options(st.opts, f64::NEG_INFINITY);
        match gradient_sampling(obj, x0, &gopts, self.rng, ctl, self.adapter) {
            Ok(r) => {
                st.add(2, &r, c0, ctl.cpu_elapsed());
                Ok(Some(r))
            }
            Err(OptimError::NonFiniteStart { .. }) => {
                st.stats[2].evals += 1;
                Ok(None)
            }
            Err(e) => Err(optim_error(e)),
        }
    }

    /// HIFOO's fallback when no first start was stabilised: gradient sampling on f_s from the
    /// best f_s point (in its local search's coordinates), then f_h from its end point if stable.
    fn gs_stabilise(
        &mut self,
        st: &mut State<'_>,
        k: usize,
        ctl: &RunControl,
    ) -> Result<(Option<SearchStop>, bool), DesignError> {
        let opts = st.opts;
        let Some((x0, c)) = st.stab.as_ref().filter(|b| b.f.is_finite()).map(|b| (b.x.clone(), b.coords)) else {
            return Ok((None, false));
        };
        let x0 = self.to_coords(&x0, c);
        let obj = pick(self.stab_obj, &mut self.scaled, false, c);
        self.adapter.switch(obj, Phase::Stabilisation);
        self.adapter.set_evals_base(st.evals());
        let c0 = ctl.cpu_elapsed();
        match gradient_sampling(obj, &x0, &gradsamp_options(opts, 0.0), self.rng, ctl, self.adapter) {
            Ok(r) => {
                st.add(0, &r, c0, ctl.cpu_elapsed());
                let better = st.offer_stab(self.to_raw(&r.x, c), r.f, k, c);
                if let Some(stop) = stop_of(r.termination) {
                    return Ok((Some(stop), better));
                }
                if is_stable(r.f) {
                    st.stabilised = true;
                    return self.optimise_from(st, &r.x, k, c, ctl);
                }
                Ok((None, better))
            }
            Err(OptimError::NonFiniteStart { .. }) => {
                st.stats[0].evals += 1;
                Ok((None, false))
            }
            Err(e) => Err(optim_error(e)),
        }
    }

    /// The start of continued local search number `j` (0-based after the first starts), in
    /// coordinates `c` (hops of the best point and random starts are drawn in them).
    /// The c-th fresh random start (c counts them) is at scale `random_scales[c mod len]`.
    fn next_start(&mut self, st: &State<'_>, j: usize, nvar: usize, c: Coords) -> (Vec<f64>, StartKind) {
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

    /// Gradient sampling on f_h from the incumbent under `ctl`, if the incumbent is not
    /// certified (HANSO 2.0's rule: dnorm > normtol) and the budget is not spent; its end point
    /// replaces the incumbent if it lowers f_h. Returns whether it ran.
    fn gs_incumbent(&mut self, st: &mut State<'_>, ctl: &RunControl) -> Result<bool, DesignError> {
        let opts = st.opts;
        let Some(best) = st.perf.clone() else { return Ok(false) };
        if !(best.dnorm > opts.normtol && ctl_stop(ctl).is_none()) {
            return Ok(false);
        }
        // In the coordinates of the local search that found the best point.
        let c = best.coords;
        let x0 = self.to_coords(&best.x, c);
        let Some(mut r) = self.gs_perf(st, &x0, c, ctl)? else { return Ok(false) };
        r.x = self.to_raw(&r.x, c);
        let b = st.perf.as_mut().expect("checked above");
        if r.f < b.f {
            b.x = r.x;
            b.f = r.f;
            b.dnorm = r.dnorm;
            b.evaldist = r.evaldist;
        } else if r.x == b.x && r.dnorm < b.dnorm {
            b.dnorm = r.dnorm;
            b.evaldist = r.evaldist;
        }
        Ok(true)
    }

    /// `return_gs_reserve`, after HIFOO's first starts and whenever the search has spent its share
    /// of the budget: gradient sampling on the incumbent (if it changed since the last one), then
    /// the control of the search from here — the whole budget less [`GS_RESERVE_FACTOR`] times the
    /// most a gradient sampling took, at most the first reserve; the whole budget when the share
    /// is spent and gradient sampling had nothing to do — or None if nothing was measured or that
    /// share is already spent (module docs).
    fn return_reserve(
        &mut self,
        st: &mut State<'_>,
        rounds: &mut GsRounds,
        share_spent: bool,
    ) -> Result<Option<RunControl>, DesignError> {
        let full = self.ctl;
        let (c0, e0) = (full.cpu_elapsed(), full.evals());
        let mut ran_now = false;
        if st.perf.as_ref().map(|b| &b.x) != rounds.at.as_ref() {
            // At most the first reserve from now (small evaluation budgets: HE1 n_K = 2 under
            // maxevals = 10 000 spent most of its budget on this gradient sampling otherwise).
            let cap = full.less(
                full.cpumax() - c0 - rounds.first.0,
                full.maxevals().map_or(0, |m| m.saturating_sub(e0.saturating_add(rounds.first.1))),
            );
            ran_now = self.gs_incumbent(st, &cap)?;
            rounds.ran |= ran_now;
        }
        rounds.at = st.perf.as_ref().map(|b| b.x.clone());
        if ran_now {
            rounds.treated.clone_from(&rounds.at);
        }
        let idle =
            st.perf.as_ref().is_some_and(|b| b.dnorm <= st.opts.normtol || rounds.treated.as_ref() == Some(&b.x));
        if share_spent && idle {
            // The search's share is spent and gradient sampling has nothing to do (a certified
            // incumbent, or the one it already ran from): a reserve kept for it would go unused,
            // so the search gets the whole rest. A later incumbent is better than this one, so
            // the result cannot get worse; gradient sampling then runs on what is left.
            return Ok(Some(full.less(0.0, 0)));
        }
        let (c, e) = (full.cpu_elapsed() - c0, full.evals() - e0);
        if !rounds.ran {
            return Ok(None); // nothing measured (a certified incumbent): the first reserve stays
        }
        rounds.kept = (
            rounds.kept.0.max(GS_RESERVE_FACTOR * c).min(rounds.first.0),
            rounds.kept.1.max((GS_RESERVE_FACTOR * e as f64).ceil() as usize).min(rounds.first.1),
        );
        let next = full.less(rounds.kept.0, rounds.kept.1);
        Ok(ctl_stop(&next).is_none().then_some(next))
    }

    /// Runs the whole search from the first starts `first` (module docs).
    pub(crate) fn run(
        &mut self,
        opts: &DesignOptions,
        first: &[Vec<f64>],
        first_kinds: &[StartKind],
        nvar: usize,
    ) -> Result<SearchResult, DesignError> {
        let reserve = if opts.gradient_sampling { 1.0 - GS_RESERVE } else { 1.0 };
        let mut search_ctl = self.ctl.sub_budget(reserve, reserve);
        let zero = |phase| PhaseStats { phase, iters: 0, evals: 0, cpu_s: 0.0 };
        let mut st = State {
            opts,
            stats: [zero(Phase::Stabilisation), zero(Phase::Optimisation), zero(Phase::GradientSampling)],
            perf: None,
            stab: None,
            stabilised: false,
            stall: 0,
            perf_cut: false,
            continued: false,
            refinements: 0,
        };
        let mut k = 0usize; // local searches made
        let mut cycle = 0usize; // continued starts drawn from the hop / random cycle
        let mut gs_fallback_done = false;
        let mut kinds: Vec<StartKind> = Vec::new(); // kind of local search k
        let mut coords: Vec<Coords> = Vec::new(); // its coordinates
        let mut cycle_coords = Coords::Raw; // coordinates of the current hop cycle
        let mut stop = None;
        let full_ctl = self.ctl;
        let returning = opts.return_gs_reserve && opts.gradient_sampling;
        let first_reserve = (
            GS_RESERVE * full_ctl.cpumax(),
            full_ctl.maxevals().map_or(usize::MAX, |m| m - search_ctl.maxevals().unwrap_or(m)),
        );
        let mut rounds = GsRounds { first: first_reserve, ..Default::default() };
        let plan = self.first_plan(opts.variable_scaling, first_kinds, first.len());
        // HIFOO's own first starts (random or init): the extra open-loop and central starts are
        // like the continued search, a budget may end the run before them without truncating it.
        let hifoo_starts = first_kinds
            .iter()
            .take(first.len())
            .filter(|k| !matches!(k, StartKind::Central | StartKind::OpenLoop))
            .count();
        while stop.is_none() {
            let share_spent = ctl_stop(&search_ctl).is_some() && ctl_stop(full_ctl).is_none();
            // Gradient sampling where HIFOO's search makes it (after its first starts, with the
            // generator in the same state), and whenever the search's share is spent.
            let hifoo_done = k == hifoo_starts && !rounds.after_first;
            if returning && st.stabilised && !rounds.done && (share_spent || hifoo_done) {
                rounds.after_first |= hifoo_done;
                match self.return_reserve(&mut st, &mut rounds, share_spent)? {
                    Some(c) => search_ctl = c,
                    None => rounds.done = share_spent,
                }
            }
            // The gradient-sampling reserve is kept only once there is a stable point to refine.
            let search_ctl = if st.stabilised { &search_ctl } else { full_ctl };
            if let Some(s) = ctl_stop(search_ctl) {
                stop = Some(s);
                break;
            }
            if opts.max_starts.is_some_and(|m| k >= m) {
                stop = Some(SearchStop::Starts);
                break;
            }
            let (s, better) = if let Some(&(i, c)) = plan.get(k) {
                kinds.push(first_kinds.get(i).copied().unwrap_or(StartKind::Random));
                coords.push(c);
                let x0 = self.to_coords(&first[i], c);
                self.local(&mut st, &x0, k, c, search_ctl)?
            } else if !st.stabilised && opts.gradient_sampling && !gs_fallback_done {
                gs_fallback_done = true;
                kinds.push(StartKind::GradientSampling);
                coords.push(st.stab.as_ref().map_or(Coords::Raw, |b| b.coords));
                self.gs_stabilise(&mut st, k, search_ctl)?
            } else {
                if opts.stall_starts == 0 {
                    stop = Some(SearchStop::Starts);
                    break;
                }
                // Stabilisation is never given up while a budget bounds the run: the stall rule
                // applies once a stable point is known (or when nothing else would end the run),
                // and with `spend_budget` only when nothing else would end the run.
                let bounded = search_ctl.cpumax().is_finite() || opts.maxevals.is_some() || opts.max_starts.is_some();
                let stall_ends = !bounded || (st.stabilised && !opts.spend_budget);
                if st.stall >= opts.stall_starts && stall_ends {
                    stop = Some(SearchStop::Stall);
                    break;
                }
                let (x0, kind, c) = match st.take_continuation() {
                    Some((x, c)) => (self.to_coords(&x, c), StartKind::Hop, c),
                    None => {
                        cycle += 1;
                        // A hop cycle's coordinates are chosen at its first start.
                        let len = opts.hop_scales.len() + 1;
                        if (cycle - 1).is_multiple_of(len) {
                            let inc = st.perf.as_ref().or(st.stab.as_ref()).map_or(Coords::Raw, |b| b.coords);
                            cycle_coords = self.coords_of(opts.variable_scaling, Some((cycle - 1, len, inc)));
                        }
                        let c = cycle_coords;
                        let (x0, kind) = self.next_start(&st, cycle - 1, nvar, c);
                        (x0, kind, c)
                    }
                };
                kinds.push(kind);
                st.continued = true;
                coords.push(c);
                self.local(&mut st, &x0, k, c, search_ctl)?
            };
            k += 1;
            st.stall = if better { 0 } else { st.stall + 1 };
            // The search's share of a budget is spent but the budget is not: the next turn may
            // give the search back what gradient sampling does not need (`return_gs_reserve`).
            let share_only =
                matches!(s, Some(SearchStop::Budget | SearchStop::Maxevals)) && ctl_stop(full_ctl).is_none();
            stop = s.filter(|_| !(returning && st.stabilised && share_only && !rounds.done));
        }
        let stop = stop.unwrap_or(SearchStop::Starts);
        let truncated = k < hifoo_starts && matches!(stop, SearchStop::Budget | SearchStop::Maxevals);

        // Gradient sampling from the best stable point, under the whole budget (unless it already
        // ran from it).
        if opts.gradient_sampling
            && stop != SearchStop::Interrupted
            && st.perf.as_ref().map(|b| &b.x) != rounds.at.as_ref()
        {
            rounds.ran |= self.gs_incumbent(&mut st, full_ctl)?;
        }
        let [s0, s1, s2] = st.stats;
        let mut phases = vec![s0];
        if st.stabilised {
            phases.push(s1);
        }
        if rounds.ran || st.refinements > 0 {
            phases.push(s2);
        }
        let stab = st.stab.unwrap_or_else(|| Best {
            x: first[0].clone(),
            f: f64::INFINITY,
            dnorm: f64::NAN,
            evaldist: f64::NAN,
            start: 0,
            from: first[0].clone(),
            coords: Coords::Raw,
        });
        let best_start = st.perf.as_ref().map_or(stab.start, |b| b.start);
        let (phase, f) = match &st.perf {
            Some(b) => (ObjectivePhase::Performance, b.f),
            None => (ObjectivePhase::Stabilisation, stab.f),
        };
        let reached = self.adapter.first_reached(phase, f, TIME_TO_BEST_RTOL);
        let summary = SearchSummary {
            starts: k,
            best_start,
            best_start_kind: kinds.get(best_start).copied(),
            best_start_scaled: coords.get(best_start) == Some(&Coords::Scaled),
            cpu_to_best_s: reached.map_or(0.0, |r| r.cpu_s),
            evals_to_best: reached.map_or(0, |r| r.evals),
            stop,
        };
        Ok(SearchResult { perf: st.perf, stab, stabilised: st.stabilised, phases, summary, truncated })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn end(f: f64, dnorm: f64, termination: Termination) -> OptimResult {
        OptimResult { x: vec![0.0], f, g: vec![0.0], dnorm, evaldist: 0.0, termination, iters: 1, evals: 1, cpu_s: 0.0 }
    }

    /// `refines`: only uncertified continued local searches that end within `refine_rtol` above
    /// the incumbent and were not cut by a budget.
    #[test]
    fn near_misses_are_refined_only_within_the_tolerance() {
        let opts = DesignOptions { refine_rtol: 0.03, ..Default::default() };
        let zero = |phase| PhaseStats { phase, iters: 0, evals: 0, cpu_s: 0.0 };
        let best =
            |f| Best { x: vec![1.0], f, dnorm: 0.0, evaldist: 0.0, start: 0, from: vec![1.0], coords: Coords::Raw };
        let mut st = State {
            opts: &opts,
            stats: [zero(Phase::Stabilisation), zero(Phase::Optimisation), zero(Phase::GradientSampling)],
            perf: Some(best(1.0)),
            stab: None,
            stabilised: true,
            stall: 0,
            perf_cut: false,
            continued: true,
            refinements: 0,
        };
        let stalled = Termination::LineSearchFailed;
        assert!(st.refines(&end(1.02, 0.1, stalled)));
        assert!(st.refines(&end(1.0, 0.1, Termination::MaxIters)));
        assert!(!st.refines(&end(1.04, 0.1, stalled)), "beyond refine_rtol");
        assert!(!st.refines(&end(0.99, 0.1, stalled)), "below the incumbent: it becomes the incumbent");
        assert!(!st.refines(&end(1.02, 1e-4, stalled)), "certified");
        assert!(!st.refines(&end(1.02, 0.1, Termination::CpuBudget)), "cut by a budget");
        assert!(!st.refines(&end(f64::INFINITY, 0.1, stalled)));
        st.continued = false;
        assert!(!st.refines(&end(1.02, 0.1, stalled)), "HIFOO's first starts are not refined");
        st.continued = true;
        st.perf = None;
        assert!(!st.refines(&end(1.02, 0.1, stalled)), "no incumbent");
        let off = DesignOptions { refine_rtol: 0.0, ..Default::default() };
        st.opts = &off;
        st.perf = Some(best(1.0));
        assert!(!st.refines(&end(1.0, 0.1, stalled)), "refine_rtol = 0: off");
    }
}
