//! One HIFOO design: `design(plant, options_json, init)` → the controller's four matrices and the
//! outcome as JSON (the crate's `DesignOutcome` serialisation, as `campaign design --json`
//! prints it).
//!
//! The options come as a JSON object of `DesignOptions` fields (the option table of
//! `design/options.rs`, with its defaults for what is absent); an unknown name or a value out of
//! range is a `ValueError` with the crate's message.
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use numpy::PyArray2;
use pyo3::prelude::*;

use hinfix::design::{run_with_control, validate, DesignOptions, NoDesignObserver};
use hinfix::lti::Controller;
use hinfix::optim::RunControl;

use crate::arrays::{to_mat, to_numpy, In};
use crate::errors::{bad_input, failure};
use crate::interrupt::run_interruptible;
use crate::plant::plant_from;

type Matrices<'py> = Vec<Bound<'py, PyArray2<f64>>>;

/// Designs a controller for the plant `plant` (nine matrices) with the options `options` (JSON);
/// `init` is an initial controller (Ak, Bk, Ck, Dk). Returns (Ak, Bk, Ck, Dk) and the outcome as
/// JSON, and every option used (the given ones and the defaults) as JSON. Ctrl-C stops the design
/// (KeyboardInterrupt is raised after it has returned).
#[pyfunction]
#[pyo3(signature = (plant, options, init = None, name = "plant"))]
pub fn design<'py>(
    py: Python<'py>,
    plant: Vec<In<'py>>,
    options: &str,
    init: Option<Vec<In<'py>>>,
    name: &str,
) -> PyResult<(Matrices<'py>, String, String)> {
    let plant = plant_from(name, plant)?;
    let opts = read_options(options)?;
    let init = init.map(|k| controller_from(&k)).transpose()?;
    validate(&plant, &opts, init.as_ref()).map_err(|e| bad_input("design", e))?;
    let used = serde_json::to_string(&opts).map_err(|e| failure("design options", e))?;
    let cancel = Arc::new(AtomicBool::new(false));
    let flag = Arc::clone(&cancel);
    let outcome = run_interruptible(py, cancel, move |_| {
        // The clock starts here, in the thread that spends the CPU time.
        let ctl = RunControl::new(opts.cpumax).with_cancel(flag);
        run_with_control(&plant, &opts, init.as_ref(), &ctl, &mut NoDesignObserver)
    })?
    .map_err(|e| failure("design", e))?;
    let k = &outcome.controller;
    let mats = [k.ak.as_ref(), k.bk.as_ref(), k.ck.as_ref(), k.dk.as_ref()].map(|m| to_numpy(py, m)).into();
    let json = serde_json::to_string(&outcome).map_err(|e| failure("design outcome", e))?;
    Ok((mats, json, used))
}

/// The options of a JSON object of `DesignOptions` fields. A value of the wrong type is reported
/// with its option's name (serde's message gives only a column of the JSON text).
fn read_options(text: &str) -> PyResult<DesignOptions> {
    serde_json::from_str(text).map_err(|e| {
        let culprit = serde_json::from_str::<serde_json::Map<String, serde_json::Value>>(text).ok().and_then(|map| {
            map.into_iter().find_map(|(k, v)| {
                let one = serde_json::Value::Object([(k.clone(), v)].into_iter().collect());
                serde_json::from_value::<DesignOptions>(one).err().map(|e| format!("option `{k}`: {e}"))
            })
        });
        bad_input("design options", culprit.unwrap_or_else(|| e.to_string()))
    })
}

/// The controller (Ak, Bk, Ck, Dk); its fit to the plant is checked by `validate`.
fn controller_from(k: &[In<'_>]) -> PyResult<Controller> {
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
    Ok(Controller::continuous(ak, bk, ck, dk))
}

/// The names of the design options (the fields of `DesignOptions`), in the option table's order.
#[pyfunction]
pub fn option_names() -> Vec<&'static str> {
    DesignOptions::table().into_iter().map(|row| row.name).collect()
}
