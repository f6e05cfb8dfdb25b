//! The numerical kernels the norms and the synthesis are built from, on matrices and
//! state-space realisations:
//!
//! * eigenvalues: `spectral.rs` (eigenvalues, spectral abscissa and its gradient),
//!   `hessenberg_qr.rs` (our Francis double-shift QR on an upper Hessenberg matrix);
//! * the frequency response G(iω) through the Hessenberg form of A: `freq_response.rs`, with the
//!   shifted Hessenberg solve on split real and imaginary parts in `hessenberg_solve.rs`;
//! * the Hamiltonian level sets of the H∞ norm: `square_reduced.rs` (Van Loan's square-reduced
//!   method), its PVL reduction `pvl_update.rs`, and the pencil form used near a singular
//!   γ²I − DᵀD, `level_set_pencil.rs`;
//! * discrete time: `bilinear.rs` (the Cayley transform to a continuous-time system with the
//!   same response on the boundary, for the discrete H∞ norm);
//! * matrix equations: `lyapunov.rs`, `riccati.rs` (and the stable/antistable splitting);
//! * `step_stats.rs`: per-thread counters (and optional CPU times) of these steps, for the
//!   benches; no computed value depends on them.
//!
//! Imports `system` (for [`StateSpace`](crate::lti::StateSpace)) and the shared `error`,
//! `interrupt`; never `norms` or `synthesis`.

pub(crate) mod balance;
pub(crate) mod bilinear;
pub(crate) mod freq_response;
pub(crate) mod hessenberg_qr;
pub(crate) mod hessenberg_solve;
pub(crate) mod level_set_pencil;
pub(crate) mod lyapunov;
pub(crate) mod pvl_update;
pub(crate) mod riccati;
pub(crate) mod spectral;
pub(crate) mod square_reduced;
pub mod step_stats;
