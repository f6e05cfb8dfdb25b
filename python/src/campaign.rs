//! Campaigns: `run_campaign(file, results)` runs a campaign file as `campaign run FILE --results
//! DIR --no-progress` does (same jobs, journal, resume, traces and report files), and
//! `read_results(folder)` reads every journal of a results folder.
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use pyo3::prelude::*;
use serde_json::{json, Value};

use hinfix::campaign::{
    campaign_dir, design_job, expand, journals_in, read_journal, records_for, report, run_jobs, trace_observers,
    Campaign, ExecuteOptions, ProgressDisplay, Reporter, RunnerTag, MAX_THREADS,
};

use crate::errors::{bad_input, failure};
use crate::interrupt::run_interruptible_with;

/// Runs the campaign file `path` into `<results>/<campaign name>/` (resuming what is journaled
/// there) with `threads` workers (default: the file's), then writes the report files. Returns a
/// JSON summary: the folder, the job counts and the report's best rows. `progress` prints one
/// line per event on Python's `sys.stderr` (from the calling thread, so a Jupyter cell shows
/// them). Ctrl-C stops the run (the finished jobs stay journaled; running the
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
    if let Some(t) = threads.filter(|t| !(1..=MAX_THREADS).contains(t)) {
        // as the campaign file's `threads` and `campaign run --threads`: a pool of 10⁶ OS threads
        // took longer to build than any run
        return Err(bad_input("run_campaign", format!("threads must be in 1..={MAX_THREADS}, found {t}")));
    }
    let jobs = expand(&campaign, RunnerTag::Design);
    let dir = campaign_dir(&results, &campaign.name);
    std::fs::create_dir_all(&dir).map_err(|e| failure(&format!("creating {}", dir.display()), e))?;
    let opts = ExecuteOptions::new(&campaign.name, campaign.threads(threads));
    let cancel = opts.cancel.clone();
    let lines: Arc<Mutex<Vec<String>>> = Arc::default();
    let shown = Arc::clone(&lines);
    let show = |py: Python<'_>, _done: bool| -> PyResult<()> {
        let pending = shown.lock().map(|mut l| std::mem::take(&mut *l)).unwrap_or_default();
        if pending.is_empty() {
            return Ok(());
        }
        let stderr = py.import("sys")?.getattr("stderr")?;
        for line in pending {
            stderr.call_method1("write", (line + "\n",))?;
        }
        stderr.call_method0("flush")?;
        Ok(())
    };
    let summary = run_interruptible_with(
        py,
        cancel,
        |_| -> Result<Value, String> {
            let observers = trace_observers(&dir.join("traces"), campaign.trace_levels(None));
            let mut reporter = Reporter::new(&jobs, ProgressDisplay::Collect);
            let on_event = |ev: &_| {
                if progress {
                    reporter.on_event(ev);
                    if let Ok(mut l) = lines.lock() {
                        l.extend(reporter.take_lines());
                    }
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
        },
        show,
    )?
    .map_err(|e| failure("run_campaign", e))?;
    Ok(summary.to_string())
}

/// Every record of the journals (`runs*.jsonl`) of the results folder `folder`, as JSON `{"records":
/// [...], "warnings": [...]}`: the journal lines (in the crate's record format), journals in name
/// order, lines in file order; a torn last line is left out with the warning `campaign report`
/// prints. A folder without journals gives no records; a results root (a folder whose
/// sub-folders hold journals, `results/`) is a `ValueError` naming the campaign folders in it.
#[pyfunction]
pub fn read_results(folder: PathBuf) -> PyResult<String> {
    if !folder.is_dir() {
        return Err(bad_input("read_results", format!("{} is not a folder", folder.display())));
    }
    let journals = journals_in(&folder).map_err(|e| failure("read_results", e))?;
    if journals.is_empty() {
        let campaigns = campaign_folders(&folder);
        if !campaigns.is_empty() {
            let first = folder.join(&campaigns[0]);
            return Err(bad_input(
                "read_results",
                format!(
                    "{} is a results root, not a campaign's folder: it holds {} (read one of them, e.g. read_results({:?}))",
                    folder.display(),
                    campaigns.join(", "),
                    first.display().to_string()
                ),
            ));
        }
    }
    let mut records = Vec::new();
    let mut warnings = Vec::new();
    for j in &journals {
        let read = read_journal(j).map_err(|e| failure("read_results", e))?;
        if let Some(t) = &read.torn {
            warnings.push(format!("{}: line {} is torn ({}); ignored", j.display(), t.line, t.reason));
        }
        records.extend(read.records);
    }
    serde_json::to_string(&json!({"records": records, "warnings": warnings})).map_err(|e| failure("read_results", e))
}

/// The sub-folders of `root` that hold a journal, sorted by name.
fn campaign_folders(root: &Path) -> Vec<String> {
    let Ok(entries) = std::fs::read_dir(root) else { return Vec::new() };
    let mut names: Vec<String> = entries
        .flatten()
        .filter(|e| e.path().is_dir() && journals_in(&e.path()).is_ok_and(|j| !j.is_empty()))
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}
