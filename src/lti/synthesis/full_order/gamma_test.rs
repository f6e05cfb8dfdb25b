//! The γ-test: does a stabilising controller with ‖T_zw‖∞ < γ exist? (Glover–Doyle 1988;
//! Doyle–Glover–Khargonekar–Francis 1989; the general-D form as in Zhou–Doyle–Glover 1996,
//! ch. 17, and SLICOT SB10PD/SB10QD)
//!
//!
//! With `B = [B1 B2]`, `C = [C1; C2]`, `D1• = [D11 D12]`, `D•1 = [D11; D21]` and
//!
//! ```text
//! R  = D1•ᵀ D1• − diag(γ² I_m1, 0),          R̃ = D•1 D•1ᵀ − diag(γ² I_p1, 0),
//! X:  (A − B R⁻¹ D1•ᵀ C1)ᵀ X + X (A − B R⁻¹ D1•ᵀ C1) − X B R⁻¹ Bᵀ X + C1ᵀ (I − D1• R⁻¹ D1•ᵀ) C1 = 0,
//! Y:  (A − B1 D•1ᵀ R̃⁻¹ C) Y + Y (…)ᵀ − Y Cᵀ R̃⁻¹ C Y + B1 (I − D•1ᵀ R̃⁻¹ D•1) B1ᵀ = 0,
//! ```
//!
//! a stabilising controller with ‖T_zw‖∞ < γ exists iff (i) γ > max(σ̄(D12⊥ᵀ D11), σ̄(D11 D21⊥ᵀ))
//! (the part of D11 no controller can touch), (ii) the X Hamiltonian has no imaginary-axis
//! eigenvalues and its stabilising solution X ⪰ 0, (iii) the same for Y ⪰ 0, (iv) ρ(XY) < γ².
//! This "R-form" needs no explicit normalisation of D12, D21: it is invariant under the usual
//! scalings u → T u, z → U z, y → S y, w → V w that bring D12ᵀD12 = I and D21D21ᵀ = I, so the
//! standing assumption is only that D12 has full column rank and D21 full row rank (plus the
//! imaginary-axis rank conditions). D11 ≠ 0 is handled directly (no loop shifting needed). D22
//! does not affect γ_opt (it is removed by a loop transformation of the controller) and is ignored.
//! The constant terms `C1ᵀ (I − D1• R⁻¹ D1•ᵀ) C1` and `B1 (I − D•1ᵀ R̃⁻¹ D•1) B1ᵀ` are not formed
//! as written but as Gram products in the normalised coordinates (`exogenous_weights.rs`): as
//! differences they cancel to rounding noise where the exact value is 0 or small (a square D21
//! with B1·D21ᵀ ≠ 0, a square D12 with D12ᵀ·C1 ≠ 0), and that noise made the γ-test fail at every γ.
//! Each Riccati equation is solved by [`solve_care`] (matrix sign function, with
//! finiteness, residual and stabilising checks); any failure there means "γ infeasible".
//!

use faer::{Mat, MatRef};

use super::exogenous_weights::ExogenousWeight;
use super::linalg::{concat_cols, concat_rows, feedthrough_bound, solve, sym_eig};
use super::{Binding, FullOrderError};
use crate::lti::kernels::riccati::solve_care;
use crate::lti::system::plant::Plant;

/// X ⪰ 0 test: λmin(X) ≥ −(PSD_RTOL·max|λ(X)| + PSD_ATOL).
pub(crate) const PSD_RTOL: f64 = 1e-8;
/// Absolute part of the X ⪰ 0 / Y ⪰ 0 test (accepts rounding noise around X = 0).
pub(crate) const PSD_ATOL: f64 = 1e-12;

/// The plant's exogenous channels (B1, C1, D11, D12, D21): the plant's own ([`Channels::of`]) or
/// δ-augmented (`regularisation::augment`). A, B2 and C2 are always the plant's; D22 plays no
/// part in γ_opt.
pub(crate) struct Channels {
    pub(crate) b1: Mat<f64>,
    pub(crate) c1: Mat<f64>,
    pub(crate) d11: Mat<f64>,
    pub(crate) d12: Mat<f64>,
    pub(crate) d21: Mat<f64>,
}

impl Channels {
    /// The plant's channels as they are.
    pub(crate) fn of(plant: &Plant) -> Channels {
        Channels {
            b1: plant.b1.clone(),
            c1: plant.c1.clone(),
            d11: plant.d11.clone(),
            d12: plant.d12.clone(),
            d21: plant.d21.clone(),
        }
    }
}

/// The (possibly regularised) plant with the γ-independent products precomputed: the input of
/// [`Problem::test`].
pub(crate) struct Problem {
    n: usize,
    a: Mat<f64>,
    b: Mat<f64>,
    c: Mat<f64>,
    /// Condition (ii): D1•ᵀ D1• ((m1+m2)²), D1•ᵀ C1 and the X equation's constant term.
    x: RiccatiCondition,
    /// Condition (iii): D•1 D•1ᵀ ((p1+p2)²), D•1 B1ᵀ and the Y equation's constant term.
    y: RiccatiCondition,
    /// Condition (i) bound.
    pub(crate) gamma_d: f64,
}

impl Problem {
    /// The γ-independent products of `plant` with its exogenous channels replaced by `ch`.
    pub(crate) fn new(plant: &Plant, ch: Channels) -> Result<Problem, FullOrderError> {
        let n = plant.dims.n;
        let Channels { b1, c1, d11, d12, d21 } = ch;
        let (p1, m1) = (c1.nrows(), b1.ncols());
        let b = concat_cols(b1.as_ref(), plant.b2.as_ref());
        let c = concat_rows(c1.as_ref(), plant.c2.as_ref());
        let d1 = concat_cols(d11.as_ref(), d12.as_ref());
        let dd1 = concat_rows(d11.as_ref(), d21.as_ref());
        let gamma_d = feedthrough_bound(d11.as_ref(), d12.as_ref(), d21.as_ref())?;
        let qx = ExogenousWeight::state_feedback(c1.as_ref(), d11.as_ref(), d12.as_ref())?;
        let qy = ExogenousWeight::filter(b1.as_ref(), d11.as_ref(), d21.as_ref())?;
        Ok(Problem {
            n,
            a: plant.a.clone(),
            x: RiccatiCondition { gram: d1.transpose() * &d1, shifted: m1, cross: d1.transpose() * &c1, weight: qx },
            y: RiccatiCondition { gram: &dd1 * dd1.transpose(), shifted: p1, cross: &dd1 * b1.transpose(), weight: qy },
            b,
            c,
            gamma_d,
        })
    }

    /// The γ-test: Ok(ρ(XY)/γ²) if γ is feasible, Err((binding, reason)) otherwise.
    pub(crate) fn test(&self, gamma: f64) -> Result<f64, (Binding, String)> {
        let n = self.n;
        let g2 = gamma * gamma;
        if gamma <= self.gamma_d {
            return Err((Binding::Feedthrough, format!("gamma {gamma} <= D11 bound {}", self.gamma_d)));
        }
        // X: R = D1ᵀD1 − diag(γ²I, 0); M = R⁻¹ [D1ᵀC1, Bᵀ].
        let (_, xl, xv) = self.x.solve(Binding::StateFeedback, self.a.as_ref(), self.b.as_ref(), gamma)?;
        // Y: R̃ = D•1D•1ᵀ − diag(γ²I, 0); N = R̃⁻¹ [D•1B1ᵀ, C]; the CARE in transposed form,
        // A_yᵀ Y + Y A_y − Y G_y Y + Q_y with A_y = (A − B1 D•1ᵀ R̃⁻¹ C)ᵀ.
        let (y, _, _) = self.y.solve(Binding::Filter, self.a.transpose(), self.c.transpose(), gamma)?;

        // ρ(XY) = λmax(X^{1/2} Y X^{1/2}).
        let sq = Mat::from_fn(n, n, |i, j| xv[(i, j)] * xl[j].max(0.0).sqrt());
        let xh = &sq * xv.transpose();
        let mm = &xh * &y * &xh;
        let (ml, _) = sym_eig(mm.as_ref()).ok_or((Binding::Coupling, "eig(X^1/2 Y X^1/2) failed".to_string()))?;
        let rho = ml.last().copied().unwrap_or(0.0);
        if rho < g2 {
            Ok(rho / g2)
        } else {
            Err((Binding::Coupling, format!("rho(XY)/gamma^2 = {:.6}", rho / g2)))
        }
    }
}

/// Condition (ii) or (iii) of the module docs, the two in one form: with R the Gram matrix
/// `gram` less γ² on its first `shifted` diagonal entries and [M₁ M₂] = R⁻¹ [`cross`, Bᵀ], the
/// CARE of (A − B M₁, B M₂, Q(γ)) (Q = `weight`) has a stabilising solution ⪰ 0. X is
/// (A, B) = (A, [B1 B2]); Y is the transposed form, (A, B) = (Aᵀ, Cᵀ).
struct RiccatiCondition {
    gram: Mat<f64>,
    shifted: usize,
    cross: Mat<f64>,
    weight: ExogenousWeight,
}

/// A Riccati solution with its eigenvalues (ascending) and eigenvectors.
type RiccatiSolution = (Mat<f64>, Vec<f64>, Mat<f64>);

impl RiccatiCondition {
    /// The solution with its eigenvalues (ascending) and eigenvectors, or the binding condition
    /// and the reason it fails at γ. `binding`: [`Binding::StateFeedback`] for X,
    /// [`Binding::Filter`] for Y (which also names the matrices in the reasons).
    fn solve(
        &self,
        binding: Binding,
        a: MatRef<'_, f64>,
        b: MatRef<'_, f64>,
        gamma: f64,
    ) -> Result<RiccatiSolution, (Binding, String)> {
        let (name, r_name, weight_name) = if binding == Binding::StateFeedback {
            ("X", "R", "I - D11 D11'/gamma^2")
        } else {
            ("Y", "R~", "I - D11' D11/gamma^2")
        };
        let n = a.nrows();
        let mut r = self.gram.clone();
        for i in 0..self.shifted {
            r[(i, i)] -= gamma * gamma;
        }
        let rhs = concat_cols(self.cross.as_ref(), b.transpose());
        let m = solve(r.as_ref(), rhs.as_ref()).ok_or((binding, format!("{r_name} singular")))?;
        let (r_cross, r_bt) = (m.subcols(0, n), m.subcols(n, n));
        let a_closed = a - b * r_cross;
        let g = b * r_bt;
        let q = self.weight.at(gamma).ok_or((Binding::Feedthrough, format!("{weight_name} not positive definite")))?;
        let x = solve_care(a_closed.as_ref(), g.as_ref(), q.as_ref()).map_err(|e| (binding, format!("{name}: {e}")))?.x;
        let (l, v) = sym_eig(x.as_ref()).ok_or((binding, format!("eig({name}) failed")))?;
        psd_check(&l).map_err(|s| (binding, format!("{name}: {s}")))?;
        Ok((x, l, v))
    }
}

/// The X ⪰ 0 / Y ⪰ 0 test on ascending eigenvalues, with [`PSD_RTOL`] and [`PSD_ATOL`].
fn psd_check(eigs: &[f64]) -> Result<(), String> {
    let max_abs = eigs.iter().fold(0.0f64, |a, &v| a.max(v.abs()));
    let lmin = eigs.first().copied().unwrap_or(0.0);
    if lmin >= -(PSD_RTOL * max_abs + PSD_ATOL) {
        Ok(())
    } else {
        Err(format!("not positive semidefinite (lambda_min = {lmin:.3e}, max |lambda| = {max_abs:.3e})"))
    }
}
