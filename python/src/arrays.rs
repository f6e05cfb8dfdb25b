//! numpy ↔ faer. An input array is read in place (any strides, through a read-only view) and
//! copied once into the column-major matrix the crate computes with; an output matrix is copied
//! once into an ndarray whose buffer numpy then owns (no second copy).
use faer::{Mat, MatRef};
use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray2, PyReadonlyArray2};
use pyo3::prelude::*;

/// A float64 matrix from numpy.
pub type In<'py> = PyReadonlyArray2<'py, f64>;

/// The matrix of a numpy array.
pub fn to_mat(a: &In<'_>) -> Mat<f64> {
    let v = a.as_array();
    Mat::from_fn(v.nrows(), v.ncols(), |i, j| v[[i, j]])
}

/// A numpy array holding `m`.
pub fn to_numpy<'py>(py: Python<'py>, m: MatRef<'_, f64>) -> Bound<'py, PyArray2<f64>> {
    Array2::from_shape_fn((m.nrows(), m.ncols()), |(i, j)| m[(i, j)]).into_pyarray(py)
}
