//! Errors of the optimiser: only for situations in which no trustworthy point exists
//! (bad options, wrong dimensions, a start where f is not finite). Everything else — converged,
//! budget exhausted, line search failed — is an outcome ([`Termination`](super::Termination)).

use super::termination::Termination;

/// Why an optimiser call could not produce a result.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum OptimError {
    /// An option is out of its documented range.
    #[error("invalid option {field} = {value}: must be {range}")]
    Options {
        /// Name of the option field.
        field: &'static str,
        /// The offending value (as f64; counts are converted).
        value: f64,
        /// The admissible range, in words.
        range: &'static str,
    },
    /// f (or ∇f) at the starting point is not finite: BFGS cannot start there
    /// (HANSO `bfgs1run` info 5). The caller must supply a point inside the domain.
    #[error("starting point rejected: f(x0) = {f} is not finite (or ∇f(x0) has a non-finite entry)")]
    NonFiniteStart {
        /// The value returned by the objective at x0 (may be finite if only ∇f was bad).
        f: f64,
    },
    /// A vector has the wrong length for the objective.
    #[error("dimension mismatch in {what}: expected {expected}, got {got}")]
    DimensionMismatch {
        /// Which vector.
        what: &'static str,
        /// `Objective::nvar()`.
        expected: usize,
        /// Its actual length.
        got: usize,
    },
    /// `hanso` was given no starting point at all.
    #[error("no starting points given")]
    NoStarts,
    /// A start of a multi-start run that was not run because an earlier start ended the whole
    /// run (CPU budget, cancellation, observer break, `fvalquit` or `xnormquit`).
    #[error("start not run: the run had already ended ({})", reason.text())]
    NotRun {
        /// The termination of the start that ended the run.
        reason: Termination,
    },
}
