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
//! - [`cli`]: the `campaign` command line (the binary's `main`), on top of all of them.
//!
//! Under all of them, used by any and using none: `numeric` (a few shared numeric helpers,
//! crate-private), [`fs_atomic`] (atomic, durable file writes) and [`input`] (bounded reading of
//! every input file, with documented size limits), [`panic_guard`] (a third-party parser's panic on
//! damaged input turned into an error), and [`malloc_tuning`] (the C allocator's reuse of
//! freed memory, set by the binary). The layers, a job's path through them and the
//! journal's guarantees are described in docs/ARCHITECTURE.md; the methods, with their
//! references, in docs/ALGORITHMS.md.
// `!(x > 0.0)` is this crate's NaN-aware comparison (true when x is NaN, which must count as a
// failure); clippy's suggested `partial_cmp` form would hide that intent.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
#![warn(missing_docs)]

pub mod campaign;
pub mod cli;
pub mod design;
pub mod fs_atomic;
pub mod input;
pub mod lti;
pub mod malloc_tuning;
pub(crate) mod numeric;
pub mod optim;
pub mod panic_guard;
