//! Several plants, one controller (docs/ALGORITHMS.md §14): HIFOO's multi-model problem
//!
//! ```text
//! minimise   max( max_{j ∈ U} w_j·g_j(K),  ε‖K‖∞ )  +  μ · Σ_{j ∈ B} max(0, w_j·g_j(K) − b_j)
//! ```
//!
//! over the controllers K that stabilise every plant (and, strong stabilisation, K itself), where
//! g_j is plant j's objective ([`PlantObjective`]: ‖Tzw‖∞, ‖Tzw‖₂, the stability measure of its
//! closed loop, or 1/r_C of its closed loop), w_j > 0 its weight, U the plants without a bound and
//! B those with one (bound b_j). The constraint w_j·g_j ≤ b_j is enforced by the exact ℓ1 penalty
//! with the fixed weight μ = [`PENALTY_WEIGHT`]; with U empty the first term is ε‖K‖∞ (strong) or
//! nothing, and the problem is one of feasibility. The stabilisation phase is that of one plant
//! with the max taken over all: max( max_j s(A_cl,j), ε·s(Ak) ), s = α, or ρ − 1 in discrete time.
//!
//! An H2 objective needs strictly proper loops in continuous time: every controller is projected
//! onto {Dk : D11 + D12 Dk D21 = 0} (`lti::h2_feedthrough_parameterisation`), whose gradient is the
//! projection of ∇_Dk onto the affine set's directions ([`H2Feedthrough`]).
//!
//! A problem of one plant with the H∞ objective, weight 1 and no bound is today's single-plant
//! design, which [`super::run`] computes by exactly the single-plant code.

use std::fmt;
use std::str::FromStr;

use faer::Mat;
use serde::{Deserialize, Serialize};

use crate::lti::{
    closed_loop, closed_loop_h2_grad_in, closed_loop_hinf_grad, closed_loop_inverse_stability_radius_grad,
    closed_loop_stability_grad, h2_feedthrough_parameterisation, stability_measure, Controller, ControllerGradient,
    DkAffine, FeedthroughError, HinfParams, LtiError, Plant, TimeDomain,
};

/// Weight μ of the exact ℓ1 penalty on violated bounds (module docs). It is exact once μ exceeds
/// the constraint's Lagrange multiplier; in a max-type objective those are the weights of a
/// convex combination of gradients, at most 1 for weights near 1, so 10 leaves a margin
/// (docs/ALGORITHMS.md §14.2).
pub const PENALTY_WEIGHT: f64 = 10.0;

/// Largest weight w_j of a plant. Weights and bounds are checked before a design starts so that
/// the objective cannot overflow after the search (a weight of 1e308 once journaled γ = inf and
/// exited 0): with plant entries below 1e50 (`lti::MAX_PLANT_MAGNITUDE`) the values g_j a
/// stabilising controller reaches stay far enough below f64's 1.8e308.
pub const MAX_WEIGHT: f64 = 1e50;
/// Smallest weight w_j of a plant: a smaller one makes w·g underflow to 0 and the plant's term
/// vanish from the objective.
pub const MIN_WEIGHT: f64 = 1e-50;
/// Largest |b_j| of a bound (see [`MAX_WEIGHT`]).
pub const MAX_BOUND: f64 = 1e50;

/// Relative tolerance of [`PlantValue::bound_met`]: the exact penalty ends a design on the
/// constraint w·g = b when the bound is active, where the rounding of the norms decides which side
/// the recomputed value falls (HE1 at two operating points, bound 0.135 on the second:
/// w·g − b = 1.1e-9); a reader of six significant figures sees it met.
pub const BOUND_RTOL: f64 = 1e-6;

/// What is measured on one plant's closed loop.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum PlantObjective {
    /// ‖Tzw‖∞ (HIFOO's default).
    #[default]
    Hinf,
    /// ‖Tzw‖₂ (continuous time: D11 + D12 Dk D21 = 0 kept by the design, D22 = 0 required).
    H2,
    /// The closed loop's stability measure α(A_cl) (ρ(A_cl) − 1 in discrete time): stabilisation
    /// with a margin.
    Abscissa,
    /// 1/r_C(A_cl) = ‖(sI − A_cl)⁻¹‖∞, the reciprocal of the complex stability radius
    /// (continuous time).
    Radius,
}

impl PlantObjective {
    /// Every objective, in the order of the docs.
    pub const ALL: [PlantObjective; 4] =
        [PlantObjective::Hinf, PlantObjective::H2, PlantObjective::Abscissa, PlantObjective::Radius];

    /// The name of `--objective` and of campaign files.
    pub fn name(self) -> &'static str {
        match self {
            PlantObjective::Hinf => "hinf",
            PlantObjective::H2 => "h2",
            PlantObjective::Abscissa => "abscissa",
            PlantObjective::Radius => "radius",
        }
    }

    /// Whether the value `g` of this objective means an unstable loop, which the performance
    /// objective counts as +∞ (docs/ALGORITHMS.md §14.1): for the abscissa objective g ≥ 0 (or
    /// NaN); the norms are +∞ there themselves.
    pub fn means_unstable(self, g: f64) -> bool {
        self == PlantObjective::Abscissa && !(g < 0.0)
    }

    /// The quantity as a reader sees it (‖Tzw‖∞, …) for a plant in `domain`: the abscissa
    /// objective of a discrete plant is ρ(A_cl) − 1 (`lti::stability_measure`).
    pub fn symbol(self, domain: TimeDomain) -> &'static str {
        match self {
            PlantObjective::Hinf => "‖Tzw‖∞",
            PlantObjective::H2 => "‖Tzw‖₂",
            PlantObjective::Abscissa if domain.is_discrete() => "ρ(A_cl) − 1",
            PlantObjective::Abscissa => "α(A_cl)",
            PlantObjective::Radius => "1/r_C(A_cl)",
        }
    }
}

impl fmt::Display for PlantObjective {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// An objective name that is none of hinf, h2, abscissa, radius.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown objective {0:?} (expected hinf, h2, abscissa or radius)")]
pub struct UnknownObjective(pub String);

impl FromStr for PlantObjective {
    type Err = UnknownObjective;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        PlantObjective::ALL.into_iter().find(|o| o.name() == s).ok_or_else(|| UnknownObjective(s.to_string()))
    }
}

/// One plant of a problem with its objective, weight and optional bound.
#[derive(Debug, Clone)]
pub struct PlantTerm {
    /// The plant.
    pub plant: Plant,
    /// What is measured on its closed loop.
    pub objective: PlantObjective,
    /// w_j > 0.
    pub weight: f64,
    /// b_j: the constraint w_j·g_j ≤ b_j; `None`: the plant is in the minimised max.
    pub bound: Option<f64>,
}

impl PlantTerm {
    /// The plant with the H∞ objective, weight 1 and no bound.
    pub fn hinf(plant: Plant) -> Self {
        PlantTerm { plant, objective: PlantObjective::Hinf, weight: 1.0, bound: None }
    }
}

/// Why a problem cannot be designed for. `plant` is the 1-based position of the plant (as the
/// `--plant`s are given) and its name.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ProblemError {
    /// No plant at all.
    #[error("no plant given")]
    Empty,
    /// Another number of controls or measurements than the first plant's.
    #[error("plant {index} ({name}) has {m2} controls and {p2} measurements, plant 1 has {m2_first} and {p2_first}: one controller must fit every plant")]
    Channels {
        /// 1-based position.
        index: usize,
        /// Its name.
        name: String,
        /// Its controls.
        m2: usize,
        /// Its measurements.
        p2: usize,
        /// Plant 1's controls.
        m2_first: usize,
        /// Plant 1's measurements.
        p2_first: usize,
    },
    /// Another time domain (continuous, or another sampling time) than the first plant's.
    #[error("plant {index} ({name}) is {domain}, plant 1 is {first}: one controller must run in one time domain")]
    Domain {
        /// 1-based position.
        index: usize,
        /// Its name.
        name: String,
        /// Its domain.
        domain: String,
        /// Plant 1's.
        first: String,
    },
    /// A weight outside [[`MIN_WEIGHT`], [`MAX_WEIGHT`]].
    #[error(
        "plant {index} ({name}): weight {} must be a number from {MIN_WEIGHT:e} to {MAX_WEIGHT:e} (the weighted \
         values w·g, and the penalty on violated bounds, must stay finite)",
        crate::numeric::readable(*value)
    )]
    Weight {
        /// 1-based position.
        index: usize,
        /// Its name.
        name: String,
        /// The weight.
        value: f64,
    },
    /// A bound that is not finite or larger than [`MAX_BOUND`] in absolute value.
    #[error(
        "plant {index} ({name}): bound {} must be a finite number from −{MAX_BOUND:e} to {MAX_BOUND:e}",
        crate::numeric::readable(*value)
    )]
    Bound {
        /// 1-based position.
        index: usize,
        /// Its name.
        name: String,
        /// The bound.
        value: f64,
    },
    /// The stability radius objective on a discrete-time plant.
    #[error("plant {index} ({name}): the radius objective (1/r_C, the complex stability radius of the left half-plane) is for continuous-time plants; use abscissa (ρ − 1) in discrete time")]
    RadiusDiscrete {
        /// 1-based position.
        index: usize,
        /// Its name.
        name: String,
    },
    /// A continuous H2 objective on a plant whose loops cannot be strictly proper.
    #[error("plant {index} ({name}): the h2 objective needs a strictly proper loop: {source}")]
    H2Feedthrough {
        /// 1-based position.
        index: usize,
        /// Its name.
        name: String,
        /// Why.
        source: FeedthroughError,
    },
    /// Continuous H2 objectives on plants whose feedthroughs ask for different sets of Dk.
    #[error("plants {first} and {index} ({name}) have the h2 objective with different D11, D12, D21: one controller feedthrough Dk cannot be parameterised for both (give them the same feedthroughs, or one of them another objective)")]
    H2Mixed {
        /// 1-based position of the first continuous H2 plant.
        first: usize,
        /// 1-based position of the other.
        index: usize,
        /// Its name.
        name: String,
    },
}

/// The affine set of controller feedthroughs {Dk : D11 + D12 Dk D21 = 0} of a problem's
/// continuous H2 plants, as an orthogonal projection (module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct H2Feedthrough(pub DkAffine);

impl H2Feedthrough {
    /// Dk projected onto the set: Dk0 + Σ ⟨Eᵢ, Dk⟩ Eᵢ (Dk0 ⟂ every Eᵢ).
    pub fn project(&self, dk: &Mat<f64>) -> Mat<f64> {
        let z = self.0.components(dk.as_ref()).expect("Dk of the plant's shape");
        self.0.dk(&z).expect("z of the set's dimension")
    }

    /// A gradient with respect to the projected Dk taken back through the projection: Σ ⟨Eᵢ, G⟩ Eᵢ.
    pub fn project_gradient(&self, g: &Mat<f64>) -> Mat<f64> {
        let z = self.0.components(g.as_ref()).expect("G of the plant's shape");
        let mut out = Mat::zeros(g.nrows(), g.ncols());
        for (zi, e) in z.iter().zip(&self.0.basis) {
            out += e * faer::Scale(*zi);
        }
        out
    }

    /// Whether every Dk is in the set (no constraint at all).
    pub fn is_everything(&self) -> bool {
        let m = &self.0.dk0;
        self.0.dim() == m.nrows() * m.ncols() && (0..m.ncols()).all(|j| (0..m.nrows()).all(|i| m[(i, j)] == 0.0))
    }
}

/// Several plants, one controller (module docs).
#[derive(Debug, Clone)]
pub struct Problem {
    /// The plants, in the order given.
    pub terms: Vec<PlantTerm>,
}

impl Problem {
    /// One plant with the H∞ objective (today's design).
    pub fn single(plant: Plant) -> Self {
        Problem { terms: vec![PlantTerm::hinf(plant)] }
    }

    /// The first plant: it gives the controller's sizes and domain, and the starting points.
    pub fn first(&self) -> &Plant {
        &self.terms[0].plant
    }

    /// Whether the strong objective's controller term is ε·s(Ak) rather than ε‖K‖∞: when every
    /// minimised plant's objective is the stability measure (`abscissa`), whose values are
    /// negative where the performance phase lives. ε‖K‖∞ > 0 would then always set f_p, and the
    /// design would minimise ‖K‖∞ on the stability boundary instead of the closed loop's margin
    /// (docs/ALGORITHMS.md §14.1). False where every plant has a bound (f_p is then ε‖K‖∞ plus
    /// the penalties: the smallest controller that meets the bounds).
    pub fn controller_term_is_abscissa(&self) -> bool {
        let mut minimised = self.terms.iter().filter(|t| t.bound.is_none()).peekable();
        minimised.peek().is_some() && minimised.all(|t| t.objective == PlantObjective::Abscissa)
    }

    /// Whether this is the single-plant H∞ problem: one plant, H∞, weight 1, no bound.
    pub fn is_single_hinf(&self) -> bool {
        matches!(self.terms.as_slice(), [t] if t.objective == PlantObjective::Hinf && t.weight == 1.0 && t.bound.is_none())
    }

    /// Checks sizes, domains, weights, bounds and objectives; the continuous H2 plants' affine
    /// set of feedthroughs (`None`: no constraint on Dk).
    pub fn validate(&self) -> Result<Option<H2Feedthrough>, ProblemError> {
        let first = self.terms.first().ok_or(ProblemError::Empty)?;
        let (m2, p2) = (first.plant.dims.m2, first.plant.dims.p2);
        let mut h2: Option<(usize, H2Feedthrough)> = None;
        for (i, t) in self.terms.iter().enumerate() {
            let (index, name) = (i + 1, t.plant.name.clone());
            if (t.plant.dims.m2, t.plant.dims.p2) != (m2, p2) {
                let (m2_first, p2_first) = (m2, p2);
                let (m2, p2) = (t.plant.dims.m2, t.plant.dims.p2);
                return Err(ProblemError::Channels { index, name, m2, p2, m2_first, p2_first });
            }
            if t.plant.domain != first.plant.domain {
                let (domain, first) = (t.plant.domain.to_string(), first.plant.domain.to_string());
                return Err(ProblemError::Domain { index, name, domain, first });
            }
            if !(MIN_WEIGHT..=MAX_WEIGHT).contains(&t.weight) {
                return Err(ProblemError::Weight { index, name, value: t.weight });
            }
            if let Some(b) = t.bound.filter(|b| !(b.abs() <= MAX_BOUND)) {
                return Err(ProblemError::Bound { index, name, value: b });
            }
            match t.objective {
                PlantObjective::Radius if t.plant.domain.is_discrete() => {
                    return Err(ProblemError::RadiusDiscrete { index, name })
                }
                PlantObjective::H2 if !t.plant.domain.is_discrete() => {
                    let set = h2_feedthrough_parameterisation(&t.plant)
                        .map_err(|source| ProblemError::H2Feedthrough { index, name: name.clone(), source })?;
                    match &h2 {
                        None => h2 = Some((index, H2Feedthrough(set))),
                        Some((j, other)) if other.0 != set => {
                            return Err(ProblemError::H2Mixed { first: *j, index, name })
                        }
                        Some(_) => {}
                    }
                }
                _ => {}
            }
        }
        Ok(h2.map(|(_, s)| s).filter(|s| !s.is_everything()))
    }
}

/// g_j = `objective` of `plant`'s closed loop with `k`, and its gradient (NaN entries where g_j is not finite). H∞ and 1/r_C
/// are computed as `params` ask. `Err(IllPosed)` for an ill-posed loop (the objective is then
/// +∞), `Err(Interrupted)` when `params.stop` fired.
pub fn plant_value(
    plant: &Plant,
    objective: PlantObjective,
    k: &Controller,
    params: &HinfParams<'_>,
) -> Result<(f64, ControllerGradient), LtiError> {
    match objective {
        PlantObjective::Hinf => closed_loop_hinf_grad(plant, k, params).map(|(n, g)| (n.value, g)),
        PlantObjective::H2 => closed_loop_h2_grad_in(plant, k),
        PlantObjective::Abscissa => closed_loop_stability_grad(plant, k),
        PlantObjective::Radius => {
            closed_loop_inverse_stability_radius_grad(plant, k, params).map(|(n, g)| (n.value, g))
        }
    }
}

/// One plant's figures for a controller, as the outcome, the journal and `check` report them.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PlantValue {
    /// The plant's name.
    pub plant: String,
    /// Its objective.
    pub objective: PlantObjective,
    /// w_j.
    #[serde(with = "super::float_serde::serde_f64_or_string")]
    pub weight: f64,
    /// b_j, if any.
    #[serde(default, with = "super::float_serde::serde_opt_f64_or_string")]
    pub bound: Option<f64>,
    /// g_j (unweighted; +∞ for an unstable loop where g_j needs stability).
    #[serde(with = "super::float_serde::serde_f64_or_string")]
    pub value: f64,
    /// The closed loop's stability measure (α, or ρ − 1 in discrete time).
    #[serde(with = "super::float_serde::serde_f64_or_string")]
    pub alpha_cl: f64,
    /// Whether its bound holds ([`PlantValue::bound_met`]): `null` without a bound, `true` met,
    /// `false` violated (`design --json`, the journal; absent, read as `null`, in records of
    /// older builds).
    #[serde(default)]
    pub bound_met: Option<bool>,
}

impl PlantValue {
    /// w_j·g_j.
    pub fn weighted(&self) -> f64 {
        self.weight * self.value
    }

    /// Whether its bound holds to [`BOUND_RTOL`] (true without a bound; false when w·g is NaN,
    /// and for the abscissa objective on an unstable loop, g ≥ 0, which the objective counts as
    /// +∞ — docs/ALGORITHMS.md §14.1 — whatever the bound: α = 0.21 under a bound 1 is no loop
    /// the bound admits).
    pub fn bound_met(&self) -> bool {
        let unstable = self.objective.means_unstable(self.value);
        self.bound.is_none_or(|b| !unstable && self.weighted() <= b + BOUND_RTOL * b.abs())
    }

    /// With the field [`PlantValue::bound_met`] set from the values.
    pub fn with_bound_verdict(self) -> Self {
        let met = self.bound.map(|_| self.bound_met());
        PlantValue { bound_met: met, ..self }
    }
}

/// Every plant's figures for `k` (g_j computed to `hinf_tol`; no gradient).
pub fn plant_values(problem: &Problem, k: &Controller, hinf_tol: f64) -> Vec<PlantValue> {
    let params = HinfParams::new(hinf_tol);
    problem
        .terms
        .iter()
        .map(|t| {
            let alpha_cl = closed_loop(&t.plant, k)
                .map(|cl| stability_measure(t.plant.domain, cl.a.as_ref()))
                .unwrap_or(f64::INFINITY);
            let value = plant_value(&t.plant, t.objective, k, &params).map_or(f64::INFINITY, |(v, _)| v);
            PlantValue {
                plant: t.plant.name.clone(),
                objective: t.objective,
                weight: t.weight,
                bound: t.bound,
                value,
                alpha_cl,
                bound_met: None,
            }
            .with_bound_verdict()
        })
        .collect()
}

/// The plants' part of the performance objective from their weighted values w_j·g_j:
/// (max over the unbounded plants, or −∞ if every plant has a bound; Σ of the bound violations).
pub fn plant_part(values: &[PlantValue]) -> (f64, f64) {
    let max = values.iter().filter(|v| v.bound.is_none()).map(PlantValue::weighted).fold(f64::NEG_INFINITY, nan_max);
    let violation = values.iter().filter_map(|v| v.bound.map(|b| (v.weighted() - b).max(0.0))).sum();
    (max, violation)
}

/// The problem's γ from its plants' values: the largest weighted value w_j·g_j of the plants
/// without a bound, of all plants if each has one (what [`super::DesignOutcome::gamma`] reports).
pub fn problem_gamma(values: &[PlantValue]) -> f64 {
    let free_max = plant_part(values).0;
    if free_max == f64::NEG_INFINITY {
        values.iter().map(PlantValue::weighted).fold(f64::NEG_INFINITY, nan_max)
    } else {
        free_max
    }
}

/// max that keeps a NaN.
pub(crate) fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() {
        f64::NAN
    } else {
        a.max(b)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn objective_names_read_back() {
        for o in PlantObjective::ALL {
            assert_eq!(o.name().parse::<PlantObjective>(), Ok(o));
        }
        assert_eq!("H2".parse::<PlantObjective>(), Err(UnknownObjective("H2".into())));
    }

    #[test]
    fn the_plant_part_is_the_max_of_the_free_and_the_sum_of_the_violations() {
        let v = |value: f64, weight: f64, bound: Option<f64>| {
            PlantValue {
                plant: "P".into(),
                objective: PlantObjective::Hinf,
                weight,
                bound,
                value,
                alpha_cl: -1.0,
                bound_met: None,
            }
            .with_bound_verdict()
        };
        let values = [v(2.0, 1.0, None), v(1.0, 3.0, None), v(5.0, 1.0, Some(4.0)), v(1.0, 1.0, Some(4.0))];
        assert_eq!(plant_part(&values), (3.0, 1.0));
        assert!(!values[2].bound_met() && values[3].bound_met());
        let met: Vec<Option<bool>> = values.iter().map(|v| v.bound_met).collect();
        assert_eq!(met, [None, None, Some(false), Some(true)]);
        assert_eq!(serde_json::to_value(&values[2]).unwrap()["bound_met"], serde_json::json!(false));
        assert_eq!(plant_part(&values[2..]).0, f64::NEG_INFINITY);
    }

    /// The abscissa objective's bound is never met by an unstable loop (g ≥ 0 counts as +∞),
    /// whatever the bound; a stable loop is judged by its value.
    #[test]
    fn an_unstable_loop_never_meets_an_abscissa_bound() {
        let v = |value: f64, bound: f64| PlantValue {
            plant: "P".into(),
            objective: PlantObjective::Abscissa,
            weight: 1.0,
            bound: Some(bound),
            value,
            alpha_cl: value,
            bound_met: None,
        };
        assert!(!v(0.2107, 1.0).bound_met() && !v(0.0, 1.0).bound_met() && !v(f64::NAN, 1.0).bound_met());
        assert!(v(-0.5, -0.1).bound_met() && !v(-0.05, -0.1).bound_met());
        assert_eq!(v(0.2107, 1.0).with_bound_verdict().bound_met, Some(false));
    }
}
