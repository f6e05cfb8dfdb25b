//! `tables.tex`: the paper's tables, ours beside its values, one per plant
//! ([`crate::campaign::tables_tex_about`]).

use super::{Exporter, ReportData};
use crate::campaign::reduction::latex::tables_tex_about;

/// `tables.tex`.
pub struct TablesTex;

impl Exporter for TablesTex {
    fn file(&self) -> &'static str {
        "tables.tex"
    }

    fn export(&self, data: &ReportData) -> Result<Option<Vec<u8>>, csv::Error> {
        Ok(Some(tables_tex_about(&data.best, &data.full, data.reference, &data.about).into_bytes()))
    }
}
