//! Why a solver stopped: a typed reason, `Copy` and serde, in the order of HANSO's tests
//! (docs/ALGORITHMS.md §7.1; HANSO `bfgs1run` `info` codes are available via [`Termination::hanso_info`]).

use serde::{Deserialize, Serialize};

/// Why a BFGS or gradient-sampling run stopped. These are outcomes (the point returned is the
/// best one found and is trustworthy); failures without a usable point are
/// [`OptimError`](super::OptimError)s.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Termination {
    /// The certificate test passed: dnorm ≤ normtol (HANSO info 0).
    Certified,
    /// `maxit` iterations done (info 1).
    MaxIters,
    /// f < fvalquit (info 2).
    TargetReached,
    /// ‖x‖ > xnormquit (info 3).
    XNormExceeded,
    /// The CPU budget of the [`RunControl`](super::RunControl) is spent (info 4).
    CpuBudget,
    /// The evaluation budget (`maxevals`) of the [`RunControl`](super::RunControl) is spent.
    EvalBudget,
    /// f or ∇f not finite at the start (info 5); only seen in `NotRun` reasons and results of
    /// the multi-start driver, the solvers themselves return `Err(NonFiniteStart)`.
    NonFiniteStart,
    /// The search direction is not a descent direction, gᵀp ≥ 0 or NaN (info 6).
    NotDescent,
    /// The line search bracketed a step but could not satisfy the Wolfe conditions — the typical
    /// end at a nonsmooth minimiser (info 7). For gradient sampling: backtracking failed.
    LineSearchFailed,
    /// The line search never bracketed: f appears unbounded below along the direction (info 8).
    Unbounded,
    /// The observer returned `Break`, or the cancel flag of the `RunControl` was set.
    Interrupted,
    /// Gradient sampling met its final targets: ‖d‖ ≤ ν_opt with sampling radius ρ ≤ ρ_opt.
    GradSampConverged,
}

impl Termination {
    /// One line for logs and reports.
    pub fn text(self) -> &'static str {
        match self {
            Termination::Certified => {
                "certified: smallest vector in the convex hull of nearby gradients is below normtol"
            }
            Termination::MaxIters => "maximum number of iterations reached",
            Termination::TargetReached => "f dropped below fvalquit",
            Termination::XNormExceeded => "norm of x exceeded xnormquit",
            Termination::CpuBudget => "CPU time budget exhausted",
            Termination::EvalBudget => "evaluation budget (maxevals) exhausted",
            Termination::NonFiniteStart => "f or its gradient is not finite at the starting point",
            Termination::NotDescent => "search direction is not a descent direction",
            Termination::LineSearchFailed => "line search bracketed a step but could not satisfy the Wolfe conditions",
            Termination::Unbounded => "line search never bracketed: f may be unbounded below",
            Termination::Interrupted => "interrupted by the observer or the cancel flag",
            Termination::GradSampConverged => "gradient sampling reached its stationarity target at its final radius",
        }
    }

    /// HANSO's `info` code for comparison with MATLAB runs (`None` where HANSO has no code).
    pub fn hanso_info(self) -> Option<u8> {
        match self {
            Termination::Certified => Some(0),
            Termination::MaxIters => Some(1),
            Termination::TargetReached => Some(2),
            Termination::XNormExceeded => Some(3),
            Termination::CpuBudget => Some(4),
            Termination::NonFiniteStart => Some(5),
            Termination::NotDescent => Some(6),
            Termination::LineSearchFailed => Some(7),
            Termination::Unbounded => Some(8),
            Termination::Interrupted | Termination::GradSampConverged | Termination::EvalBudget => None,
        }
    }

    /// True for reasons that end a whole multi-start run (budget, cancellation, targets).
    pub fn ends_run(self) -> bool {
        matches!(
            self,
            Termination::CpuBudget
                | Termination::EvalBudget
                | Termination::Interrupted
                | Termination::TargetReached
                | Termination::XNormExceeded
        )
    }
}

impl std::fmt::Display for Termination {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.text())
    }
}
