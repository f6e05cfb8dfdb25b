//! The small dense linear algebra of the full-order γ (faer underneath): numerical ranks, the
//! D11 bound, symmetric eigen-decomposition, an LU solve and block concatenation.

use faer::{Mat, MatRef, Side};

use super::FullOrderError;
use crate::numeric::all_finite;

/// Relative singular-value threshold for the numerical rank of D12 and D21.
pub(crate) const RANK_TOL: f64 = 1e-10;

/// max(σ̄(D12⊥ᵀ D11), σ̄(D11 D21⊥ᵀ)) via the projectors onto the complements of range(D12) and of
/// the row space of D21.
pub(crate) fn feedthrough_bound(
    d11: MatRef<'_, f64>,
    d12: MatRef<'_, f64>,
    d21: MatRef<'_, f64>,
) -> Result<f64, FullOrderError> {
    if d11.nrows() == 0 || d11.ncols() == 0 || d11.norm_max() == 0.0 {
        return Ok(0.0);
    }
    let p12 = complement_projector(d12)?; // p1 × p1
    let p21 = complement_projector(d21.transpose())?; // m1 × m1
    let a = sigma_max((&p12 * d11).as_ref())?;
    let b = sigma_max((d11 * &p21).as_ref())?;
    Ok(a.max(b))
}

/// I − U_r U_rᵀ, U_r an orthonormal basis of range(M).
fn complement_projector(m: MatRef<'_, f64>) -> Result<Mat<f64>, FullOrderError> {
    let r = m.nrows();
    let mut p = Mat::<f64>::identity(r, r);
    if m.ncols() == 0 || m.norm_max() == 0.0 {
        return Ok(p);
    }
    let svd = m.thin_svd().map_err(|_| FullOrderError::LinearAlgebra("SVD"))?;
    let s = svd.S().column_vector();
    let smax = (0..s.nrows()).map(|i| s[i]).fold(0.0, f64::max);
    let u = svd.U();
    for k in 0..s.nrows() {
        if s[k] > RANK_TOL * smax {
            for i in 0..r {
                for j in 0..r {
                    p[(i, j)] -= u[(i, k)] * u[(j, k)];
                }
            }
        }
    }
    Ok(p)
}

/// Number of singular values above [`RANK_TOL`] × the largest.
pub(crate) fn numerical_rank(m: MatRef<'_, f64>) -> Result<usize, FullOrderError> {
    if m.nrows() == 0 || m.ncols() == 0 {
        return Ok(0);
    }
    let s = m.singular_values().map_err(|_| FullOrderError::LinearAlgebra("singular values"))?;
    let smax = s.iter().copied().fold(0.0, f64::max);
    Ok(s.iter().filter(|&&v| v > RANK_TOL * smax && v > 0.0).count())
}

/// Largest singular value (0 for an empty matrix).
fn sigma_max(m: MatRef<'_, f64>) -> Result<f64, FullOrderError> {
    if m.nrows() == 0 || m.ncols() == 0 {
        return Ok(0.0);
    }
    let s = m.singular_values().map_err(|_| FullOrderError::LinearAlgebra("singular values"))?;
    Ok(s.iter().copied().fold(0.0, f64::max))
}

/// Ascending eigenvalues and eigenvectors of the symmetric part of m.
pub(crate) fn sym_eig(m: MatRef<'_, f64>) -> Option<(Vec<f64>, Mat<f64>)> {
    let n = m.nrows();
    let s = Mat::from_fn(n, n, |i, j| 0.5 * (m[(i, j)] + m[(j, i)]));
    let e = s.self_adjoint_eigen(Side::Lower).ok()?;
    let d = e.S().column_vector();
    let vals: Vec<f64> = (0..n).map(|i| d[i]).collect();
    if vals.iter().any(|v| !v.is_finite()) {
        return None;
    }
    Some((vals, e.U().to_owned()))
}

/// Solves R Z = B by LU; None if the result is not finite.
pub(crate) fn solve(r: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Option<Mat<f64>> {
    use faer::linalg::solvers::Solve;
    let z = r.partial_piv_lu().solve(b);
    all_finite(z.as_ref()).then_some(z)
}

/// [a b].
pub(crate) fn concat_cols(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    let ca = a.ncols();
    Mat::from_fn(a.nrows(), ca + b.ncols(), |i, j| if j < ca { a[(i, j)] } else { b[(i, j - ca)] })
}

/// [a; b].
pub(crate) fn concat_rows(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    let ra = a.nrows();
    Mat::from_fn(ra + b.nrows(), a.ncols(), |i, j| if i < ra { a[(i, j)] } else { b[(i - ra, j)] })
}
