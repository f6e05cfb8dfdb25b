//! The two design objectives of a [`Problem`] of several plants (docs/ALGORITHMS.md §14.1), for
//! [`DesignObjective`](super::DesignObjective):
//!
//! ```text
//! stabilisation:  f_s = max( max_j s(A_cl,j), ε·s(Ak) )
//! performance:    f_p = max( max_{j ∈ U} w_j·g_j, ε‖K‖∞ ) + μ Σ_{j ∈ B} max(0, w_j·g_j − b_j)
//! ```
//!
//! (plain mode: without the ε terms; s = α, or ρ − 1 in discrete time). Where every plant of U
//! has the abscissa objective, f_p's controller term is ε·s(Ak) instead of ε‖K‖∞
//! ([`Problem::controller_term_is_abscissa`]): the g_j are then negative, and a positive ε‖K‖∞
//! would always be the max (none for a static gain, whose Ak is empty). The gradient is that of
//! the active term of each max (ties: the first plant, then the plants before the controller)
//! plus μ·w_j·∇g_j of every violated bound (at w_j·g_j = b_j exactly: none, an element of the
//! Clarke subdifferential). f_p = +∞ off the controllers that stabilise every plant (g_j = +∞ for
//! H∞, H2 and 1/r_C there; for the abscissa objective g_j ≥ 0 counts as +∞), for an ill-posed
//! loop, or where Ak is not stable (strong): the performance phase, as the single-plant one,
//! stays among stabilising controllers.

use crate::lti::{
    closed_loop_stability_grad, controller_hinf_grad, controller_stability_grad, stability_measure, Controller,
    ControllerGradient, HinfParams, LtiError,
};

use super::components::Components;
use super::problem::{plant_value, Problem, PENALTY_WEIGHT};

/// `acc += s·g`.
fn add_scaled(acc: &mut ControllerGradient, g: &ControllerGradient, s: f64) {
    for (a, b) in [(&mut acc.ak, &g.ak), (&mut acc.bk, &g.bk), (&mut acc.ck, &g.ck), (&mut acc.dk, &g.dk)] {
        for j in 0..a.ncols() {
            for i in 0..a.nrows() {
                a[(i, j)] += s * b[(i, j)];
            }
        }
    }
}

/// `s·g`.
pub(crate) fn scaled(g: &ControllerGradient, s: f64) -> ControllerGradient {
    let mut out =
        Controller { ak: g.ak.clone(), bk: g.bk.clone(), ck: g.ck.clone(), dk: g.dk.clone(), domain: g.domain };
    add_scaled(&mut out, g, s - 1.0);
    out
}

/// The largest of (value, gradient) pairs, NaN-safe (a NaN value wins, making f NaN); the first
/// of equal values.
fn arg_max(terms: impl IntoIterator<Item = (f64, Option<ControllerGradient>)>) -> (f64, Option<ControllerGradient>) {
    let mut best = (f64::NEG_INFINITY, None);
    for (v, g) in terms {
        if v.is_nan() {
            return (v, None);
        }
        if v > best.0 {
            best = (v, g);
        }
    }
    best
}

/// f_s and its components at `k` (module docs).
pub(crate) fn stabilisation(
    problem: &Problem,
    k: &Controller,
    strong: bool,
    eps: f64,
) -> (Components, Option<ControllerGradient>) {
    let mut c = Components::UNKNOWN;
    let nk = k.order();
    let mut terms = Vec::with_capacity(problem.terms.len() + 1);
    for t in &problem.terms {
        terms.push(match closed_loop_stability_grad(&t.plant, k) {
            Ok((a, g)) => (a, Some(g)),
            Err(_) => (f64::INFINITY, None),
        });
    }
    c.alpha_cl = terms.iter().map(|t| t.0).fold(f64::NEG_INFINITY, super::problem::nan_max);
    if nk > 0 {
        let (a, g) = controller_stability_grad(k);
        c.alpha_k = a;
        if strong {
            terms.push((eps * a, Some(scaled(&g, eps))));
        }
    }
    let (f, g) = arg_max(terms);
    c.f = f;
    (c, g)
}

/// Why a performance evaluation has no value.
pub(crate) enum NoValue {
    /// The stop hook fired inside a norm: abandoned, f = NaN.
    Interrupted,
}

/// f_p and its components at `k` (module docs); norms computed as `params` ask (its stop hook
/// abandons the evaluation: `Err(NoValue::Interrupted)`).
pub(crate) fn performance(
    problem: &Problem,
    k: &Controller,
    strong: bool,
    eps: f64,
    hinf_tol: f64,
    params: &HinfParams<'_>,
) -> Result<(Components, Option<ControllerGradient>), NoValue> {
    let mut c = Components::UNKNOWN;
    if k.order() > 0 {
        c.alpha_k = stability_measure(k.domain, k.ak.as_ref());
    }
    let mut maxed = Vec::with_capacity(problem.terms.len() + 1);
    let mut penalty = 0.0;
    let mut penalty_grad: Option<ControllerGradient> = None;
    for t in &problem.terms {
        let (g, grad) = match plant_value(&t.plant, t.objective, k, params) {
            Ok(v) => v,
            Err(LtiError::Interrupted(_)) => return Err(NoValue::Interrupted),
            Err(_) => (f64::INFINITY, k.clone()),
        };
        // The performance phase stays among controllers that stabilise every plant (as the
        // single-plant design, where ‖Tzw‖∞ = +∞ off them): a stability measure ≥ 0 is +∞ too.
        if !g.is_finite() || t.objective.means_unstable(g) {
            c.f = if g.is_nan() { f64::NAN } else { f64::INFINITY };
            return Ok((c, None));
        }
        let wg = t.weight * g;
        match t.bound {
            None => maxed.push((wg, Some(scaled(&grad, t.weight)))),
            Some(b) if wg > b => {
                penalty += PENALTY_WEIGHT * (wg - b);
                let s = PENALTY_WEIGHT * t.weight;
                match &mut penalty_grad {
                    Some(acc) => add_scaled(acc, &grad, s),
                    None => penalty_grad = Some(scaled(&grad, s)),
                }
            }
            Some(_) => {}
        }
    }
    c.gamma = if maxed.is_empty() { f64::NAN } else { arg_max(maxed.iter().cloned()).0 };
    if strong {
        let (norm, g) = controller_hinf_grad(k, hinf_tol);
        c.k_hinf = norm.value;
        if !norm.value.is_finite() {
            c.f = f64::INFINITY;
            return Ok((c, None));
        }
        if !problem.controller_term_is_abscissa() {
            maxed.push((eps * norm.value, Some(scaled(&g, eps))));
        } else if k.order() > 0 {
            let (a, g) = controller_stability_grad(k);
            maxed.push((eps * a, Some(scaled(&g, eps))));
        }
    }
    let (top, mut grad) = match arg_max(maxed) {
        (v, _) if v == f64::NEG_INFINITY => (0.0, Some(scaled(k, 0.0))), // every plant bounded, plain: feasibility only
        best => best,
    };
    c.f = top + penalty;
    if let (Some(acc), Some(p)) = (&mut grad, &penalty_grad) {
        add_scaled(acc, p, 1.0);
    }
    Ok((c, grad))
}
