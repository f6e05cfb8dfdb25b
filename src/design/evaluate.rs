//! [`evaluate`]: one controller K on a problem's plants, as verification sees it — the one
//! evaluation behind a design's verified status ([`stabilises`](super::stabilises)), the
//! campaign's re-verification of journal records and order chaining, `campaign check` and
//! `campaign design`.
//!
//! Per plant j, on the closed loop A_cl of K: the stability measure s(A_cl) (α, or ρ − 1 in
//! discrete time) with its verification margin, both from one balancing
//! (`lti::verified_stability`: stable means s < −margin, docs/ALGORITHMS.md §5), and ‖Tzw‖∞ with
//! its peak frequency in rad/s (`lti::hinf_norm_in`, on the imaginary axis or the unit circle);
//! for a problem of several plants (or another objective, weight or bound) each plant's value
//! g_j of its objective with its weight and bound (`design::plant_values`). Of K itself: ‖K‖∞
//! and, for nk > 0, s(A_K) with its margin. Norms to the tolerance
//! [`DEFAULT_HINF_TOL`](crate::lti::DEFAULT_HINF_TOL) (the optimiser's figures of a run, to the
//! run's `hinf_tol`, are the outcome's: `design::run`).
//!
//! [`Evaluation::verdict`] is the rule a controller must pass to count: every closed loop formed
//! and stable with the margin, K too under the strong objective, every ‖Tzw‖∞ finite, every bound
//! met, and γ finite.

use crate::lti::{
    closed_loop, controller_hinf_grad, hinf_norm_checked, near_peak_frequencies, verified_stability, Controller,
    ControllerErrorKind, HinfNorm, HinfParams, LtiError, Plant, TimeDomain, VerifiedStability, DEFAULT_HINF_TOL,
    NORM_TIE_RTOL,
};

use super::options::{DesignOptions, ObjectiveKind};
use super::problem::{nan_max, plant_value, plant_values, problem_gamma, PlantObjective, PlantValue, Problem};

/// One closed loop of K, as [`evaluate`] finds it.
#[derive(Debug, Clone, PartialEq)]
pub struct LoopEvaluation {
    /// s(A_cl) and its verification margin.
    pub stability: VerifiedStability,
    /// ‖Tzw‖∞ (+∞ for an unstable loop) and its peak frequency, in rad/s in either domain.
    pub hinf: HinfNorm,
}

/// One plant's part of an [`Evaluation`].
#[derive(Debug, Clone, PartialEq)]
pub struct PlantEvaluation {
    /// The plant's name.
    pub plant: String,
    /// Its time domain.
    pub domain: TimeDomain,
    /// Its closed loop with K, or why it could not be formed (an ill-posed loop, a controller of
    /// another domain).
    pub closed_loop: Result<LoopEvaluation, LtiError>,
}

/// K itself, as [`evaluate`] finds it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControllerEvaluation {
    /// ‖K‖∞ (+∞ if K is not stable; σmax(Dk) for nk = 0).
    pub hinf: f64,
    /// s(A_K) and its verification margin; `None` for nk = 0.
    pub stability: Option<VerifiedStability>,
}

impl ControllerEvaluation {
    /// Whether K is stable with the verification margin (nk = 0 always is).
    pub fn is_stable(&self) -> bool {
        self.stability.is_none_or(|s| s.is_stable())
    }
}

/// Everything [`evaluate`] computes of K on a problem.
#[derive(Debug, Clone, PartialEq)]
pub struct Evaluation {
    /// Per plant, in the problem's order.
    pub plants: Vec<PlantEvaluation>,
    /// Each plant's value g_j of its objective, weight, bound and whether the bound is met, for a
    /// problem of several plants (or another objective, weight or bound: `design::plant_values`,
    /// as the journal records it); empty for the single H∞ plant, whose value is its ‖Tzw‖∞.
    pub values: Vec<PlantValue>,
    /// K itself.
    pub controller: ControllerEvaluation,
}

/// Why a controller does not count ([`Evaluation::verdict`]); the message names the plant of a
/// problem of several.
#[derive(Debug, thiserror::Error)]
pub enum Rejection {
    /// The closed loop of plant `plant` could not be formed.
    #[error("{}closed loop: {error}", plant_prefix(.plant))]
    ClosedLoop {
        /// The plant's name (`None` for the single plant).
        plant: Option<String>,
        /// Why.
        error: LtiError,
    },
    /// A closed loop is not stable with the verification margin.
    #[error("{}closed loop not stable ({symbol} = {measure}, must be below −{margin:.1e})", plant_prefix(.plant))]
    LoopUnstable {
        /// The plant's name (`None` for the single plant).
        plant: Option<String>,
        /// "α" or "ρ − 1".
        symbol: &'static str,
        /// s(A_cl).
        measure: f64,
        /// Its margin.
        margin: f64,
    },
    /// K is not stable with the margin, and the strong objective asks it to be.
    #[error("{}controller not stable ({symbol} of A_K = {measure}, must be below −{margin:.1e})", plant_prefix(.plant))]
    ControllerUnstable {
        /// The plant's name (`None` for the single plant).
        plant: Option<String>,
        /// "α" or "ρ − 1".
        symbol: &'static str,
        /// s(A_K).
        measure: f64,
        /// Its margin.
        margin: f64,
    },
    /// A plant's ‖Tzw‖∞, or the problem's γ (`plant` `None`), is not finite.
    #[error("{}γ not finite ({gamma})", plant_prefix(.plant))]
    NotFinite {
        /// The plant's name, or `None` for γ of the single plant or of the problem.
        plant: Option<String>,
        /// The value.
        gamma: f64,
    },
    /// A plant's bound is violated.
    #[error("plant {plant}: bound violated (w·g = {} > {})", crate::numeric::readable(*.weighted), crate::numeric::readable(*.bound))]
    BoundViolated {
        /// The plant's name.
        plant: String,
        /// w_j·g_j.
        weighted: f64,
        /// b_j.
        bound: f64,
    },
    /// The controller does not fit a plant or is not of the job's order.
    #[error("{}controller does not fit the job: {error}", plant_prefix(.plant))]
    DoesNotFit {
        /// The plant's name (`None` for the single plant).
        plant: Option<String>,
        /// Why.
        error: ControllerErrorKind,
    },
    /// The problem has no plant.
    #[error("no plant")]
    NoPlant,
}

fn plant_prefix(plant: &Option<String>) -> String {
    plant.as_ref().map_or_else(String::new, |p| format!("plant {p}: "))
}

/// Whether `k` stabilises every plant of `problem` as `opts` asks, with the verification margin
/// (`lti::verified_stability`, the test of [`evaluate`], `design --out` and `campaign
/// report`): every closed loop stable and, with the strong objective, the controller too. `Err`
/// holds the largest of the closed-loop measures and ε·α(A_K) (strong), as
/// [`DesignStatus::NotStabilised`](super::DesignStatus::NotStabilised) reports it.
pub fn stabilises(problem: &Problem, opts: &DesignOptions, k: &Controller) -> Result<(), f64> {
    let mut worst = f64::NEG_INFINITY;
    let mut stable = true;
    for t in &problem.terms {
        match closed_loop(&t.plant, k) {
            Ok(cl) => {
                let s = verified_stability(t.plant.domain, cl.a.as_ref());
                worst = nan_max(worst, s.measure);
                stable &= s.is_stable();
            }
            Err(_) => (worst, stable) = (f64::INFINITY, false),
        }
    }
    if opts.objective == ObjectiveKind::Strong && k.order() > 0 {
        let s = verified_stability(k.domain, k.ak.as_ref());
        worst = nan_max(worst, opts.eps * s.measure);
        stable &= s.is_stable();
    }
    if stable {
        Ok(())
    } else {
        Err(worst)
    }
}

/// The evaluation of a campaign job's controller `k`, which must be of the job's `order` (a
/// journal record's controller is checked against its job): [`evaluate`] of the job's problem
/// (`multi`: several plants, or another objective, weight or bound), else [`evaluate_plant`] of
/// its plant; [`Rejection::DoesNotFit`] if `k` does not fit.
pub fn evaluate_job(
    multi: Option<&Problem>,
    plant: &Plant,
    k: &Controller,
    order: usize,
) -> Result<Evaluation, Rejection> {
    match multi {
        Some(problem) => {
            for t in &problem.terms {
                k.check_fits_order(&t.plant, order)
                    .map_err(|error| Rejection::DoesNotFit { plant: Some(t.plant.name.clone()), error })?;
            }
            Ok(evaluate(problem, k))
        }
        None => {
            k.check_fits_order(plant, order).map_err(|error| Rejection::DoesNotFit { plant: None, error })?;
            Ok(evaluate_plant(plant, k))
        }
    }
}

/// Evaluates `k` on every plant of `problem` (module docs). `k` must fit the plants (a closed
/// loop that cannot be formed is reported per plant).
pub fn evaluate(problem: &Problem, k: &Controller) -> Evaluation {
    let plants = problem.terms.iter().map(|t| plant_evaluation(&t.plant, k)).collect();
    let values = if problem.is_single_hinf() { Vec::new() } else { plant_values(problem, k, DEFAULT_HINF_TOL) };
    Evaluation { plants, values, controller: controller_evaluation(k) }
}

/// [`evaluate`] of the single H∞ problem of `plant` ([`Problem::single`], without copying the
/// plant).
pub fn evaluate_plant(plant: &Plant, k: &Controller) -> Evaluation {
    Evaluation { plants: vec![plant_evaluation(plant, k)], values: Vec::new(), controller: controller_evaluation(k) }
}

fn plant_evaluation(plant: &Plant, k: &Controller) -> PlantEvaluation {
    let closed_loop = closed_loop(plant, k).map(|cl| {
        let stability = verified_stability(plant.domain, cl.a.as_ref());
        // a loop not stable with the margin is unstable here: its norm is +∞, as the design's
        // (a finite ‖Tzw‖∞ = 1.1e14 was printed beside "UNSTABLE" for α(A_cl) = −4e-16)
        let h = if stability.is_stable() { hinf_norm_checked(plant.domain, &cl) } else { HinfNorm::UNSTABLE };
        // in rad/s (a discrete norm's θ is in rad/sample)
        LoopEvaluation {
            stability,
            hinf: HinfNorm { value: h.value, peak_freq: plant.domain.to_rad_per_s(h.peak_freq) },
        }
    });
    PlantEvaluation { plant: plant.name.clone(), domain: plant.domain, closed_loop }
}

fn controller_evaluation(k: &Controller) -> ControllerEvaluation {
    let stability = (k.order() > 0).then(|| verified_stability(k.domain, k.ak.as_ref()));
    ControllerEvaluation { hinf: controller_hinf_grad(k, DEFAULT_HINF_TOL).0.value, stability }
}

impl Evaluation {
    /// γ: the problem's (the largest weighted value of the plants without a bound, of all if
    /// each has one: `design::problem_gamma`), or the single plant's ‖Tzw‖∞ (+∞ if its loop
    /// could not be formed).
    pub fn gamma(&self) -> f64 {
        if !self.values.is_empty() {
            return problem_gamma(&self.values);
        }
        self.plants.first().map_or(f64::NAN, |p| p.closed_loop.as_ref().map_or(f64::INFINITY, |l| l.hinf.value))
    }

    /// The largest closed-loop stability measure (+∞ if a loop could not be formed).
    pub fn worst_loop_measure(&self) -> f64 {
        let measure = |p: &PlantEvaluation| p.closed_loop.as_ref().map_or(f64::INFINITY, |l| l.stability.measure);
        self.plants.iter().map(measure).fold(f64::NEG_INFINITY, f64::max)
    }

    /// Whether K counts as a solution of the problem under `objective` (module docs): `Ok(γ)`,
    /// or the first reason it does not, plant by plant in the problem's order.
    pub fn verdict(&self, objective: ObjectiveKind) -> Result<f64, Rejection> {
        let named = self.plants.len() > 1 || !self.values.is_empty();
        if self.plants.is_empty() {
            return Err(Rejection::NoPlant);
        }
        let k = &self.controller;
        for p in &self.plants {
            let plant = named.then(|| p.plant.clone());
            let l = match &p.closed_loop {
                Ok(l) => l,
                Err(e) => return Err(Rejection::ClosedLoop { plant, error: e.clone() }),
            };
            let symbol = p.domain.stability_symbol();
            if !l.stability.is_stable() {
                let (measure, margin) = (l.stability.measure, l.stability.margin);
                return Err(Rejection::LoopUnstable { plant, symbol, measure, margin });
            }
            if !k.is_stable() && objective == ObjectiveKind::Strong {
                let s = k.stability.unwrap_or(VerifiedStability { measure: f64::NAN, margin: f64::NAN });
                return Err(Rejection::ControllerUnstable { plant, symbol, measure: s.measure, margin: s.margin });
            }
            if !l.hinf.value.is_finite() {
                return Err(Rejection::NotFinite { plant, gamma: l.hinf.value });
            }
        }
        if let Some(v) = self.values.iter().find(|v| !v.bound_met()) {
            let (weighted, bound) = (v.weighted(), v.bound.unwrap_or(f64::NAN));
            return Err(Rejection::BoundViolated { plant: v.plant.clone(), weighted, bound });
        }
        let gamma = self.gamma();
        if !gamma.is_finite() {
            return Err(Rejection::NotFinite { plant: None, gamma });
        }
        Ok(gamma)
    }
}

/// What `campaign check` reports of a closed loop beyond its [`LoopEvaluation`].
#[derive(Debug, Clone, PartialEq)]
pub struct LoopDetails {
    /// Every frequency (rad/s) where σmax(Tzw) is within
    /// [`NORM_TIE_RTOL`](crate::lti::NORM_TIE_RTOL) of ‖Tzw‖∞ (`lti::near_peak_frequencies`; an
    /// optimal controller often equalises several peaks); empty for an unstable loop.
    pub peak_freqs: Vec<f64>,
    /// ‖Tzw‖₂ (+∞ where it is not finite or the loop is unstable).
    pub h2: f64,
    /// 1/r_C, the inverse complex stability radius of A_cl (continuous time only).
    pub inverse_radius: Option<f64>,
}

/// The [`LoopDetails`] of `k` on `plant`, whose loop has the norm `hinf` ([`LoopEvaluation::hinf`],
/// peak in rad/s).
pub fn loop_details(plant: &Plant, k: &Controller, hinf: &HinfNorm) -> Result<LoopDetails, LtiError> {
    let cl = closed_loop(plant, k)?;
    if !hinf.value.is_finite() {
        // unstable (with the margin, `plant_evaluation`): every norm of it is +∞
        let inverse_radius = (!plant.domain.is_discrete()).then_some(f64::INFINITY);
        return Ok(LoopDetails { peak_freqs: Vec::new(), h2: f64::INFINITY, inverse_radius });
    }
    let peak_freqs = near_peak_frequencies(plant.domain, &cl, hinf, NORM_TIE_RTOL);
    let params = HinfParams::default();
    let value = |o: PlantObjective| plant_value(plant, o, k, &params).map_or(f64::INFINITY, |(v, _)| v);
    let h2 = value(PlantObjective::H2);
    let inverse_radius = (!plant.domain.is_discrete()).then(|| value(PlantObjective::Radius));
    Ok(LoopDetails { peak_freqs, h2, inverse_radius })
}
