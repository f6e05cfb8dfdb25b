//! The HIFOO method: fixed-order H∞ design with strong stabilisation (docs/ALGORITHMS.md §3, §8;
//! Gumussoy, Millstone & Overton, CDC 2008).
//!
//! * `params`: x = [vec Ak; vec Bk; vec Ck; vec Dk] ↔ controller;
//! * `starts`: seeded random starts, perturbations of an initial controller, warm-start padding;
//! * `central_start`: reduced-order full-order-central-controller starts;
//! * `objective`: max(α(Acl), ε·α(Ak)) and max(‖Tzw‖∞, ε‖K‖∞) as optimiser objectives, and the
//!   observer adapter (the optimiser's iteration record extended with the design's);
//! * `observe`: the iteration record, the observer trait, the best value so far and the observer
//!   modes (every iteration, every k-th, on improvement, throttled, sparse);
//! * `phases`: the optimiser options of the two phases;
//! * `structure`: structured controllers (entries of Ak, Bk, Ck, Dk fixed at values);
//! * `scaling`: plant-scaled controller variables x = d ∘ x̃ for the search;
//! * `search`: the multi-start search (local searches until a budget or the stall rule, basin
//!   hopping, gradient sampling on the best point);
//! * `builder`: [`Design`], the one entry point (a builder: problem, options, initial and chained
//!   controllers, structure, observer, cancel flag), which makes the run's budget;
//! * `evaluate`: [`evaluate`], one controller on a problem's plants as verification sees it
//!   (stability with the margin, norms, each plant's value, the verdict);
//! * `run`: one design as [`Design::run`] starts it (checks, starting points, the search, the
//!   outcome's figures recomputed from the returned controller).
//!
//! The modules are crate-private; what is API is re-exported here.
mod builder;
pub(crate) mod central_start;
mod components;
mod evaluate;
mod float_serde;
mod multi_objective;
pub(crate) mod objective;
mod observe;
mod options;
mod outcome;
pub(crate) mod params;
mod phases;
mod problem;
mod run;
pub(crate) mod scaling;
mod search;
pub(crate) mod starts;
mod structure;

pub use builder::Design;
pub use central_start::{central_starts, reduce as reduce_controller, CENTRAL_MAX_STATES, CENTRAL_REGULARISATIONS};
pub use evaluate::{
    evaluate, evaluate_job, evaluate_plant, loop_details, stabilises, ControllerEvaluation, Evaluation, LoopDetails,
    LoopEvaluation, PlantEvaluation, Rejection,
};
pub use float_serde::{f64_from_json, f64_text, f64_to_json, serde_f64_or_string, serde_opt_f64_or_string};
pub use objective::{
    ComponentCache, Components, DesignObjective, ObjectivePhase, ObserverAdapter, COMPONENT_CACHE_LEN,
    MIN_ORDER_FOR_INTERRUPT, MIN_ORDER_FOR_REJECTION,
};
pub use observe::{
    BestSoFar, DesignIterRecord, DesignObserver, Improvement, Keep, ModeFilter, NoDesignObserver, Observed,
    ObserverMode, SparseFilter, IMPROVE_RTOL, SAMPLE_CPU_S, SAMPLE_RATIO,
};
pub(crate) use options::design_option_table;
pub use options::{
    options_markdown, DesignOptions, ObjectiveKind, OptionRow, OptionValue, UnknownVariableScaling, VariableScaling,
    DEFAULT_BFGS_RESTART, DEFAULT_CENTRAL_GAMMAS, DEFAULT_CONTINUED_MAXIT, DEFAULT_HOP_SCALES, DEFAULT_RANDOM_SCALES,
    DEFAULT_REFINE_RTOL, DEFAULT_STALL_STARTS, MAX_ITERATIONS, MAX_NRAND,
};
pub use outcome::{
    Certificate, DesignError, DesignOutcome, DesignStatus, InitError, Phase, PhaseStats, SearchStop, SearchSummary,
    StartKind,
};
pub use params::{controller_to_x, x_to_controller, ControllerShape};
pub use problem::{
    plant_part, plant_value, plant_values, problem_gamma, H2Feedthrough, PlantObjective, PlantTerm, PlantValue,
    Problem, ProblemError, UnknownObjective, BOUND_RTOL, MAX_BOUND, MAX_WEIGHT, MIN_WEIGHT, PENALTY_WEIGHT,
};
pub use run::{strongly_stabilisable, validate, MAX_VARIABLES};
pub use scaling::{channel_scales, variable_scaling, MAX_UNSCALED_SPREAD};
pub use search::{ALTERNATE_PERIOD, GS_RESERVE, GS_RESERVE_FACTOR, TIME_TO_BEST_RTOL};
pub use structure::{Structure, StructureError};
