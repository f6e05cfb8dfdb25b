//! One HIFOO design: `design(terms, options_json, init, …)` → the controller's four matrices and
//! the outcome as JSON (the crate's `DesignOutcome` serialisation, as `campaign design --json`
//! prints it).
//!
//! The options come as a JSON object naming some `DesignOptions` fields; the others are the
//! option table's defaults (`DesignOptions::from_json_over_defaults`, the same defaults as
//! `campaign design` and campaign jobs). An unknown name or a value out of range is a
//! `ValueError` with the crate's message.
use std::sync::atomic::AtomicBool;
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use numpy::PyArray2;
use pyo3::prelude::*;
use pyo3::types::PyDict;

use hinfix::design::{
    ControllerShape, Design, DesignError, DesignIterRecord, DesignObserver, DesignOptions, PlantObjective, PlantTerm,
    Problem, Structure,
};
use hinfix::lti::{Controller, TimeDomain};

use crate::arrays::{to_mat, to_numpy, In};
use crate::errors::{bad_input, failure};
use crate::interrupt::run_interruptible_with;
use crate::plant::plant_from;

type Matrices<'py> = Vec<Bound<'py, PyArray2<f64>>>;

/// One plant of a design as Python hands it over: name, the nine matrices, sampling time (0:
/// continuous time), objective name, weight, bound (None: none).
type TermIn<'py> = (String, Vec<In<'py>>, f64, String, f64, Option<f64>);

/// How often at most the progress callback is called.
const PROGRESS_EVERY: Duration = Duration::from_millis(250);

/// Designs one controller for the plants `terms` (one or several, docs/ALGORITHMS.md §14) with
/// the options `options` (JSON); `init` is an initial controller (Ak, Bk, Ck, Dk) in the plants'
/// time domain, `structure` a structure as the JSON text of a structure file (null = free) and
/// `structure_path` a structure file (JSON or .mat). `progress(dict)` is called from the calling
/// thread at most every 250 ms while the design runs (phase, start, iteration, evaluations, CPU
/// seconds, best objective so far). Returns (Ak, Bk, Ck, Dk), the outcome as JSON and every
/// option used (the given ones and the defaults) as JSON. Ctrl-C stops the design
/// (KeyboardInterrupt is raised after it has returned), as does an exception of `progress`.
#[pyfunction]
#[pyo3(signature = (terms, options, init = None, structure = None, structure_path = None, progress = None))]
pub fn design<'py>(
    py: Python<'py>,
    terms: Vec<TermIn<'py>>,
    options: &str,
    init: Option<Vec<In<'py>>>,
    structure: Option<&str>,
    structure_path: Option<std::path::PathBuf>,
    progress: Option<Bound<'py, PyAny>>,
) -> PyResult<(Matrices<'py>, String, String)> {
    let problem = problem_from(terms)?;
    let opts = read_options(options)?;
    let plant = problem.first();
    let domain = plant.domain;
    let init = init.map(|k| controller_from(&k, domain)).transpose()?;
    for t in &problem.terms {
        hinfix::design::validate(&t.plant, &opts, init.as_ref()).map_err(|e| bad_input("design", e))?;
    }
    let shape = ControllerShape::for_plant(plant, opts.order);
    let structure = match (structure, structure_path) {
        (Some(_), Some(_)) => return Err(bad_input("structure", "give a structure or a structure file, not both")),
        (Some(text), None) => {
            Some(Structure::from_json(text, "structure", shape).map_err(|e| bad_input("structure", e))?)
        }
        (None, Some(path)) => Some(Structure::load(&path, shape).map_err(|e| bad_input("structure", e))?),
        (None, None) => None,
    };
    let used = serde_json::to_string(&opts).map_err(|e| failure("design options", e))?;
    let cancel = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&cancel);
    let latest: Arc<Mutex<Option<Progress>>> = Arc::new(Mutex::new(None));
    let mut watcher = Watcher { latest: Arc::clone(&latest), best: f64::INFINITY };
    let mut last_call = Instant::now();
    let on_poll = |py: Python<'_>, done: bool| -> PyResult<()> {
        let Some(callback) = &progress else { return Ok(()) };
        if !done && last_call.elapsed() < PROGRESS_EVERY {
            return Ok(());
        }
        last_call = Instant::now();
        let state = latest.lock().map(|g| *g).unwrap_or(None);
        let Some(p) = state else { return Ok(()) };
        let d = PyDict::new(py);
        d.set_item("phase", p.phase)?;
        d.set_item("start", p.start)?;
        d.set_item("iteration", p.iter)?;
        d.set_item("evaluations", p.evals)?;
        d.set_item("cpu_s", p.cpu_s)?;
        d.set_item("best", p.best)?;
        d.set_item("done", done)?;
        callback.call1((d,))?;
        Ok(())
    };
    let outcome = run_interruptible_with(
        py,
        cancel,
        move |_| {
            // The clock starts here, in the thread that spends the CPU time.
            Design::new(&problem, &opts)
                .init(init.as_ref())
                .structure(structure.as_ref())
                .observe(&mut watcher)
                .cancel(flag)
                .run()
        },
        on_poll,
    )?
    .map_err(|e| match e {
        // a failure of the optimiser is the program's; every other refusal (options, the
        // initial controller, the structure, the plants) is of the arguments
        DesignError::Numerical(_) => failure("design", e),
        _ => bad_input("design", e),
    })?;
    let k = &outcome.controller;
    let mats = [k.ak.as_ref(), k.bk.as_ref(), k.ck.as_ref(), k.dk.as_ref()].map(|m| to_numpy(py, m)).into();
    let json = serde_json::to_string(&outcome).map_err(|e| failure("design outcome", e))?;
    Ok((mats, json, used))
}

/// The latest iteration a design reported, for the progress callback.
#[derive(Clone, Copy)]
struct Progress {
    phase: &'static str,
    start: usize,
    iter: usize,
    evals: usize,
    cpu_s: f64,
    /// The smallest objective of the optimisation phases so far (inf before the first).
    best: f64,
}

/// Keeps the latest iteration for the calling thread (it never stops the design and asks for
/// nothing that costs: the same run as with `NoDesignObserver`).
struct Watcher {
    latest: Arc<Mutex<Option<Progress>>>,
    best: f64,
}

impl DesignObserver for Watcher {
    fn wants_components(&self) -> bool {
        false
    }

    fn on_iter(&mut self, r: &DesignIterRecord) -> std::ops::ControlFlow<()> {
        if r.phase != hinfix::design::Phase::Stabilisation && r.improved {
            self.best = r.f;
        }
        let p = Progress {
            phase: r.phase.name(),
            start: r.start,
            iter: r.iter,
            evals: r.evals,
            cpu_s: r.cpu_s,
            best: self.best,
        };
        if let Ok(mut g) = self.latest.lock() {
            *g = Some(p);
        }
        std::ops::ControlFlow::Continue(())
    }
}

/// The problem of the plants Python hands over (each checked as a plant file is).
fn problem_from(terms: Vec<TermIn<'_>>) -> PyResult<Problem> {
    if terms.is_empty() {
        return Err(bad_input("design", "no plant given"));
    }
    let mut out = Vec::with_capacity(terms.len());
    for (name, mats, ts, objective, weight, bound) in terms {
        let plant = plant_from(&name, mats, ts)?;
        let objective = objective.parse::<PlantObjective>().map_err(|e| bad_input("objective", e))?;
        out.push(PlantTerm { plant, objective, weight, bound });
    }
    let problem = Problem { terms: out };
    problem.validate().map_err(|e| bad_input("design", e))?;
    Ok(problem)
}

/// The options of a JSON object naming some `DesignOptions` fields, the others at their
/// defaults. A value of the wrong type is reported with its option's name and in plain words
/// (serde's message gives only a column of the JSON text and Rust's type names).
fn read_options(text: &str) -> PyResult<DesignOptions> {
    let given: serde_json::Map<String, serde_json::Value> =
        serde_json::from_str(text).map_err(|e| bad_input("design options", e))?;
    DesignOptions::from_json_over_defaults(given.clone()).map_err(|e| {
        let culprit = given.into_iter().find_map(|(k, v)| {
            let one = [(k.clone(), v)].into_iter().collect();
            DesignOptions::from_json_over_defaults(one).err().map(|e| format!("option `{k}`: {}", plain_words(&e)))
        });
        bad_input("design options", culprit.unwrap_or_else(|| plain_words(&e)))
    })
}

/// serde's message in the project's words: no Rust type names, no column of a JSON text the
/// user never wrote.
fn plain_words(e: &serde_json::Error) -> String {
    let text = e.to_string();
    let text = text.split(" at line ").next().unwrap_or(&text).to_string();
    [
        ("expected usize", "expected a whole number ≥ 0"),
        ("expected u64", "expected a whole number ≥ 0"),
        ("expected f64", "expected a number"),
        ("expected a boolean", "expected True or False"),
        ("floating point", "number"),
        ("invalid type: ", ""),
        ("data did not match any variant of untagged enum NumOrStr", "expected a number, \"inf\", \"-inf\" or \"nan\""),
    ]
    .iter()
    .fold(text, |t, (rust, plain)| t.replace(rust, plain))
}

/// The controller (Ak, Bk, Ck, Dk) in the time domain `domain`; its fit to the plant is checked
/// by `validate`.
fn controller_from(k: &[In<'_>], domain: TimeDomain) -> PyResult<Controller> {
    let [ak, bk, ck, dk] = k else {
        return Err(bad_input("init", format!("expected the four matrices Ak, Bk, Ck, Dk, got {}", k.len())));
    };
    let (ak, bk, ck, dk) = (to_mat(ak), to_mat(bk), to_mat(ck), to_mat(dk));
    let nk = ak.nrows();
    let shapes = [
        ("Ak", (ak.nrows(), ak.ncols()), (nk, nk)),
        ("Bk", (bk.nrows(), bk.ncols()), (nk, dk.ncols())),
        ("Ck", (ck.nrows(), ck.ncols()), (dk.nrows(), nk)),
    ];
    for (what, got, want) in shapes {
        if got != want {
            return Err(bad_input("init", format!("{what} is {}×{}, expected {}×{}", got.0, got.1, want.0, want.1)));
        }
    }
    Ok(Controller::continuous(ak, bk, ck, dk).in_domain(domain))
}

/// The names of the design options (the fields of `DesignOptions`), in the option table's order.
#[pyfunction]
pub fn option_names() -> Vec<&'static str> {
    DesignOptions::table().into_iter().map(|row| row.name).collect()
}

/// Every design option's default as JSON (`DesignOptions::default`, the defaults of `campaign
/// design` and of campaign files). The record format leaves out a value that means "off"
/// (`refine_rtol` 0, the optional limits): those are taken from the option table, a number as a
/// float and an absent limit as null.
#[pyfunction]
pub fn default_options() -> PyResult<String> {
    let value = serde_json::to_value(DesignOptions::default()).map_err(|e| failure("default_options", e))?;
    let serde_json::Value::Object(mut all) = value else {
        return Err(failure("default_options", "the options are not a JSON object"));
    };
    for row in DesignOptions::table() {
        if !all.contains_key(row.name) {
            let shown = serde_json::from_str::<serde_json::Value>(&row.default).ok();
            let v = shown.and_then(|v| v.as_f64()).map_or(serde_json::Value::Null, serde_json::Value::from);
            all.insert(row.name.to_string(), v);
        }
    }
    serde_json::to_string(&all).map_err(|e| failure("default_options", e))
}

/// `closed_loop(plant, k, dt)` → (A, B, C, D) of the loop of the nine plant matrices and the
/// controller's four (Ak, Bk, Ck, Dk): the crate's `lti::closed_loop`, the loop every design
/// measures. `design` uses it where python-control's `P.lft(K)` refuses a loop the crate forms:
/// its well-posedness test of [[I, −D22], [−Dk, I]] depends on the scale of Dk (it failed for
/// |Dk| ≈ 1e8 with D22 = 0), and a plant without w or z channels is not a python-control system.
#[pyfunction]
#[pyo3(signature = (plant, k, dt = 0.0))]
#[allow(clippy::type_complexity)]
pub fn closed_loop<'py>(py: Python<'py>, plant: Vec<In<'_>>, k: Vec<In<'_>>, dt: f64) -> PyResult<Matrices<'py>> {
    let plant = plant_from("plant", plant, dt)?;
    let k = controller_from(&k, plant.domain)?;
    k.check_fits(&plant).map_err(|e| bad_input("closed_loop", e))?;
    let cl = hinfix::lti::closed_loop(&plant, &k).map_err(|e| bad_input("closed_loop", e))?;
    Ok([&cl.a, &cl.b, &cl.c, &cl.d].into_iter().map(|m| to_numpy(py, m.as_ref())).collect())
}
