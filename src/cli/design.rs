//! `campaign design --plant NAME|PATH --order K [--eps 1e-3] [--seed 7] [--cpumax 60] [--nrand 3]
//! [--init K.json] [--no-strong] [--json] --out K.json`: one HIFOO design. Prints a short summary
//! (or the whole outcome as JSON with `--json`) and writes the controller file that
//! `campaign check` reads, atomically and durably (`hinfix::fs_atomic`).
//!
//! Every outcome writes the returned controller. Exit codes: 0 for a stabilising controller
//! (converged, stopped by a limit, budget exhausted, stabilised only), 4 when it is NOT
//! STABILISED, 130/143/129 after Ctrl-C/SIGTERM/SIGHUP (the run is cancelled; the best
//! controller so far is still written). `--out` is checked (not a directory, writable) before
//! the design starts.
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;

use anyhow::Context;
use hinfix::design::{run_with_control, DesignOptions, DesignOutcome, DesignStatus, NoDesignObserver, ObjectiveKind};
use hinfix::fs_atomic::write_atomic;
use hinfix::lti::{resolve_plant, Controller, Plant};
use hinfix::optim::RunControl;

use super::{fmt_num, signals, EXIT_NOT_STABILISED};
use hinfix::campaign::sanitise::for_terminal;

/// Arguments of `campaign design`.
#[derive(clap::Args, Debug)]
pub struct DesignArgs {
    /// Plant name (from plants/) or path to a plant file (JSON, or MATLAB .mat with A B1 B2 C1 C2 D11 D12 D21 D22).
    #[arg(long)]
    pub plant: String,
    /// Controller order nk ≥ 0.
    #[arg(long)]
    pub order: usize,
    /// Weight ε of ‖K‖∞ and α(Ak) (strong stabilisation), > 0.
    #[arg(long, default_value_t = 1e-3, allow_negative_numbers = true)]
    pub eps: f64,
    /// Seed of the random starting points.
    #[arg(long, default_value_t = 0)]
    pub seed: u64,
    /// CPU-second budget of the whole design, > 0.
    #[arg(long, default_value_t = 60.0, allow_negative_numbers = true)]
    pub cpumax: f64,
    /// Number of random starts (or of perturbations of --init), 1..=10000.
    #[arg(long, default_value_t = 3)]
    pub nrand: usize,
    /// Initial controller, JSON or .mat (order ≤ --order; a lower order is padded with stable modes).
    #[arg(long)]
    pub init: Option<PathBuf>,
    /// Plain fixed-order H∞: do not require a stable controller.
    #[arg(long)]
    pub no_strong: bool,
    /// Print the whole outcome as JSON instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// Where to write the controller: JSON {AK, BK, CK, DK}, or a MATLAB level-5 file with the
    /// variables AK BK CK DK when the name ends in `.mat`.
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
        nrand: a.nrand,
        objective: if a.no_strong { ObjectiveKind::Plain } else { ObjectiveKind::Strong },
        ..Default::default()
    };
    // Bad options and an unusable --out are errors before any work (and before any file is made).
    hinfix::design::validate(&plant, &opts, init.as_ref())
        .with_context(|| format!("designing an order-{} controller for {}", a.order, for_terminal(&plant.name)))?;
    check_writable(&a.out).with_context(|| format!("--out {}", a.out.display()))?;
    let cancel = signals::install();
    let ctl = RunControl::new(opts.cpumax).with_cancel(Arc::clone(&cancel));
    let outcome = run_with_control(&plant, &opts, init.as_ref(), &ctl, &mut NoDesignObserver)
        .with_context(|| format!("designing an order-{} controller for {}", a.order, for_terminal(&plant.name)))?;
    if hinfix::lti::mat_file::is_mat_path(&a.out) {
        let k = Controller::from_json_value(&outcome.controller).context("the designed controller")?;
        k.save(&a.out).with_context(|| format!("writing {}", a.out.display()))?;
    } else {
        let text = serde_json::to_string_pretty(&outcome.controller)? + "\n";
        write_atomic(&a.out, text.as_bytes()).with_context(|| format!("writing {}", a.out.display()))?;
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&outcome)?);
    } else {
        print!("{}", summary(&plant, &opts, &outcome, &a.out));
    }
    Ok(match outcome.status {
        DesignStatus::Interrupted => ExitCode::from(signals::exit_code()),
        DesignStatus::NotStabilised { .. } => ExitCode::from(EXIT_NOT_STABILISED),
        _ => ExitCode::SUCCESS,
    })
}

/// `path` can receive the controller: not a directory, and its `.tmp` sibling can be created
/// (it is removed again).
fn check_writable(path: &Path) -> anyhow::Result<()> {
    if path.is_dir() {
        anyhow::bail!("is a directory; give a file name such as {}", path.join("K.json").display());
    }
    let tmp = tmp_path(path);
    std::fs::OpenOptions::new().write(true).create(true).truncate(true).open(&tmp)?;
    std::fs::remove_file(&tmp)?;
    Ok(())
}

fn tmp_path(path: &Path) -> PathBuf {
    let mut tmp = path.as_os_str().to_owned();
    tmp.push(".tmp");
    PathBuf::from(tmp)
}

fn status_text(s: &DesignStatus) -> String {
    match s {
        DesignStatus::Converged => "converged (optimality certificate met)".into(),
        DesignStatus::Stopped => "stopped by a limit before the optimality certificate was met".into(),
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
    let mut s = format!("{} (n = {}), order {}, {}, seed {}\n", for_terminal(&plant.name), plant.dims.n, opts.order, mode, opts.seed);
    s += &format!("status:   {}\n", status_text(&o.status));
    s += &format!("‖Tzw‖∞ = {}   ‖K‖∞ = {}   objective = {}\n", fmt_num(o.gamma, 6), fmt_num(o.k_hinf, 6), fmt_num(o.objective, 6));
    if o.controller_norm_active {
        s += &format!(
            "note:     ε‖K‖∞ = {} ≥ ‖Tzw‖∞: the controller-norm penalty, not the closed loop, sets the objective (a smaller ε lets γ go lower)\n",
            fmt_num(opts.eps * o.k_hinf, 6)
        );
    }
    s += &format!("α(A_cl) = {:+.4e}", o.alpha_cl);
    match o.alpha_k {
        Some(a) => s += &format!("   α(Ak) = {a:+.4e}\n"),
        None => s += "   (static gain)\n",
    }
    let per_eval = if o.evals > 0 { o.cpu_s / o.evals as f64 } else { f64::NAN };
    s += &format!("CPU {:.2} s, {} iterations, {} evaluations ({:.3} ms/eval)\n", o.cpu_s, o.iters, o.evals, 1e3 * per_eval);
    if let (Some(d), Some(e)) = (o.dnorm, o.evaldist) {
        s += &format!("certificate: dnorm = {d:.2e}, evaldist = {e:.2e}\n");
    }
    s += &format!("controller written to {}\n", out.display());
    s
}
