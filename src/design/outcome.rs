//! What a design run returns.

use serde::{Deserialize, Serialize};

use super::float_serde::{serde_f64_or_string, serde_opt_f64_or_string};

/// Phase of a design run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Phase {
    /// Minimising max(α(A_cl), ε·α(Ak)) until it is negative.
    Stabilisation,
    /// BFGS on max(‖Tzw‖∞, ε‖K‖∞).
    Optimisation,
    /// Gradient sampling from the best optimisation point.
    GradientSampling,
}

impl Phase {
    /// The phase's name as the journal and the traces write it.
    pub fn name(self) -> &'static str {
        match self {
            Phase::Stabilisation => "stabilisation",
            Phase::Optimisation => "optimisation",
            Phase::GradientSampling => "gradient_sampling",
        }
    }
}

/// How a design run ended. Failing to stabilise is an outcome, not an error.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum DesignStatus {
    /// Both phases ran and the final point meets the optimality certificate (dnorm ≤ normtol
    /// on a bundle of radius evaldist); the controller is stable and stabilising.
    Converged,
    /// Both phases ran and made progress, but a limit (iterations, stall, evaluations) ended the
    /// search before the certificate was met; the controller is stable and stabilising.
    /// Journals of older builds, which called both cases "optimised", read as this.
    #[serde(alias = "optimised")]
    Stopped,
    /// Stabilised, but the optimisation phase made no progress (or could not run).
    StabilisedOnly,
    /// No stabilising (strongly stabilising) controller found; the best abscissa reached.
    NotStabilised {
        /// Best max(α(A_cl), ε·α(Ak)) reached.
        #[serde(with = "serde_f64_or_string")]
        best_alpha: f64,
    },
    /// A budget (`cpumax` or `maxevals`, the search summary's stop reason says which) ran out
    /// before HIFOO's first starts were all made; the best controller so far is returned.
    BudgetExhausted,
    /// Stopped by a cancel request or an observer.
    Interrupted,
    /// The controller stabilises, but a plant's bound w·g ≤ b does not hold (to
    /// `design::BOUND_RTOL`): the constraints were not met, whatever the certificate says; the
    /// outcome's `plants` say which (`bound_met`).
    BoundViolated,
}

impl DesignStatus {
    /// The name of the status, as in the `kind` field of its JSON form (journal, CLI output).
    pub fn kind(&self) -> &'static str {
        match self {
            DesignStatus::Converged => "converged",
            DesignStatus::Stopped => "stopped",
            DesignStatus::StabilisedOnly => "stabilised_only",
            DesignStatus::NotStabilised { .. } => "not_stabilised",
            DesignStatus::BudgetExhausted => "budget_exhausted",
            DesignStatus::Interrupted => "interrupted",
            DesignStatus::BoundViolated => "bound_violated",
        }
    }
}

/// Per-phase counters. Written with the outcome's key names (`iterations`, `evaluations`,
/// `design_cpu_s`: one set of names in `design --json` and the journal); the names of older
/// builds (`iters`, `evals`, `cpu_s`) are still read.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PhaseStats {
    /// Which phase.
    pub phase: Phase,
    /// Iterations (over all starts).
    #[serde(rename = "iterations", alias = "iters")]
    pub iters: usize,
    /// Objective evaluations.
    #[serde(rename = "evaluations", alias = "evals")]
    pub evals: usize,
    /// CPU seconds of the phase (as counted by the design's budget).
    #[serde(rename = "design_cpu_s", alias = "cpu_s", with = "serde_f64_or_string")]
    pub cpu_s: f64,
}

/// Why the search stopped starting new local searches.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SearchStop {
    /// The CPU budget (`cpumax`) ran out (not reproducible bit for bit).
    Budget,
    /// The evaluation budget (`maxevals`) ran out.
    Maxevals,
    /// The stall rule: `stall_starts` consecutive local searches without a relative improvement
    /// of `stall_rtol`.
    Stall,
    /// The fixed number of starts was made (`max_starts`, or the first starts with
    /// `stall_starts = 0`).
    Starts,
    /// Cancelled or stopped by the observer.
    Interrupted,
    /// Nothing to search: the design has no free variable (every entry fixed by a structure, or
    /// Dk forced by the H2 feedthrough constraint at order 0); its one controller was evaluated
    /// once.
    NoFreeVariable,
    /// Not known: the record was journaled by a build before the search summary existed
    /// (06018b1); never returned by a design run. See [`SearchSummary::not_recorded`].
    NotRecorded,
}

impl SearchStop {
    /// The name used in journals and traces.
    pub fn name(self) -> &'static str {
        match self {
            SearchStop::Budget => "budget",
            SearchStop::Maxevals => "maxevals",
            SearchStop::Stall => "stall",
            SearchStop::Starts => "starts",
            SearchStop::Interrupted => "interrupted",
            SearchStop::NoFreeVariable => "no_free_variable",
            SearchStop::NotRecorded => "not_recorded",
        }
    }
}

/// What kind of start a local search began from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StartKind {
    /// A random point: a standard-normal first start, or a fresh start of the continued search
    /// (scaled by `random_scales`).
    Random,
    /// The initial controller or one of its perturbations.
    Init,
    /// The padded controller of the order below (a campaign's order chaining,
    /// [`crate::design::Design::chained`]).
    Chained,
    /// A reduced-order full-order-central-controller start (`central_gammas`).
    Central,
    /// The open-loop start K = 0 (`open_loop_start`).
    OpenLoop,
    /// A basin-hopping perturbation of the best point.
    Hop,
    /// HIFOO's gradient-sampling stabilisation fallback.
    GradientSampling,
}

impl StartKind {
    /// The name used in journals and traces.
    pub fn name(self) -> &'static str {
        match self {
            StartKind::Random => "random",
            StartKind::Init => "init",
            StartKind::Chained => "chained",
            StartKind::Central => "central",
            StartKind::OpenLoop => "open_loop",
            StartKind::Hop => "hop",
            StartKind::GradientSampling => "gradient_sampling",
        }
    }
}

/// How the multi-start search went.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SearchSummary {
    /// Local searches started (the first starts included).
    pub starts: usize,
    /// Index (0-based, in the order started) of the local search that produced the returned
    /// controller.
    pub best_start: usize,
    /// The kind of that start (absent in records of older builds).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub best_start_kind: Option<StartKind>,
    /// Whether that local search ran in plant-scaled variables (`variable_scaling`,
    /// docs/ALGORITHMS.md §8.6). Absent in records of older builds and when false.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub best_start_scaled: bool,
    /// CPU seconds from the start of the run until the returned objective value was first
    /// reached within a relative 1e-6 (the final objective of a not-stabilised run: its best
    /// abscissa).
    #[serde(with = "serde_f64_or_string")]
    pub cpu_to_best_s: f64,
    /// Evaluations made until then.
    pub evals_to_best: usize,
    /// Why no further local search was started.
    pub stop: SearchStop,
}

impl SearchSummary {
    /// The summary of a journal line written before the search summary existed: stop
    /// [`SearchStop::NotRecorded`], no counts (0), no time (NaN).
    pub fn not_recorded() -> SearchSummary {
        SearchSummary {
            starts: 0,
            best_start: 0,
            best_start_kind: None,
            best_start_scaled: false,
            cpu_to_best_s: f64::NAN,
            evals_to_best: 0,
            stop: SearchStop::NotRecorded,
        }
    }

    /// "7 (central)": the best start's index and, if recorded, its kind ("7 (hop, scaled)" if
    /// its local search ran in plant-scaled variables).
    pub fn best_start_label(&self) -> String {
        let scaled = if self.best_start_scaled { ", scaled" } else { "" };
        match self.best_start_kind {
            Some(k) => format!("{} ({}{scaled})", self.best_start, k.name()),
            None if self.best_start_scaled => format!("{} (scaled)", self.best_start),
            None => self.best_start.to_string(),
        }
    }
}

/// The optimality certificate of a design run's final point (docs/ALGORITHMS.md §7.3): the min-norm element of the gradient
/// bundle has norm `dnorm`, the bundle radius is `evaldist`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Certificate {
    /// Norm of the min-norm element of the gradient bundle.
    #[serde(with = "serde_f64_or_string")]
    pub dnorm: f64,
    /// Bundle radius.
    #[serde(with = "serde_f64_or_string")]
    pub evaldist: f64,
}

/// The result of [`crate::design::Design::run`]. Every figure is recomputed from `controller`.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct DesignOutcome {
    /// How the run ended.
    pub status: DesignStatus,
    /// The returned controller (serialised as the JSON `{AK, BK, CK, DK}` of
    /// [`crate::lti::Controller::to_json`], as in a controller file).
    pub controller: crate::lti::Controller,
    /// ‖Tzw‖∞ of the returned controller (+∞ if the loop is unstable or ill-posed).
    #[serde(with = "serde_f64_or_string")]
    pub gamma: f64,
    /// ‖K‖∞ of the returned controller (+∞ if Ak is unstable; σmax(Dk) for order 0).
    #[serde(with = "serde_f64_or_string")]
    pub k_hinf: f64,
    /// Spectral abscissa of the closed loop.
    #[serde(with = "serde_f64_or_string")]
    pub alpha_cl: f64,
    /// Spectral abscissa of Ak (None for order 0).
    #[serde(default, with = "serde_opt_f64_or_string")]
    pub alpha_k: Option<f64>,
    /// Final objective: max(γ, ε‖K‖∞) (strong) or γ (plain); a problem's f_p
    /// (docs/ALGORITHMS.md §14.1: ε·s(Ak) in place of ε‖K‖∞ where every minimised plant has the
    /// abscissa objective).
    #[serde(with = "serde_f64_or_string")]
    pub objective: f64,
    /// Whether ε‖K‖∞ is the active term of the final objective max(‖Tzw‖∞, ε‖K‖∞) (at least
    /// ‖Tzw‖∞ within [`crate::lti::NORM_TIE_RTOL`], 0.1 %): the controller-norm penalty, not
    /// the closed loop, sets the objective (strong stabilisation only; a smaller ε would let γ go
    /// lower). For a problem of several plants, ε‖K‖∞ against the largest weighted value of the
    /// plants without a bound. Never where the controller's term is ε·s(Ak) (an abscissa
    /// problem), where every plant has a bound (ε‖K‖∞ is then the objective by design: the
    /// smallest controller meeting the bounds), where a bound is violated (its penalty is in the
    /// objective), or where no variable is free.
    #[serde(default)]
    pub controller_norm_active: bool,
    /// Optimality certificate of the final point, if the optimisation phase ran.
    #[serde(default)]
    pub certificate: Option<Certificate>,
    /// Total iterations.
    pub iterations: usize,
    /// Total objective evaluations.
    pub evaluations: usize,
    /// Per-phase counters.
    pub phases: Vec<PhaseStats>,
    /// Total CPU seconds of the design run (as counted by its budget; a campaign record's
    /// `cpu_s` is the worker thread's CPU time for the whole job).
    #[serde(with = "serde_f64_or_string")]
    pub design_cpu_s: f64,
    /// The multi-start search: starts made, the best one, time to best, stop reason
    /// ([`SearchSummary::not_recorded`] when read from a journal line that predates it).
    #[serde(default = "SearchSummary::not_recorded")]
    pub search: SearchSummary,
    /// Each plant's recomputed value, of a design for several plants or another objective than
    /// one plant's H∞ norm (`design::Design::new`); empty for the single-plant H∞ design.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub plants: Vec<super::problem::PlantValue>,
}

/// A design run that could not produce a trustworthy result.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DesignError {
    /// Invalid options.
    #[error("invalid design option `{field}`: {problem}")]
    Options {
        /// Field.
        field: &'static str,
        /// What is wrong.
        problem: String,
    },
    /// The initial controller does not fit.
    #[error("initial controller: {0}")]
    Init(InitError),
    /// A numerical failure of the optimiser that left no trustworthy point.
    #[error("numerical failure: {0}")]
    Numerical(crate::optim::OptimError),
    /// The strong objective on a plant no stable controller stabilises (the parity interlacing
    /// property fails, `lti::parity_interlacing`): refused before any search.
    #[error("{0}")]
    NotStronglyStabilisable(crate::lti::PipViolation),
    /// Several plants that cannot share one controller, or a bad weight, bound or objective
    /// (`design::problem`).
    #[error("{0}")]
    Problem(super::problem::ProblemError),
}

/// Why an initial controller (warm start, `--init`) cannot start a design run. Part of the
/// message of [`DesignError::Init`], so not also its `source`.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum InitError {
    /// Its Dk does not match the plant's m2 × p2 ([`crate::lti::Controller::check_fits`]).
    #[error("{0}")]
    Shape(crate::lti::ControllerErrorKind),
    /// Its order is above the target order.
    #[error("its order {order} exceeds the target order {target} (warm starts only grow the order)")]
    OrderTooHigh {
        /// The initial controller's order.
        order: usize,
        /// The order being designed.
        target: usize,
    },
    /// An entry of Ak, Bk, Ck or Dk is NaN or infinite.
    #[error("has a non-finite entry")]
    NonFinite,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn phase_names_are_the_serialised_ones() {
        for p in [Phase::Stabilisation, Phase::Optimisation, Phase::GradientSampling] {
            assert_eq!(serde_json::to_value(p).unwrap(), p.name());
        }
    }

    /// `design --json` and the journal name the per-phase counters as the outcome does; lines
    /// of older builds (`iters`, `evals`, `cpu_s`) still read.
    #[test]
    fn phase_counters_use_the_outcomes_key_names() {
        let s = PhaseStats { phase: Phase::Optimisation, iters: 3, evals: 5, cpu_s: 0.25 };
        let v = serde_json::to_value(&s).unwrap();
        let keys: Vec<&str> = v.as_object().unwrap().keys().map(String::as_str).collect();
        assert_eq!(keys, ["design_cpu_s", "evaluations", "iterations", "phase"]);
        let old: PhaseStats =
            serde_json::from_str(r#"{"phase":"optimisation","iters":3,"evals":5,"cpu_s":0.25}"#).unwrap();
        assert_eq!(old, s);
    }
}
