//! Benchmark campaigns: campaign files, job expansion, scheduling, journal/resume, traces and
//! reports — plus the paper's reference numbers they are compared with.
//!
//! The pieces are separate, nextest style (docs/ARCHITECTURE.md §2): [`execute`] runs jobs and
//! emits [`CampaignEvent`]s without printing or writing anything; the journal ([`run_jobs`],
//! [`JournalWriter`]), the trace writer ([`TraceWriter`]), the progress reporter and the report
//! writers ([`write_reports`]) each consume what they need.
//!
//! The modules are crate-private; what is API is re-exported here (the command line, `crate::cli`,
//! also reaches a few crate-private helpers by path).
pub(crate) mod claims;
mod compare;
pub(crate) mod fake;
mod jobs;
pub(crate) mod journal;
pub(crate) mod latex;
mod model;
pub mod plot;
pub(crate) mod progress;
mod provenance;
pub(crate) mod record;
pub(crate) mod reduce;
mod reference;
pub(crate) mod report;
pub(crate) mod run;
pub(crate) mod sanitise;
pub(crate) mod scheduler;
pub(crate) mod shard;
mod spec;
pub(crate) mod trace;
mod trace_filter;

pub use fake::{FakeRunner, DEFAULT_PAUSE_MS, FAKE_ITERS, FAKE_RUNNER_ENV};
pub use jobs::{expand, job_id, Job, JobId, RunnerTag, JOB_ID_VERSION};
pub use journal::{
    is_journal_name, journals_in, parse_journal, read_journal, Follower, JournalError, JournalRead, JournalWriter,
    TornTail, JOURNAL_FILE,
};
pub use latex::{compare_tex, sig4, sig_figs, tables_tex};
pub use provenance::Provenance;
pub use record::{FailureKind, JobFailure, JobRecord, JobResult, JobStatus, Unverifiable, SCHEMA_VERSION};
pub use reduce::{best_per_order, verify, BestRow, PlantMap, Verdict, NEAR_BEST_RTOL};
pub use reference::{
    load_default_reference, load_reference, paper_plant_name, RefMethod, ReferenceError, ReferenceRow,
    PAPER_PLANT_FINGERPRINTS, REFERENCE_CSV,
};
pub use report::{compare_rows, write_reports, CompareRow, FullOrderRow, ReportError, ReportSummary, FULL_ORDER_MAX_N};
pub use run::{campaign_dir, journal_path, run_jobs, RunError, RunOutcome};
pub use scheduler::{
    execute, no_observers, CampaignEvent, CancelReason, Claim, Coordinator, DesignRunner, ExecuteError, ExecuteOptions,
    JobObserver, JobRunner, ObserverError, ObserverFactory, RunStats, Scheduler, Solo,
};
pub use spec::{
    Campaign, Location, Problem, SpecError, DEFAULT_THREADS, MAX_JOBS, MAX_NAME_CHARS, MAX_ORDER, MAX_SEEDS,
    MAX_THREADS,
};
pub use trace::{
    iter_message, read_iterations, summarise, summarise_bytes, trace_observers, PhaseSummary, TraceError,
    TraceIteration, TraceSummary, TraceWriter, ITER_TOPIC, RESULT_TOPIC,
};
pub use trace_filter::{Keep, SparseFilter, TraceLevel, IMPROVE_RTOL, SAMPLE_CPU_S, SAMPLE_RATIO};
