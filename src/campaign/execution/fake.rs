//! A deterministic stand-in for `design::Design::run`, for testing the campaign machinery (scheduling,
//! journal, resume after kill -9) quickly. Only the test-only binary examples/fake_campaign.rs
//! uses it (through [`crate::cli::main_with`]); the `campaign` binary has no way to select it, so
//! a production binary cannot be switched to fake results. Jobs made for it carry
//! [`RunnerTag::Fake`] in their id and `"runner": "fake"` in their record, so its results can
//! never pass for real ones.
//!
//! A fake job takes [`FAKE_ITERS`] "iterations", sleeping `pause` between them and reporting each
//! to the observer (so cancellation works exactly as with the real runner), and returns figures
//! that are a pure function of the job id and the initial controllers: the same job gives the same
//! record, and a warm-started (or chained) job depends on its predecessor's controller.

use std::ops::ControlFlow;
use std::time::Duration;

use sha2::{Digest, Sha256};

use super::scheduler::{JobRunner, JobStarts};
use crate::campaign::model::jobs::{Job, RunnerTag};
use crate::design::{
    BestSoFar, Certificate, Components, DesignError, DesignIterRecord, DesignObserver, DesignOutcome, DesignStatus,
    Improvement, Phase, PhaseStats, SearchStop, SearchSummary,
};
use crate::lti::Controller;
use crate::optim::{Iteration, SolverKind};

/// The environment variable the fake binary reads its pause between fake iterations from, in
/// milliseconds (unset, empty or unparsable: [`DEFAULT_PAUSE_MS`]).
pub const FAKE_RUNNER_ENV: &str = "HINFIX_FAKE_RUNNER";
/// Default pause between fake iterations (ms).
pub const DEFAULT_PAUSE_MS: u64 = 20;
/// Iterations of one fake job.
pub const FAKE_ITERS: usize = 10;

/// The fake runner.
#[derive(Debug, Clone)]
pub struct FakeRunner {
    /// Pause between iterations.
    pub pause: Duration,
}

impl FakeRunner {
    /// The runner with the pause [`FAKE_RUNNER_ENV`] asks for.
    pub fn from_env() -> FakeRunner {
        let ms = std::env::var(FAKE_RUNNER_ENV).ok().and_then(|v| v.trim().parse().ok());
        FakeRunner { pause: Duration::from_millis(ms.unwrap_or(DEFAULT_PAUSE_MS)) }
    }

    /// The runner tag for job expansion.
    pub fn tag(&self) -> RunnerTag {
        RunnerTag::Fake
    }
}

/// A number in [0, 1) from the hash of `parts`.
fn unit(parts: &[&[u8]]) -> f64 {
    let mut h = Sha256::new();
    for p in parts {
        h.update((p.len() as u64).to_le_bytes());
        h.update(p);
    }
    let d = h.finalize();
    let mut b = [0u8; 8];
    b.copy_from_slice(&d[..8]);
    (u64::from_le_bytes(b) >> 11) as f64 / (1u64 << 53) as f64
}

impl JobRunner for FakeRunner {
    fn run(
        &self,
        job: &Job,
        starts: JobStarts<'_>,
        obs: &mut dyn DesignObserver,
    ) -> Result<DesignOutcome, DesignError> {
        let init = starts.warm.or(starts.chained);
        let mut init_text = starts.warm.map(|k| k.to_json().to_string()).unwrap_or_default();
        if let Some(k) = starts.chained {
            init_text += &format!("chained {}", k.to_json());
        }
        let seed = unit(&[job.id.0.as_bytes(), init_text.as_bytes()]);
        // warm starts improve on the predecessor, as a real chain tends to
        let base = init.map_or(10.0, |_| 5.0);
        let gamma = base * (1.0 + seed) / (1.0 + job.options.order as f64);
        let d = &job.plant.dims;
        let mut k = Controller::zeros(job.options.order, d.m2, d.p2);
        if d.m2 > 0 && d.p2 > 0 {
            k.dk[(0, 0)] = -seed;
        }
        for i in 0..job.options.order {
            k.ak[(i, i)] = -1.0 - seed - i as f64;
        }
        let mut status = DesignStatus::Converged;
        let mut iters = 0;
        let mut best = BestSoFar::new();
        for iter in 0..FAKE_ITERS {
            std::thread::sleep(self.pause);
            iters += 1;
            let f = gamma * (1.0 + (FAKE_ITERS - 1 - iter) as f64 / FAKE_ITERS as f64);
            let (evals, cpu_s) = (iter + 1, 0.0);
            let it = Iteration {
                solver: SolverKind::Bfgs,
                start: 0,
                iter: iter + 1,
                f,
                dnorm: 1.0 / (1.0 + iter as f64),
                step: 1.0,
                evals,
                cpu_s,
            };
            let improved = best.offer(Phase::Optimisation, Improvement { f, cpu_s, evals });
            let c = Components { f, gamma: f, k_hinf: 1.0, alpha_cl: -1.0, alpha_k: -1.0 };
            let rec = DesignIterRecord::new(Phase::Optimisation, it, &c, improved);
            if obs.on_iter(&rec) == ControlFlow::Break(()) {
                status = DesignStatus::Interrupted;
                break;
            }
        }
        Ok(DesignOutcome {
            status,
            controller: k,
            gamma,
            k_hinf: 1.0 + seed,
            alpha_cl: -1.0,
            alpha_k: (job.options.order > 0).then_some(-1.0),
            objective: gamma,
            controller_norm_active: false,
            certificate: Some(Certificate { dnorm: 1e-4, evaldist: job.options.evaldist }),
            iterations: iters,
            evaluations: iters,
            phases: vec![PhaseStats { phase: Phase::Optimisation, iters, evals: iters, cpu_s: 0.0 }],
            design_cpu_s: 0.0,
            search: SearchSummary {
                starts: 1,
                best_start: 0,
                best_start_kind: None,
                best_start_scaled: false,
                cpu_to_best_s: 0.0,
                evals_to_best: iters,
                stop: SearchStop::Starts,
            },
            plants: Vec::new(),
        })
    }
}
