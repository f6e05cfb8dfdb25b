//! `report/index.html`: the campaign's page ([`crate::campaign::report_html`]), written by
//! `campaign report`.

use super::{Exporter, ReportData};
use crate::campaign::reduction::html::report_html;

/// `report/index.html`.
pub struct HtmlPage;

impl Exporter for HtmlPage {
    fn file(&self) -> &'static str {
        "report/index.html"
    }

    fn export(&self, data: &ReportData) -> Result<Option<Vec<u8>>, csv::Error> {
        Ok(Some(report_html(data.dir, &data.best, &data.compare, data.records).into_bytes()))
    }
}
