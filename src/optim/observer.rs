//! Watching a run: one [`IterRecord`] per iteration to an [`Observer`], which may stop the run
//! (`ControlFlow::Break` ⇒ `Termination::Interrupted`) but never change it. The record's scalar
//! part, [`Iteration`], is the iteration record every layer above passes on (`design` extends it
//! with its phase and the objective's components; `design::DesignIterRecord`). Trace writers and
//! progress bars live outside `optim` and implement `design`'s observer trait; `optim` does no I/O.

use serde::{Deserialize, Serialize};
use std::ops::ControlFlow;

/// Which solver produced an iteration.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SolverKind {
    /// BFGS with the weak-Wolfe line search.
    Bfgs,
    /// Gradient sampling (BCLOS 2020 Algorithm GS).
    GradientSampling,
}

/// One iteration, as every observer sees it (owned, so that the layers above can keep it and
/// pass it on).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Iteration {
    /// Which solver.
    pub solver: SolverKind,
    /// Index of the starting point (0 for a single run and for gradient sampling).
    pub start: usize,
    /// Iteration number, 1-based (0 is the starting point, reported once before the first step).
    pub iter: usize,
    /// f(x).
    pub f: f64,
    /// Norm of the smallest vector in the convex hull of the current gradient bundle.
    pub dnorm: f64,
    /// Step length t of this iteration's line search (0 for no move).
    pub step: f64,
    /// Objective evaluations so far in this call (`bfgs`, `gradient_sampling` or `hanso`).
    pub evals: usize,
    /// CPU seconds since the `RunControl` was created.
    pub cpu_s: f64,
}

/// What an observer sees after every iteration: the [`Iteration`] and the current point
/// (borrowed from the solver state). Derefs to the [`Iteration`].
#[derive(Debug, Clone, Copy)]
pub struct IterRecord<'a> {
    /// Current point.
    pub x: &'a [f64],
    /// The iteration's numbers.
    pub it: Iteration,
}

impl std::ops::Deref for IterRecord<'_> {
    type Target = Iteration;
    fn deref(&self) -> &Iteration {
        &self.it
    }
}

/// Receives every iteration; return `Break` to stop the run (`Termination::Interrupted`).
pub trait Observer {
    /// Called once per iteration (and once at iteration 0 with the starting point).
    fn on_iter(&mut self, rec: &IterRecord<'_>) -> ControlFlow<()> {
        let _ = rec;
        ControlFlow::Continue(())
    }
}

/// Observes nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoObserver;
impl Observer for NoObserver {}

/// Adapts a closure into an observer.
pub struct FnObserver<F>(pub F);
impl<F: FnMut(&IterRecord<'_>) -> ControlFlow<()>> Observer for FnObserver<F> {
    fn on_iter(&mut self, rec: &IterRecord<'_>) -> ControlFlow<()> {
        (self.0)(rec)
    }
}
