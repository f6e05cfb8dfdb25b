//! Singular problems: regularisation of a rank-deficient D12 or D21.
//!
//! Several benchmark plants have D12 without full column rank or D21 without full row rank (HE1,
//! REA2, HF1, AC10, BDT2: D21 = 0; CM4: D21 is 2×1). As is usual in the field (e.g. the
//! regularisation used with `hinfsyn`, and the perturbation argument of Stoorvogel 1992 showing
//! γ_opt(δ) ↓ γ_opt as δ ↓ 0), the singular side is augmented with δ-weighted channels:
//!
//! * D21 rank-deficient: new disturbances w_x (state noise) and v (sensor noise),
//!   `B1 → [B1, δI_n, 0]`, `D21 → [D21, 0, δI_p2]`, `D11 → [D11, 0, 0]`;
//! * D12 rank-deficient: new outputs δ x and δ u,
//!   `C1 → [C1; δI_n; 0]`, `D12 → [D12; 0; δI_m2]`, `D11 → [D11; 0; 0]`.
//!
//! The state channels also restore the imaginary-axis rank conditions (BDT2 has integrators not
//! reached by B1). Augmenting w and z can only increase ‖T_zw‖ for every controller, so γ(δ) is an
//! upper bound of the singular infimum and decreases to it as δ → 0. δ is absolute (in the plant's
//! units). It is decreased through [`REGULARISATION_DELTAS`] (10⁻⁵ … 10⁻⁸) until γ(δ) is flat to
//! [`FLAT_RTOL`], or until the numerics stop being trustworthy (γ(δ) would increase as δ
//! decreases, which is impossible in exact arithmetic: the Hamiltonians carry 1/δ² terms), and
//! the value at the smallest trusted δ is reported, with the whole sequence, in
//! [`super::FullOrderGamma::regularisation_history`]. Very slowly converging plants (BDT2) are reported as such.

use faer::{Mat, MatRef};

use super::bracketing::{gamma_opt, Bracket};
use super::gamma_test::{Channels, Problem};
use super::{FullOrderError, FullOrderOptions};
use crate::lti::system::plant::Plant;

/// Regularisation levels tried in order (absolute), for plants with singular D12 or D21.
pub const REGULARISATION_DELTAS: [f64; 4] = [1e-5, 1e-6, 1e-7, 1e-8];
/// Stop decreasing δ once γ changes relatively by less than this.
pub const FLAT_RTOL: f64 = 1e-6;

/// How singular problems are regularised.
#[derive(Debug, Clone, PartialEq)]
pub enum Regularisation {
    /// Decrease δ through [`REGULARISATION_DELTAS`] until flat or no longer trustworthy (default).
    Auto,
    /// One fixed δ (used if D12 or D21 is rank-deficient).
    Fixed(f64),
}

/// What the δ sequence gave: the bracket at the smallest trusted δ, and how it got there.
pub(crate) struct Regularised {
    /// The smallest trusted δ.
    pub(crate) delta: f64,
    /// The γ bracket at `delta`.
    pub(crate) bracket: Bracket,
    /// The D11 bound (condition (i)) of the augmented plant at `delta`.
    pub(crate) feedthrough_bound: f64,
    /// γ(δ) for every δ evaluated, in order.
    pub(crate) history: Vec<(f64, f64)>,
    /// γ(δ) was flat to [`FLAT_RTOL`] at `delta` (never for a fixed δ).
    pub(crate) converged: bool,
}

/// γ_opt of a plant whose D12 (`reg12`) and/or D21 (`reg21`) is rank-deficient, at decreasing δ
/// as the module docs describe; counts γ-tests in `tests` and says in `notes` why δ stopped.
pub(crate) fn decrease_eps(
    plant: &Plant,
    opts: &FullOrderOptions,
    reg12: bool,
    reg21: bool,
    tests: &mut usize,
    notes: &mut Vec<String>,
) -> Result<Regularised, FullOrderError> {
    let delta_list: Vec<f64> = match opts.regularisation {
        Regularisation::Auto => REGULARISATION_DELTAS.to_vec(),
        Regularisation::Fixed(e) => vec![e],
    };
    let mut history: Vec<(f64, f64)> = Vec::new();
    let mut best: Option<(f64, Bracket, f64)> = None; // (delta, bracket, gamma_d)
    let mut converged = false;
    for &delta in &delta_list {
        let prob = Problem::new(plant, augment(plant, delta, reg12, reg21))?;
        let warm = best.as_ref().map(|(_, b, _)| b.hi);
        if let Some(prev) = warm {
            // γ(δ) is non-increasing as δ decreases: the previous γ must still be feasible.
            *tests += 1;
            if let Err(why) = prob.test(prev) {
                notes.push(format!(
                    "delta = {delta:.0e} not used: the previous gamma {prev:.7} tested infeasible there ({}), \
                     i.e. the 1/delta^2-scaled Riccati equations are no longer numerically reliable",
                    why.1
                ));
                break;
            }
        }
        let b = match gamma_opt(&prob, opts.rtol, warm, tests) {
            Ok(b) => b,
            Err(e) if best.is_some() => {
                notes.push(format!("delta = {delta:.0e} not used: {e}"));
                break;
            }
            Err(e) => return Err(e),
        };
        history.push((delta, b.hi));
        let prev = best.as_ref().map(|(_, pb, _)| pb.hi);
        best = Some((delta, b, prob.gamma_d));
        if let Some(p) = prev {
            if (p - history.last().expect("pushed").1).abs() <= FLAT_RTOL * p {
                converged = true;
                break;
            }
        }
    }
    let (delta, bracket, feedthrough_bound) = best.expect("the first delta either succeeds or returns an error");
    if matches!(opts.regularisation, Regularisation::Fixed(_)) {
        converged = false;
        notes.push("fixed delta requested: no delta -> 0 convergence check".into());
    }
    Ok(Regularised { delta, bracket, feedthrough_bound, history, converged })
}

/// The plant's channels with the δ-weighted ones of the module docs added on the singular side(s).
pub(crate) fn augment(plant: &Plant, delta: f64, reg12: bool, reg21: bool) -> Channels {
    let (n, m2, p2) = (plant.dims.n, plant.dims.m2, plant.dims.p2);
    let (mut b1, mut c1) = (plant.b1.clone(), plant.c1.clone());
    let (mut d11, mut d12, mut d21) = (plant.d11.clone(), plant.d12.clone(), plant.d21.clone());
    if reg12 {
        // [C1; δI; 0], [D12; 0; δI], [D11; 0; 0]
        c1 = append_rows(c1.as_ref(), n + m2, 0, delta);
        d12 = append_rows(d12.as_ref(), n + m2, n, delta);
        d11 = append_rows(d11.as_ref(), n + m2, 0, 0.0);
    }
    if reg21 {
        // [B1 δI 0], [D21 0 δI], [D11 0 0]
        b1 = append_rows(b1.transpose(), n + p2, 0, delta).transpose().to_owned();
        d21 = append_rows(d21.transpose(), n + p2, n, delta).transpose().to_owned();
        d11 = append_rows(d11.transpose(), n + p2, 0, 0.0).transpose().to_owned();
    }
    Channels { b1, c1, d11, d12, d21 }
}

/// `x` with `extra` rows appended below it, zero but for δ on the diagonal of the block that
/// starts `from` rows below `x` (entry (r + from + j, j), r = `x`'s row count): the added rows
/// of an augmented channel (δ = 0: zero rows). Columns are appended by transposing.
fn append_rows(x: MatRef<'_, f64>, extra: usize, from: usize, delta: f64) -> Mat<f64> {
    let r = x.nrows();
    Mat::from_fn(r + extra, x.ncols(), |i, j| {
        if i < r {
            x[(i, j)]
        } else if i >= r + from && i - r - from == j {
            delta
        } else {
            0.0
        }
    })
}
