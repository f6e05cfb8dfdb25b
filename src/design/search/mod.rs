//! The multi-start search of a design run (docs/ALGORITHMS.md §8.3–§8.6): local searches
//! until a budget or the stall rule ends it, then gradient sampling from the best point. The
//! measurements behind its rules are in docs/ALGORITHMS.md §8, not here.
//!
//! Four parts, one module each:
//! * [`given`]: the run's given controllers (warm and chained starts) are incumbents before any
//!   local search, and their local searches are made best first;
//! * [`plan`]: where the local searches start — HIFOO's first starts (`nrand` random points, or
//!   an initial controller and `nrand` perturbations of it), the open-loop start, the central
//!   starts (twice on a scaled plant under `Alternate`), then the continued search's cycles of
//!   basin hops and fresh random starts at alternating scales, in the coordinates (x or x̃) each
//!   cycle is given, and the resumption of a local search cut by `maxit`;
//! * [`local`]: one local search — BFGS on f_s until stable, BFGS on f_h, the certificate, and
//!   the optional gradient sampling (HIFOO's stabilisation fallback, refining near-misses, the
//!   incumbent's);
//! * [`budget`]: what ends the search and what each part may spend — `cpumax`, `maxevals`,
//!   `max_starts`, the stall rule, and the gradient-sampling reserve.
//!
//! [`Search::run`] joins them: it offers the given controllers, then asks the plan for the next start, runs the local search from
//! it under the budget's control, offers the end point to the incumbents ([`State`]) and counts
//! the stall, until the budget ends the search; then the incumbent's gradient sampling.
//!
//! # Reproducibility
//! All randomness comes from the run's ChaCha8 generator, drawn in a fixed order. With
//! `maxevals`, `max_starts` or the stall rule ending the run, and the CPU budget not binding, the
//! run's path — and the returned controller, bit for bit — does not depend on timing, threads or
//! load. A run ended by `cpumax` depends on the machine's speed.

mod budget;
mod given;
mod local;
mod plan;
mod verified;

use std::rc::Rc;

use rand::RngCore;

use crate::optim::{OptimResult, RunControl, Termination};

use super::objective::{DesignObjective, ObjectivePhase, ObserverAdapter};
use super::options::DesignOptions;
use super::outcome::{DesignError, Phase, PhaseStats, SearchStop, SearchSummary, StartKind};
use super::problem::Problem;
use super::scaling::{from_scaled, to_scaled};
use budget::{ctl_stop, improves, stop_of, GsRounds};
use plan::{NextStart, StartPlan};

pub use budget::{GS_RESERVE, GS_RESERVE_FACTOR};
pub use plan::ALTERNATE_PERIOD;

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
    /// Whether a local search reached it by moving: its f_h local search ended away from its
    /// start, or it is the incumbent's point again (a resumed local search that could not move
    /// it, replacing it on a tie) and the incumbent was so reached. False for the f_s points, the
    /// given controllers, and f_h end points no local search moved: the run's status calls a
    /// result that is such a point "stabilised only" (`design::run`).
    pub moved: bool,
    /// The coordinates of the local search that produced it.
    pub coords: Coords,
    /// Whether it is stable with the verification margin (f_h points; [`verified`]).
    pub verified: bool,
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

/// The first starts of a search (module docs), as `design::run` makes them: the points
/// (controller parameters), their kinds, how many of them (at the front) are the run's given
/// controllers ([`given`]), and whether a chained start's local searches come first (else after
/// the run's own first starts, `given` module docs).
pub(crate) struct FirstStarts {
    pub points: Vec<Vec<f64>>,
    pub kinds: Vec<StartKind>,
    pub given: usize,
    pub chained_first: bool,
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

/// Mutable state of the search.
struct State<'s> {
    opts: &'s DesignOptions,
    stats: [PhaseStats; 3],
    perf: Option<Best>,
    stab: Option<Best>,
    stabilised: bool,
    stall: usize,
    /// CPU seconds of the run (its control's clock) at the last improvement in the stall rule's
    /// sense (0: none yet), for `stall_cpu`.
    improved_cpu: f64,
    /// The f_h local search that produced `perf` ended on `maxit` or a budget (not at a
    /// minimiser): the next continued start resumes it (`continue_at_maxit`).
    perf_cut: bool,
    /// The continued search has begun: its f_h local searches use `continued_maxit`.
    continued: bool,
    /// Near-misses refined by gradient sampling so far (`refine_rtol`).
    refinements: usize,
}

impl<'s> State<'s> {
    /// The state before the first start.
    fn new(opts: &'s DesignOptions) -> Self {
        let zero = |phase| PhaseStats { phase, iters: 0, evals: 0, cpu_s: 0.0 };
        State {
            opts,
            stats: [zero(Phase::Stabilisation), zero(Phase::Optimisation), zero(Phase::GradientSampling)],
            perf: None,
            stab: None,
            stabilised: false,
            stall: 0,
            improved_cpu: 0.0,
            perf_cut: false,
            continued: false,
            refinements: 0,
        }
    }

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
            let verified = false; // not asked of f_s points
            self.stab = Some(Best { x, f, dnorm: f64::NAN, evaldist: f64::NAN, start, moved: false, coords, verified });
        }
        better
    }

    /// Records an f_h end point, `verified` if it is stable with the verification margin;
    /// returns whether it improved the best f_h (stall sense). A verified point beats an
    /// unverified one whatever their f_h ([`verified`]).
    fn offer_perf(&mut self, r: &OptimResult, from: &[f64], start: usize, coords: Coords, verified: bool) -> bool {
        let (old, old_verified, old_dnorm) =
            self.perf.as_ref().map_or((f64::INFINITY, false, f64::INFINITY), |b| (b.f, b.verified, b.dnorm));
        if old_verified && !verified {
            return false;
        }
        let upgrade = verified && !old_verified && self.perf.is_some() && r.f.is_finite();
        let better = upgrade || improves(r.f, old, self.opts.stall_rtol, 0.0);
        // A tie with a better certificate replaces (a local search that could not move its
        // start, a given point offered uncertified: module `given`).
        if r.f.is_finite() && (upgrade || r.f < old || (r.f == old && r.dnorm < old_dnorm)) {
            let moved = r.x != from || self.perf.as_ref().is_some_and(|b| b.moved && b.x == r.x);
            let x = r.x.clone();
            self.perf = Some(Best { x, f: r.f, dnorm: r.dnorm, evaldist: r.evaldist, start, moved, coords, verified });
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

/// Everything one search needs besides its state.
pub(crate) struct Search<'r, 'o, 'a> {
    pub stab_obj: &'r mut DesignObjective<'o>,
    pub perf_obj: &'r mut DesignObjective<'o>,
    pub adapter: &'r mut ObserverAdapter<'a, 'o>,
    pub rng: &'r mut dyn RngCore,
    /// The whole run's control.
    pub ctl: &'r RunControl,
    /// The design problem: what the returned controller must stabilise ([`verified`]).
    pub problem: &'r Problem,
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

    /// Runs the whole search from the first starts `starts` (module docs).
    pub(crate) fn run(
        &mut self,
        opts: &DesignOptions,
        starts: &FirstStarts,
        nvar: usize,
    ) -> Result<SearchResult, DesignError> {
        let FirstStarts { points: first, kinds: first_kinds, given, chained_first } = starts;
        let reserve = if opts.gradient_sampling { 1.0 - GS_RESERVE } else { 1.0 };
        let mut search_ctl = self.ctl.sub_budget(reserve, reserve);
        let mut st = State::new(opts);
        let mut stop = None;
        let full_ctl = self.ctl;
        let returning = opts.return_gs_reserve && opts.gradient_sampling;
        let first_reserve = (
            GS_RESERVE * full_ctl.cpumax(),
            full_ctl.maxevals().map_or(usize::MAX, |m| m - search_ctl.maxevals().unwrap_or(m)),
        );
        let mut rounds = GsRounds { first: first_reserve, ..Default::default() };
        let given_values = self.given_values(&mut st, &first[..*given]);
        let given_order = given::lowest_first(&given_values);
        let mut plan = self.start_plan(opts.variable_scaling, first_kinds, &given_order, first.len(), *chained_first);
        self.offer_given(&mut st, &first[..*given], &given_values, &given_order, &plan);
        // HIFOO's own first starts (random or init): the extra open-loop and central starts are
        // like the continued search, a budget may end the run before them without truncating it.
        let hifoo_starts = first_kinds
            .iter()
            .take(first.len())
            .filter(|k| !matches!(k, StartKind::Central | StartKind::OpenLoop))
            .count();
        while stop.is_none() {
            let k = plan.made(); // the index of this turn's local search
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
            let (s, better) = match plan.next(&st) {
                NextStart::First(i, c) => {
                    let x0 = self.to_coords(&first[i], c);
                    self.local(&mut st, &x0, k, c, search_ctl)?
                }
                NextStart::Fallback => self.gs_stabilise(&mut st, k, search_ctl)?,
                NextStart::Continued => {
                    if let Some(s) = budget::continued_stop(&st, search_ctl) {
                        stop = Some(s);
                        break;
                    }
                    let (x0, c) = self.continued_start(&mut st, &mut plan, nvar);
                    st.continued = true;
                    self.local(&mut st, &x0, k, c, search_ctl)?
                }
            };
            st.stall = if better { 0 } else { st.stall + 1 };
            if better {
                st.improved_cpu = self.ctl.cpu_elapsed();
            }
            // The search's share of a budget is spent but the budget is not: the next turn may
            // give the search back what gradient sampling does not need (`return_gs_reserve`).
            let share_only =
                matches!(s, Some(SearchStop::Budget | SearchStop::Maxevals)) && ctl_stop(full_ctl).is_none();
            stop = s.filter(|_| !(returning && st.stabilised && share_only && !rounds.done));
        }
        let stop = stop.unwrap_or(SearchStop::Starts);
        let truncated = plan.made() < hifoo_starts && matches!(stop, SearchStop::Budget | SearchStop::Maxevals);

        // Gradient sampling from the best stable point, under the whole budget (unless it already
        // ran from it).
        if opts.gradient_sampling
            && stop != SearchStop::Interrupted
            && st.perf.as_ref().map(|b| &b.x) != rounds.at.as_ref()
        {
            rounds.ran |= self.gs_incumbent(&mut st, full_ctl)?;
        }
        Ok(self.result(st, first, plan, stop, truncated, rounds.ran))
    }

    /// What the search produced, once it has ended with `stop` after `plan`'s local searches:
    /// the best points (the f_s one defaults to the first of the first starts, `first`), the phases' counters
    /// (gradient sampling's if it ran, `gs_ran`, or refined near-misses) and the summary.
    fn result(
        &mut self,
        st: State<'_>,
        first: &[Vec<f64>],
        plan: StartPlan,
        stop: SearchStop,
        truncated: bool,
        gs_ran: bool,
    ) -> SearchResult {
        let k = plan.made();
        let [s0, s1, s2] = st.stats;
        let mut phases = vec![s0];
        if st.stabilised {
            phases.push(s1);
        }
        if gs_ran || st.refinements > 0 {
            phases.push(s2);
        }
        let stab = st.stab.unwrap_or_else(|| Best {
            x: first[0].clone(),
            f: f64::INFINITY,
            dnorm: f64::NAN,
            evaldist: f64::NAN,
            start: 0,
            moved: false,
            coords: Coords::Raw,
            verified: false,
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
            best_start_kind: plan.kind_at(best_start),
            best_start_scaled: plan.coords_at(best_start) == Some(Coords::Scaled),
            cpu_to_best_s: reached.map_or(0.0, |r| r.cpu_s),
            evals_to_best: reached.map_or(0, |r| r.evals),
            stop,
        };
        SearchResult { perf: st.perf, stab, stabilised: st.stabilised, phases, summary, truncated }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn end(f: f64, dnorm: f64, termination: Termination) -> OptimResult {
        OptimResult { x: vec![0.0], f, g: vec![0.0], dnorm, evaldist: 0.0, termination, iters: 1, evals: 1, cpu_s: 0.0 }
    }

    /// `offer_perf`'s `moved`: kept through a tie with the incumbent's own point (a resumed local
    /// search that could not move it), false for an end point no local search moved.
    #[test]
    fn a_resumed_search_that_cannot_move_the_incumbent_keeps_it_moved() {
        let opts = DesignOptions::default();
        let mut st = State::new(&opts);
        let at = |x: f64, f: f64, dnorm: f64| OptimResult { x: vec![x], ..end(f, dnorm, Termination::CpuBudget) };
        // a local search from 0 ends at 1 (cut by its budget share): moved
        assert!(st.offer_perf(&at(1.0, 2.0, 5.0), &[0.0], 0, Coords::Raw, true));
        assert!(st.perf.as_ref().unwrap().moved);
        // resumed from 1, it cannot move; the tie with a smaller dnorm replaces the incumbent,
        // which is still a point a local search reached by moving (NN13 n_K = 2 was called
        // "stabilised only" at γ = 10.4842, 0.6 below every start)
        st.offer_perf(&at(1.0, 2.0, 1.0), &[1.0], 1, Coords::Raw, true);
        let b = st.perf.as_ref().unwrap();
        assert_eq!((b.start, b.dnorm), (1, 1.0));
        assert!(b.moved);
        // a local search that ends where it started, below the incumbent: a point nothing moved
        st.offer_perf(&at(3.0, 1.5, 1.0), &[3.0], 2, Coords::Raw, true);
        assert!(!st.perf.as_ref().unwrap().moved);
    }

    /// `offer_perf`: a verified point beats an unverified one whatever their f_h; among points of
    /// one kind the smaller f_h wins (module `verified`).
    #[test]
    fn a_verified_point_beats_an_unverified_one() {
        let opts = DesignOptions::default();
        let mut st = State::new(&opts);
        let at = |x: f64, f: f64| OptimResult { x: vec![x], ..end(f, 0.1, Termination::LineSearchFailed) };
        assert!(st.offer_perf(&at(1.0, 1.0), &[0.0], 0, Coords::Raw, false));
        assert!(st.offer_perf(&at(2.0, 3.0), &[0.0], 1, Coords::Raw, true), "an upgrade counts as progress");
        assert_eq!((st.perf.as_ref().unwrap().x[0], st.perf.as_ref().unwrap().verified), (2.0, true));
        assert!(!st.offer_perf(&at(3.0, 0.5), &[0.0], 2, Coords::Raw, false), "unverified never displaces");
        assert_eq!(st.perf.as_ref().unwrap().x[0], 2.0);
        assert!(!st.offer_perf(&at(4.0, 3.5), &[0.0], 3, Coords::Raw, true));
        assert!(st.offer_perf(&at(5.0, 2.0), &[0.0], 4, Coords::Raw, true));
        assert_eq!(st.perf.as_ref().unwrap().x[0], 5.0);
    }

    /// `refines`: only uncertified continued local searches that end within `refine_rtol` above
    /// the incumbent and were not cut by a budget.
    #[test]
    fn near_misses_are_refined_only_within_the_tolerance() {
        let opts = DesignOptions { refine_rtol: 0.03, ..Default::default() };
        let zero = |phase| PhaseStats { phase, iters: 0, evals: 0, cpu_s: 0.0 };
        let best = |f| Best {
            x: vec![1.0],
            f,
            dnorm: 0.0,
            evaldist: 0.0,
            start: 0,
            moved: false,
            coords: Coords::Raw,
            verified: true,
        };
        let mut st = State {
            opts: &opts,
            stats: [zero(Phase::Stabilisation), zero(Phase::Optimisation), zero(Phase::GradientSampling)],
            perf: Some(best(1.0)),
            stab: None,
            stabilised: true,
            stall: 0,
            improved_cpu: 0.0,
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
