//! The leaves of `campaign`, importing no other part: the provenance of a record, the paper's
//! reference values, the plant library's full-order values, escaping for the terminal, CSV and
//! LaTeX, and what a sparse trace keeps.
pub(crate) mod library_index;
pub(crate) mod provenance;
pub(crate) mod reference;
pub(crate) mod sanitise;
pub(crate) mod trace_filter;
