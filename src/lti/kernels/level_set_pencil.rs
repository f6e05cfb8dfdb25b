//! The H∞ level-set test for γ close to σmax(D), without inverting γ²I − DᵀD.
//!
//! iω is a crossing (γ a singular value of G(iω)) iff λ = iω is a finite eigenvalue of the
//! (2n+m+p) pencil M − λE (unknowns x, q, v, u with G v = γ u, Gᴴ u = γ v):
//! ```text
//!     [ A   0    B    0  ]       [ I       ]
//! M = [ 0  −Aᵀ   0   −Cᵀ ]   E = [   I     ]
//!     [ C   0    D   −γI ]       [     0   ]
//!     [ 0   Bᵀ  −γI   Dᵀ ]       [       0 ]
//! ```
//! Eliminating v, u needs the inverse of [D −γI; −γI Dᵀ], i.e. of γ²I − DᵀD, whose condition
//! κ = γ²/(γ² − σmax(D)²) is the amplification of rounding in the explicit Hamiltonian. Here we
//! use a *shift and invert* instead (the spectral transformation of Ericsson & Ruhe, 1980): for
//! a real shift s > 0 that is not an eigenvalue, T = (M − sE)⁻¹E has the eigenvalues
//! θ = 1/(λ − s) of the finite λ, and 0 for the infinite ones. Only the first 2n columns of E are
//! nonzero, so the nonzero θ are the eigenvalues of the leading 2n×2n block T₁₁ of
//! (M − sE)⁻¹[I₂ₙ; 0]. One LU with partial pivoting of M − sE (backward stable, no ill-conditioned
//! elimination) and one standard 2n×2n eigenvalue problem (faer): no QZ. (faer 0.24's `gevd_real`
//! was tried first and returned β = 0 for almost every eigenvalue on singular E, i.e. lost the
//! crossings.)
//!
//! # Eigenvalues through a skew-Hamiltonian matrix (half the size)
//! T₁₁ = (H − sI)⁻¹ for the Hamiltonian H(γ) (the explicit one of hinf.rs, never formed), and
//! with J = [0 I; −I 0], Hᵀ = JHJ gives J T₁₁ᵀ J = (H + sI)⁻¹. Hence
//! ```text
//! W = T₁₁ − J T₁₁ᵀ J = (H − sI)⁻¹ − (H + sI)⁻¹,   eigenvalues ν = 1/(λ − s) − 1/(λ + s) = 2s/(λ² − s²),
//! ```
//! one per pair ±λ, and W = [W₁₁ W₁₂; W₂₁ W₁₁ᵀ] with W₁₁ = T₁₁¹¹ + T₁₁²²ᵀ, W₁₂ = T₁₁¹² − T₁₁¹²ᵀ,
//! W₂₁ = T₁₁²¹ − T₁₁²¹ᵀ is skew-Hamiltonian *by construction* (exactly, also in floating point),
//! so its n distinct eigenvalues come from Van Loan's PVL reduction and an n×n Hessenberg QR
//! (`square_reduced.rs`) instead of a 2n×2n QR: about a quarter of the work. (This is the
//! skew-Hamiltonian form of the Cayley transform S = (H − sI)⁻¹(H + sI), which is symplectic,
//! S + S⁻¹ = 2I + 2sW; cf. Kressner 2005, §4.) Unlike Van Loan's H², nothing is squared: the
//! errors in ν are of order ε‖W‖ ≤ 2ε‖T₁₁‖, independent of κ.
//!
//! A crossing λ = iω gives ν = −2s/(ω² + s²), real in [−2/s, 0) (ν → 0⁻ as ω → ∞, ν = −2/s at
//! ω = 0), and ω² = −2s/ν − s². A simple real ν stays real under real perturbations; the double ν
//! of a tangent crossing may split into a complex pair at distance √(ε‖W‖²). So ν counts as a
//! crossing if |Im ν| and its distance to [−2/s, 0] are at most [`CIRCLE_TOL_FACTOR`]·√ε·‖W‖_F:
//! loose on purpose, since a spurious crossing costs one evaluation of σmax(G(iω)) whereas a
//! missed one lowers the norm. (Before this, T₁₁'s 2n eigenvalues θ = 1/(λ − s) came from faer's
//! dense solver and were tested against the image circle of the axis, at 4× the cost of the
//! reduction.)
//!
//! The shift is chosen among the system's frequency scale times a few factors; a shift too close
//! to an eigenvalue of the pencil shows as a large ‖T₁₁‖·‖M − sE‖ and the next one is tried.

use faer::linalg::solvers::Solve;
use faer::{Mat, MatRef};

use super::square_reduced::skew_hamiltonian_eigenvalues;
use super::step_stats::{timed, Step};
use crate::lti::system::state_space::StateSpace;

/// Distance to the image [−2/s, 0] of the imaginary axis accepted as a crossing, in units of
/// √ε·‖W‖_F.
const CIRCLE_TOL_FACTOR: f64 = 10.0;
/// A shift s with ‖T₁₁‖_F·‖M − sE‖_F above this is too close to an eigenvalue: try the next.
const MAX_SHIFT_CONDITION: f64 = 1e11;
/// Multipliers of the base shift tried in turn.
const SHIFT_FACTORS: [f64; 4] = [1.0, 3.7, 0.23, 17.0];

/// Sorted-or-not frequencies ω ≥ 0 of the crossings at level γ; `None` if every shift failed.
/// `scale` is a positive frequency typical of the system (e.g. the geometric mean of its pole
/// magnitudes).
///
/// Shifts are tried in the order of [`SHIFT_FACTORS`]; the first well-conditioned one whose
/// crossings can be computed gives the result. If none is, the first ill-conditioned one (with
/// finite T₁₁) whose crossings can be computed does. The crossings of an ill-conditioned shift are
/// only computed when every shift has failed, and from order [`SCREEN_SHIFTS_FROM`] on a shift that
/// [`shifted_inverse`] can reject from a lower bound of ‖T₁₁‖ is not even solved for in full (measured on CM4's converged designs:
/// the first shift failed in two tests of three, and each failure cost a full solve plus a PVL
/// reduction and QR for a fallback that was then not used). The result is the same as computing
/// every tried shift in full.
pub(crate) fn pencil_crossings(sys: &StateSpace, gamma: f64, scale: f64) -> Option<Vec<f64>> {
    let solve = if sys.order() >= SCREEN_SHIFTS_FROM { Elimination::Block } else { Elimination::Full };
    crossings_screened(sys, gamma, scale, solve)
}

/// How [`shifted_inverse`] computes T₁₁.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Elimination {
    /// The LU of the whole pencil (below order [`SCREEN_SHIFTS_FROM`]).
    Full,
    /// The same, rejecting an ill-conditioned shift before the 2n-column solve (as `Block` does
    /// when it falls back to the LU; alone only in the tests).
    #[cfg(test)]
    Screened,
    /// By block elimination ([`block_inverse`]), else as `Screened` (from order
    /// [`SCREEN_SHIFTS_FROM`] on).
    Block,
}

/// From this order on an ill-conditioned shift is rejected before the full solve (below it the
/// full solve costs little more than the screen's four single-column solves).
const SCREEN_SHIFTS_FROM: usize = 30;

/// [`pencil_crossings`], with T₁₁ computed as `solve` says.
fn crossings_screened(sys: &StateSpace, gamma: f64, scale: f64, solve: Elimination) -> Option<Vec<f64>> {
    let base = if scale.is_finite() && scale > 0.0 { scale } else { 1.0 };
    // Ill-conditioned shifts in the order tried, with T₁₁ if it was computed.
    let mut ill: Vec<(f64, Option<Mat<f64>>)> = Vec::new();
    for f in SHIFT_FACTORS {
        let s = base * f;
        match shifted_inverse(sys, gamma, s, solve) {
            ShiftedInverse::Rejected => ill.push((s, None)),
            ShiftedInverse::NotFinite => {}
            ShiftedInverse::Solved { t, well_conditioned: true } => {
                if let Some(ws) = cayley_crossings(t.as_ref(), s) {
                    return Some(ws);
                }
            }
            ShiftedInverse::Solved { t, well_conditioned: false } => ill.push((s, Some(t))),
        }
    }
    ill.into_iter().find_map(|(s, t)| {
        let t = match t {
            Some(t) => t,
            None => match shifted_inverse(sys, gamma, s, Elimination::Full) {
                ShiftedInverse::Solved { t, .. } => t,
                _ => return None,
            },
        };
        cayley_crossings(t.as_ref(), s)
    })
}

/// The outcome of one shift.
enum ShiftedInverse {
    /// T₁₁ = (H − sI)⁻¹ and whether ‖T₁₁‖_F·‖M − sE‖_F ≤ [`MAX_SHIFT_CONDITION`].
    Solved { t: Mat<f64>, well_conditioned: bool },
    /// ‖T₁₁‖_F is not finite.
    NotFinite,
    /// A lower bound of ‖T₁₁‖ already shows the shift ill-conditioned (by a margin of
    /// [`REJECT_MARGIN`] against rounding): T₁₁ was not computed.
    Rejected,
}

/// Factor by which the lower bound of ‖T₁₁‖·‖M − sE‖_F must exceed [`MAX_SHIFT_CONDITION`] to
/// reject a shift without the full solve. The bound and the full ‖T₁₁‖_F come from the same LU,
/// so their rounding differs by far less than this factor: a shift rejected early would have
/// failed the full test too.
const REJECT_MARGIN: f64 = 2.0;

/// T₁₁ = first 2n rows of (M − sE)⁻¹[I₂ₙ; 0] by one LU with partial pivoting of M − sE
/// (module docs). With `screen`, before the 2n-column solve, a lower bound of ‖T₁₁‖₂ ≤ ‖T₁₁‖_F
/// from one and a half power iterations (y = T₁₁x, z = T₁₁ᵀy: ‖y‖/‖x‖ and ‖z‖/‖y‖ are both at
/// most ‖T₁₁‖₂; four single-column solves against 2n) rejects a shift close to an eigenvalue.
fn shifted_inverse(sys: &StateSpace, gamma: f64, s: f64, solve: Elimination) -> ShiftedInverse {
    let n = sys.order();
    let k = 2 * n + sys.inputs() + sys.outputs();
    let screen = solve != Elimination::Full;
    timed(Step::PencilSolve, || {
        let mat = shifted_pencil(sys, gamma, s);
        let m_norm = mat.norm_l2();
        if solve == Elimination::Block {
            if let Some(t) = block_inverse(sys, gamma, s) {
                let t_norm = t.norm_l2();
                return ShiftedInverse::Solved { t, well_conditioned: t_norm * m_norm <= MAX_SHIFT_CONDITION };
            }
        }
        let lu = mat.partial_piv_lu();
        if screen && n > 0 {
            let t_lower = t11_norm_lower_bound(&lu, n, k);
            if t_lower.is_finite() && t_lower * m_norm > REJECT_MARGIN * MAX_SHIFT_CONDITION {
                return ShiftedInverse::Rejected;
            }
        }
        let rhs = Mat::<f64>::from_fn(k, 2 * n, |i, j| if i == j { 1.0 } else { 0.0 });
        let x = lu.solve(rhs);
        let t = x.as_ref().submatrix(0, 0, 2 * n, 2 * n).to_owned();
        let t_norm = t.norm_l2();
        if !t_norm.is_finite() {
            return ShiftedInverse::NotFinite;
        }
        ShiftedInverse::Solved { t, well_conditioned: t_norm * m_norm <= MAX_SHIFT_CONDITION }
    })
}

/// Above this ratio of max(‖P⁻¹‖_F, ‖P⁻¹B̂S⁻¹ĈP⁻¹‖_F) to ‖T₁₁‖_F, [`block_inverse`] leaves
/// T₁₁ to the full LU: its two terms cancelled, and their rounding would not.
const MAX_BLOCK_GROWTH: f64 = 10.0;

/// T₁₁ by block elimination of the pencil's (m+p) rows and columns (from order
/// [`SCREEN_SHIFTS_FROM`] on, where it is cheaper than the full solve): with M − sE = [P B̂; Ĉ R], P = diag(A − sI, −Aᵀ − sI),
/// B̂ = diag(B, −Cᵀ), Ĉ = diag(C, Bᵀ) and R the (m+p) block of the module docs,
/// ```text
/// T₁₁ = P⁻¹ + P⁻¹B̂ S⁻¹ ĈP⁻¹,   S = R − ĈP⁻¹B̂ = [D − C(A − sI)⁻¹B, −γI; −γI, Dᵀ − Bᵀ(A + sI)⁻ᵀCᵀ],
/// ```
/// two n×n LUs and inverses and a rank-(m+p) correction: about a quarter of the flops of the
/// (2n+m+p) LU and its 2n-column solve (CM4's converged designs: 6.5 % of a design run). S is
/// never γ²I − DᵀD (the point of the pencil): it is the Schur complement at the shift, singular
/// only where s is an eigenvalue of H(γ), which the caller's conditioning test rejects. The
/// elimination is stable while neither term is much larger than their sum; `None` (use the full
/// LU) when one is ([`MAX_BLOCK_GROWTH`], e.g. a pole of A near −s) or a factor is singular.
fn block_inverse(sys: &StateSpace, gamma: f64, s: f64) -> Option<Mat<f64>> {
    let (n, m, p) = (sys.order(), sys.inputs(), sys.outputs());
    let id = Mat::<f64>::identity(n, n);
    let x1 = (&sys.a - &id * faer::Scale(s)).partial_piv_lu().solve(&id); // (A − sI)⁻¹
    let x2t = (sys.a.transpose() + &id * faer::Scale(s)).partial_piv_lu().solve(&id); // (A + sI)⁻ᵀ
    let (x1b, cx1) = (&x1 * &sys.b, &sys.c * &x1);
    let (x2tct, btx2t) = (&x2t * sys.c.transpose(), sys.b.transpose() * &x2t);
    // S: rows (p, m), columns (m, p), as R in the module docs.
    let mut sc = Mat::<f64>::zeros(p + m, m + p);
    sc.as_mut().submatrix_mut(0, 0, p, m).copy_from(&sys.d - &sys.c * &x1b);
    sc.as_mut().submatrix_mut(p, m, m, p).copy_from(sys.d.transpose() - sys.b.transpose() * &x2tct);
    for i in 0..p {
        sc[(i, m + i)] = -gamma;
    }
    for i in 0..m {
        sc[(p + i, i)] = -gamma;
    }
    // ĈP⁻¹ (rows p, m; columns n, n) and P⁻¹B̂ (rows n, n; columns m, p).
    let mut v = Mat::<f64>::zeros(p + m, 2 * n);
    v.as_mut().submatrix_mut(0, 0, p, n).copy_from(&cx1);
    v.as_mut().submatrix_mut(p, n, m, n).copy_from(&btx2t * faer::Scale(-1.0));
    let mut u = Mat::<f64>::zeros(2 * n, m + p);
    u.as_mut().submatrix_mut(0, 0, n, m).copy_from(&x1b);
    u.as_mut().submatrix_mut(n, m, n, p).copy_from(&x2tct);
    let correction = &u * sc.partial_piv_lu().solve(&v);
    let t = Mat::<f64>::from_fn(2 * n, 2 * n, |i, j| {
        let diag = match (i < n, j < n) {
            (true, true) => x1[(i, j)],
            (false, false) => -x2t[(i - n, j - n)],
            _ => 0.0,
        };
        diag + correction[(i, j)]
    });
    let p_norm = (x1.squared_norm_l2() + x2t.squared_norm_l2()).sqrt();
    let t_norm = t.norm_l2();
    let growth = p_norm.max(correction.norm_l2()) / t_norm;
    (growth.is_finite() && growth <= MAX_BLOCK_GROWTH).then_some(t)
}

/// max(‖y‖/‖x‖, ‖z‖/‖y‖) ≤ ‖T₁₁‖₂ for y = T₁₁x, z = T₁₁ᵀy (T₁₁ the leading 2n×2n block of
/// (M − sE)⁻¹, whose transpose is the leading block of (M − sE)⁻ᵀ), from a fixed x with entries
/// of varying size and sign (so that it is not orthogonal to a dominant singular vector by
/// accident). NaN if not finite.
fn t11_norm_lower_bound(lu: &faer::linalg::solvers::PartialPivLu<f64>, n: usize, k: usize) -> f64 {
    let x = Mat::<f64>::from_fn(k, 1, |i, _| if i < 2 * n { ((i + 1) as f64).sin() + 0.5 } else { 0.0 });
    let x_norm = x.norm_l2();
    let mut y = lu.solve(x);
    for i in 2 * n..k {
        y[(i, 0)] = 0.0;
    }
    let y_norm = y.norm_l2();
    let z = lu.solve_transpose(y);
    let z_norm = z.as_ref().submatrix(0, 0, 2 * n, 1).norm_l2();
    let bound = (y_norm / x_norm).max(z_norm / y_norm);
    if bound.is_finite() {
        bound
    } else {
        f64::NAN
    }
}

/// M − sE of the module docs.
fn shifted_pencil(sys: &StateSpace, gamma: f64, s: f64) -> Mat<f64> {
    let (n, m, p) = (sys.order(), sys.inputs(), sys.outputs());
    let k = 2 * n + m + p;
    let mut a = Mat::<f64>::zeros(k, k);
    // columns: x (0), q (n), v (2n, m wide), u (2n+m, p wide);
    // rows: ẋ (0), q̇ (n), Cx + Dv − γu (2n, p rows), Bᵀq + Dᵀu − γv (2n+p, m rows)
    let (iq, cv, cu, r3, r4) = (n, 2 * n, 2 * n + m, 2 * n, 2 * n + p);
    a.as_mut().submatrix_mut(0, 0, n, n).copy_from(&sys.a);
    a.as_mut().submatrix_mut(0, cv, n, m).copy_from(&sys.b);
    a.as_mut().submatrix_mut(iq, iq, n, n).copy_from(sys.a.transpose() * faer::Scale(-1.0));
    a.as_mut().submatrix_mut(iq, cu, n, p).copy_from(sys.c.transpose() * faer::Scale(-1.0));
    a.as_mut().submatrix_mut(r3, 0, p, n).copy_from(&sys.c);
    a.as_mut().submatrix_mut(r3, cv, p, m).copy_from(&sys.d);
    a.as_mut().submatrix_mut(r4, iq, m, n).copy_from(sys.b.transpose());
    a.as_mut().submatrix_mut(r4, cu, m, p).copy_from(sys.d.transpose());
    for i in 0..p {
        a[(r3 + i, cu + i)] = -gamma;
    }
    for i in 0..m {
        a[(r4 + i, cv + i)] = -gamma;
    }
    for i in 0..2 * n {
        a[(i, i)] -= s;
    }
    a
}

/// The crossings from T = (H − sI)⁻¹ (2n×2n, H Hamiltonian) through the skew-Hamiltonian
/// W = T − J Tᵀ J (module docs); `None` if the eigensolver fails.
fn cayley_crossings(t: MatRef<'_, f64>, s: f64) -> Option<Vec<f64>> {
    let n = t.nrows() / 2;
    let (t11, t12, t21, t22) =
        (t.submatrix(0, 0, n, n), t.submatrix(0, n, n, n), t.submatrix(n, 0, n, n), t.submatrix(n, n, n, n));
    let w11 = t11 + t22.transpose();
    let w12 = t12 - t12.transpose();
    let w21 = t21 - t21.transpose();
    let w_norm = (2.0 * w11.squared_norm_l2() + w12.squared_norm_l2() + w21.squared_norm_l2()).sqrt();
    let nu = skew_hamiltonian_eigenvalues(w11.as_ref(), w12.as_ref(), w21.as_ref())?;
    let tol = CIRCLE_TOL_FACTOR * f64::EPSILON.sqrt() * w_norm;
    Some(
        nu.iter()
            .filter(|v| v.im.abs() <= tol && v.re >= -2.0 / s - tol && v.re <= tol)
            .map(|v| if v.re < 0.0 { (-2.0 * s / v.re - s * s).max(0.0).sqrt() } else { f64::INFINITY })
            .collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lti::kernels::freq_response::FreqResponse;
    use faer::linalg::solvers::DenseSolveCore;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, StandardNormal};

    /// G = D + δ·G₀ with σmax(D) = 1 (so κ is large at every γ below the peak), stable A.
    fn near_d_system(n: usize, m: usize, p: usize, delta: f64, seed: u64) -> StateSpace {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut r = |rows: usize, cols: usize, s: f64| {
            Mat::<f64>::from_fn(rows, cols, |_, _| {
                let z: f64 = StandardNormal.sample(&mut rng);
                s * z
            })
        };
        let mut a = r(n, n, 1.0 / (n as f64).sqrt());
        for i in 0..n {
            a[(i, i)] -= 1.3;
        }
        let (b, c, d) = (r(n, m, 1.0), r(p, n, delta), r(p, m, 1.0));
        let sd = d.singular_values().unwrap()[0];
        StateSpace { a, b, c, d: d * faer::Scale(1.0 / sd) }
    }

    /// A shift on a real eigenvalue of H(γ) is rejected from the lower bound of ‖T₁₁‖ alone, the
    /// bound never exceeds ‖T₁₁‖_F, and the crossings are exactly those of the unscreened path.
    #[test]
    fn ill_conditioned_shift_is_rejected_early_with_the_same_crossings() {
        let sys = near_d_system(12, 2, 3, 1e-2, 3);
        let mut fr = FreqResponse::new(&sys);
        let peak = (0..2000).map(|k| fr.sigma_max(10f64.powf(-3.0 + 6.0 * k as f64 / 2000.0))).fold(0.0, f64::max);
        let gamma = 1.0 + 0.5 * (peak - 1.0).abs();
        // T₁₁ = (H − sI)⁻¹ at a generic shift gives H = s I + T₁₁⁻¹: its real positive eigenvalues.
        let n = sys.order();
        let ShiftedInverse::Solved { t, .. } = shifted_inverse(&sys, gamma, 1.3, Elimination::Full) else {
            panic!("no inverse")
        };
        let h = t.partial_piv_lu().inverse() + Mat::<f64>::identity(2 * n, 2 * n) * faer::Scale(1.3);
        let ev = crate::lti::kernels::spectral::eigenvalues(h.as_ref()).unwrap();
        let real = ev.iter().filter(|l| l.im == 0.0 && l.re > 0.0).map(|l| l.re).next().expect("a real eigenvalue");
        for (s, expect_rejected) in [(real, true), (1.3, false), (0.7 * real, false)] {
            let mat = shifted_pencil(&sys, gamma, s);
            let k = mat.nrows();
            let lu = mat.partial_piv_lu();
            let lb = t11_norm_lower_bound(&lu, n, k);
            let full = lu.solve(Mat::<f64>::from_fn(k, 2 * n, |i, j| if i == j { 1.0 } else { 0.0 }));
            let t_norm = full.as_ref().submatrix(0, 0, 2 * n, 2 * n).norm_l2();
            assert!(lb <= t_norm * (1.0 + 1e-10), "s = {s}: bound {lb:e} above ‖T‖_F {t_norm:e}");
            let rejected = matches!(shifted_inverse(&sys, gamma, s, Elimination::Screened), ShiftedInverse::Rejected);
            assert_eq!(rejected, expect_rejected, "s = {s}: bound {lb:e}, ‖T‖_F {t_norm:e}");
            // Every shift order starting at s: the same crossings, bit for bit.
            let (screened, full) = (
                crossings_screened(&sys, gamma, s, Elimination::Screened),
                crossings_screened(&sys, gamma, s, Elimination::Full),
            );
            assert_eq!(screened, full, "s = {s}");
            // By block elimination: the same crossings to rounding.
            let block = crossings_screened(&sys, gamma, s, Elimination::Block).unwrap();
            assert_close(&block, &full.unwrap(), 1e-9, &format!("s = {s}"));
        }
    }

    fn assert_close(got: &[f64], want: &[f64], rtol: f64, what: &str) {
        let (mut got, mut want) = (got.to_vec(), want.to_vec());
        got.sort_by(f64::total_cmp);
        want.sort_by(f64::total_cmp);
        assert_eq!(got.len(), want.len(), "{what}: {got:?} vs {want:?}");
        for (g, w) in got.iter().zip(&want) {
            assert!(g == w || (g - w).abs() <= rtol * w.abs(), "{what}: {got:?} vs {want:?}");
        }
    }

    /// T₁₁ by block elimination is the full LU's to rounding (relative to ‖T₁₁‖), at shifts
    /// below, at and above the system's frequencies, for square and non-square D; and a shift on
    /// a pole of −A (where the block's P is singular) is left to the full LU.
    #[test]
    fn block_elimination_matches_the_full_lu() {
        for (seed, (n, m, p, delta)) in
            [(31usize, 2usize, 3usize, 1e-3), (40, 1, 1, 1e-1), (45, 3, 2, 1e-5)].into_iter().enumerate()
        {
            let sys = near_d_system(n, m, p, delta, 100 + seed as u64);
            for (gamma, s) in [(1.0 + 0.3 * delta, 0.4), (1.0 + 2.0 * delta, 1.3), (1.5, 7.0)] {
                let ShiftedInverse::Solved { t: full, .. } = shifted_inverse(&sys, gamma, s, Elimination::Full) else {
                    panic!("no inverse")
                };
                let block = block_inverse(&sys, gamma, s).expect("block elimination");
                let err = (&block - &full).norm_l2() / full.norm_l2();
                assert!(err <= 1e-10, "n = {n}, γ = {gamma}, s = {s}: {err:e}");
            }
        }
        // A real pole at −s of A: A + sI singular.
        let mut sys = near_d_system(31, 2, 2, 1e-2, 7);
        sys.a = Mat::from_fn(31, 31, |i, j| {
            if i == j {
                -1.0 - i as f64 * 0.1
            } else if j == i + 1 {
                0.3
            } else {
                0.0
            }
        });
        assert!(block_inverse(&sys, 1.01, 1.0).is_none(), "a pole at −s must be left to the full LU");
        assert!(matches!(shifted_inverse(&sys, 1.01, 1.0, Elimination::Block), ShiftedInverse::Solved { .. }));
    }

    #[test]
    fn crossings_are_frequencies_where_gamma_is_a_singular_value() {
        for (seed, (n, m, p, delta)) in
            [(6usize, 2usize, 3usize, 1e-3), (9, 3, 3, 1e-4), (12, 1, 2, 1e-2)].into_iter().enumerate()
        {
            let sweep = |fr: &mut FreqResponse| {
                (0..4000).map(|k| fr.sigma_max(10f64.powf(-3.0 + 6.0 * k as f64 / 4000.0))).fold(0.0, f64::max)
            };
            let mut sys = near_d_system(n, m, p, delta, seed as u64);
            if sweep(&mut FreqResponse::new(&sys)) <= 1.0 {
                sys.c = &sys.c * faer::Scale(-1.0); // δ·G₀ only lowered σmax(D): flip it
            }
            let mut fr = FreqResponse::new(&sys);
            // A level halfway between σmax(D) = 1 and the sweep's peak: crossings must exist.
            let peak = sweep(&mut fr);
            assert!(peak > 1.0 + 1e-12, "seed {seed}: no peak above σmax(D)");
            let gamma = 0.5 * (1.0 + peak);
            let ws = pencil_crossings(&sys, gamma, 1.3).unwrap();
            // σ(∞) = 1 < γ: an odd count iff the response starts above γ at ω = 0.
            let odd = fr.sigma_max(0.0) > gamma;
            assert!(!ws.is_empty() && (ws.len() % 2 == 1) == odd, "seed {seed}: crossings {ws:?}");
            for &w in &ws {
                let sv = fr.eval(w).singular_values().unwrap();
                let off = sv.iter().map(|s| (s - gamma).abs()).fold(f64::INFINITY, f64::min);
                assert!(off <= 1e-6 * (peak - 1.0), "seed {seed}: ω = {w}: σ = {sv:?}, γ = {gamma}");
            }
            // Above the peak: none.
            assert!(pencil_crossings(&sys, peak * (1.0 + 1e-3 * (peak - 1.0)) + 1e-3 * (peak - 1.0), 1.3)
                .unwrap()
                .is_empty());
        }
    }
}
