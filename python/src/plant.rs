//! The generalised plant as nine numpy matrices (A, B1, B2, C1, C2, D11, D12, D21, D22) ↔
//! `hinfix::lti::Plant`, and the shipped plant library.
use numpy::PyArray2;
use pyo3::prelude::*;

use hinfix::lti::{resolve_plant, Plant, TimeDomain};

use crate::arrays::{to_mat, to_numpy, In};
use crate::errors::{bad_input, failure};

/// The plant of nine matrices in file order, validated as a plant file is (a `ValueError` naming
/// the matrix, row and column of the first thing wrong), in continuous time (`dt` 0) or discrete
/// time with sampling time `dt` seconds.
pub fn plant_from(name: &str, mats: Vec<In<'_>>, dt: f64) -> PyResult<Plant> {
    let mats: Vec<_> = mats.iter().map(to_mat).collect();
    let mats: [_; 9] = mats.try_into().map_err(|m: Vec<_>| {
        bad_input("plant", format!("expected the nine matrices A, B1, B2, C1, C2, D11, D12, D21, D22, got {}", m.len()))
    })?;
    let refs = mats.each_ref().map(|m| m.as_ref());
    let mut plant = Plant::from_matrices(name, refs).map_err(|e| bad_input("plant", e))?;
    plant.domain = TimeDomain::from_ts(dt).map_err(|e| bad_input("plant", format!("{name}: dt {e}")))?;
    Ok(plant)
}

/// `load_plant(name_or_path)` → `(name, [A, B1, B2, C1, C2, D11, D12, D21, D22], dt)`: a shipped
/// plant by name (`HE1`) or a plant file (JSON or MATLAB `.mat`) by path; `dt` is its sampling
/// time (0: continuous time).
#[pyfunction]
#[allow(clippy::type_complexity)]
pub fn load_plant<'py>(py: Python<'py>, name_or_path: &str) -> PyResult<(String, Vec<Bound<'py, PyArray2<f64>>>, f64)> {
    let file = resolve_plant(name_or_path).map_err(|e| bad_input("load_plant", e))?;
    let plant = Plant::load(&file).map_err(|e| failure("load_plant", e))?;
    let mats = plant.matrices().into_iter().map(|m| to_numpy(py, m)).collect();
    Ok((plant.name.clone(), mats, plant.domain.ts_or_zero()))
}

/// The names of the shipped plants, sorted.
#[pyfunction]
pub fn shipped_plants() -> PyResult<Vec<String>> {
    hinfix::lti::shipped_plants().map_err(|e| failure("shipped_plants", e))
}
