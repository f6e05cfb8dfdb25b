//! Options of the solvers, with documented defaults and validation.
//!
//! Defaults: [`BfgsOptions`] follows HANSO 2.x `bfgs` (docs/ALGORITHMS.md §7.1) with `wolfe1 = 1e-4`
//! (HANSO 2.2/3.0; HANSO 2.0 had 0); [`GradSampOptions`] follows Algorithm GS of Burke, Curtis,
//! Lewis, Overton and Simões (2020) as used by HANSO 3.0 (docs/ALGORITHMS.md §7.4).
//! Override with struct-update syntax: `BfgsOptions { normtol: 1e-3, ..Default::default() }`.

use super::error::OptimError;
use serde::{Deserialize, Serialize};

/// Largest default gradient-bundle size (HANSO: `ngrad = min(100, 2n, n + 10)`).
pub const NGRAD_CAP: usize = 100;

/// Options of one BFGS run (HANSO 2.x `bfgs1run`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct BfgsOptions {
    /// Stop when dnorm ≤ normtol, dnorm = ‖smallest vector in the convex hull of the gradient
    /// bundle‖ (absolute). Default 1e-6 (HANSO `bfgs`; `hanso` uses 1e-4, HIFOO passes 1e-3).
    pub normtol: f64,
    /// Gradients are kept in the bundle while consecutive steps are ≤ evaldist (absolute,
    /// Euclidean). Default 1e-4 (HIFOO passes 1e-3).
    pub evaldist: f64,
    /// Maximum number of BFGS iterations for this start. Default 1000.
    pub maxit: usize,
    /// Armijo parameter c1 of the weak-Wolfe line search, 0 ≤ c1 < c2. Default 1e-4.
    pub wolfe1: f64,
    /// Weak-curvature parameter c2, c1 < c2 < 1. Default 0.5.
    pub wolfe2: f64,
    /// Bundle size; `None` = min(100, 2n, n + 10). Default `None`.
    pub ngrad: Option<usize>,
    /// Stop as soon as f < fvalquit (also at a line-search trial point). Default −∞.
    pub fvalquit: f64,
    /// Stop when ‖x‖₂ > xnormquit. Default +∞.
    pub xnormquit: f64,
    /// Stop when the line search bracketed but failed (HANSO `quitLSfail`). Default true.
    pub quit_ls_fail: bool,
    /// Scale H₀ = I by sᵀy/yᵀy before the first update (HANSO `scale`). Default true.
    pub scale: bool,
    /// Powell-type damping of the update as in GRANSO (Curtis, Mitchell & Overton 2017): with B = H⁻¹ (here
    /// Bs = −t·g_prev exactly, since s = −t·H·g_prev), if sᵀy < damping·sᵀBs replace y by
    /// θy + (1−θ)Bs, θ = (1−damping)·sᵀBs/(sᵀBs − sᵀy) (GRANSO: damping 1e-4, factor 0.9999).
    /// `None` (HANSO: no damping, skip the update when sᵀy ≤ 0). Default `None`.
    pub damping: Option<f64>,
    /// Relative eigenvalue floor for H: after every update, H ← H + h_floor·maxᵢ Hᵢᵢ·I, which
    /// keeps λ_min(H) ≥ h_floor·λ_max(H)/n, so H stays positive definite in floating point
    /// (a common quasi-Newton safeguard, bounding cond(H); not in HANSO). On partly smooth
    /// functions whose smooth manifold is hard to follow (Chebyshev–Rosenbrock, n = 4)
    /// unsafeguarded BFGS reaches the kinks to rounding level long before the minimiser and
    /// stops there (`NotDescent` / `LineSearchFailed`); with a floor of 1e-16…3e-14 it goes on to
    /// the minimiser. The floor sets an accuracy floor of its own (f ≈ 3e-10 at 3e-15, 3e-9 at
    /// 3e-14 on that problem). `None` (HANSO). Default `None`.
    pub h_floor: Option<f64>,
    /// Restart period: after every `restart_every` iterations H is set back to I (unscaled) and
    /// the run goes on from its current point, with its gradient bundle. On long nonsmooth runs
    /// H keeps the curvature of kinks the iterates have left, and its steps shrink: a run that
    /// crawls for thousands of iterations reaches lower minimisers with a periodic restart
    /// (docs/ALGORITHMS.md §7.1 has the measurements). 0: never (HANSO). Default 0.
    pub restart_every: usize,
}

impl Default for BfgsOptions {
    fn default() -> Self {
        BfgsOptions {
            normtol: 1e-6,
            evaldist: 1e-4,
            maxit: 1000,
            wolfe1: 1e-4,
            wolfe2: 0.5,
            ngrad: None,
            fvalquit: f64::NEG_INFINITY,
            xnormquit: f64::INFINITY,
            quit_ls_fail: true,
            scale: true,
            damping: None,
            h_floor: None,
            restart_every: 0,
        }
    }
}

pub(crate) fn check(ok: bool, field: &'static str, value: f64, range: &'static str) -> Result<(), OptimError> {
    if ok {
        Ok(())
    } else {
        Err(OptimError::Options { field, value, range })
    }
}

impl BfgsOptions {
    /// Check every field against its documented range.
    pub fn validate(&self) -> Result<(), OptimError> {
        check(self.normtol.is_finite() && self.normtol >= 0.0, "normtol", self.normtol, "finite and >= 0")?;
        check(self.evaldist.is_finite() && self.evaldist >= 0.0, "evaldist", self.evaldist, "finite and >= 0")?;
        check(self.wolfe1 >= 0.0 && self.wolfe1 < 1.0, "wolfe1", self.wolfe1, "in [0, 1)")?;
        check(self.wolfe2 > self.wolfe1 && self.wolfe2 < 1.0, "wolfe2", self.wolfe2, "in (wolfe1, 1)")?;
        if let Some(k) = self.ngrad {
            check(k >= 1, "ngrad", k as f64, ">= 1")?;
        }
        check(!self.fvalquit.is_nan(), "fvalquit", self.fvalquit, "not NaN")?;
        check(self.xnormquit > 0.0, "xnormquit", self.xnormquit, "> 0 (may be +inf)")?;
        if let Some(d) = self.damping {
            check((0.0..1.0).contains(&d), "damping", d, "in [0, 1)")?;
        }
        if let Some(d) = self.h_floor {
            check(d.is_finite() && d > 0.0 && d < 1.0, "h_floor", d, "in (0, 1)")?;
        }
        Ok(())
    }

    /// The bundle size for `nvar` variables.
    pub fn ngrad_for(&self, nvar: usize) -> usize {
        self.ngrad.unwrap_or_else(|| NGRAD_CAP.min(2 * nvar).min(nvar + 10).max(1))
    }
}

/// Options of gradient sampling: Algorithm GS of Burke, Curtis, Lewis, Overton, Simões (2020),
/// HANSO 3.0 defaults.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct GradSampOptions {
    /// Initial sampling radius ρ₀ (absolute, Euclidean ball). Default 0.1 (HANSO 3.0 `samprad0`).
    pub samprad0: f64,
    /// Initial stationarity target ν₀. Default 0.1 (HANSO 3.0 `target0`).
    pub target0: f64,
    /// Final sampling radius ρ_opt. Default 1e-6.
    pub samprad_opt: f64,
    /// Final stationarity target ν_opt. Default 1e-6.
    pub target_opt: f64,
    /// Factor θ_ρ applied to ρ when ‖d‖ ≤ ν. Default 0.1.
    pub samprad_factor: f64,
    /// Factor θ_ν applied to ν when ‖d‖ ≤ ν. Default 0.1.
    pub target_factor: f64,
    /// Number of sampled gradients per iteration (besides ∇f(x)); `None` = 2n. Default `None`.
    pub ngrad: Option<usize>,
    /// Sufficient-decrease parameter β of f(x − t d) < f(x) − β t ‖d‖². Default 1e-4.
    pub armijo: f64,
    /// Backtracking factor γ (t ← γ t). Default 0.5.
    pub backtrack: f64,
    /// Maximum number of iterations (sampling rounds). Default 10000.
    pub maxit: usize,
    /// Stop as soon as f < fvalquit. Default −∞.
    pub fvalquit: f64,
    /// In `hanso` (feature `test-support`), run gradient sampling only when the best BFGS point is not
    /// certified (dnorm > normtol), as HANSO 2.0 (which HIFOO 3.5 shipped with) did.
    /// Default true. Ignored by [`gradient_sampling`](super::gradient_sampling) itself.
    pub only_if_uncertified: bool,
}

impl Default for GradSampOptions {
    fn default() -> Self {
        GradSampOptions {
            samprad0: 0.1,
            target0: 0.1,
            samprad_opt: 1e-6,
            target_opt: 1e-6,
            samprad_factor: 0.1,
            target_factor: 0.1,
            ngrad: None,
            armijo: 1e-4,
            backtrack: 0.5,
            maxit: 10_000,
            fvalquit: f64::NEG_INFINITY,
            only_if_uncertified: true,
        }
    }
}

impl GradSampOptions {
    /// Check every field against its documented range.
    pub fn validate(&self) -> Result<(), OptimError> {
        let pos = |v: f64| v.is_finite() && v > 0.0;
        check(pos(self.samprad0), "samprad0", self.samprad0, "finite and > 0")?;
        check(pos(self.target0), "target0", self.target0, "finite and > 0")?;
        check(
            self.samprad_opt.is_finite() && self.samprad_opt >= 0.0,
            "samprad_opt",
            self.samprad_opt,
            "finite and >= 0",
        )?;
        check(self.target_opt.is_finite() && self.target_opt >= 0.0, "target_opt", self.target_opt, "finite and >= 0")?;
        check(
            self.samprad_factor > 0.0 && self.samprad_factor < 1.0,
            "samprad_factor",
            self.samprad_factor,
            "in (0, 1)",
        )?;
        check(self.target_factor > 0.0 && self.target_factor < 1.0, "target_factor", self.target_factor, "in (0, 1)")?;
        if let Some(k) = self.ngrad {
            check(k >= 1, "ngrad", k as f64, ">= 1")?;
        }
        check(self.armijo > 0.0 && self.armijo < 1.0, "armijo", self.armijo, "in (0, 1)")?;
        check(self.backtrack > 0.0 && self.backtrack < 1.0, "backtrack", self.backtrack, "in (0, 1)")?;
        check(!self.fvalquit.is_nan(), "fvalquit", self.fvalquit, "not NaN")?;
        Ok(())
    }

    /// Number of sampled gradients for `nvar` variables.
    pub fn ngrad_for(&self, nvar: usize) -> usize {
        self.ngrad.unwrap_or((2 * nvar).max(1))
    }
}

/// Options of the HANSO-style driver `hanso` (feature `test-support`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(default, deny_unknown_fields)]
pub struct HansoOptions {
    /// Options of every BFGS start.
    pub bfgs: BfgsOptions,
    /// Options of the gradient-sampling phase.
    pub gradsamp: GradSampOptions,
    /// Run gradient sampling from the best BFGS point. Default false (HANSO 3.0).
    pub gradient_sampling: bool,
}

impl HansoOptions {
    /// Validate both option sets.
    pub fn validate(&self) -> Result<(), OptimError> {
        self.bfgs.validate()?;
        self.gradsamp.validate()
    }
}
