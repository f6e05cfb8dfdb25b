//! `compare.csv`: ours against the paper, one row per (plant, order, objective), with the
//! literature's values and the full-order bound.

use super::{csv_num, CsvFile, ReportData};
use crate::campaign::leaves::sanitise::for_csv;
use crate::campaign::reduction::compare::CompareRow;

/// `compare.csv`.
pub struct CompareCsv;

/// One row.
#[derive(serde::Serialize)]
pub struct Row {
    /// The plant (problem) name.
    plant: String,
    /// The controller order.
    order: usize,
    /// Our best verified γ.
    ours: String,
    /// The paper's γ.
    paper: String,
    /// Earlier literature's values, `source=γ` joined by `; `.
    literature: String,
    /// The full-order bound.
    full_order: String,
    /// ours/paper.
    ratio: String,
    /// The design objective (`strong` or `plain`).
    objective: &'static str,
}

impl CsvFile for CompareCsv {
    const FILE: &'static str = "compare.csv";
    type Row = Row;

    fn rows(data: &ReportData) -> Vec<Row> {
        let literature = |r: &CompareRow| r.literature.iter().map(|(s, g)| format!("{s}={g}")).collect::<Vec<_>>();
        data.compare
            .iter()
            .map(|r| Row {
                plant: for_csv(&r.plant),
                order: r.order,
                ours: csv_num(r.ours),
                paper: csv_num(r.paper),
                literature: for_csv(&literature(r).join("; ")),
                full_order: csv_num(r.full_order),
                ratio: csv_num(r.ratio),
                objective: r.objective.name(),
            })
            .collect()
    }
}
