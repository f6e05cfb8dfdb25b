//! The closed loop of a generalised plant with a dynamic controller u = K y (docs/ALGORITHMS.md §2).
//!
//! The loop is written as a linear-fractional transformation of the controller's realisation
//! X = [Ak Bk; Ck Dk] ((nk+m)×(nk+p)) around the augmented plant
//!
//! ```text
//! A0 = diag(A, 0),  B̄ = [0 B2; I 0],  C̄ = [0 I; C2 0],  D̄22 = [0 0; 0 D22],
//! B̄1 = [B1; 0],     C̄1 = [C1 0],      D̄12 = [0 D12],    D̄21 = [0; D21].
//! ```
//!
//! With W = X (I − D̄22 X)⁻¹ = (I − X D̄22)⁻¹ X:
//!
//! ```text
//! Acl = A0 + B̄ W C̄,  Bcl = B̄1 + B̄ W D̄21,  Ccl = C̄1 + D̄12 W C̄,  Dcl = D11 + D̄12 W D̄21.
//! ```
//!
//! Written out, W = [Ak + Bk D22 F⁻¹ Ck, Bk N; F⁻¹ Ck, F⁻¹ Dk] with F = I − Dk D22 and
//! N = (I − D22 Dk)⁻¹ = I + D22 F⁻¹ Dk, which is the usual block form (the SLICOT oracle's formula, tests/fixtures/oracle/README.md).
//! The loop is well posed iff F is invertible; we require cond₂(F) ≤ [`MAX_LOOP_CONDITION`]
//! and report [`LtiError::IllPosed`] otherwise (HIFOO itself does not test this; docs/ALGORITHMS.md §2).
//!
//! The same form gives the chain rule (docs/ALGORITHMS.md §6.2) in one line: dW = P dX Q with
//! P = (I − X D̄22)⁻¹ and Q = (I − D̄22 X)⁻¹, so for any f of (Acl, Bcl, Ccl, Dcl) with real
//! matrix gradients G_A, G_B, G_C, G_D,
//!
//! ```text
//! ∂f/∂X = Pᵀ Γ Qᵀ,   Γ = [B̄ᵀ D̄12ᵀ] [G_A G_B; G_C G_D] [C̄ᵀ; D̄21ᵀ],
//! ```
//!
//! whose blocks for D22 = 0 (P = Q = I) are HIFOO's four formulas. The gradients of α and ‖·‖∞
//! are rank-one complex outer products (α: ū vᵀ/(uᴴv); ‖·‖∞: ā bᵀ etc.), so Γ is assembled
//! from two short vectors instead of (n+nk)² matrices ([`ClosedLoop::chain_rule`]); the H2
//! norm's gradients are full matrices (2QP, 2QB, 2CP, docs/ALGORITHMS.md §13.1) and take
//! [`ClosedLoop::chain_rule_dense`], the same formula on matrices.

use faer::linalg::solvers::DenseSolveCore;
use faer::{c64, Mat, MatRef};

use super::controller::Controller;
use super::plant::Plant;
use super::state_space::StateSpace;
use crate::lti::error::LtiError;

/// Largest acceptable 2-norm condition number of F = I − Dk·D22; beyond it the loop is treated as
/// ill-posed. At 1e12 the closed-loop matrices still carry about 4 correct digits.
pub const MAX_LOOP_CONDITION: f64 = 1e12;

/// Forms the closed loop (Acl, Bcl, Ccl, Dcl) of `plant` with controller `k` (u = K y), in the
/// plant's time domain (the formulas are the same in both; `Err(DomainMismatch)` unless the
/// controller is in the plant's domain).
pub fn closed_loop(plant: &Plant, k: &Controller) -> Result<StateSpace, LtiError> {
    Ok(ClosedLoop::new(plant, k)?.sys)
}

/// A closed loop together with what the chain rule needs.
#[derive(Debug, Clone)]
pub(crate) struct ClosedLoop<'p> {
    /// The closed-loop system, states (x, xk).
    pub sys: StateSpace,
    plant: &'p Plant,
    nk: usize,
    /// (P, Q) = ((I − X D̄22)⁻¹, (I − D̄22 X)⁻¹); `None` when D22 = 0 (both are the identity).
    pq: Option<(Mat<f64>, Mat<f64>)>,
}

impl<'p> ClosedLoop<'p> {
    /// Forms the closed loop; checks the time domains, the shapes and well-posedness.
    pub(crate) fn new(plant: &'p Plant, k: &Controller) -> Result<Self, LtiError> {
        if plant.domain != k.domain {
            return Err(LtiError::DomainMismatch { plant: plant.domain, controller: k.domain });
        }
        let dims = plant.dims;
        let (n, m, p) = (dims.n, dims.m2, dims.p2);
        let nk = k.order();
        check_shape("AK", k.ak.as_ref(), (nk, nk))?;
        check_shape("BK", k.bk.as_ref(), (nk, p))?;
        check_shape("CK", k.ck.as_ref(), (m, nk))?;
        check_shape("DK", k.dk.as_ref(), (m, p))?;

        // W = [W11 W12; W21 W22] and the chain-rule factors.
        let (w11, w12, w21, w22, pq) = if plant.d22_is_zero() {
            (k.ak.clone(), k.bk.clone(), k.ck.clone(), k.dk.clone(), None)
        } else {
            let f = Mat::<f64>::identity(m, m) - &k.dk * &plant.d22;
            let cond = condition_number(f.as_ref());
            if !(cond <= MAX_LOOP_CONDITION) {
                return Err(LtiError::IllPosed { cond: if cond.is_nan() { f64::INFINITY } else { cond } });
            }
            let finv = f.partial_piv_lu().inverse();
            let fdk = &finv * &k.dk; // F⁻¹ Dk
            let fck = &finv * &k.ck; // F⁻¹ Ck
            let nmat = Mat::<f64>::identity(p, p) + &plant.d22 * &fdk; // N = (I − D22 Dk)⁻¹
            let bkd22 = &k.bk * &plant.d22; // Bk D22
            let w11 = &k.ak + &bkd22 * &fck;
            let w12 = &k.bk * &nmat;
            // P = [I, Bk D22 F⁻¹; 0, F⁻¹],  Q = [I, 0; N D22 Ck, N]
            let mut pm = Mat::<f64>::identity(nk + m, nk + m);
            pm.as_mut().submatrix_mut(0, nk, nk, m).copy_from(&bkd22 * &finv);
            pm.as_mut().submatrix_mut(nk, nk, m, m).copy_from(&finv);
            let mut qm = Mat::<f64>::identity(nk + p, nk + p);
            qm.as_mut().submatrix_mut(nk, 0, p, nk).copy_from(&nmat * &plant.d22 * &k.ck);
            qm.as_mut().submatrix_mut(nk, nk, p, p).copy_from(&nmat);
            (w11, w12, fck, fdk, Some((pm, qm)))
        };

        let b2w22 = &plant.b2 * &w22; // n×p
        let d12w22 = &plant.d12 * &w22; // p1×p
        let mut a = Mat::<f64>::zeros(n + nk, n + nk);
        a.as_mut().submatrix_mut(0, 0, n, n).copy_from(&plant.a + &b2w22 * &plant.c2);
        a.as_mut().submatrix_mut(0, n, n, nk).copy_from(&plant.b2 * &w21);
        a.as_mut().submatrix_mut(n, 0, nk, n).copy_from(&w12 * &plant.c2);
        a.as_mut().submatrix_mut(n, n, nk, nk).copy_from(&w11);
        let m1 = dims.m1;
        let mut b = Mat::<f64>::zeros(n + nk, m1);
        b.as_mut().submatrix_mut(0, 0, n, m1).copy_from(&plant.b1 + &b2w22 * &plant.d21);
        b.as_mut().submatrix_mut(n, 0, nk, m1).copy_from(&w12 * &plant.d21);
        let p1 = dims.p1;
        let mut c = Mat::<f64>::zeros(p1, n + nk);
        c.as_mut().submatrix_mut(0, 0, p1, n).copy_from(&plant.c1 + &d12w22 * &plant.c2);
        c.as_mut().submatrix_mut(0, n, p1, nk).copy_from(&plant.d12 * &w21);
        let d = &plant.d11 + &d12w22 * &plant.d21;
        Ok(ClosedLoop { sys: StateSpace { a, b, c, d }, plant, nk, pq })
    }

    /// Gradient with respect to (Ak, Bk, Ck, Dk) of an f whose closed-loop matrix gradients are
    /// G_A = Re(ā bᵀ), G_B = Re(ā vᵀ), G_C = Re(ū bᵀ), G_D = Re(ū vᵀ) (complex vectors
    /// a, b ∈ ℂⁿ⁺ⁿᵏ, u ∈ ℂᵖ¹, v ∈ ℂᵐ¹; pass `None` for u, v when G_B = G_C = G_D = 0).
    /// Then Γ = Re(ℓ rᵀ) with ℓ = B̄ᵀā + D̄12ᵀū and r = C̄ b + D̄21 v (module docs).
    pub(crate) fn chain_rule(&self, a: &[c64], b: &[c64], uv: Option<(&[c64], &[c64])>) -> Controller {
        let pl = self.plant;
        let (n, nk) = (pl.dims.n, self.nk);
        let abar: Vec<c64> = a.iter().map(|z| z.conj()).collect();
        // ℓ = [ā₂; B2ᵀ ā₁ + D12ᵀ ū],  r = [b₂; C2 b₁ + D21 v]
        let mut l: Vec<c64> = abar[n..].to_vec();
        let mut l2 = mul_t(pl.b2.as_ref(), &abar[..n]);
        let mut r: Vec<c64> = b[n..].to_vec();
        let mut r2 = mul(pl.c2.as_ref(), &b[..n]);
        if let Some((u, v)) = uv {
            let ubar: Vec<c64> = u.iter().map(|z| z.conj()).collect();
            add_to(&mut l2, &mul_t(pl.d12.as_ref(), &ubar));
            add_to(&mut r2, &mul(pl.d21.as_ref(), v));
        }
        l.extend(l2);
        r.extend(r2);
        if let Some((pm, qm)) = &self.pq {
            l = mul_t(pm.as_ref(), &l);
            r = mul(qm.as_ref(), &r);
        }
        let outer = |li: &[c64], rj: &[c64]| Mat::from_fn(li.len(), rj.len(), |i, j| (li[i] * rj[j]).re);
        Controller::continuous(
            outer(&l[..nk], &r[..nk]),
            outer(&l[..nk], &r[nk..]),
            outer(&l[nk..], &r[..nk]),
            outer(&l[nk..], &r[nk..]),
        )
    }

    /// Gradient with respect to (Ak, Bk, Ck, Dk) of an f whose closed-loop matrix gradients are
    /// the real matrices `g` = (G_A, G_B, G_C, G_D), shaped as the closed loop's (Acl, Bcl, Ccl,
    /// Dcl): ∂f/∂X = Pᵀ Γ Qᵀ with Γ = L_A C̄ᵀ + L_B D̄21ᵀ and [L_A L_B] = B̄ᵀ [G_A G_B] + D̄12ᵀ
    /// [G_C G_D] (module docs; docs/ALGORITHMS.md §13.3), for gradients that are not rank-one (the
    /// H2 norm's).
    pub(crate) fn chain_rule_dense(&self, g: &StateSpace) -> Controller {
        let pl = self.plant;
        let (n, nk, m2, p2) = (pl.dims.n, self.nk, pl.dims.m2, pl.dims.p2);
        // B̄ᵀ M = [M₂; B2ᵀ M₁] (M₁ the plant's n rows, M₂ the controller's nk rows).
        let lift = |gx: &Mat<f64>, gy: &Mat<f64>| {
            let mut l = Mat::<f64>::zeros(nk + m2, gx.ncols());
            l.as_mut().subrows_mut(0, nk).copy_from(gx.as_ref().subrows(n, nk));
            l.as_mut()
                .subrows_mut(nk, m2)
                .copy_from(pl.b2.transpose() * gx.as_ref().subrows(0, n) + pl.d12.transpose() * gy);
            l
        };
        let (la, lb) = (lift(&g.a, &g.c), lift(&g.b, &g.d));
        // M C̄ᵀ = [M₂, M₁ C2ᵀ] and N D̄21ᵀ = [0, N D21ᵀ] (columns: the controller's nk, then p2).
        let mut gamma = Mat::<f64>::zeros(nk + m2, nk + p2);
        gamma.as_mut().subcols_mut(0, nk).copy_from(la.as_ref().subcols(n, nk));
        gamma
            .as_mut()
            .subcols_mut(nk, p2)
            .copy_from(la.as_ref().subcols(0, n) * pl.c2.transpose() + &lb * pl.d21.transpose());
        if let Some((pm, qm)) = &self.pq {
            gamma = pm.transpose() * &gamma * qm.transpose();
        }
        let block = |i: usize, j: usize, r: usize, c: usize| gamma.as_ref().submatrix(i, j, r, c).to_owned();
        Controller::continuous(block(0, 0, nk, nk), block(0, nk, nk, p2), block(nk, 0, m2, nk), block(nk, nk, m2, p2))
    }
}

fn check_shape(what: &'static str, m: MatRef<'_, f64>, expected: (usize, usize)) -> Result<(), LtiError> {
    let got = (m.nrows(), m.ncols());
    if got == expected {
        Ok(())
    } else {
        Err(LtiError::Shape { what, expected, got })
    }
}

/// 2-norm condition number σmax/σmin of a square matrix (+∞ if singular, NaN if not finite).
pub(crate) fn condition_number(f: MatRef<'_, f64>) -> f64 {
    if !crate::numeric::all_finite(f) {
        return f64::NAN;
    }
    match f.singular_values() {
        Ok(s) if !s.is_empty() => {
            let (hi, lo) = s.iter().fold((0.0f64, f64::INFINITY), |(h, l), &x| (h.max(x), l.min(x)));
            if lo == 0.0 {
                f64::INFINITY
            } else {
                hi / lo
            }
        }
        Ok(_) => 1.0,
        Err(_) => f64::NAN,
    }
}

/// M x for real M and complex x.
pub(crate) fn mul(m: MatRef<'_, f64>, x: &[c64]) -> Vec<c64> {
    let mut y = vec![c64::new(0.0, 0.0); m.nrows()];
    for j in 0..m.ncols() {
        let xj = x[j];
        for (i, yi) in y.iter_mut().enumerate() {
            *yi += xj * m[(i, j)];
        }
    }
    y
}

/// Mᵀ x for real M and complex x.
pub(crate) fn mul_t(m: MatRef<'_, f64>, x: &[c64]) -> Vec<c64> {
    (0..m.ncols()).map(|j| (0..m.nrows()).fold(c64::new(0.0, 0.0), |s, i| s + x[i] * m[(i, j)])).collect()
}

fn add_to(y: &mut [c64], x: &[c64]) {
    for (a, b) in y.iter_mut().zip(x) {
        *a += *b;
    }
}
