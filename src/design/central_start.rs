//! Reduced-order central-controller starts (docs/ALGORITHMS.md §8.1).
//!
//! For each factor f of `DesignOptions::central_gammas`: the full-order H∞ central controller at
//! γ = f·γ_opt ([`crate::lti::CentralProblem`]), reduced to the target order n_K by balanced
//! truncation ([`crate::lti::balanced_truncation`]: an unstable central controller keeps its
//! antistable part and only its stable part is truncated; if it has more than n_K unstable
//! states, that level gives no start). For n_K = 0 the start is the controller's static gain
//! K(0) = −Ck Ak⁻¹ Bk (the order-0 singular-perturbation approximation: truncation would give
//! Dk = 0). A reduced controller of lower order than n_K (fewer non-zero Hankel singular values)
//! is padded with decoupled stable modes ([`super::starts::pad_controller`]).
//!
//! Each factor is tried with every regularisation of [`CENTRAL_REGULARISATIONS`] (singular
//! D12/D21 only). Plants with more than [`CENTRAL_MAX_STATES`] states get no central starts.
//!
//! Levels whose γ-test fails numerically, or whose reduction fails, are skipped: these starts
//! are an addition to the random ones, never a reason for a run to fail. The computation is
//! deterministic (no random numbers), so it does not change the reproducibility of a run.

use crate::lti::{
    balanced_truncation, coprime_factor_truncation, dc_gain, spectral_abscissa, CentralProblem, Controller, Plant,
    PlantImage, StateSpace,
};

use super::starts::{pad_controller, padding_diagonal};

/// Regularisations ε (absolute, plant units) of singular D12/D21 tried, each giving its own
/// central controllers: a small one (close to the singular problem) and a moderate one (lower
/// gains; on HE1 and BDT2 it gives the better reduced starts, measured in tests/central_start.rs).
pub const CENTRAL_REGULARISATIONS: [f64; 2] = [1e-2, 1.0];

/// Plants with more states get no central starts: the γ-iteration and the Riccati and Lyapunov
/// solves are O(n³) with 2n×2n sign iterations (CM4, n = 240, took 45 s, HF1, n = 130, 9 s).
pub const CENTRAL_MAX_STATES: usize = 100;

/// The central-controller starts of order `nk` for the factors `factors` (module docs), in the
/// order of `factors`, with the factor each came from.
///
/// A discrete-time plant's starts are those of its bilinear image (`lti::PlantImage`: the
/// central controller and balanced truncation of the image are those of the plant) taken back
/// to discrete time.
pub fn central_starts(plant: &Plant, nk: usize, factors: &[f64]) -> Vec<(f64, Controller)> {
    if factors.is_empty() {
        return Vec::new();
    }
    if plant.dims.n > CENTRAL_MAX_STATES {
        return Vec::new();
    }
    if plant.domain.is_discrete() {
        let Ok(image) = PlantImage::new(plant) else { return Vec::new() };
        return central_starts(&image.plant, nk, factors)
            .into_iter()
            .filter_map(|(f, k)| Some((f, image.controller_back(&k)?)))
            .collect();
    }
    let mut out = Vec::new();
    for eps in CENTRAL_REGULARISATIONS {
        let Ok(problem) = CentralProblem::with_regularisation(plant, eps) else {
            continue;
        };
        for &f in factors {
            if let Ok(k) = problem.controller(f * problem.gamma_opt) {
                out.extend(reduce(plant, &k, nk).into_iter().map(|r| (f, r)));
            }
        }
        if problem.regularisation.is_none() {
            break; // a regular plant: the regularisation does not matter
        }
    }
    out
}

/// `k` reduced to order `nk` (module docs): by balanced truncation (unstable part kept) when
/// possible, and by coprime-factor truncation when `k` is unstable (then both, in this order).
pub fn reduce(plant: &Plant, k: &Controller, nk: usize) -> Vec<Controller> {
    let sys = StateSpace { a: k.ak.clone(), b: k.bk.clone(), c: k.ck.clone(), d: k.dk.clone() };
    if nk == 0 {
        let Some(dk) = dc_gain(&sys) else { return Vec::new() };
        let (m, p) = (dk.nrows(), dk.ncols());
        return vec![Controller { dk, ..Controller::zeros(0, m, p) }];
    }
    let mut reduced = Vec::new();
    if let Ok(r) = balanced_truncation(&sys, nk) {
        reduced.push(r.sys);
    }
    if nk < k.order() && !(spectral_abscissa(k.ak.as_ref()) < 0.0) {
        if let Ok(r) = coprime_factor_truncation(&sys, nk) {
            reduced.push(r.sys);
        }
    }
    reduced
        .into_iter()
        .filter_map(|red| {
            let kr = Controller::continuous(red.a, red.b, red.c, red.d).in_domain(k.domain);
            if !kr.is_finite() {
                None
            } else if kr.order() < nk {
                let d = padding_diagonal(plant, &kr);
                pad_controller(&kr, nk, d)
            } else {
                Some(kr)
            }
        })
        .collect()
}
