//! The progress reporter: a consumer of [`CampaignEvent`]s, never called by the scheduler itself
//! (nextest's runner/reporter split; docs/ARCHITECTURE.md §2).
//!
//! Two displays:
//! * [`Display::Bars`] (stderr is a terminal): an indicatif bar over all jobs with ETA, and one
//!   line per worker showing its job (plant, n_K, ε, seed) and the current γ;
//! * [`Display::Plain`] (stderr is not a terminal, or `--no-progress`): one log line per started,
//!   finished or interrupted job and per warning, so CI logs and `nohup` files stay readable;
//! * [`Display::Collect`]: the plain lines, kept for the caller ([`Reporter::take_lines`]), who
//!   shows them where its user looks (the Python package: `sys.stderr`, a Jupyter cell).

use std::io::IsTerminal;
use std::time::Duration;

use indicatif::{MultiProgress, ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::scheduler::CampaignEvent;
use crate::campaign::model::jobs::Job;

/// How progress is shown.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Display {
    /// Live bars (interactive terminal).
    Bars,
    /// One line per event on stderr.
    Plain,
    /// The plain lines, kept until [`Reporter::take_lines`].
    Collect,
}

impl Display {
    /// Bars when stderr is a terminal and `no_progress` is false, else plain lines.
    pub fn choose(no_progress: bool) -> Display {
        if !no_progress && std::io::stderr().is_terminal() {
            Display::Bars
        } else {
            Display::Plain
        }
    }
}

/// Shows a campaign's progress on stderr.
pub struct Reporter<'a> {
    jobs: &'a [Job],
    display: Display,
    multi: MultiProgress,
    overall: Option<ProgressBar>,
    workers: Vec<ProgressBar>,
    /// The lines kept by [`Display::Collect`].
    pending: Vec<String>,
}

impl<'a> Reporter<'a> {
    /// A reporter for `jobs` (the slice the scheduler indexes into).
    pub fn new(jobs: &'a [Job], display: Display) -> Self {
        let multi = MultiProgress::with_draw_target(match display {
            Display::Bars => ProgressDrawTarget::stderr(),
            Display::Plain | Display::Collect => ProgressDrawTarget::hidden(),
        });
        Reporter { jobs, display, multi, overall: None, workers: Vec::new(), pending: Vec::new() }
    }

    fn label(&self, index: usize) -> String {
        self.jobs.get(index).map_or_else(|| format!("job {index}"), Job::label)
    }

    /// Prints a line above the bars (or plainly).
    fn line(&mut self, msg: String) {
        match self.display {
            Display::Bars => {
                let _ = self.multi.println(msg);
            }
            Display::Plain => eprintln!("{msg}"),
            Display::Collect => self.pending.push(msg),
        }
    }

    /// The lines kept since the last call ([`Display::Collect`]; none for the other displays).
    pub fn take_lines(&mut self) -> Vec<String> {
        std::mem::take(&mut self.pending)
    }

    /// Consumes one event.
    pub fn on_event(&mut self, ev: &CampaignEvent) {
        match ev {
            CampaignEvent::Started { total, already_done, to_run, threads } => {
                self.line(format!(
                    "{total} jobs: {already_done} already in the journal, {to_run} to run on {threads} thread(s)"
                ));
                if self.display == Display::Bars {
                    let style = ProgressStyle::with_template("{bar:40} {pos}/{len} jobs  {elapsed_precise} ETA {eta}")
                        .unwrap_or_else(|_| ProgressStyle::default_bar());
                    let bar = self.multi.add(ProgressBar::new(*to_run as u64).with_style(style));
                    bar.enable_steady_tick(Duration::from_millis(500));
                    self.overall = Some(bar);
                    self.workers = (0..*threads)
                        .map(|w| {
                            let b = self.multi.add(ProgressBar::new_spinner());
                            b.set_message(format!("worker {w}: idle"));
                            b
                        })
                        .collect();
                }
            }
            CampaignEvent::JobStarted { index, worker, warm } => {
                let warm = if *warm { " (warm start)" } else { "" };
                match self.workers.get(*worker) {
                    Some(b) => b.set_message(format!("worker {worker}: {}{warm}", self.label(*index))),
                    None => self.line(format!("start  {}{warm}", self.label(*index))),
                }
            }
            CampaignEvent::JobProgress { index, worker, phase, iter, f, gamma } => {
                if let Some(b) = self.workers.get(*worker) {
                    let g = if gamma.is_finite() { format!("γ = {gamma:.6}") } else { format!("f = {f:.4e}") };
                    b.set_message(format!("worker {worker}: {}  {} it {iter}  {g}", self.label(*index), phase.name()));
                }
            }
            CampaignEvent::JobFinished { index, worker, record } => {
                self.line(format!(
                    "done   {}  {}  γ = {:.6}  ‖K‖∞ = {:.4}  {:.1} s",
                    self.label(*index),
                    record.status().kind(),
                    record.outcome().map_or(f64::NAN, |o| o.gamma),
                    record.outcome().map_or(f64::NAN, |o| o.k_hinf),
                    record.cpu_s
                ));
                if let Some(b) = self.workers.get(*worker) {
                    b.set_message(format!("worker {worker}: idle"));
                }
                if let Some(b) = &self.overall {
                    b.inc(1);
                }
            }
            CampaignEvent::JobDoneElsewhere { index } => {
                self.line(format!("done elsewhere {} (another process journaled it)", self.label(*index)));
                if let Some(b) = &self.overall {
                    b.inc(1);
                }
            }
            CampaignEvent::JobInterrupted { index, .. } => {
                self.line(format!("stopped {} (not journaled; a rerun redoes it)", self.label(*index)))
            }
            CampaignEvent::Warning { index, message } => match index {
                Some(i) => self.line(format!("warning: {}: {message}", self.label(*i))),
                None => self.line(format!("warning: {message}")),
            },
            CampaignEvent::CancelRequested { reason } => {
                self.line(format!("stopping ({}): no new jobs; in-flight jobs are dropped", reason.describe()))
            }
            CampaignEvent::Finished { .. } => {
                for b in &self.workers {
                    b.finish_and_clear();
                }
                if let Some(b) = &self.overall {
                    b.finish();
                }
            }
        }
    }
}
