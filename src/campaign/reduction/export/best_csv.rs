//! `best.csv`: one row per (problem, order, objective), the best verified controller
//! ([`BestRow`]'s fields, the plant name escaped for CSV).

use super::{CsvFile, ReportData};
use crate::campaign::leaves::sanitise::for_csv;
use crate::campaign::reduction::reduce::BestRow;

/// `best.csv`.
pub struct BestCsv;

impl CsvFile for BestCsv {
    const FILE: &'static str = "best.csv";
    type Row = BestRow;

    fn rows(data: &ReportData) -> Vec<BestRow> {
        data.best.iter().map(|b| BestRow { plant: for_csv(&b.plant), ..b.clone() }).collect()
    }
}
