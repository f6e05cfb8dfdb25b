//! Benchmark campaigns: campaign files, job expansion, scheduling, journal/resume, traces and
//! reports — plus the paper's reference numbers they are compared with.
//!
//! The pieces are separate, nextest style (docs/ARCHITECTURE.md §2): [`execute`] runs jobs and
//! emits [`CampaignEvent`]s without printing or writing anything; the journal ([`run_jobs`],
//! [`JournalWriter`]), the trace writer ([`TraceWriter`]), the progress reporter and the report
//! files (one [`Exporter`] each, written by [`write_reports`]) each consume what they need.
//!
//! The modules are in five parts, one folder each, from the bottom up (a part imports only its
//! own and those below it, `tests/module_graph.rs`; docs/ARCHITECTURE.md §1):
//!
//! * `leaves/`: provenance, the paper's reference values, the plant library's full-order values,
//!   escaping, what a sparse trace keeps;
//! * `model/`: the validated [`Campaign`], its TOML file, its jobs and their ids;
//! * `records/`: a job's record, the journal, claims, shards;
//! * `execution/`: the scheduler and order chaining, traces, progress, resume;
//! * `reduction/`: the best verified controllers, the comparison with the paper, the report
//!   files behind one [`Exporter`] each, the HTML page, figures, the comparison of methods,
//!   `campaign status`.
//!
//! The modules are crate-private; what is API is re-exported here, and the command line
//! (`crate::cli`) uses only that: [`status`] and [`report`] give it typed results to print.
mod execution;
mod leaves;
mod model;
mod records;
mod reduction;

#[cfg(any(test, feature = "test-support"))]
pub use execution::fake::{FakeRunner, DEFAULT_PAUSE_MS, FAKE_ITERS, FAKE_RUNNER_ENV};
pub use execution::progress::{Display as ProgressDisplay, Reporter};
pub use execution::run::{
    campaign_dir, duplicate_ids, journal_path, records_and_disagreements, records_for, run_jobs, RunError, RunOutcome,
};
pub use execution::scheduler::{
    design_job, execute, no_observers, CampaignEvent, CancelReason, Claim, Coordinator, ExecuteError, ExecuteOptions,
    JobObserver, JobRunner, JobStarts, ObserverError, ObserverFactory, RunStats, Scheduler, Solo,
};
pub use execution::trace::{
    iter_message, read_iterations, summarise, summarise_bytes, trace_observers, PhaseSummary, TraceError,
    TraceIteration, TraceSummary, TraceWriter, ITER_TOPIC, RESULT_TOPIC,
};
pub use leaves::library_index::{
    IndexEntry, IndexFieldProblem, LibraryIndex, LibraryIndexError, LIBRARY_FINGERPRINTS_CSV, LIBRARY_INDEX_CSV,
};
pub use leaves::provenance::Provenance;
pub use leaves::reference::{
    load_default_reference, load_reference, paper_plant_name, RefMethod, ReferenceError, ReferenceRow, RowProblem,
    PAPER_PLANT_FINGERPRINTS, REFERENCE_CSV,
};
pub use leaves::sanitise::for_terminal;
pub use leaves::trace_filter::TraceLevel;
pub use model::jobs::{
    chained_job_id, expand, job_id, problem_fingerprint, problem_job_id, Job, JobId, ProblemKey, RunnerTag,
    JOB_ID_VERSION,
};
pub use model::spec::{
    Campaign, Location, Problem, SpecError, SpecProblem, DEFAULT_THREADS, MAX_JOBS, MAX_NAME_CHARS, MAX_ORDER,
    MAX_SEEDS, MAX_THREADS,
};
pub use records::claims::unix_now;
pub use records::journal::{
    is_journal_name, journals_in, parse_journal, read_journal, CorruptLine, Follower, JournalError, JournalRead,
    JournalWriter, TornTail, JOURNAL_FILE,
};
pub use records::record::{FailureKind, JobFailure, JobRecord, JobResult, JobStatus, Unverifiable, SCHEMA_VERSION};
pub use records::shard::{select as shard_jobs, Shard};
pub use reduction::compare::{
    compare_rows, cost_rows, full_order_controller_stable, CampaignAbout, CompareRow, CostRow, FullOrderRow,
    FullOrderSource, FULL_ORDER_CENTRAL_LEVEL, FULL_ORDER_MAX_N,
};
pub use reduction::export::{
    BestCsv, CompareCsv, CompareTex, CsvFile, Exporter, HtmlPage, LibraryTex, PlantsCsv, ReportData, StrongVsPlainCsv,
    TablesTex, HTML_PAGE, TABLES,
};
pub use reduction::html::report_html;
pub use reduction::latex::{campaign_table, compare_tex, cost_table, sig4, sig_figs, tables_tex, tables_tex_about};
pub use reduction::lookup::{find_record, Entry, LookupError};
pub use reduction::methods::{compare_methods, load_sources, MethodsError, MethodsOutcome, SourceError, DEFAULT_RTOL};
pub use reduction::reduce::{
    best_per_order, best_per_problem, verify, verify_controller, verify_problem, verify_problem_controller, BestRow,
    PlantMap, ProblemMap, Verdict, NEAR_BEST_RTOL,
};
pub use reduction::report::{
    plant_map, problem_map, report, write_exports, write_html_report, write_problem_reports, write_reports,
    CampaignReport, CampaignReportError, ReportError, ReportSummary,
};
pub use reduction::status::{shard_plan, status, CampaignStatus, DuplicateJob, PlantStatus, RunningJob, ShardLoad};
pub use reduction::{html, methods, plot};
