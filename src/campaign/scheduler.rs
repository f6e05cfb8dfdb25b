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

use std::collections::{HashMap, VecDeque};
use std::ops::ControlFlow;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc;
use std::sync::Arc;
use std::time::{Duration, Instant};

use super::jobs::{Job, JobId};
use super::record::JobRecord;
use crate::design::{DesignError, DesignIterRecord, DesignObserver, DesignOutcome, Phase};
use crate::lti::Controller;
use crate::optim::thread_cpu_time;

/// Runs one job. Production: [`DesignRunner`]; tests: closures.
pub trait JobRunner: Sync {
    /// Runs `job` from `init` (warm start) or from scratch, reporting iterations to `obs`.
    fn run(&self, job: &Job, init: Option<&Controller>, obs: &mut dyn DesignObserver) -> Result<DesignOutcome, DesignError>;
}

impl<F> JobRunner for F
where
    F: Fn(&Job, Option<&Controller>, &mut dyn DesignObserver) -> Result<DesignOutcome, DesignError> + Sync,
{
    fn run(&self, job: &Job, init: Option<&Controller>, obs: &mut dyn DesignObserver) -> Result<DesignOutcome, DesignError> {
        self(job, init, obs)
    }
}

/// The production runner: [`crate::design::run`] with the job's plant and options.
pub struct DesignRunner;

impl JobRunner for DesignRunner {
    fn run(&self, job: &Job, init: Option<&Controller>, obs: &mut dyn DesignObserver) -> Result<DesignOutcome, DesignError> {
        crate::design::run(&job.plant, &job.options, init, obs)
    }
}

/// Watches one job on its worker (the trace writer is one).
pub trait JobObserver: Send {
    /// Called once per optimiser iteration; `Break` stops the job (status `Interrupted`).
    fn on_iter(&mut self, _rec: &DesignIterRecord) -> ControlFlow<()> {
        ControlFlow::Continue(())
    }
    /// The job finished with `record` (which is journaled next). An error becomes a warning.
    fn finish(self: Box<Self>, _record: &JobRecord) -> Result<(), String> {
        Ok(())
    }
    /// The job was interrupted: nothing will be journaled.
    fn abandon(self: Box<Self>) {}
}

/// Makes the observer of a job (called on the worker). An error becomes a warning and the job
/// runs unobserved.
pub type ObserverFactory<'a> = dyn Fn(&Job) -> Result<Box<dyn JobObserver>, String> + Sync + 'a;

/// A factory that observes nothing.
pub fn no_observers(_: &Job) -> Result<Box<dyn JobObserver>, String> {
    struct Nothing;
    impl JobObserver for Nothing {}
    Ok(Box::new(Nothing))
}

/// Why scheduling stopped early; ordered by severity.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum CancelReason {
    /// The event callback failed (e.g. the journal could not be written).
    CallbackError,
    /// The cancel flag was set (Ctrl-C).
    Interrupt,
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
    /// Stopped in flight by a cancel (not journaled).
    pub interrupted: usize,
    /// Never started.
    pub not_started: usize,
    /// Why scheduling stopped early, if it did.
    pub cancel: Option<CancelReason>,
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
}

impl ExecuteOptions {
    /// `threads` workers, a fresh cancel flag, progress every 200 ms.
    pub fn new(campaign: &str, threads: usize) -> Self {
        ExecuteOptions {
            threads: threads.max(1),
            campaign: campaign.to_string(),
            cancel: Arc::new(AtomicBool::new(false)),
            progress_interval: Duration::from_millis(200),
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

/// Runs every job of `jobs` that is not in `done` (the journal), respecting warm-start chains,
/// and reports events to `on_event` on the calling thread. Returns the counts, or the first
/// callback error (after cancelling and draining in-flight jobs).
pub fn execute<E>(
    jobs: &[Job],
    done: &HashMap<JobId, JobRecord>,
    runner: &dyn JobRunner,
    observers: &ObserverFactory<'_>,
    opts: &ExecuteOptions,
    mut on_event: impl FnMut(CampaignEvent) -> Result<(), E>,
) -> Result<RunStats, ExecuteError<E>> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(opts.threads)
        .thread_name(|i| format!("campaign-worker-{i}"))
        .build()?;
    // Controllers of finished jobs (journal + this run), for warm starts.
    let mut finished: HashMap<JobId, Option<serde_json::Value>> =
        done.iter().map(|(id, r)| (id.clone(), r.controller.clone())).collect();
    let mut pending: VecDeque<usize> = (0..jobs.len()).filter(|&i| !done.contains_key(&jobs[i].id)).collect();
    let mut stats = RunStats {
        total: jobs.len(),
        already_done: jobs.len() - pending.len(),
        ..RunStats::default()
    };
    let mut first_err: Option<E> = None;
    let mut emit = |ev: CampaignEvent, first_err: &mut Option<E>, stats: &mut RunStats| {
        if let Err(e) = on_event(ev) {
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
        CampaignEvent::Started { total: stats.total, already_done: stats.already_done, to_run: pending.len(), threads: opts.threads },
        &mut first_err,
        &mut stats,
    );

    let (tx, rx) = mpsc::channel::<WorkerMsg>();
    let mut free: Vec<usize> = (0..opts.threads).rev().collect();
    let mut running = 0usize;
    let campaign = opts.campaign.as_str();
    let cancel = &opts.cancel;
    let interval = opts.progress_interval;

    pool.in_place_scope(|scope| loop {
        if cancel.load(Ordering::SeqCst) && stats.cancel.is_none() {
            stats.cancel = Some(CancelReason::Interrupt);
            emit(CampaignEvent::CancelRequested { reason: CancelReason::Interrupt }, &mut first_err, &mut stats);
        }
        if stats.cancel.is_none() {
            while !free.is_empty() {
                let ready = pending.iter().position(|&i| match &jobs[i].warm_from {
                    None => true,
                    Some(p) => finished.contains_key(p),
                });
                let Some(pos) = ready else { break };
                let index = pending.remove(pos).expect("position is in range");
                let job = &jobs[index];
                let worker = free.pop().expect("a free worker");
                let mut init = None;
                if let Some(Some(k)) = job.warm_from.as_ref().and_then(|p| finished.get(p)) {
                    match Controller::from_json_value(k) {
                        Ok(k) => init = Some(k),
                        Err(e) => emit(
                            CampaignEvent::Warning {
                                index: Some(index),
                                message: format!("{}: predecessor's controller unusable ({e}); starting cold", job.label()),
                            },
                            &mut first_err,
                            &mut stats,
                        ),
                    }
                }
                running += 1;
                emit(CampaignEvent::JobStarted { index, worker, warm: init.is_some() }, &mut first_err, &mut stats);
                let tx = tx.clone();
                scope.spawn(move |_| run_one(campaign, job, index, worker, init, runner, observers, cancel, interval, tx));
            }
        }
        if running == 0 {
            break;
        }
        let msg = match rx.recv_timeout(Duration::from_millis(100)) {
            Ok(m) => m,
            Err(mpsc::RecvTimeoutError::Timeout) => continue,
            Err(mpsc::RecvTimeoutError::Disconnected) => unreachable!("the scheduler holds a sender"),
        };
        let ev = match msg {
            WorkerMsg::Progress { index, worker, phase, iter, f, gamma } => CampaignEvent::JobProgress { index, worker, phase, iter, f, gamma },
            WorkerMsg::Warning { index, message } => CampaignEvent::Warning { index: Some(index), message },
            WorkerMsg::Finished { index, worker, record } => {
                running -= 1;
                free.push(worker);
                stats.finished += 1;
                if record.failed() {
                    stats.failed += 1;
                }
                finished.insert(record.job_id.clone(), record.controller.clone());
                CampaignEvent::JobFinished { index, worker, record }
            }
            WorkerMsg::Interrupted { index, worker } => {
                running -= 1;
                free.push(worker);
                stats.interrupted += 1;
                CampaignEvent::JobInterrupted { index, worker }
            }
        };
        emit(ev, &mut first_err, &mut stats);
    });
    drop(tx);
    stats.not_started = pending.len();
    let final_stats = stats.clone();
    emit(CampaignEvent::Finished { stats: final_stats }, &mut first_err, &mut stats);
    match first_err {
        Some(e) => Err(ExecuteError::Callback(e)),
        None => Ok(stats),
    }
}

/// The observer a job actually runs with: the user's (trace), progress events, cancellation.
struct WorkerObserver<'a> {
    user: Option<Box<dyn JobObserver>>,
    cancel: &'a AtomicBool,
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
                gamma: rec.hinf_cl,
            });
        }
        if self.cancel.load(Ordering::Relaxed) {
            return ControlFlow::Break(());
        }
        user
    }
}

#[allow(clippy::too_many_arguments)]
fn run_one(
    campaign: &str,
    job: &Job,
    index: usize,
    worker: usize,
    init: Option<Controller>,
    runner: &dyn JobRunner,
    observers: &ObserverFactory<'_>,
    cancel: &AtomicBool,
    interval: Duration,
    tx: mpsc::Sender<WorkerMsg>,
) {
    let cpu0 = thread_cpu_time();
    let t0 = Instant::now();
    let user = match catch_unwind(AssertUnwindSafe(|| observers(job))) {
        Ok(Ok(o)) => Some(o),
        Ok(Err(message)) => {
            let _ = tx.send(WorkerMsg::Warning { index, message });
            None
        }
        Err(_) => None,
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
    match JobRecord::from_run(campaign, job, warm, result, cpu, wall) {
        None => {
            if let Some(u) = user {
                u.abandon();
            }
            let _ = tx.send(WorkerMsg::Interrupted { index, worker });
        }
        Some(record) => {
            if let Some(u) = user {
                if let Err(message) = u.finish(&record) {
                    let _ = tx.send(WorkerMsg::Warning { index, message });
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
