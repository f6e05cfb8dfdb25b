//! Entry points of the per-call microbenchmarks of `benches/lti.rs`: `--qr`, the
//! matrices the H∞ norm hands to the Hessenberg QR (the closed loop's Hessenberg form, the
//! square-reduced method's W) and the QR itself; `--pvl`, the PVL reduction; `--record` and
//! `--replay`, the H∞ norms of a design run replayed on their recorded closed loops. Not a stable
//! API: built only with the `test-support` feature (`cargo bench --bench lti --features
//! test-support`).

use std::cell::RefCell;

use faer::{c64, MatRef};

use super::kernels::freq_response;
use super::kernels::hessenberg_qr::hessenberg_eigenvalues;
use super::kernels::square_reduced::{self, hamiltonian_squared_w};
use super::StateSpace;

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

/// One H∞ norm a design run asked for: the closed loop, the tolerance and the peak hints.
#[derive(Debug, Clone)]
pub struct RecordedNorm {
    pub sys: StateSpace,
    pub tol: f64,
    pub hints: Vec<f64>,
}

thread_local! {
    static RECORDED: RefCell<Option<Vec<RecordedNorm>>> = const { RefCell::new(None) };
}

/// Starts recording, on the calling thread, every H∞ norm of order ≥ 30 (the closed loops of
/// large plants), for a replay that does not depend on the design path (`--replay`).
pub fn record_norms() {
    RECORDED.with(|r| *r.borrow_mut() = Some(Vec::new()));
}

/// Stops recording and returns what was recorded.
pub fn take_recorded_norms() -> Vec<RecordedNorm> {
    RECORDED.with(|r| r.borrow_mut().take().unwrap_or_default())
}

/// Records one norm if recording is on (a thread-local check otherwise).
pub(crate) fn note_norm(sys: &StateSpace, tol: f64, hints: &[f64]) {
    RECORDED.with(|r| {
        if let Some(v) = r.borrow_mut().as_mut() {
            v.push(RecordedNorm { sys: sys.clone(), tol, hints: hints.to_vec() });
        }
    });
}
