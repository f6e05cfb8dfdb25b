//! The domain-dependent quantities of a design in one place: stability and the H∞ norm in
//! continuous or discrete time ([`TimeDomain`], docs/ALGORITHMS.md §3.1, §10).
//!
//! The *stability measure* of a state matrix A is
//!
//! ```text
//! s(A) = α(A) = max Re λ(A)        (continuous time)
//! s(A) = ρ(A) − 1 = max |λ(A)| − 1  (discrete time)
//! ```
//!
//! negative exactly when the system is stable, in both domains. The stabilisation objective,
//! the optimiser's test ([`is_stable`](crate::lti::is_stable): s < 0) and the verification
//! margin ([`is_stable_with_margin`](crate::lti::is_stable_with_margin): s < −margin, i.e.
//! ρ < 1 − margin in discrete time, as `is_schur_stable_with_margin`) are then written once for
//! both. The gradient of ρ − 1 is that of ρ (§10.1).

use super::discrete::{closed_loop_hinf_grad_discrete, controller_hinf_grad_discrete, hinf_norm_discrete};
use super::gradient::{
    closed_loop_abscissa_grad, closed_loop_hinf_grad_continuous, closed_loop_radius_grad, controller_abscissa_grad,
    controller_hinf_grad_continuous, controller_radius_grad, ControllerGradient,
};
use super::h2::{closed_loop_h2_grad, closed_loop_h2_grad_discrete};
use super::hinf::{hinf_norm, HinfNorm, HinfParams};
use crate::lti::error::LtiError;
use crate::lti::interrupt::Interrupted;
use crate::lti::kernels::balance::balanced_for_eigenvalues;
use crate::lti::kernels::spectral::{
    abscissa_of, radius_of, spectral_abscissa, spectral_radius, verified_spectral_abscissa, verified_spectral_radius,
    STABILITY_MARGIN_RTOL,
};
use crate::lti::system::controller::Controller;
use crate::lti::system::plant::Plant;
use crate::lti::system::state_space::StateSpace;
use crate::lti::system::time_domain::TimeDomain;
use faer::{c64, MatRef};

/// The stability measure s(A) of the module docs: α(A), or ρ(A) − 1 in discrete time (−∞ and −1
/// for a 0×0 matrix; +∞ if the eigenvalues fail).
pub fn stability_measure(domain: TimeDomain, a: MatRef<'_, f64>) -> f64 {
    match domain {
        TimeDomain::Continuous => spectral_abscissa(a),
        TimeDomain::Discrete { .. } => spectral_radius(a) - 1.0,
    }
}

/// The stability measure as verification and reports compute it (on the balanced matrix:
/// [`verified_spectral_abscissa`], [`verified_spectral_radius`]), to be judged against
/// [`stability_margin`](crate::lti::kernels::spectral::stability_margin). The optimiser's
/// objective uses [`stability_measure`].
pub fn verified_stability_measure(domain: TimeDomain, a: MatRef<'_, f64>) -> f64 {
    match domain {
        TimeDomain::Continuous => verified_spectral_abscissa(a),
        TimeDomain::Discrete { .. } => verified_spectral_radius(a) - 1.0,
    }
}

/// The stability measure of a state matrix A as verification computes it, with its margin: the
/// one verification of stability (of a closed loop or of a controller), so that A is balanced
/// once for both numbers.
///
/// With B the balanced A where balancing pays (`kernels::balance::balanced_for_eigenvalues`),
/// else A itself: `measure` is s(B) (α, or ρ − 1 in discrete time: bit for bit
/// [`verified_stability_measure`]), `margin` is
/// [`STABILITY_MARGIN_RTOL`](crate::lti::STABILITY_MARGIN_RTOL) · max(1, ‖B‖_F) (bit for bit
/// [`stability_margin`](crate::lti::stability_margin)), and A is stable with the verification
/// margin when s < −margin ([`VerifiedStability::is_stable`], as
/// [`is_stable_with_margin`](crate::lti::is_stable_with_margin)).
pub fn verified_stability(domain: TimeDomain, a: MatRef<'_, f64>) -> VerifiedStability {
    let balanced = balanced_for_eigenvalues(a);
    let b = balanced.as_ref().map_or(a, |b| b.as_ref());
    VerifiedStability { measure: stability_measure(domain, b), margin: STABILITY_MARGIN_RTOL * b.norm_l2().max(1.0) }
}

/// A stability measure and its verification margin ([`verified_stability`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VerifiedStability {
    /// s(A): α(A), or ρ(A) − 1 in discrete time (of the balanced A where balancing pays).
    pub measure: f64,
    /// The verification margin of A (> 0).
    pub margin: f64,
}

impl VerifiedStability {
    /// Stable with the margin: s < −margin (NaN is not stable; −∞, an empty matrix, is).
    pub fn is_stable(&self) -> bool {
        self.measure < -self.margin
    }
}

/// The stability measure of a matrix with eigenvalues `poles` (as [`stability_measure`]; the
/// empty list gives −∞, or −1 in discrete time).
pub(crate) fn stability_measure_of(domain: TimeDomain, poles: &[c64]) -> f64 {
    match domain {
        TimeDomain::Continuous => abscissa_of(poles),
        TimeDomain::Discrete { .. } => radius_of(poles) - 1.0,
    }
}

/// s(Acl) of the closed loop in the plant's domain and its gradient with respect to the
/// controller (as [`closed_loop_abscissa_grad`]).
pub fn closed_loop_stability_grad(plant: &Plant, k: &Controller) -> Result<(f64, ControllerGradient), LtiError> {
    match plant.domain {
        TimeDomain::Continuous => closed_loop_abscissa_grad(plant, k),
        TimeDomain::Discrete { .. } => closed_loop_radius_grad(plant, k).map(|(rho, g)| (rho - 1.0, g)),
    }
}

/// s(Ak) of the controller in its domain and its gradient (as [`controller_abscissa_grad`]).
pub fn controller_stability_grad(k: &Controller) -> (f64, ControllerGradient) {
    match k.domain {
        TimeDomain::Continuous => controller_abscissa_grad(k),
        TimeDomain::Discrete { .. } => {
            let (rho, g) = controller_radius_grad(k);
            (rho - 1.0, g)
        }
    }
}

/// ‖sys‖∞ of a system of the domain `domain`: on the imaginary axis ([`hinf_norm`]) or on the
/// unit circle ([`hinf_norm_discrete`]; its peak frequency is then in rad/sample,
/// [`TimeDomain::to_rad_per_s`] turns it into rad/s).
pub fn hinf_norm_in(domain: TimeDomain, sys: &StateSpace, params: &HinfParams<'_>) -> Result<HinfNorm, Interrupted> {
    match domain {
        TimeDomain::Continuous => hinf_norm(sys, params),
        TimeDomain::Discrete { .. } => hinf_norm_discrete(sys, params),
    }
}

/// ‖Tzw‖₂ of the closed loop in the plant's domain and its gradient with respect to the
/// controller ([`closed_loop_h2_grad`](crate::lti::closed_loop_h2_grad), or
/// [`closed_loop_h2_grad_discrete`](crate::lti::closed_loop_h2_grad_discrete)).
pub fn closed_loop_h2_grad_in(plant: &Plant, k: &Controller) -> Result<(f64, ControllerGradient), LtiError> {
    match plant.domain {
        TimeDomain::Continuous => closed_loop_h2_grad(plant, k),
        TimeDomain::Discrete { .. } => closed_loop_h2_grad_discrete(plant, k),
    }
}

/// ‖Tzw‖∞ of the closed loop in the plant's domain (+∞ if the loop is unstable, with a NaN
/// gradient) and its gradient with respect to (Ak, Bk, Ck, Dk), computed as `params` ask
/// ([`HinfParams`]: tolerance, peak hints of a nearby controller — in rad/sample in discrete
/// time —, a stop hook — `Err(LtiError::Interrupted)` once it fires —, a level at which to stop
/// early — a value at or above `params.enough` is then an attained σmax, a lower bound of the
/// norm, returned with a NaN gradient —, and a [`ResponseSlot`](crate::lti::ResponseSlot) whose
/// evaluator of this very closed loop is reused, continuous time only). `Err(IllPosed)` for an
/// ill-posed loop, `Err(DomainMismatch)` for a controller of another domain. In discrete time
/// the norm is on the unit circle
/// ([`closed_loop_hinf_grad_discrete`](crate::lti::closed_loop_hinf_grad_discrete)).
pub fn closed_loop_hinf_grad(
    plant: &Plant,
    k: &Controller,
    params: &HinfParams<'_>,
) -> Result<(HinfNorm, ControllerGradient), LtiError> {
    match plant.domain {
        TimeDomain::Continuous => closed_loop_hinf_grad_continuous(plant, k, params),
        // (the closed loop refuses a controller of another domain: `Err(DomainMismatch)`)
        TimeDomain::Discrete { .. } => closed_loop_hinf_grad_discrete(plant, k, params),
    }
}

/// ‖K‖∞ of the controller itself in its domain (+∞ if it is not stable; σmax(Dk) for nk = 0)
/// and its gradient: on the imaginary axis, or on the unit circle
/// ([`controller_hinf_grad_discrete`](crate::lti::controller_hinf_grad_discrete)).
pub fn controller_hinf_grad(k: &Controller, tol: f64) -> (HinfNorm, ControllerGradient) {
    match k.domain {
        TimeDomain::Continuous => controller_hinf_grad_continuous(k, tol),
        TimeDomain::Discrete { .. } => controller_hinf_grad_discrete(k, tol),
    }
}
