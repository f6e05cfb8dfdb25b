//! Continuous Lyapunov equations `A P + P Aᵀ + W = 0` (A Hurwitz, W symmetric) and the
//! stable/antistable splitting of a state matrix, both by the matrix sign function.
//!
//! # Lyapunov equation (Roberts 1971; Benner–Quintana-Ortí 1999)
//!
//! With `T = [I P; 0 I]` and P the solution, `[A W; 0 −Aᵀ] = T diag(A, −Aᵀ) T⁻¹`, so for Hurwitz A
//!
//! ```text
//! sign [A  W; 0  −Aᵀ] = T diag(−I, I) T⁻¹ = [−I  2P; 0  I],
//! ```
//!
//! and P is half the (1,2) block. The sign function is the scaled Newton iteration of
//! [`super::riccati`] (no ordered Schur form is needed). The result is symmetrised and checked:
//! the relative residual ‖AP + PAᵀ + W‖_F / (2‖A‖_F‖P‖_F + ‖W‖_F) must be at most
//! [`LYAPUNOV_RESIDUAL_TOL`].
//!
//! # Stable/antistable splitting
//!
//! For A without imaginary-axis eigenvalues, `(I − sign A)/2` and `(I + sign A)/2` are the spectral
//! projectors onto the stable and the antistable invariant subspaces. Orthonormal bases V_s, V_u
//! of their ranges (SVD) give `T = [V_s V_u]` with `T⁻¹ A T = diag(A_s, A_u)`: the additive
//! decomposition G = G_s + G_u used to reduce an unstable system (its antistable part is kept).

use faer::linalg::solvers::DenseSolveCore;
use faer::{Mat, MatRef};

use super::riccati::{abscissa, sign_iteration, RiccatiError};
use crate::numeric::all_finite;

/// Largest accepted relative residual of a Lyapunov solution (see the module docs).
pub const LYAPUNOV_RESIDUAL_TOL: f64 = 1e-9;

/// Why a Lyapunov equation or a splitting could not be solved.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum LyapunovError {
    /// A is not Hurwitz (the Gramian does not exist).
    #[error("state matrix is not Hurwitz (spectral abscissa {abscissa:.3e}): no Gramian")]
    NotStable {
        /// Spectral abscissa of A.
        abscissa: f64,
    },
    /// Shapes do not fit.
    #[error("Lyapunov equation shape mismatch: A is {a:?}, W is {w:?}")]
    Shape {
        /// Shape of A.
        a: (usize, usize),
        /// Shape of W.
        w: (usize, usize),
    },
    /// The sign iteration failed (eigenvalues numerically on the imaginary axis, or non-finite).
    #[error("sign function: {0}")]
    Sign(#[from] RiccatiError),
    /// The computed solution does not satisfy the equation.
    #[error("Lyapunov relative residual {residual:.2e} exceeds {tol:.0e}")]
    Residual {
        /// Relative residual.
        residual: f64,
        /// Tolerance.
        tol: f64,
    },
}

/// The solution P of `A P + P Aᵀ + W = 0` for Hurwitz A (module docs). For `W = B Bᵀ` this is
/// the controllability Gramian, for `Aᵀ` and `W = Cᵀ C` the observability Gramian.
pub fn solve_lyapunov(a: MatRef<'_, f64>, w: MatRef<'_, f64>) -> Result<Mat<f64>, LyapunovError> {
    let n = a.nrows();
    if a.ncols() != n || w.nrows() != n || w.ncols() != n {
        return Err(LyapunovError::Shape { a: (a.nrows(), a.ncols()), w: (w.nrows(), w.ncols()) });
    }
    if n == 0 {
        return Ok(Mat::zeros(0, 0));
    }
    if !(all_finite(a) && all_finite(w)) {
        return Err(RiccatiError::NonFinite { stage: "Lyapunov input" }.into());
    }
    let alpha = abscissa(a);
    if !(alpha < 0.0) {
        return Err(LyapunovError::NotStable { abscissa: alpha });
    }
    let z = Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
        (true, true) => a[(i, j)],
        (true, false) => 0.5 * (w[(i, j - n)] + w[(j - n, i)]),
        (false, true) => 0.0,
        (false, false) => -a[(j - n, i - n)],
    });
    let (s, _, _) = sign_iteration(z)?;
    let p = Mat::from_fn(n, n, |i, j| 0.25 * (s[(i, n + j)] + s[(j, n + i)]));
    let residual = lyapunov_residual(a, w, p.as_ref());
    if !(residual <= LYAPUNOV_RESIDUAL_TOL) {
        return Err(LyapunovError::Residual { residual, tol: LYAPUNOV_RESIDUAL_TOL });
    }
    Ok(p)
}

/// Relative residual ‖AP + PAᵀ + W‖_F / (2‖A‖_F‖P‖_F + ‖W‖_F).
pub fn lyapunov_residual(a: MatRef<'_, f64>, w: MatRef<'_, f64>, p: MatRef<'_, f64>) -> f64 {
    let ap = a * p;
    let r = &ap + ap.transpose() + w;
    let scale = 2.0 * a.norm_l2() * p.norm_l2() + w.norm_l2();
    if scale == 0.0 {
        return r.norm_l2();
    }
    r.norm_l2() / scale
}

/// Bases of the stable and antistable invariant subspaces of `a` (module docs): returns
/// `(T, n_s)` with `T = [V_s V_u]` invertible and `T⁻¹ a T` block diagonal, the first `n_s`
/// columns spanning the stable subspace.
pub fn stable_antistable_basis(a: MatRef<'_, f64>) -> Result<(Mat<f64>, usize), LyapunovError> {
    let n = a.nrows();
    if n == 0 {
        return Ok((Mat::zeros(0, 0), 0));
    }
    if !all_finite(a) {
        return Err(RiccatiError::NonFinite { stage: "splitting input" }.into());
    }
    let (s, iterations, change) = sign_iteration(a.to_owned())?;
    let tr: f64 = (0..n).map(|i| s[(i, i)]).sum();
    // trace sign(A) = n_u − n_s must be (numerically) an integer of the parity of n.
    let n_u_f = 0.5 * (n as f64 + tr);
    let n_u = n_u_f.round();
    if (n_u_f - n_u).abs() > 0.25 || n_u < 0.0 || n_u > n as f64 {
        return Err(RiccatiError::NoDichotomy { iterations, trace: tr, change }.into());
    }
    let n_u = n_u as usize;
    let n_s = n - n_u;
    let mut t = Mat::<f64>::zeros(n, n);
    for (sign, off, cols) in [(-1.0, 0, n_s), (1.0, n_s, n_u)] {
        if cols == 0 {
            continue;
        }
        let proj = Mat::from_fn(n, n, |i, j| 0.5 * ((i == j) as u8 as f64 + sign * s[(i, j)]));
        let svd = proj.svd().map_err(|_| RiccatiError::NonFinite { stage: "projector SVD" })?;
        let u = svd.U();
        for j in 0..cols {
            for i in 0..n {
                t[(i, off + j)] = u[(i, j)];
            }
        }
    }
    let cond_ok = t.partial_piv_lu().inverse();
    if !all_finite(cond_ok.as_ref()) {
        return Err(RiccatiError::NonFinite { stage: "splitting basis" }.into());
    }
    Ok((t, n_s))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, StandardNormal};

    fn random(rng: &mut ChaCha8Rng, r: usize, c: usize) -> Mat<f64> {
        Mat::from_fn(r, c, |_, _| StandardNormal.sample(&mut *rng))
    }

    #[test]
    fn scalar_closed_form() {
        // a p + p a + w = 0  =>  p = −w / (2a)
        let a = Mat::from_fn(1, 1, |_, _| -3.0);
        let w = Mat::from_fn(1, 1, |_, _| 2.0);
        let p = solve_lyapunov(a.as_ref(), w.as_ref()).unwrap();
        assert!((p[(0, 0)] - 1.0 / 3.0).abs() < 1e-14);
    }

    #[test]
    fn diagonal_closed_form() {
        // A = diag(a_i): P_ij = −W_ij / (a_i + a_j).
        let d = [-1.0, -2.5, -0.1];
        let a = Mat::from_fn(3, 3, |i, j| if i == j { d[i] } else { 0.0 });
        let w = Mat::from_fn(3, 3, |i, j| 1.0 + (i + j) as f64);
        let p = solve_lyapunov(a.as_ref(), w.as_ref()).unwrap();
        for i in 0..3 {
            for j in 0..3 {
                let exact = -w[(i, j)] / (d[i] + d[j]);
                assert!((p[(i, j)] - exact).abs() < 1e-12 * exact.abs().max(1.0), "{i},{j}");
            }
        }
    }

    #[test]
    fn random_stable_residuals() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        for n in [2, 5, 12, 30] {
            let mut a = random(&mut rng, n, n);
            let shift = abscissa(a.as_ref()) + 0.5;
            for i in 0..n {
                a[(i, i)] -= shift;
            }
            let b = random(&mut rng, n, 2);
            let w = &b * b.transpose();
            let p = solve_lyapunov(a.as_ref(), w.as_ref()).unwrap();
            let r = lyapunov_residual(a.as_ref(), w.as_ref(), p.as_ref());
            assert!(r < 1e-12, "n = {n}: residual {r}");
        }
    }

    #[test]
    fn unstable_is_an_error() {
        let a = Mat::from_fn(2, 2, |i, j| if i == j { [1.0, -1.0][i] } else { 0.0 });
        let w = Mat::<f64>::identity(2, 2);
        assert!(matches!(solve_lyapunov(a.as_ref(), w.as_ref()), Err(LyapunovError::NotStable { .. })));
    }

    #[test]
    fn splitting_block_diagonalises() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let n = 7;
        // eigenvalues −3, −2, −1, −0.5, 0.7, 1.5, 2 in a random basis
        let ev = [-3.0, -2.0, -1.0, -0.5, 0.7, 1.5, 2.0];
        let v = random(&mut rng, n, n);
        let d = Mat::from_fn(n, n, |i, j| if i == j { ev[i] } else { 0.0 });
        let a = &v * &d * v.partial_piv_lu().inverse();
        let (t, ns) = stable_antistable_basis(a.as_ref()).unwrap();
        assert_eq!(ns, 4);
        let blk = t.partial_piv_lu().inverse() * &a * &t;
        let scale = blk.norm_l2();
        for i in 0..n {
            for j in 0..n {
                if (i < ns) != (j < ns) {
                    assert!(blk[(i, j)].abs() < 1e-9 * scale, "off-diagonal block entry {i},{j}: {}", blk[(i, j)]);
                }
            }
        }
        let a_s = Mat::from_fn(ns, ns, |i, j| blk[(i, j)]);
        assert!((abscissa(a_s.as_ref()) + 0.5).abs() < 1e-8);
    }
}
