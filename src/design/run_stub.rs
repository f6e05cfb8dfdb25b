//! TEMPORARY stand-in for `design::run` so the campaign CLI compiles before the design branch
//! lands. Drop this file (and its two lines in `design/mod.rs`) at merge. It never produces
//! numbers: every call is an honest "not implemented" error.
use super::{DesignError, DesignObserver, DesignOptions, DesignOutcome};
use crate::lti::{Controller, Plant};

/// Stand-in with the real signature; always `Err(DesignError::Numerical("not implemented"))`.
pub fn run(
    _plant: &Plant,
    _opts: &DesignOptions,
    _init: Option<&Controller>,
    _obs: &mut dyn DesignObserver,
) -> Result<DesignOutcome, DesignError> {
    Err(DesignError::Numerical(
        "design::run is not implemented on this branch (temporary stand-in)".to_string(),
    ))
}
