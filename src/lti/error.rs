//! Errors of the LTI numerics.
//!
//! Most numerical outcomes are values, not errors: an unstable loop has H∞ norm +∞ and a failed
//! eigenvalue computation gives spectral abscissa +∞ (docs/ALGORITHMS.md §3.1). What remains are inputs
//! that do not fit together and an ill-posed feedback loop.

/// Why an LTI computation could not produce a value.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum LtiError {
    /// The feedback loop is ill-posed: I − Dk·D22 is (numerically) singular. `cond` is its
    /// 2-norm condition number (+∞ if exactly singular or not finite). The design objective
    /// treats this like instability (f = +∞).
    #[error("ill-posed feedback loop: I − Dk·D22 is numerically singular (condition number {cond:.3e})")]
    IllPosed {
        /// Condition number of I − Dk·D22.
        cond: f64,
    },
    /// An iterative eigenvalue or singular-value computation did not converge.
    #[error("no convergence in {0}")]
    NoConvergence(&'static str),
    /// The computation was abandoned because its [`Interrupt`](super::Interrupt) fired (CPU
    /// budget spent or run cancelled): there is no value.
    #[error("{0}")]
    Interrupted(#[from] super::Interrupted),
    /// A plant and a controller in different time domains (continuous and discrete, or two
    /// sampling times): they have no closed loop.
    #[error("the plant is in {plant}, the controller in {controller}")]
    DomainMismatch {
        /// The plant's domain.
        plant: super::TimeDomain,
        /// The controller's domain.
        controller: super::TimeDomain,
    },
    /// Matrices whose shapes do not fit together.
    #[error("{what} is {}×{}, expected {}×{}", got.0, got.1, expected.0, expected.1)]
    Shape {
        /// Which matrix.
        what: &'static str,
        /// The shape it must have.
        expected: (usize, usize),
        /// The shape it has.
        got: (usize, usize),
    },
}
