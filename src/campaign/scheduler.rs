//! The scheduler: runs jobs on a local rayon pool and reports [`CampaignEvent`]s to one
//! callback on the calling thread. It never prints or writes (nextest's split; docs/ARCHITECTURE.md §2); the
//! journal, traces and progress display are consumers.
//!
//! * The job runner is injected ([`JobRunner`]): production passes [`DesignRunner`]
//!   (`design::run`), tests pass fast fakes.
//! * Per-job observers (the trace writer) are made by an injected [`ObserverFactory`] on the
//!   worker that runs the job.
//! * Warm-start chains: a job whose `warm_from` predecessor has not finished is not started; its
//!   initial controller is the predecessor's (from this run or from the journal).
//! * Cancellation: when `cancel` becomes true (first Ctrl-C, or a failing callback), nothing new
//!   is scheduled and every in-flight job's observer returns `Break`, so `design::run` stops with
//!   status `Interrupted`; such jobs produce [`CampaignEvent::JobInterrupted`] and no record, so a
//!   resumed run reruns them.
//! * Workers send events over one `std::sync::mpsc` channel; the calling thread owns the callback.
//! * Other processes on the same jobs: an injected [`Coordinator`] is asked to claim each job
//!   before it starts (a job claimed elsewhere is skipped for [`BUSY_RETRY`] and tried again),
//!   told when it ended, and polled every `poll_interval` for records journaled elsewhere (those
//!   jobs are dropped from the queue, their controllers feed warm starts). When nothing runs here
//!   and nothing left can be claimed, the run ends: the remaining jobs are being run by other
//!   processes (or wait for a predecessor that is). [`Solo`] is the coordinator of a lone run.

use std::collections::{HashMap, VecDeque};
use std::ops::ControlFlow;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::sync::Arc;
use std::time::{Duration, Instant};

use super::jobs::{Job, JobId};
use super::provenance::Provenance;
use super::record::JobRecord;
use crate::design::{DesignError, DesignIterRecord, DesignObserver, DesignOutcome, Phase};
use crate::lti::Controller;
use crate::optim::thread_cpu_time;

/// Runs one job. Production: [`DesignRunner`]; tests: closures.
pub trait JobRunner: Sync {
    /// Runs `job` from `init` (warm start) or from scratch, reporting iterations to `obs`.
    fn run(
        &self,
        job: &Job,
        init: Option<&Controller>,
        obs: &mut dyn DesignObserver,
    ) -> Result<DesignOutcome, DesignError>;
}

impl<F> JobRunner for F
where
    F: Fn(&Job, Option<&Controller>, &mut dyn DesignObserver) -> Result<DesignOutcome, DesignError> + Sync,
{
    fn run(
        &self,
        job: &Job,
        init: Option<&Controller>,
        obs: &mut dyn DesignObserver,
    ) -> Result<DesignOutcome, DesignError> {
        self(job, init, obs)
    }
}

/// The production runner: [`crate::design::run`] with the job's plant and options.
pub struct DesignRunner;

impl JobRunner for DesignRunner {
    fn run(
        &self,
        job: &Job,
        init: Option<&Controller>,
        obs: &mut dyn DesignObserver,
    ) -> Result<DesignOutcome, DesignError> {
        crate::design::run(&job.plant, &job.options, init, obs)
    }
}

/// What [`Coordinator::claim`] found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Claim {
    /// The job is ours to run.
    Mine,
    /// Another process is running it.
    Busy,
    /// Another process has finished it (its record comes with the next [`Coordinator::poll`]).
    Done,
}

/// Coordination with other processes working on the same jobs (see the module docs). Errors
/// stop the run like a failing callback.
pub trait Coordinator<E> {
    /// Claims `job` before it starts.
    fn claim(&mut self, job: &Job) -> Result<Claim, E>;
    /// `job` (claimed) ended: its record, if any, has been handed to the callback.
    fn release(&mut self, job: &Job);
    /// Records finished elsewhere since the last poll.
    fn poll(&mut self) -> Result<Vec<JobRecord>, E>;
}

/// A run alone on its jobs: every claim succeeds, nothing happens elsewhere.
#[derive(Debug, Clone, Copy, Default)]
pub struct Solo;

impl<E> Coordinator<E> for Solo {
    fn claim(&mut self, _job: &Job) -> Result<Claim, E> {
        Ok(Claim::Mine)
    }
    fn release(&mut self, _job: &Job) {}
    fn poll(&mut self) -> Result<Vec<JobRecord>, E> {
        Ok(Vec::new())
    }
}

/// How long a job found claimed elsewhere is left alone before it is tried again.
pub const BUSY_RETRY: Duration = Duration::from_secs(5);

/// Watches one job on its worker (the trace writer is one).
pub trait JobObserver: Send {
    /// Called once per optimiser iteration; `Break` stops the job (status `Interrupted`).
    fn on_iter(&mut self, _rec: &DesignIterRecord) -> ControlFlow<()> {
        ControlFlow::Continue(())
    }
    /// The job finished with `record` (which is journaled next). An error becomes a warning.
    fn finish(self: Box<Self>, _record: &JobRecord) -> Result<(), ObserverError> {
        Ok(())
    }
    /// The job was interrupted: nothing will be journaled.
    fn abandon(self: Box<Self>) {}
}

/// Makes the observer of a job (called on the worker). An error — or a panic of the factory —
/// becomes a [`CampaignEvent::Warning`] of the job, which then runs unobserved.
pub type ObserverFactory<'a> = dyn Fn(&Job) -> Result<Box<dyn JobObserver>, ObserverError> + Sync + 'a;

/// Why a job's observer could not be made or finished. Reported as a warning; never fails the
/// job.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ObserverError {
    /// The observer's own error (e.g. a `TraceError` naming the trace file), kept with its
    /// `source` chain; its message is the warning's.
    #[error(transparent)]
    Failed(Box<dyn std::error::Error + Send + Sync>),
    /// The observer factory panicked (the scheduler catches it).
    #[error("the job's observer could not be made (panic: {0}); the job runs unobserved")]
    FactoryPanicked(String),
}

impl ObserverError {
    /// Wraps an observer's error.
    pub fn failed(e: impl std::error::Error + Send + Sync + 'static) -> Self {
        ObserverError::Failed(Box::new(e))
    }
}

/// A factory that observes nothing.
pub fn no_observers(_: &Job) -> Result<Box<dyn JobObserver>, ObserverError> {
    struct Nothing;
    impl JobObserver for Nothing {}
    Ok(Box::new(Nothing))
}

/// Why scheduling stopped early; ordered by severity.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum CancelReason {
    /// The event callback or the coordinator failed (e.g. the journal could not be written).
    CallbackError,
    /// The cancel flag was set (Ctrl-C).
    Interrupt,
}

impl CancelReason {
    /// Why the run stops, in words for the user (the error itself follows from the caller).
    pub fn describe(self) -> &'static str {
        match self {
            CancelReason::CallbackError => "after an error, shown at the end",
            CancelReason::Interrupt => "interrupted",
        }
    }
}

/// Counts of one `execute` call.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct RunStats {
    /// Jobs of the campaign.
    pub total: usize,
    /// Already in the journal before this run (skipped).
    pub already_done: usize,
    /// Finished in this run (journaled), failures included.
    pub finished: usize,
    /// Of those, failed (`design::run` error or panic).
    pub failed: usize,
    /// Finished meanwhile by other processes (found in their journals).
    pub done_elsewhere: usize,
    /// Stopped in flight by a cancel (not journaled).
    pub interrupted: usize,
    /// Never started (without a cancel: claimed by other processes, or behind such a job).
    pub not_started: usize,
    /// Why scheduling stopped early, if it did.
    pub cancel: Option<CancelReason>,
    /// Warnings of jobs (an observer that failed, e.g. a trace that could not be written on a
    /// full disk): the job's result is journaled, what the observer wrote is lost.
    pub warnings: usize,
}

/// What the scheduler reports. Jobs are named by their index in the `jobs` slice.
#[derive(Debug, Clone)]
pub enum CampaignEvent {
    /// Before anything runs.
    Started {
        /// Jobs of the campaign.
        total: usize,
        /// Already journaled.
        already_done: usize,
        /// To run now.
        to_run: usize,
        /// Worker threads.
        threads: usize,
    },
    /// A job started on a worker.
    JobStarted {
        /// Job index.
        index: usize,
        /// Worker slot (0..threads).
        worker: usize,
        /// Whether it starts from its predecessor's controller.
        warm: bool,
    },
    /// A job made progress (throttled).
    JobProgress {
        /// Job index.
        index: usize,
        /// Worker slot.
        worker: usize,
        /// Current phase.
        phase: Phase,
        /// Iteration within the phase and start.
        iter: usize,
        /// Objective value.
        f: f64,
        /// ‖Tzw‖∞ at the iterate (NaN while stabilising).
        gamma: f64,
    },
    /// A job finished: its record is to be journaled.
    JobFinished {
        /// Job index.
        index: usize,
        /// Worker slot.
        worker: usize,
        /// The record.
        record: Box<JobRecord>,
    },
    /// Another process finished a job that was still queued here.
    JobDoneElsewhere {
        /// Job index.
        index: usize,
    },
    /// A job was stopped by a cancel; nothing is journaled.
    JobInterrupted {
        /// Job index.
        index: usize,
        /// Worker slot.
        worker: usize,
    },
    /// Something worth telling that does not stop the run (e.g. a trace could not be written).
    Warning {
        /// Job concerned, if any.
        index: Option<usize>,
        /// What happened.
        message: String,
    },
    /// Scheduling stops; in-flight jobs are being cancelled.
    CancelRequested {
        /// Why.
        reason: CancelReason,
    },
    /// Everything has stopped.
    Finished {
        /// Counts.
        stats: RunStats,
    },
}

/// Settings of one `execute` call.
pub struct ExecuteOptions {
    /// Worker threads (≥ 1).
    pub threads: usize,
    /// Campaign name (written into records).
    pub campaign: String,
    /// Set to cancel (Ctrl-C handler, tests). The scheduler also sets it when the callback fails.
    pub cancel: Arc<AtomicBool>,
    /// Minimum time between two progress events of one job.
    pub progress_interval: Duration,
    /// Time between two [`Coordinator::poll`]s (claims re-read the journals anyway; polling only
    /// drops jobs finished elsewhere from the queue sooner).
    pub poll_interval: Duration,
    /// Written into every record.
    pub provenance: Provenance,
}

impl ExecuteOptions {
    /// `threads` workers, a fresh cancel flag, progress every 200 ms.
    pub fn new(campaign: &str, threads: usize) -> Self {
        ExecuteOptions {
            threads: threads.max(1),
            campaign: campaign.to_string(),
            cancel: Arc::new(AtomicBool::new(false)),
            progress_interval: Duration::from_millis(200),
            poll_interval: Duration::from_secs(5),
            provenance: Provenance::here(threads.max(1)),
        }
    }
}

/// The scheduler could not run, or the callback failed.
#[derive(Debug, thiserror::Error)]
pub enum ExecuteError<E> {
    /// The thread pool could not be built.
    #[error("cannot start the worker pool: {0}")]
    Pool(#[from] rayon::ThreadPoolBuildError),
    /// The event callback failed (the first error; in-flight jobs were cancelled).
    #[error("{0}")]
    Callback(E),
}

enum WorkerMsg {
    Progress { index: usize, worker: usize, phase: Phase, iter: usize, f: f64, gamma: f64 },
    Warning { index: usize, message: String },
    Finished { index: usize, worker: usize, record: Box<JobRecord> },
    Interrupted { index: usize, worker: usize },
}

/// Runs every job of `jobs` that is not in `done` (the journals), respecting warm-start chains
/// and `coord`'s claims, and reports events to `on_event` on the calling thread. Returns the
/// counts, or the first callback or coordinator error (after cancelling and draining in-flight
/// jobs).
pub fn execute<E>(
    jobs: &[Job],
    done: &HashMap<JobId, JobRecord>,
    runner: &dyn JobRunner,
    observers: &ObserverFactory<'_>,
    coord: &mut dyn Coordinator<E>,
    opts: &ExecuteOptions,
    mut on_event: impl FnMut(CampaignEvent) -> Result<(), E>,
) -> Result<RunStats, ExecuteError<E>> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads)
        .thread_name(|i| format!("campaign-worker-{i}"))
        .build()?;
    let index_of: HashMap<&JobId, usize> = jobs.iter().enumerate().map(|(i, j)| (&j.id, i)).collect();
    // Controllers of finished jobs (journals + this run), for warm starts.
    let mut finished: HashMap<JobId, Option<Controller>> =
        done.iter().map(|(id, r)| (id.clone(), r.controller().cloned())).collect();
    let mut pending: VecDeque<usize> = (0..jobs.len()).filter(|&i| !done.contains_key(&jobs[i].id)).collect();
    let mut stats = RunStats { total: jobs.len(), already_done: jobs.len() - pending.len(), ..RunStats::default() };
    let mut first_err: Option<E> = None;
    // Hands an event to the callback (Ok) or takes a coordinator error (Err); the first error
    // of either kind cancels the run.
    let mut emit = |ev: Result<CampaignEvent, E>, first_err: &mut Option<E>, stats: &mut RunStats| {
        if let Err(e) = ev.and_then(&mut on_event) {
            if first_err.is_none() {
                *first_err = Some(e);
                opts.cancel.store(true, Ordering::SeqCst);
                if stats.cancel.is_none() {
                    stats.cancel = Some(CancelReason::CallbackError);
                    let _ = on_event(CampaignEvent::CancelRequested { reason: CancelReason::CallbackError });
                }
            }
        }
    };
    emit(
        Ok(CampaignEvent::Started {
            total: stats.total,
            already_done: stats.already_done,
            to_run: pending.len(),
            threads: opts.threads,
        }),
        &mut first_err,
        &mut stats,
    );

    let (tx, rx) = mpsc::channel::<WorkerMsg>();
    let mut free: Vec<usize> = (0..opts.threads).rev().collect();
    let mut running = 0usize;
    let campaign = opts.campaign.as_str();
    let cancel = &opts.cancel;
    let interval = opts.progress_interval;
    let provenance = &opts.provenance;
    // Jobs found claimed elsewhere, with when to try them again.
    let mut busy_until: HashMap<usize, Instant> = HashMap::new();
    let mut last_poll = Instant::now();
    let mut force_poll = false;
    // Set when nothing ran here and every claimable job was just retried: the next idle pass ends.
    let mut idle_sweep = false;

    pool.in_place_scope(|scope| loop {
        if cancel.load(Ordering::SeqCst) && stats.cancel.is_none() {
            stats.cancel = Some(CancelReason::Interrupt);
            emit(Ok(CampaignEvent::CancelRequested { reason: CancelReason::Interrupt }), &mut first_err, &mut stats);
        }
        if stats.cancel.is_none() && (force_poll || last_poll.elapsed() >= opts.poll_interval) {
            force_poll = false;
            last_poll = Instant::now();
            match coord.poll() {
                Ok(records) => {
                    for r in records {
                        if finished.contains_key(&r.job_id) {
                            continue;
                        }
                        let queued = index_of.get(&r.job_id).and_then(|i| pending.iter().position(|p| p == i));
                        finished.insert(r.job_id.clone(), r.controller().cloned());
                        if let Some(pos) = queued {
                            let index = pending.remove(pos).expect("position is in range");
                            stats.done_elsewhere += 1;
                            emit(Ok(CampaignEvent::JobDoneElsewhere { index }), &mut first_err, &mut stats);
                        }
                    }
                }
                Err(e) => emit(Err(e), &mut first_err, &mut stats),
            }
        }
        if stats.cancel.is_none() {
            let now = Instant::now();
            let mut skip = 0usize;
            while !free.is_empty() && stats.cancel.is_none() {
                let ready = pending.iter().skip(skip).position(|&i| {
                    busy_until.get(&i).is_none_or(|t| *t <= now)
                        && match &jobs[i].warm_from {
                            None => true,
                            Some(p) => finished.contains_key(p),
                        }
                });
                let Some(pos) = ready.map(|p| p + skip) else { break };
                let index = pending[pos];
                let job = &jobs[index];
                match coord.claim(job) {
                    Ok(Claim::Mine) => {}
                    Ok(Claim::Busy) => {
                        busy_until.insert(index, now + BUSY_RETRY);
                        skip = pos + 1;
                        continue;
                    }
                    Ok(Claim::Done) => {
                        // its record arrives with the poll at the top of the next pass
                        busy_until.insert(index, now + BUSY_RETRY);
                        force_poll = true;
                        skip = pos + 1;
                        continue;
                    }
                    Err(e) => {
                        emit(Err(e), &mut first_err, &mut stats);
                        break;
                    }
                }
                pending.remove(pos);
                busy_until.remove(&index);
                idle_sweep = false;
                let worker = free.pop().expect("a free worker");
                let init = job.warm_from.as_ref().and_then(|p| finished.get(p)).cloned().flatten();
                running += 1;
                emit(Ok(CampaignEvent::JobStarted { index, worker, warm: init.is_some() }), &mut first_err, &mut stats);
                let tx = tx.clone();
                scope.spawn(move |_| {
                    run_one(campaign, provenance, job, index, worker, init, runner, observers, cancel, interval, tx)
                });
            }
        }
        if running == 0 {
            // Nothing in flight here. Unless stopped or done, retry every job at once (claims
            // may have been dropped by processes that died, records may have arrived); if that
            // pass starts nothing either, the rest belongs to other processes.
            if stats.cancel.is_some() || pending.is_empty() || (idle_sweep && !force_poll) {
                break;
            }
            idle_sweep = true;
            busy_until.clear();
            force_poll = true;
            continue;
        }
        let msg = match rx.recv_timeout(Duration::from_millis(100)) {
            Ok(m) => m,
            Err(mpsc::RecvTimeoutError::Timeout) => continue,
            Err(mpsc::RecvTimeoutError::Disconnected) => unreachable!("the scheduler holds a sender"),
        };
        match msg {
            WorkerMsg::Progress { index, worker, phase, iter, f, gamma } => emit(
                Ok(CampaignEvent::JobProgress { index, worker, phase, iter, f, gamma }),
                &mut first_err,
                &mut stats,
            ),
            WorkerMsg::Warning { index, message } => {
                stats.warnings += 1;
                emit(Ok(CampaignEvent::Warning { index: Some(index), message }), &mut first_err, &mut stats)
            }
            WorkerMsg::Finished { index, worker, record } => {
                running -= 1;
                free.push(worker);
                stats.finished += 1;
                if record.failed() {
                    stats.failed += 1;
                }
                finished.insert(record.job_id.clone(), record.controller().cloned());
                emit(Ok(CampaignEvent::JobFinished { index, worker, record }), &mut first_err, &mut stats);
                // journaled (or the journal failed and the run stops): the claim can go
                coord.release(&jobs[index]);
            }
            WorkerMsg::Interrupted { index, worker } => {
                running -= 1;
                free.push(worker);
                stats.interrupted += 1;
                emit(Ok(CampaignEvent::JobInterrupted { index, worker }), &mut first_err, &mut stats);
                coord.release(&jobs[index]);
            }
        }
    });
    drop(tx);
    stats.not_started = pending.len();
    let final_stats = stats.clone();
    emit(Ok(CampaignEvent::Finished { stats: final_stats }), &mut first_err, &mut stats);
    match first_err {
        Some(e) => Err(ExecuteError::Callback(e)),
        None => Ok(stats),
    }
}

/// The observer a job actually runs with: the user's (trace), progress events, cancellation.
struct WorkerObserver<'a> {
    user: Option<Box<dyn JobObserver>>,
    cancel: &'a Arc<AtomicBool>,
    tx: &'a mpsc::Sender<WorkerMsg>,
    index: usize,
    worker: usize,
    interval: Duration,
    last_sent: Option<Instant>,
}

impl DesignObserver for WorkerObserver<'_> {
    fn on_iter(&mut self, rec: &DesignIterRecord) -> ControlFlow<()> {
        let user = match &mut self.user {
            Some(u) => u.on_iter(rec),
            None => ControlFlow::Continue(()),
        };
        if self.last_sent.is_none_or(|t| t.elapsed() >= self.interval) {
            self.last_sent = Some(Instant::now());
            let _ = self.tx.send(WorkerMsg::Progress {
                index: self.index,
                worker: self.worker,
                phase: rec.phase,
                iter: rec.iter,
                f: rec.f,
                gamma: rec.gamma,
            });
        }
        if self.cancel.load(Ordering::Relaxed) {
            return ControlFlow::Break(());
        }
        user
    }

    fn cancel_flag(&self) -> Option<Arc<AtomicBool>> {
        Some(Arc::clone(self.cancel))
    }
}

#[allow(clippy::too_many_arguments)]
fn run_one(
    campaign: &str,
    provenance: &Provenance,
    job: &Job,
    index: usize,
    worker: usize,
    init: Option<Controller>,
    runner: &dyn JobRunner,
    observers: &ObserverFactory<'_>,
    cancel: &Arc<AtomicBool>,
    interval: Duration,
    tx: mpsc::Sender<WorkerMsg>,
) {
    let cpu0 = thread_cpu_time();
    let t0 = Instant::now();
    let made = catch_unwind(AssertUnwindSafe(|| observers(job)))
        .unwrap_or_else(|panic| Err(ObserverError::FactoryPanicked(panic_message(&panic))));
    let user = match made {
        Ok(o) => Some(o),
        Err(e) => {
            let _ = tx.send(WorkerMsg::Warning { index, message: e.to_string() });
            None
        }
    };
    let mut obs = WorkerObserver { user, cancel, tx: &tx, index, worker, interval, last_sent: None };
    let warm = init.is_some();
    let result = match catch_unwind(AssertUnwindSafe(|| runner.run(job, init.as_ref(), &mut obs))) {
        Ok(Ok(out)) => Ok(out),
        Ok(Err(e)) => Err(e.to_string()),
        Err(panic) => Err(format!("panic: {}", panic_message(&panic))),
    };
    let cpu = thread_cpu_time() - cpu0;
    let wall = t0.elapsed().as_secs_f64();
    let user = obs.user.take();
    match JobRecord::from_run(campaign, job, warm, result, cpu, wall).map(|mut r| {
        r.provenance = Some(provenance.clone());
        r
    }) {
        None => {
            if let Some(u) = user {
                u.abandon();
            }
            let _ = tx.send(WorkerMsg::Interrupted { index, worker });
        }
        Some(record) => {
            if let Some(u) = user {
                if let Err(e) = u.finish(&record) {
                    let _ = tx.send(WorkerMsg::Warning { index, message: e.to_string() });
                }
            }
            let _ = tx.send(WorkerMsg::Finished { index, worker, record: Box::new(record) });
        }
    }
}

fn panic_message(p: &Box<dyn std::any::Any + Send>) -> String {
    if let Some(s) = p.downcast_ref::<&str>() {
        s.to_string()
    } else if let Some(s) = p.downcast_ref::<String>() {
        s.clone()
    } else {
        "(no message)".to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::campaign::fake::FakeRunner;
    use crate::campaign::{expand, Campaign, RunnerTag};

    /// A factory that panics must not be dropped silently: every job warns, runs unobserved and
    /// is journaled as usual.
    #[test]
    fn panicking_observer_factory_is_a_warning_per_job() {
        let text = "name = \"t\"\n[defaults]\neps = [1e-2]\nseeds = 2\ncpumax = 5.0\n[[problem]]\nplant = \"HE1\"\norders = [1]\n";
        let jobs = expand(&Campaign::from_toml_str(text, std::path::Path::new("t.toml")).unwrap(), RunnerTag::Fake);
        assert_eq!(jobs.len(), 2);
        let panicking = |_: &Job| -> Result<Box<dyn JobObserver>, ObserverError> { panic!("factory boom") };
        let runner = FakeRunner { pause: Duration::ZERO };
        let (mut warnings, mut finished) = (Vec::new(), 0);
        let stats =
            execute(&jobs, &HashMap::new(), &runner, &panicking, &mut Solo, &ExecuteOptions::new("t", 2), |ev| {
                match ev {
                    CampaignEvent::Warning { index, message } => warnings.push((index, message)),
                    CampaignEvent::JobFinished { .. } => finished += 1,
                    _ => {}
                }
                Ok::<(), std::convert::Infallible>(())
            })
            .unwrap();
        assert_eq!((stats.finished, stats.failed, finished), (2, 0, 2));
        warnings.sort();
        assert_eq!(warnings.len(), 2, "{warnings:?}");
        for (i, (index, message)) in warnings.iter().enumerate() {
            assert_eq!(*index, Some(i));
            assert!(message.contains("panic: factory boom") && message.contains("unobserved"), "{message}");
        }
    }
}
