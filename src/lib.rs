//! hinfix: fixed-order H∞ controller design with strong stabilisation (the HIFOO method of
//! Burke, Henrion, Lewis and Overton; strong stabilisation after Gumussoy, Millstone and Overton,
//! CDC 2008) and a batch benchmark-campaign runner around it.
//!
//! Layers, each depending only on the ones above it:
//! - [`optim`]: a nonsmooth optimiser (BFGS + weak Wolfe, gradient-bundle certificate, gradient
//!   sampling) that knows nothing about control;
//! - [`lti`]: plants, controllers, closed loops, spectral abscissa, H∞ norm and their gradients;
//! - [`design`]: the HIFOO method, joining `lti` and `optim`;
//! - [`campaign`]: campaign files, job scheduling, journal/resume, traces and reports;
//! - [`input`]: bounded reading of every input file (documented size limits).
pub mod input;
pub mod optim;
pub mod lti;
pub mod design;
pub mod campaign;
