//! Linear time-invariant systems: plants, controllers, closed loops, spectral abscissa, the H∞
//! and H2 norms, the complex stability radius, their gradients with respect to the controller,
//! and the full-order H∞ bound; in discrete time the spectral radius and the H∞ and H2 norms on
//! the unit circle with their gradients.
//!
//! The parts, each in its folder, from the bottom up (a part imports only parts below it,
//! `tests/module_graph.rs`; docs/ARCHITECTURE.md §1):
//!
//! * `io/`: file formats of named matrices (JSON matrices, MAT-files);
//! * `system/`: state-space realisations, plants, controllers, the closed loop, the plant
//!   library, controller export as code;
//! * `kernels/`: eigenvalues, the Hessenberg QR, the frequency response, the Hamiltonian level
//!   sets, Lyapunov and Riccati equations;
//! * `norms/`: the H∞ and H2 norms, the stability radius and the gradients (hand-written: no
//!   Rust crate offers them);
//! * `synthesis/`: the full-order γ_opt, the central controller, balanced truncation.
//!
//! `error.rs` ([`LtiError`]) and `interrupt.rs` ([`Interrupt`]) are shared by all parts. Linear
//! algebra is faer, always single-threaded (`Par::Seq`).
mod error;
mod interrupt;
mod io;
#[cfg(feature = "test-support")]
#[doc(hidden)]
pub mod kernel_bench;
mod kernels;
mod norms;
mod synthesis;
mod system;

pub use kernels::freq_response::ResponseSlot;
pub use kernels::step_stats;
pub(crate) use system::export;

pub use error::LtiError;
pub use interrupt::{Interrupt, Interrupted};
pub use io::mat_file::{is_mat_path, read_mat_vars, write_mat, MatReadError, MatVar};
pub use io::matrix_json::{
    matrix_from_json, matrix_to_json, MatrixJsonError, MAX_PLANT_MAGNITUDE, MIN_PLANT_MAGNITUDE,
};
pub use kernels::lyapunov::{
    lyapunov_residual, solve_lyapunov, stable_antistable_basis, LyapunovError, LYAPUNOV_RESIDUAL_TOL,
};
pub(crate) use kernels::riccati::balance_scaling;
pub use kernels::riccati::{care_residual, solve_care, CareSolution, RiccatiError};
pub(crate) use kernels::spectral::eigenvalues as eigenvalues_of;
pub use kernels::spectral::{
    is_schur_stable, is_schur_stable_with_margin, is_stable, is_stable_with_margin, spectral_abscissa,
    spectral_abscissa_grad, spectral_radius, spectral_radius_grad, stability_margin, verified_spectral_abscissa,
    verified_spectral_radius, MIN_EIGVEC_COSINE, STABILITY_MARGIN_RTOL,
};
pub use norms::discrete::{
    closed_loop_hinf_grad_discrete, controller_hinf_grad_discrete, hinf_norm_discrete, hinf_norm_grad_discrete,
};
pub(crate) use norms::domain::stability_measure_of;
pub use norms::domain::{
    closed_loop_h2_grad_in, closed_loop_hinf_grad, closed_loop_stability_grad, controller_hinf_grad,
    controller_stability_grad, hinf_norm_in, stability_measure, verified_stability, verified_stability_measure,
    VerifiedStability,
};
pub use norms::gradient::{
    closed_loop_abscissa_grad, closed_loop_radius_grad, controller_abscissa_grad, controller_radius_grad,
    ControllerGradient,
};
pub use norms::h2::{
    closed_loop_h2_grad, closed_loop_h2_grad_discrete, h2_feedthrough_parameterisation, h2_norm, h2_norm_discrete,
    h2_norm_grad, h2_norm_grad_discrete, DkAffine, FeedthroughError, H2_FEEDTHROUGH_RTOL,
};
pub use norms::hinf::{
    hinf_lower_bound, hinf_lower_bound_sharing, hinf_norm, HinfNorm, HinfParams, DEFAULT_HINF_TOL,
    MAX_EXPLICIT_HAMILTONIAN_COND, MAX_LEVEL_SET_ITERS, MIN_HINF_TOL,
};
pub use norms::sigma::{
    frequency_band, hinf_norm_checked, hinf_norm_checked_with, near_peak_frequencies, sigma_curve, NORM_TIE_RTOL,
    SIGMA_BASE_POINTS, SIGMA_MAX_POINTS, SIGMA_STEP_RTOL,
};
pub use norms::stability_radius::{closed_loop_inverse_stability_radius_grad, inverse_stability_radius};
pub use synthesis::balanced_truncation::{
    balanced_truncation, balanced_truncation_stable, coprime_factor_truncation, dc_gain, hankel_singular_values,
    Reduced, ReductionError, HSV_RTOL,
};
pub use synthesis::central_controller::{CentralError, CentralProblem, GAMMA_OPT_RTOL, START_REGULARISATION};
pub use synthesis::full_order::{
    full_order_gamma, full_order_gamma_discrete, full_order_gamma_with, Binding, FullOrderError, FullOrderGamma,
    FullOrderOptions, Regularisation, FLAT_RTOL, GAMMA_MAX, GAMMA_RTOL, REGULARISATION_DELTAS,
};
pub use synthesis::plant_image::{continuous_time_image, ImageError, PlantImage};
pub use synthesis::strong_stabilisability::{parity_interlacing, ParityInterlacing, PipViolation, PIP_MAX_N, PIP_RTOL};
pub use system::closed_loop::{closed_loop, MAX_LOOP_CONDITION};
pub use system::controller::{controller_to_mat, Controller, ControllerError, ControllerErrorKind};
pub use system::export::{export_code, ExportTarget};
pub use system::plant::{plant_to_mat, Dims, Plant, PlantError, PlantErrorKind};
pub use system::plant_library::{library_plants, plants_dir, resolve_plant, shipped_plants, LibraryPlant, PLANTS_ENV};
pub use system::state_space::StateSpace;
pub use system::time_domain::{BadSamplingTime, TimeDomain, MAX_TS, MIN_TS};
