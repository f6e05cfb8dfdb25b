//! The constant terms of the two γ-test Riccati equations, without cancellation.
//!
//! In the R-form of `gamma_test.rs` the X equation's constant term is
//! `Q_x = C1ᵀ (I − D1• R⁻¹ D1•ᵀ) C1` with `D1• = [D11 D12]`, `R = D1•ᵀD1• − diag(γ²I, 0)`. Formed
//! as written it is a difference of two products that cancel exactly on the part of z that u
//! reaches: with D11 = 0 it is `C1ᵀ (I − D12 (D12ᵀD12)⁻¹ D12ᵀ) C1`, which is 0 when D12 is square
//! and, in general, leaves rounding noise of size u·‖C1‖² (of either sign) where the exact value
//! is small. That noise is what made the γ-test fail at every γ on plants whose one disturbance
//! enters both a state and the measurement (B1·D21ᵀ ≠ 0 with D21 square, so the exact `Q_y` is 0,
//! and dually D12ᵀ·C1 ≠ 0 with D12 square): the Y Hamiltonian, block-triangular in exact
//! arithmetic, becomes a noisy full one whose stable subspace the sign function no longer
//! resolves (CARE relative residual ~ 1e-1 instead of 1e-15).
//!
//! The same term is computed here in the coordinates of the standard normalisation
//! (Safonov–Limebeer–Chiang 1989; Zhou–Doyle–Glover 1996, §17.2): rotate z by an orthogonal
//! `Θ = [U⊥ U]` with `U⊥` an orthonormal basis of range(D12)⊥, and scale u so that `Θᵀ D12 = [0; I]`.
//! The R-form is invariant under both changes (`gamma_test.rs`), and there, writing
//! `C1⊥ = U⊥ᵀ C1`, `D11⊥ = U⊥ᵀ D11` (the part of z no control reaches), block elimination of the
//! u-block of R gives `I − D1• R⁻¹ D1•ᵀ = diag((I − γ⁻² D11⊥ D11⊥ᵀ)⁻¹, 0)`, so
//!
//! ```text
//! Q_x = C1⊥ᵀ W⁻¹ C1⊥,   W = I − γ⁻² D11⊥ D11⊥ᵀ  (positive definite for γ above the D11 bound),
//! ```
//!
//! a Gram product: positive semidefinite by construction, exactly `C1⊥ᵀ C1⊥` when D11 = 0 and
//! exactly 0 when D12 is square. Dually, with `N` an orthonormal basis of ker(D21),
//! `Q_y = (B1 N) (I − γ⁻² Nᵀ D11ᵀ D11 N)⁻¹ (B1 N)ᵀ`. The cross terms D12ᵀ·C1 and B1·D21ᵀ stay where
//! the R-form puts them, in the Riccati equations' A matrices (`A − B R⁻¹ D1•ᵀ C1`, the
//! "Riccati equations with cross terms"), where they cause no cancellation.

use faer::{Mat, MatRef, Side};

use super::FullOrderError;
use crate::numeric::all_finite;

/// One side's γ-independent data: `C1⊥` (or `(B1 N)ᵀ`) and `D11⊥` (or `(D11 N)ᵀ`), so that both
/// sides share [`ExogenousWeight::at`].
pub(crate) struct ExogenousWeight {
    /// `C1⊥ = U⊥ᵀ C1` ((p1 − m2) × n).
    c: Mat<f64>,
    /// `D11⊥ = U⊥ᵀ D11` ((p1 − m2) × m1).
    d: Mat<f64>,
    /// `C1⊥ᵀ C1⊥` (the value for D11⊥ = 0).
    ctc: Mat<f64>,
}

impl ExogenousWeight {
    /// The X side: from C1, D11 and D12 (full column rank).
    pub(crate) fn state_feedback(
        c1: MatRef<'_, f64>,
        d11: MatRef<'_, f64>,
        d12: MatRef<'_, f64>,
    ) -> Result<ExogenousWeight, FullOrderError> {
        let u_perp = range_complement(d12)?;
        let c = u_perp.transpose() * c1;
        let d = u_perp.transpose() * d11;
        let ctc = c.transpose() * &c;
        Ok(ExogenousWeight { c, d, ctc })
    }

    /// The Y side: from B1, D11 and D21 (full row rank), as the X side of the transposed plant.
    pub(crate) fn filter(
        b1: MatRef<'_, f64>,
        d11: MatRef<'_, f64>,
        d21: MatRef<'_, f64>,
    ) -> Result<ExogenousWeight, FullOrderError> {
        ExogenousWeight::state_feedback(b1.transpose(), d11.transpose(), d21.transpose())
    }

    /// `C1⊥ᵀ (I − γ⁻² D11⊥ D11⊥ᵀ)⁻¹ C1⊥` at `gamma`; None if W is not positive definite (γ at or
    /// below σ̄(D11⊥), i.e. below the D11 bound, up to rounding).
    pub(crate) fn at(&self, gamma: f64) -> Option<Mat<f64>> {
        if self.d.nrows() == 0 || self.d.ncols() == 0 || self.d.norm_max() == 0.0 {
            return Some(self.ctc.clone());
        }
        let k = self.d.nrows();
        let g2 = 1.0 / (gamma * gamma);
        let w =
            Mat::from_fn(k, k, |i, j| if i == j { 1.0 } else { 0.0 }) - &self.d * self.d.transpose() * faer::Scale(g2);
        let llt = w.llt(Side::Lower).ok()?;
        // W = L Lᵀ: Q = (L⁻¹ C1⊥)ᵀ (L⁻¹ C1⊥).
        let mut lc = self.c.clone();
        faer::linalg::triangular_solve::solve_lower_triangular_in_place(llt.L(), lc.as_mut(), faer::Par::Seq);
        let q = lc.transpose() * &lc;
        all_finite(q.as_ref()).then_some(q)
    }
}

/// An orthonormal basis of range(M)⊥ (rows × (rows − rank M)) for M of full column rank: the
/// trailing left singular vectors of a full SVD.
fn range_complement(m: MatRef<'_, f64>) -> Result<Mat<f64>, FullOrderError> {
    let (r, c) = (m.nrows(), m.ncols());
    if c == 0 {
        return Ok(Mat::identity(r, r));
    }
    if c >= r {
        return Ok(Mat::zeros(r, 0));
    }
    if !all_finite(m) {
        return Err(FullOrderError::NonFinite);
    }
    let svd = m.svd().map_err(|_| FullOrderError::LinearAlgebra("SVD of D12 or D21"))?;
    Ok(svd.U().subcols(c, r - c).to_owned())
}
