//! Running a campaign end to end, resumably: read the journal (repairing a torn tail), skip the
//! jobs it already holds, execute the rest with [`scheduler::execute`], and append each finished
//! job's record to the journal the moment its event arrives. Display is not done here: every
//! event is handed on to the caller's consumer (the progress reporter).
//!
//! Warm-start chains work across runs: the scheduler receives the journal's records, so a job
//! whose predecessor finished in an earlier (interrupted) run starts from that controller.
//!
//! A failing journal write stops the run (the scheduler cancels in-flight jobs); it is the one
//! error that must not be swallowed, since a result that is not journaled is lost.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

use super::jobs::{Job, JobId};
use super::journal::{JournalError, JournalWriter, TornTail, JOURNAL_FILE};
use super::record::JobRecord;
use super::scheduler::{self, CampaignEvent, ExecuteError, ExecuteOptions, JobRunner, ObserverFactory, RunStats};

/// The results folder of campaign `name` under `results_root` (`results/<name>/`).
pub fn campaign_dir(results_root: &Path, name: &str) -> PathBuf {
    results_root.join(name)
}

/// The journal of a campaign folder.
pub fn journal_path(campaign_dir: &Path) -> PathBuf {
    campaign_dir.join(JOURNAL_FILE)
}

/// A campaign run that could not go on.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The journal could not be read or appended to.
    #[error(transparent)]
    Journal(#[from] JournalError),
    /// The worker pool could not be started.
    #[error("cannot start the worker pool: {0}")]
    Pool(#[from] rayon::ThreadPoolBuildError),
}

/// What a run did.
#[derive(Debug, Clone)]
pub struct RunOutcome {
    /// The scheduler's counts.
    pub stats: RunStats,
    /// The torn journal line found (and cut off) before the run, if any.
    pub torn: Option<TornTail>,
    /// The journal.
    pub journal: PathBuf,
    /// The records of this campaign's jobs after the run, in job order.
    pub records: Vec<JobRecord>,
}

impl RunOutcome {
    /// Whether the run was stopped by an interrupt.
    pub fn interrupted(&self) -> bool {
        self.stats.cancel == Some(scheduler::CancelReason::Interrupt)
    }

    /// Number of this campaign's journaled jobs that failed (this run or earlier ones).
    pub fn failed(&self) -> usize {
        self.records.iter().filter(|r| r.failed()).count()
    }
}

/// The journal's records keyed by job id (the first record of an id wins; there is normally
/// only one).
pub fn records_by_id(records: Vec<JobRecord>) -> HashMap<JobId, JobRecord> {
    let mut map = HashMap::with_capacity(records.len());
    for r in records {
        map.entry(r.job_id.clone()).or_insert(r);
    }
    map
}

/// The records of `jobs`, in job order (jobs without a record are left out).
pub fn records_of_jobs(jobs: &[Job], by_id: &HashMap<JobId, JobRecord>) -> Vec<JobRecord> {
    jobs.iter().filter_map(|j| by_id.get(&j.id).cloned()).collect()
}

/// Runs (or resumes) `jobs` with results in `dir` (created if needed). Every scheduler event
/// is passed to `on_event` after the journal has handled it.
pub fn run_jobs(
    jobs: &[Job],
    dir: &Path,
    runner: &dyn JobRunner,
    observers: &ObserverFactory<'_>,
    opts: &ExecuteOptions,
    mut on_event: impl FnMut(&CampaignEvent),
) -> Result<RunOutcome, RunError> {
    let path = journal_path(dir);
    let (mut writer, read) = JournalWriter::open(&path)?;
    let wanted: HashSet<&JobId> = jobs.iter().map(|j| &j.id).collect();
    let mut by_id = records_by_id(read.records);
    by_id.retain(|id, _| wanted.contains(id));

    let mut new_records = Vec::new();
    let result = scheduler::execute(jobs, &by_id, runner, observers, opts, |ev| {
        let written = match &ev {
            CampaignEvent::JobFinished { record, .. } => {
                let w = writer.append(record);
                if w.is_ok() {
                    new_records.push((**record).clone());
                }
                w
            }
            _ => Ok(()),
        };
        on_event(&ev);
        written
    });
    let stats = match result {
        Ok(s) => s,
        Err(ExecuteError::Pool(e)) => return Err(RunError::Pool(e)),
        Err(ExecuteError::Callback(e)) => return Err(RunError::Journal(e)),
    };
    for r in new_records {
        by_id.entry(r.job_id.clone()).or_insert(r);
    }
    Ok(RunOutcome { stats, torn: read.torn, journal: path, records: records_of_jobs(jobs, &by_id) })
}
