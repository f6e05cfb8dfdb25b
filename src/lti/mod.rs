//! Linear time-invariant systems: plants, controllers, closed loops, spectral abscissa, the H∞
//! norm, their gradients with respect to the controller, and the full-order H∞ bound.
mod controller;
mod full_order;
mod matrix_json;
mod plant;
mod riccati;

pub use controller::{Controller, ControllerError, ControllerErrorKind};
pub use matrix_json::{matrix_from_json, matrix_to_json, MatrixJsonError};
pub use plant::{Dims, Plant, PlantError, PlantErrorKind};
pub use full_order::{
    full_order_gamma, full_order_gamma_with, Binding, FullOrderError, FullOrderGamma, FullOrderOptions,
    Regularisation, FLAT_RTOL, GAMMA_RTOL, REGULARISATION_EPS,
};
pub use riccati::{care_residual, solve_care, CareSolution, RiccatiError};
