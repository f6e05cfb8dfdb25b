//! Benchmark campaigns: campaign files, job expansion, scheduling, journal/resume, traces and
//! reports — plus the paper's reference numbers they are compared with.
mod reference;

pub use reference::{load_default_reference, load_reference, RefMethod, ReferenceError, ReferenceRow, REFERENCE_CSV};
