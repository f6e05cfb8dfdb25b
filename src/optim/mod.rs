//! A minimiser for locally Lipschitz, nonsmooth, nonconvex functions x ∈ ℝⁿ ↦ (f, ∇f), where
//! f may be +∞ outside its domain: HANSO's method, hand-written because no Rust crate offers
//! BFGS for nonsmooth functions with a weak-Wolfe search, a gradient-bundle optimality
//! certificate and gradient sampling. It knows nothing about control.
//!
//! * [`bfgs`]: BFGS on the inverse Hessian with the weak-Wolfe line search
//!   (Lewis & Overton 2013, "Nonsmooth optimization via quasi-Newton methods", Math. Program.
//!   141:135–163), with HANSO 2.x's certificate: dnorm = ‖smallest vector in the convex hull of
//!   gradients at nearby iterates‖ and evaldist = the largest distance to those iterates.
//! * [`gradient_sampling`]: Algorithm GS of Burke, Curtis, Lewis, Overton & Simões (2020),
//!   "Gradient sampling methods for nonsmooth optimization" (HANSO 3.0's variant).
//! * `hanso` (feature `test-support`: the design makes its own sequence of starts,
//!   `design::search`): BFGS from several starts with a shared budget, then gradient sampling;
//!   the optimiser's tests and `benches/optim.rs` use it.
//! * [`random_starts`]: standard-normal starting points.
//! * [`min_norm_in_hull`]: the simplex QP behind both certificates.
//!
//! Structure (docs/ALGORITHMS.md §7.5): each solver has a state and a `step` (mathematics only); one driver
//! loop applies the termination tests in HANSO's order, the [`RunControl`] budget and cancel
//! flag, and calls the [`Observer`], which can stop a run but never change it. All randomness
//! comes from the `rng` passed in, so the same seed gives a bitwise-identical path.
//! See docs/ALGORITHMS.md §7 for the method and its defaults.

mod bfgs;
mod bundle;
mod control;
mod error;
mod gradsamp;
#[cfg(any(test, feature = "test-support"))]
mod hanso;
mod linesearch;
mod objective;
mod observer;
mod options;
mod qp;
mod solver;
mod starts;
mod termination;
#[cfg(any(test, feature = "test-support"))]
pub mod test_problems;

pub use bfgs::{bfgs, BfgsState};
pub use control::{thread_cpu_time, RunControl};
pub use error::OptimError;
pub use gradsamp::{gradient_sampling, GradSampState, GS_MAX_CONTRACT, GS_MIN_STEP_REL};
#[cfg(any(test, feature = "test-support"))]
pub use hanso::{hanso, HansoResult};
pub use objective::{FnObjective, Objective};
pub use observer::{FnObserver, IterRecord, Iteration, NoObserver, Observer, SolverKind};
pub use options::{BfgsOptions, GradSampOptions, HansoOptions, NGRAD_CAP};
pub use qp::{min_norm_clarabel, min_norm_dense, min_norm_in_hull, MinNormResult, QpMethod};
pub use solver::OptimResult;
pub use starts::random_starts;
pub use termination::Termination;

#[cfg(test)]
mod tests;
