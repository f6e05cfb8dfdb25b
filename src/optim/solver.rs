//! The single driver loop shared by BFGS and gradient sampling (argmin's split: a solver state,
//! a `step` that is mathematics only, and one loop that applies the termination tests in HANSO's
//! order, the budget, the cancel flag and the observer).

use super::control::RunControl;
use super::error::OptimError;
use super::objective::{Evaluator, Objective};
use super::observer::{IterRecord, Iteration, Observer, SolverKind};
use super::termination::Termination;
use serde::{Deserialize, Serialize};
use std::ops::ControlFlow;

/// Result of one solver run (the best point it found, with its certificate).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OptimResult {
    /// The final (best) point.
    pub x: Vec<f64>,
    /// f(x).
    pub f: f64,
    /// ∇f(x).
    pub g: Vec<f64>,
    /// Certificate: ‖smallest vector in the convex hull of the gradients taken near x‖.
    pub dnorm: f64,
    /// Certificate: largest distance from x to a point whose gradient is in that hull.
    pub evaldist: f64,
    /// Why the run stopped.
    pub termination: Termination,
    /// Iterations done.
    pub iters: usize,
    /// Objective evaluations made by this run.
    pub evals: usize,
    /// `ctl.cpu_elapsed()` when the run ended.
    pub cpu_s: f64,
}

/// Generic limits applied by the driver.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Limits {
    pub maxit: usize,
    pub fvalquit: f64,
    pub xnormquit: f64,
}

/// What the driver needs to see of a solver state.
pub(crate) trait SolverState {
    fn x(&self) -> &[f64];
    fn f(&self) -> f64;
    fn dnorm(&self) -> f64;
}

/// Implements [`SolverState`] for a state struct with the fields `x`, `f` and `dnorm`.
macro_rules! solver_state {
    ($state:ty) => {
        impl $crate::optim::solver::SolverState for $state {
            fn x(&self) -> &[f64] {
                &self.x
            }
            fn f(&self) -> f64 {
                self.f
            }
            fn dnorm(&self) -> f64 {
                self.dnorm
            }
        }
    };
}
pub(crate) use solver_state;

pub(crate) trait Solver {
    type State: SolverState;
    const KIND: SolverKind;
    fn limits(&self) -> Limits;
    /// Evaluate at x0 and set up the state; `Err(NonFiniteStart)` if f or ∇f is not finite.
    fn init(&mut self, ev: &mut Evaluator<'_>, x0: &[f64]) -> Result<Self::State, OptimError>;
    /// One iteration; `Ok(step length)` or `Err(reason)` to stop now (state stays consistent).
    fn step(&mut self, ev: &mut Evaluator<'_>, s: &mut Self::State) -> Result<f64, Termination>;
    /// The solver's own tests, applied after f < fvalquit and ‖x‖ > xnormquit and before the CPU
    /// and iteration limits (HANSO order). `initial`: at the starting point, before any step.
    fn converged(&self, s: &Self::State, initial: bool) -> Option<Termination>;
    /// Build the result with its certificate.
    fn result(&self, ev: &mut Evaluator<'_>, s: Self::State, termination: Termination, iters: usize) -> OptimResult;
}

fn norm(x: &[f64]) -> f64 {
    x.iter().map(|v| v * v).sum::<f64>().sqrt()
}

/// What the observer sees of state `s` at iteration `iter` (`step`: this iteration's step length).
fn record<'s, S: Solver>(s: &'s S::State, start: usize, iter: usize, step: f64, ev: &Evaluator<'_>) -> IterRecord<'s> {
    IterRecord {
        x: s.x(),
        it: Iteration {
            solver: S::KIND,
            start,
            iter,
            f: s.f(),
            dnorm: s.dnorm(),
            step,
            evals: ev.evals,
            cpu_s: ev.ctl.cpu_elapsed(),
        },
    }
}

/// `Err(DimensionMismatch)` unless x0 has `obj.nvar()` entries.
pub(crate) fn check_dims(obj: &dyn Objective, x0: &[f64]) -> Result<(), OptimError> {
    if x0.len() != obj.nvar() {
        return Err(OptimError::DimensionMismatch { what: "x0", expected: obj.nvar(), got: x0.len() });
    }
    Ok(())
}

/// Run `solver` on `obj` from x0 to termination (x0 checked against `obj.nvar()`).
pub(crate) fn run<S: Solver>(
    solver: &mut S,
    obj: &mut dyn Objective,
    x0: &[f64],
    start: usize,
    ctl: &RunControl,
    obs: &mut dyn Observer,
) -> Result<OptimResult, OptimError> {
    check_dims(obj, x0)?;
    let ev = &mut Evaluator::new(obj, ctl);
    let lim = solver.limits();
    let mut s = solver.init(ev, x0)?;
    let mut iter = 0usize;
    let mut step = 0.0;
    loop {
        let flow = obs.on_iter(&record::<S>(&s, start, iter, step, ev));
        let term = if s.f() < lim.fvalquit {
            Some(Termination::TargetReached)
        } else if norm(s.x()) > lim.xnormquit {
            Some(Termination::XNormExceeded)
        } else if let Some(t) = solver.converged(&s, iter == 0) {
            Some(t)
        } else if ctl.cpu_exhausted() {
            Some(Termination::CpuBudget)
        } else if ctl.evals_exhausted() {
            Some(Termination::EvalBudget)
        } else if iter >= lim.maxit {
            Some(Termination::MaxIters)
        } else if flow == ControlFlow::Break(()) || ctl.cancelled() {
            Some(Termination::Interrupted)
        } else {
            None
        };
        if let Some(t) = term {
            return Ok(solver.result(ev, s, t, iter));
        }
        iter += 1;
        match solver.step(ev, &mut s) {
            Ok(t) => step = t,
            Err(t) => {
                // Report the (possibly partially advanced) state once more, then stop.
                let _ = obs.on_iter(&record::<S>(&s, start, iter, 0.0, ev));
                // A trial point may have met the target before the budget check fired.
                let t = if s.f() < lim.fvalquit { Termination::TargetReached } else { t };
                return Ok(solver.result(ev, s, t, iter));
            }
        }
    }
}
