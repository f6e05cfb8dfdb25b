//! Running a campaign end to end, resumably: read the journal (repairing a torn tail), skip the
//! jobs it already holds, execute the rest with [`scheduler::execute`], and append each finished
//! job's record to the journal the moment its event arrives. Display is not done here: every
//! event is handed on to the caller's consumer (the progress reporter).
//!
//! Warm-start chains work across runs: the scheduler receives the journal's records, so a job
//! whose predecessor finished in an earlier (interrupted) run starts from that controller.
//!
//! Any number of processes may run the same campaign into the same folder at once (on one
//! machine, or on several sharing the folder over NFS): see [`SharedFolder`] and module
//! `claims`.
//!
//! A failing journal write stops the run (the scheduler cancels in-flight jobs); it is the one
//! error that must not be swallowed, since a result that is not journaled is lost.

use std::collections::{HashMap, HashSet};
use std::path::{Path, PathBuf};

use super::scheduler::{
    self, CampaignEvent, Claim, Coordinator, ExecuteError, ExecuteOptions, JobRunner, ObserverFactory, RunStats,
};
use crate::campaign::model::jobs::{Job, JobId};
use crate::campaign::records::claims::{ClaimDir, ClaimError, ClaimGuard, ClaimOwner, TryClaim};
use crate::campaign::records::journal::{journals_in, Follower, JournalError, JournalWriter, TornTail, JOURNAL_FILE};
use crate::campaign::records::record::JobRecord;

/// The results folder of campaign `name` under `results_root` (`results/<name>/`).
pub fn campaign_dir(results_root: &Path, name: &str) -> PathBuf {
    results_root.join(name)
}

/// The first journal of a campaign folder (`runs.jsonl`; concurrent runs add `runs.<k>.jsonl`).
pub fn journal_path(campaign_dir: &Path) -> PathBuf {
    campaign_dir.join(JOURNAL_FILE)
}

/// A campaign run that could not go on.
#[derive(Debug, thiserror::Error)]
pub enum RunError {
    /// The journal could not be read or appended to.
    #[error(transparent)]
    Journal(#[from] JournalError),
    /// A job could not be claimed.
    #[error("cannot claim a job: {0}")]
    Claim(#[from] ClaimError),
    /// The worker pool could not be started.
    #[error("cannot start the worker pool: {0}")]
    Pool(#[from] rayon::ThreadPoolBuildError),
}

/// What a run did.
#[derive(Debug, Clone)]
pub struct RunOutcome {
    /// The scheduler's counts.
    pub stats: RunStats,
    /// The torn line found (and cut off) in this run's journal before the run, if any.
    pub torn: Option<TornTail>,
    /// Torn last lines of other journals of the folder (writers that died mid-line and whose
    /// journal is still held, or that could not be repaired).
    pub torn_elsewhere: Vec<(PathBuf, TornTail)>,
    /// This run's journal.
    pub journal: PathBuf,
    /// Every record of the folder's journals after the run (all campaigns' jobs, duplicates
    /// included), this run's new ones last.
    pub records: Vec<JobRecord>,
    /// Jobs of this run's job list whose records all say `failed`.
    pub jobs_failed: usize,
}

impl RunOutcome {
    /// Whether the run was stopped by an interrupt.
    pub fn interrupted(&self) -> bool {
        self.stats.cancel == Some(scheduler::CancelReason::Interrupt)
    }

    /// Number of this run's journaled jobs that failed (this run or earlier ones, any process).
    pub fn failed(&self) -> usize {
        self.jobs_failed
    }
}

/// The records keyed by job id (the first record of an id wins; reports choose among
/// duplicates by re-verification, see `reduce`).
pub fn records_by_id(records: Vec<JobRecord>) -> HashMap<JobId, JobRecord> {
    let mut map = HashMap::with_capacity(records.len());
    for r in records {
        map.entry(r.job_id.clone()).or_insert(r);
    }
    map
}

/// Every record (duplicates included) whose job is one of `jobs` and that agrees with it
/// (`disagreement`; a record carrying a job's id but not its plant, order, ε, seed or
/// objective is left out: [`records_and_disagreements`] also names them).
pub fn records_for(jobs: &[Job], records: &[JobRecord]) -> Vec<JobRecord> {
    records_and_disagreements(jobs, records).0
}

/// [`records_for`], and the records that carry the id of one of `jobs` but disagree with it, each
/// with the field that differs ("job 6d7025f7: eps 0.5 in the record, 1e-6 in the campaign").
pub fn records_and_disagreements(jobs: &[Job], records: &[JobRecord]) -> (Vec<JobRecord>, Vec<String>) {
    let wanted: HashMap<&JobId, &Job> = jobs.iter().map(|j| (&j.id, j)).collect();
    let (mut kept, mut disagreeing) = (Vec::new(), Vec::new());
    for r in records {
        let Some(job) = wanted.get(&r.job_id) else { continue };
        match disagreement(job, r) {
            None => kept.push(r.clone()),
            Some(why) => disagreeing.push(format!("job {}: {why}", &r.job_id.0[..r.job_id.0.len().min(8)])),
        }
    }
    (kept, disagreeing)
}

/// Why the record `r` is not the record of `job` although it carries its id: the first of its
/// identifying fields (those the id is made of) that differs, or `None`. The id names the job;
/// a hand-edited or damaged line that says otherwise was reported under a plant, order, ε or
/// seed the campaign never ran.
pub fn disagreement(job: &Job, r: &JobRecord) -> Option<String> {
    let o = &job.options;
    let differs =
        |what: &str, rec: String, camp: String| Some(format!("{what} {rec} in the record, {camp} in the campaign"));
    if r.plant_fingerprint != job.plant_fingerprint {
        return differs("plant fingerprint", r.plant_fingerprint.clone(), job.plant_fingerprint.clone());
    }
    if r.order != o.order || r.options.order != o.order {
        return differs("order", r.order.to_string(), o.order.to_string());
    }
    if r.eps.to_bits() != o.eps.to_bits() || r.options.eps.to_bits() != o.eps.to_bits() {
        return differs("eps", r.eps.to_string(), o.eps.to_string());
    }
    if r.seed != o.seed || r.options.seed != o.seed {
        return differs("seed", r.seed.to_string(), o.seed.to_string());
    }
    if r.options.objective != o.objective {
        return differs("objective", r.options.objective.name().into(), o.objective.name().into());
    }
    None
}

/// Job ids with more than one record, with their counts (sorted by id).
pub fn duplicate_ids(records: &[JobRecord]) -> Vec<(JobId, usize)> {
    let mut counts: std::collections::BTreeMap<&JobId, usize> = std::collections::BTreeMap::new();
    for r in records {
        *counts.entry(&r.job_id).or_default() += 1;
    }
    counts.into_iter().filter(|(_, n)| *n > 1).map(|(id, n)| (id.clone(), n)).collect()
}

/// The coordinator of a run sharing its results folder with other processes: claims
/// (`claims/`) and the other processes' journals (followed incrementally). See `claims` for
/// the protocol.
pub struct SharedFolder {
    claims: ClaimDir,
    follower: Follower,
    owner: ClaimOwner,
    held: HashMap<JobId, ClaimGuard>,
    seen: HashSet<JobId>,
    unpolled: Vec<JobRecord>,
    read: Vec<JobRecord>,
}

impl SharedFolder {
    /// The coordinator of a run writing `own_journal` in results folder `dir`.
    pub fn new(dir: &Path, own_journal: &Path) -> SharedFolder {
        SharedFolder {
            claims: ClaimDir::new(dir),
            follower: Follower::new(vec![dir.to_path_buf()], Vec::new(), Some(own_journal.to_path_buf())),
            owner: ClaimOwner::this_process(own_journal),
            held: HashMap::new(),
            seen: HashSet::new(),
            unpolled: Vec::new(),
            read: Vec::new(),
        }
    }

    /// Reads what the other journals gained; new records are kept for the next poll.
    fn follow(&mut self) -> Result<(), JournalError> {
        for r in self.follower.poll()? {
            self.seen.insert(r.job_id.clone());
            self.read.push(r.clone());
            self.unpolled.push(r);
        }
        Ok(())
    }
}

impl Coordinator<RunError> for SharedFolder {
    fn claim(&mut self, job: &Job) -> Result<Claim, RunError> {
        self.owner.since_unix_s = crate::campaign::records::claims::unix_now();
        let guard = match self.claims.try_claim(&job.id, job.options.cpumax, &self.owner)? {
            TryClaim::Busy => return Ok(Claim::Busy),
            TryClaim::Claimed(g) => g,
        };
        // Claimed: but it may have finished just before (claim → check → run → journal → release).
        if let Err(e) = self.follow() {
            guard.release();
            return Err(e.into());
        }
        if self.seen.contains(&job.id) {
            guard.release();
            return Ok(Claim::Done);
        }
        self.held.insert(job.id.clone(), guard);
        Ok(Claim::Mine)
    }

    fn release(&mut self, job: &Job) {
        if let Some(g) = self.held.remove(&job.id) {
            g.release();
        }
    }

    fn poll(&mut self) -> Result<Vec<JobRecord>, RunError> {
        self.follow()?;
        Ok(std::mem::take(&mut self.unpolled))
    }
}

/// Runs (or resumes) `jobs` with results in `dir` (created if needed), cooperating with any
/// other process doing the same (module `claims`): this process appends to a journal of its
/// own (`JournalWriter::open_in`), claims each job before running it and skips jobs journaled
/// elsewhere. Every scheduler event is passed to `on_event` after the journal has handled it.
pub fn run_jobs(
    jobs: &[Job],
    dir: &Path,
    runner: &dyn JobRunner,
    observers: &ObserverFactory<'_>,
    opts: &ExecuteOptions,
    mut on_event: impl FnMut(&CampaignEvent),
) -> Result<RunOutcome, RunError> {
    let (mut writer, read) = JournalWriter::open_in(dir)?;
    let own = writer.path().to_path_buf();
    // Journals left by processes that died mid-line: whoever can lock one repairs it.
    for other in journals_in(dir)? {
        if other != own {
            match JournalWriter::open(&other) {
                Ok(_) | Err(JournalError::Busy { .. }) => {}
                Err(e) => return Err(e.into()),
            }
        }
    }
    let mut coord = SharedFolder::new(dir, &own);
    coord.follow()?;
    coord.unpolled.clear();
    let wanted: HashSet<&JobId> = jobs.iter().map(|j| &j.id).collect();
    let mut by_id = records_by_id(read.records.iter().chain(&coord.read).cloned().collect());
    by_id.retain(|id, _| wanted.contains(id));

    let mut new_records = Vec::new();
    let result = scheduler::execute(jobs, &by_id, runner, observers, &mut coord, opts, |ev| {
        let written = match &ev {
            CampaignEvent::JobFinished { record, .. } => {
                let w = writer.append(record);
                if w.is_ok() {
                    new_records.push((**record).clone());
                }
                w.map_err(RunError::from)
            }
            _ => Ok(()),
        };
        on_event(&ev);
        written
    });
    let stats = match result {
        Ok(s) => s,
        Err(ExecuteError::Pool(e)) => return Err(RunError::Pool(e)),
        Err(ExecuteError::Callback(e)) => return Err(e),
    };
    coord.follow()?;
    let mut records = read.records;
    records.append(&mut coord.read);
    records.extend(new_records);
    let mut ok: HashMap<&JobId, bool> = HashMap::new();
    for r in records.iter().filter(|r| wanted.contains(&r.job_id)) {
        *ok.entry(&r.job_id).or_default() |= !r.failed();
    }
    let jobs_failed = ok.values().filter(|ok| !**ok).count();
    Ok(RunOutcome { stats, torn: read.torn, torn_elsewhere: coord.follower.torn(), journal: own, records, jobs_failed })
}
