//! Reading a campaign's results: the best verified controller per entry (`reduce.rs`), the rows
//! against the paper and the full-order bound (`compare.rs`), the report files behind one
//! [`Exporter`](export::Exporter) each (`report.rs`, `export/`, with the LaTeX in `latex.rs`
//! and the HTML page in `html/`), the figures (`plot/`), the comparison of methods
//! (`methods/`), `campaign status` (`status.rs`) and a row's controller (`lookup.rs`).
pub(crate) mod compare;
pub(crate) mod export;
pub mod html;
pub(crate) mod latex;
pub(crate) mod lookup;
pub mod methods;
pub mod plot;
pub(crate) mod reduce;
pub(crate) mod report;
pub(crate) mod status;
