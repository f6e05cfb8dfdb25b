//! The H∞ norm of a state-space system and the full-order γ_opt of a plant.
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use pyo3::prelude::*;

use hinfix::lti::{hinf_norm_in, HinfParams, Interrupt, StateSpace, TimeDomain, DEFAULT_HINF_TOL};

use crate::arrays::{to_mat, In};
use crate::errors::{bad_input, failure};
use crate::interrupt::run_interruptible;
use crate::plant::plant_from;

/// `hinfnorm(A, B, C, D, tol, dt)` → (‖G‖∞, peak frequency in rad/s): the crate's norm to
/// relative tolerance `tol`, of a continuous-time system (`dt` 0) or of a discrete-time one with
/// sampling time `dt` seconds (on the unit circle; the peak θ/dt rad/s, at most the Nyquist
/// frequency π/dt). An unstable system gives (inf, nan); the peak frequency may be inf (peak as
/// ω → ∞, continuous time).
#[pyfunction]
#[pyo3(signature = (a, b, c, d, tol = DEFAULT_HINF_TOL, dt = 0.0))]
#[allow(clippy::too_many_arguments)]
pub fn hinfnorm(py: Python<'_>, a: In<'_>, b: In<'_>, c: In<'_>, d: In<'_>, tol: f64, dt: f64) -> PyResult<(f64, f64)> {
    if !(tol.is_finite() && tol > 0.0 && tol < 1.0) {
        return Err(bad_input("hinfnorm", format!("tol must be in (0, 1), got {tol}")));
    }
    let domain = TimeDomain::from_ts(dt).map_err(|e| bad_input("hinfnorm", format!("dt {e}")))?;
    let sys = StateSpace::new(to_mat(&a), to_mat(&b), to_mat(&c), to_mat(&d)).map_err(|e| bad_input("hinfnorm", e))?;
    if !sys.is_finite() {
        return Err(bad_input("hinfnorm", "the system has a NaN or infinite entry"));
    }
    let cancel = Arc::new(AtomicBool::new(false));
    let norm = run_interruptible(py, cancel, move |flag| {
        let stop = || flag.load(Ordering::Relaxed);
        let params = HinfParams::new(tol).with_stop(Interrupt::new(&stop));
        hinf_norm_in(domain, &sys, &params)
    })?
    .map_err(|e| failure("hinfnorm", e))?;
    Ok((norm.value, domain.to_rad_per_s(norm.peak_freq)))
}

/// `full_order_gamma(plant, name, dt)` → the crate's `FullOrderGamma` as JSON: γ_opt of full-order H∞
/// synthesis (the lower bound of every fixed-order design), with its bracket and diagnostics.
#[pyfunction]
#[pyo3(signature = (plant, name = "plant", dt = 0.0))]
pub fn full_order_gamma(py: Python<'_>, plant: Vec<In<'_>>, name: &str, dt: f64) -> PyResult<String> {
    let plant = plant_from(name, plant, dt)?;
    let cancel = Arc::new(AtomicBool::new(false));
    let g = run_interruptible(py, cancel, move |_| hinfix::lti::full_order_gamma(&plant))?
        .map_err(|e| failure("full_order_gamma", e))?;
    serde_json::to_string(&g).map_err(|e| failure("full_order_gamma", e))
}
