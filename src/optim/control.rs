//! Budget and cancellation shared by everything in one run.
//!
//! CPU time is the calling **thread's** CPU time (`clock_gettime(CLOCK_THREAD_CPUTIME_ID)`), so
//! concurrent jobs on other threads do not eat each other's budget. Create the [`RunControl`] on
//! the thread that runs the optimiser: the clock of another thread is meaningless here.
//! The solvers check [`RunControl::cpu_exhausted`] and [`RunControl::cancelled`] between objective
//! evaluations (also inside line searches and sampling loops), so the budget is honoured to
//! within one evaluation.
//!
//! An optional **evaluation budget** (`maxevals`, [`RunControl::with_maxevals`]) counts objective
//! evaluations over the whole run (every solver call made with this control or a clone of it
//! shares one counter). Unlike CPU time it does not depend on the machine or its load, so a run
//! stopped by it is reproducible bit for bit.

use std::sync::atomic::{AtomicBool, AtomicU64, AtomicUsize, Ordering};
use std::sync::Arc;

pub use crate::numeric::thread_cpu_time;

/// Shared budget (CPU seconds of this thread since [`RunControl::new`], and optionally a number
/// of objective evaluations) and an optional cancel flag. Clones share the clock, the evaluation
/// counter and the cancel flag.
#[derive(Debug, Clone)]
pub struct RunControl {
    start_cpu: f64,
    /// Budget in CPU seconds (thread CPU time, not wall-clock time).
    cpumax: f64,
    cancel: Option<Arc<AtomicBool>>,
    evals: Arc<AtomicUsize>,
    maxevals: Option<usize>,
    /// CPU seconds held back from `cpumax` for work after the run (f64 bits; shared by clones).
    reserve: Arc<AtomicU64>,
}

impl RunControl {
    /// Start the clock now; `cpumax` in CPU seconds (thread CPU time, not wall-clock time),
    /// `f64::INFINITY` for no limit
    /// (NaN or negative values are treated as 0, i.e. already exhausted).
    pub fn new(cpumax: f64) -> Self {
        let cpumax = if cpumax.is_nan() { 0.0 } else { cpumax.max(0.0) };
        RunControl {
            start_cpu: thread_cpu_time(),
            cpumax,
            cancel: None,
            evals: Arc::default(),
            maxevals: None,
            reserve: Arc::default(),
        }
    }

    /// Set an evaluation budget: once [`Self::evals`] ≥ `maxevals`, the run stops with
    /// `Termination::EvalBudget` before the next evaluation (`None`: no limit).
    pub fn with_maxevals(mut self, maxevals: Option<usize>) -> Self {
        self.maxevals = maxevals;
        self
    }

    /// A control with smaller limits on the same clock, counter and cancel flag: CPU budget
    /// `cpu_fraction · cpumax`, evaluation budget `⌊evals_fraction · maxevals⌋` (fractions in
    /// [0, 1]). Used to keep part of a budget for a final stage.
    pub fn sub_budget(&self, cpu_fraction: f64, evals_fraction: f64) -> RunControl {
        let mut c = self.clone();
        if c.cpumax.is_finite() {
            c.cpumax *= cpu_fraction.clamp(0.0, 1.0);
        }
        c.maxevals = c.maxevals.map(|m| (m as f64 * evals_fraction.clamp(0.0, 1.0)).floor() as usize);
        c
    }

    /// A control with limits `cpu_s` CPU seconds and `evals` evaluations below this one's (not
    /// below 0), on the same clock, counter and cancel flag: keeps an absolute amount of a budget
    /// for a final stage. A missing limit stays missing.
    pub fn less(&self, cpu_s: f64, evals: usize) -> RunControl {
        let mut c = self.clone();
        if c.cpumax.is_finite() && cpu_s.is_finite() {
            c.cpumax = (c.cpumax - cpu_s.max(0.0)).max(0.0);
        }
        c.maxevals = c.maxevals.map(|m| m.saturating_sub(evals));
        c
    }

    /// Counts one objective evaluation (called by the solvers' evaluator).
    pub fn count_eval(&self) {
        self.evals.fetch_add(1, Ordering::Relaxed);
    }

    /// Objective evaluations counted so far.
    pub fn evals(&self) -> usize {
        self.evals.load(Ordering::Relaxed)
    }

    /// The evaluation budget, if any.
    pub fn maxevals(&self) -> Option<usize> {
        self.maxevals
    }

    /// True once the evaluation budget (if any) is spent.
    pub fn evals_exhausted(&self) -> bool {
        self.maxevals.is_some_and(|m| self.evals() >= m)
    }

    /// Attach a cancel flag: once it is set, the run stops with `Termination::Interrupted`
    /// at the next check (between evaluations).
    pub fn with_cancel(mut self, flag: Arc<AtomicBool>) -> Self {
        self.cancel = Some(flag);
        self
    }

    /// CPU seconds of this thread since `new()`.
    pub fn cpu_elapsed(&self) -> f64 {
        thread_cpu_time() - self.start_cpu
    }

    /// The budget given to `new()`, in CPU seconds (thread CPU time).
    pub fn cpumax(&self) -> f64 {
        self.cpumax
    }

    /// Holds back `seconds` of the CPU budget (the largest value asked so far; shared by clones
    /// and sub-budgets) for work the caller must still do after the run, such as recomputing its
    /// result: the run then counts as exhausted that much earlier, so that work ends near
    /// `cpumax` rather than after it. Ignored if not finite and positive.
    pub fn reserve_cpu(&self, seconds: f64) {
        if seconds.is_finite() && seconds > 0.0 {
            let _ = self.reserve.fetch_update(Ordering::Relaxed, Ordering::Relaxed, |old| {
                (seconds > f64::from_bits(old)).then(|| seconds.to_bits())
            });
        }
    }

    /// The CPU seconds held back by [`Self::reserve_cpu`] (0 if none).
    pub fn cpu_reserved(&self) -> f64 {
        f64::from_bits(self.reserve.load(Ordering::Relaxed))
    }

    /// CPU seconds left (≥ 0; ∞ without a limit), after the reserve.
    pub fn cpu_remaining(&self) -> f64 {
        (self.cpumax - self.cpu_reserved() - self.cpu_elapsed()).max(0.0)
    }

    /// True once `cpu_elapsed() + cpu_reserved() ≥ cpumax`.
    pub fn cpu_exhausted(&self) -> bool {
        self.cpumax.is_finite() && self.cpu_elapsed() + self.cpu_reserved() >= self.cpumax
    }

    /// True once the cancel flag (if any) is set.
    pub fn cancelled(&self) -> bool {
        self.cancel.as_ref().is_some_and(|c| c.load(Ordering::Relaxed))
    }
}

#[cfg(test)]
mod tests {
    use super::RunControl;

    #[test]
    fn reserve_is_shared_monotone_and_counts_against_the_budget() {
        let ctl = RunControl::new(1e6);
        let sub = ctl.sub_budget(0.9, 1.0);
        assert_eq!(ctl.cpu_reserved(), 0.0);
        sub.reserve_cpu(3.0);
        ctl.reserve_cpu(2.0); // smaller: ignored
        ctl.reserve_cpu(f64::NAN);
        ctl.reserve_cpu(-1.0);
        assert_eq!(ctl.cpu_reserved(), 3.0, "clones and sub-budgets share the largest reserve");
        assert_eq!(sub.clone().cpu_reserved(), 3.0);
        assert!(ctl.cpu_remaining() <= 1e6 - 3.0);
        assert!(!ctl.cpu_exhausted());
        ctl.reserve_cpu(2e6);
        assert!(ctl.cpu_exhausted() && sub.cpu_exhausted(), "a reserve beyond the budget exhausts it");
        assert_eq!(ctl.cpu_remaining(), 0.0);
        let unlimited = RunControl::new(f64::INFINITY);
        unlimited.reserve_cpu(1e9);
        assert!(!unlimited.cpu_exhausted(), "no limit, nothing to exhaust");
    }

    #[test]
    fn less_lowers_both_limits_by_absolute_amounts() {
        let ctl = RunControl::new(10.0).with_maxevals(Some(100));
        let l = ctl.less(4.0, 30);
        assert_eq!((l.cpumax(), l.maxevals()), (6.0, Some(70)));
        let all = ctl.less(20.0, 200);
        assert_eq!((all.cpumax(), all.maxevals()), (0.0, Some(0)), "not below 0");
        assert!(all.cpu_exhausted() && all.evals_exhausted());
        let unlimited = RunControl::new(f64::INFINITY).less(5.0, 5);
        assert_eq!((unlimited.cpumax(), unlimited.maxevals()), (f64::INFINITY, None), "a missing limit stays missing");
        l.count_eval();
        assert_eq!(ctl.evals(), 1, "same counter");
    }
}
