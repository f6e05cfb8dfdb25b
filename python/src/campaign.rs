//! Campaigns: `run_campaign(file, results)` runs a campaign file as `campaign run FILE --results
//! DIR --no-progress` does (same jobs, journal, resume, traces and report files), and
//! `read_results(folder)` reads every journal of a results folder.
use std::path::{Path, PathBuf};

use pyo3::prelude::*;
use serde_json::{json, Value};

use hinfix::campaign::{
    campaign_dir, design_job, expand, journals_in, read_journal, records_for, report, run_jobs, trace_observers,
    Campaign, ExecuteOptions, ProgressDisplay, Reporter, RunnerTag,
};

use crate::errors::{bad_input, failure};
use crate::interrupt::run_interruptible;

/// Runs the campaign file `path` into `<results>/<campaign name>/` (resuming what is journaled
/// there) with `threads` workers (default: the file's), then writes the report files. Returns a
/// JSON summary: the folder, the job counts and the report's best rows. `progress` prints one
/// line per event on stderr. Ctrl-C stops the run (the finished jobs stay journaled; running the
/// same call again resumes) and raises KeyboardInterrupt.
#[pyfunction]
#[pyo3(signature = (path, results, threads = None, progress = false))]
pub fn run_campaign(
    py: Python<'_>,
    path: PathBuf,
    results: PathBuf,
    threads: Option<usize>,
    progress: bool,
) -> PyResult<String> {
    let campaign = Campaign::load(&path).map_err(|e| bad_input("run_campaign", e))?;
    if threads == Some(0) {
        return Err(bad_input("run_campaign", "threads must be at least 1"));
    }
    let jobs = expand(&campaign, RunnerTag::Design);
    let dir = campaign_dir(&results, &campaign.name);
    std::fs::create_dir_all(&dir).map_err(|e| failure(&format!("creating {}", dir.display()), e))?;
    let opts = ExecuteOptions::new(&campaign.name, campaign.threads(threads));
    let cancel = opts.cancel.clone();
    let summary = run_interruptible(py, cancel, |_| -> Result<Value, String> {
        let observers = trace_observers(&dir.join("traces"), campaign.trace_levels(None));
        let mut reporter = Reporter::new(&jobs, ProgressDisplay::Plain);
        let on_event = |ev: &_| {
            if progress {
                reporter.on_event(ev)
            }
        };
        let outcome = run_jobs(&jobs, &dir, &design_job, &observers, &opts, on_event).map_err(|e| e.to_string())?;
        let records = records_for(&jobs, &outcome.records);
        let rep = report(&dir, &campaign, &records).map_err(|e| e.to_string())?;
        let s = &outcome.stats;
        Ok(json!({
            "dir": dir,
            "total": s.total, "already_done": s.already_done, "finished": s.finished, "failed": outcome.failed(),
            "done_elsewhere": s.done_elsewhere, "interrupted": s.interrupted, "not_started": s.not_started,
            "warnings": s.warnings,
            "report_files": rep.summary.files,
            "best": rep.summary.best,
        }))
    })?
    .map_err(|e| failure("run_campaign", e))?;
    Ok(summary.to_string())
}

/// Every record of the journals (`runs*.jsonl`) of the results folder `folder`, as a JSON array of
/// journal lines (in the crate's record format), journals in name order, lines in file order; a
/// torn last line is left out. A folder without journals gives `[]`.
#[pyfunction]
pub fn read_results(folder: PathBuf) -> PyResult<String> {
    let journals = journals_in(&folder).map_err(|e| failure("read_results", e))?;
    if !folder.is_dir() {
        return Err(bad_input("read_results", format!("{} is not a folder", folder.display())));
    }
    let mut records = Vec::new();
    for j in &journals {
        records.extend(read(j)?);
    }
    serde_json::to_string(&records).map_err(|e| failure("read_results", e))
}

fn read(journal: &Path) -> PyResult<Vec<hinfix::campaign::JobRecord>> {
    Ok(read_journal(journal).map_err(|e| failure("read_results", e))?.records)
}
