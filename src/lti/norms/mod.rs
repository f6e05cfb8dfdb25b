//! The H∞ norm and the gradients with respect to the controller: `hinf.rs` (the level-set
//! method: ‖G‖∞, its peak frequency, the cheap lower bound of the line-search screen; what it
//! tells the benchmarks goes through one hook, `hinf_hooks.rs`) and
//! `gradient.rs` (α and ‖·‖∞ of the closed loop and of the controller with their gradients in
//! the controller's matrices), `discrete.rs` (the norm on the unit circle), `domain.rs` (which
//! of them a continuous- or discrete-time system takes), `h2.rs` (the H2 norm and its gradients,
//! the affine Dk of strictly proper loops), `stability_radius.rs` (1/r_C of the closed loop and
//! its gradient). Hand-written: no Rust crate offers them.
//!
//! Imports `kernels` and `system`; never `synthesis`.

pub(crate) mod discrete;
pub(crate) mod domain;
pub(crate) mod gradient;
pub(crate) mod h2;
pub(crate) mod hinf;
mod hinf_hooks;
pub(crate) mod sigma;
pub(crate) mod stability_radius;
