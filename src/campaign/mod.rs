//! Benchmark campaigns: campaign files, job expansion, scheduling, journal/resume, traces and
//! reports — plus the paper's reference numbers they are compared with.
//!
//! The pieces are separate, nextest style (docs/ARCHITECTURE.md §2): [`scheduler::execute`] runs jobs and
//! emits [`scheduler::CampaignEvent`]s without printing or writing anything; the journal
//! ([`run`]), the trace writer ([`trace`]), the progress reporter ([`progress`]) and the report
//! writers ([`report`]) each consume what they need.
pub mod claims;
mod compare;
pub mod fake;
mod jobs;
pub mod journal;
pub mod latex;
mod model;
pub mod plot;
pub mod progress;
mod provenance;
pub mod record;
pub mod reduce;
mod reference;
pub mod report;
pub mod run;
pub mod sanitise;
pub mod scheduler;
pub mod shard;
mod spec;
pub mod trace;

pub use jobs::{expand, job_id, Job, JobId, RunnerTag, JOB_ID_VERSION};
pub use provenance::Provenance;
pub use reduce::{best_per_order, verify, BestRow, PlantMap, Verdict};
pub use reference::{load_default_reference, load_reference, RefMethod, ReferenceError, ReferenceRow, REFERENCE_CSV};
pub use report::{write_reports, CompareRow, FullOrderRow, ReportError, ReportSummary};
pub use spec::{
    Campaign, Location, Problem, SpecError, DEFAULT_THREADS, MAX_JOBS, MAX_NAME_CHARS, MAX_ORDER, MAX_SEEDS,
    MAX_THREADS,
};
pub use trace::{summarise, trace_observers, TraceError, TraceSummary, TraceWriter};
