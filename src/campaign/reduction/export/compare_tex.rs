//! `compare.tex`: ours against the paper as a LaTeX table ([`crate::campaign::compare_tex`]).

use super::{Exporter, ReportData};
use crate::campaign::reduction::latex::compare_tex;

/// `compare.tex`.
pub struct CompareTex;

impl Exporter for CompareTex {
    fn file(&self) -> &'static str {
        "compare.tex"
    }

    fn export(&self, data: &ReportData) -> Result<Option<Vec<u8>>, csv::Error> {
        Ok(Some(compare_tex(&data.compare).into_bytes()))
    }
}
