//! The reciprocal of the complex stability radius of a closed loop and its gradient with respect
//! to the controller (HIFOO's stability-radius objective; docs/ALGORITHMS.md §13.4).
//!
//! For Hurwitz A the complex stability radius r_C(A) = min{‖Δ‖₂ : A + Δ not Hurwitz, Δ complex}
//! is inf_ω σmin(iωI − A) (Hinrichsen & Pritchard 1986), so
//!
//! ```text
//! 1/r_C(A) = sup_ω σmax((iωI − A)⁻¹) = ‖(sI − A)⁻¹‖∞,
//! ```
//!
//! the H∞ norm of the system (A, I, I, 0), +∞ if A is not Hurwitz. Its value is the crate's
//! [`hinf_norm`](super::hinf::hinf_norm) on that system (the level-set method with all its
//! safeguards, §5), its gradient with respect to A is §6.1's G_A = Re(ā bᵀ) at the peak with
//! a = Z⁻ᴴ u and b = Z⁻¹ v (Z = iωI − A; B = C = I are no variables), and the chain rule through
//! the loop is §6.2's rank-one one with G_B = G_C = G_D = 0 ([`ClosedLoop::chain_rule`] with no
//! (u, v)). The peak is never at ω = ∞ ((iωI − A)⁻¹ → 0).

use faer::{Mat, MatRef};

use super::gradient::{grad_at_peak, hinf_with_vectors, ControllerGradient};
use super::hinf::{HinfNorm, HinfParams};
use crate::lti::error::LtiError;
use crate::lti::system::closed_loop::ClosedLoop;
use crate::lti::system::controller::Controller;
use crate::lti::system::plant::Plant;
use crate::lti::system::state_space::StateSpace;

/// 1/r_C(a) = ‖(sI − a)⁻¹‖∞ and a frequency attaining it, computed as `params` ask (as
/// [`hinf_norm`](super::hinf::hinf_norm)); +∞ (frequency NaN) if `a` is not Hurwitz or not
/// finite. `Err(Shape)` if `a` is not square, `Err(Interrupted)` once `params.stop` fires.
pub fn inverse_stability_radius(a: MatRef<'_, f64>, params: &HinfParams<'_>) -> Result<HinfNorm, LtiError> {
    if a.nrows() != a.ncols() {
        return Err(LtiError::Shape { what: "A", expected: (a.nrows(), a.nrows()), got: (a.nrows(), a.ncols()) });
    }
    Ok(hinf_with_vectors(&resolvent_system(a), &HinfParams { reuse: None, ..*params })?
        .map_or(HinfNorm::UNSTABLE, |(norm, _)| norm))
}

/// 1/r_C(Acl) of the closed loop of `plant` and `k` and its gradient with respect to (Ak, Bk,
/// Ck, Dk) (module docs), computed as `params` ask ([`HinfParams`]; `reuse` is ignored: its
/// evaluator would be Tzw's); +∞ with a NaN gradient if the loop is unstable, a NaN gradient for
/// a value at or above `params.enough`. `Err(IllPosed)` for an ill-posed loop,
/// `Err(Interrupted)` once `params.stop` fires.
pub fn closed_loop_inverse_stability_radius_grad(
    plant: &Plant,
    k: &Controller,
    params: &HinfParams<'_>,
) -> Result<(HinfNorm, ControllerGradient), LtiError> {
    let cl = ClosedLoop::new(plant, k)?;
    let peak = hinf_with_vectors(&resolvent_system(cl.sys.a.as_ref()), &HinfParams { reuse: None, ..*params })?;
    Ok(grad_at_peak(k, peak, |pv| cl.chain_rule(&pv.a, &pv.b, None)))
}

/// (A, I, I, 0): the system whose transfer function is the resolvent (sI − A)⁻¹.
fn resolvent_system(a: MatRef<'_, f64>) -> StateSpace {
    let n = a.nrows();
    StateSpace { a: a.to_owned(), b: Mat::identity(n, n), c: Mat::identity(n, n), d: Mat::zeros(n, n) }
}
