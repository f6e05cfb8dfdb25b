//! Model reduction by balanced truncation (square-root method), for stable and unstable systems.
//!
//! # Stable systems (Moore 1981; square-root form: Tombs–Postlethwaite 1987, Laub et al. 1987)
//!
//! The Gramians `A P + P Aᵀ + B Bᵀ = 0`, `Aᵀ Q + Q A + Cᵀ C = 0` ([`crate::lti::kernels::lyapunov`]) are factored
//! as P = L_c L_cᵀ, Q = L_o L_oᵀ (symmetric eigen-decompositions: semidefinite Gramians are fine).
//! With the SVD `L_oᵀ L_c = U Σ Vᵀ` (Σ = the Hankel singular values σ₁ ≥ σ₂ ≥ …) and, for order r,
//!
//! ```text
//! T_r = L_c V_r Σ_r^{−1/2},   T_l = L_o U_r Σ_r^{−1/2}   (T_lᵀ T_r = I_r),
//! A_r = T_lᵀ A T_r,  B_r = T_lᵀ B,  C_r = C T_r,  D_r = D,
//! ```
//!
//! a stable, balanced realisation with ‖G − G_r‖∞ ≤ 2 Σ_{i>r} σᵢ (Glover 1984). The order is lowered
//! to the number of Hankel singular values above [`HSV_RTOL`]·σ₁ (a non-minimal system has fewer
//! than n non-zero ones; their states carry nothing).
//!
//! # Unstable systems (as MATLAB `balred` and Safonov–Chiang–Limebeer 1987 do)
//!
//! G = G_s + G_u by the stable/antistable splitting of [`crate::lti::kernels::lyapunov::stable_antistable_basis`];
//! the antistable part (n_u states) is kept exactly and the stable part is truncated to order
//! r − n_u. If n_u > r there is no such reduction ([`ReductionError::TooManyUnstable`]).
//! Eigenvalues on (numerically) the imaginary axis are refused.

use faer::linalg::solvers::DenseSolveCore;
use faer::{Mat, MatRef, Side};

use crate::lti::kernels::lyapunov::{solve_lyapunov, stable_antistable_basis, LyapunovError};
use crate::lti::system::state_space::StateSpace;

/// Hankel singular values below this times the largest are treated as zero.
pub const HSV_RTOL: f64 = 1e-12;

/// Why a system could not be reduced.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ReductionError {
    /// The unstable part alone has more states than the requested order.
    #[error("the system has {n_unstable} unstable states, more than the requested order {order}")]
    TooManyUnstable {
        /// Antistable states.
        n_unstable: usize,
        /// Requested order.
        order: usize,
    },
    /// A Gramian or the splitting failed.
    #[error("{0}")]
    Lyapunov(#[from] LyapunovError),
    /// An eigen- or singular-value decomposition failed.
    #[error("linear algebra failure: {0}")]
    LinearAlgebra(&'static str),
}

/// A reduced system and how it was obtained.
#[derive(Debug, Clone)]
pub struct Reduced {
    /// The reduced system (order ≤ the requested order; lower if the system has fewer non-zero
    /// Hankel singular values).
    pub sys: StateSpace,
    /// Hankel singular values of the stable part, descending.
    pub hsv: Vec<f64>,
    /// Antistable states kept unreduced.
    pub n_unstable: usize,
}

/// Hankel singular values (descending) of a stable system.
pub fn hankel_singular_values(sys: &StateSpace) -> Result<Vec<f64>, ReductionError> {
    Ok(square_root_factors(sys)?.2)
}

/// (L_c, L_o, σ, U, V) of the square-root method for a stable system.
type Factors = (Mat<f64>, Mat<f64>, Vec<f64>, Mat<f64>, Mat<f64>);

fn square_root_factors(sys: &StateSpace) -> Result<Factors, ReductionError> {
    let a = sys.a.as_ref();
    let p = solve_lyapunov(a, (&sys.b * sys.b.transpose()).as_ref())?;
    let q = solve_lyapunov(a.transpose(), (sys.c.transpose() * &sys.c).as_ref())?;
    let lc = psd_factor(p.as_ref())?;
    let lo = psd_factor(q.as_ref())?;
    let m = lo.transpose() * &lc;
    let svd = m.svd().map_err(|_| ReductionError::LinearAlgebra("SVD of L_o^T L_c"))?;
    let s = svd.S().column_vector();
    let hsv: Vec<f64> = (0..s.nrows()).map(|i| s[i].max(0.0)).collect();
    Ok((lc, lo, hsv, svd.U().to_owned(), svd.V().to_owned()))
}

/// L with P = L Lᵀ for symmetric positive semidefinite P (negative rounding eigenvalues → 0).
fn psd_factor(p: MatRef<'_, f64>) -> Result<Mat<f64>, ReductionError> {
    let n = p.nrows();
    let e = p.self_adjoint_eigen(Side::Lower).map_err(|_| ReductionError::LinearAlgebra("eigen of a Gramian"))?;
    let d = e.S().column_vector();
    let u = e.U();
    Ok(Mat::from_fn(n, n, |i, j| u[(i, j)] * d[j].max(0.0).sqrt()))
}

/// Balanced truncation of a stable system to order ≤ `order` (module docs).
pub fn balanced_truncation_stable(sys: &StateSpace, order: usize) -> Result<Reduced, ReductionError> {
    let n = sys.order();
    if n == 0 || order >= n {
        let hsv = if n == 0 { Vec::new() } else { hankel_singular_values(sys)? };
        return Ok(Reduced { sys: sys.clone(), hsv, n_unstable: 0 });
    }
    let (lc, lo, hsv, u, v) = square_root_factors(sys)?;
    let s1 = hsv.first().copied().unwrap_or(0.0);
    let r = hsv.iter().take(order).filter(|&&s| s > HSV_RTOL * s1 && s > 0.0).count();
    let tr = Mat::from_fn(n, r, |i, j| (0..n).map(|k| lc[(i, k)] * v[(k, j)]).sum::<f64>() / hsv[j].sqrt());
    let tl = Mat::from_fn(n, r, |i, j| (0..n).map(|k| lo[(i, k)] * u[(k, j)]).sum::<f64>() / hsv[j].sqrt());
    let red =
        StateSpace { a: tl.transpose() * &sys.a * &tr, b: tl.transpose() * &sys.b, c: &sys.c * &tr, d: sys.d.clone() };
    Ok(Reduced { sys: red, hsv, n_unstable: 0 })
}

/// Balanced truncation of a possibly unstable system to order ≤ `order`: the antistable part is
/// kept, the stable part truncated (module docs).
pub fn balanced_truncation(sys: &StateSpace, order: usize) -> Result<Reduced, ReductionError> {
    let n = sys.order();
    if order >= n {
        return Ok(Reduced { sys: sys.clone(), hsv: Vec::new(), n_unstable: 0 });
    }
    let (t, ns) = stable_antistable_basis(sys.a.as_ref())?;
    let nu = n - ns;
    if nu > order {
        return Err(ReductionError::TooManyUnstable { n_unstable: nu, order });
    }
    if nu == 0 {
        return balanced_truncation_stable(sys, order);
    }
    let ti = t.partial_piv_lu().inverse();
    let at = &ti * &sys.a * &t;
    let bt = &ti * &sys.b;
    let ct = &sys.c * &t;
    let (m, p) = (sys.b.ncols(), sys.c.nrows());
    let stable = StateSpace {
        a: Mat::from_fn(ns, ns, |i, j| at[(i, j)]),
        b: Mat::from_fn(ns, m, |i, j| bt[(i, j)]),
        c: Mat::from_fn(p, ns, |i, j| ct[(i, j)]),
        d: sys.d.clone(),
    };
    let red = balanced_truncation_stable(&stable, order - nu)?;
    let rs = red.sys.order();
    let r = rs + nu;
    // [A_s,r 0; 0 A_u], [B_s,r; B_u], [C_s,r C_u], D.
    let a = Mat::from_fn(r, r, |i, j| match (i < rs, j < rs) {
        (true, true) => red.sys.a[(i, j)],
        (false, false) => at[(ns + i - rs, ns + j - rs)],
        _ => 0.0,
    });
    let b = Mat::from_fn(r, m, |i, j| if i < rs { red.sys.b[(i, j)] } else { bt[(ns + i - rs, j)] });
    let c = Mat::from_fn(p, r, |i, j| if j < rs { red.sys.c[(i, j)] } else { ct[(i, ns + j - rs)] });
    Ok(Reduced { sys: StateSpace { a, b, c, d: sys.d.clone() }, hsv: red.hsv, n_unstable: nu })
}

/// Balanced truncation of a left coprime factorisation `G = M⁻¹ N` (for unstable systems, e.g.
/// controllers; Meyer 1990, Zhou–Doyle–Glover 1996, ch. 19 "controller reduction").
///
/// With H stabilising A + HC, `[N M] = (A + HC, [B + HD, H], C, [D, I])` is stable and
/// `G = M⁻¹N`. It is reduced by [`balanced_truncation_stable`] to `(A_r, [B̃_r, H_r], C_r, [D, I])`,
/// and `G_r = M_r⁻¹ N_r = (A_r − H_r C_r, B̃_r − H_r D, C_r, D)`. H = −Z Cᵀ with Z the stabilising
/// solution of `A Z + Z Aᵀ − Z CᵀC Z + B Bᵀ = 0` (normalised coprime factors when D = 0). Unlike the
/// additive splitting this reduces the unstable part too, so any order is reachable; the result
/// may have a different number of unstable poles.
pub fn coprime_factor_truncation(sys: &StateSpace, order: usize) -> Result<Reduced, ReductionError> {
    let n = sys.order();
    if order >= n {
        return Ok(Reduced { sys: sys.clone(), hsv: Vec::new(), n_unstable: 0 });
    }
    let (m, p) = (sys.b.ncols(), sys.c.nrows());
    let z = crate::lti::kernels::riccati::solve_care(
        sys.a.transpose(),
        (sys.c.transpose() * &sys.c).as_ref(),
        (&sys.b * sys.b.transpose()).as_ref(),
    )
    .map_err(|e| ReductionError::Lyapunov(LyapunovError::Sign(e)))?
    .x;
    let h = -(&z * sys.c.transpose());
    let bh = &sys.b + &h * &sys.d;
    let nm = StateSpace {
        a: &sys.a + &h * &sys.c,
        b: Mat::from_fn(n, m + p, |i, j| if j < m { bh[(i, j)] } else { h[(i, j - m)] }),
        c: sys.c.clone(),
        d: Mat::from_fn(p, m + p, |i, j| if j < m { sys.d[(i, j)] } else { (i == j - m) as u8 as f64 }),
    };
    let red = balanced_truncation_stable(&nm, order)?;
    let r = red.sys.order();
    let br = Mat::from_fn(r, m, |i, j| red.sys.b[(i, j)]);
    let hr = Mat::from_fn(r, p, |i, j| red.sys.b[(i, m + j)]);
    let g =
        StateSpace { a: &red.sys.a - &hr * &red.sys.c, b: &br - &hr * &sys.d, c: red.sys.c.clone(), d: sys.d.clone() };
    let n_unstable = g.a.eigenvalues().map(|ev| ev.iter().filter(|l| l.re >= 0.0).count()).unwrap_or(0);
    Ok(Reduced { sys: g, hsv: red.hsv, n_unstable })
}

/// The static gain G(0) = D − C A⁻¹ B (the order-0 singular-perturbation approximation, which keeps
/// the DC gain where truncation to order 0 would keep only D). `None` if A is (numerically)
/// singular.
pub fn dc_gain(sys: &StateSpace) -> Option<Mat<f64>> {
    if sys.order() == 0 {
        return Some(sys.d.clone());
    }
    use faer::linalg::solvers::Solve;
    let x = sys.a.partial_piv_lu().solve(&sys.b);
    let g = &sys.d - &sys.c * x;
    crate::numeric::all_finite(g.as_ref()).then_some(g)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lti::{hinf_norm, HinfParams};

    fn diag_sys(poles: &[f64], b: &[f64], c: &[f64]) -> StateSpace {
        let n = poles.len();
        StateSpace {
            a: Mat::from_fn(n, n, |i, j| if i == j { poles[i] } else { 0.0 }),
            b: Mat::from_fn(n, 1, |i, _| b[i]),
            c: Mat::from_fn(1, n, |_, j| c[j]),
            d: Mat::zeros(1, 1),
        }
    }

    #[test]
    fn first_order_hsv_closed_form() {
        // G = c b / (s + a): P = b²/(2a), Q = c²/(2a), σ = |b c| / (2a).
        let s = diag_sys(&[-2.0], &[3.0], &[0.5]);
        let h = hankel_singular_values(&s).unwrap();
        assert!((h[0] - 1.5 / 4.0).abs() < 1e-14);
    }

    #[test]
    fn truncation_error_bound_and_balance() {
        let s = diag_sys(&[-1.0, -3.0, -10.0, -40.0], &[1.0, 2.0, 0.5, 3.0], &[1.0, -1.0, 2.0, 0.3]);
        let h = hankel_singular_values(&s).unwrap();
        for r in 1..4 {
            let red = balanced_truncation(&s, r).unwrap();
            assert_eq!(red.sys.order(), r);
            let err = StateSpace {
                a: Mat::from_fn(4 + r, 4 + r, |i, j| match (i < 4, j < 4) {
                    (true, true) => s.a[(i, j)],
                    (false, false) => red.sys.a[(i - 4, j - 4)],
                    _ => 0.0,
                }),
                b: Mat::from_fn(4 + r, 1, |i, _| if i < 4 { s.b[(i, 0)] } else { red.sys.b[(i - 4, 0)] }),
                c: Mat::from_fn(1, 4 + r, |_, j| if j < 4 { s.c[(0, j)] } else { -red.sys.c[(0, j - 4)] }),
                d: Mat::zeros(1, 1),
            };
            let e = hinf_norm(&err, &HinfParams::new(1e-10)).unwrap().value;
            let tail: f64 = h[r..].iter().sum();
            assert!(e <= 2.0 * tail * (1.0 + 1e-8), "r = {r}: error {e} > 2·tail {}", 2.0 * tail);
            assert!(e >= h[r] * (1.0 - 1e-8), "r = {r}: error {e} below σ_(r+1) {}", h[r]);
            // the reduced system is balanced: its Hankel singular values are the first r
            let hr = hankel_singular_values(&red.sys).unwrap();
            for i in 0..r {
                assert!((hr[i] - h[i]).abs() < 1e-9 * h[0], "r = {r}, σ{i}: {} vs {}", hr[i], h[i]);
            }
        }
    }

    #[test]
    fn unstable_part_is_kept() {
        let s = diag_sys(&[2.0, -1.0, -5.0, -30.0], &[1.0, 1.0, 1.0, 1.0], &[1.0, 1.0, 0.2, 0.1]);
        let red = balanced_truncation(&s, 2).unwrap();
        assert_eq!(red.n_unstable, 1);
        let mut ev: Vec<f64> = red.sys.a.eigenvalues().unwrap().iter().map(|l| l.re).collect();
        ev.sort_by(f64::total_cmp);
        assert!((ev[1] - 2.0).abs() < 1e-9, "{ev:?}");
        assert!(ev[0] < 0.0);
        assert!(matches!(balanced_truncation(&s, 0), Err(ReductionError::TooManyUnstable { n_unstable: 1, order: 0 })));
    }

    #[test]
    fn coprime_factor_truncation_keeps_full_order_and_approximates() {
        // G = 1/(s − 1) + 1/(s + 2) + 0.01/(s + 50): order 3 is G itself; order 2 is close.
        let s = diag_sys(&[1.0, -2.0, -50.0], &[1.0, 1.0, 0.1], &[1.0, 1.0, 0.1]);
        let same = coprime_factor_truncation(&s, 3).unwrap();
        assert_eq!(same.sys, s);
        let red = coprime_factor_truncation(&s, 2).unwrap();
        assert_eq!(red.sys.order(), 2);
        assert_eq!(red.n_unstable, 1);
        // compare frequency responses at a few points (through the DC gain and a large s)
        let g0 = dc_gain(&s).unwrap()[(0, 0)];
        let r0 = dc_gain(&red.sys).unwrap()[(0, 0)];
        assert!((g0 - r0).abs() < 0.05 * g0.abs(), "{g0} vs {r0}");
    }

    #[test]
    fn dc_gain_closed_form() {
        let s = diag_sys(&[-2.0, -4.0], &[1.0, 2.0], &[3.0, 1.0]);
        // 3/2 + 2/4
        assert!((dc_gain(&s).unwrap()[(0, 0)] - 2.0).abs() < 1e-14);
    }
}
