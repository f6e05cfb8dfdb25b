//! Budget and cancellation shared by everything in one run.
//!
//! CPU time is the calling **thread's** CPU time (`clock_gettime(CLOCK_THREAD_CPUTIME_ID)`), so
//! concurrent jobs on other threads do not eat each other's budget. Create the [`RunControl`] on
//! the thread that runs the optimiser: the clock of another thread is meaningless here.
//! The solvers check [`RunControl::cpu_exhausted`] and [`RunControl::cancelled`] between objective
//! evaluations (also inside line searches and sampling loops), so the budget is honoured to
//! within one evaluation.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// CPU seconds used so far by the calling thread: `clock_gettime(CLOCK_THREAD_CPUTIME_ID)`.
///
/// The one CPU clock of the crate (the optimiser's budget, the campaign's per-job `cpu_s` and the
/// benches all read it). Callers only ever take differences of two readings.
///
/// # Failure
/// If the clock cannot be read (the call cannot fail on Linux or macOS with a valid pointer;
/// a platform without a per-thread CPU clock would fail every time), this returns `0.0`: the
/// clock then stands still, elapsed CPU reads 0 and a CPU budget is never exhausted (runs end by
/// `maxit`, convergence or cancellation instead). Every derived number stays finite, so
/// journal lines and traces remain valid; a NaN here would turn every budget test false as
/// well, but would also reach the journal and make `RunControl::cpu_remaining` report 0.
pub fn thread_cpu_time() -> f64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `ts` is a valid, writable timespec; clock_gettime only writes into it.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    if rc != 0 {
        return 0.0;
    }
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

/// Shared budget (CPU seconds of this thread since [`RunControl::new`]) and an optional cancel flag.
#[derive(Debug, Clone)]
pub struct RunControl {
    start_cpu: f64,
    cpumax: f64,
    cancel: Option<Arc<AtomicBool>>,
}

impl RunControl {
    /// Start the clock now; `cpumax` in CPU seconds, `f64::INFINITY` for no limit
    /// (NaN or negative values are treated as 0, i.e. already exhausted).
    pub fn new(cpumax: f64) -> Self {
        let cpumax = if cpumax.is_nan() { 0.0 } else { cpumax.max(0.0) };
        RunControl { start_cpu: thread_cpu_time(), cpumax, cancel: None }
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

    /// The budget given to `new()`.
    pub fn cpumax(&self) -> f64 {
        self.cpumax
    }

    /// CPU seconds left (≥ 0; ∞ without a limit).
    pub fn cpu_remaining(&self) -> f64 {
        (self.cpumax - self.cpu_elapsed()).max(0.0)
    }

    /// True once `cpu_elapsed() ≥ cpumax`.
    pub fn cpu_exhausted(&self) -> bool {
        self.cpumax.is_finite() && self.cpu_elapsed() >= self.cpumax
    }

    /// True once the cancel flag (if any) is set.
    pub fn cancelled(&self) -> bool {
        self.cancel.as_ref().is_some_and(|c| c.load(Ordering::Relaxed))
    }
}
