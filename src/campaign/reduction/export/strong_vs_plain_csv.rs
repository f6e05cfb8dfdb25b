//! `strong_vs_plain.csv`: the two objectives side by side ([`CostRow`]), written only when the
//! campaign ran both on some (plant, n_K).

use super::{CsvFile, ReportData};
use crate::campaign::leaves::sanitise::for_csv;
use crate::campaign::reduction::compare::{cost_rows, CostRow};

/// `strong_vs_plain.csv`.
pub struct StrongVsPlainCsv;

impl CsvFile for StrongVsPlainCsv {
    const FILE: &'static str = "strong_vs_plain.csv";
    const WRITTEN_EMPTY: bool = false;
    type Row = CostRow;

    fn rows(data: &ReportData) -> Vec<CostRow> {
        cost_rows(&data.best).into_iter().map(|c| CostRow { plant: for_csv(&c.plant), ..c }).collect()
    }
}
