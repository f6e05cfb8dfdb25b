//! `compare.csv`: ours against the paper, one row per (plant, order, objective), with the
//! literature's values and the full-order bound.

use super::{csv_bytes, csv_num, Exporter, ReportData};
use crate::campaign::leaves::sanitise::for_csv;

/// `compare.csv`.
pub struct CompareCsv;

#[derive(serde::Serialize)]
struct Row {
    plant: String,
    order: usize,
    ours: String,
    paper: String,
    literature: String,
    full_order: String,
    ratio: String,
    objective: &'static str,
}

impl Exporter for CompareCsv {
    fn file(&self) -> &'static str {
        "compare.csv"
    }

    fn export(&self, data: &ReportData) -> Result<Option<Vec<u8>>, csv::Error> {
        let rows = data.compare.iter().map(|r| Row {
            plant: for_csv(&r.plant),
            order: r.order,
            ours: csv_num(r.ours),
            paper: csv_num(r.paper),
            literature: for_csv(&r.literature.iter().map(|(s, g)| format!("{s}={g}")).collect::<Vec<_>>().join("; ")),
            full_order: csv_num(r.full_order),
            ratio: csv_num(r.ratio),
            objective: r.objective.name(),
        });
        csv_bytes(rows).map(Some)
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn snapshot() {
        super::super::fixture::assert_snapshot(&super::CompareCsv);
    }
}
