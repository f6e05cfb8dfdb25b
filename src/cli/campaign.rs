//! `campaign run | status | report | trace`: the command-line edge of `hinfix::campaign`. All the
//! work is in the library (spec, jobs, scheduler, journal, progress, trace, report); this file
//! only parses arguments, wires the pieces together and maps outcomes to exit codes.
use std::collections::{BTreeMap, HashMap};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::Context;
use hinfix::campaign::fake::FakeRunner;
use hinfix::campaign::journal::read_journal;
use hinfix::campaign::progress::{Display, Reporter};
use hinfix::campaign::record::JobRecord;
use hinfix::campaign::run::{campaign_dir, journal_path, records_by_id, records_of_jobs, run_jobs};
use hinfix::campaign::scheduler::{DesignRunner, ExecuteOptions, JobRunner};
use hinfix::campaign::{
    expand, load_default_reference, summarise, trace_observers, write_reports, Campaign, Job, PlantMap, RunnerTag,
};

use hinfix::campaign::sanitise::for_terminal;

use super::{signals, EXIT_JOBS_FAILED};

/// Where campaign results go unless `--results` says otherwise.
const DEFAULT_RESULTS: &str = "results";

/// The campaign file and the results root, shared by `run`, `status` and `report`.
#[derive(clap::Args, Debug)]
pub struct CampaignFileArgs {
    /// Campaign file (TOML; format in campaigns/FORMAT.md).
    pub file: PathBuf,
    /// Results root: the campaign writes into `<RESULTS>/<campaign name>/`.
    #[arg(long, value_name = "DIR", default_value = DEFAULT_RESULTS)]
    pub results: PathBuf,
}

/// Arguments of `campaign run`.
#[derive(clap::Args, Debug)]
pub struct RunArgs {
    #[command(flatten)]
    pub campaign: CampaignFileArgs,
    /// Worker threads (one job per thread; faer is single-threaded inside a job), 1..=256.
    /// Default: the file's `defaults.threads`, else 2.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=hinfix::campaign::MAX_THREADS as i64))]
    pub threads: Option<u32>,
    /// Plain log lines instead of live progress bars (automatic when stderr is not a terminal).
    #[arg(long)]
    pub no_progress: bool,
}

/// Arguments of `campaign status`.
#[derive(clap::Args, Debug)]
pub struct StatusArgs {
    #[command(flatten)]
    pub campaign: CampaignFileArgs,
}

/// Arguments of `campaign report`.
#[derive(clap::Args, Debug)]
pub struct ReportArgs {
    #[command(flatten)]
    pub campaign: CampaignFileArgs,
}

/// Arguments of `campaign trace`.
#[derive(clap::Args, Debug)]
pub struct TraceArgs {
    /// Trace file (`results/<campaign>/traces/<job>.mcap`).
    pub file: PathBuf,
    /// Print the summary as JSON.
    #[arg(long)]
    pub json: bool,
}

/// A loaded campaign, its jobs, its results folder and the runner its jobs are meant for.
struct Loaded {
    campaign: Campaign,
    jobs: Vec<Job>,
    dir: PathBuf,
    fake: Option<FakeRunner>,
}

fn load(a: &CampaignFileArgs) -> anyhow::Result<Loaded> {
    let campaign = Campaign::load(&a.file)?;
    // The hidden fake runner (tests of the machinery) makes jobs with different ids, so its
    // records can never be mistaken for real ones.
    let fake = FakeRunner::from_env();
    let tag = fake.as_ref().map_or(RunnerTag::Design, FakeRunner::tag);
    let jobs = expand(&campaign, tag);
    let dir = campaign_dir(&a.results, &campaign.name);
    Ok(Loaded { campaign, jobs, dir, fake })
}

fn plant_map(c: &Campaign) -> PlantMap {
    c.problems.iter().map(|p| (p.plant.name.clone(), p.plant.clone())).collect::<BTreeMap<_, _>>()
}

/// Reduces `records` to the report files in `dir` and prints the comparison.
fn report_into(dir: &Path, c: &Campaign, records: &[JobRecord]) -> anyhow::Result<()> {
    let reference = load_default_reference().context("reading the paper's reference table")?;
    let summary = write_reports(dir, records, &plant_map(c), &reference)?;
    print!("{summary}");
    Ok(())
}

/// `campaign run FILE`.
pub fn run(a: RunArgs) -> anyhow::Result<ExitCode> {
    let l = load(&a.campaign)?;
    std::fs::create_dir_all(&l.dir).with_context(|| format!("creating {}", l.dir.display()))?;
    let threads = l.campaign.threads(a.threads.map(|t| t as usize));
    let opts = ExecuteOptions::new(&l.campaign.name, threads);
    let cancel = opts.cancel.clone();
    signals::install_into(&cancel).context("installing the signal handlers")?;

    let runner: &dyn JobRunner = match &l.fake {
        Some(f) => f,
        None => &DesignRunner,
    };
    let observers = trace_observers(&l.dir.join("traces"));
    let mut reporter = Reporter::new(&l.jobs, Display::choose(a.no_progress));
    eprintln!("campaign {} → {}", for_terminal(&l.campaign.name), for_terminal(&l.dir.display().to_string()));
    let outcome = run_jobs(&l.jobs, &l.dir, runner, &observers, &opts, |ev| reporter.on_event(ev))?;
    if let Some(t) = &outcome.torn {
        eprintln!(
            "warning: {}: line {} was torn ({}); it was ignored and cut off",
            outcome.journal.display(),
            t.line,
            t.reason
        );
    }
    let s = &outcome.stats;
    eprintln!(
        "{} jobs: {} were already done, {} finished now ({} failed), {} interrupted, {} not started",
        s.total, s.already_done, s.finished, s.failed, s.interrupted, s.not_started
    );
    report_into(&l.dir, &l.campaign, &outcome.records)?;
    if outcome.interrupted() {
        eprintln!("interrupted: rerun the same command to resume");
        return Ok(ExitCode::from(signals::exit_code()));
    }
    if outcome.failed() > 0 {
        eprintln!("{} job(s) failed: see `status` in {}", outcome.failed(), outcome.journal.display());
        return Ok(ExitCode::from(EXIT_JOBS_FAILED));
    }
    Ok(ExitCode::SUCCESS)
}

/// The journal's records of this campaign's jobs (torn tail reported on stderr).
fn journaled(l: &Loaded) -> anyhow::Result<Vec<JobRecord>> {
    let path = journal_path(&l.dir);
    let read = read_journal(&path)?;
    if let Some(t) = &read.torn {
        eprintln!("warning: {}: line {} is torn ({}); ignored", path.display(), t.line, t.reason);
    }
    Ok(records_of_jobs(&l.jobs, &records_by_id(read.records)))
}

/// `campaign status FILE`.
pub fn status(a: StatusArgs) -> anyhow::Result<ExitCode> {
    let l = load(&a.campaign)?;
    let records = journaled(&l)?;
    let done: HashMap<_, _> = records.iter().map(|r| (&r.job_id, r)).collect();
    // plant → (jobs, done, failed), in campaign order.
    let mut rows: Vec<(String, usize, usize, usize)> = Vec::new();
    for j in &l.jobs {
        let i = match rows.iter().position(|r| r.0 == j.plant_name) {
            Some(i) => i,
            None => {
                rows.push((j.plant_name.clone(), 0, 0, 0));
                rows.len() - 1
            }
        };
        rows[i].1 += 1;
        if let Some(r) = done.get(&j.id) {
            rows[i].2 += 1;
            rows[i].3 += r.failed() as usize;
        }
    }
    println!("campaign {} ({})", for_terminal(&l.campaign.name), for_terminal(&journal_path(&l.dir).display().to_string()));
    println!("{:<16} {:>6} {:>6} {:>9} {:>7}", "plant", "jobs", "done", "remaining", "failed");
    for (p, n, d, f) in &rows {
        println!("{:<16} {n:>6} {d:>6} {:>9} {f:>7}", for_terminal(p), n - d);
    }
    let (n, d, f) = rows.iter().fold((0, 0, 0), |acc, r| (acc.0 + r.1, acc.1 + r.2, acc.2 + r.3));
    println!("{:<16} {n:>6} {d:>6} {:>9} {f:>7}", "total", n - d);
    Ok(ExitCode::SUCCESS)
}

/// `campaign report FILE`.
pub fn report(a: ReportArgs) -> anyhow::Result<ExitCode> {
    let l = load(&a.campaign)?;
    let records = journaled(&l)?;
    if records.is_empty() {
        anyhow::bail!("{}: no finished jobs of this campaign yet (run it first)", journal_path(&l.dir).display());
    }
    report_into(&l.dir, &l.campaign, &records)?;
    Ok(ExitCode::SUCCESS)
}

/// `campaign trace FILE`.
pub fn trace(a: TraceArgs) -> anyhow::Result<ExitCode> {
    let s = summarise(&a.file)?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&s)?);
    } else {
        print!("{s}");
    }
    Ok(ExitCode::SUCCESS)
}
