//! What is computed from a plant by Riccati equations and model reduction rather than by
//! optimisation: the optimal full-order H∞ level γ_opt (`full_order/`), the central full-order
//! controller at a γ above it (`central_controller.rs`) and balanced truncation
//! (`balanced_truncation.rs`), which reduces a controller to a fixed order.
//!
//! The top part of `lti`: imports `kernels` and `system`, and nothing imports it but
//! `lti/mod.rs`'s re-exports.

pub(crate) mod balanced_truncation;
pub(crate) mod central_controller;
pub(crate) mod full_order;
