//! Weak-Wolfe bracketing line search (Lewis & Overton 2013, §4.2; HANSO `linesch_ww`,
//! docs/ALGORITHMS.md §7.2).
//!
//! Along a descent direction d from x₀ (g₀ᵀd < 0) find t > 0 with
//!
//! * Armijo: f(x₀ + t d) < f(x₀) + c₁ t g₀ᵀd,
//! * weak curvature: ∇f(x₀ + t d)ᵀd > c₂ g₀ᵀd,
//!
//! (strict inequalities, as HANSO). t = 1 is tried first — essential for BFGS's superlinear
//! convergence on smooth functions. A bracket [α, β] starts as [0, ∞]: if Armijo fails β ← t,
//! else if curvature fails α ← t, else t is accepted. Next t = (α+β)/2 if β < ∞, else 2α.
//! A point where f is +∞ or NaN, or where ∇f has a non-finite entry, counts as an Armijo
//! failure, so a step into the region where f = +∞ is never accepted: the search backs off.
//!
//! Limits (HANSO): at most max(30, round(log₂(10⁵‖d‖))) bisections and
//! max(10, round(log₂(10⁵/‖d‖))) expansions. The weak (not strong) Wolfe conditions matter on
//! nonsmooth functions: the strong version can fail at kinks where the directional derivative
//! jumps, and is unnecessary for BFGS (Lewis & Overton 2013).
//!
//! # Deviation
//! HANSO treats a NaN gradient with a finite f as a curvature failure; here it is an Armijo
//! failure (the point is treated as outside the domain), so a returned point always has a finite
//! gradient that BFGS can use.

use super::objective::{usable, Evaluator};
use super::termination::Termination;

/// Minimum number of bisections allowed (HANSO).
pub(crate) const LS_MIN_BISECT: f64 = 30.0;
/// Minimum number of expansions allowed (HANSO).
pub(crate) const LS_MIN_EXPAND: f64 = 10.0;
/// Scale in the bisection/expansion limits log₂(10⁵‖d‖), log₂(10⁵/‖d‖) (HANSO).
pub(crate) const LS_LIMIT_SCALE: f64 = 1e5;
/// Hard cap on either limit (guards ‖d‖ → 0 or ∞, where the HANSO formulas blow up).
pub(crate) const LS_LIMIT_CAP: f64 = 2000.0;

/// Parameters of one search.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LsParams {
    /// Armijo parameter c₁.
    pub c1: f64,
    /// Curvature parameter c₂.
    pub c2: f64,
    /// Return immediately when a trial has f < fvalquit.
    pub fvalquit: f64,
}

/// How the search ended (HANSO `fail` flag).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum LsStatus {
    /// Both conditions hold at t (fail = 0), or f < fvalquit at t.
    Success,
    /// Bracketed but the bisection limit was hit (fail = 1); the α point is returned (α may be 0).
    Bracketed,
    /// Never bracketed within the expansion limit (fail = −1): f may be unbounded below.
    Unbounded,
    /// The budget ran out or the run was cancelled between trials; the α point is returned.
    Stopped(Termination),
}

/// Result: the accepted (or best safe) step and f, ∇f there.
#[derive(Debug, Clone)]
pub(crate) struct LsOutcome {
    pub t: f64,
    pub x: Vec<f64>,
    pub f: f64,
    pub g: Vec<f64>,
    pub status: LsStatus,
}

fn limit(v: f64, min: f64) -> usize {
    let r = if v.is_nan() { min } else { v.round().max(min) };
    r.min(LS_LIMIT_CAP) as usize
}

/// Weak-Wolfe search along `d` from (x0, f0, g0); requires g0ᵀd < 0 (checked by the caller).
pub(crate) fn weak_wolfe(ev: &mut Evaluator<'_>, x0: &[f64], f0: f64, g0: &[f64], d: &[f64], p: LsParams) -> LsOutcome {
    let n = x0.len();
    let dnorm = d.iter().map(|v| v * v).sum::<f64>().sqrt();
    let nbisect_max = limit((LS_LIMIT_SCALE * dnorm).log2(), LS_MIN_BISECT);
    let nexpand_max = limit((LS_LIMIT_SCALE / dnorm).log2(), LS_MIN_EXPAND);
    let g0d: f64 = g0.iter().zip(d).map(|(a, b)| a * b).sum();

    let (mut alpha, mut beta) = (0.0_f64, f64::INFINITY);
    // The α point (initially x0): Armijo holds there, it is the safe point to return.
    let mut xa = x0.to_vec();
    let mut fa = f0;
    let mut ga = g0.to_vec();
    let (mut nbisect, mut nexpand) = (0usize, 0usize);
    let mut t = 1.0_f64;
    let mut x = vec![0.0; n];
    let mut g = vec![0.0; n];

    let done = |t, x, f, g, status| LsOutcome { t, x, f, g, status };
    loop {
        for i in 0..n {
            x[i] = x0[i] + t * d[i];
        }
        // A trial is rejected unless f < max(Armijo bound, fvalquit): the objective may prove
        // f ≥ that bound cheaply instead of computing f (exact, see Objective::eval_below).
        let threshold = (f0 + p.c1 * t * g0d).max(p.fvalquit);
        let f = match ev.eval_checked_below(&x, &mut g, threshold) {
            Ok(f) => f,
            Err(reason) => return done(alpha, xa, fa, ga, LsStatus::Stopped(reason)),
        };
        let ok = usable(f, &g);
        if ok && f < p.fvalquit {
            return done(t, x, f, g, LsStatus::Success);
        }
        // Negated comparisons so that NaN counts as failure.
        let armijo = ok && f < f0 + p.c1 * t * g0d;
        if !armijo {
            beta = t;
        } else {
            let gd: f64 = g.iter().zip(d).map(|(a, b)| a * b).sum();
            if !(gd > p.c2 * g0d) {
                alpha = t;
                xa.copy_from_slice(&x);
                fa = f;
                ga.copy_from_slice(&g);
            } else {
                return done(t, x, f, g, LsStatus::Success);
            }
        }
        if beta < f64::INFINITY {
            if nbisect < nbisect_max {
                nbisect += 1;
                t = 0.5 * (alpha + beta);
            } else {
                return done(alpha, xa, fa, ga, LsStatus::Bracketed);
            }
        } else if nexpand < nexpand_max {
            nexpand += 1;
            t = 2.0 * alpha;
        } else {
            return done(alpha, xa, fa, ga, LsStatus::Unbounded);
        }
    }
}
