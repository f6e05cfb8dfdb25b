//! The H∞ norm of a discrete-time system, ‖G‖∞ = sup_{θ ∈ [0, π]} σmax(G(e^{iθ})) with
//! G(z) = C(zI − A)⁻¹B + D, its peak frequency θ (rad/sample; ω = θ/Ts rad/s for a sampling
//! time Ts), and its gradients (docs/ALGORITHMS.md §10).
//!
//! # Method: the bilinear transform, then the continuous norm
//! 1. ρ(A) ≥ 1 (the spectral radius, `spectral.rs`; any pole on or outside the unit circle) or
//!    non-finite data → +∞, as the continuous norm does for α(A) ≥ 0.
//! 2. The Cayley map z = ±(1 + s)/(1 − s) (`bilinear.rs`: the sign whose singular point z = ∓1
//!    is farther from the spectrum, measured by ‖(A ± I)⁻¹‖_F) gives a continuous-time system
//!    Gc with σmax(Gc(iω)) = σmax(G(e^{iθ})), θ = 2·atan ω (π − 2·atan ω for the minus sign),
//!    Ac Hurwitz. Its norm is the crate's continuous [`hinf_norm`] (level set with AB13DD's
//!    refinements, the square-reduced Hamiltonian and the pencil near σmax(Dc),
//!    docs/ALGORITHMS.md §5), with the hints mapped to ω and its peak mapped back to θ. Hence
//!    everything that makes the continuous norm never under-estimate (the property families of
//!    `tests/hinf_property.rs`, the near-σmax(D) cases) carries over: the two functions are equal
//!    on the boundary, not approximately equal. (If rounding puts a pole of Ac on the axis although
//!    ρ(A) < 1, i.e. a pole within rounding of the unit circle, the norm is +∞.)
//! 3. At the peak z = e^{iθ} (exactly ±1 at θ = 0, π) σmax(G(z)) is evaluated once more on the
//!    original data by a dense complex LU of zI − A, which also gives the gradient's vectors, and
//!    that is the value returned: attained by G itself at the returned θ, as the continuous norm's
//!    value is. The transform's rounding then only displaces the peak frequency, which changes
//!    the value to second order. (Measured on the SLICOT fixture with the side choice of step 2
//!    disabled: returning the image's value was 2.5e-8 off on a mode 1e-3 from z = −1, the
//!    re-evaluated one 2.1e-12; with the side choice, 2.9e-12 at worst, on other cases.)
//!
//! Why not a level set on the unit circle (the symplectic pencil of Boyd–Balakrishnan's
//! discrete-time form)? It would need its own copy of every safeguard the continuous level-set
//! test has grown (`hinf.rs`); the transform is exact and costs one LU of A ± I, whose rounding is
//! a relative perturbation of A of size ε·κ(A ± I) (`bilinear.rs`).
//!
//! # Gradient
//! At the peak with Z = zI − A, z = e^{iθ}, and the leading singular pair G(z) v = σ u, first-order
//! perturbation of σ = Re(uᴴ G v) gives exactly the continuous formulas with iω replaced by z:
//! with a = Z⁻ᴴCᵀu and b = Z⁻¹Bv, G_A = Re(ā bᵀ), G_B = Re(ā vᵀ), G_C = Re(ū bᵀ), G_D = Re(ū vᵀ)
//! (dZ⁻¹ = Z⁻¹ dA Z⁻¹ for any fixed z). The closed loop of a discrete plant with a discrete
//! controller has the continuous LFT formulas, so the chain rule (`closed_loop.rs`) is the same.
//! A dense LU at the peak, O(n³) (the continuous norm's Hessenberg route serves iω only).

use faer::c64;

use super::gradient::{
    closed_loop_grad_from, controller_grad_from, controller_system, matrix_gradients, peak_vectors_at,
    ControllerGradient, PeakVectors,
};
use super::hinf::{hinf_norm, HinfNorm, HinfParams};
use crate::lti::error::LtiError;
use crate::lti::interrupt::Interrupted;
use crate::lti::kernels::bilinear::Cayley;
use crate::lti::kernels::spectral::{is_schur_stable, spectral_radius};
use crate::lti::system::closed_loop::ClosedLoop;
use crate::lti::system::controller::Controller;
use crate::lti::system::plant::Plant;
use crate::lti::system::state_space::StateSpace;

/// ‖sys‖∞ of the discrete-time system `sys` on the unit circle and a frequency θ ∈ [0, π]
/// (rad/sample) attaining it, as `params` ask ([`HinfParams`]: tolerance, hints — in rad/sample
/// —, stop hook, early level; `reuse` is not used); +∞ (θ NaN) if ρ(A) ≥ 1 or the data are not
/// finite. `Err(Interrupted)` only if `params.stop` fired. Module docs for the method.
pub fn hinf_norm_discrete(sys: &StateSpace, params: &HinfParams<'_>) -> Result<HinfNorm, Interrupted> {
    Ok(discrete_hinf_with_vectors(sys, params)?.map_or(HinfNorm::UNSTABLE, |(norm, _)| norm))
}

/// [`hinf_norm_discrete`] with its gradient with respect to the system's own (A, B, C, D), as a
/// [`StateSpace`] of the same shapes (NaN entries where the norm is +∞, or, for a value at or
/// above `params.enough`, a lower bound).
pub fn hinf_norm_grad_discrete(
    sys: &StateSpace,
    params: &HinfParams<'_>,
) -> Result<(HinfNorm, StateSpace), Interrupted> {
    let nan = || {
        let f = |m: &faer::Mat<f64>| faer::Mat::from_fn(m.nrows(), m.ncols(), |_, _| f64::NAN);
        StateSpace { a: f(&sys.a), b: f(&sys.b), c: f(&sys.c), d: f(&sys.d) }
    };
    Ok(match discrete_hinf_with_vectors(sys, params)? {
        Some((norm, Some(pv))) => {
            let [a, b, c, d] = matrix_gradients(&pv);
            (norm, StateSpace { a, b, c, d })
        }
        Some((norm, None)) => (norm, nan()),
        None => (HinfNorm::UNSTABLE, nan()),
    })
}

/// ‖Tzw‖∞ of the closed loop of a discrete-time plant with a discrete-time controller (same
/// sampling time; the loop has the continuous LFT formulas) and its gradient with respect to
/// (Ak, Bk, Ck, Dk): as [`closed_loop_hinf_grad`](crate::lti::closed_loop_hinf_grad), with θ in
/// rad/sample and +∞ when ρ(Acl) ≥ 1. `Err(IllPosed)` for an ill-posed loop.
pub fn closed_loop_hinf_grad_discrete(
    plant: &Plant,
    k: &Controller,
    params: &HinfParams<'_>,
) -> Result<(HinfNorm, ControllerGradient), LtiError> {
    let cl = ClosedLoop::new(plant, k)?;
    Ok(closed_loop_grad_from(&cl, k, discrete_hinf_with_vectors(&cl.sys, params)?))
}

/// ‖K‖∞ of a discrete-time controller (+∞ if ρ(Ak) ≥ 1; σmax(Dk) for nk = 0) and its gradient,
/// as [`controller_hinf_grad`](crate::lti::controller_hinf_grad).
pub fn controller_hinf_grad_discrete(k: &Controller, tol: f64) -> (HinfNorm, ControllerGradient) {
    let peak = discrete_hinf_with_vectors(&controller_system(k), &HinfParams::new(tol)).map_err(LtiError::from);
    controller_grad_from(k, peak)
}

/// The discrete norm (θ in rad/sample) with the gradient's vectors at its peak; `Ok(None)` if
/// unstable (or not finite, or the vectors fail); a value at or above `params.enough` comes
/// without vectors.
fn discrete_hinf_with_vectors(
    sys: &StateSpace,
    params: &HinfParams<'_>,
) -> Result<Option<(HinfNorm, Option<PeakVectors>)>, Interrupted> {
    if !sys.is_finite() {
        return Ok(None);
    }
    params.stop.poll()?;
    if !is_schur_stable(spectral_radius(sys.a.as_ref())) {
        return Ok(None);
    }
    let Some(cayley) = Cayley::new(sys) else { return Ok(None) };
    let hints: Vec<f64> = params.hints.iter().map(|&t| cayley.continuous_freq(t)).collect();
    let continuous = hinf_norm(&cayley.sys, &HinfParams { hints: &hints, reuse: None, ..*params })?;
    if !continuous.value.is_finite() {
        return Ok(None);
    }
    let theta = cayley.discrete_freq(continuous.peak_freq);
    if continuous.value >= params.enough {
        return Ok(Some((HinfNorm { value: continuous.value, peak_freq: theta }, None)));
    }
    params.stop.poll()?;
    Ok(peak_vectors_at(sys, Some(unit_circle_point(theta)))
        .map(|pv| (HinfNorm { value: pv.sigma, peak_freq: theta }, Some(pv))))
}

/// e^{iθ}, exactly ±1 at θ = 0 and θ = π.
fn unit_circle_point(theta: f64) -> c64 {
    if theta == std::f64::consts::PI {
        c64::new(-1.0, 0.0)
    } else if theta == 0.0 {
        c64::new(1.0, 0.0)
    } else {
        c64::new(theta.cos(), theta.sin())
    }
}
