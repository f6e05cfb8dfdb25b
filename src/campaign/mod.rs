//! Benchmark campaigns: campaign files, job expansion, scheduling, journal/resume, traces and
//! reports — plus the paper's reference numbers they are compared with.
//!
//! The pieces are separate, nextest style (docs/ARCHITECTURE.md §2): [`execute`] runs jobs and
//! emits [`CampaignEvent`]s without printing or writing anything; the journal ([`run_jobs`],
//! [`JournalWriter`]), the trace writer ([`TraceWriter`]), the progress reporter and the report
//! writers ([`write_reports`]) each consume what they need.
//!
//! The modules are crate-private; what is API is re-exported here, and the command line
//! (`crate::cli`) uses only that: [`status`] and [`report`] give it typed results to print.
mod chain;
pub(crate) mod claims;
mod compare;
#[cfg(any(test, feature = "test-support"))]
pub(crate) mod fake;
pub mod html;
mod jobs;
pub(crate) mod journal;
pub(crate) mod latex;
mod lookup;
pub mod methods;
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
mod status;
pub(crate) mod trace;
mod trace_filter;

pub use claims::unix_now;
#[cfg(any(test, feature = "test-support"))]
pub use fake::{FakeRunner, DEFAULT_PAUSE_MS, FAKE_ITERS, FAKE_RUNNER_ENV};
pub use html::{report_html, write_html_report};
pub use jobs::{
    chained_job_id, expand, job_id, problem_fingerprint, problem_job_id, Job, JobId, ProblemKey, RunnerTag,
    JOB_ID_VERSION,
};
pub use journal::{
    is_journal_name, journals_in, parse_journal, read_journal, CorruptLine, Follower, JournalError, JournalRead,
    JournalWriter, TornTail, JOURNAL_FILE,
};
pub use latex::{campaign_table, compare_tex, cost_table, sig4, sig_figs, tables_tex, tables_tex_about};
pub use lookup::{find_record, Entry, LookupError};
pub use methods::{compare_methods, load_sources, MethodsError, MethodsOutcome, SourceError, DEFAULT_RTOL};
pub use progress::{Display as ProgressDisplay, Reporter};
pub use provenance::Provenance;
pub use record::{FailureKind, JobFailure, JobRecord, JobResult, JobStatus, Unverifiable, SCHEMA_VERSION};
pub use reduce::{
    best_per_order, best_per_problem, verify, verify_controller, verify_problem, verify_problem_controller, BestRow,
    PlantMap, ProblemMap, Verdict, NEAR_BEST_RTOL,
};
pub use reference::{
    load_default_reference, load_reference, paper_plant_name, RefMethod, ReferenceError, ReferenceRow, RowProblem,
    PAPER_PLANT_FINGERPRINTS, REFERENCE_CSV,
};
pub use report::{
    compare_rows, cost_rows, full_order_controller_stable, write_problem_reports, write_reports, CampaignAbout,
    CompareRow, CostRow, FullOrderRow, ReportError, ReportSummary, FULL_ORDER_CENTRAL_LEVEL, FULL_ORDER_MAX_N,
};
pub use run::{campaign_dir, duplicate_ids, journal_path, records_for, run_jobs, RunError, RunOutcome};
pub use sanitise::for_terminal;
pub use scheduler::{
    design_job, execute, no_observers, CampaignEvent, CancelReason, Claim, Coordinator, ExecuteError, ExecuteOptions,
    JobObserver, JobRunner, JobStarts, ObserverError, ObserverFactory, RunStats, Scheduler, Solo,
};
pub use shard::{select as shard_jobs, Shard};
pub use spec::{
    Campaign, Location, Problem, SpecError, SpecProblem, DEFAULT_THREADS, MAX_JOBS, MAX_NAME_CHARS, MAX_ORDER,
    MAX_SEEDS, MAX_THREADS,
};
pub use status::{
    plant_map, problem_map, report, shard_plan, status, CampaignReport, CampaignReportError, CampaignStatus,
    DuplicateJob, PlantStatus, RunningJob, ShardLoad,
};
pub use trace::{
    iter_message, read_iterations, summarise, summarise_bytes, trace_observers, PhaseSummary, TraceError,
    TraceIteration, TraceSummary, TraceWriter, ITER_TOPIC, RESULT_TOPIC,
};
pub use trace_filter::TraceLevel;
