//! Options of one design run (they enter the campaign's job-id hash, so they are serde).

use serde::{Deserialize, Serialize};

use super::float_serde::serde_f64_or_string;

/// Largest accepted number of random starts `nrand` (each start is a BFGS run of its own).
pub const MAX_NRAND: usize = 10_000;
/// Largest accepted iteration limit `maxit` and `gradsamp_maxit` (the CPU budget stops a run
/// long before; the bound only turns a typo into an error).
pub const MAX_ITERATIONS: usize = 100_000_000;

/// Which problem to solve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum ObjectiveKind {
    /// Strong stabilisation: minimise max(‖Tzw‖∞, ε‖K‖∞) subject to a stable closed loop and a
    /// stable controller (Gumussoy–Millstone–Overton 2008).
    #[default]
    Strong,
    /// Plain fixed-order H∞: minimise ‖Tzw‖∞ with a stable closed loop, K unrestricted.
    Plain,
}

/// Options of [`crate::design::run`]. Defaults follow HIFOO 3.5 (docs/ALGORITHMS.md §8).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DesignOptions {
    /// Controller order nk ≥ 0.
    pub order: usize,
    /// Weight ε of the controller's own term (strong stabilisation only), ε > 0.
    #[serde(with = "serde_f64_or_string")]
    pub eps: f64,
    /// Seed of the run's random number generator.
    pub seed: u64,
    /// CPU-second budget of the whole run (both phases and gradient sampling).
    #[serde(with = "serde_f64_or_string")]
    pub cpumax: f64,
    /// Number of random starting points (HIFOO `nrand`, default 3).
    pub nrand: usize,
    /// Strong stabilisation or plain H∞.
    pub objective: ObjectiveKind,
    /// Relative tolerance of the H∞ norm computation.
    #[serde(with = "serde_f64_or_string")]
    pub hinf_tol: f64,
    /// BFGS iteration limit per start and phase (HIFOO `maxit`, 1000).
    pub maxit: usize,
    /// Stop BFGS when the certificate dnorm ≤ normtol (HIFOO passes 1e-3).
    #[serde(with = "serde_f64_or_string")]
    pub normtol: f64,
    /// Gradient-bundle radius (HIFOO passes 1e-3).
    #[serde(with = "serde_f64_or_string")]
    pub evaldist: f64,
    /// Run gradient sampling after BFGS (HIFOO `fast = 0`).
    pub gradient_sampling: bool,
    /// Iteration limit of each gradient-sampling run (HIFOO caps HANSO 2.0's gradient sampling
    /// at 100 iterations per radius, 3 radii; each iteration costs 2·nvar evaluations).
    pub gradsamp_maxit: usize,
}

impl Default for DesignOptions {
    fn default() -> Self {
        DesignOptions {
            order: 1,
            eps: 1e-3,
            seed: 0,
            cpumax: 60.0,
            nrand: 3,
            objective: ObjectiveKind::Strong,
            hinf_tol: 1e-10,
            maxit: 1000,
            normtol: 1e-3,
            evaldist: 1e-3,
            gradient_sampling: true,
            gradsamp_maxit: 300,
        }
    }
}
