//! `campaign status` as data: how far a campaign is (per plant, the jobs being run and by whom,
//! claims left by dead processes, jobs journaled more than once), and the shard plan of
//! `--shards N`. The command line (`cli/campaign.rs`) only prints these.

use std::collections::{HashMap, HashSet};
use std::path::Path;

use super::reduce::plant_labels;
use crate::campaign::execution::run::duplicate_ids;
use crate::campaign::model::jobs::{Job, JobId};
use crate::campaign::records::claims::{ClaimDir, ClaimError, ClaimOwner};
use crate::campaign::records::record::JobRecord;
use crate::campaign::records::shard;

/// The jobs of one plant (or of the whole campaign, [`CampaignStatus::total`]).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct PlantStatus {
    /// The plant's label (its name, made unique by content fingerprint when names clash).
    pub plant: String,
    /// Its jobs in the campaign.
    pub jobs: usize,
    /// Jobs with a record (failed ones included).
    pub done: usize,
    /// Jobs without a record whose claim a live process holds.
    pub running: usize,
    /// Jobs whose every record failed.
    pub failed: usize,
}

impl PlantStatus {
    /// Jobs neither done nor running.
    pub fn remaining(&self) -> usize {
        self.jobs - self.done - self.running
    }
}

/// A job being run by a live process.
#[derive(Debug, Clone, PartialEq)]
pub struct RunningJob {
    /// The job.
    pub id: JobId,
    /// Its label (plant, order, ε, seed).
    pub label: String,
    /// Who runs it (`None`: the claim's owner is not written yet).
    pub owner: Option<ClaimOwner>,
}

/// A job with more than one record.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct DuplicateJob {
    /// The job.
    pub id: JobId,
    /// Its label, when it is a job of the campaign.
    pub label: Option<String>,
    /// How many records it has.
    pub records: usize,
}

/// What `campaign status` shows.
#[derive(Debug, Clone, PartialEq)]
pub struct CampaignStatus {
    /// Per plant, in campaign order.
    pub plants: Vec<PlantStatus>,
    /// The jobs being run, in campaign order.
    pub running: Vec<RunningJob>,
    /// Claims left by processes that died (their jobs run again at the next `campaign run`).
    pub stale_claims: usize,
    /// Jobs journaled more than once (sorted by id).
    pub duplicates: Vec<DuplicateJob>,
}

impl CampaignStatus {
    /// The sums over the plants, labelled `total`.
    pub fn total(&self) -> PlantStatus {
        self.plants.iter().fold(PlantStatus { plant: "total".into(), ..PlantStatus::default() }, |t, p| PlantStatus {
            jobs: t.jobs + p.jobs,
            done: t.done + p.done,
            running: t.running + p.running,
            failed: t.failed + p.failed,
            ..t
        })
    }
}

/// The status of `jobs` given their `records` (duplicates included) and the claims in the
/// results folder `dir`.
pub fn status(jobs: &[Job], records: &[JobRecord], dir: &Path) -> Result<CampaignStatus, ClaimError> {
    // job id → whether some record of it did not fail
    let mut done: HashMap<&JobId, bool> = HashMap::new();
    for r in records {
        *done.entry(&r.job_id).or_default() |= !r.failed();
    }
    let claims = ClaimDir::new(dir).list()?;
    let index: HashMap<&JobId, &Job> = jobs.iter().map(|j| (&j.id, j)).collect();
    let running: HashMap<&JobId, _> = claims
        .iter()
        .filter(|c| c.held && !done.contains_key(&c.job))
        .filter_map(|c| index.get(&c.job).map(|j| (&j.id, c)))
        .collect();
    let labels = plant_labels(jobs.iter().map(|j| (j.plant_fingerprint.as_str(), j.plant_name.as_str())));
    // plants by fingerprint, in campaign order
    let mut plants: Vec<PlantStatus> = Vec::new();
    for j in jobs {
        let label = &labels[&j.plant_fingerprint];
        let i = match plants.iter().position(|p| &p.plant == label) {
            Some(i) => i,
            None => {
                plants.push(PlantStatus { plant: label.clone(), ..PlantStatus::default() });
                plants.len() - 1
            }
        };
        let p = &mut plants[i];
        p.jobs += 1;
        if let Some(ok) = done.get(&j.id) {
            p.done += 1;
            p.failed += !ok as usize;
        } else if running.contains_key(&j.id) {
            p.running += 1;
        }
    }
    let running_jobs = jobs
        .iter()
        .filter_map(|j| {
            running.get(&j.id).map(|c| RunningJob { id: j.id.clone(), label: j.label(), owner: c.owner.clone() })
        })
        .collect();
    let stale_claims = claims.iter().filter(|c| !c.held && !done.contains_key(&c.job)).count();
    let duplicates = duplicate_ids(records)
        .into_iter()
        .map(|(id, n)| DuplicateJob { label: index.get(&id).map(|j| j.label()), id, records: n })
        .collect();
    Ok(CampaignStatus { plants, running: running_jobs, stale_claims, duplicates })
}

/// One shard of [`shard_plan`].
#[derive(Debug, Clone, PartialEq)]
pub struct ShardLoad {
    /// Its jobs.
    pub jobs: usize,
    /// The sum of their `cpumax` (CPU seconds).
    pub cpu_s: f64,
    /// A bound on its wall time (seconds) at the plan's threads.
    pub wall_bound_s: f64,
}

/// How `--shard K/N` splits the jobs: per shard, its jobs left to run (those not in `done`, the
/// journaled ones, which `campaign run` skips), their CPU budget and a wall-time bound by list
/// scheduling on `threads` workers: Σ cpumax / threads + its longest chain of jobs left to run
/// that wait for others (warm start, order chaining; Graham's bound; jobs stop at their CPU
/// budget, and a worker thread gets a CPU to itself). The shards are those of every job, as
/// `run --shard` takes them.
pub fn shard_plan(jobs: &[Job], n: usize, threads: usize, done: &HashSet<&JobId>) -> Vec<ShardLoad> {
    let assign = shard::assign(jobs, n);
    let index: HashMap<_, _> = jobs.iter().enumerate().map(|(i, j)| (&j.id, i)).collect();
    let left = |i: usize| !done.contains(&jobs[i].id);
    let budget = |i: usize| if left(i) { jobs[i].options.cpumax } else { 0.0 };
    // budget of the chain up to and including each job
    let mut chain = vec![0.0f64; jobs.len()];
    for (i, j) in jobs.iter().enumerate() {
        let before = j.predecessors().filter_map(|p| index.get(p)).map(|&p| chain[p]).fold(0.0, f64::max);
        chain[i] = before + budget(i);
    }
    (0..n)
        .map(|k| {
            let mine: Vec<usize> = (0..jobs.len()).filter(|&i| assign[i] == k && left(i)).collect();
            // + 0.0: an empty `sum` of f64 is −0 (printed "-0 s"), and −0 + 0 is +0
            let cpu_s = mine.iter().map(|&i| budget(i)).sum::<f64>() + 0.0;
            let longest = mine.iter().map(|&i| chain[i]).fold(0.0, f64::max);
            ShardLoad { jobs: mine.len(), cpu_s, wall_bound_s: cpu_s / threads as f64 + longest }
        })
        .collect()
}
