//! Benchmark campaigns: campaign files, job expansion, scheduling, journal/resume, traces and
//! reports — plus the paper's reference numbers they are compared with.
//!
//! The pieces are separate, nextest style (style.md §4): [`scheduler::execute`] runs jobs and
//! emits [`CampaignEvent`]s without printing or writing anything; the journal, the trace writer,
//! the progress reporter and the report writers each consume what they need.
pub mod jobs;
pub mod record;
pub mod scheduler;
mod reference;
pub mod spec;

pub use jobs::{expand, job_id, Job, JobId, RunnerTag};
pub use reference::{load_default_reference, load_reference, RefMethod, ReferenceError, ReferenceRow, REFERENCE_CSV};
pub use spec::{Campaign, Location, Problem, SpecError, DEFAULT_THREADS};
