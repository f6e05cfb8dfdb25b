//! The full-order H∞ central controller at a level γ > γ_opt (used as a starting controller).
//!
//! # Formulas (Glover–Doyle 1988; Zhou–Doyle–Glover 1996, §17.1, D11 = 0)
//!
//! For a plant with D11 = 0, D22 = 0, D12ᵀD12 = I and D21D21ᵀ = I (cross terms D12ᵀC1, B1D21ᵀ
//! allowed), with Ã = A − B2D12ᵀC1 and Â = A − B1D21ᵀC2, the stabilising solutions
//!
//! ```text
//! X:  Ãᵀ X + X Ã − X (B2B2ᵀ − γ⁻²B1B1ᵀ) X + C1ᵀ(I − D12D12ᵀ)C1 = 0,
//! Y:  Â Y + Y Âᵀ − Y (C2ᵀC2 − γ⁻²C1ᵀC1) Y + B1(I − D21ᵀD21)B1ᵀ = 0,
//! ```
//!
//! with X ⪰ 0, Y ⪰ 0 and ρ(XY) < γ² (the same γ-test as [`super::full_order`]) give
//!
//! ```text
//! F = −(B2ᵀX + D12ᵀC1),  L = −(YC2ᵀ + B1D21ᵀ),  Z = (I − γ⁻²YX)⁻¹,
//! Ak = A + γ⁻²B1B1ᵀX + B2F + ZL(C2 + γ⁻²D21B1ᵀX),  Bk = −ZL,  Ck = F,  Dk = 0,
//! ```
//!
//! the central controller (u = K y), with ‖T_zw‖∞ < γ.
//!
//! # Reaching that form from a benchmark plant
//!
//! * **D11 is set to 0.** The controller is a *start* for the fixed-order search, whose job is
//!   first to stabilise: stabilisation depends on (A, B2, C2) only, and D11 ≠ 0 would need loop
//!   shifting. For plants with D11 ≠ 0 the γ guarantee is for the plant without D11.
//! * **Singular D12 or D21** is regularised as in [`super::full_order`] (z augmented with εx, εu;
//!   w with ε state and sensor noise), here with one fixed absolute ε (default
//!   [`START_REGULARISATION`]): a start needs no ε → 0 limit, and a tiny ε gives observer and
//!   state-feedback gains ~ 1/ε, a poor start. (An ε relative to the data norms was tried and
//!   rejected: on the badly scaled AC10, ‖A‖ ~ 10⁷, it gave ε = 1600 and γ 2× worse.)
//! * **Normalisation**: u = (D12ᵀD12)^{−1/2} ũ, ỹ = (D21D21ᵀ)^{−1/2} y; the controller is mapped
//!   back by K = (D12ᵀD12)^{−1/2} K̃ (D21D21ᵀ)^{−1/2}.
//! * **D22 ≠ 0**: K is designed for y − D22 u and realised as Ak − Bk D22 Ck (Dk = 0).
//!
//! γ_opt of the regularised plant is computed by [`super::full_order::full_order_gamma_with`] (relative
//! bracket [`GAMMA_OPT_RTOL`]); [`CentralProblem::controller`] then builds the controller at any
//! γ above it. Just above γ_opt the central controller has large gains (Z is nearly singular), so
//! starts use γ = f·γ_opt with f of order 1.1–2 (`DesignOptions::central_gammas`).

use faer::linalg::solvers::Solve;
use faer::{Mat, MatRef, Side};

use super::full_order::{augment, full_order_gamma_with, FullOrderError, FullOrderOptions, Regularisation, PSD_ATOL};
use crate::lti::kernels::riccati::{abscissa, solve_care};
use crate::lti::system::controller::Controller;
use crate::lti::system::plant::Plant;
use crate::numeric::all_finite;

/// Default regularisation ε (absolute) of singular D12/D21 (module docs).
pub const START_REGULARISATION: f64 = 1e-2;
/// Relative width of the γ_opt bracket (γ_opt only sets the scale of the levels used).
pub const GAMMA_OPT_RTOL: f64 = 1e-2;
/// Relative threshold of the numerical rank of D12, D21 (as [`super::full_order`]).
const RANK_TOL: f64 = 1e-10;

/// Why no central controller could be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum CentralError {
    /// γ_opt of the (regularised) plant could not be computed.
    #[error("full-order gamma: {0}")]
    FullOrder(#[from] FullOrderError),
    /// The γ-test fails at the requested level.
    #[error("gamma = {gamma} is infeasible: {why}")]
    Infeasible {
        /// The level.
        gamma: f64,
        /// Which condition failed.
        why: String,
    },
    /// A decomposition failed or produced non-finite values.
    #[error("linear algebra failure: {0}")]
    LinearAlgebra(&'static str),
    /// The plant is in discrete time: take the central controller of its bilinear image
    /// (`lti::PlantImage`) back.
    #[error("the central controller is computed in continuous time; for a discrete-time plant use its bilinear image")]
    DiscreteTime,
}

/// The normalised, regularised plant of the module docs, with γ_opt.
#[derive(Debug, Clone)]
pub struct CentralProblem {
    /// The regularised plant with D11 = 0 and D12, D21 normalised (D22 kept for the mapping back).
    normalised: Plant,
    /// (D12ᵀD12)^{−1/2} of the regularised plant (m2 × m2).
    t_u: Mat<f64>,
    /// (D21D21ᵀ)^{−1/2} of the regularised plant (p2 × p2).
    s_y: Mat<f64>,
    /// The plant's D22 (p2 × m2).
    d22: Mat<f64>,
    /// γ_opt of the normalised plant (feasible end of its bracket).
    pub gamma_opt: f64,
    /// The regularisation ε used (None if D12 and D21 were of full rank).
    pub regularisation: Option<f64>,
}

impl CentralProblem {
    /// Regularises (ε = [`START_REGULARISATION`]) and normalises `plant` and computes its γ_opt
    /// (module docs).
    pub fn new(plant: &Plant) -> Result<Self, CentralError> {
        Self::with_regularisation(plant, START_REGULARISATION)
    }

    /// As [`CentralProblem::new`] with an explicit (absolute) regularisation ε.
    pub fn with_regularisation(plant: &Plant, eps: f64) -> Result<Self, CentralError> {
        if plant.domain.is_discrete() {
            return Err(CentralError::DiscreteTime);
        }
        let d = plant.dims;
        if d.m2 == 0 || d.p2 == 0 {
            return Err(FullOrderError::NoControl { m2: d.m2, p2: d.p2 }.into());
        }
        let reg12 = rank(plant.d12.as_ref())? < d.m2;
        let reg21 = rank(plant.d21.as_ref())? < d.p2;
        let (m2, p2) = (d.m2, d.p2);
        // The δ-weighted channels of the full-order regularisation (`full_order::augment`).
        let ch = augment(plant, eps, reg12, reg21);
        let mut p = plant.clone();
        (p.b1, p.c1, p.d12, p.d21) = (ch.b1, ch.c1, ch.d12, ch.d21);
        p.d11 = Mat::zeros(p.c1.nrows(), p.b1.ncols());
        p.dims.p1 = p.c1.nrows();
        p.dims.m1 = p.b1.ncols();
        let t_u = inv_sqrt(p.d12.transpose() * &p.d12)?;
        let s_y = inv_sqrt(&p.d21 * p.d21.transpose())?;
        p.b2 = &p.b2 * &t_u;
        p.d12 = &p.d12 * &t_u;
        p.c2 = &s_y * &p.c2;
        p.d21 = &s_y * &p.d21;
        let d22 = std::mem::replace(&mut p.d22, Mat::zeros(p2, m2));
        let opts = FullOrderOptions { rtol: GAMMA_OPT_RTOL, regularisation: Regularisation::Auto };
        let g = full_order_gamma_with(&p, &opts)?;
        Ok(CentralProblem {
            normalised: p,
            t_u,
            s_y,
            d22,
            gamma_opt: g.gamma,
            regularisation: (reg12 || reg21).then_some(eps),
        })
    }

    /// The central controller at level `gamma` (> γ_opt), for the original plant (module docs).
    pub fn controller(&self, gamma: f64) -> Result<Controller, CentralError> {
        let p = &self.normalised;
        let n = p.dims.n;
        let g2 = 1.0 / (gamma * gamma);
        let infeasible = |why: String| CentralError::Infeasible { gamma, why };
        let b1b1t = &p.b1 * p.b1.transpose();
        let c1tc1 = p.c1.transpose() * &p.c1;
        // X
        let ax = &p.a - &p.b2 * p.d12.transpose() * &p.c1;
        let gx = &p.b2 * p.b2.transpose() - &b1b1t * g2;
        let proj12 = Mat::<f64>::identity(p.c1.nrows(), p.c1.nrows()) - &p.d12 * p.d12.transpose();
        let qx = p.c1.transpose() * proj12 * &p.c1;
        let x = solve_care(ax.as_ref(), gx.as_ref(), qx.as_ref()).map_err(|e| infeasible(format!("X: {e}")))?.x;
        // Y (transposed form)
        let ay = (&p.a - &p.b1 * p.d21.transpose() * &p.c2).transpose().to_owned();
        let gy = p.c2.transpose() * &p.c2 - &c1tc1 * g2;
        let proj21 = Mat::<f64>::identity(p.b1.ncols(), p.b1.ncols()) - p.d21.transpose() * &p.d21;
        let qy = &p.b1 * proj21 * p.b1.transpose();
        let y = solve_care(ay.as_ref(), gy.as_ref(), qy.as_ref()).map_err(|e| infeasible(format!("Y: {e}")))?.x;
        for (name, m) in [("X", &x), ("Y", &y)] {
            let lmin = min_eig(m.as_ref())?;
            // The absolute part (as the γ-test's) accepts rounding noise around X = 0 or Y = 0:
            // with D21 square and B1·D21ᵀ ≠ 0 the exact Y is 0 (tests/full_order.rs).
            if lmin < -(1e-8 * m.norm_l2() + PSD_ATOL) {
                return Err(infeasible(format!("{name} is not positive semidefinite (lambda_min {lmin:.3e})")));
            }
        }
        let zinv = Mat::<f64>::identity(n, n) - &y * &x * g2;
        let rho = abscissa((&y * &x).as_ref()) * g2;
        if !(rho < 1.0) {
            return Err(infeasible(format!("rho(XY)/gamma^2 = {rho:.6} >= 1")));
        }
        let f = -(p.b2.transpose() * &x + p.d12.transpose() * &p.c1);
        let l = -(&y * p.c2.transpose() + &p.b1 * p.d21.transpose());
        let zl = zinv.partial_piv_lu().solve(&l);
        let ak = &p.a + &b1b1t * &x * g2 + &p.b2 * &f + &zl * (&p.c2 + &p.d21 * p.b1.transpose() * &x * g2);
        let bk = -&zl;
        // Back to the plant's units; then the D22 loop transformation (Dk = 0).
        let bk = &bk * &self.s_y;
        let ck = &self.t_u * &f;
        let ak = if self.d22.norm_max() > 0.0 { &ak - &bk * &self.d22 * &ck } else { ak };
        let dk = Mat::zeros(ck.nrows(), bk.ncols());
        for m in [&ak, &bk, &ck] {
            if !all_finite(m.as_ref()) {
                return Err(CentralError::LinearAlgebra("non-finite central controller"));
            }
        }
        Ok(Controller::continuous(ak, bk, ck, dk))
    }
}

/// M^{−1/2} of a symmetric positive definite M.
fn inv_sqrt(m: Mat<f64>) -> Result<Mat<f64>, CentralError> {
    let n = m.nrows();
    let e = m.self_adjoint_eigen(Side::Lower).map_err(|_| CentralError::LinearAlgebra("eigen"))?;
    let d = e.S().column_vector();
    let u = e.U();
    if (0..n).any(|i| !(d[i] > 0.0)) {
        return Err(CentralError::LinearAlgebra("D12'D12 or D21 D21' is not positive definite"));
    }
    let us = Mat::from_fn(n, n, |i, j| u[(i, j)] / d[j].sqrt());
    Ok(us * u.transpose())
}

fn min_eig(m: MatRef<'_, f64>) -> Result<f64, CentralError> {
    let n = m.nrows();
    if n == 0 {
        return Ok(0.0);
    }
    let s = Mat::from_fn(n, n, |i, j| 0.5 * (m[(i, j)] + m[(j, i)]));
    let e = s.self_adjoint_eigen(Side::Lower).map_err(|_| CentralError::LinearAlgebra("eigen"))?;
    let d = e.S().column_vector();
    Ok((0..n).map(|i| d[i]).fold(f64::INFINITY, f64::min))
}

fn rank(m: MatRef<'_, f64>) -> Result<usize, CentralError> {
    if m.nrows() == 0 || m.ncols() == 0 {
        return Ok(0);
    }
    let s = m.singular_values().map_err(|_| CentralError::LinearAlgebra("singular values"))?;
    let smax = s.iter().copied().fold(0.0, f64::max);
    Ok(s.iter().filter(|&&v| v > RANK_TOL * smax && v > 0.0).count())
}
