//! Balancing of a square matrix by a diagonal similarity of powers of 2 (Parlett & Reinsch,
//! "Balancing a matrix for calculation of eigenvalues and eigenvectors", Numer. Math. 13, 1969;
//! the scaling step of LAPACK's `dgebal`, without its permutations).
//!
//! A computed eigenvalue carries an error of about ε_mach·‖A‖ (times its condition number), so a
//! matrix whose entries span many orders of magnitude while its eigenvalues do not (COMPleib's
//! EB6: ‖A‖_F = 1.3e8, |λ| ≤ 6 400, modes damped to 1e-7; TL: entries up to 3e14) has eigenvalues
//! that cannot be told from the imaginary axis. Balancing finds D = diag(2^k_i) such that each
//! row and column of B = D⁻¹·A·D has about the same 2-norm; B has the same eigenvalues as A, and
//! since every scale is a power of 2, B is computed from A **exactly** (no rounding, barring
//! underflow, which the scale bounds exclude). A matrix that is already balanced gets D = I and
//! B = A, bit for bit.
//!
//! Each sweep visits every index i: with c and r the 2-norms of column i and row i of B, the
//! power of 2 f closest to √(r/c) is applied (column i times f, row i divided by f) when it lowers
//! c + r by at least 5 %; sweeps repeat until none does.

use faer::{Mat, MatRef};

/// A step must lower c + r below this fraction of its value to be taken (LAPACK's 0.95).
const STEP_FACTOR: f64 = 0.95;
/// Scales stay within 2^±SCALE_EXP_MAX, far from under- and overflow of any plant entry.
const SCALE_EXP_MAX: i32 = 200;
/// At most this many sweeps (each lowers Σ(c + r) by a factor; convergence takes a few).
const MAX_SWEEPS: usize = 100;

/// Balancing is used for eigenvalues only where it pays: when it lowers ‖A‖_F by more than this
/// factor. Below it, the verification margin 1e-12·‖A‖_F is at most 100 times the balanced one,
/// still 1e-10 relative to the balanced matrix and far below any damping a design aims at, and
/// the matrix is taken as it is, so that verification computes bit for bit the abscissa the
/// optimiser computed (every controller of the committed runs is such a matrix). Badly scaled
/// plants are far beyond it (EB6: 1e4).
pub const BALANCE_GAIN: f64 = 100.0;

/// The matrix to compute `a`'s eigenvalues from: its balanced form ([`balance`]) if that lowers
/// the Frobenius norm by more than [`BALANCE_GAIN`], else `None` (use `a`).
pub fn balanced_for_eigenvalues(a: MatRef<'_, f64>) -> Option<Mat<f64>> {
    balance_if_it_pays(a).map(|(b, _)| b)
}

/// [`balance`]`(a)` (the balanced matrix and the diagonal of D) if it lowers the Frobenius norm
/// by more than [`BALANCE_GAIN`], else `None`: the one test of where balancing pays (the
/// eigenvalues of verification, the H∞ norm's level-set test).
pub fn balance_if_it_pays(a: MatRef<'_, f64>) -> Option<(Mat<f64>, Vec<f64>)> {
    let (b, d) = balance(a);
    (b.norm_l2() * BALANCE_GAIN < a.norm_l2()).then_some((b, d))
}

/// The balanced matrix D⁻¹·A·D and the diagonal of D (powers of 2). Non-finite entries are left
/// as they are (D = I).
pub fn balance(a: MatRef<'_, f64>) -> (Mat<f64>, Vec<f64>) {
    let n = a.nrows();
    let mut b = a.to_owned();
    let mut d = vec![1.0; n];
    if !crate::numeric::all_finite(a) {
        return (b, d);
    }
    for _ in 0..MAX_SWEEPS {
        let mut changed = false;
        for i in 0..n {
            let c = (0..n).map(|k| b[(k, i)] * b[(k, i)]).sum::<f64>().sqrt();
            let r = (0..n).map(|k| b[(i, k)] * b[(i, k)]).sum::<f64>().sqrt();
            if c == 0.0 || r == 0.0 {
                continue;
            }
            let (mut f, mut cs, mut rs) = (1.0_f64, c, r);
            while cs < rs / 2.0 && f < 2f64.powi(SCALE_EXP_MAX) / d[i] {
                f *= 2.0;
                cs *= 2.0;
                rs /= 2.0;
            }
            while cs / 2.0 >= rs && f > 2f64.powi(-SCALE_EXP_MAX) / d[i] {
                f /= 2.0;
                cs /= 2.0;
                rs *= 2.0;
            }
            if f == 1.0 || cs + rs >= STEP_FACTOR * (c + r) {
                continue;
            }
            d[i] *= f;
            for k in 0..n {
                b[(k, i)] *= f;
                b[(i, k)] /= f;
            }
            changed = true;
        }
        if !changed {
            break;
        }
    }
    (b, d)
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// (M, A): A = T·M·T⁻¹ with M a well-scaled 3×3 matrix and T = diag(1, 1e6, 1e-6), so A has
    /// the eigenvalues of M and entries up to 1e12 (this test's and `spectral`'s).
    pub(crate) fn badly_scaled_3x3() -> (Mat<f64>, Mat<f64>) {
        let m = faer::mat![[-1.0, 2.0, 0.5], [-3.0, -1.0, 1.0], [0.25, -0.5, -2.0]];
        let t = [1.0, 1e6, 1e-6];
        let a = Mat::from_fn(3, 3, |i, j| t[i] * m[(i, j)] / t[j]);
        (m, a)
    }

    #[test]
    fn a_badly_scaled_matrix_is_balanced_exactly_with_the_same_eigenvalues() {
        let (m, a) = badly_scaled_3x3();
        let (b, d) = balance(a.as_ref());
        assert!(b.norm_l2() < 10.0 * m.norm_l2(), "{:?}", b);
        assert_eq!(balanced_for_eigenvalues(a.as_ref()), Some(b.clone()));
        assert!(a.norm_l2() > 1e11);
        for i in 0..3 {
            assert_eq!(d[i].log2().fract(), 0.0, "a power of 2");
            for j in 0..3 {
                // exactly D⁻¹ A D
                assert_eq!(b[(i, j)], a[(i, j)] / d[i] * d[j]);
            }
        }
        // the eigenvalues: `spectral`'s test of `verified_spectral_abscissa`
    }

    #[test]
    fn a_balanced_matrix_is_left_as_it_is() {
        let a = faer::mat![[-1.0, 2.0], [-2.0, -1.0]];
        let (b, d) = balance(a.as_ref());
        assert_eq!(d, vec![1.0, 1.0]);
        assert_eq!(b, a);
        let (b, d) = balance(Mat::<f64>::zeros(0, 0).as_ref());
        assert!(d.is_empty() && b.nrows() == 0);
        // an index whose row or column is zero is not scaled (no scale would balance it)
        let z = faer::mat![[0.0, 0.0], [0.0, -1.0]];
        assert_eq!(balance(z.as_ref()), (z.clone(), vec![1.0, 1.0]));
        assert!(balanced_for_eigenvalues(z.as_ref()).is_none());
        // a slightly unbalanced matrix is not worth it
        let s = faer::mat![[-1.0, 300.0], [-1.0, -1.0]];
        assert_ne!(balance(s.as_ref()).1, vec![1.0, 1.0]);
        assert!(balanced_for_eigenvalues(s.as_ref()).is_none());
    }
}
