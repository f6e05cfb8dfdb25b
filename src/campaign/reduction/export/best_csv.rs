//! `best.csv`: one row per (problem, order, objective), the best verified controller
//! ([`BestRow`]'s fields, the plant name escaped for CSV).

use super::{csv_bytes, Exporter, ReportData};
use crate::campaign::leaves::sanitise::for_csv;
use crate::campaign::reduction::reduce::BestRow;

/// `best.csv`.
pub struct BestCsv;

impl Exporter for BestCsv {
    fn file(&self) -> &'static str {
        "best.csv"
    }

    fn export(&self, data: &ReportData) -> Result<Option<Vec<u8>>, csv::Error> {
        let rows = data.best.iter().map(|b| BestRow { plant: for_csv(&b.plant), ..b.clone() });
        csv_bytes(rows).map(Some)
    }
}

#[cfg(test)]
mod tests {
    #[test]
    fn snapshot() {
        super::super::fixture::assert_snapshot(&super::BestCsv);
    }
}
