//! The function to minimise: x ∈ ℝⁿ ↦ (f(x), ∇f(x)), f locally Lipschitz and differentiable
//! almost everywhere, possibly +∞ outside its domain.

use super::control::RunControl;
use super::termination::Termination;

/// A function to minimise together with its gradient.
pub trait Objective {
    /// Number of variables n.
    fn nvar(&self) -> usize;
    /// f(x), writing ∇f(x) into `g` (len nvar). Outside the domain return f = +∞ (g: anything,
    /// e.g. NaN). NaN f is treated like +∞ by the line search.
    fn eval(&mut self, x: &[f64], g: &mut [f64]) -> f64;
    /// f(x) at a trial point that is of use only if f(x) < `threshold` (a line search's Armijo
    /// bound). An objective that can show f(x) ≥ `threshold` more cheaply than computing f may
    /// instead return any v with `threshold` ≤ v ≤ f(x) and fill `g` with NaN: the caller then
    /// rejects the point exactly as it would have with the true f. Default: [`Objective::eval`].
    fn eval_below(&mut self, x: &[f64], g: &mut [f64], threshold: f64) -> f64 {
        let _ = threshold;
        self.eval(x, g)
    }
    /// The unit of the gradient that [`Objective::eval`] returned at `x`, a point it has just
    /// evaluated; used by the optimality certificate only, which takes each gradient of its
    /// bundle as g / unit (`bundle` module). Default 1: HANSO's certificate.
    ///
    /// For an objective that is a max of terms of very different weights, f = max(f₁, ε·f₂),
    /// return the weight of the term that sets f at `x` (ε where ε·f₂ > f₁). Zero lies in the
    /// convex hull of some gradients exactly when it lies in the hull of any positive multiples of
    /// them, so what is stationary does not change; but the smallest vector of the hull of
    /// {∇f₁, ε∇f₂} is at most ε‖∇f₂‖ — below an absolute tolerance merely because ε is small —
    /// while that of {∇f₁, ∇f₂} is small only where the two terms' gradients nearly cancel.
    fn gradient_unit(&self, x: &[f64]) -> f64 {
        let _ = x;
        1.0
    }
}

/// Adapts a closure `FnMut(x, g) -> f` with a fixed dimension into an [`Objective`].
pub struct FnObjective<F> {
    nvar: usize,
    f: F,
}

impl<F: FnMut(&[f64], &mut [f64]) -> f64> FnObjective<F> {
    /// Wrap `f` as an objective in `nvar` variables.
    pub fn new(nvar: usize, f: F) -> Self {
        FnObjective { nvar, f }
    }
}

impl<F: FnMut(&[f64], &mut [f64]) -> f64> Objective for FnObjective<F> {
    fn nvar(&self) -> usize {
        self.nvar
    }
    fn eval(&mut self, x: &[f64], g: &mut [f64]) -> f64 {
        (self.f)(x, g)
    }
}

/// True if f and every gradient entry are finite: the point lies in the domain and its
/// gradient can be used. Everything else is treated as "outside" (Armijo failure).
pub(crate) fn usable(f: f64, g: &[f64]) -> bool {
    f.is_finite() && g.iter().all(|v| v.is_finite())
}

/// The objective as the solvers see it: counts evaluations and knows the budget, so that every
/// loop can stop between two evaluations.
pub(crate) struct Evaluator<'a> {
    obj: &'a mut dyn Objective,
    pub(crate) ctl: &'a RunControl,
    /// Evaluations made through this evaluator.
    pub(crate) evals: usize,
}

impl<'a> Evaluator<'a> {
    pub(crate) fn new(obj: &'a mut dyn Objective, ctl: &'a RunControl) -> Self {
        Evaluator { obj, ctl, evals: 0 }
    }

    /// Evaluate without any budget check (used for the starting point).
    pub(crate) fn eval(&mut self, x: &[f64], g: &mut [f64]) -> f64 {
        self.evals += 1;
        self.ctl.count_eval();
        self.obj.eval(x, g)
    }

    /// `Some(reason)` if the run must stop before the next evaluation.
    pub(crate) fn must_stop(&self) -> Option<Termination> {
        if self.ctl.cancelled() {
            Some(Termination::Interrupted)
        } else if self.ctl.cpu_exhausted() {
            Some(Termination::CpuBudget)
        } else if self.ctl.evals_exhausted() {
            Some(Termination::EvalBudget)
        } else {
            None
        }
    }

    /// [`Objective::gradient_unit`] at `x`, a positive finite number (1 otherwise).
    pub(crate) fn gradient_unit(&self, x: &[f64]) -> f64 {
        let u = self.obj.gradient_unit(x);
        if u.is_finite() && u > 0.0 {
            u
        } else {
            1.0
        }
    }

    /// Evaluate unless the budget is spent or the run cancelled.
    pub(crate) fn eval_checked(&mut self, x: &[f64], g: &mut [f64]) -> Result<f64, Termination> {
        if let Some(t) = self.must_stop() {
            return Err(t);
        }
        Ok(self.eval(x, g))
    }

    /// [`Evaluator::eval_checked`] for a point of use only if f < `threshold`
    /// ([`Objective::eval_below`]).
    pub(crate) fn eval_checked_below(&mut self, x: &[f64], g: &mut [f64], threshold: f64) -> Result<f64, Termination> {
        if let Some(t) = self.must_stop() {
            return Err(t);
        }
        self.evals += 1;
        self.ctl.count_eval();
        Ok(self.obj.eval_below(x, g, threshold))
    }
}
