//! Running a campaign's jobs: the worker pool (`scheduler.rs`) and the start of a chained job
//! (`chain.rs`), the MCAP traces (`trace.rs`), the progress display (`progress.rs`), the resume
//! from the journal (`run.rs`), and the fake runner of the tests (`fake.rs`).
pub(crate) mod chain;
#[cfg(any(test, feature = "test-support"))]
pub(crate) mod fake;
pub(crate) mod progress;
pub(crate) mod run;
pub(crate) mod scheduler;
pub(crate) mod trace;
