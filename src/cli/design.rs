//! `campaign design --plant NAME|PATH --order K [--eps 1e-3] [--seed 7] [--cpumax 60] [--nrand 3]
//! [--maxevals N] [--stall-starts 60] [--stall-rtol 1e-6] [--stop-on-stall] [--max-starts N] [--hop-scales 0.01,0.1,1]
//! [--central-gammas 1.1,2] [--random-scales 1,0.1,0.01] [--no-open-loop-start] [--no-continue-at-maxit]
//! [--continued-maxit 3000] [--keep-gs-reserve]
//! [--variable-scaling off|alternate|always] [--init K.json] [--structure S.json] [--no-strong] [--json] [--out K.json]`: one HIFOO design. Prints a short summary
//! (or the whole outcome as JSON with `--json`) and writes the controller file that
//! `campaign check` reads, atomically and durably (`crate::fs_atomic`). `--out` may be left out
//! with `--json` only (the controller is then in the JSON, `controller`, and no file is written).
//!
//! Only a stabilising controller (closed loop stable and, with the strong objective, the
//! controller too, both with the verification margin of `lti::is_stable_with_margin`) is written
//! to `--out`; a run that found none writes nothing there, and with `--out-unverified` writes the
//! controller it ended with next to it as `<stem>.unverified.<ext>`, a name that says what it is.
//! With the strong objective, a plant that no stable controller stabilises (the parity
//! interlacing property fails) is refused at once, naming the zeros and poles that prove it.
//! Exit codes: 0 for a stabilising controller (converged, stopped by a limit, budget exhausted,
//! stabilised only), 4 when it is NOT STABILISED or the plant is not strongly stabilisable, 5
//! when it stabilises but a plant's bound does not hold (status `bound_violated`),
//! 130/143/129 after Ctrl-C/SIGTERM/SIGHUP (the run is cancelled; the best controller so far is
//! still written if it stabilises). `--out` is checked (not a directory, writable, with a
//! probe file of a unique name, so that concurrent runs writing one file do not trip) before
//! the design starts.
//!
//! `--structure S.json` designs a structured controller (docs/ALGORITHMS.md §1.1): a JSON object
//! `{"AK": [[null, 0.0], …], "BK": …, "CK": …, "DK": …}` in which `null` is a free entry and a
//! number an entry fixed at that value (bit for bit in the result); each block given has the
//! shape of --order, a block left out is free, and a structure with no free entry is an error.
//! A `.mat` file with variables AK, BK, CK, DK is read the same way, NaN = free.
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;

use crate::design::{
    stabilises, ControllerShape, Design, DesignOptions, DesignOutcome, DesignStatus, ObjectiveKind, PlantObjective,
    PlantTerm, PlantValue, Problem, SearchStop, Structure, VariableScaling,
};
use crate::fs_atomic::write_atomic;
use crate::lti::{resolve_plant, Controller, Plant, TimeDomain};
use anyhow::Context;

use super::{fmt_num, print_out, signals, EXIT_BOUND_VIOLATED, EXIT_NOT_STABILISED};
use crate::campaign::for_terminal;

/// The default of a flag: the option's default ([`DesignOptions::default`], the option table of
/// design/options.rs), never a literal of its own.
fn default() -> DesignOptions {
    DesignOptions::default()
}

/// A list default as the comma-separated text its flag reads (`0.01,0.1,1`; `none` when empty).
fn list_text(v: &[f64]) -> String {
    if v.is_empty() {
        "none".into()
    } else {
        v.iter().map(|x| x.to_string()).collect::<Vec<_>>().join(",")
    }
}

/// Arguments of `campaign design`. Each flag's default is its option's
/// ([`DesignOptions::default`]); a switch names the side that is not the default.
#[derive(clap::Args, Debug)]
pub struct DesignArgs {
    /// Plant name (from plants/) or path to a plant file (JSON, or MATLAB .mat with A B1 B2 C1 C2 D11 D12 D21 D22).
    /// Repeat it to design one controller for several plants (docs/ALGORITHMS.md §14): every
    /// plant is stabilised, and the largest weighted objective of the plants without a bound is
    /// minimised subject to the bounds.
    #[arg(long, required = true)]
    pub plant: Vec<String>,
    /// The objective of each plant: hinf (‖Tzw‖∞), h2 (‖Tzw‖₂; continuous time keeps
    /// D11 + D12·DK·D21 = 0 and needs D22 = 0), abscissa (the closed loop's spectral abscissa,
    /// ρ − 1 in discrete time) or radius (1/r_C, the reciprocal of the complex stability radius).
    /// Given once (every plant) or once per --plant, in their order. Default hinf.
    #[arg(long, value_name = "hinf|h2|abscissa|radius", value_parser = clap::value_parser!(PlantObjective))]
    pub objective: Vec<PlantObjective>,
    /// The weight w > 0 of each plant's objective: once (every plant) or once per --plant. Default 1.
    #[arg(long, value_name = "W", allow_hyphen_values = true)]
    pub weight: Vec<f64>,
    /// A bound b on a plant's weighted objective (w·g ≤ b, an exact penalty; that plant is then
    /// not in the minimised max): once (every plant) or once per --plant, "none" for no bound.
    /// Default none.
    #[arg(long, value_name = "B|none", allow_hyphen_values = true)]
    pub bound: Vec<String>,
    /// Controller order nk ≥ 0.
    #[arg(long, allow_hyphen_values = true)]
    pub order: usize,
    /// Weight ε of ‖K‖∞ and α(Ak) (strong stabilisation), > 0.
    #[arg(long, default_value_t = default().eps, allow_hyphen_values = true)]
    pub eps: f64,
    /// Seed of the random starting points.
    #[arg(long, default_value_t = default().seed, allow_hyphen_values = true)]
    pub seed: u64,
    /// Budget of the whole design in CPU seconds (thread CPU time, not wall-clock time; a run
    /// it ends is not reproducible bit for bit).
    #[arg(long, default_value_t = default().cpumax, allow_hyphen_values = true)]
    pub cpumax: f64,
    /// Evaluation budget of the whole design (deterministic: same seed, same controller).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..), allow_hyphen_values = true)]
    pub maxevals: Option<u64>,
    /// Number of first random starts (HIFOO's nrand), or of perturbations of --init, 1..=10000.
    #[arg(long, default_value_t = default().nrand, allow_hyphen_values = true)]
    pub nrand: usize,
    /// After the first starts, keep starting local searches (basin hops of the best point and
    /// random starts) until a budget ends the run. The stall rule — this many local searches in
    /// a row have not improved the best objective by --stall-rtol — ends runs without any budget
    /// (--cpumax inf and no --maxevals, --max-starts), or with --stop-on-stall any run once a
    /// stabilising controller is found. 0: HIFOO's search (the first starts only).
    #[arg(long, value_name = "K", default_value_t = default().stall_starts, allow_hyphen_values = true)]
    pub stall_starts: usize,
    /// Relative improvement that resets the stall count.
    #[arg(long, value_name = "R", default_value_t = default().stall_rtol, allow_hyphen_values = true)]
    pub stall_rtol: f64,
    /// Stall rule in CPU time: the stall rule also ends the run once this many CPU seconds
    /// passed without an improvement by --stall-rtol (same conditions). 0: off.
    #[arg(long, value_name = "S", default_value_t = default().stall_cpu, allow_hyphen_values = true)]
    pub stall_cpu: f64,
    /// Let the stall rule end the run even when a budget (--cpumax, --maxevals, --max-starts)
    /// bounds it. By default a bounded run spends its budget: once a stabilising controller is
    /// found, the continued search goes on until a budget ends it, and the stall rule ends only
    /// runs without any budget.
    #[arg(long)]
    pub stop_on_stall: bool,
    /// Do not resume the best point's local search when BFGS stopped it at its iteration limit
    /// (by default the next continued start is that point itself, with a fresh BFGS).
    #[arg(long)]
    pub no_continue_at_maxit: bool,
    /// BFGS iteration limit of the continued search's local searches on the H∞ objective
    /// (HIFOO's first starts keep its 1000); 0: the same 1000. Only local searches on many
    /// variables reach it.
    #[arg(long, value_name = "N", default_value_t = default().continued_maxit, allow_hyphen_values = true)]
    pub continued_maxit: usize,
    /// Restart every BFGS run's inverse-Hessian approximation at the identity after every this
    /// many iterations (the run goes on from its point; docs/ALGORITHMS.md §7.1). 0: never, as
    /// HIFOO.
    #[arg(long, value_name = "N", default_value_t = default().bfgs_restart, allow_hyphen_values = true)]
    pub bfgs_restart: usize,
    /// Keep the whole gradient-sampling reserve (10 % of the budget) to the end. By default
    /// gradient sampling runs on the best controller right after the --nrand first starts (as
    /// HIFOO's search does) and the search keeps only twice what that took; gradient sampling
    /// runs again at the end if the best controller changed.
    #[arg(long)]
    pub keep_gs_reserve: bool,
    /// Refine near-misses: a local search of the continued search that ends without a
    /// certificate at most this relative amount above the best controller gets gradient sampling
    /// from its end point, so that its basin is judged by a refined value, as the best one's is.
    /// 0: none (the default; 0.03 is the value measured in docs/ALGORITHMS.md §8.3).
    #[arg(long, value_name = "R", default_value_t = default().refine_rtol, allow_hyphen_values = true)]
    pub refine_rtol: f64,
    /// Largest number of local searches (first starts included; deterministic).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u64).range(1..), allow_hyphen_values = true)]
    pub max_starts: Option<u64>,
    /// Relative sizes of the basin-hopping perturbations of the best point, comma-separated
    /// (one hop per size, then one random start, in turn). "none": random starts only.
    #[arg(long, value_name = "R,R,...", default_value_t = list_text(&default().hop_scales), allow_hyphen_values = true)]
    pub hop_scales: String,
    /// Scales σ of the continued search's fresh random starts σ·N(0, I), comma-separated, used in
    /// turn (the first --nrand starts are always standard normal). Small scales reach small
    /// gains, which badly scaled plants need to be stabilised.
    #[arg(long, value_name = "S,S,...", default_value_t = list_text(&default().random_scales), allow_hyphen_values = true)]
    pub random_scales: String,
    /// Do not make the open-loop start K = 0 (by default one more first start after the random
    /// ones: Bk, Ck, Dk = 0 and Ak a stable diagonal).
    #[arg(long)]
    pub no_open_loop_start: bool,
    /// Coordinates of the local searches: "off" (the controller's parameters), "alternate"
    /// (HIFOO's first starts and the open-loop start unscaled, each central start unscaled and
    /// then scaled; then three hop cycles in four in the coordinates that
    /// found the best controller so far and one in the others: the parameters, or variables
    /// scaled by the plant's control and measurement channel sizes) or "always" (scaled only; a
    /// bare --variable-scaling). No change for a plant whose
    /// channels are within 2^10 of each other. Plants whose channels differ by orders of
    /// magnitude (AC10) need the scaled searches, others (BDT2) do better unscaled.
    #[arg(long, value_name = "MODE", default_value = default().variable_scaling.name(), num_args = 0..=1,
          default_missing_value = "always", value_parser = VariableScaling::parse)]
    pub variable_scaling: VariableScaling,
    /// Reduced-order central-controller starts: factors f > 1, comma-separated; for each, the
    /// full-order H∞ central controller at f·gamma_opt, reduced to --order by balanced
    /// truncation, is one more first start (plants with ≤ 100 states). "none": no such starts.
    #[arg(long, value_name = "F,F,...", default_value_t = list_text(&default().central_gammas), allow_hyphen_values = true)]
    pub central_gammas: String,
    /// Initial controller, JSON or .mat (order ≤ --order; a lower order is padded with stable modes).
    #[arg(long)]
    pub init: Option<PathBuf>,
    /// Controller structure, JSON {"AK": [[null, 0.0], …], "BK": …, "CK": …, "DK": …}: null = free,
    /// a number = fixed at that value; blocks of the shapes of --order, a block left out is free.
    /// Or a .mat file with variables AK BK CK DK, NaN = free.
    /// Initial, open-loop and central starts are projected onto it (fixed entries overwritten).
    #[arg(long, value_name = "S.json")]
    pub structure: Option<PathBuf>,
    /// Plain fixed-order H∞: do not require a stable controller.
    #[arg(long)]
    pub no_strong: bool,
    /// Print the whole outcome as JSON instead of the summary.
    #[arg(long)]
    pub json: bool,
    /// Where to write the controller: JSON {AK, BK, CK, DK}, or a MATLAB level-5 file with the
    /// variables AK BK CK DK when the name ends in `.mat`. Only a stabilising controller is
    /// written here. Required unless --json is given (the JSON holds the controller).
    #[arg(long, required_unless_present = "json")]
    pub out: Option<PathBuf>,
    /// When the run finds no stabilising controller, write the one it ended with anyway, as
    /// `<stem>.unverified.<ext>` next to --out (never to --out itself).
    #[arg(long, requires = "out")]
    pub out_unverified: bool,
}

/// Where `--out-unverified` writes a controller that does not stabilise: `K.json` →
/// `K.unverified.json`.
fn unverified_path(out: &Path) -> PathBuf {
    let stem = out.file_stem().map_or_else(|| "controller".into(), |s| s.to_string_lossy().into_owned());
    let name = match out.extension() {
        Some(ext) => format!("{stem}.unverified.{}", ext.to_string_lossy()),
        None => format!("{stem}.unverified"),
    };
    out.with_file_name(name)
}

/// Whether `o`'s controller stabilises every plant as the objective asks: the closed loops and
/// (strong objective) the controller stable with the verification margin (`design::stabilises`,
/// the test `campaign report` applies to a journaled controller).
fn stabilising(problem: &Problem, opts: &DesignOptions, o: &DesignOutcome) -> bool {
    !matches!(o.status, DesignStatus::NotStabilised { .. }) && stabilises(problem, opts, &o.controller).is_ok()
}

/// A per-plant list of `flag`'s values: none (every plant `default`), one (every plant), or one
/// per plant.
fn per_plant<T: Clone>(values: &[T], nplants: usize, default: T, flag: &str) -> anyhow::Result<Vec<T>> {
    match values.len() {
        0 => Ok(vec![default; nplants]),
        1 => Ok(vec![values[0].clone(); nplants]),
        n if n == nplants => Ok(values.to_vec()),
        n => anyhow::bail!(
            "{flag} is given {n} times for {nplants} --plant(s): give it once (for every plant) or once per --plant"
        ),
    }
}

/// `--bound`: a finite number, or "none".
fn parse_bound(text: &str) -> anyhow::Result<Option<f64>> {
    match text.trim() {
        "none" => Ok(None),
        t => match t.parse::<f64>() {
            Ok(b) if b.is_finite() => Ok(Some(b)),
            _ => anyhow::bail!("--bound: {t:?} is not a finite number or \"none\""),
        },
    }
}

/// The problem the `--plant`, `--objective`, `--weight` and `--bound` flags describe.
pub fn problem(a: &DesignArgs) -> anyhow::Result<Problem> {
    let n = a.plant.len();
    let objectives = per_plant(&a.objective, n, PlantObjective::Hinf, "--objective")?;
    let weights = per_plant(&a.weight, n, 1.0, "--weight")?;
    let bounds = per_plant(&a.bound, n, "none".to_string(), "--bound")?;
    let mut terms = Vec::with_capacity(n);
    for (i, name) in a.plant.iter().enumerate() {
        let plant = Plant::load(&resolve_plant(name)?)?;
        let bound = parse_bound(&bounds[i])?;
        terms.push(PlantTerm { plant, objective: objectives[i], weight: weights[i], bound });
    }
    let problem = Problem { terms };
    problem.validate()?;
    Ok(problem)
}

pub fn run(a: DesignArgs) -> anyhow::Result<ExitCode> {
    let problem = problem(&a)?;
    let plant = problem.first();
    let init = match &a.init {
        Some(path) => Some(Controller::load(path)?),
        None => None,
    };
    let opts = options(&a)?;
    // Bad options and an unusable --out are errors before any work (and before any file is made).
    for t in &problem.terms {
        crate::design::validate(&t.plant, &opts, init.as_ref()).with_context(|| {
            // the initial controller's file, where it is the one that does not fit
            let init_file = a.init.as_ref().map_or(String::new(), |p| format!(" from --init {}", p.display()));
            format!("designing an order-{} controller for {}{init_file}", a.order, for_terminal(&t.plant.name))
        })?;
    }
    for t in &problem.terms {
        if let Err(e) = crate::design::strongly_stabilisable(&t.plant, &opts) {
            eprintln!("error: {} (order {}, strong objective): {e}", for_terminal(&t.plant.name), a.order);
            return Ok(ExitCode::from(EXIT_NOT_STABILISED));
        }
    }
    let structure = match &a.structure {
        Some(path) => {
            Some(Structure::load(path, ControllerShape::for_plant(plant, opts.order)).context("--structure")?)
        }
        None => None,
    };
    let names = problem.terms.iter().map(|t| for_terminal(&t.plant.name)).collect::<Vec<_>>().join(", ");
    if let Some(out) = &a.out {
        check_writable(out).with_context(|| format!("--out {}", out.display()))?;
    }
    let cancel = signals::install();
    let outcome = Design::new(&problem, &opts)
        .init(init.as_ref())
        .structure(structure.as_ref())
        .cancel(Arc::clone(&cancel))
        .run()
        .with_context(|| format!("designing an order-{} controller for {names}", a.order))?;
    let good = stabilising(&problem, &opts, &outcome);
    // A stabilising result has a finite γ; NaN or ∞ would be a failed computation called success.
    let stabilising = !matches!(outcome.status, DesignStatus::NotStabilised { .. } | DesignStatus::Interrupted);
    if stabilising && !(outcome.gamma.is_finite() && outcome.objective.is_finite()) {
        anyhow::bail!(
            "designing an order-{} controller for {names}: the result's ‖Tzw‖∞ = {} (objective {}) is not finite for a \
             stable closed loop; the numbers are out of the range the norm can be computed in, no controller written",
            a.order,
            outcome.gamma,
            outcome.objective
        );
    }
    let written = match (&a.out, good, a.out_unverified) {
        (None, _, _) => None,
        (Some(out), true, _) => Some(out.clone()),
        (Some(out), false, true) => Some(unverified_path(out)),
        (Some(_), false, false) => None,
    };
    if let Some(path) = &written {
        if crate::lti::is_mat_path(path) {
            outcome.controller.save(path).with_context(|| format!("writing {}", path.display()))?;
        } else {
            let text = serde_json::to_string_pretty(&outcome.controller)? + "\n";
            write_atomic(path, text.as_bytes()).with_context(|| format!("writing {}", path.display()))?;
        }
    }
    if a.json {
        print_out(&(serde_json::to_string_pretty(&outcome)? + "\n")).context("writing to stdout")?;
    } else {
        print_out(&summary(&problem, &opts, &outcome)).context("writing to stdout")?;
    }
    let what = match (&a.out, &written, good) {
        (None, _, _) => "no --out: no controller file written (the JSON above holds it, `controller`)".to_string(),
        (Some(_), Some(p), true) => format!("controller written to {}", p.display()),
        (Some(out), Some(p), false) => {
            format!(
                "NOT STABILISING controller written to {} (--out-unverified); {} untouched",
                p.display(),
                out.display()
            )
        }
        (Some(out), None, _) => format!(
            "no controller written: it does not stabilise ({} untouched; --out-unverified writes it to {})",
            out.display(),
            unverified_path(out).display()
        ),
    };
    if a.json {
        eprintln!("{what}");
    } else {
        print_out(&format!("{what}\n")).context("writing to stdout")?;
    }
    Ok(match outcome.status {
        DesignStatus::Interrupted => ExitCode::from(signals::exit_code()),
        DesignStatus::NotStabilised { .. } => ExitCode::from(EXIT_NOT_STABILISED),
        DesignStatus::BoundViolated => ExitCode::from(EXIT_BOUND_VIOLATED),
        _ if !good => ExitCode::from(EXIT_NOT_STABILISED),
        _ => ExitCode::SUCCESS,
    })
}

/// The design options the flags ask for: each one the flag's value, a switch the non-default
/// side of its option.
fn options(a: &DesignArgs) -> anyhow::Result<DesignOptions> {
    let d = DesignOptions::default();
    Ok(DesignOptions {
        order: a.order,
        eps: a.eps,
        seed: a.seed,
        cpumax: a.cpumax,
        maxevals: a.maxevals.map(|n| n as usize),
        nrand: a.nrand,
        stall_starts: a.stall_starts,
        stall_rtol: a.stall_rtol,
        stall_cpu: a.stall_cpu,
        spend_budget: if a.stop_on_stall { false } else { d.spend_budget },
        continue_at_maxit: if a.no_continue_at_maxit { false } else { d.continue_at_maxit },
        continued_maxit: a.continued_maxit,
        bfgs_restart: a.bfgs_restart,
        return_gs_reserve: if a.keep_gs_reserve { false } else { d.return_gs_reserve },
        refine_rtol: a.refine_rtol,
        max_starts: a.max_starts.map(|n| n as usize),
        hop_scales: parse_scales(&a.hop_scales, "--hop-scales")?,
        central_gammas: parse_scales(&a.central_gammas, "--central-gammas")?,
        random_scales: parse_scales(&a.random_scales, "--random-scales")?,
        open_loop_start: if a.no_open_loop_start { false } else { d.open_loop_start },
        variable_scaling: a.variable_scaling,
        objective: if a.no_strong { ObjectiveKind::Plain } else { d.objective },
        ..d
    })
}

/// `--hop-scales`, `--central-gammas`: comma-separated positive numbers, or "none" (empty).
fn parse_scales(text: &str, flag: &str) -> anyhow::Result<Vec<f64>> {
    if text.trim() == "none" || text.trim().is_empty() {
        return Ok(Vec::new());
    }
    text.split(',')
        .map(|t| match t.trim().parse::<f64>() {
            Ok(r) if r.is_finite() && r > 0.0 => Ok(r),
            _ => anyhow::bail!("{flag}: {t:?} is not a finite positive number"),
        })
        .collect()
}

/// `path` can receive the controller (`fs_atomic::check_writable`); a directory gets a hint.
fn check_writable(path: &Path) -> anyhow::Result<()> {
    if path.is_dir() {
        anyhow::bail!("is a directory; give a file name such as {}", path.join("K.json").display());
    }
    Ok(crate::fs_atomic::check_writable(path)?)
}

/// The status as printed; a budget that ran out is named by the search's stop reason (a run
/// `--maxevals` ended was once said to have exhausted its CPU budget).
fn status_text(s: &DesignStatus, stop: SearchStop, domain: TimeDomain) -> String {
    match s {
        DesignStatus::Converged => "converged (optimality certificate met)".into(),
        DesignStatus::Stopped => "stopped by a limit before the optimality certificate was met".into(),
        DesignStatus::StabilisedOnly => "stabilised only (the optimisation made no progress)".into(),
        DesignStatus::NotStabilised { best_alpha } => {
            // the measure of the time domain; the margin of `lti::verified_stability` (‖·‖_F, of
            // the balanced A where that pays)
            let (measure, stable) = if domain.is_discrete() {
                ("max(ρ(A_cl) − 1, ε·(ρ(Ak) − 1))", "ρ < 1 − ")
            } else {
                ("max(α(A_cl), ε·α(Ak))", "α < −")
            };
            format!(
                "NOT STABILISED with the verification margin (best {measure} = {best_alpha:+.6e}; stable means \
                 {stable}1e-12·max(1, ‖A‖_F))"
            )
        }
        DesignStatus::BoundViolated => "BOUND VIOLATED: the controller stabilises, but a bound does not hold".into(),
        DesignStatus::BudgetExhausted => format!("{} exhausted (best controller so far)", budget_name(stop)),
        DesignStatus::Interrupted => "interrupted (best controller so far)".into(),
    }
}

/// The budget a search's stop reason names.
fn budget_name(stop: SearchStop) -> &'static str {
    match stop {
        SearchStop::Budget => "CPU budget (--cpumax)",
        SearchStop::Maxevals => "evaluation budget (--maxevals)",
        SearchStop::Starts => "start budget (--max-starts)",
        _ => "budget",
    }
}

/// One line per plant of a several-plant (or non-H∞) design: its objective's value, weighted,
/// its bound and whether it holds, its closed-loop stability measure. Empty for none.
fn plant_lines(values: &[PlantValue], domain: TimeDomain) -> String {
    let mut s = String::new();
    for (i, v) in values.iter().enumerate() {
        let bound = match v.bound {
            None => String::new(),
            Some(b) => format!("   bound {} {}", fmt_num(b, 6), if v.bound_met() { "met" } else { "VIOLATED" }),
        };
        s += &format!(
            "plant {} {}: {} = {}   weight {} → {}{}   s(A_cl) = {:+.4e}\n",
            i + 1,
            for_terminal(&v.plant),
            v.objective.symbol(domain),
            fmt_num(v.value, 6),
            fmt_num(v.weight, 6),
            fmt_num(v.weighted(), 6),
            bound,
            v.alpha_cl
        );
    }
    s
}

/// The summary's note that ε‖K‖∞ sets the objective: active means within 0.1 % of γ or above
/// (`design::controller_norm_active`), so "≥" is printed only where ε‖K‖∞ ≥ γ holds.
fn controller_norm_note(eps_k: f64, gamma: f64, gamma_name: &str) -> String {
    let relation = if eps_k >= gamma { "≥" } else { "is within 0.1 % of" };
    format!(
        "note:     ε‖K‖∞ = {} {relation} {gamma_name}: the controller-norm penalty, not the closed loop, sets the objective (a smaller ε lets {gamma_name} go lower)\n",
        fmt_num(eps_k, 6)
    )
}

fn summary(problem: &Problem, opts: &DesignOptions, o: &DesignOutcome) -> String {
    let plant = problem.first();
    let mode = match opts.objective {
        ObjectiveKind::Strong => format!("strong stabilisation, ε = {:e}", opts.eps),
        // "plain H∞" only for the single-plant H∞ problem: an H2, abscissa or radius design (or
        // several plants) is plain too, but not H∞
        ObjectiveKind::Plain if o.plants.is_empty() => "plain H∞".to_string(),
        ObjectiveKind::Plain => "plain (the controller may be unstable)".to_string(),
    };
    let names = match problem.terms.as_slice() {
        [_] => format!("{} (n = {}", for_terminal(&plant.name), plant.dims.n),
        terms => format!(
            "{} plants ({}",
            terms.len(),
            terms
                .iter()
                .map(|t| format!("{} n = {}", for_terminal(&t.plant.name), t.plant.dims.n))
                .collect::<Vec<_>>()
                .join(", ")
        ),
    };
    let mut s = format!(
        "{}{}), order {}, {}, seed {}\n",
        names,
        plant
            .domain
            .ts()
            .map_or(String::new(), |ts| format!(", discrete time Ts = {} s", crate::numeric::readable(ts))),
        opts.order,
        mode,
        opts.seed
    );
    s += &format!("status:   {}\n", status_text(&o.status, o.search.stop, plant.domain));
    s += &plant_lines(&o.plants, plant.domain);
    // A problem's γ is its plants' largest weighted value (`design::Design`).
    let gamma_name = if o.plants.is_empty() { "‖Tzw‖∞" } else { "max w·g" };
    s += &format!(
        "{gamma_name} = {}   ‖K‖∞ = {}   objective = {}\n",
        fmt_num(o.gamma, 6),
        fmt_num(o.k_hinf, 6),
        fmt_num(o.objective, 6)
    );
    if o.status == DesignStatus::Interrupted && o.gamma.is_nan() {
        s += "note:     ‖Tzw‖∞ not recomputed: interrupted (`campaign check` computes it from the controller file)\n";
    }
    if o.controller_norm_active {
        s += &controller_norm_note(opts.eps * o.k_hinf, o.gamma, gamma_name);
    }
    // α, or in discrete time ρ (the outcome holds ρ − 1, `lti::stability_measure`)
    let (name, alpha_cl) = plant.domain.stability_quantity(o.alpha_cl);
    s += &format!("{name}(A_cl) = {alpha_cl:+.4e}");
    match o.alpha_k {
        Some(a) => s += &format!("   {name}(Ak) = {:+.4e}\n", plant.domain.stability_quantity(a).1),
        None => s += "   (static gain)\n",
    }
    let per_eval = if o.evaluations > 0 { o.design_cpu_s / o.evaluations as f64 } else { f64::NAN };
    s += &format!(
        "CPU {:.2} s, {} iterations, {} evaluations ({:.3} ms/eval)\n",
        o.design_cpu_s,
        o.iterations,
        o.evaluations,
        1e3 * per_eval
    );
    let sr = &o.search;
    s += &format!(
        "search: {} local searches, best from start {}, reached after {:.2} CPU s ({} evaluations), stopped: {}\n",
        sr.starts,
        sr.best_start_label(),
        sr.cpu_to_best_s,
        sr.evals_to_best,
        sr.stop.name()
    );
    if let Some(c) = &o.certificate {
        s += &format!("certificate: dnorm = {:.2e}, evaldist = {:.2e}\n", c.dnorm, c.evaldist);
    }
    s
}

#[cfg(test)]
mod tests {
    use clap::CommandFactory;

    use super::*;

    /// `campaign design` with only the required flags designs with the options' defaults.
    #[test]
    fn the_flags_default_to_the_options_defaults() {
        use clap::Parser;
        let cli = crate::cli::Cli::try_parse_from([
            "campaign", "design", "--plant", "HE1", "--order", "2", "--out", "K.json",
        ])
        .unwrap();
        let a = cli.design_args().expect("a design command");
        assert_eq!(options(a).unwrap(), DesignOptions { order: 2, ..DesignOptions::default() });
    }

    /// One search everywhere: a campaign job that sets no option designs with
    /// exactly the options of `campaign design` given only the required flags, both the option
    /// table's defaults. (The Python package's defaults are the same `DesignOptions::default`,
    /// python/tests/test_defaults.py.)
    #[test]
    fn a_campaign_job_designs_as_campaign_design_does() {
        use clap::Parser;
        let cli = crate::cli::Cli::try_parse_from([
            "campaign", "design", "--plant", "HE1", "--order", "2", "--out", "K.json",
        ])
        .unwrap();
        let flags = options(cli.design_args().expect("a design command")).unwrap();
        let text = "name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [2]\n";
        let campaign = crate::campaign::Campaign::from_toml_str(text, Path::new("t.toml")).unwrap();
        let jobs = crate::campaign::expand(&campaign, crate::campaign::RunnerTag::Design);
        assert_eq!(jobs.len(), 1);
        assert_eq!(jobs[0].options, flags);
        assert_eq!(flags, DesignOptions { order: 2, ..DesignOptions::default() });
    }

    /// NN13 n_K = 2, ε = 1e-3: ε‖K‖∞ = 10.475971 against ‖Tzw‖∞ = 10.485645 is active (0.09 %
    /// below) but not "≥".
    #[test]
    fn the_controller_norm_note_says_ge_only_where_it_holds() {
        let below = controller_norm_note(10.475971, 10.485645, "‖Tzw‖∞");
        assert!(below.contains("ε‖K‖∞ = 10.475971 is within 0.1 % of ‖Tzw‖∞"), "{below}");
        let above = controller_norm_note(10.5, 10.485645, "‖Tzw‖∞");
        assert!(above.contains("ε‖K‖∞ = 10.500000 ≥ ‖Tzw‖∞"), "{above}");
    }

    /// The not-stabilised status names the measure of the plant's time domain and the margin's
    /// norm as `lti::verified_stability` computes it (‖A‖_F, not ‖A‖₂).
    #[test]
    fn the_not_stabilised_status_speaks_of_the_plants_time_domain() {
        let s = DesignStatus::NotStabilised { best_alpha: 0.5 };
        let c = status_text(&s, SearchStop::Budget, TimeDomain::Continuous);
        assert!(c.contains("max(α(A_cl), ε·α(Ak)) = +5.000000e-1") && c.contains("α < −1e-12·max(1, ‖A‖_F)"), "{c}");
        let d = status_text(&s, SearchStop::Budget, TimeDomain::Discrete { ts: 0.1 });
        assert!(d.contains("max(ρ(A_cl) − 1, ε·(ρ(Ak) − 1))") && d.contains("ρ < 1 − 1e-12"), "{d}");
    }

    #[test]
    fn an_unverified_controller_gets_a_name_that_says_so() {
        assert_eq!(unverified_path(Path::new("out/K.json")), Path::new("out/K.unverified.json"));
        assert_eq!(unverified_path(Path::new("K.mat")), Path::new("K.unverified.mat"));
        assert_eq!(unverified_path(Path::new("K")), Path::new("K.unverified"));
    }

    /// Every flag the option table names is a flag of `campaign design`.
    #[test]
    fn the_option_tables_flags_exist() {
        let cmd = crate::cli::Cli::command();
        let design = cmd.find_subcommand("design").unwrap();
        let flags: Vec<String> =
            design.get_arguments().filter_map(|a| a.get_long()).map(|l| format!("--{l}")).collect();
        for row in DesignOptions::table() {
            assert!(
                row.flag.is_empty() || flags.iter().any(|f| f == row.flag),
                "{} is not a flag: {flags:?}",
                row.flag
            );
        }
    }
    /// The flags that are no design option: the problem, the starting point, the structure and
    /// the output.
    const NOT_OPTIONS: [&str; 10] =
        ["plant", "objective", "weight", "bound", "init", "structure", "json", "out", "out-unverified", "help"];

    /// Options declared once: every flag of `campaign design` is an option of the table (or one
    /// of [`NOT_OPTIONS`]), and each option's flag sets that option and no other — an option
    /// added to the table with a flag, or a flag added to the command, without the other fails
    /// here. The value given is derived from the option's default (a number plus one, a list of
    /// one 0.5, a switch given, another mode).
    #[test]
    fn every_flag_is_one_option_of_the_table() {
        use clap::Parser;
        let table = DesignOptions::table();
        let cmd = crate::cli::Cli::command();
        let design = cmd.find_subcommand("design").unwrap();
        for arg in design.get_arguments() {
            let Some(long) = arg.get_long() else { continue };
            let flag = format!("--{long}");
            assert!(
                NOT_OPTIONS.contains(&long) || table.iter().any(|r| r.flag == flag),
                "{flag} is a flag of `campaign design` but no option of the table (design/options.rs)"
            );
        }
        let defaults = serde_json::to_value(DesignOptions::default()).unwrap();
        // With the default order (1): the options of the required flags alone are the defaults.
        let required = ["campaign", "design", "--plant", "HE1", "--order", "1", "--out", "K.json"];
        for row in table.iter().filter(|r| !r.flag.is_empty()) {
            let arg = design.get_arguments().find(|a| a.get_long() == Some(&row.flag[2..])).unwrap();
            let switch = matches!(arg.get_action(), clap::ArgAction::SetTrue);
            let value = match &defaults.get(row.name) {
                _ if switch => None,
                Some(serde_json::Value::Number(n)) if n.is_u64() => Some((n.as_u64().unwrap() + 1).to_string()),
                Some(serde_json::Value::Number(n)) => Some((n.as_f64().unwrap() + 1.0).to_string()),
                Some(serde_json::Value::Array(_)) => Some("0.5".to_string()),
                Some(serde_json::Value::String(s)) if s == "off" => Some("always".to_string()),
                Some(serde_json::Value::String(_)) => Some("off".to_string()),
                // Left out of the record when off (an absent limit, a zero, a mode off).
                None | Some(serde_json::Value::Null) => Some("7".to_string()),
                Some(v) => panic!("{}: no test value derived from the default {v}", row.name),
            };
            let mut argv: Vec<&str> = required.to_vec();
            match value.as_deref() {
                Some(v) if row.flag == "--order" => argv[5] = v, // required: given once
                v => argv.extend(std::iter::once(row.flag).chain(v)),
            }
            let cli = crate::cli::Cli::try_parse_from(&argv).unwrap_or_else(|e| panic!("{argv:?}: {e}"));
            let got = serde_json::to_value(options(cli.design_args().unwrap()).unwrap()).unwrap();
            let keys = got.as_object().unwrap().keys().chain(defaults.as_object().unwrap().keys());
            let mut changed: Vec<&str> = keys.map(String::as_str).filter(|&k| got.get(k) != defaults.get(k)).collect();
            changed.sort_unstable();
            changed.dedup();
            assert_eq!(changed, [row.name], "{argv:?} should set option `{}` and no other", row.name);
        }
    }
}
