//! HANSO-style driver (Hybrid Algorithm for Non-Smooth Optimization; Lewis & Overton 2013;
//! docs/ALGORITHMS.md §7.5): BFGS from every starting point with one shared
//! budget, then optionally gradient sampling from the best BFGS point.
//!
//! * The budget ([`RunControl`]: CPU seconds, cancel flag) is shared by all starts. A start that
//!   ends with `CpuBudget`, `Interrupted`, `TargetReached` (f < fvalquit) or `XNormExceeded`
//!   ends the whole run (as HANSO); the remaining starts are reported as
//!   `Err(OptimError::NotRun { reason })`, so `starts[i]` always belongs to the i-th start.
//! * A start where f or ∇f is not finite is rejected with `Err(NonFiniteStart { f })` and skipped.
//! * The best point is the one with the smallest f (first one on ties).
//! * Gradient sampling ([`gradient_sampling`]) runs from the best BFGS point when
//!   `opts.gradient_sampling` is set, the run was not ended early, and (with
//!   `gradsamp.only_if_uncertified`, HANSO 2.0's rule) the BFGS point is not certified. Its
//!   result replaces the BFGS one only if f decreased; at the same x the smaller certificate is
//!   kept (HANSO).

use super::bfgs::bfgs;
use super::control::RunControl;
use super::error::OptimError;
use super::gradsamp::gradient_sampling;
use super::objective::Objective;
use super::observer::{IterRecord, Iteration, Observer};
use super::options::HansoOptions;
use super::solver::{check_dims, OptimResult};
use super::termination::Termination;
use rand::RngCore;

/// Passes each record on with the evaluations of the call's earlier runs added, so that
/// [`Iteration::evals`] counts the whole `hanso` call.
struct EvalsBefore<'o> {
    inner: &'o mut dyn Observer,
    evals: usize,
}

impl Observer for EvalsBefore<'_> {
    fn on_iter(&mut self, rec: &IterRecord<'_>) -> std::ops::ControlFlow<()> {
        self.inner.on_iter(&IterRecord { it: Iteration { evals: self.evals + rec.evals, ..rec.it }, ..*rec })
    }
}

/// Result of [`hanso`].
#[derive(Debug, Clone, PartialEq)]
pub struct HansoResult {
    /// The best point over all starts and gradient sampling, with its certificate.
    pub best: OptimResult,
    /// One entry per starting point, in order.
    pub starts: Vec<Result<OptimResult, OptimError>>,
    /// The gradient-sampling run, if one was made.
    pub gradient_sampling: Option<OptimResult>,
    /// Index of the start whose BFGS run gave the best BFGS point.
    pub best_start: usize,
    /// Objective evaluations made by the whole call.
    pub evals: usize,
}

/// HANSO-style driver: BFGS from every start (shared budget; a start whose f is not finite is
/// rejected with NonFiniteStart and skipped), then (if opts.gradient_sampling) GS from the best.
/// `Err` only for invalid options or dimensions, no starts, or when no start had a finite f
/// (then the error of the first start is returned).
pub fn hanso(
    obj: &mut dyn Objective,
    starts: &[Vec<f64>],
    opts: &HansoOptions,
    rng: &mut dyn RngCore,
    ctl: &RunControl,
    obs: &mut dyn Observer,
) -> Result<HansoResult, OptimError> {
    opts.validate()?;
    if starts.is_empty() {
        return Err(OptimError::NoStarts);
    }
    for x0 in starts {
        check_dims(obj, x0)?;
    }
    let mut evals = 0usize;
    let mut ended: Option<Termination> = None;
    let mut results: Vec<Result<OptimResult, OptimError>> = Vec::with_capacity(starts.len());
    for (i, x0) in starts.iter().enumerate() {
        if let Some(reason) = ended {
            results.push(Err(OptimError::NotRun { reason }));
            continue;
        }
        let r = bfgs(obj, x0, i, &opts.bfgs, ctl, &mut EvalsBefore { inner: &mut *obs, evals });
        match &r {
            Ok(res) => {
                evals += res.evals;
                if res.termination.ends_run() {
                    ended = Some(res.termination);
                }
            }
            // The rejected start cost its one evaluation.
            Err(OptimError::NonFiniteStart { .. }) => evals += 1,
            Err(_) => {}
        }
        results.push(r);
    }
    let mut best_start = None;
    for (i, r) in results.iter().enumerate() {
        if let Ok(res) = r {
            if best_start.is_none_or(|b: usize| res.f < results[b].as_ref().map_or(f64::INFINITY, |x| x.f)) {
                best_start = Some(i);
            }
        }
    }
    let Some(best_start) = best_start else {
        return Err(results.into_iter().next().and_then(|r| r.err()).unwrap_or(OptimError::NoStarts));
    };
    let mut best = results[best_start].as_ref().map_err(Clone::clone)?.clone();

    let mut gs_result = None;
    let certified = best.dnorm <= opts.bfgs.normtol;
    if opts.gradient_sampling && ended.is_none() && !(opts.gradsamp.only_if_uncertified && certified) {
        let gs =
            gradient_sampling(obj, &best.x, &opts.gradsamp, rng, ctl, &mut EvalsBefore { inner: &mut *obs, evals })?;
        evals += gs.evals;
        if gs.f < best.f {
            best = gs.clone();
        } else if gs.x == best.x && gs.dnorm < best.dnorm {
            best.dnorm = gs.dnorm;
            best.evaldist = gs.evaldist;
        }
        gs_result = Some(gs);
    }
    Ok(HansoResult { best, starts: results, gradient_sampling: gs_result, best_start, evals })
}
