//! `hinfix._hinfix`: the Python extension module of hinfix, thin bindings only. Every number is
//! computed by the hinfix crate; this crate converts numpy arrays to and from its matrices, turns
//! its errors into Python exceptions, and runs long calls off the GIL with Ctrl-C polled
//! (`interrupt.rs`). The python-control conventions (partitioned `StateSpace` plants, the
//! controller as a `StateSpace`) live in the Python package around it (`hinfix/`).
//!
//! * `arrays`: numpy ↔ faer matrices;
//! * `errors`: `HinfixError` and the mapping of the crate's errors to exceptions;
//! * `interrupt`: a long call in a worker thread, KeyboardInterrupt as a cancel;
//! * `plant`: the nine plant matrices ↔ `hinfix::lti::Plant`, the plant library;
//! * `design`: one HIFOO design;
//! * `norms`: the H∞ norm and the full-order γ_opt;
//! * `campaign`: running a campaign file and reading a results folder.
use pyo3::prelude::*;

mod arrays;
mod campaign;
mod design;
mod errors;
mod interrupt;
mod norms;
mod plant;

#[pymodule]
fn _hinfix(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add("HinfixError", m.py().get_type::<errors::HinfixError>())?;
    m.add_function(wrap_pyfunction!(design::design, m)?)?;
    m.add_function(wrap_pyfunction!(design::option_names, m)?)?;
    m.add_function(wrap_pyfunction!(design::default_options, m)?)?;
    m.add_function(wrap_pyfunction!(design::closed_loop, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    m.add_function(wrap_pyfunction!(norms::hinfnorm, m)?)?;
    m.add_function(wrap_pyfunction!(norms::full_order_gamma, m)?)?;
    m.add_function(wrap_pyfunction!(plant::load_plant, m)?)?;
    m.add_function(wrap_pyfunction!(plant::shipped_plants, m)?)?;
    m.add_function(wrap_pyfunction!(campaign::run_campaign, m)?)?;
    m.add_function(wrap_pyfunction!(campaign::read_results, m)?)?;
    Ok(())
}
