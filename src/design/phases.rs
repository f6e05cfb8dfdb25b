//! The two phases of a HIFOO run (docs/ALGORITHMS.md §8.3, §8.4).
//!
//! **Stabilisation.** BFGS on f_s = max(α(Acl), ε·α(Ak)) from each start separately, with
//! fvalquit = 0 (stop as soon as f_s < 0, i.e. Acl and Ak both Hurwitz). If no start was
//! stabilised and gradient sampling is enabled, gradient sampling (fvalquit = 0) from the best
//! half of the BFGS end points, best first, stopping at the first stable point. Every stable end
//! point becomes a start of the next phase.
//!
//! **Optimisation.** HANSO on f_h = max(‖Tzw‖∞, ε·‖K‖∞) from all stable points: BFGS from each,
//! then (if enabled, and HANSO 2.0's rule: only if the best BFGS point is not certified) gradient
//! sampling from the best point.
//!
//! One [`RunControl`] (CPU budget, cancel flag) is shared by both phases; a phase stops at the
//! first optimiser run that ends on the budget or an interrupt.

use rand::RngCore;

use crate::optim::{
    bfgs, gradient_sampling, hanso, BfgsOptions, GradSampOptions, HansoOptions, OptimError, OptimResult, RunControl,
    Termination,
};

use super::objective::{DesignObjective, ObserverAdapter};
use super::options::DesignOptions;
use super::outcome::{DesignError, Phase, PhaseStats};

/// BFGS options of both phases from the design options (fvalquit is set per phase).
pub(crate) fn bfgs_options(opts: &DesignOptions, fvalquit: f64) -> BfgsOptions {
    BfgsOptions { normtol: opts.normtol, evaldist: opts.evaldist, maxit: opts.maxit, fvalquit, ..Default::default() }
}

/// Gradient-sampling options of both phases.
pub(crate) fn gradsamp_options(opts: &DesignOptions, fvalquit: f64) -> GradSampOptions {
    GradSampOptions { maxit: opts.gradsamp_maxit, fvalquit, only_if_uncertified: true, ..Default::default() }
}

pub(crate) fn optim_error(e: OptimError) -> DesignError {
    match e {
        OptimError::Options { field, value, range } => {
            DesignError::Options { field, problem: format!("{value} is out of range (must be {range})") }
        }
        other => DesignError::Numerical(other.to_string()),
    }
}

fn stops_phase(t: Termination) -> bool {
    matches!(t, Termination::CpuBudget | Termination::Interrupted)
}

/// What the stabilisation phase produced.
#[derive(Debug, Clone)]
pub(crate) struct Stabilisation {
    /// Stable end points (f_s < 0), in the order found.
    pub stable: Vec<Vec<f64>>,
    /// The point with the smallest f_s (a stable one if any).
    pub best_x: Vec<f64>,
    /// Its f_s.
    pub best_f: f64,
    /// Counters (BFGS and any gradient sampling of this phase).
    pub stats: PhaseStats,
    /// Set if the budget or an interrupt ended the phase.
    pub stopped: Option<Termination>,
}

/// Runs the stabilisation phase from `starts` (docs/ALGORITHMS.md §8.3).
pub(crate) fn stabilise(
    obj: &mut DesignObjective<'_>,
    starts: &[Vec<f64>],
    opts: &DesignOptions,
    rng: &mut dyn RngCore,
    ctl: &RunControl,
    obs: &mut ObserverAdapter<'_, '_>,
    evals_base: usize,
) -> Result<Stabilisation, DesignError> {
    let cpu0 = ctl.cpu_elapsed();
    let bopts = bfgs_options(opts, 0.0);
    let mut stats = PhaseStats { phase: Phase::Stabilisation, iters: 0, evals: 0, cpu_s: 0.0 };
    let mut ends: Vec<(Vec<f64>, f64)> = Vec::with_capacity(starts.len());
    let mut stopped = None;
    for (i, x0) in starts.iter().enumerate() {
        obs.set_evals_base(evals_base + stats.evals);
        match bfgs(obj, x0, i, &bopts, ctl, obs) {
            Ok(r) => {
                stats.iters += r.iters;
                stats.evals += r.evals;
                ends.push((r.x, r.f));
                if stops_phase(r.termination) {
                    stopped = Some(r.termination);
                    break;
                }
            }
            // An ill-posed loop (or failed eigensolver) at the start: skip it, as HANSO does.
            Err(OptimError::NonFiniteStart { f }) => {
                stats.evals += 1;
                ends.push((x0.clone(), if f.is_nan() { f64::INFINITY } else { f }));
            }
            Err(e) => return Err(optim_error(e)),
        }
    }
    let is_stable = |f: f64| f < 0.0;
    if stopped.is_none() && opts.gradient_sampling && !ends.iter().any(|(_, f)| is_stable(*f)) {
        // Gradient sampling from the best half of the end points, best first (HIFOO).
        let mut order: Vec<usize> = (0..ends.len()).filter(|&i| ends[i].1.is_finite()).collect();
        order.sort_by(|&a, &b| ends[a].1.total_cmp(&ends[b].1));
        order.truncate(ends.len().div_ceil(2));
        let gopts = gradsamp_options(opts, 0.0);
        for i in order {
            obs.set_evals_base(evals_base + stats.evals);
            let x0 = ends[i].0.clone();
            match gradient_sampling(obj, &x0, &gopts, rng, ctl, obs) {
                Ok(r) => {
                    stats.iters += r.iters;
                    stats.evals += r.evals;
                    let (t, f) = (r.termination, r.f);
                    ends.push((r.x, f));
                    if stops_phase(t) {
                        stopped = Some(t);
                        break;
                    }
                    if is_stable(f) {
                        break;
                    }
                }
                Err(OptimError::NonFiniteStart { .. }) => stats.evals += 1,
                Err(e) => return Err(optim_error(e)),
            }
        }
    }
    stats.cpu_s = ctl.cpu_elapsed() - cpu0;
    let stable: Vec<Vec<f64>> = ends.iter().filter(|(_, f)| is_stable(*f)).map(|(x, _)| x.clone()).collect();
    let (best_x, best_f) = ends
        .iter()
        .min_by(|a, b| nan_last(a.1).total_cmp(&nan_last(b.1)))
        .cloned()
        .unwrap_or_else(|| (starts[0].clone(), f64::INFINITY));
    Ok(Stabilisation { stable, best_x, best_f, stats, stopped })
}

fn nan_last(f: f64) -> f64 {
    if f.is_nan() {
        f64::INFINITY
    } else {
        f
    }
}

/// What the optimisation phase produced.
#[derive(Debug, Clone)]
pub(crate) struct Optimisation {
    /// The best point with its certificate; `None` if f_h was +∞ at every start.
    pub best: Option<OptimResult>,
    /// Whether the returned point differs from (is better than) every start.
    pub progress: bool,
    /// BFGS counters.
    pub bfgs_stats: PhaseStats,
    /// Gradient-sampling counters, if it ran.
    pub gs_stats: Option<PhaseStats>,
    /// Set if the budget or an interrupt ended the phase.
    pub stopped: Option<Termination>,
}

/// Runs the optimisation phase (HANSO) from the stable points (docs/ALGORITHMS.md §8.4).
pub(crate) fn optimise(
    obj: &mut DesignObjective<'_>,
    starts: &[Vec<f64>],
    opts: &DesignOptions,
    rng: &mut dyn RngCore,
    ctl: &RunControl,
    obs: &mut ObserverAdapter<'_, '_>,
    evals_base: usize,
) -> Result<Optimisation, DesignError> {
    let cpu0 = ctl.cpu_elapsed();
    let hopts = HansoOptions {
        bfgs: bfgs_options(opts, f64::NEG_INFINITY),
        gradsamp: gradsamp_options(opts, f64::NEG_INFINITY),
        gradient_sampling: opts.gradient_sampling,
    };
    obs.set_evals_base(evals_base);
    let mut bfgs_stats = PhaseStats { phase: Phase::Optimisation, iters: 0, evals: 0, cpu_s: 0.0 };
    let h = match hanso(obj, starts, &hopts, rng, ctl, obs) {
        Ok(h) => h,
        Err(OptimError::NonFiniteStart { .. }) => {
            // f_h = +∞ at every stable point (e.g. α just below 0 but the norm's stability test,
            // which has a margin, says unstable): nothing to optimise.
            bfgs_stats.evals = starts.len();
            bfgs_stats.cpu_s = ctl.cpu_elapsed() - cpu0;
            return Ok(Optimisation { best: None, progress: false, bfgs_stats, gs_stats: None, stopped: None });
        }
        Err(e) => return Err(optim_error(e)),
    };
    let mut stopped = None;
    let mut bfgs_end_cpu = cpu0;
    for r in &h.starts {
        match r {
            Ok(res) => {
                bfgs_stats.iters += res.iters;
                bfgs_stats.evals += res.evals;
                bfgs_end_cpu = bfgs_end_cpu.max(res.cpu_s);
                if stops_phase(res.termination) {
                    stopped = Some(res.termination);
                }
            }
            Err(OptimError::NonFiniteStart { .. }) => bfgs_stats.evals += 1,
            Err(_) => {}
        }
    }
    bfgs_stats.cpu_s = bfgs_end_cpu - cpu0;
    let gs_stats = h.gradient_sampling.as_ref().map(|gs| {
        if stops_phase(gs.termination) {
            stopped = Some(gs.termination);
        }
        PhaseStats { phase: Phase::GradientSampling, iters: gs.iters, evals: gs.evals, cpu_s: gs.cpu_s - bfgs_end_cpu }
    });
    let progress = starts.iter().all(|x0| *x0 != h.best.x);
    Ok(Optimisation { best: Some(h.best), progress, bfgs_stats, gs_stats, stopped })
}
