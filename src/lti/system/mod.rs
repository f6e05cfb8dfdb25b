//! The systems themselves: a state-space realisation (`state_space.rs`), the generalised plant
//! (`plant.rs`) and the controller (`controller.rs`) with their JSON and MAT-file forms, the
//! closed loop F_l(P, K) (`closed_loop.rs`), continuous or discrete time (`time_domain.rs`), the plant library that turns a benchmark name into a
//! plant file (`plant_library.rs`) and a controller written out as MATLAB or python-control code
//! (`export.rs`).
//!
//! Imports only `io` (and the shared `error`, `interrupt`) from the rest of `lti`.

pub(crate) mod closed_loop;
pub(crate) mod controller;
pub(crate) mod export;
pub(crate) mod plant;
pub(crate) mod plant_library;
pub(crate) mod state_space;
pub(crate) mod time_domain;
