//! Errors at the boundary: bad input is a `ValueError`, anything else the crate reports is a
//! `hinfix.HinfixError` (a `RuntimeError`); both carry the crate's message unchanged.
use std::fmt::Display;

use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::PyErr;

pyo3::create_exception!(
    hinfix,
    HinfixError,
    PyRuntimeError,
    "An error of the hinfix library that is not a bad argument (a numerical failure, an unreadable file, a campaign that could not run)."
);

/// A `ValueError` with `context: message`.
pub fn bad_input(context: &str, e: impl Display) -> PyErr {
    PyValueError::new_err(format!("{context}: {e}"))
}

/// A `HinfixError` with `context: message`.
pub fn failure(context: &str, e: impl Display) -> PyErr {
    HinfixError::new_err(format!("{context}: {e}"))
}
