//! Entry points of the per-call microbenchmarks of `benches/lti.rs` (issue 13): `--qr`, the
//! matrices the H∞ norm hands to the Hessenberg QR (the closed loop's Hessenberg form, the
//! square-reduced method's W) and the QR itself; `--pvl`, the PVL reduction. Not a stable API.

use faer::{c64, MatRef};

use super::freq_response;
use super::hessenberg_qr::hessenberg_eigenvalues;
use super::square_reduced::{self, hamiltonian_squared_w};

/// The eigenvalues of the n×n upper Hessenberg `h` (column-major, overwritten) as the H∞ norm
/// computes them (`hessenberg_qr.rs`); `None` if the QR fails.
pub fn eigenvalues(h: &mut [f64], n: usize) -> Option<Vec<c64>> {
    hessenberg_eigenvalues(h, n).ok()
}

/// The Hessenberg form of the square `a` (column-major), by the frequency response's reduction.
pub fn hessenberg_form(a: MatRef<'_, f64>) -> Vec<f64> {
    freq_response::of_matrix(a).hessenberg_column_major()
}

/// The W of the square-reduced method for the Hamiltonian [F G; K −Fᵀ] (column-major; below
/// the subdiagonal the reduction's rounding); `None` if not finite.
pub fn hamiltonian_w(f: MatRef<'_, f64>, g: MatRef<'_, f64>, k: MatRef<'_, f64>) -> Option<Vec<f64>> {
    hamiltonian_squared_w(f, g, k)
}

/// The W of the PVL reduction of the skew-Hamiltonian [A G; Q Aᵀ] (column-major), as the
/// square-reduced method computes it.
pub fn pvl_w(a: MatRef<'_, f64>, g: MatRef<'_, f64>, q: MatRef<'_, f64>) -> Vec<f64> {
    square_reduced::pvl_w(a, g, q)
}
