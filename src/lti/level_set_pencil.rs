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
//! crossings: issue 13.)
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
//! reduction: issue 13.)
//!
//! The shift is chosen among the system's frequency scale times a few factors; a shift too close
//! to an eigenvalue of the pencil shows as a large ‖T₁₁‖·‖M − sE‖ and the next one is tried.

use faer::linalg::solvers::Solve;
use faer::{Mat, MatRef};

use super::square_reduced::skew_hamiltonian_eigenvalues;
use super::step_stats::{timed, Step};
use super::StateSpace;

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
pub(crate) fn pencil_crossings(sys: &StateSpace, gamma: f64, scale: f64) -> Option<Vec<f64>> {
    let (n, m, p) = (sys.order(), sys.inputs(), sys.outputs());
    let k = 2 * n + m + p;
    let base = if scale.is_finite() && scale > 0.0 { scale } else { 1.0 };
    let mut fallback = None;
    for f in SHIFT_FACTORS {
        let s = base * f;
        let (mat, t) = timed(Step::PencilSolve, || {
            let mat = shifted_pencil(sys, gamma, s);
            let lu = mat.partial_piv_lu();
            let rhs = Mat::<f64>::from_fn(k, 2 * n, |i, j| if i == j { 1.0 } else { 0.0 });
            let x = lu.solve(rhs);
            let t = x.as_ref().submatrix(0, 0, 2 * n, 2 * n).to_owned();
            (mat, t)
        });
        let t_norm = t.norm_l2();
        if !t_norm.is_finite() {
            continue;
        }
        let cond = t_norm * mat.norm_l2();
        if cond <= MAX_SHIFT_CONDITION {
            if let Some(ws) = cayley_crossings(t.as_ref(), s) {
                return Some(ws);
            }
        } else if fallback.is_none() {
            fallback = cayley_crossings(t.as_ref(), s);
        }
    }
    fallback
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
    use crate::lti::freq_response::FreqResponse;
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
