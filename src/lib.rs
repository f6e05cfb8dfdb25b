//! hinfix: fixed-order H∞ controller design with strong stabilisation (the HIFOO method of
//! Burke, Henrion, Lewis and Overton; strong stabilisation after Gumussoy, Millstone and Overton,
//! CDC 2008) and a batch benchmark-campaign runner around it.
//!
//! Layers, each depending only on the ones above it:
//! - [`optim`]: a nonsmooth optimiser (BFGS + weak Wolfe, gradient-bundle certificate, gradient
//!   sampling) that knows nothing about control;
//! - [`lti`]: plants, controllers, closed loops, spectral abscissa, H∞ norm and their gradients;
//! - [`design`]: the HIFOO method, joining `lti` and `optim`;
//! - [`campaign`]: campaign files, job scheduling, journal/resume, traces and reports.
//!
//! Below all of them, [`numeric`] (a few shared numeric helpers) and [`fs_atomic`] (atomic file
//! writes). The layers, a job's path through them and the journal's guarantees are described in
//! docs/ARCHITECTURE.md; the methods, with their references, in docs/ALGORITHMS.md.
pub mod fs_atomic;
pub(crate) mod numeric;
pub mod optim;
pub mod lti;
pub mod design;
pub mod campaign;
