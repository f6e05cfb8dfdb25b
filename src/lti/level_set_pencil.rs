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
//! The imaginary axis λ = iω becomes the circle |θ + 1/(2s)| = 1/(2s) through θ = 0 (ω = ∞)
//! and θ = −1/s (ω = 0), and ω = Im(1/θ) on it. The eigenvalues θ carry absolute errors of
//! about ε‖T₁₁‖ (‖·‖_F here) for simple ones and √(ε‖T₁₁‖²) for the double eigenvalue of a
//! tangent crossing, so a θ counts as a crossing if its distance to the circle is at most
//! [`CIRCLE_TOL_FACTOR`]·√ε·‖T₁₁‖: loose on purpose, since a spurious crossing costs one
//! evaluation of σmax(G(iω)) whereas a missed one lowers the norm.
//!
//! The shift is chosen among the system's frequency scale times a few factors; a shift too close
//! to an eigenvalue of the pencil shows as a large ‖T₁₁‖·‖M − sE‖ and the next one is tried.

use faer::linalg::solvers::Solve;
use faer::Mat;

use super::spectral::eigenvalues;
use super::StateSpace;

/// Distance to the image of the imaginary axis accepted as a crossing, in units of √ε·‖T₁₁‖_F.
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
        let mat = shifted_pencil(sys, gamma, s);
        let lu = mat.partial_piv_lu();
        let rhs = Mat::<f64>::from_fn(k, 2 * n, |i, j| if i == j { 1.0 } else { 0.0 });
        let x = lu.solve(rhs);
        let t = x.as_ref().submatrix(0, 0, 2 * n, 2 * n).to_owned();
        let t_norm = t.norm_l2();
        if !t_norm.is_finite() {
            continue;
        }
        let cond = t_norm * mat.norm_l2();
        let Some(theta) = eigenvalues(t.as_ref()) else { continue };
        let tol = CIRCLE_TOL_FACTOR * f64::EPSILON.sqrt() * t_norm;
        let (c, r) = (-0.5 / s, 0.5 / s);
        let ws: Vec<f64> = theta
            .iter()
            .filter(|th| ((th.re - c).hypot(th.im) - r).abs() <= tol && th.im <= 0.0)
            .map(|th| {
                let inv = th.inv();
                if inv.im.is_finite() {
                    inv.im.abs()
                } else {
                    f64::INFINITY
                }
            })
            .collect();
        if cond <= MAX_SHIFT_CONDITION {
            return Some(ws);
        }
        fallback.get_or_insert(ws);
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
