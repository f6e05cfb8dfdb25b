//! The HIFOO method: fixed-order H∞ design with strong stabilisation (algorithm.md §3, §3.1, §7).
//!
//! (The optimisation itself lands with the design issue; this file fixes the public types that the
//! campaign runner codes against.)
mod float_serde;
mod options;
mod outcome;
// TEMP: stand-in for design::run until the design branch lands (drop at merge).
mod run_stub;
pub use run_stub::run;

pub use float_serde::serde_f64_or_string;
pub use options::{DesignOptions, ObjectiveKind};
pub use outcome::{DesignError, DesignIterRecord, DesignObserver, DesignOutcome, DesignStatus, NoDesignObserver, Phase, PhaseStats};
