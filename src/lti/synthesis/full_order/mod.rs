//! The optimal full-order H∞ level γ_opt of a generalised plant (the "full" row of the paper's
//! tables), by γ-iteration on the two Riccati equations. One idea per file:
//!
//! * `gamma_test.rs`: the γ-test — for a given γ, the X and Y Riccati equations, X, Y ⪰ 0 and the
//!   coupling ρ(XY) < γ² (the theory and references are there);
//! * `exogenous_weights.rs`: the γ-test's Riccati constant terms as Gram products in the
//!   normalised coordinates (no cancellation when B1·D21ᵀ ≠ 0 or D12ᵀ·C1 ≠ 0);
//! * `bracketing.rs`: the γ-iteration — feasibility is monotone in γ, so γ_opt is bracketed and
//!   bisected to [`GAMMA_RTOL`];
//! * `regularisation.rs`: plants with a rank-deficient D12 or D21 — δ-weighted channels are added
//!   and δ is decreased through [`REGULARISATION_DELTAS`] while γ(δ) can be trusted;
//! * `linalg.rs`: the small dense linear algebra the others share (numerical rank, the D11 bound,
//!   symmetric eigen-decomposition, LU solve, block concatenation).
//!
//! This file holds the result, the error and the options, and the entry points
//! [`full_order_gamma`], [`full_order_gamma_with`] and, for discrete-time plants through the
//! bilinear transform, [`full_order_gamma_discrete`]; all public names of the former single file
//! `full_order.rs` stay reachable here.

use std::fmt;

use super::plant_image::{ImageError, PlantImage};
use crate::lti::system::plant::Plant;
use crate::numeric::all_finite;

mod bracketing;
mod exogenous_weights;
mod gamma_test;
pub(super) mod linalg;
mod regularisation;

pub use bracketing::{GAMMA_MAX, GAMMA_RTOL};
/// The absolute part of the X ⪰ 0 / Y ⪰ 0 test, shared with the central controller.
pub(crate) use gamma_test::PSD_ATOL;
/// The δ-augmentation of a singular D12/D21, shared with the central-controller start.
pub(crate) use regularisation::augment;
pub use regularisation::{Regularisation, FLAT_RTOL, REGULARISATION_DELTAS};

use bracketing::gamma_opt;
use gamma_test::{Channels, Problem};
use linalg::numerical_rank;
use regularisation::decrease_eps;

/// Which condition of the γ-test fails just below γ_opt.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Binding {
    /// γ_opt equals the D11 bound (condition (i)).
    Feedthrough,
    /// The X (state-feedback) Riccati equation has no stabilising X ⪰ 0.
    StateFeedback,
    /// The Y (output-injection / filter) Riccati equation has no stabilising Y ⪰ 0.
    Filter,
    /// The coupling condition ρ(XY) < γ².
    Coupling,
    /// γ_opt = 0 (every tried level was feasible).
    None,
}

impl Binding {
    /// Short human-readable text.
    pub fn text(self) -> &'static str {
        match self {
            Binding::Feedthrough => "D11 bound",
            Binding::StateFeedback => "X Riccati (state feedback)",
            Binding::Filter => "Y Riccati (filter)",
            Binding::Coupling => "coupling rho(XY) = gamma^2",
            Binding::None => "none",
        }
    }
}

/// The full-order optimal H∞ level and how it was obtained.
#[derive(Debug, Clone, serde::Serialize)]
pub struct FullOrderGamma {
    /// γ_opt (feasible end of the final bracket; at the reported δ for singular plants).
    pub gamma: f64,
    /// Infeasible end of the final bracket (γ_opt ∈ (gamma_lower, gamma]).
    pub gamma_lower: f64,
    /// The regularisation δ at which `gamma` was evaluated; `None` for a regular plant.
    pub regularisation: Option<f64>,
    /// Numerical rank of D12 (m2 = full column rank).
    pub d12_rank: usize,
    /// Numerical rank of D21 (p2 = full row rank).
    pub d21_rank: usize,
    /// D12 was regularised (z augmented with δ x, δ u).
    pub d12_regularised: bool,
    /// D21 was regularised (w augmented with δ state noise, δ sensor noise).
    pub d21_regularised: bool,
    /// γ(δ) for every δ evaluated, in order (empty for a regular plant).
    pub regularisation_history: Vec<(f64, f64)>,
    /// Whether γ(δ) was flat to [`FLAT_RTOL`] at the reported δ (true for a regular plant).
    pub regularisation_converged: bool,
    /// The condition that fails just below γ_opt.
    pub binding: Binding,
    /// The D11 lower bound (condition (i)).
    pub feedthrough_bound: f64,
    /// Number of γ-tests (pairs of Riccati solves) performed in total.
    pub gamma_tests: usize,
    /// Remarks (e.g. why δ was not decreased further).
    pub notes: Vec<String>,
}

impl FullOrderGamma {
    /// A one-paragraph description for `campaign plant NAME`.
    pub fn describe(&self) -> String {
        self.to_string()
    }
}

impl fmt::Display for FullOrderGamma {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "full-order gamma_opt = {:.7} (bracket ({:.7}, {:.7}], {} gamma-tests; binding: {})",
            self.gamma,
            self.gamma_lower,
            self.gamma,
            self.gamma_tests,
            self.binding.text()
        )?;
        if let Some(delta) = self.regularisation {
            let mut what = Vec::new();
            if self.d21_regularised {
                what.push(format!("D21 rank {} (w augmented with delta*I state and sensor noise)", self.d21_rank));
            }
            if self.d12_regularised {
                what.push(format!("D12 rank {} (z augmented with delta*x, delta*u)", self.d12_rank));
            }
            write!(f, "\n  singular plant: {}; regularised, reported at delta = {delta:.0e}", what.join("; "))?;
            let hist: Vec<String> =
                self.regularisation_history.iter().map(|(e, g)| format!("{e:.0e}: {g:.7}")).collect();
            write!(
                f,
                "\n  gamma(delta): {}{}",
                hist.join(", "),
                if self.regularisation_converged {
                    " (flat)"
                } else {
                    " (not flat: an upper bound of the delta -> 0 limit)"
                }
            )?;
        }
        for n in &self.notes {
            write!(f, "\n  note: {n}")?;
        }
        Ok(())
    }
}

/// Why γ_opt could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FullOrderError {
    /// Plant data with NaN or infinity.
    #[error("plant has non-finite entries")]
    NonFinite,
    /// The plant has no control input or no measurement.
    #[error("plant has m2 = {m2} control inputs and p2 = {p2} measurements; both must be positive")]
    NoControl {
        /// Control inputs.
        m2: usize,
        /// Measurements.
        p2: usize,
    },
    /// No γ up to [`GAMMA_MAX`] passes the test (e.g. (A, B2) not stabilisable, (C2, A) not
    /// detectable, or the rank conditions fail on the imaginary axis).
    #[error("no feasible gamma up to {gamma_max:e} (last failure: {last})")]
    NoFeasibleGamma {
        /// Largest γ tried.
        gamma_max: f64,
        /// The last failure seen.
        last: String,
    },
    /// A rank or eigenvalue computation failed.
    #[error("linear algebra failure: {0}")]
    LinearAlgebra(&'static str),
}

/// Options of [`full_order_gamma_with`].
#[derive(Debug, Clone, PartialEq)]
pub struct FullOrderOptions {
    /// Relative width of the final bracket.
    pub rtol: f64,
    /// Regularisation policy.
    pub regularisation: Regularisation,
}

impl Default for FullOrderOptions {
    fn default() -> Self {
        FullOrderOptions { rtol: GAMMA_RTOL, regularisation: Regularisation::Auto }
    }
}

/// γ_opt of the plant with default options (see the module docs).
pub fn full_order_gamma(plant: &Plant) -> Result<FullOrderGamma, FullOrderError> {
    full_order_gamma_with(plant, &FullOrderOptions::default())
}

/// γ_opt of a discrete-time plant: the continuous-time γ_opt of its bilinear image
/// (`kernels/bilinear.rs`, docs/ALGORITHMS.md §10.4). The map z = ±(1 + s)/(1 − s) takes every
/// discrete controller to a continuous one of the same order and back, the closed loop of the
/// images to the image of the closed loop, the unit disc to the left half-plane and the circle
/// to the axis, so the two infima are equal. The result's notes and regularisation refer to the
/// image (its D12 and D21 are P12 and P21 at z = ∓1, not the discrete D12 and D21).
/// `Err(LinearAlgebra)` if A has eigenvalues at both z = 1 and z = −1 (no image).
///
/// The plant's matrices are taken as discrete-time ones whatever its `domain`;
/// [`full_order_gamma_with`] comes here for a plant whose domain is discrete.
pub fn full_order_gamma_discrete(plant: &Plant, opts: &FullOrderOptions) -> Result<FullOrderGamma, FullOrderError> {
    let image = PlantImage::new(plant)
        .map_err(|e| match e {
            ImageError::NonFinite => FullOrderError::NonFinite,
            ImageError::NoImage => {
                FullOrderError::LinearAlgebra("bilinear transform: A has eigenvalues at both z = 1 and z = −1")
            }
        })?
        .plant;
    full_order_gamma_with(&image, opts)
}

/// γ_opt of the plant with explicit options (of its bilinear image for a discrete-time plant,
/// [`full_order_gamma_discrete`]).
pub fn full_order_gamma_with(plant: &Plant, opts: &FullOrderOptions) -> Result<FullOrderGamma, FullOrderError> {
    if plant.domain.is_discrete() {
        return full_order_gamma_discrete(plant, opts);
    }
    let d = plant.dims;
    if d.m2 == 0 || d.p2 == 0 {
        return Err(FullOrderError::NoControl { m2: d.m2, p2: d.p2 });
    }
    for m in [&plant.a, &plant.b1, &plant.b2, &plant.c1, &plant.c2, &plant.d11, &plant.d12, &plant.d21] {
        if !all_finite(m.as_ref()) {
            return Err(FullOrderError::NonFinite);
        }
    }
    let d12_rank = numerical_rank(plant.d12.as_ref())?;
    let d21_rank = numerical_rank(plant.d21.as_ref())?;
    let d12_reg = d12_rank < d.m2;
    let d21_reg = d21_rank < d.p2;
    let mut tests = 0usize;
    let mut notes = Vec::new();

    if !d12_reg && !d21_reg {
        let prob = Problem::new(plant, Channels::of(plant))?;
        let b = gamma_opt(&prob, opts.rtol, None, &mut tests)?;
        return Ok(FullOrderGamma {
            gamma: b.hi,
            gamma_lower: b.lo,
            regularisation: None,
            d12_rank,
            d21_rank,
            d12_regularised: false,
            d21_regularised: false,
            regularisation_history: Vec::new(),
            regularisation_converged: true,
            binding: b.binding,
            feedthrough_bound: prob.gamma_d,
            gamma_tests: tests,
            notes,
        });
    }

    let r = decrease_eps(plant, opts, d12_reg, d21_reg, &mut tests, &mut notes)?;
    Ok(FullOrderGamma {
        gamma: r.bracket.hi,
        gamma_lower: r.bracket.lo,
        regularisation: Some(r.delta),
        d12_rank,
        d21_rank,
        d12_regularised: d12_reg,
        d21_regularised: d21_reg,
        regularisation_history: r.history,
        regularisation_converged: r.converged,
        binding: r.bracket.binding,
        feedthrough_bound: r.feedthrough_bound,
        gamma_tests: tests,
        notes,
    })
}
