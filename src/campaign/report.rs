//! The campaign's report files, written atomically (tmp in the same directory, fsync, rename):
//! `best.csv`, `tables.tex`, `compare.csv`, `compare.tex`, and `strong_vs_plain.csv` when the
//! campaign ran both objectives on a (plant, n_K), and `plants.csv` when it ran a problem of
//! several plants ([`PlantsCsv`]: one row per plant of each best controller). Pure functions of journal records,
//! the plants and the paper's reference rows, so `campaign report` reruns without jobs.
//!
//! The rows themselves (ours against the paper's, the full-order bound) are computed by
//! [`compare_rows`] and [`full_order_rows`] (module `compare`, re-exported here); the LaTeX
//! rendering is [`super::latex`].

use std::collections::BTreeMap;
use std::fmt;
use std::path::{Path, PathBuf};

use super::latex;
use super::record::JobRecord;
use super::reduce::{best_per_problem, BestRow, ProblemMap};
use super::reference::ReferenceRow;
use super::sanitise::{for_csv, for_terminal};

// The rows moved to `compare` (so that `latex` and `report` no longer import each other); these
// paths stay valid.
pub use super::compare::{
    compare_rows, cost_rows, full_order_controller_stable, full_order_rows, CampaignAbout, CompareRow, CostRow,
    FullOrderRow, FULL_ORDER_CENTRAL_LEVEL, FULL_ORDER_MAX_N,
};

/// Errors writing the report, naming the file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReportError {
    /// I/O on a file.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// CSV serialisation.
    #[error("{}: {source}", path.display())]
    Csv {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: csv::Error,
    },
}

/// What was written, with a compact compare table as Display.
#[derive(Debug, Clone)]
pub struct ReportSummary {
    /// Files written.
    pub files: Vec<PathBuf>,
    /// Best rows.
    pub best: Vec<BestRow>,
    /// Compare rows.
    pub compare: Vec<CompareRow>,
}

impl fmt::Display for ReportSummary {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // the objective is named only when the campaign ran both
        let mixed = self.compare.iter().any(|r| r.objective != self.compare[0].objective);
        // the plant column as wide as its longest name (at least 8, the width it always had)
        let w = self.compare.iter().map(|r| for_terminal(&r.plant).chars().count()).fold(8, usize::max);
        writeln!(
            f,
            "{:<w$} {:>3} {:>11} {:>11} {:>8} {:>9}{}",
            "plant",
            "nK",
            "ours",
            "paper",
            "ratio",
            "verified",
            if mixed { "  objective" } else { "" }
        )?;
        for r in &self.compare {
            let b = self.best.iter().find(|b| b.plant == r.plant && b.order == r.order && b.objective == r.objective);
            let v = b.map(|b| format!("{}/{}", b.verified, b.runs)).unwrap_or_default();
            let objective = match (mixed, b.and_then(|b| b.controller_stable)) {
                (false, _) => String::new(),
                (true, Some(false)) => format!("  {} (K unstable)", r.objective.name()),
                (true, _) => format!("  {}", r.objective.name()),
            };
            writeln!(
                f,
                "{:<w$} {:>3} {:>11} {:>11} {:>8} {:>9}{objective}",
                for_terminal(&r.plant),
                r.order,
                latex::num(r.ours),
                latex::num(r.paper),
                latex::num(r.ratio),
                v
            )?;
        }
        Ok(())
    }
}

/// Writes `bytes` to `path` atomically and durably ([`crate::fs_atomic::write_atomic`]), with
/// the path in the error.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), ReportError> {
    crate::fs_atomic::write_atomic(path, bytes).map_err(|source| ReportError::Io { path: path.to_path_buf(), source })
}

fn csv_bytes<R: serde::Serialize>(path: &Path, rows: impl IntoIterator<Item = R>) -> Result<Vec<u8>, ReportError> {
    let err = |source| ReportError::Csv { path: path.to_path_buf(), source };
    let mut w = csv::Writer::from_writer(Vec::new());
    for r in rows {
        w.serialize(r).map_err(err)?;
    }
    w.into_inner().map_err(|e| ReportError::Io { path: path.to_path_buf(), source: e.into_error() })
}

#[derive(serde::Serialize)]
struct CompareCsv {
    plant: String,
    order: usize,
    ours: String,
    paper: String,
    literature: String,
    full_order: String,
    ratio: String,
    objective: &'static str,
}

/// One row of `plants.csv`: a plant of a problem of several plants (or another objective,
/// weight or bound), with its recomputed value for the best controller of the problem's
/// (problem, order, objective) row of best.csv.
#[derive(serde::Serialize)]
struct PlantsCsv {
    /// The problem's name (best.csv's `plant`).
    problem: String,
    order: usize,
    /// The design objective (`strong` or `plain`), as best.csv's `objective`.
    objective: &'static str,
    job_id: String,
    /// The plant's name.
    plant: String,
    /// Its objective: hinf, h2, abscissa or radius.
    plant_objective: &'static str,
    weight: String,
    /// Its bound, or "none".
    bound: String,
    /// g_j, unweighted.
    value: String,
    /// w_j·g_j.
    weighted: String,
    /// Whether w_j·g_j ≤ b_j (true without a bound).
    bound_met: bool,
    /// The closed loop's stability measure (α, or ρ − 1 in discrete time).
    alpha_cl: String,
}

/// The rows of `plants.csv` (none for a campaign of single-plant H∞ problems).
fn plants_rows(best: &[BestRow]) -> Vec<PlantsCsv> {
    let rows = best.iter().flat_map(|b| b.plants.iter().map(move |v| (b, v)));
    rows.map(|(b, v)| PlantsCsv {
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
        bound_met: v.bound_met(),
        alpha_cl: csv_num(v.alpha_cl),
    })
    .collect()
}

/// A number cell: non-finite values as "inf", "-inf", "nan", as in best.csv and every JSON file
/// (builds before left the cell empty).
fn csv_num(x: f64) -> String {
    crate::design::f64_text(x)
}

/// Reduces `records` and writes the four report files into `out_dir` (created if needed).
/// `plants` maps plant fingerprints to the plants (as `Job::plant` holds them).
pub fn write_reports(
    out_dir: &Path,
    records: &[JobRecord],
    plants: &BTreeMap<String, std::sync::Arc<crate::lti::Plant>>,
    reference: &[ReferenceRow],
) -> Result<ReportSummary, ReportError> {
    write_problem_reports(out_dir, records, plants, &ProblemMap::new(), reference)
}

/// [`write_reports`] with the campaign's problems of several plants (`problems`, by
/// fingerprint): their rows are verified on every plant, and `plants.csv` gives each plant's
/// value.
pub fn write_problem_reports(
    out_dir: &Path,
    records: &[JobRecord],
    plants: &BTreeMap<String, std::sync::Arc<crate::lti::Plant>>,
    problems: &ProblemMap,
    reference: &[ReferenceRow],
) -> Result<ReportSummary, ReportError> {
    std::fs::create_dir_all(out_dir).map_err(|source| ReportError::Io { path: out_dir.to_path_buf(), source })?;
    let best = best_per_problem(records, plants, problems);
    let full = full_order_rows(&best, plants, reference);
    let compare = compare_rows(&best, &full, reference);
    let mut files = Vec::new();

    let p = out_dir.join("best.csv");
    let best_csv = best.iter().map(|b| BestRow { plant: for_csv(&b.plant), ..b.clone() });
    write_atomic(&p, &csv_bytes(&p, best_csv)?)?;
    files.push(p);

    let p = out_dir.join("tables.tex");
    let about = CampaignAbout::of(records).with_plants(plants);
    write_atomic(&p, latex::tables_tex_about(&best, &full, reference, &about).as_bytes())?;
    files.push(p);

    // the two objectives side by side, when the campaign ran both on a (plant, n_K)
    let costs = cost_rows(&best);
    if !costs.is_empty() {
        let p = out_dir.join("strong_vs_plain.csv");
        let rows = costs.iter().map(|c| CostRow { plant: for_csv(&c.plant), ..c.clone() });
        write_atomic(&p, &csv_bytes(&p, rows)?)?;
        files.push(p);
    }

    let per_plant = plants_rows(&best);
    if !per_plant.is_empty() {
        let p = out_dir.join("plants.csv");
        write_atomic(&p, &csv_bytes(&p, per_plant)?)?;
        files.push(p);
    }

    let p = out_dir.join("compare.csv");
    let rows = compare.iter().map(|r| CompareCsv {
        plant: for_csv(&r.plant),
        order: r.order,
        ours: csv_num(r.ours),
        paper: csv_num(r.paper),
        literature: for_csv(&r.literature.iter().map(|(s, g)| format!("{s}={g}")).collect::<Vec<_>>().join("; ")),
        full_order: csv_num(r.full_order),
        ratio: csv_num(r.ratio),
        objective: r.objective.name(),
    });
    write_atomic(&p, &csv_bytes(&p, rows)?)?;
    files.push(p);

    let p = out_dir.join("compare.tex");
    write_atomic(&p, latex::compare_tex(&compare).as_bytes())?;
    files.push(p);

    Ok(ReportSummary { files, best, compare })
}

#[cfg(test)]
mod tests {
    use super::FULL_ORDER_MAX_N;

    /// The console table's columns line up whatever the length of the plant names (a name longer
    /// than the column's 8 characters pushed its row to the right); names of up to 8 keep the
    /// table as it always was.
    #[test]
    fn the_console_table_aligns_long_plant_names() {
        use super::ReportSummary;
        use crate::campaign::CompareRow;
        use crate::design::ObjectiveKind;
        let row = |plant: &str, order| CompareRow {
            plant: plant.into(),
            order,
            objective: ObjectiveKind::Strong,
            ours: 1.5,
            paper: 1.25,
            literature: vec![],
            full_order: f64::NAN,
            ratio: 1.2,
        };
        let table = |names: &[&str]| {
            let compare = names.iter().enumerate().map(|(i, n)| row(n, i)).collect();
            ReportSummary { files: vec![], best: vec![], compare }.to_string()
        };
        let widths = |t: &str| t.lines().map(|l| l.chars().count()).collect::<Vec<_>>();
        let long = table(&["HE1", "two_mass_spring", "AC10"]);
        let w = widths(&long);
        assert!(w.iter().all(|&x| x == w[0]), "{long}");
        assert_eq!(w[0], widths(&table(&["HE1"]))[0] + "two_mass_spring".len() - 8);
        let short = table(&["HE1", "Enns"]);
        assert!(short.starts_with(&format!("{:<8} {:>3} ", "plant", "nK")), "{short}");
        assert!(short.lines().nth(1).unwrap().starts_with(&format!("{:<8} {:>3} ", "HE1", 0)), "{short}");
    }

    /// campaigns/FORMAT.md states the limit in prose; it must say what the code does.
    #[test]
    fn format_md_states_full_order_max_n() {
        let doc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/campaigns/FORMAT.md")).unwrap();
        let want = format!("n ≤ {FULL_ORDER_MAX_N} ");
        assert!(doc.contains(&want), "campaigns/FORMAT.md should say `{want}` (FULL_ORDER_MAX_N)");
    }
}
