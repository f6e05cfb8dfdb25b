//! `plants.csv`: one row per plant of each best controller of a problem of several plants (or
//! of another objective, weight or bound); written only when the campaign has such a problem.

use super::{csv_num, CsvFile, ReportData};
use crate::campaign::leaves::sanitise::for_csv;

/// `plants.csv`.
pub struct PlantsCsv;

/// One row: a plant of a problem, with its recomputed value for the best controller of the
/// problem's (problem, order, objective) row of best.csv.
#[derive(serde::Serialize)]
pub struct Row {
    /// The problem's name (best.csv's `plant`).
    problem: String,
    /// The controller order.
    order: usize,
    /// The design objective (`strong` or `plain`), as best.csv's `objective`.
    objective: &'static str,
    /// The job of the best controller.
    job_id: String,
    /// The plant's name.
    plant: String,
    /// Its objective: hinf, h2, abscissa or radius.
    plant_objective: &'static str,
    /// Its weight w_j.
    weight: String,
    /// Its bound, or "none".
    bound: String,
    /// g_j, unweighted.
    value: String,
    /// w_j·g_j.
    weighted: String,
    /// Whether w_j·g_j ≤ b_j: `true`, `false`, or `none` without a bound (the journal's `null`;
    /// `true` there read as a bound that holds).
    bound_met: &'static str,
    /// The closed loop's stability measure (α, or ρ − 1 in discrete time).
    alpha_cl: String,
}

impl CsvFile for PlantsCsv {
    const FILE: &'static str = "plants.csv";
    const WRITTEN_EMPTY: bool = false;
    type Row = Row;

    fn rows(data: &ReportData) -> Vec<Row> {
        data.best
            .iter()
            .flat_map(|b| b.plants.iter().map(move |v| (b, v)))
            .map(|(b, v)| Row {
                problem: for_csv(&b.plant),
                order: b.order,
                objective: b.objective.name(),
                job_id: b.job_id.clone().unwrap_or_default(),
                plant: for_csv(&v.plant),
                plant_objective: v.objective.name(),
                weight: csv_num(v.weight),
                bound: v.bound.map_or_else(|| "none".to_string(), csv_num),
                value: csv_num(v.value),
                weighted: csv_num(v.weighted()),
                bound_met: match (v.bound, v.bound_met()) {
                    (None, _) => "none",
                    (Some(_), true) => "true",
                    (Some(_), false) => "false",
                },
                alpha_cl: csv_num(v.alpha_cl),
            })
            .collect()
    }
}
