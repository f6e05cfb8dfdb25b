//! The scheduler: runs jobs on a local rayon pool and reports [`CampaignEvent`]s to one
//! callback on the calling thread. It never prints or writes (nextest's split; docs/ARCHITECTURE.md §2); the
//! journal, traces and progress display are consumers.
//!
//! * The job runner is injected ([`JobRunner`]): production passes [`design_job`]
//!   (`design::Design`), tests pass fast fakes.
//! * Per-job observers (the trace writer) are made by an injected [`ObserverFactory`] on the
//!   worker that runs the job.
//! * Warm-start chains: a job whose `warm_from` predecessor has not finished is not started; its
//!   initial controller is the predecessor's (from this run or from the journal).
//! * Order chaining: a job with `chain_from` jobs is not started before all of them have
//!   finished (here, in the journals or elsewhere); its chained start is the controller of the
//!   best of them (`campaign::chain`), re-verified once per job on the calling thread.
//! * Cancellation: when `cancel` becomes true (first Ctrl-C, or a failing callback), nothing new
//!   is scheduled and every in-flight job's observer returns `Break`, so `design::Design::run` stops with
//!   status `Interrupted`; such jobs produce [`CampaignEvent::JobInterrupted`] and no record, so a
//!   resumed run reruns them.
//! * Workers send events over one `std::sync::mpsc` channel; the calling thread owns the callback.
//! * Structure: a [`Scheduler`] is built once from the jobs, the journals' records, the runner,
//!   the observer factory (trace settings), the coordinator (claims) and the callback (the
//!   journal); on the calling thread it polls, claims, starts and releases jobs in named steps.
//!   Each job runs on a worker as `run_one(context, job)`: make the observer, run (under
//!   `catch_unwind`), make the record (verified, `record::verify_outcome`), hand the record or the
//!   interruption to the calling thread. A job that fails is journaled with its typed
//!   [`JobFailure`] (panic, runner error, verification).
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

use crate::campaign::leaves::provenance::Provenance;
use crate::campaign::model::jobs::{Job, JobId};
use crate::campaign::records::record::{JobFailure, JobRecord};
use crate::design::{DesignError, DesignIterRecord, DesignObserver, DesignOutcome, Observed, ObserverMode, Phase};
use crate::lti::Controller;
use crate::optim::thread_cpu_time;

/// The controllers a job starts from, besides its own random starts.
#[derive(Debug, Clone, Copy, Default)]
pub struct JobStarts<'a> {
    /// Its `warm_from` predecessor's controller (warm start, ε-continuation): the initial
    /// controller, with its perturbations.
    pub warm: Option<&'a Controller>,
    /// The best controller of its `chain_from` jobs (order chaining): one more start, an
    /// incumbent from the outset ([`Job::leads_chain`]: its local search the first).
    pub chained: Option<&'a Controller>,
}

/// Runs one job. Production: [`design_job`]; tests: closures.
pub trait JobRunner: Sync {
    /// Runs `job` from `starts` (or from scratch), reporting iterations to `obs`.
    fn run(&self, job: &Job, starts: JobStarts<'_>, obs: &mut dyn DesignObserver)
        -> Result<DesignOutcome, DesignError>;
}

impl<F> JobRunner for F
where
    F: Fn(&Job, JobStarts<'_>, &mut dyn DesignObserver) -> Result<DesignOutcome, DesignError> + Sync,
{
    fn run(
        &self,
        job: &Job,
        starts: JobStarts<'_>,
        obs: &mut dyn DesignObserver,
    ) -> Result<DesignOutcome, DesignError> {
        self(job, starts, obs)
    }
}

/// The production runner (a [`JobRunner`] as every such function is): [`crate::design::Design`]
/// of the job's problem (its plant, or its plants with their objectives, weights and bounds) and
/// options, with its warm start, chained start and structure, observed by `obs` (whose cancel
/// flag stops the run).
pub fn design_job(
    job: &Job,
    starts: JobStarts<'_>,
    obs: &mut dyn DesignObserver,
) -> Result<DesignOutcome, DesignError> {
    let design = match &job.multi {
        Some(p) => crate::design::Design::new(p, &job.options),
        None => crate::design::Design::for_plant(&job.plant, &job.options),
    };
    design
        .init(starts.warm)
        .chained(starts.chained)
        .chained_first(job.leads_chain)
        .structure(job.structure.as_deref())
        .observe(obs)
        .run()
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

/// Watches one job on its worker (the trace writer is one): a [`DesignObserver`] of the job's
/// run (its `on_iter` gets the run's records as they are; `Break` stops the job, status
/// `Interrupted`), also told how the job ended.
pub trait JobObserver: DesignObserver + Send {
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
    impl DesignObserver for Nothing {}
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
    /// Of those, failed (`design::Design::run` error or panic).
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
/// jobs): builds the [`Scheduler`] and runs it ([`Scheduler::run`]).
pub fn execute<'a, E>(
    jobs: &'a [Job],
    done: &HashMap<JobId, JobRecord>,
    runner: &'a dyn JobRunner,
    observers: &'a ObserverFactory<'_>,
    coord: &'a mut dyn Coordinator<E>,
    opts: &'a ExecuteOptions,
    on_event: impl FnMut(CampaignEvent) -> Result<(), E>,
) -> Result<RunStats, ExecuteError<E>> {
    let pending: VecDeque<usize> = (0..jobs.len()).filter(|&i| !done.contains_key(&jobs[i].id)).collect();
    Scheduler {
        jobs,
        runner,
        observers,
        coord,
        opts,
        on_event,
        index_of: jobs.iter().enumerate().map(|(i, j)| (&j.id, i)).collect(),
        finished: done.iter().map(|(id, r)| (id.clone(), r.controller().cloned())).collect(),
        chain_gamma: HashMap::new(),
        stats: RunStats { total: jobs.len(), already_done: jobs.len() - pending.len(), ..RunStats::default() },
        pending,
        busy_until: HashMap::new(),
        free: (0..opts.threads).rev().collect(),
        running: 0,
        last_poll: Instant::now(),
        force_poll: false,
        idle_sweep: false,
        first_err: None,
    }
    .run()
}

/// What the claim of a ready job decided ([`Scheduler::claim`]).
enum ClaimStep {
    /// Ours: start it.
    Start,
    /// Claimed or finished elsewhere: left alone for [`BUSY_RETRY`], look further down the queue.
    Skip,
    /// The coordinator failed (the run is being cancelled): start nothing more now.
    Stop,
}

/// One `execute` call: the campaign's jobs, what runs and observes them, the coordinator of the
/// claims, the event callback (the journal is one of its consumers) and the state of the queue.
/// Built once ([`execute`]); [`Scheduler::run`] runs it on the calling thread, each job
/// on a worker with a `WorkerContext` (module docs).
pub struct Scheduler<'a, E, F> {
    jobs: &'a [Job],
    runner: &'a dyn JobRunner,
    observers: &'a ObserverFactory<'a>,
    coord: &'a mut dyn Coordinator<E>,
    opts: &'a ExecuteOptions,
    on_event: F,
    index_of: HashMap<&'a JobId, usize>,
    /// Controllers of finished jobs (journals + this run), for warm starts.
    finished: HashMap<JobId, Option<Controller>>,
    /// Re-verified γ of finished jobs that others chain from (order chaining), once computed.
    chain_gamma: HashMap<JobId, Option<f64>>,
    /// Jobs still to run here, in campaign order.
    pending: VecDeque<usize>,
    /// Jobs found claimed elsewhere, with when to try them again.
    busy_until: HashMap<usize, Instant>,
    /// Free worker slots.
    free: Vec<usize>,
    /// Jobs in flight here.
    running: usize,
    last_poll: Instant,
    force_poll: bool,
    /// Set when nothing ran here and every claimable job was just retried: the next idle pass
    /// ends.
    idle_sweep: bool,
    stats: RunStats,
    /// The first callback or coordinator error.
    first_err: Option<E>,
}

impl<'a, E, F> Scheduler<'a, E, F>
where
    F: FnMut(CampaignEvent) -> Result<(), E>,
{
    /// Runs the jobs (module docs): returns the counts, or the first callback or coordinator
    /// error after cancelling and draining in-flight jobs.
    pub fn run(mut self) -> Result<RunStats, ExecuteError<E>> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(self.opts.threads)
            .thread_name(|i| format!("campaign-worker-{i}"))
            .build()?;
        self.emit(Ok(CampaignEvent::Started {
            total: self.stats.total,
            already_done: self.stats.already_done,
            to_run: self.pending.len(),
            threads: self.opts.threads,
        }));
        let (tx, rx) = mpsc::channel::<WorkerMsg>();
        pool.in_place_scope(|scope| loop {
            self.notice_cancel();
            if self.stats.cancel.is_none() && (self.force_poll || self.last_poll.elapsed() >= self.opts.poll_interval) {
                self.poll();
            }
            if self.stats.cancel.is_none() {
                self.start_ready(scope, &tx);
            }
            if self.running == 0 {
                // Nothing in flight here. Unless stopped or done, retry every job at once (claims
                // may have been dropped by processes that died, records may have arrived); if
                // that pass starts nothing either, the rest belongs to other processes.
                if self.stats.cancel.is_some() || self.pending.is_empty() || (self.idle_sweep && !self.force_poll) {
                    break;
                }
                self.idle_sweep = true;
                self.busy_until.clear();
                self.force_poll = true;
                continue;
            }
            match rx.recv_timeout(Duration::from_millis(100)) {
                Ok(msg) => self.handle(msg),
                Err(mpsc::RecvTimeoutError::Timeout) => continue,
                Err(mpsc::RecvTimeoutError::Disconnected) => unreachable!("the scheduler holds a sender"),
            }
        });
        drop(tx);
        self.stats.not_started = self.pending.len();
        let final_stats = self.stats.clone();
        self.emit(Ok(CampaignEvent::Finished { stats: final_stats }));
        match self.first_err {
            Some(e) => Err(ExecuteError::Callback(e)),
            None => Ok(self.stats),
        }
    }

    /// Hands an event to the callback (Ok) or takes a coordinator error (Err); the first error of
    /// either kind cancels the run.
    fn emit(&mut self, ev: Result<CampaignEvent, E>) {
        if let Err(e) = ev.and_then(&mut self.on_event) {
            if self.first_err.is_none() {
                self.first_err = Some(e);
                self.opts.cancel.store(true, Ordering::SeqCst);
                if self.stats.cancel.is_none() {
                    self.stats.cancel = Some(CancelReason::CallbackError);
                    let _ = (self.on_event)(CampaignEvent::CancelRequested { reason: CancelReason::CallbackError });
                }
            }
        }
    }

    /// A cancel flag set from outside (Ctrl-C) stops the scheduling, once.
    fn notice_cancel(&mut self) {
        if self.opts.cancel.load(Ordering::SeqCst) && self.stats.cancel.is_none() {
            self.stats.cancel = Some(CancelReason::Interrupt);
            self.emit(Ok(CampaignEvent::CancelRequested { reason: CancelReason::Interrupt }));
        }
    }

    /// Takes the records journaled elsewhere since the last poll: their jobs leave the queue,
    /// their controllers serve warm starts.
    fn poll(&mut self) {
        self.force_poll = false;
        self.last_poll = Instant::now();
        match self.coord.poll() {
            Ok(records) => {
                for r in records {
                    if self.finished.contains_key(&r.job_id) {
                        continue;
                    }
                    let queued = self.index_of.get(&r.job_id).and_then(|i| self.pending.iter().position(|p| p == i));
                    self.finished.insert(r.job_id.clone(), r.controller().cloned());
                    if let Some(pos) = queued {
                        let index = self.pending.remove(pos).expect("position is in range");
                        self.stats.done_elsewhere += 1;
                        self.emit(Ok(CampaignEvent::JobDoneElsewhere { index }));
                    }
                }
            }
            Err(e) => self.emit(Err(e)),
        }
    }

    /// Starts ready jobs (not left alone after a busy claim, predecessor finished) on the free
    /// workers, each after its claim.
    fn start_ready<'s>(&mut self, scope: &rayon::Scope<'s>, tx: &mpsc::Sender<WorkerMsg>)
    where
        'a: 's,
    {
        let now = Instant::now();
        let mut skip = 0usize;
        while !self.free.is_empty() && self.stats.cancel.is_none() {
            let ready = self.pending.iter().skip(skip).position(|&i| {
                let job = &self.jobs[i];
                self.busy_until.get(&i).is_none_or(|t| *t <= now)
                    && job.predecessors().all(|p| self.finished.contains_key(p))
            });
            let Some(pos) = ready.map(|p| p + skip) else { break };
            match self.claim(self.pending[pos], now) {
                ClaimStep::Start => self.start(scope, tx, pos),
                ClaimStep::Skip => skip = pos + 1,
                ClaimStep::Stop => break,
            }
        }
    }

    /// Claims job `index` through the coordinator before it starts.
    fn claim(&mut self, index: usize, now: Instant) -> ClaimStep {
        match self.coord.claim(&self.jobs[index]) {
            Ok(Claim::Mine) => ClaimStep::Start,
            Ok(Claim::Busy) => {
                self.busy_until.insert(index, now + BUSY_RETRY);
                ClaimStep::Skip
            }
            Ok(Claim::Done) => {
                // its record arrives with the poll at the top of the next pass
                self.busy_until.insert(index, now + BUSY_RETRY);
                self.force_poll = true;
                ClaimStep::Skip
            }
            Err(e) => {
                self.emit(Err(e));
                ClaimStep::Stop
            }
        }
    }

    /// Starts the claimed job at queue position `pos` on a free worker, from its predecessor's
    /// controller if it has one.
    fn start<'s>(&mut self, scope: &rayon::Scope<'s>, tx: &mpsc::Sender<WorkerMsg>, pos: usize)
    where
        'a: 's,
    {
        let index = self.pending.remove(pos).expect("position is in range");
        self.busy_until.remove(&index);
        self.idle_sweep = false;
        let worker = self.free.pop().expect("a free worker");
        let job: &'a Job = &self.jobs[index];
        let init = job.warm_from.as_ref().and_then(|p| self.finished.get(p)).cloned().flatten();
        let chained = self.chained_start(job);
        self.running += 1;
        self.emit(Ok(CampaignEvent::JobStarted { index, worker, warm: init.is_some() }));
        let ctx = WorkerContext {
            campaign: &self.opts.campaign,
            provenance: &self.opts.provenance,
            runner: self.runner,
            observers: self.observers,
            cancel: &self.opts.cancel,
            progress_interval: self.opts.progress_interval,
            worker,
            tx: tx.clone(),
        };
        scope.spawn(move |_| run_one(ctx, StartedJob { index, job, init, chained }));
    }

    /// The chained start of `job` (order chaining): the best of its finished `chain_from` jobs
    /// (`campaign::chain`) and its controller; `None` without such jobs or if none verified.
    fn chained_start(&mut self, job: &Job) -> Option<(JobId, Controller)> {
        for id in &job.chain_from {
            if self.chain_gamma.contains_key(id) {
                continue;
            }
            let gamma = match (self.index_of.get(id), self.finished.get(id)) {
                (Some(&i), Some(Some(k))) => super::chain::verified_gamma(&self.jobs[i], k),
                _ => None,
            };
            self.chain_gamma.insert(id.clone(), gamma);
        }
        let best = super::chain::best(job.chain_from.iter().map(|id| (id, self.chain_gamma[id])))?;
        let k = self.finished.get(best).cloned().flatten()?;
        Some((best.clone(), k))
    }

    /// Handles one message of a worker.
    fn handle(&mut self, msg: WorkerMsg) {
        match msg {
            WorkerMsg::Progress { index, worker, phase, iter, f, gamma } => {
                self.emit(Ok(CampaignEvent::JobProgress { index, worker, phase, iter, f, gamma }))
            }
            WorkerMsg::Warning { index, message } => {
                self.stats.warnings += 1;
                self.emit(Ok(CampaignEvent::Warning { index: Some(index), message }))
            }
            WorkerMsg::Finished { index, worker, record } => {
                self.running -= 1;
                self.free.push(worker);
                self.stats.finished += 1;
                if record.failed() {
                    self.stats.failed += 1;
                }
                self.finished.insert(record.job_id.clone(), record.controller().cloned());
                // the callback journals the record
                self.emit(Ok(CampaignEvent::JobFinished { index, worker, record }));
                // journaled (or the journal failed and the run stops): the claim can go
                self.release(index);
            }
            WorkerMsg::Interrupted { index, worker } => {
                self.running -= 1;
                self.free.push(worker);
                self.stats.interrupted += 1;
                self.emit(Ok(CampaignEvent::JobInterrupted { index, worker }));
                self.release(index);
            }
        }
    }

    /// Job `index` ended here (its record, if any, handed to the callback): its claim goes.
    fn release(&mut self, index: usize) {
        self.coord.release(&self.jobs[index]);
    }
}

/// What a worker needs to run one job, besides the job: where its record and events go, what
/// runs and observes it, the cancel flag.
struct WorkerContext<'a> {
    /// Campaign name (written into the record).
    campaign: &'a str,
    /// Written into the record.
    provenance: &'a Provenance,
    runner: &'a dyn JobRunner,
    observers: &'a ObserverFactory<'a>,
    cancel: &'a Arc<AtomicBool>,
    /// Minimum time between two progress events.
    progress_interval: Duration,
    /// The worker slot.
    worker: usize,
    tx: mpsc::Sender<WorkerMsg>,
}

/// A claimed job on its way to a worker.
struct StartedJob<'a> {
    /// Its index in the campaign's jobs.
    index: usize,
    job: &'a Job,
    /// Its predecessor's controller (warm start).
    init: Option<Controller>,
    /// Its chained start (order chaining): the job it comes from and its controller.
    chained: Option<(JobId, Controller)>,
}

/// The observer a job actually runs with: the user's (trace), progress events (throttled:
/// [`ObserverMode::Throttled`] by the progress interval), cancellation.
struct WorkerObserver<'a> {
    user: Option<Box<dyn JobObserver>>,
    progress: Observed<ProgressEvents<'a>>,
    cancel: &'a Arc<AtomicBool>,
}

/// Sends a progress event of each iteration it is told of to the scheduler thread.
struct ProgressEvents<'a> {
    tx: &'a mpsc::Sender<WorkerMsg>,
    index: usize,
    worker: usize,
}

impl DesignObserver for ProgressEvents<'_> {
    fn on_iter(&mut self, rec: &DesignIterRecord) -> ControlFlow<()> {
        let (index, worker) = (self.index, self.worker);
        let (phase, iter, f, gamma) = (rec.phase, rec.iter, rec.f, rec.gamma);
        let _ = self.tx.send(WorkerMsg::Progress { index, worker, phase, iter, f, gamma });
        ControlFlow::Continue(())
    }
}

impl DesignObserver for WorkerObserver<'_> {
    fn on_iter(&mut self, rec: &DesignIterRecord) -> ControlFlow<()> {
        let user = match &mut self.user {
            Some(u) => u.on_iter(rec),
            None => ControlFlow::Continue(()),
        };
        let _ = self.progress.on_iter(rec);
        if self.cancel.load(Ordering::Relaxed) {
            return ControlFlow::Break(());
        }
        user
    }

    fn cancel_flag(&self) -> Option<Arc<AtomicBool>> {
        Some(Arc::clone(self.cancel))
    }
}

/// Runs one job on its worker: observer, run, record (verified), then the record or the
/// interruption goes to the scheduler thread, which journals it and releases the claim.
fn run_one(ctx: WorkerContext<'_>, job: StartedJob<'_>) {
    let cpu0 = thread_cpu_time();
    let t0 = Instant::now();
    let user = ctx.make_observer(&job);
    let (result, user) = ctx.run(&job, user);
    let cpu = thread_cpu_time() - cpu0;
    let wall = t0.elapsed().as_secs_f64();
    match ctx.record(&job, result, cpu, wall) {
        None => ctx.abandon(&job, user),
        Some(record) => ctx.finish(&job, user, record),
    }
}

impl WorkerContext<'_> {
    /// The job's observer from the factory; an error or a panic of the factory is a warning, and
    /// the job runs unobserved.
    fn make_observer(&self, job: &StartedJob<'_>) -> Option<Box<dyn JobObserver>> {
        let made = catch_unwind(AssertUnwindSafe(|| (self.observers)(job.job)))
            .unwrap_or_else(|panic| Err(ObserverError::FactoryPanicked(panic_message(&panic))));
        match made {
            Ok(o) => Some(o),
            Err(e) => {
                let _ = self.tx.send(WorkerMsg::Warning { index: job.index, message: e.to_string() });
                None
            }
        }
    }

    /// Runs the job under `catch_unwind` (a panic is a failed job, not a dead worker); returns
    /// its result and the user's observer.
    fn run(
        &self,
        job: &StartedJob<'_>,
        user: Option<Box<dyn JobObserver>>,
    ) -> (Result<DesignOutcome, JobFailure>, Option<Box<dyn JobObserver>>) {
        let progress = ProgressEvents { tx: &self.tx, index: job.index, worker: self.worker };
        let progress = Observed::new(ObserverMode::Throttled(self.progress_interval), progress);
        let mut obs = WorkerObserver { user, progress, cancel: self.cancel };
        let starts = JobStarts { warm: job.init.as_ref(), chained: job.chained.as_ref().map(|(_, k)| k) };
        let result = match catch_unwind(AssertUnwindSafe(|| self.runner.run(job.job, starts, &mut obs))) {
            Ok(Ok(out)) => Ok(out),
            Ok(Err(e)) => Err(JobFailure::RunnerError(e.to_string())),
            Err(panic) => Err(JobFailure::Panicked(panic_message(&panic))),
        };
        (result, obs.user.take())
    }

    /// The job's record, its result verified ([`crate::campaign::records::record::verify_outcome`]: a result that fails
    /// is journaled as a failure); `None` for an interrupted run (not journaled).
    fn record(
        &self,
        job: &StartedJob<'_>,
        result: Result<DesignOutcome, JobFailure>,
        cpu: f64,
        wall: f64,
    ) -> Option<JobRecord> {
        let warm = job.init.is_some();
        JobRecord::from_run(self.campaign, job.job, warm, result, cpu, wall).map(|mut r| {
            r.provenance = Some(self.provenance.clone());
            r.chained_from = job.chained.as_ref().map(|(id, _)| id.clone());
            r
        })
    }

    /// An interrupted job: its observer drops what it wrote; the scheduler releases the claim.
    fn abandon(&self, job: &StartedJob<'_>, user: Option<Box<dyn JobObserver>>) {
        if let Some(u) = user {
            u.abandon();
        }
        let _ = self.tx.send(WorkerMsg::Interrupted { index: job.index, worker: self.worker });
    }

    /// A finished job: its observer completes (the trace gets the record), then the record goes
    /// to the scheduler thread to be journaled.
    fn finish(&self, job: &StartedJob<'_>, user: Option<Box<dyn JobObserver>>, record: JobRecord) {
        if let Some(u) = user {
            if let Err(e) = u.finish(&record) {
                let _ = self.tx.send(WorkerMsg::Warning { index: job.index, message: e.to_string() });
            }
        }
        let _ = self.tx.send(WorkerMsg::Finished { index: job.index, worker: self.worker, record: Box::new(record) });
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
    use crate::campaign::execution::fake::FakeRunner;
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
