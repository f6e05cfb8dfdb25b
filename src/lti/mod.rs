//! Linear time-invariant systems: plants, controllers, closed loops, spectral abscissa, the H∞
//! norm, their gradients with respect to the controller, and the full-order H∞ bound.
//!
//! The H∞ norm and all gradients are hand-written (`hinf.rs`, `gradient.rs`): no Rust crate
//! offers them. Linear algebra is faer, always single-threaded (`Par::Seq`).
mod balanced_truncation;
mod central_controller;
mod closed_loop;
mod controller;
mod error;
pub(crate) mod export;
pub(crate) mod freq_response;
pub use freq_response::ResponseSlot;
mod full_order;
mod gradient;
mod hessenberg_qr;
mod hessenberg_solve;
mod hinf;
mod interrupt;
#[doc(hidden)]
pub mod kernel_bench;
mod level_set_pencil;
mod lyapunov;
mod mat_file;
mod mat_inflate;
mod matrix_json;
mod plant;
mod plant_library;
mod pvl_update;
mod riccati;
mod spectral;
mod square_reduced;
mod state_space;
pub mod step_stats;

pub use balanced_truncation::{
    balanced_truncation, balanced_truncation_stable, coprime_factor_truncation, dc_gain, hankel_singular_values,
    Reduced, ReductionError, HSV_RTOL,
};
pub use central_controller::{CentralError, CentralProblem, GAMMA_OPT_RTOL, START_REGULARISATION};
pub use closed_loop::{closed_loop, MAX_LOOP_CONDITION};
pub use controller::{controller_to_mat, Controller, ControllerError, ControllerErrorKind};
pub use error::LtiError;
pub use export::{export_code, ExportTarget};
pub use full_order::{
    full_order_gamma, full_order_gamma_with, Binding, FullOrderError, FullOrderGamma, FullOrderOptions, Regularisation,
    FLAT_RTOL, GAMMA_MAX, GAMMA_RTOL, REGULARISATION_DELTAS,
};
pub use gradient::{
    closed_loop_abscissa_grad, closed_loop_hinf_grad, closed_loop_hinf_grad_interruptible, closed_loop_hinf_grad_near,
    closed_loop_hinf_grad_near_interruptible, closed_loop_hinf_grad_sharing, controller_abscissa_grad,
    controller_hinf_grad, ControllerGradient,
};
pub(crate) use hinf::hinf_norm_with_poles_interruptible;
pub use hinf::{
    hinf_lower_bound, hinf_lower_bound_sharing, hinf_norm, hinf_norm_interruptible, hinf_norm_near,
    hinf_norm_near_interruptible, HinfNorm, DEFAULT_HINF_TOL, MAX_EXPLICIT_HAMILTONIAN_COND, MAX_LEVEL_SET_ITERS,
    MIN_HINF_TOL,
};
pub use interrupt::{Interrupt, Interrupted};
pub use lyapunov::{lyapunov_residual, solve_lyapunov, stable_antistable_basis, LyapunovError, LYAPUNOV_RESIDUAL_TOL};
pub use mat_file::{is_mat_path, read_mat_vars, write_mat, MatReadError, MatVar};
pub use matrix_json::{matrix_from_json, matrix_to_json, MatrixJsonError, MAX_PLANT_MAGNITUDE, MIN_PLANT_MAGNITUDE};
pub use plant::{plant_to_mat, Dims, Plant, PlantError, PlantErrorKind};
pub use plant_library::{plants_dir, resolve_plant, shipped_plants, PLANTS_ENV};
pub(crate) use riccati::balance_scaling;
pub use riccati::{care_residual, solve_care, CareSolution, RiccatiError};
pub(crate) use spectral::abscissa_of;
pub(crate) use spectral::eigenvalues as eigenvalues_of;
pub use spectral::{
    is_stable, is_stable_with_margin, spectral_abscissa, spectral_abscissa_grad, stability_margin, MIN_EIGVEC_COSINE,
    STABILITY_MARGIN_RTOL,
};
pub use state_space::StateSpace;
