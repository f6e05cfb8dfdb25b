//! `strong_vs_plain.csv`: the two objectives side by side ([`CostRow`]), written only when the
//! campaign ran both on some (plant, n_K).

use super::{csv_bytes, Exporter, ReportData};
use crate::campaign::leaves::sanitise::for_csv;
use crate::campaign::reduction::compare::{cost_rows, CostRow};

/// `strong_vs_plain.csv`.
pub struct StrongVsPlainCsv;

impl Exporter for StrongVsPlainCsv {
    fn file(&self) -> &'static str {
        "strong_vs_plain.csv"
    }

    fn export(&self, data: &ReportData) -> Result<Option<Vec<u8>>, csv::Error> {
        let costs = cost_rows(&data.best);
        if costs.is_empty() {
            return Ok(None);
        }
        let rows = costs.iter().map(|c| CostRow { plant: for_csv(&c.plant), ..c.clone() });
        csv_bytes(rows).map(Some)
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn snapshot() {
        super::super::fixture::assert_snapshot(&super::StrongVsPlainCsv);
    }
}
