//! One finished job as the journal stores it (one JSON line of `runs.jsonl`), and the final
//! message of its trace.

use serde::{Deserialize, Serialize};

use crate::campaign::leaves::provenance::Provenance;
use crate::campaign::model::jobs::{Job, JobId, RunnerTag};
use crate::design::{serde_f64_or_string, DesignOptions, DesignOutcome, DesignStatus};
use crate::lti::Controller;
use serde::ser::SerializeMap;

/// Version of the journal line format. Readers refuse newer versions.
/// 2: a failed job's line carries no outcome fields (schema 1 wrote them as NaN, `null` and
/// zeros). Lines of schema 1 and 2 are read.
pub const SCHEMA_VERSION: u32 = 2;

/// Why a job failed, as the scheduler found it and the journal carries it. Its `Display` is the
/// message journal lines have always held in `status.error`; [`FailureKind`] is written next to
/// it. Lines of older builds, which recorded only the message, read as [`JobFailure::Unrecorded`].
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum JobFailure {
    /// The runner panicked (the scheduler caught it); the panic's message.
    #[error("panic: {0}")]
    Panicked(String),
    /// The runner returned an error (for `design::Design::run`, a `DesignError`); its message.
    #[error("{0}")]
    RunnerError(String),
    /// The runner's result failed the check before journaling.
    #[error("{0}")]
    Verification(Unverifiable),
    /// Read from a journal line that did not record the kind; its message.
    #[error("{0}")]
    Unrecorded(String),
}

/// Why a design run's result cannot be journaled as one ([`JobFailure::Verification`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum Unverifiable {
    /// The controller has a NaN or infinite entry: a journal line must read back, and a
    /// controller is read only if it is finite.
    #[error("the design run returned a controller with a non-finite entry")]
    NonFiniteController,
}

/// The kind of a [`JobFailure`], as the journal names it (`status.failure_kind`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FailureKind {
    /// [`JobFailure::Panicked`].
    Panicked,
    /// [`JobFailure::RunnerError`].
    RunnerError,
    /// [`JobFailure::Verification`].
    Verification,
}

impl JobFailure {
    /// Its kind; `None` for a failure read from a line that did not record it.
    pub fn kind(&self) -> Option<FailureKind> {
        match self {
            JobFailure::Panicked(_) => Some(FailureKind::Panicked),
            JobFailure::RunnerError(_) => Some(FailureKind::RunnerError),
            JobFailure::Verification(_) => Some(FailureKind::Verification),
            JobFailure::Unrecorded(_) => None,
        }
    }

    /// The failure a journal line's `status` describes: its message and, if recorded, its kind.
    /// A verification failure whose message this build does not know reads as
    /// [`JobFailure::Unrecorded`], so its message is kept.
    pub fn from_journal(error: String, kind: Option<FailureKind>) -> JobFailure {
        match kind {
            Some(FailureKind::Panicked) => match error.strip_prefix("panic: ") {
                Some(m) => JobFailure::Panicked(m.to_string()),
                None => JobFailure::Unrecorded(error),
            },
            Some(FailureKind::RunnerError) => JobFailure::RunnerError(error),
            Some(FailureKind::Verification) if error == Unverifiable::NonFiniteController.to_string() => {
                JobFailure::Verification(Unverifiable::NonFiniteController)
            }
            Some(FailureKind::Verification) | None => JobFailure::Unrecorded(error),
        }
    }

    /// Its journal `status`.
    pub fn status(&self) -> JobStatus {
        JobStatus::Failed { error: self.to_string(), failure_kind: self.kind() }
    }
}

/// How a journaled job ended: the design run's own [`DesignStatus`] (one definition of the
/// statuses, their meaning and their journal names), or a failure. Never
/// `DesignStatus::Interrupted`: interrupted runs are not journaled (resume reruns them), and a
/// line that says so is refused on reading.
///
/// Journal form, as it always was: `{"kind": "converged"}`, `{"kind": "stopped"}`,
/// `{"kind": "stabilised_only"}`, `{"kind": "not_stabilised", "best_alpha": …}`,
/// `{"kind": "budget_exhausted"}`, `{"kind": "failed", "error": "…"}`; the kind "optimised" of
/// older builds reads as `stopped` (an alias of [`DesignStatus::Stopped`]). A failure written by
/// this build also names its [`FailureKind`] (`"failure_kind": "panicked"`), a key older readers
/// ignore and older lines lack.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case", try_from = "StatusLine")]
pub enum JobStatus {
    /// `design::Design::run` returned an error (or panicked), or its result failed the check before
    /// journaling: no trustworthy result.
    Failed {
        /// The failure's message ([`JobFailure`]'s `Display`).
        error: String,
        /// What kind of failure; `None` in lines of builds that did not record it.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        failure_kind: Option<FailureKind>,
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
        #[serde(default)]
        failure_kind: Option<FailureKind>,
    },
    #[serde(untagged)]
    Design(DesignStatus),
}

impl TryFrom<StatusLine> for JobStatus {
    type Error = &'static str;
    fn try_from(s: StatusLine) -> Result<JobStatus, Self::Error> {
        match s {
            StatusLine::Failed { error, failure_kind } => Ok(JobStatus::Failed { error, failure_kind }),
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
    /// Order chaining: the job of the order below whose controller was the chained start
    /// (`campaign::chain`); absent without one (and in journals of builds before it).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub chained_from: Option<JobId>,
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
    /// `design::Design::run` finished (never with [`DesignStatus::Interrupted`]: interrupted runs are not
    /// journaled) and returned this.
    Designed(Box<DesignOutcome>),
    /// `design::Design::run` returned an error (or panicked), or its result failed the check before
    /// journaling: no trustworthy result.
    Failed(JobFailure),
}

/// A designed job: the outcome's fields. A failed job: `{"status": {"kind": "failed", …}}`.
impl Serialize for JobResult {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            JobResult::Designed(outcome) => outcome.serialize(s),
            JobResult::Failed(failure) => {
                let mut m = s.serialize_map(Some(1))?;
                m.serialize_entry("status", &failure.status())?;
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
            JobStatus::Failed { error, failure_kind } => {
                Ok(JobResult::Failed(JobFailure::from_journal(error, failure_kind)))
            }
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

/// The check a design run's result passes before it is journaled as one: a journal line must
/// read back, and a controller is read only if it is finite.
pub fn verify_outcome(out: DesignOutcome) -> Result<DesignOutcome, JobFailure> {
    if out.controller.is_finite() {
        Ok(out)
    } else {
        Err(JobFailure::Verification(Unverifiable::NonFiniteController))
    }
}

impl JobRecord {
    /// The record of `job` after its run; `None` when the run was interrupted (not journaled).
    /// A result that fails `verify_outcome` is journaled as that failure.
    pub fn from_run(
        campaign: &str,
        job: &Job,
        warm_started: bool,
        result: Result<DesignOutcome, JobFailure>,
        cpu_s: f64,
        wall_s: f64,
    ) -> Option<JobRecord> {
        let result = match result {
            Ok(out) if out.status == DesignStatus::Interrupted => return None,
            r => match r.and_then(verify_outcome) {
                Ok(out) => JobResult::Designed(Box::new(out)),
                Err(failure) => JobResult::Failed(failure),
            },
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
            chained_from: None,
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
                        p.remove("design_cpu_s");
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
            JobResult::Failed(_) => None,
        }
    }

    /// Why the job failed; `None` when it did not.
    pub fn failure(&self) -> Option<&JobFailure> {
        match &self.result {
            JobResult::Designed(_) => None,
            JobResult::Failed(f) => Some(f),
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
            JobResult::Failed(failure) => failure.status(),
        }
    }

    /// Whether the job failed (no trustworthy result).
    pub fn failed(&self) -> bool {
        matches!(self.result, JobResult::Failed(_))
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
            (JobStatus::Failed { error: "boom".into(), failure_kind: None }, r#"{"kind":"failed","error":"boom"}"#),
            (
                JobFailure::Panicked("boom".into()).status(),
                r#"{"kind":"failed","error":"panic: boom","failure_kind":"panicked"}"#,
            ),
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

    /// Each failure writes the message older builds wrote, plus its kind, and reads back to
    /// itself; a line without the kind (older builds) reads as `Unrecorded` with its message.
    #[test]
    fn failures_keep_their_message_and_read_back() {
        let cases = [
            (JobFailure::Panicked("index out of bounds".into()), "panic: index out of bounds"),
            (JobFailure::RunnerError("numerical failure: x".into()), "numerical failure: x"),
            (
                JobFailure::Verification(Unverifiable::NonFiniteController),
                "the design run returned a controller with a non-finite entry",
            ),
        ];
        for (failure, message) in cases {
            assert_eq!(failure.to_string(), message);
            let JobStatus::Failed { error, failure_kind } = failure.status() else { unreachable!() };
            assert_eq!((error.as_str(), failure_kind), (message, failure.kind()));
            assert_eq!(JobFailure::from_journal(error.clone(), failure_kind), failure);
            assert_eq!(JobFailure::from_journal(error, None), JobFailure::Unrecorded(message.into()));
        }
        let odd = JobFailure::from_journal("no prefix".into(), Some(FailureKind::Panicked));
        assert_eq!((odd.to_string(), odd.kind()), ("no prefix".to_string(), None));
    }
}
