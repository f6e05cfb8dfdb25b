//! One finished job as the journal stores it (one JSON line of `runs.jsonl`), and the final
//! message of its trace.

use serde::{Deserialize, Serialize};

use super::jobs::{Job, JobId, RunnerTag};
use super::provenance::Provenance;
use crate::design::{serde_f64_or_string, DesignOptions, DesignOutcome, DesignStatus};
use crate::lti::Controller;
use serde::ser::SerializeMap;

/// Version of the journal line format. Readers refuse newer versions.
/// 2: a failed job's line carries no outcome fields (schema 1 wrote them as NaN, `null` and
/// zeros). Lines of schema 1 and 2 are read.
pub const SCHEMA_VERSION: u32 = 2;

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

/// One journal line: the job (id, plant, every option, warm-start predecessor), how it ran
/// (runner, CPU and wall seconds, provenance) and its result, the design run's own
/// [`DesignOutcome`] or why it failed.
///
/// Journal form: one flat JSON object. The job's fields, then the result's: a designed job's
/// outcome fields (`status`, `controller`, `gamma`, `k_hinf`, `alpha_cl`, `alpha_k`, `objective`,
/// `controller_norm_active`, `certificate`, `iterations`, `evaluations`, `phases`,
/// `design_cpu_s`, `search`) sit at the top level, as they always did; a failed job has only
/// `"status": {"kind": "failed", "error": …}` ([`JobResult`] reads the lines of older builds).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct JobRecord {
    /// The schema version of the line it was read from ([`SCHEMA_VERSION`] for a new record).
    /// Always written as [`SCHEMA_VERSION`]: a record is written in this build's format.
    #[serde(serialize_with = "write_current_schema")]
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
    /// CPU budget (CPU seconds).
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
    /// How it ended: the design run's outcome, or the error.
    #[serde(flatten)]
    pub result: JobResult,
    /// CPU seconds of the worker thread for the whole job (the design run's own count is the
    /// outcome's `design_cpu_s`).
    #[serde(with = "serde_f64_or_string")]
    pub cpu_s: f64,
    /// Wall seconds of the whole job.
    #[serde(with = "serde_f64_or_string")]
    pub wall_s: f64,
    /// When it finished (Unix seconds).
    #[serde(with = "serde_f64_or_string")]
    pub finished_unix_s: f64,
    /// Where and with what it ran (absent in journals written before it existed).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub provenance: Option<Provenance>,
}

fn write_current_schema<S: serde::Serializer>(_: &u32, s: S) -> Result<S::Ok, S::Error> {
    s.serialize_u32(SCHEMA_VERSION)
}

/// The result of a journaled job.
#[derive(Debug, Clone)]
pub enum JobResult {
    /// `design::run` finished (never with [`DesignStatus::Interrupted`]: interrupted runs are not
    /// journaled) and returned this.
    Designed(Box<DesignOutcome>),
    /// `design::run` returned an error (or panicked): no trustworthy result.
    Failed {
        /// The error.
        error: String,
    },
}

/// A designed job: the outcome's fields. A failed job: `{"status": {"kind": "failed", …}}`.
impl Serialize for JobResult {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            JobResult::Designed(outcome) => outcome.serialize(s),
            JobResult::Failed { error } => {
                let mut m = s.serialize_map(Some(1))?;
                m.serialize_entry("status", &JobStatus::Failed { error: error.clone() })?;
                m.end()
            }
        }
    }
}

/// The one place where journal lines of every version become a result. `status` decides:
/// `failed` ignores the other outcome fields (builds before schema 2 wrote them as NaN, `null`
/// and zeros); any other status reads the outcome ([`DesignOutcome`]'s field names are the
/// journal's since its first version; `"optimised"` and a missing `search` read as its
/// deserialiser says). `interrupted` is refused.
impl<'de> Deserialize<'de> for JobResult {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        use serde::de::Error;
        let fields = serde_json::Map::<String, serde_json::Value>::deserialize(d)?;
        let status = fields.get("status").ok_or_else(|| D::Error::missing_field("status"))?;
        match JobStatus::deserialize(status).map_err(|e| D::Error::custom(format_args!("status: {e}")))? {
            JobStatus::Failed { error } => Ok(JobResult::Failed { error }),
            JobStatus::Design(_) => DesignOutcome::deserialize(serde_json::Value::Object(fields))
                .map(|o| JobResult::Designed(Box::new(o)))
                .map_err(D::Error::custom),
        }
    }
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
        let result = match result {
            Err(error) => JobResult::Failed { error },
            Ok(out) if out.status == DesignStatus::Interrupted => return None,
            // A journal line must read back, and a controller is read only if it is finite.
            Ok(out) if !out.controller.is_finite() => {
                JobResult::Failed { error: "the design run returned a controller with a non-finite entry".into() }
            }
            Ok(out) => JobResult::Designed(Box::new(out)),
        };
        let o = &job.options;
        Some(JobRecord {
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
            result,
            cpu_s,
            wall_s,
            finished_unix_s: std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0.0, |d| d.as_secs_f64()),
            provenance: None,
        })
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

    /// The design run's outcome; `None` when the job failed.
    pub fn outcome(&self) -> Option<&DesignOutcome> {
        match &self.result {
            JobResult::Designed(o) => Some(o),
            JobResult::Failed { .. } => None,
        }
    }

    /// The returned controller; `None` when the job failed.
    pub fn controller(&self) -> Option<&Controller> {
        self.outcome().map(|o| &o.controller)
    }

    /// How the job ended.
    pub fn status(&self) -> JobStatus {
        match &self.result {
            JobResult::Designed(o) => JobStatus::Design(o.status.clone()),
            JobResult::Failed { error } => JobStatus::Failed { error: error.clone() },
        }
    }

    /// Whether the job failed (no trustworthy result).
    pub fn failed(&self) -> bool {
        matches!(self.result, JobResult::Failed { .. })
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
