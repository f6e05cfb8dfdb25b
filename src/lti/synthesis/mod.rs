//! What is computed from a plant by Riccati equations and model reduction rather than by
//! optimisation: the optimal full-order H∞ level γ_opt (`full_order/`), the central full-order
//! controller at a γ above it (`central_controller.rs`), balanced truncation
//! (`balanced_truncation.rs`), which reduces a controller to a fixed order, the continuous-time
//! image of a discrete-time plant on which these run in discrete time (`plant_image.rs`), and whether a stable
//! controller can stabilise the plant at all (`strong_stabilisability.rs`: the parity interlacing
//! property).
//!
//! The top part of `lti`: imports `kernels` and `system`, and nothing imports it but
//! `lti/mod.rs`'s re-exports.

pub(crate) mod balanced_truncation;
pub(crate) mod central_controller;
pub(crate) mod full_order;
pub(crate) mod plant_image;
pub(crate) mod strong_stabilisability;
