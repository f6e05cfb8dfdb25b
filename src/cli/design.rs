//! `campaign design --plant NAME|PATH --order K [--eps 1e-3] [--seed 7] [--cpumax 60] [--nrand 3]
//! [--init K.json] [--no-strong] [--json] --out K.json`: one HIFOO design. Prints a short summary
//! (or the whole outcome as JSON with `--json`) and writes the controller file that
//! `campaign check` reads, atomically and durably (`hinfix::fs_atomic`).
//!
//! Every outcome (including "not stabilised") writes the returned controller and exits 0, except
//! an interrupt (Ctrl-C cancels the run; the best controller so far is still written), which
//! exits 130.
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use anyhow::Context;
use hinfix::design::{run_with_control, DesignOptions, DesignOutcome, DesignStatus, NoDesignObserver, ObjectiveKind};
use hinfix::fs_atomic::write_atomic;
use hinfix::lti::{resolve_plant, Controller, Plant};
use hinfix::optim::RunControl;

use super::EXIT_INTERRUPTED;

/// Arguments of `campaign design`.
#[derive(clap::Args, Debug)]
pub struct DesignArgs {
    /// Plant name (from plants/) or path to a plant file (JSON, or MATLAB .mat with A B1 B2 C1 C2 D11 D12 D21 D22).
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
    /// CPU-second budget of the whole design.
    #[arg(long, default_value_t = 60.0)]
    pub cpumax: f64,
    /// Number of random starts (or of perturbations of --init).
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
    let cancel = Arc::new(AtomicBool::new(false));
    {
        let cancel = Arc::clone(&cancel);
        // Not fatal if a handler is already installed (e.g. in tests).
        let _ = ctrlc::set_handler(move || cancel.store(true, Ordering::Relaxed));
    }
    let ctl = RunControl::new(opts.cpumax).with_cancel(Arc::clone(&cancel));
    let outcome = run_with_control(&plant, &opts, init.as_ref(), &ctl, &mut NoDesignObserver)
        .with_context(|| format!("designing an order-{} controller for {}", a.order, plant.name))?;
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
    Ok(if outcome.status == DesignStatus::Interrupted { ExitCode::from(EXIT_INTERRUPTED) } else { ExitCode::SUCCESS })
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
    if let (Some(d), Some(e)) = (o.dnorm, o.evaldist) {
        s += &format!("certificate: dnorm = {d:.2e}, evaldist = {e:.2e}\n");
    }
    s += &format!("controller written to {}\n", out.display());
    s
}
