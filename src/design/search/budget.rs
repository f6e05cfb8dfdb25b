//! What ends the search, and what each part of it may spend (docs/ALGORITHMS.md §8.3).
//!
//! # When it stops
//! Before each new local search (and within one, between evaluations) the run stops on the CPU
//! budget `cpumax`, the evaluation budget `maxevals`, a cancel request, or when `max_starts`
//! local searches were made. The **stall rule**: after the first starts, the search stops once
//! `stall_starts` consecutive local searches have not lowered the best objective by at least
//! `stall_rtol`·|best| (f_h once a stable point exists; before that, f_s, whose improvements count
//! at least `stall_rtol` in absolute terms near 0, and only if no budget is finite).
//! The stall rule in CPU time (`stall_cpu` > 0) ends the run the same way once `stall_cpu` CPU
//! seconds have passed since the last such improvement (or since the run began).
//! `stall_starts = 0` is HIFOO's search. With `spend_budget` (the default) the stall rule ends
//! only runs that no budget bounds: a run with a finite `cpumax`, `maxevals` or `max_starts`
//! goes on until that budget ends it, since more local searches can only lower the best
//! objective. Stabilisation is restarted, never given up, until a budget ends the run.
//!
//! # Gradient sampling on the incumbent
//! If gradient sampling is on, [`GS_RESERVE`] of each budget (CPU and evaluations) is kept for
//! it once a stable point is known: from then on the local searches run under the remaining
//! part, then gradient sampling on f_h runs from the best point under the whole budget. With
//! `return_gs_reserve` (the default) gradient sampling runs on the incumbent where HIFOO's search
//! runs it — right after HIFOO's `nrand` first starts, with the generator in the same state, so
//! the incumbent is from then on HIFOO's own result, bit for bit, and the search can only end
//! below it — and the search goes on under the whole budget less [`GS_RESERVE_FACTOR`] times
//! what that gradient sampling took (CPU seconds and evaluations; the most measured so far, at
//! most the first reserve; this gradient sampling itself gets at most the first reserve, so that
//! a small evaluation budget is not spent on it). Whenever the search's share is spent, gradient
//! sampling runs again from the incumbent if it changed, and the search goes on with what that
//! leaves, first resuming the incumbent's local search if the budget or `maxit` cut it
//! (`continue_at_maxit`), until a round gives nothing back; at the end gradient sampling runs
//! from the incumbent only if it changed since the last one. While nothing was measured (no
//! stable point after the first starts, or a certified incumbent) the first reserve stays. The
//! final incumbent thus always had its gradient sampling (or a certificate), as without the
//! option.

use crate::optim::{RunControl, Termination};

use super::{Search, State};
use crate::design::outcome::{DesignError, SearchStop};

/// Share of the CPU and evaluation budgets kept for the final gradient sampling (when enabled).
pub const GS_RESERVE: f64 = 0.1;

/// With `return_gs_reserve`: the reserve kept after a gradient sampling on the incumbent is this
/// many times what it took (CPU seconds and evaluations), at most [`GS_RESERVE`] of the budget.
pub const GS_RESERVE_FACTOR: f64 = 2.0;

pub(super) fn stop_of(t: Termination) -> Option<SearchStop> {
    match t {
        Termination::CpuBudget => Some(SearchStop::Budget),
        Termination::EvalBudget => Some(SearchStop::Maxevals),
        Termination::Interrupted => Some(SearchStop::Interrupted),
        _ => None,
    }
}

pub(super) fn ctl_stop(ctl: &RunControl) -> Option<SearchStop> {
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
pub(super) fn improves(new: f64, old: f64, rtol: f64, abs_floor: f64) -> bool {
    new.is_finite() && (!old.is_finite() || new < old - rtol * old.abs().max(abs_floor))
}

/// Whether the continued search must not start another local search: `Starts` if there is none
/// (`stall_starts = 0`, HIFOO's search), `Stall` if the stall rule ends it (module docs).
pub(super) fn continued_stop(st: &State<'_>, search_ctl: &RunControl) -> Option<SearchStop> {
    let opts = st.opts;
    if opts.stall_starts == 0 {
        return Some(SearchStop::Starts);
    }
    // Stabilisation is never given up while a budget bounds the run: the stall rule
    // applies once a stable point is known (or when nothing else would end the run),
    // and with `spend_budget` only when nothing else would end the run.
    let bounded = search_ctl.cpumax().is_finite() || opts.maxevals.is_some() || opts.max_starts.is_some();
    let stall_ends = !bounded || (st.stabilised && !opts.spend_budget);
    let cpu_stalled = opts.stall_cpu > 0.0 && search_ctl.cpu_elapsed() - st.improved_cpu >= opts.stall_cpu;
    ((st.stall >= opts.stall_starts || cpu_stalled) && stall_ends).then_some(SearchStop::Stall)
}

/// What `return_gs_reserve` has done so far (module docs).
#[derive(Debug, Default)]
pub(super) struct GsRounds {
    /// The first reserve (CPU seconds, evaluations): the most that is ever kept.
    pub(super) first: (f64, usize),
    /// The reserve kept now.
    pub(super) kept: (f64, usize),
    /// The incumbent as the last gradient sampling left it.
    pub(super) at: Option<Vec<f64>>,
    /// Gradient sampling ran at least once.
    pub(super) ran: bool,
    /// The incumbent as the last gradient sampling that actually ran left it.
    pub(super) treated: Option<Vec<f64>>,
    /// The step after HIFOO's first starts was taken.
    pub(super) after_first: bool,
    /// No round is left to give.
    pub(super) done: bool,
}

impl Search<'_, '_, '_> {
    /// `return_gs_reserve`, after HIFOO's first starts and whenever the search has spent its share
    /// of the budget: gradient sampling on the incumbent (if it changed since the last one), then
    /// the control of the search from here — the whole budget less [`GS_RESERVE_FACTOR`] times the
    /// most a gradient sampling took, at most the first reserve; the whole budget when the share
    /// is spent and gradient sampling had nothing to do — or None if nothing was measured or that
    /// share is already spent (module docs).
    pub(super) fn return_reserve(
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
}
