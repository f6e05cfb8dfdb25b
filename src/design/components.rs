//! What one design-objective evaluation computed besides its value (docs/ALGORITHMS.md §3),
//! shared by the single-plant objective (`design::objective`) and a problem's
//! (`design::multi_objective`).

/// The values behind one objective evaluation; NaN = not computed at this point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Components {
    /// The objective value.
    pub f: f64,
    /// ‖Tzw‖∞.
    pub gamma: f64,
    /// ‖K‖∞.
    pub k_hinf: f64,
    /// α(Acl) (in discrete time ρ(Acl) − 1, `lti::stability_measure`).
    pub alpha_cl: f64,
    /// α(Ak) (ρ(Ak) − 1 in discrete time; NaN for order 0).
    pub alpha_k: f64,
}

impl Components {
    pub(crate) const UNKNOWN: Components =
        Components { f: f64::NAN, gamma: f64::NAN, k_hinf: f64::NAN, alpha_cl: f64::NAN, alpha_k: f64::NAN };
}
