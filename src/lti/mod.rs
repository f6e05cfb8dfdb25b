//! Linear time-invariant systems: plants, controllers, closed loops, spectral abscissa, the H∞
//! norm, their gradients with respect to the controller, and the full-order H∞ bound.
mod controller;
mod matrix_json;
mod plant;
mod plant_library;

pub use controller::{Controller, ControllerError, ControllerErrorKind};
pub use matrix_json::{matrix_from_json, matrix_to_json, MatrixJsonError};
pub use plant::{Dims, Plant, PlantError, PlantErrorKind};
pub use plant_library::{plants_dir, resolve_plant, shipped_plants, PLANTS_ENV};
