//! One finished job as the journal stores it (one JSON line of `runs.jsonl`), and the final
//! message of its trace.

use serde::{Deserialize, Serialize};

use super::jobs::{Job, JobId, RunnerTag};
use super::provenance::Provenance;
use crate::design::{
    serde_f64_or_string, serde_opt_f64_or_string, DesignOptions, DesignOutcome, DesignStatus, PhaseStats, SearchSummary,
};

/// Version of the journal line format. Readers refuse newer versions.
pub const SCHEMA_VERSION: u32 = 1;

/// How a journaled job ended: the design run's own [`DesignStatus`] (one definition of the
/// statuses, their meaning and their journal names), or a failure. Never
/// `DesignStatus::Interrupted`: interrupted runs are not journaled (resume reruns them), and a
/// line that says so is refused on reading.
///
/// Journal form, as it always was: `{"kind": "converged"}`, `{"kind": "stopped"}`,
/// `{"kind": "stabilised_only"}`, `{"kind": "not_stabilised", "best_alpha": …}`,
/// `{"kind": "budget_exhausted"}`, `{"kind": "failed", "error": "…"}`; the kind "optimised" of
/// older builds reads as `stopped` (an alias of [`DesignStatus::Stopped`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", try_from = "StatusLine")]
pub enum JobStatus {
    /// `design::run` returned an error (or panicked): no trustworthy result.
    Failed {
        /// The error.
        error: String,
    },
    /// The design run ended with this status (serialised as the status itself).
    #[serde(untagged)]
    Design(DesignStatus),
}

/// The journal's `status` object as read, before `Interrupted` is refused.
#[derive(Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
enum StatusLine {
    Failed {
        error: String,
    },
    #[serde(untagged)]
    Design(DesignStatus),
}

impl TryFrom<StatusLine> for JobStatus {
    type Error = &'static str;
    fn try_from(s: StatusLine) -> Result<JobStatus, Self::Error> {
        match s {
            StatusLine::Failed { error } => Ok(JobStatus::Failed { error }),
            StatusLine::Design(DesignStatus::Interrupted) => {
                Err("status \"interrupted\": interrupted runs are never journaled")
            }
            StatusLine::Design(d) => Ok(JobStatus::Design(d)),
        }
    }
}

impl JobStatus {
    /// The status of a finished design run; `None` for an interrupted one (not journaled).
    pub fn of_design(status: DesignStatus) -> Option<JobStatus> {
        match status {
            DesignStatus::Interrupted => None,
            s => Some(JobStatus::Design(s)),
        }
    }

    /// Short name as in the journal's `kind`.
    pub fn kind(&self) -> &'static str {
        match self {
            JobStatus::Design(s) => s.kind(),
            JobStatus::Failed { .. } => "failed",
        }
    }
}

/// The optimality certificate of the final point.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Certificate {
    /// Norm of the min-norm element of the gradient bundle.
    #[serde(with = "serde_f64_or_string")]
    pub dnorm: f64,
    /// Bundle radius.
    #[serde(with = "serde_f64_or_string")]
    pub evaldist: f64,
}

/// One journal line.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct JobRecord {
    /// [`SCHEMA_VERSION`].
    pub schema_version: u32,
    /// The job's id.
    pub job_id: JobId,
    /// Campaign name.
    pub campaign: String,
    /// Plant name.
    pub plant: String,
    /// Plant content fingerprint.
    pub plant_fingerprint: String,
    /// Controller order.
    pub order: usize,
    /// Weight ε.
    #[serde(with = "serde_f64_or_string")]
    pub eps: f64,
    /// Seed.
    pub seed: u64,
    /// CPU budget (s).
    #[serde(with = "serde_f64_or_string")]
    pub cpumax: f64,
    /// Every design option (repeats order, eps, seed, cpumax).
    pub options: DesignOptions,
    /// Predecessor of a warm-start chain.
    pub warm_from: Option<JobId>,
    /// Whether the predecessor's controller was actually passed as the initial point.
    pub warm_started: bool,
    /// Set only by the fake runner of the test hook.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub runner: Option<String>,
    /// How it ended.
    pub status: JobStatus,
    /// ‖Tzw‖∞ of the returned controller (as reported by the design run).
    #[serde(with = "serde_f64_or_string")]
    pub gamma: f64,
    /// ‖K‖∞.
    #[serde(with = "serde_f64_or_string")]
    pub k_hinf: f64,
    /// α(A_cl).
    #[serde(with = "serde_f64_or_string")]
    pub alpha_cl: f64,
    /// α(Ak) (None for order 0 or failed jobs).
    #[serde(default, with = "serde_opt_f64_or_string")]
    pub alpha_k: Option<f64>,
    /// Final objective value.
    #[serde(with = "serde_f64_or_string")]
    pub objective: f64,
    /// ε‖K‖∞ is the active term of the objective (γ is held up by the controller-norm penalty).
    #[serde(default)]
    pub controller_norm_active: bool,
    /// Certificate of the final point, if the optimisation ran.
    pub certificate: Option<Certificate>,
    /// Total iterations.
    pub iterations: usize,
    /// Total objective evaluations.
    pub evaluations: usize,
    /// Per-phase counters.
    pub phases: Vec<PhaseStats>,
    /// The multi-start search: starts made, the best one, CPU time to best, stop reason
    /// (absent in journals written before it existed, and for failed jobs).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub search: Option<SearchSummary>,
    /// CPU seconds as counted by the design run.
    #[serde(with = "serde_f64_or_string")]
    pub design_cpu_s: f64,
    /// CPU seconds of the worker thread for the whole job.
    #[serde(with = "serde_f64_or_string")]
    pub cpu_s: f64,
    /// Wall seconds of the whole job.
    #[serde(with = "serde_f64_or_string")]
    pub wall_s: f64,
    /// When it finished (Unix seconds).
    #[serde(with = "serde_f64_or_string")]
    pub finished_unix_s: f64,
    /// The controller `{AK, BK, CK, DK}` (None for failed jobs).
    pub controller: Option<serde_json::Value>,
    /// Where and with what it ran (absent in journals written before it existed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub provenance: Option<Provenance>,
}

/// Keys whose values depend on timing, not on the computation.
pub const TIMING_KEYS: &[&str] = &["design_cpu_s", "cpu_s", "wall_s", "finished_unix_s"];
/// Keys that say where a job ran, not what it computed.
pub const WHERE_KEYS: &[&str] = &["provenance"];

impl JobRecord {
    /// The record of `job` after its run; `None` when the run was interrupted (not journaled).
    pub fn from_run(
        campaign: &str,
        job: &Job,
        warm_started: bool,
        result: Result<DesignOutcome, String>,
        cpu_s: f64,
        wall_s: f64,
    ) -> Option<JobRecord> {
        let o = &job.options;
        let mut r = JobRecord {
            schema_version: SCHEMA_VERSION,
            job_id: job.id.clone(),
            campaign: campaign.to_string(),
            plant: job.plant_name.clone(),
            plant_fingerprint: job.plant_fingerprint.clone(),
            order: o.order,
            eps: o.eps,
            seed: o.seed,
            cpumax: o.cpumax,
            options: o.clone(),
            warm_from: job.warm_from.clone(),
            warm_started,
            runner: (job.runner == RunnerTag::Fake).then(|| "fake".to_string()),
            status: JobStatus::Failed { error: String::new() },
            gamma: f64::NAN,
            k_hinf: f64::NAN,
            alpha_cl: f64::NAN,
            alpha_k: None,
            objective: f64::NAN,
            controller_norm_active: false,
            certificate: None,
            iterations: 0,
            evaluations: 0,
            phases: Vec::new(),
            search: None,
            design_cpu_s: 0.0,
            cpu_s,
            wall_s,
            finished_unix_s: std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0.0, |d| d.as_secs_f64()),
            controller: None,
            provenance: None,
        };
        match result {
            Err(error) => r.status = JobStatus::Failed { error },
            Ok(out) => {
                r.status = JobStatus::of_design(out.status)?;
                r.gamma = out.gamma;
                r.k_hinf = out.k_hinf;
                r.alpha_cl = out.alpha_cl;
                r.alpha_k = out.alpha_k;
                r.objective = out.objective;
                r.controller_norm_active = out.controller_norm_active;
                r.certificate = match (out.dnorm, out.evaldist) {
                    (Some(dnorm), Some(evaldist)) => Some(Certificate { dnorm, evaldist }),
                    _ => None,
                };
                r.iterations = out.iters;
                r.evaluations = out.evals;
                r.phases = out.phases;
                r.search = Some(out.search);
                r.design_cpu_s = out.cpu_s;
                r.controller = Some(out.controller.to_json());
            }
        }
        Some(r)
    }

    /// The record as JSON without the timing fields (also inside `phases`) and the provenance:
    /// two runs of the same job on the same machine must agree on this exactly.
    pub fn comparable(&self) -> serde_json::Value {
        let mut v = serde_json::to_value(self).expect("record serialises");
        if let Some(obj) = v.as_object_mut() {
            for k in TIMING_KEYS.iter().chain(WHERE_KEYS) {
                obj.remove(*k);
            }
            if let Some(serde_json::Value::Array(phases)) = obj.get_mut("phases") {
                for p in phases {
                    if let Some(p) = p.as_object_mut() {
                        p.remove("cpu_s");
                    }
                }
            }
            if let Some(serde_json::Value::Object(search)) = obj.get_mut("search") {
                search.remove("cpu_to_best_s");
            }
        }
        v
    }

    /// Whether the job failed (no trustworthy result).
    pub fn failed(&self) -> bool {
        matches!(self.status, JobStatus::Failed { .. })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The journal's status objects are the ones older builds wrote, and read back.
    #[test]
    fn status_lines_keep_their_journal_form() {
        let cases = [
            (JobStatus::Design(DesignStatus::Converged), r#"{"kind":"converged"}"#),
            (JobStatus::Design(DesignStatus::Stopped), r#"{"kind":"stopped"}"#),
            (JobStatus::Design(DesignStatus::StabilisedOnly), r#"{"kind":"stabilised_only"}"#),
            (
                JobStatus::Design(DesignStatus::NotStabilised { best_alpha: 0.25 }),
                r#"{"kind":"not_stabilised","best_alpha":0.25}"#,
            ),
            (
                JobStatus::Design(DesignStatus::NotStabilised { best_alpha: f64::INFINITY }),
                r#"{"kind":"not_stabilised","best_alpha":"inf"}"#,
            ),
            (JobStatus::Design(DesignStatus::BudgetExhausted), r#"{"kind":"budget_exhausted"}"#),
            (JobStatus::Failed { error: "boom".into() }, r#"{"kind":"failed","error":"boom"}"#),
        ];
        for (status, line) in cases {
            assert_eq!(serde_json::to_string(&status).unwrap(), line);
            assert_eq!(serde_json::from_str::<JobStatus>(line).unwrap(), status, "{line}");
            assert_eq!(status.kind(), serde_json::from_str::<serde_json::Value>(line).unwrap()["kind"]);
        }
        let old: JobStatus = serde_json::from_str(r#"{"kind":"optimised"}"#).unwrap();
        assert_eq!(old, JobStatus::Design(DesignStatus::Stopped));
        for bad in [r#"{"kind":"interrupted"}"#, r#"{"kind":"exploded"}"#, r#"{"kind":"failed"}"#, "{}"] {
            assert!(serde_json::from_str::<JobStatus>(bad).is_err(), "{bad} was accepted");
        }
        assert_eq!(JobStatus::of_design(DesignStatus::Interrupted), None);
    }
}
