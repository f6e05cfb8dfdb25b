//! `campaign run | status | report | trace`: the command-line edge of `crate::campaign`. All the
//! work is in the library (spec, jobs, scheduler, journal, progress, trace, report); this file
//! only parses arguments, wires the pieces together and maps outcomes to exit codes.
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use crate::campaign::{
    campaign_dir, design_job, expand, for_terminal, journals_in, load_default_reference, plant_map, records_for,
    run_jobs, shard_jobs, shard_plan, summarise, trace_observers, Campaign, CampaignStatus, ExecuteOptions, Follower,
    Job, JobRecord, JobRunner, ProgressDisplay, Reporter, RunnerTag, Shard, TornTail, TraceLevel,
};
use anyhow::Context;

use super::{print_out, signals, EXIT_JOBS_FAILED};

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
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=crate::campaign::MAX_THREADS as i64))]
    pub threads: Option<u32>,
    /// Plain log lines instead of live progress bars (automatic when stderr is not a terminal).
    #[arg(long)]
    pub no_progress: bool,
    /// Run only shard K of N (1-based): a deterministic partition of the jobs that keeps
    /// warm-start chains together and balances the CPU budgets. Any number of runs (shards or
    /// not) may share one results folder.
    #[arg(long, value_name = "K/N")]
    pub shard: Option<Shard>,
    /// How much of each job's iterations its trace keeps: `sparse` (what `campaign trace` and the
    /// convergence figure need), `full` (every iteration) or `off` (no trace file). Overrides the
    /// file's `trace` keys; default: those, else sparse. Job ids and results do not depend on it.
    #[arg(long, value_name = "LEVEL", value_enum)]
    pub trace: Option<TraceLevel>,
}

/// Extra journals merged into `status` and `report`.
#[derive(clap::Args, Debug)]
pub struct JournalArgs {
    /// A journal file, or a results folder whose `runs*.jsonl` are all read, to merge with the
    /// campaign's own folder (e.g. results copied from another machine). Repeatable.
    #[arg(long = "journal", value_name = "PATH")]
    pub journals: Vec<PathBuf>,
}

/// Arguments of `campaign status`.
#[derive(clap::Args, Debug)]
pub struct StatusArgs {
    #[command(flatten)]
    pub campaign: CampaignFileArgs,
    #[command(flatten)]
    pub extra: JournalArgs,
    /// Also show how `--shard K/N` splits the campaign into N shards: jobs, CPU budget and a wall
    /// time bound per shard, and the time limit to give each task of a job array.
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=100_000))]
    pub shards: Option<u32>,
    /// Worker threads per shard assumed by `--shards` (default: as `campaign run` would use).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=256), requires = "shards")]
    pub threads: Option<u32>,
}

/// Arguments of `campaign report`.
#[derive(clap::Args, Debug)]
pub struct ReportArgs {
    #[command(flatten)]
    pub campaign: CampaignFileArgs,
    #[command(flatten)]
    pub extra: JournalArgs,
}

/// Arguments of `campaign plot`.
#[derive(clap::Args, Debug)]
pub struct PlotArgs {
    #[command(flatten)]
    pub campaign: CampaignFileArgs,
    #[command(flatten)]
    pub extra: JournalArgs,
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
    fake: Option<Box<dyn JobRunner>>,
}

/// Loads the campaign file and expands its jobs for `fake` (the machinery tests' fake runner,
/// [`crate::cli::main_with`]) or, when `None`, for the design.
fn load(a: &CampaignFileArgs, fake: Option<Box<dyn JobRunner>>) -> anyhow::Result<Loaded> {
    let campaign = Campaign::load(&a.file)?;
    // The fake runner makes jobs with different ids, so its records can never be mistaken for
    // real ones.
    let tag = if fake.is_some() { RunnerTag::Fake } else { RunnerTag::Design };
    let jobs = expand(&campaign, tag);
    let dir = campaign_dir(&a.results, &campaign.name);
    Ok(Loaded { campaign, jobs, dir, fake })
}

/// Under the comparison table, when an entry is above the paper's value (ratio > 1 + 1e-3; only
/// strong entries have a paper value, `campaign::compare_rows`): the campaign's budget per job
/// against the paper's protocol, so that a reader of a small campaign (the smoke run: HE1
/// n_K = 2 at 1.0116) sees why. `None` when no entry is above.
fn budget_note(c: &Campaign, compare: &[crate::campaign::CompareRow]) -> Option<String> {
    let above = compare.iter().filter(|r| r.ratio.is_finite() && r.ratio > 1.0 + 1e-3).count();
    if above == 0 {
        return None;
    }
    let most = |f: &dyn Fn(&crate::campaign::Problem) -> f64| c.problems.iter().map(f).fold(0.0, f64::max);
    let cpumax = most(&|p| p.base.cpumax);
    let seeds = most(&|p| p.seeds.len() as f64);
    let evals = match c.problems.iter().map(|p| p.base.maxevals).collect::<Option<Vec<_>>>() {
        Some(v) => format!("{} evaluations (maxevals) or ", v.into_iter().max().unwrap_or(0)),
        None => String::new(),
    };
    Some(format!(
        "note: {above} entr{} above the paper (ratio > 1.001): this campaign gives a job at most {evals}{cpumax} CPU s \
         and runs {seeds} seed(s) per (n_K, ε); the paper's protocol (campaigns/strong-stab.toml) runs 10 seeds × 5 ε at \
         300 CPU s per job, and its run (results/strong-stab/) has every entry ≤ paper·(1 + 1e-3). More seeds or a \
         larger budget bring such entries down.",
        if above == 1 { "y is" } else { "ies are" },
    ))
}

/// Reduces `records` (the campaign's, duplicates included) to the report files in `dir` and
/// prints the comparison, and how many jobs were journaled more than once.
fn report_into(dir: &Path, c: &Campaign, records: &[JobRecord]) -> anyhow::Result<crate::campaign::CampaignReport> {
    let report = crate::campaign::report(dir, c, records)?;
    print_out(&report.summary.to_string()).context("writing to stdout")?;
    if let Some(note) = budget_note(c, &report.summary.compare) {
        print_out(&format!("{note}\n")).context("writing to stdout")?;
    }
    let dups = &report.duplicates;
    if !dups.is_empty() {
        let extra: usize = dups.iter().map(|(_, n)| n - 1).sum();
        eprintln!(
            "note: {} job(s) have more than one record ({extra} extra); each counts once, by its best verified record",
            dups.len()
        );
    }
    Ok(report)
}

/// `campaign run FILE`.
pub fn run(a: RunArgs, fake: Option<Box<dyn JobRunner>>) -> anyhow::Result<ExitCode> {
    let l = load(&a.campaign, fake)?;
    crate::fs_atomic::create_dir_all(&l.dir).with_context(|| format!("creating {}", l.dir.display()))?;
    let jobs = match a.shard {
        Some(s) => shard_jobs(&l.jobs, s),
        None => l.jobs.clone(),
    };
    let threads = l.campaign.threads(a.threads.map(|t| t as usize));
    let opts = ExecuteOptions::new(&l.campaign.name, threads);
    let cancel = opts.cancel.clone();
    signals::install_into(&cancel).context("installing the signal handlers")?;

    let runner: &dyn JobRunner = match &l.fake {
        Some(f) => f.as_ref(),
        None => &design_job,
    };
    let observers = trace_observers(&l.dir.join("traces"), l.campaign.trace_levels(a.trace));
    let mut reporter = Reporter::new(&jobs, ProgressDisplay::choose(a.no_progress));
    let (name, dir) = (for_terminal(&l.campaign.name), for_terminal(&l.dir.display().to_string()));
    match a.shard {
        Some(s) => eprintln!("campaign {name} shard {s}: {} of {} jobs → {dir}", jobs.len(), l.jobs.len()),
        None => eprintln!("campaign {name} → {dir}"),
    }
    let outcome = run_jobs(&jobs, &l.dir, runner, &observers, &opts, |ev| reporter.on_event(ev))?;
    if let Some(t) = &outcome.torn {
        eprintln!(
            "warning: {}: line {} was torn ({}); it was ignored and cut off",
            outcome.journal.display(),
            t.line,
            t.reason
        );
    }
    warn_torn(&outcome.torn_elsewhere);
    let s = &outcome.stats;
    eprintln!(
        "{} jobs: {} were already done, {} finished now ({} failed), {} done by other processes meanwhile, {} interrupted, {} not started",
        s.total, s.already_done, s.finished, s.failed, s.done_elsewhere, s.interrupted, s.not_started
    );
    if s.cancel.is_none() && s.not_started > 0 {
        eprintln!(
            "{} job(s) left to other processes that hold them (or their predecessors); `campaign status` shows them",
            s.not_started
        );
    }
    report_into(&l.dir, &l.campaign, &records_for(&l.jobs, &outcome.records))?;
    if outcome.interrupted() {
        eprintln!("interrupted: rerun the same command to resume");
        return Ok(ExitCode::from(signals::exit_code()));
    }
    if outcome.failed() > 0 {
        eprintln!("{} job(s) failed: see `campaign status` and the journals in {}", outcome.failed(), l.dir.display());
        return Ok(ExitCode::from(EXIT_JOBS_FAILED));
    }
    // A trace that could not be written (a full disk) is lost: the run must not look clean.
    if outcome.stats.warnings > 0 {
        eprintln!(
            "error: {} warning(s) above (e.g. traces that could not be written); the jobs' results are journaled",
            outcome.stats.warnings
        );
        return Ok(ExitCode::FAILURE);
    }
    Ok(ExitCode::SUCCESS)
}

fn warn_torn(torn: &[(PathBuf, TornTail)]) {
    for (path, t) in torn {
        eprintln!("warning: {}: line {} is torn ({}); ignored", path.display(), t.line, t.reason);
    }
}

/// Every record of this campaign's jobs (duplicates included) in every journal of its folder
/// and of `--journal` (torn tails reported on stderr), and the journals read.
fn journaled(l: &Loaded, extra: &JournalArgs) -> anyhow::Result<(Vec<JobRecord>, Vec<PathBuf>)> {
    let mut dirs = vec![l.dir.clone()];
    let mut files = Vec::new();
    for p in &extra.journals {
        if p.is_dir() {
            if journals_in(p)?.is_empty() {
                anyhow::bail!("--journal {}: the folder holds no journal (runs*.jsonl)", p.display());
            }
            dirs.push(p.clone());
        } else if p.is_file() {
            files.push(p.clone());
        } else {
            anyhow::bail!("--journal {}: no such file or folder", p.display());
        }
    }
    let mut follower = Follower::new(dirs, files, None);
    let records = follower.poll()?;
    warn_torn(&follower.torn());
    let (records, disagreeing) = crate::campaign::records_and_disagreements(&l.jobs, &records);
    for why in disagreeing {
        eprintln!("warning: a record of {why} (the line is damaged or edited); not counted");
    }
    Ok((records, follower.journals()))
}

/// `campaign status FILE`.
pub fn status(a: StatusArgs, fake: Option<Box<dyn JobRunner>>) -> anyhow::Result<ExitCode> {
    let l = load(&a.campaign, fake)?;
    let (records, journals) = journaled(&l, &a.extra)?;
    let s = crate::campaign::status(&l.jobs, &records, &l.dir)?;
    print!("{}", status_text(&l.campaign.name, &journals, &s));
    if let Some(n) = a.shards {
        let done = records.iter().map(|r| &r.job_id).collect();
        print_shards(&l, n as usize, l.campaign.threads(a.threads.map(|t| t as usize)), &done);
    }
    Ok(ExitCode::SUCCESS)
}

/// The status table, the running jobs, stale claims and duplicate records, for the terminal.
fn status_text(name: &str, journals: &[PathBuf], s: &CampaignStatus) -> String {
    let mut out = String::new();
    let names: Vec<String> = journals.iter().map(|p| p.display().to_string()).collect();
    out +=
        &format!("campaign {} ({} journal(s): {})\n", for_terminal(name), names.len(), for_terminal(&names.join(", ")));
    out +=
        &format!("{:<16} {:>6} {:>6} {:>8} {:>9} {:>7}\n", "plant", "jobs", "done", "running", "remaining", "failed");
    for p in s.plants.iter().chain([&s.total()]) {
        out += &format!(
            "{:<16} {:>6} {:>6} {:>8} {:>9} {:>7}\n",
            for_terminal(&p.plant),
            p.jobs,
            p.done,
            p.running,
            p.remaining(),
            p.failed
        );
    }
    if !s.running.is_empty() {
        out += "running:\n";
        for j in &s.running {
            let who = match &j.owner {
                Some(o) => {
                    format!("{}:{} for {:.0} s", o.host, o.pid, (crate::campaign::unix_now() - o.since_unix_s).max(0.0))
                }
                None => "(owner not written yet)".into(),
            };
            out += &format!("  {}  {}  {}\n", j.id.short(), for_terminal(&j.label), for_terminal(&who));
        }
    }
    if s.stale_claims > 0 {
        out += &format!(
            "{} claim(s) left by processes that died: those jobs run again at the next `campaign run`\n",
            s.stale_claims
        );
    }
    if !s.duplicates.is_empty() {
        out += &format!(
            "{} job(s) have more than one record; reports count each once, by its best verified record:\n",
            s.duplicates.len()
        );
        for d in &s.duplicates {
            let label = d.label.clone().unwrap_or_default();
            out += &format!("  {}  {}  {} records\n", d.id.short(), for_terminal(&label), d.records);
        }
    }
    out
}

/// The shard plan of `status --shards N` ([`shard_plan`]) over the jobs left to run (`done`: the
/// journaled ones). The array time limit adds 25 % and 10 minutes for start-up, reports and a
/// loaded node; with nothing left to run it says so (`scripts/slurm/campaign.sbatch` then
/// submits nothing).
fn print_shards(l: &Loaded, n: usize, threads: usize, done: &std::collections::HashSet<&crate::campaign::JobId>) {
    println!("{n} shard(s) at {threads} thread(s) each, jobs left to run:");
    println!("{:>8} {:>6} {:>12} {:>14}", "shard", "jobs", "cpu budget", "wall bound");
    let mut worst = 0.0f64;
    let plan = shard_plan(&l.jobs, n, threads, done);
    for (k, s) in plan.iter().enumerate() {
        worst = worst.max(s.wall_bound_s);
        println!("{:>8} {:>6} {:>10.0} s {:>12.0} s", format!("{}/{n}", k + 1), s.jobs, s.cpu_s, s.wall_bound_s);
    }
    if plan.iter().all(|s| s.jobs == 0) {
        println!("slurm time per task: none (nothing left to run)");
    } else {
        println!("slurm time per task: {}", slurm_time(worst * 1.25 + 600.0));
    }
}

/// Longest time limit `status --shards` spells out: 365 days. Beyond it (or with an infinite
/// `cpumax`) the plan has no meaningful bound, and Slurm's own word for that is used.
const MAX_SLURM_SECONDS: f64 = 365.0 * 86400.0;

/// A Slurm `--time` value (`D-HH:MM:SS`) for `seconds`, or `UNLIMITED` with the reason when it
/// is not finite or above [`MAX_SLURM_SECONDS`] (`cpumax = inf` printed 213503982334601 days).
fn slurm_time(seconds: f64) -> String {
    if !(seconds <= MAX_SLURM_SECONDS) {
        return "UNLIMITED (no time bound: a job's cpumax is infinite or the plan exceeds a year)".into();
    }
    let limit = seconds.ceil() as u64;
    format!("{}-{:02}:{:02}:{:02}", limit / 86400, limit % 86400 / 3600, limit % 3600 / 60, limit % 60)
}

/// The journaled records of this campaign's jobs ([`journaled`]); an error if there are none.
fn finished_records(l: &Loaded, extra: &JournalArgs) -> anyhow::Result<Vec<JobRecord>> {
    let (records, journals) = journaled(l, extra)?;
    if records.is_empty() {
        anyhow::bail!(
            "{}: no finished jobs of this campaign in {} journal(s) (run it first)",
            l.dir.display(),
            journals.len()
        );
    }
    Ok(records)
}

/// `campaign report FILE`: the tables, and the page `report/index.html` (`campaign::html`).
pub fn report(a: ReportArgs, fake: Option<Box<dyn JobRunner>>) -> anyhow::Result<ExitCode> {
    let l = load(&a.campaign, fake)?;
    let records = finished_records(&l, &a.extra)?;
    let r = report_into(&l.dir, &l.campaign, &records)?;
    let page = crate::campaign::write_html_report(&l.dir, &r.summary.best, &r.summary.compare, &records)?;
    eprintln!("report page: {}", for_terminal(&page.display().to_string()));
    Ok(ExitCode::SUCCESS)
}

/// `campaign plot FILE`: figures of the journaled jobs into `<results>/<name>/plots/`.
pub fn plot(a: PlotArgs, fake: Option<Box<dyn JobRunner>>) -> anyhow::Result<ExitCode> {
    let l = load(&a.campaign, fake)?;
    let records = finished_records(&l, &a.extra)?;
    let reference = load_default_reference().context("reading the paper's reference table")?;
    let library = crate::campaign::LibraryIndex::load_default()?;
    let (plants, problems) = (plant_map(&l.campaign), crate::campaign::problem_map(&l.campaign));
    let s = crate::campaign::plot::write_plots(&l.dir, &records, &plants, &problems, &reference, &library)?;
    for f in &s.files {
        print_out(&format!("{}\n", f.display())).context("writing to stdout")?;
    }
    for why in &s.skipped {
        eprintln!("skipped: {why}");
    }
    for why in &s.failed {
        eprintln!("error: {why}");
    }
    if !s.failed.is_empty() {
        eprintln!("error: {} figure(s) could not be made; the others were written", s.failed.len());
        return Ok(ExitCode::FAILURE);
    }
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slurm_time_is_bounded() {
        // Cpumax = inf gave a time of 213503982334601 days.
        assert_eq!(slurm_time(90061.2), "1-01:01:02");
        assert!(slurm_time(f64::INFINITY).starts_with("UNLIMITED"));
        assert!(slurm_time(f64::NAN).starts_with("UNLIMITED"));
        assert!(slurm_time(1e300).starts_with("UNLIMITED"));
    }
}
