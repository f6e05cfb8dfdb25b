//! Plant-scaled controller variables (docs/ALGORITHMS.md §8.6), used by the local searches that
//! `DesignOptions::variable_scaling` puts in them (by default every other hop cycle of the
//! continued search, `design::search`: scaled searches help AC10 and hurt BDT2, see the last
//! paragraph).
//!
//! The search works on x̃ with x = d ∘ x̃ (elementwise), where d comes from the scaling of the
//! plant's control and measurement channels — the usual input/output scaling of a multivariable
//! plant (Skogestad & Postlethwaite, *Multivariable Feedback Control*, 2nd ed. 2005, §1.4),
//! applied to the controller's parameters instead of to the plant:
//!
//! ```text
//! K = S_u · K̃ · S_y:   Ak = Ãk,  Bk = B̃k·S_y,  Ck = S_u·C̃k,  Dk = S_u·D̃k·S_y
//! ```
//!
//! with S_u = diag(s_u,i) over the m controls and S_y = diag(s_y,j) over the p measurements:
//! a unit K̃ is a feedback B2·K·C2 of unit size. Scales: A is first balanced by a diagonal
//! similarity A_b = T⁻¹AT (powers of two, `dgebal`-style, `lti::balance_scaling`), so that the
//! state coordinates carry comparable units; then s_u,i = 1/‖column i of T⁻¹B2‖₂ and
//! s_y,j = 1/‖row j of C2·T‖₂, rounded to the nearest power of two (so x ↔ x̃ is exact in
//! floating point both ways; a zero channel gets 1).
//!
//! A plant whose channels are *alike* — within each group the largest norm at most
//! [`MAX_UNSCALED_SPREAD`] = 2¹⁰ times the smallest (every SISO plant; HE1, REA2, Enns, AC8) — is
//! not scaled at all (d = 1: the search is exactly the unscaled one). Only plants whose channels
//! differ by more than three orders of magnitude (AC10: 2·10⁵ between its measurements; BDT2:
//! 10⁴ between its controls) change. Measured on AC8 (measurement norms 128× apart), scaling all
//! plants would hurt: n_K = 1 at 20 000 evaluations, seeds 1 and 2, reached γ 2.016 and 2.020
//! scaled against 1.650 and 1.651 unscaled: with channels that close, the identity is already a
//! good first inverse Hessian, and rescaling them only changes which basins BFGS reaches.
//!
//! The objective is the same function of the controller in either coordinates; only the
//! optimiser's view changes: its steps, its initial inverse Hessian (the identity), the basin
//! hops and the continued search's random starts are taken in x̃ (HIFOO's first `nrand` starts,
//! the open-loop, central and initial-controller starts are the same controllers either way). On
//! AC10 (balanced measurement rows of norms 0.33 and 9.9·10⁴) the gains from y₁ and y₂ of a good
//! first-order controller differ by ~10⁴; from the same start, BFGS in x stalls after ~20
//! iterations (γ 14.6, or not stabilised) where BFGS in x̃ goes on to γ ≈ 10.2–13.3, and one
//! 300-CPU-s job reaches 10.047 against 17.57 unscaled. On BDT2 n_K = 1 (controls 10⁴ apart) the
//! same job reached 0.897 with every local search scaled against 0.581 unscaled — not understood
//! yet — so the default alternates: the incumbent is kept in x, and unscaled and scaled hop
//! cycles both start from the best point either found.

use faer::Mat;

use crate::lti::{balance_scaling, Plant};

use super::params::ControllerShape;

/// The power of two nearest to 1/v (1 for a zero or non-finite v).
fn reciprocal_scale(v: f64) -> f64 {
    if v.is_finite() && v > 0.0 {
        (-v.log2()).round().exp2()
    } else {
        1.0
    }
}

/// Largest ratio of two channel norms within a group (controls, or measurements) for which the
/// plant is searched unscaled (module docs).
pub const MAX_UNSCALED_SPREAD: f64 = 1024.0;

/// Whether the channels of one group are alike: largest / smallest norm ≤ [`MAX_UNSCALED_SPREAD`]
/// (zero or non-finite norms are ignored).
fn alike(norms: &[f64]) -> bool {
    let ok = || norms.iter().copied().filter(|v| v.is_finite() && *v > 0.0);
    let (lo, hi) = (ok().fold(f64::INFINITY, f64::min), ok().fold(0.0, f64::max));
    !(hi > MAX_UNSCALED_SPREAD * lo)
}

/// The channel scales (s_u over the m controls, s_y over the p measurements) of `plant`
/// (module docs), `None` if the plant's channels are alike (spread ≤ [`MAX_UNSCALED_SPREAD`]
/// in each group).
pub fn channel_scales(plant: &Plant) -> Option<(Vec<f64>, Vec<f64>)> {
    let n = plant.dims.n;
    let zero = Mat::<f64>::zeros(n, n);
    let t = balance_scaling(plant.a.as_ref(), zero.as_ref(), zero.as_ref());
    let b2 = &plant.b2;
    let c2 = &plant.c2;
    let col_norm = |j: usize| (0..n).map(|i| (b2[(i, j)] / t[i]).powi(2)).sum::<f64>().sqrt();
    let row_norm = |i: usize| (0..n).map(|j| (c2[(i, j)] * t[j]).powi(2)).sum::<f64>().sqrt();
    let bu: Vec<f64> = (0..b2.ncols()).map(col_norm).collect();
    let cy: Vec<f64> = (0..c2.nrows()).map(row_norm).collect();
    if alike(&bu) && alike(&cy) {
        return None;
    }
    Some((bu.into_iter().map(reciprocal_scale).collect(), cy.into_iter().map(reciprocal_scale).collect()))
}

/// d with x = d ∘ x̃ for controllers of `shape` on `plant` (module docs), in the layout of
/// [`ControllerShape`]; `None` if the plant's channels are alike ([`channel_scales`]).
pub fn variable_scaling(plant: &Plant, shape: ControllerShape) -> Option<Vec<f64>> {
    let (su, sy) = channel_scales(plant)?;
    let nk = shape.nk;
    let mut d = Vec::with_capacity(shape.nvar());
    d.extend(std::iter::repeat_n(1.0, nk * nk)); // Ak
    for &s in &sy {
        d.extend(std::iter::repeat_n(s, nk)); // Bk (nk × p), column-major
    }
    for _ in 0..nk {
        d.extend_from_slice(&su); // Ck (m × nk), column-major
    }
    for &s in &sy {
        d.extend(su.iter().map(|&u| u * s)); // Dk (m × p), column-major
    }
    debug_assert_eq!(d.len(), shape.nvar());
    Some(d)
}

/// x̃ = x / d (exact: d holds powers of two).
pub fn to_scaled(x: &[f64], d: Option<&[f64]>) -> Vec<f64> {
    match d {
        Some(d) => x.iter().zip(d).map(|(v, s)| v / s).collect(),
        None => x.to_vec(),
    }
}

/// x = d ∘ x̃.
pub fn from_scaled(xs: &[f64], d: Option<&[f64]>) -> Vec<f64> {
    match d {
        Some(d) => xs.iter().zip(d).map(|(v, s)| v * s).collect(),
        None => xs.to_vec(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scales_are_powers_of_two_and_alike_means_within_the_spread() {
        assert_eq!([5.0, 0.3, 1.0, 0.0, f64::NAN].map(reciprocal_scale), [0.25, 4.0, 1.0, 1.0, 1.0]);
        assert!(alike(&[3.0, 3.0]) && alike(&[5.0]) && alike(&[0.0, 2.0, 2000.0]) && alike(&[]));
        assert!(!alike(&[1.0, 1025.0]) && !alike(&[0.05, 5e3]));
    }

    #[test]
    fn scaling_round_trips_exactly() {
        let d = [1.0, 0.25, 1024.0, 2f64.powi(-30)];
        let x = [0.1, -3.7, 1e-5, 12345.678];
        assert_eq!(from_scaled(&to_scaled(&x, Some(&d)), Some(&d)), x.to_vec());
        assert_eq!(to_scaled(&x, None), x.to_vec());
    }
}
