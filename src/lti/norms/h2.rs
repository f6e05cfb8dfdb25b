//! The H2 norm of a state-space system, continuous and discrete time, with its exact gradients
//! with respect to the system's matrices and to the controller of a closed loop, and the affine
//! parameterisation of the controller feedthroughs Dk that keep the loop strictly proper
//! (docs/ALGORITHMS.md §13.1–§13.3).
//!
//! # Value
//! Continuous time, A Hurwitz and D = 0: ‖G‖₂² = trace(C P Cᵀ) with the controllability Gramian
//! A P + P Aᵀ + B Bᵀ = 0 (`kernels/lyapunov.rs`, the matrix sign function); D ≠ 0 gives +∞ (G is
//! not square-integrable on the axis), as does α(A) ≥ 0. Discrete time, ρ(A) < 1:
//! ‖G‖₂² = trace(C P Cᵀ + D Dᵀ) with the Stein equation A P Aᵀ − P + B Bᵀ = 0. The Stein equation
//! is not solved by a second solver: the discrete Gramians are exactly the continuous Gramians of
//! the bilinear image (Ac, Bc, Cc) of `kernels/bilinear.rs` (Ac = (A − I)(A + I)⁻¹, Bc = √2 (A + I)⁻¹B,
//! Cc = √2 C(A + I)⁻¹; multiply Ac P + P Acᵀ + Bc Bcᵀ = 0 by (A + I) on the left and (A + I)ᵀ on the
//! right to get 2(A P Aᵀ − P + B Bᵀ) = 0, likewise for Q; the flipped map is the image of −A,
//! which has the same Stein equations). Its accuracy is that of the transform, ε·κ(A ± I).
//!
//! # Gradients
//! With the observability Gramian Aᵀ Q + Q A + Cᵀ C = 0 (discrete: Aᵀ Q A − Q + Cᵀ C = 0), the
//! derivative of J = ‖G‖₂² is
//!
//! ```text
//! continuous:  ∇_A J = 2 Q P,    ∇_B J = 2 Q B,  ∇_C J = 2 C P,  (∇_D J: D = 0 only)
//! discrete:    ∇_A J = 2 Q A P,  ∇_B J = 2 Q B,  ∇_C J = 2 C P,  ∇_D J = 2 D
//! ```
//!
//! (docs/ALGORITHMS.md §13.1), and ∇‖G‖₂ = ∇J / (2‖G‖₂); where ‖G‖₂ = 0 (J at its minimum, where
//! the square root is not differentiable) the zero matrices are returned, an element of the
//! Clarke subdifferential. These are full-rank matrices, so the chain rule through the loop is
//! [`ClosedLoop::chain_rule_dense`].
//!
//! # The loop's feedthrough
//! A continuous loop has a finite H2 norm only if Dcl = D11 + D12 Dk D21 = 0 (D22 = 0). A design
//! keeps it there by the affine parameterisation [`h2_feedthrough_parameterisation`]; Dcl is
//! then zero up to the rounding of that product, so the closed-loop functions accept
//! ‖Dcl‖_F ≤ [`H2_FEEDTHROUGH_RTOL`]·(‖D11‖_F + ‖D12‖_F ‖Dk‖_F ‖D21‖_F) as zero (the norm is then
//! that of the strictly proper part, and its gradient the gradient of that restriction) and give
//! +∞ otherwise. [`h2_norm`] of a bare [`StateSpace`] has no such scale: there any D ≠ 0 is +∞.

use faer::{Mat, MatRef};

use super::gradient::{nan_like, ControllerGradient};
use crate::lti::error::LtiError;
use crate::lti::kernels::bilinear::Cayley;
use crate::lti::kernels::lyapunov::{solve_lyapunov, LyapunovError};
use crate::lti::kernels::spectral::spectral_radius;
use crate::lti::system::closed_loop::ClosedLoop;
use crate::lti::system::controller::Controller;
use crate::lti::system::plant::Plant;
use crate::lti::system::state_space::StateSpace;
use crate::numeric::all_finite;

/// Relative size below which a continuous loop's feedthrough Dcl counts as zero, and to which
/// [`h2_feedthrough_parameterisation`] must solve D11 + D12 Dk D21 = 0 (module docs): the rounding
/// of D12 Dk D21 is a few ε times ‖D12‖‖Dk‖‖D21‖, so 1e-12 leaves a factor of about 10⁴ for it.
pub const H2_FEEDTHROUGH_RTOL: f64 = 1e-12;

/// ‖sys‖₂ of a continuous-time system: +∞ if D ≠ 0, if A is not Hurwitz or the data are not
/// finite; NaN if the Lyapunov equation could not be solved to its residual tolerance (module
/// docs; docs/ALGORITHMS.md §13.1).
pub fn h2_norm(sys: &StateSpace) -> f64 {
    value_of(continuous_squared(sys, false))
}

/// ‖sys‖₂ of a discrete-time system on the unit circle: +∞ if ρ(A) ≥ 1 or the data are not
/// finite; NaN if the Gramian could not be computed (module docs).
pub fn h2_norm_discrete(sys: &StateSpace) -> f64 {
    value_of(h2_squared(sys, Time::Discrete, false))
}

/// [`h2_norm`] with its gradient with respect to the system's own (A, B, C, D), as a
/// [`StateSpace`] of the same shapes (NaN entries where the norm is not finite; the D block is
/// zero, the norm being +∞ off D = 0).
pub fn h2_norm_grad(sys: &StateSpace) -> (f64, StateSpace) {
    grad_of(sys, continuous_squared(sys, true))
}

/// [`h2_norm_discrete`] with its gradient with respect to the system's own (A, B, C, D).
pub fn h2_norm_grad_discrete(sys: &StateSpace) -> (f64, StateSpace) {
    grad_of(sys, h2_squared(sys, Time::Discrete, true))
}

/// ‖Tzw‖₂ of the continuous closed loop and its gradient with respect to (Ak, Bk, Ck, Dk): +∞
/// with a NaN gradient if the loop is unstable or its feedthrough is not zero (to
/// [`H2_FEEDTHROUGH_RTOL`], module docs). `Err(IllPosed)` for an ill-posed loop,
/// `Err(NoConvergence)` if a Gramian could not be computed.
pub fn closed_loop_h2_grad(plant: &Plant, k: &Controller) -> Result<(f64, ControllerGradient), LtiError> {
    closed_loop_h2(plant, k, Time::Continuous)
}

/// ‖Tzw‖₂ of the discrete closed loop (discrete plant and controller, the loop of §2) and its
/// gradient with respect to (Ak, Bk, Ck, Dk); Dcl may be nonzero. As [`closed_loop_h2_grad`]
/// otherwise.
pub fn closed_loop_h2_grad_discrete(plant: &Plant, k: &Controller) -> Result<(f64, ControllerGradient), LtiError> {
    closed_loop_h2(plant, k, Time::Discrete)
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Time {
    Continuous,
    Discrete,
}

/// J = ‖G‖₂² with, if asked for, ∇J; `Ok(None)`: +∞.
type H2Squared = Result<Option<(f64, Option<StateSpace>)>, LyapunovError>;

/// J = ‖sys‖₂² and, if `grad`, ∇J with respect to (A, B, C, D); `Ok(None)` where the norm is
/// +∞. In continuous time `sys.d` must be zero (checked by the callers: exactly for a bare
/// system, to rounding for a loop) and is not read.
fn h2_squared(sys: &StateSpace, time: Time, grad: bool) -> H2Squared {
    if !sys.is_finite() {
        return Ok(None);
    }
    let image;
    let gram = match time {
        Time::Continuous => sys,
        Time::Discrete => {
            if !(spectral_radius(sys.a.as_ref()) < 1.0) {
                return Ok(None);
            }
            let Some(cayley) = Cayley::new(sys) else { return Ok(None) };
            image = cayley.sys;
            &image
        }
    };
    let gramian = |a: MatRef<'_, f64>, f: MatRef<'_, f64>| match solve_lyapunov(a, (f * f.transpose()).as_ref()) {
        Err(LyapunovError::NotStable { .. }) => Ok(None),
        other => other.map(Some),
    };
    let Some(p) = gramian(gram.a.as_ref(), gram.b.as_ref())? else { return Ok(None) };
    let cp = &sys.c * &p;
    let mut j = frobenius_dot(cp.as_ref(), sys.c.as_ref());
    if time == Time::Discrete {
        j += frobenius_dot(sys.d.as_ref(), sys.d.as_ref());
    }
    if !grad {
        return Ok(Some((j, None)));
    }
    let Some(q) = gramian(gram.a.transpose(), gram.c.transpose())? else { return Ok(None) };
    let qp = match time {
        Time::Continuous => &q * &p,
        Time::Discrete => &q * &sys.a * &p,
    };
    let g = StateSpace {
        a: qp * faer::Scale(2.0),
        b: &q * &sys.b * faer::Scale(2.0),
        c: cp * faer::Scale(2.0),
        d: match time {
            Time::Continuous => Mat::zeros(sys.outputs(), sys.inputs()),
            Time::Discrete => &sys.d * faer::Scale(2.0),
        },
    };
    Ok(Some((j, Some(g))))
}

/// Σ x_ij y_ij.
fn frobenius_dot(x: MatRef<'_, f64>, y: MatRef<'_, f64>) -> f64 {
    (0..x.ncols()).map(|j| (0..x.nrows()).map(|i| x[(i, j)] * y[(i, j)]).sum::<f64>()).sum()
}

/// Whether every entry is exactly zero.
fn is_zero(m: MatRef<'_, f64>) -> bool {
    (0..m.ncols()).all(|j| (0..m.nrows()).all(|i| m[(i, j)] == 0.0))
}

/// The norm from J (+∞ for `None`, NaN for a failed Gramian).
fn value_of(j: H2Squared) -> f64 {
    match j {
        Ok(Some((j, _))) => j.max(0.0).sqrt(),
        Ok(None) => f64::INFINITY,
        Err(_) => f64::NAN,
    }
}

/// ‖G‖₂ and ∇‖G‖₂ = ∇J / (2‖G‖₂) (zeros at ‖G‖₂ = 0, module docs).
fn root(j: f64, g: StateSpace) -> (f64, StateSpace) {
    let norm = j.max(0.0).sqrt();
    let s = if norm > 0.0 { 0.5 / norm } else { 0.0 };
    let scale = |m: Mat<f64>| m * faer::Scale(s);
    (norm, StateSpace { a: scale(g.a), b: scale(g.b), c: scale(g.c), d: scale(g.d) })
}

/// [`h2_squared`] of a bare continuous system: +∞ (`Ok(None)`) for D ≠ 0.
fn continuous_squared(sys: &StateSpace, grad: bool) -> H2Squared {
    if is_zero(sys.d.as_ref()) {
        h2_squared(sys, Time::Continuous, grad)
    } else {
        Ok(None)
    }
}

/// The norm and gradient of a bare system from J (NaN gradient where the norm is not finite).
fn grad_of(sys: &StateSpace, j: H2Squared) -> (f64, StateSpace) {
    match j {
        Ok(Some((j, Some(g)))) => root(j, g),
        other => {
            let nan = |m: &Mat<f64>| Mat::from_fn(m.nrows(), m.ncols(), |_, _| f64::NAN);
            (value_of(other), StateSpace { a: nan(&sys.a), b: nan(&sys.b), c: nan(&sys.c), d: nan(&sys.d) })
        }
    }
}

/// The closed loop's norm and gradient (module docs).
fn closed_loop_h2(plant: &Plant, k: &Controller, time: Time) -> Result<(f64, ControllerGradient), LtiError> {
    let cl = ClosedLoop::new(plant, k)?;
    if time == Time::Continuous {
        let scale = feedthrough_scale(plant, k.dk.as_ref());
        if !(cl.sys.d.norm_l2() <= H2_FEEDTHROUGH_RTOL * scale) {
            return Ok((f64::INFINITY, nan_like(k)));
        }
    }
    match h2_squared(&cl.sys, time, true) {
        Ok(Some((j, Some(g)))) => {
            let (norm, g) = root(j, g);
            Ok((norm, cl.chain_rule_dense(&g)))
        }
        Ok(_) => Ok((f64::INFINITY, nan_like(k))),
        Err(_) => Err(LtiError::NoConvergence("the Lyapunov equation of the H2 norm")),
    }
}

/// ‖D11‖_F + ‖D12‖_F ‖Dk‖_F ‖D21‖_F: the size of the terms of D11 + D12 Dk D21, whose rounding
/// [`H2_FEEDTHROUGH_RTOL`] is relative to.
fn feedthrough_scale(plant: &Plant, dk: MatRef<'_, f64>) -> f64 {
    plant.d11.norm_l2() + plant.d12.norm_l2() * dk.norm_l2() * plant.d21.norm_l2()
}

/// Why no affine parameterisation of the strictly proper loops exists.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FeedthroughError {
    /// D22 ≠ 0: the loop's feedthrough D11 + D12 Dk (I − D22 Dk)⁻¹ D21 is not affine in Dk.
    #[error("D22 ≠ 0: the loop's feedthrough D11 + D12·Dk·(I − D22·Dk)⁻¹·D21 is not affine in Dk")]
    D22NotZero,
    /// D11, D12 or D21 has a non-finite entry, or an SVD of them failed.
    #[error("D11, D12 or D21 is not finite, or its SVD failed")]
    NonFinite,
    /// D11 + D12 Dk D21 = 0 has no solution: D11 has a part outside the range of D12 or the row
    /// space of D21. `residual` is ‖D11 + D12 Dk0 D21‖_F of the least-squares Dk0, relative to
    /// ‖D11‖_F + ‖D12‖_F ‖Dk0‖_F ‖D21‖_F.
    #[error("no Dk makes D11 + D12·Dk·D21 = 0 (relative least-squares residual {residual:.3e})")]
    NoSolution {
        /// Relative residual of the least-squares solution.
        residual: f64,
    },
}

/// The feedthroughs of the strictly proper loops, {Dk : D11 + D12 Dk D21 = 0} =
/// {Dk0 + Σ zᵢ Eᵢ : z ∈ ℝᵈ} (docs/ALGORITHMS.md §13.2).
#[derive(Debug, Clone, PartialEq)]
pub struct DkAffine {
    /// The least-norm solution −D12⁺ D11 D21⁺ (orthogonal to every Eᵢ).
    pub dk0: Mat<f64>,
    /// An orthonormal basis (in ⟨X, Y⟩ = trace XᵀY) of {X : D12 X D21 = 0}, of dimension
    /// m2·p2 − rank D12 · rank D21.
    pub basis: Vec<Mat<f64>>,
}

impl DkAffine {
    /// The number d of free parameters.
    pub fn dim(&self) -> usize {
        self.basis.len()
    }

    /// Dk0 + Σ zᵢ Eᵢ; `Err(Shape)` unless z has [`DkAffine::dim`] entries.
    pub fn dk(&self, z: &[f64]) -> Result<Mat<f64>, LtiError> {
        self.check_len(z.len())?;
        Ok(self.basis.iter().zip(z).fold(self.dk0.clone(), |dk, (e, &zi)| dk + e * faer::Scale(zi)))
    }

    /// The components ⟨Eᵢ, X⟩ of an m2×p2 matrix: z of Dk = Dk0 + Σ zᵢ Eᵢ for X = Dk − Dk0, and
    /// ∂f/∂zᵢ for X = ∂f/∂Dk (the chain rule of the parameterisation). `Err(Shape)` for another
    /// shape.
    pub fn components(&self, x: MatRef<'_, f64>) -> Result<Vec<f64>, LtiError> {
        let expected = (self.dk0.nrows(), self.dk0.ncols());
        if (x.nrows(), x.ncols()) != expected {
            return Err(LtiError::Shape { what: "Dk", expected, got: (x.nrows(), x.ncols()) });
        }
        Ok(self.basis.iter().map(|e| frobenius_dot(e.as_ref(), x)).collect())
    }

    fn check_len(&self, len: usize) -> Result<(), LtiError> {
        if len == self.dim() {
            Ok(())
        } else {
            Err(LtiError::Shape { what: "z", expected: (self.dim(), 1), got: (len, 1) })
        }
    }
}

/// The affine set of controller feedthroughs Dk with D11 + D12 Dk D21 = 0, the strictly proper
/// loops on which a continuous H2 norm is finite (docs/ALGORITHMS.md §13.2). From the SVDs
/// D12 = U1 S1 V1ᵀ, D21 = U2 S2 V2ᵀ (ranks r1, r2: singular values above max(rows, cols)·ε·σmax):
/// Dk0 = −D12⁺ D11 D21⁺ and Eᵢⱼ = v1ᵢ u2ⱼᵀ for i ≥ r1 or j ≥ r2. Errors: D22 ≠ 0 (the loop's
/// feedthrough D11 + D12 Dk (I − D22 Dk)⁻¹ D21 is then not affine in Dk), non-finite data, and no
/// solution (residual above [`H2_FEEDTHROUGH_RTOL`] relative to ‖D11‖_F + ‖D12‖_F ‖Dk0‖_F ‖D21‖_F).
pub fn h2_feedthrough_parameterisation(plant: &Plant) -> Result<DkAffine, FeedthroughError> {
    if !plant.d22_is_zero() {
        return Err(FeedthroughError::D22NotZero);
    }
    let (d11, d12, d21) = (plant.d11.as_ref(), plant.d12.as_ref(), plant.d21.as_ref());
    if !(all_finite(d11) && all_finite(d12) && all_finite(d21)) {
        return Err(FeedthroughError::NonFinite);
    }
    let (svd12, svd21) = (full_svd(d12)?, full_svd(d21)?);
    let (r1, r2) = (svd12.s.len(), svd21.s.len());
    let dk0 = -(svd12.pinv() * d11 * svd21.pinv());
    let residual = (d11 + d12 * &dk0 * d21).norm_l2();
    let scale = d11.norm_l2() + d12.norm_l2() * dk0.norm_l2() * d21.norm_l2();
    if !(residual <= H2_FEEDTHROUGH_RTOL * scale) {
        return Err(FeedthroughError::NoSolution { residual: residual / scale });
    }
    let (m2, p2) = (d12.ncols(), d21.nrows());
    let basis = (0..m2)
        .flat_map(|i| (0..p2).map(move |j| (i, j)))
        .filter(|&(i, j)| i >= r1 || j >= r2)
        .map(|(i, j)| Mat::from_fn(m2, p2, |r, c| svd12.v[(r, i)] * svd21.u[(c, j)]))
        .collect();
    Ok(DkAffine { dk0, basis })
}

/// A full SVD M = U S Vᵀ (U and V square and orthogonal) truncated to the numerical rank: `s`
/// holds the singular values above max(rows, cols)·ε·σmax, leading.
struct RankSvd {
    u: Mat<f64>,
    s: Vec<f64>,
    v: Mat<f64>,
}

impl RankSvd {
    /// M⁺ = V_r S_r⁻¹ U_rᵀ.
    fn pinv(&self) -> Mat<f64> {
        let (u, s, v) = (&self.u, &self.s, &self.v);
        Mat::from_fn(v.nrows(), u.nrows(), |i, j| (0..s.len()).map(|k| v[(i, k)] * u[(j, k)] / s[k]).sum::<f64>())
    }
}

/// The [`RankSvd`] of `m` (identities for an empty `m`).
fn full_svd(m: MatRef<'_, f64>) -> Result<RankSvd, FeedthroughError> {
    let (r, c) = (m.nrows(), m.ncols());
    if r == 0 || c == 0 {
        return Ok(RankSvd { u: Mat::identity(r, r), s: Vec::new(), v: Mat::identity(c, c) });
    }
    let svd = m.svd().map_err(|_| FeedthroughError::NonFinite)?;
    let s: Vec<f64> = (0..r.min(c)).map(|i| svd.S()[i]).collect();
    let smax = s.iter().fold(0.0f64, |a, &b| a.max(b));
    let tol = r.max(c) as f64 * f64::EPSILON * smax;
    let rank = s.iter().take_while(|&&x| x > tol).count();
    Ok(RankSvd { u: svd.U().to_owned(), s: s[..rank].to_vec(), v: svd.V().to_owned() })
}
