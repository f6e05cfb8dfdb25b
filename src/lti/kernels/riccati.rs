//! Stabilising solution of the continuous algebraic Riccati equation (CARE) by the matrix sign
//! function.
//!
//! Solves, for symmetric `G` (possibly indefinite, as in H∞ problems) and symmetric `Q`,
//!
//! ```text
//! Aᵀ X + X A − X G X + Q = 0,        A − G X stable,
//! ```
//!
//! through the Hamiltonian `H = [A, −G; −Q, −Aᵀ]`: if `H` has no eigenvalue on the imaginary axis
//! its stable invariant subspace is n-dimensional, and if that subspace is the graph
//! `span [I; X]` then `X` is the (unique, symmetric) stabilising solution, `X = Ric(H)` in the
//! notation of Doyle–Glover–Khargonekar–Francis (IEEE TAC 34(8), 1989).
//!
//! # Method (docs/ALGORITHMS.md §9.2)
//!
//! No Rust crate offers an ordered real Schur form, so the stable subspace is obtained from the
//! matrix sign function `S = sign(H)` (Roberts 1971; Byers 1987; Kenney–Laub 1995), computed by the
//! Newton iteration with determinant scaling
//!
//! ```text
//! Z₀ = H,   Z_{k+1} = (Z_k / c_k + c_k Z_k⁻¹) / 2,   c_k = |det Z_k|^{1/(2n)},
//! ```
//!
//! (scaling switched off once the iteration is close, to keep its quadratic convergence), until
//! the relative change is below [`SIGN_TOL`] or, below [`SIGN_STAGNATION_TOL`], stops decreasing
//! (rounding-level stagnation on ill-conditioned problems). The
//! stable subspace is `ker(S + I)`, so `X` solves the overdetermined consistent system
//! `[S₁₂; S₂₂ + I] X = −[S₁₁ + I; S₂₁]` (least squares by QR), then is symmetrised.
//!
//! Before iterating, `H` is balanced by a *symplectic* diagonal similarity `T = diag(D, D⁻¹)`
//! (powers of two, so exact): `A → D⁻¹AD`, `G → D⁻¹GD⁻¹`, `Q → DQD`, reducing ‖H‖_F. This matters
//! for the δ-regularised H∞ problems of [`crate::lti::synthesis::full_order`], whose `G` holds entries ~ 1/δ²:
//! unbalanced, eigenvalues close to the imaginary axis lose accuracy like √(u‖H‖). The balanced
//! solution is `X̃ = D X D`.
//!
//! # Checks (each failure is a typed [`RiccatiError`])
//!
//! * inputs and iterates finite;
//! * the sign iteration converges within [`SIGN_MAX_ITER`] and `trace S ≈ 0` (n eigenvalues on each
//!   side): otherwise `H` has (numerically) imaginary-axis eigenvalues — [`RiccatiError::NoDichotomy`];
//! * the relative residual `‖AᵀX + XA − XGX + Q‖_F / (2‖A‖‖X‖ + ‖X‖²‖G‖ + ‖Q‖)` is at most
//!   [`CARE_RESIDUAL_TOL`] — otherwise the stable subspace is not (numerically) a graph or the
//!   problem is too ill-conditioned — [`RiccatiError::Residual`]. Except: when the exact X is 0
//!   (Q = 0 and A stable, e.g. the filter equation of a plant with a square D21,
//!   `synthesis/full_order/exogenous_weights.rs`), the computed X is rounding noise (~1e-26) and
//!   that relative residual, normalised by ‖X‖, is O(1) however exact the subspace; so a
//!   solution whose stable subspace `[I; X]` of the balanced Hamiltonian has a backward error
//!   `‖H[I; X] − [I; X](A − GX)‖_F / (‖H‖_F (1 + ‖X‖²_F))` of at most [`SUBSPACE_RESIDUAL_TOL`]
//!   is accepted as well (measured: 1e-26…1e-32 on such X ≈ 0 cases, 1e-7…1e-2 on the genuine
//!   refusals of the γ-iteration);
//! * `A − GX` is stable: its spectral abscissa is negative — [`RiccatiError::NotStabilising`].
//!
//! # Known failure modes
//! Eigenvalues of `H` within about `√u·‖H‖` of the imaginary axis make the iteration slow or wrong
//! (reported as `NoDichotomy` or `Residual`); a stable subspace that is almost not a graph (‖X‖
//! huge) fails the residual test. Both are *correct* refusals for the γ-iteration, which treats
//! them as "γ infeasible".

use faer::linalg::solvers::{DenseSolveCore, SolveLstsq};
use faer::{Mat, MatRef};

use crate::numeric::all_finite;

/// Relative change ‖Z_{k+1} − Z_k‖_F / ‖Z_{k+1}‖_F below which the sign iteration has converged.
pub(crate) const SIGN_TOL: f64 = 1e-12;
/// Relative change below which determinant scaling is switched off (the iteration is then in its
/// quadratically convergent regime, where scaling only slows it).
const SIGN_UNSCALED_BELOW: f64 = 1e-2;
/// Once the relative change is below this, the iteration is also stopped when the change no longer
/// shrinks by at least half (rounding-error stagnation of an ill-conditioned but dichotomic
/// Hamiltonian; the residual test then decides).
pub(crate) const SIGN_STAGNATION_TOL: f64 = 1e-7;
/// Maximum number of sign-function iterations. Well-separated spectra need 8–20; slow convergence
/// beyond this means eigenvalues (numerically) on the imaginary axis.
pub(crate) const SIGN_MAX_ITER: usize = 60;
/// Accepted |trace sign(H)| (exact value 0 for a Hamiltonian without imaginary-axis eigenvalues;
/// any wrong count changes it by 2).
const TRACE_TOL: f64 = 0.5;
/// Maximum relative CARE residual (see the module docs for the normalisation).
pub(crate) const CARE_RESIDUAL_TOL: f64 = 1e-8;
/// Maximum backward error of the stable subspace (see [`solve_care`]) accepted when the relative
/// residual exceeds [`CARE_RESIDUAL_TOL`].
pub(crate) const SUBSPACE_RESIDUAL_TOL: f64 = 1e-13;
/// Maximum number of sweeps of the symplectic balancing.
const BALANCE_MAX_SWEEPS: usize = 30;
/// A balancing step is taken only if it reduces the affected part of ‖H‖²_F below this factor.
const BALANCE_GAIN: f64 = 0.95;

/// The stabilising solution of a CARE with its diagnostics.
#[derive(Debug, Clone)]
pub struct CareSolution {
    /// The symmetric stabilising solution X.
    pub x: Mat<f64>,
    /// Sign-function iterations used.
    pub iterations: usize,
    /// Relative residual (see the module docs; above its tolerance 1e-8 only for a solution
    /// accepted by its subspace backward error).
    pub residual: f64,
    /// Spectral abscissa of the closed loop `A − G X` (negative).
    pub closed_loop_abscissa: f64,
}

/// Why a CARE has no (numerically trustworthy) stabilising solution.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum RiccatiError {
    /// Input matrices of inconsistent sizes.
    #[error("CARE shape mismatch: A is {a:?}, G is {g:?}, Q is {q:?} (all must be n×n)")]
    Shape {
        /// Shape of A.
        a: (usize, usize),
        /// Shape of G.
        g: (usize, usize),
        /// Shape of Q.
        q: (usize, usize),
    },
    /// A NaN or infinity in the data or in an iterate.
    #[error("non-finite value in the CARE ({stage})")]
    NonFinite {
        /// Where it appeared.
        stage: &'static str,
    },
    /// The Hamiltonian has (numerically) eigenvalues on the imaginary axis: the sign iteration did
    /// not converge, or converged to the wrong inertia.
    #[error("Hamiltonian has no stable/antistable dichotomy (sign iteration: {iterations} iterations, trace {trace:.3}, last relative change {change:.2e})")]
    NoDichotomy {
        /// Iterations done.
        iterations: usize,
        /// trace of the last iterate (0 expected).
        trace: f64,
        /// Last relative change.
        change: f64,
    },
    /// The computed X does not satisfy the equation (the stable subspace is not a graph, or the
    /// problem is too ill-conditioned).
    #[error("CARE relative residual {residual:.2e} exceeds {tol:.0e}")]
    Residual {
        /// Relative residual.
        residual: f64,
        /// Tolerance.
        tol: f64,
    },
    /// A − GX is not stable.
    #[error("CARE solution is not stabilising: spectral abscissa of A − GX is {abscissa:.3e}")]
    NotStabilising {
        /// Spectral abscissa of A − GX.
        abscissa: f64,
    },
}

/// Stabilising solution of `AᵀX + XA − XGX + Q = 0` (G, Q symmetric; only their symmetric parts
/// are used). See the module docs for the method and the checks.
pub fn solve_care(a: MatRef<'_, f64>, g: MatRef<'_, f64>, q: MatRef<'_, f64>) -> Result<CareSolution, RiccatiError> {
    let n = a.nrows();
    if a.ncols() != n || g.nrows() != n || g.ncols() != n || q.nrows() != n || q.ncols() != n {
        return Err(RiccatiError::Shape {
            a: (a.nrows(), a.ncols()),
            g: (g.nrows(), g.ncols()),
            q: (q.nrows(), q.ncols()),
        });
    }
    if !(all_finite(a) && all_finite(g) && all_finite(q)) {
        return Err(RiccatiError::NonFinite { stage: "input" });
    }
    if n == 0 {
        return Ok(CareSolution {
            x: Mat::zeros(0, 0),
            iterations: 0,
            residual: 0.0,
            closed_loop_abscissa: f64::NEG_INFINITY,
        });
    }
    let gs = symmetrise(g);
    let qs = symmetrise(q);

    // Symplectic balancing (exact: powers of two).
    let d = balance_scaling(a, gs.as_ref(), qs.as_ref());
    let ab = Mat::from_fn(n, n, |i, j| a[(i, j)] * d[j] / d[i]);
    let gb = Mat::from_fn(n, n, |i, j| gs[(i, j)] / (d[i] * d[j]));
    let qb = Mat::from_fn(n, n, |i, j| qs[(i, j)] * d[i] * d[j]);

    let h = Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
        (true, true) => ab[(i, j)],
        (true, false) => -gb[(i, j - n)],
        (false, true) => -qb[(i - n, j)],
        (false, false) => -ab[(j - n, i - n)],
    });
    let (s, iterations) = sign_function(h)?;

    // Stable subspace = ker(S + I): [S12; S22 + I] X = −[S11 + I; S21].
    let lhs = Mat::from_fn(2 * n, n, |i, j| s[(i, n + j)] + if i == n + j { 1.0 } else { 0.0 });
    let rhs = Mat::from_fn(2 * n, n, |i, j| -(s[(i, j)] + if i == j { 1.0 } else { 0.0 }));
    let xb = lhs.qr().solve_lstsq(&rhs);
    if !all_finite(xb.as_ref()) {
        return Err(RiccatiError::NonFinite { stage: "stable subspace solve" });
    }
    // Undo balancing: X̃ = D X D.
    let x = Mat::from_fn(n, n, |i, j| 0.5 * (xb[(i, j)] + xb[(j, i)]) / (d[i] * d[j]));

    let residual = care_residual(a, gs.as_ref(), qs.as_ref(), x.as_ref());
    if !(residual <= CARE_RESIDUAL_TOL) {
        let xbs = symmetrise(xb.as_ref());
        let subspace = subspace_residual(ab.as_ref(), gb.as_ref(), qb.as_ref(), xbs.as_ref());
        if !(subspace <= SUBSPACE_RESIDUAL_TOL) {
            return Err(RiccatiError::Residual { residual, tol: CARE_RESIDUAL_TOL });
        }
    }
    let acl = a - &gs * &x;
    let closed_loop_abscissa = abscissa(acl.as_ref());
    if !super::spectral::is_stable(closed_loop_abscissa) {
        return Err(RiccatiError::NotStabilising { abscissa: closed_loop_abscissa });
    }
    Ok(CareSolution { x, iterations, residual, closed_loop_abscissa })
}

/// Relative residual ‖AᵀX + XA − XGX + Q‖_F / (2‖A‖_F‖X‖_F + ‖X‖²_F‖G‖_F + ‖Q‖_F).
pub fn care_residual(a: MatRef<'_, f64>, g: MatRef<'_, f64>, q: MatRef<'_, f64>, x: MatRef<'_, f64>) -> f64 {
    let xa = x * a;
    let r = xa.transpose() + &xa - x * g * x + q;
    let (na, nx, ng, nq) = (a.norm_l2(), x.norm_l2(), g.norm_l2(), q.norm_l2());
    let scale = 2.0 * na * nx + nx * nx * ng + nq;
    if scale == 0.0 {
        return r.norm_l2();
    }
    r.norm_l2() / scale
}

/// Backward error of the stable subspace `span [I; X]` of the balanced Hamiltonian `H`:
/// `‖H [I; X] − [I; X] (A − G X)‖_F / (‖H‖_F (1 + ‖X‖²_F))`; the first block row vanishes, the
/// second is minus the CARE residual.
fn subspace_residual(a: MatRef<'_, f64>, g: MatRef<'_, f64>, q: MatRef<'_, f64>, x: MatRef<'_, f64>) -> f64 {
    let xa = x * a;
    let r = xa.transpose() + &xa - x * g * x + q;
    let (na, ng, nq, nx) = (a.norm_l2(), g.norm_l2(), q.norm_l2(), x.norm_l2());
    let nh = (2.0 * na * na + ng * ng + nq * nq).sqrt();
    if nh == 0.0 {
        return r.norm_l2();
    }
    r.norm_l2() / (nh * (1.0 + nx * nx))
}

/// Matrix sign function of the Hamiltonian `z` (2n × 2n): [`sign_iteration`], then the inertia
/// check trace S ≈ 0 (n eigenvalues on each side).
fn sign_function(z: Mat<f64>) -> Result<(Mat<f64>, usize), RiccatiError> {
    let (s, it, change) = sign_iteration(z)?;
    let tr = trace(s.as_ref());
    if tr.abs() > TRACE_TOL {
        return Err(RiccatiError::NoDichotomy { iterations: it, trace: tr, change });
    }
    Ok((s, it))
}

/// Matrix sign function of any square `z` without eigenvalues on the imaginary axis, by the
/// scaled Newton iteration of the module docs; returns (S, iterations, last relative change).
/// Also used for Lyapunov equations and stable/antistable splittings (`lti::lyapunov`).
pub(crate) fn sign_iteration(mut z: Mat<f64>) -> Result<(Mat<f64>, usize, f64), RiccatiError> {
    let m = z.nrows();
    let mut scaled = true;
    let mut change = f64::INFINITY;
    for it in 1..=SIGN_MAX_ITER {
        let lu = z.partial_piv_lu();
        let log_det: f64 = (0..m).map(|i| lu.U()[(i, i)].abs().ln()).sum();
        if !log_det.is_finite() {
            // Singular iterate: an eigenvalue (numerically) at 0, i.e. on the imaginary axis.
            return Err(RiccatiError::NoDichotomy { iterations: it, trace: trace(z.as_ref()), change });
        }
        let zi = lu.inverse();
        let c = if scaled { (log_det / m as f64).exp() } else { 1.0 };
        let znew = Mat::from_fn(m, m, |i, j| 0.5 * (z[(i, j)] / c + c * zi[(i, j)]));
        if !all_finite(znew.as_ref()) {
            return Err(RiccatiError::NonFinite { stage: "sign iteration" });
        }
        let prev_change = change;
        change = (&znew - &z).norm_l2() / znew.norm_l2();
        z = znew;
        if change < SIGN_UNSCALED_BELOW {
            scaled = false;
        }
        let stagnated = change <= SIGN_STAGNATION_TOL && change > 0.5 * prev_change;
        if change <= SIGN_TOL || stagnated {
            return Ok((z, it, change));
        }
    }
    Err(RiccatiError::NoDichotomy { iterations: SIGN_MAX_ITER, trace: trace(z.as_ref()), change })
}

/// Diagonal D (powers of two) of the symplectic balancing `diag(D, D⁻¹)` of `[A, −G; −Q, −Aᵀ]`,
/// reducing its Frobenius norm one coordinate at a time (in the spirit of LAPACK `dgebal` and
/// Benner's symplectic balancing). Scaling state i by f multiplies column i of A by f and row i
/// by 1/f (each appearing twice in H), the off-diagonal row/column i of G by 1/f and of Q by f,
/// and their diagonal entries by 1/f² and f².
pub(crate) fn balance_scaling(a: MatRef<'_, f64>, g: MatRef<'_, f64>, q: MatRef<'_, f64>) -> Vec<f64> {
    let n = a.nrows();
    let mut a = a.to_owned();
    let mut g = g.to_owned();
    let mut q = q.to_owned();
    let mut d = vec![1.0; n];
    for _ in 0..BALANCE_MAX_SWEEPS {
        let mut changed = false;
        for i in 0..n {
            let (mut up2, mut down2, mut up4, mut down4) = (0.0, 0.0, 0.0, 0.0);
            for k in 0..n {
                if k != i {
                    up2 += 2.0 * a[(k, i)].powi(2) + 2.0 * q[(k, i)].powi(2);
                    down2 += 2.0 * a[(i, k)].powi(2) + 2.0 * g[(k, i)].powi(2);
                }
            }
            up4 += q[(i, i)].powi(2);
            down4 += g[(i, i)].powi(2);
            let cost = |f: f64| up2 * f * f + down2 / (f * f) + up4 * f.powi(4) + down4 / f.powi(4);
            let base = cost(1.0);
            // One side empty: the cost falls monotonically towards f = 0 or ∞ (a decoupled
            // state, which LAPACK isolates by permutation): leave that coordinate alone.
            if base == 0.0 || !base.is_finite() || up2 + up4 == 0.0 || down2 + down4 == 0.0 {
                continue;
            }
            // Walk by factors of two while the cost keeps dropping.
            let mut f = 1.0;
            for step in [2.0, 0.5] {
                let mut trial = f * step;
                while cost(trial) < BALANCE_GAIN * cost(f) && trial.abs() < 1e150 && trial > 1e-150 {
                    f = trial;
                    trial *= step;
                }
                if f != 1.0 {
                    break;
                }
            }
            if f != 1.0 {
                changed = true;
                d[i] *= f;
                for k in 0..n {
                    a[(k, i)] *= f;
                    a[(i, k)] /= f;
                    g[(k, i)] /= f;
                    g[(i, k)] /= f;
                    q[(k, i)] *= f;
                    q[(i, k)] *= f;
                }
            }
        }
        if !changed {
            break;
        }
    }
    d
}

/// Spectral abscissa of a square matrix (+∞ if the eigenvalue solver fails).
pub(crate) fn abscissa(m: MatRef<'_, f64>) -> f64 {
    if m.nrows() == 0 {
        return f64::NEG_INFINITY;
    }
    match m.eigenvalues() {
        Ok(ev) => ev.iter().map(|l| l.re).fold(f64::NEG_INFINITY, f64::max),
        Err(_) => f64::INFINITY,
    }
}

fn symmetrise(m: MatRef<'_, f64>) -> Mat<f64> {
    Mat::from_fn(m.nrows(), m.ncols(), |i, j| 0.5 * (m[(i, j)] + m[(j, i)]))
}

fn trace(m: MatRef<'_, f64>) -> f64 {
    (0..m.nrows()).map(|i| m[(i, i)]).sum()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn random(rng: &mut ChaCha8Rng, r: usize, c: usize) -> Mat<f64> {
        Mat::from_fn(r, c, |_, _| rng.random_range(-1.0..1.0))
    }

    /// LQR-type CARE on seeded random systems: residual, symmetry, X ⪰ 0, stabilising.
    #[test]
    fn random_lqr_care_residuals() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for &n in &[1usize, 2, 5, 10, 20, 40] {
            for _ in 0..3 {
                let a = random(&mut rng, n, n);
                let b = random(&mut rng, n, (n / 4).max(1));
                let c = random(&mut rng, (n / 4).max(1), n);
                let g = &b * b.transpose();
                let q = c.transpose() * &c;
                let sol = solve_care(a.as_ref(), g.as_ref(), q.as_ref()).expect("LQR CARE solvable");
                assert!(sol.residual < 1e-12 * (n as f64).sqrt().max(1.0) * 10.0, "n={n}: residual {}", sol.residual);
                assert!(sol.closed_loop_abscissa < 0.0);
                let ev = sol.x.self_adjoint_eigenvalues(faer::Side::Lower).unwrap();
                assert!(ev[0] >= -1e-10 * ev[n - 1].abs().max(1.0), "X not PSD: {ev:?}");
            }
        }
    }

    /// Indefinite G (H∞-type) with a known solution: scalar a x² form.
    #[test]
    fn scalar_closed_form() {
        // 2 a x − g x² + q = 0, stabilising root: x = (a + sqrt(a² + g q)) / g.
        for &(a, g, q) in &[(1.0f64, 1.0f64, 1.0f64), (-2.0, 0.5, 3.0), (-1.0, -0.5, 1.0), (0.3, 2.0, 0.0)] {
            let x_true = if g != 0.0 { (a + (a * a + g * q).sqrt()) / g } else { 0.0 };
            let sol = solve_care(
                Mat::from_fn(1, 1, |_, _| a).as_ref(),
                Mat::from_fn(1, 1, |_, _| g).as_ref(),
                Mat::from_fn(1, 1, |_, _| q).as_ref(),
            )
            .unwrap();
            assert!((sol.x[(0, 0)] - x_true).abs() <= 1e-13 * x_true.abs().max(1.0), "{a} {g} {q}");
        }
    }

    /// Badly scaled G (entries ~ 1/δ²) as produced by the D21 regularisation: balancing keeps the
    /// residual small.
    #[test]
    fn badly_scaled_care() {
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let n = 8;
        let a = random(&mut rng, n, n);
        let c = random(&mut rng, 2, n);
        let b = random(&mut rng, n, 3);
        let delta: f64 = 1e-6;
        let g = c.transpose() * &c * faer::Scale(1.0 / (delta * delta));
        let q = &b * b.transpose();
        let sol = solve_care(a.transpose(), g.as_ref(), q.as_ref()).expect("solvable");
        assert!(sol.residual < 1e-10, "residual {}", sol.residual);
    }

    /// Q = 0 with A stable: the stabilising solution is X = 0 (closed form), whatever G. The
    /// computed X is rounding noise, accepted through its subspace backward error (its relative
    /// residual, normalised by ‖X‖, can be O(1): the γ-test of a plant with a square D21).
    #[test]
    fn zero_constant_term_with_stable_a_gives_zero() {
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for &n in &[2usize, 4, 7, 12] {
            for _ in 0..5 {
                let mut a = random(&mut rng, n, n);
                let shift = abscissa(a.as_ref()) + 0.1;
                for i in 0..n {
                    a[(i, i)] -= shift;
                }
                let b = random(&mut rng, n, 2);
                let c = random(&mut rng, 1, n);
                let g = &b * b.transpose() - c.transpose() * &c * faer::Scale(0.3);
                let q = Mat::<f64>::zeros(n, n);
                let sol = solve_care(a.as_ref(), g.as_ref(), q.as_ref()).expect("X = 0 is the solution");
                assert!(sol.x.norm_l2() <= 1e-12, "n = {n}: ‖X‖ = {:e}", sol.x.norm_l2());
            }
        }
    }

    /// Imaginary-axis eigenvalues: H = [0 −1; 1 0]-type (a = 0, g = −1, q = 1 → x² + 1 = 0).
    #[test]
    fn no_solution_is_an_error() {
        let one = |v: f64| Mat::from_fn(1, 1, |_, _| v);
        let r = solve_care(one(0.0).as_ref(), one(-1.0).as_ref(), one(1.0).as_ref());
        assert!(matches!(r, Err(RiccatiError::NoDichotomy { .. })), "{r:?}");
        let r = solve_care(one(f64::NAN).as_ref(), one(1.0).as_ref(), one(1.0).as_ref());
        assert!(matches!(r, Err(RiccatiError::NonFinite { .. })), "{r:?}");
    }
}
