//! `campaign design --plant NAME|PATH --order K [--eps 1e-3] [--seed 7] [--cpumax 60] [--nrand 3]
//! [--maxevals N] [--stall-starts 60] [--stall-rtol 1e-6] [--max-starts N] [--hop-scales 0.01,0.1,1]
//! [--init K.json] [--no-strong] [--json] --out K.json`: one HIFOO design. Prints a short summary
//! (or the whole outcome as JSON with `--json`) and writes the controller file that
//! `campaign check` reads, atomically (temporary file + rename).
//!
//! Every outcome (including "not stabilised") writes the returned controller and exits 0, except
//! an interrupt (Ctrl-C cancels the run; the best controller so far is still written), which
//! exits 130.
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use anyhow::Context;
use hinfix::design::{
    run_with_control, DesignOptions, DesignOutcome, DesignStatus, NoDesignObserver, ObjectiveKind, DEFAULT_STALL_STARTS,
};
use hinfix::lti::{resolve_plant, Controller, Plant};
use hinfix::optim::RunControl;

use super::EXIT_INTERRUPTED;

/// Arguments of `campaign design`.
#[derive(clap::Args, Debug)]
pub struct DesignArgs {
    /// Plant name (from plants/) or path to a plant JSON file.
    #[arg(long)]
    pub plant: String,
    /// Controller order nk ≥ 0.
    #[arg(long)]
    pub order: usize,
    /// Weight ε of ‖K‖∞ and α(Ak) (strong stabilisation).
    #[arg(long, default_value_t = 1e-3)]
    pub eps: f64,
    /// Seed of the random starting points.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// CPU-second budget of the whole design (thread CPU time; a run it ends is not
    /// reproducible bit for bit).
    #[arg(long, default_value_t = 60.0)]
    pub cpumax: f64,
    /// Evaluation budget of the whole design (deterministic: same seed, same controller).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    pub maxevals: Option<u64>,
    /// Number of first random starts (HIFOO's nrand), or of perturbations of --init.
    #[arg(long, default_value_t = 3)]
    pub nrand: usize,
    /// After the first starts, keep starting local searches (basin hops of the best point and
    /// random starts) until this many in a row have not improved the best objective by
    /// --stall-rtol, or a budget ends the run. While no stabilising controller is found, only a
    /// budget ends it. 0: HIFOO's search (the first starts only).
    #[arg(long, value_name = "K", default_value_t = DEFAULT_STALL_STARTS)]
    pub stall_starts: usize,
    /// Relative improvement that resets the stall count.
    #[arg(long, value_name = "R", default_value_t = 1e-6)]
    pub stall_rtol: f64,
    /// Largest number of local searches (first starts included; deterministic).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..))]
    pub max_starts: Option<u64>,
    /// Relative sizes of the basin-hopping perturbations of the best point, comma-separated
    /// (one hop per size, then one random start, in turn). "none": random starts only.
    #[arg(long, value_name = "R,R,...", default_value = "0.01,0.1,1")]
    pub hop_scales: String,
    /// Initial controller JSON (order ≤ --order; a lower order is padded with stable modes).
    #[arg(long)]
    pub init: Option<PathBuf>,
    /// Plain fixed-order H∞: do not require a stable controller.
    #[arg(long)]
    pub no_strong: bool,
    /// Print the whole outcome as JSON instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// Where to write the controller JSON {AK, BK, CK, DK}.
    #[arg(long)]
    pub out: PathBuf,
}

pub fn run(a: DesignArgs) -> anyhow::Result<ExitCode> {
    let plant_file = resolve_plant(&a.plant)?;
    let plant = Plant::load(&plant_file)?;
    let init = match &a.init {
        Some(path) => Some(Controller::load(path)?),
        None => None,
    };
    let opts = DesignOptions {
        order: a.order,
        eps: a.eps,
        seed: a.seed,
        cpumax: a.cpumax,
        maxevals: a.maxevals.map(|n| n as usize),
        nrand: a.nrand,
        stall_starts: a.stall_starts,
        stall_rtol: a.stall_rtol,
        max_starts: a.max_starts.map(|n| n as usize),
        hop_scales: parse_scales(&a.hop_scales)?,
        objective: if a.no_strong { ObjectiveKind::Plain } else { ObjectiveKind::Strong },
        ..Default::default()
    };
    let cancel = Arc::new(AtomicBool::new(false));
    {
        let cancel = Arc::clone(&cancel);
        // Not fatal if a handler is already installed (e.g. in tests).
        let _ = ctrlc::set_handler(move || cancel.store(true, Ordering::Relaxed));
    }
    let ctl = RunControl::new(opts.cpumax).with_cancel(Arc::clone(&cancel));
    let outcome = run_with_control(&plant, &opts, init.as_ref(), &ctl, &mut NoDesignObserver)
        .with_context(|| format!("designing an order-{} controller for {}", a.order, plant.name))?;
    let text = serde_json::to_string_pretty(&outcome.controller)? + "\n";
    write_atomically(&a.out, &text).with_context(|| format!("writing {}", a.out.display()))?;
    if a.json {
        println!("{}", serde_json::to_string_pretty(&outcome)?);
    } else {
        print!("{}", summary(&plant, &opts, &outcome, &a.out));
    }
    Ok(if outcome.status == DesignStatus::Interrupted { ExitCode::from(EXIT_INTERRUPTED) } else { ExitCode::SUCCESS })
}

/// `--hop-scales`: comma-separated positive numbers, or "none" (empty).
fn parse_scales(text: &str) -> anyhow::Result<Vec<f64>> {
    if text.trim() == "none" || text.trim().is_empty() {
        return Ok(Vec::new());
    }
    text.split(',')
        .map(|t| match t.trim().parse::<f64>() {
            Ok(r) if r.is_finite() && r > 0.0 => Ok(r),
            _ => anyhow::bail!("--hop-scales: {t:?} is not a finite positive number"),
        })
        .collect()
}

/// Writes `text` to `path` via `path.tmp` + rename, so a reader never sees a partial file.
fn write_atomically(path: &Path, text: &str) -> std::io::Result<()> {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    let tmp = PathBuf::from(tmp);
    std::fs::write(&tmp, text)?;
    std::fs::rename(&tmp, path)
}

fn status_text(s: &DesignStatus) -> String {
    match s {
        DesignStatus::Optimised => "optimised".into(),
        DesignStatus::StabilisedOnly => "stabilised only (the optimisation made no progress)".into(),
        DesignStatus::NotStabilised { best_alpha } => {
            format!("NOT STABILISED (best max(α(A_cl), ε·α(Ak)) = {best_alpha:+.6e})")
        }
        DesignStatus::BudgetExhausted => "CPU budget exhausted (best controller so far)".into(),
        DesignStatus::Interrupted => "interrupted (best controller so far)".into(),
    }
}

fn summary(plant: &Plant, opts: &DesignOptions, o: &DesignOutcome, out: &Path) -> String {
    let mode = match opts.objective {
        ObjectiveKind::Strong => format!("strong stabilisation, ε = {:e}", opts.eps),
        ObjectiveKind::Plain => "plain H∞".to_string(),
    };
    let mut s = format!("{} (n = {}), order {}, {}, seed {}\n", plant.name, plant.dims.n, opts.order, mode, opts.seed);
    s += &format!("status:   {}\n", status_text(&o.status));
    s += &format!("‖Tzw‖∞ = {:.6}   ‖K‖∞ = {:.6}   objective = {:.6}\n", o.gamma, o.k_hinf, o.objective);
    s += &format!("α(A_cl) = {:+.4e}", o.alpha_cl);
    match o.alpha_k {
        Some(a) => s += &format!("   α(Ak) = {a:+.4e}\n"),
        None => s += "   (static gain)\n",
    }
    let per_eval = if o.evals > 0 { o.cpu_s / o.evals as f64 } else { f64::NAN };
    s += &format!("CPU {:.2} s, {} iterations, {} evaluations ({:.3} ms/eval)\n", o.cpu_s, o.iters, o.evals, 1e3 * per_eval);
    let sr = &o.search;
    s += &format!(
        "search: {} local searches, best from start {}, reached after {:.2} CPU s ({} evaluations), stopped: {}\n",
        sr.starts,
        sr.best_start,
        sr.cpu_to_best_s,
        sr.evals_to_best,
        sr.stop.name()
    );
    if let (Some(d), Some(e)) = (o.dnorm, o.evaldist) {
        s += &format!("certificate: dnorm = {d:.2e}, evaldist = {e:.2e}\n");
    }
    s += &format!("controller written to {}\n", out.display());
    s
}
