//! The campaign's report: its records reduced once ([`ReportData`]) and written by the
//! exporters of `super::export`, each file atomically (tmp in the same directory, fsync,
//! rename): the tables `best.csv`, `tables.tex`, `compare.csv`, `compare.tex`, `library.tex`, and
//! `strong_vs_plain.csv` when the campaign ran both objectives on a (plant, n_K), `plants.csv`
//! when it ran a problem of several plants ([`write_problem_reports`]); the page
//! `report/index.html` ([`write_html_report`]). Pure functions of journal records, the plants and
//! the paper's reference rows, so `campaign report` reruns without jobs ([`report`]).

use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use crate::campaign::execution::run::duplicate_ids;
use crate::campaign::leaves::library_index::{LibraryIndex, LibraryIndexError};
use crate::campaign::leaves::reference::{load_default_reference, ReferenceError, ReferenceRow};
use crate::campaign::leaves::sanitise::for_terminal;
use crate::campaign::model::campaign::{Campaign, Problem};
use crate::campaign::model::jobs::JobId;
use crate::campaign::records::record::JobRecord;
use crate::campaign::reduction::compare::{CampaignAbout, CompareRow};
use crate::campaign::reduction::export::{Exporter, ReportData, HTML_PAGE, TABLES};
use crate::campaign::reduction::latex;
use crate::campaign::reduction::reduce::{BestRow, PlantMap, ProblemMap};
use crate::lti::Plant;

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

/// Writes the file of each of `exporters` that has something to say into `data.dir` (its
/// folder created if needed); returns their paths.
pub fn write_exports(data: &ReportData, exporters: &[&(dyn Exporter + Sync)]) -> Result<Vec<PathBuf>, ReportError> {
    let mut files = Vec::new();
    for e in exporters {
        let p = data.dir.join(e.file());
        let Some(bytes) = e.export(data).map_err(|source| ReportError::Csv { path: p.clone(), source })? else {
            continue;
        };
        let folder = p.parent().unwrap_or(data.dir);
        crate::fs_atomic::create_dir_all(folder)
            .map_err(|source| ReportError::Io { path: folder.to_path_buf(), source })?;
        write_atomic(&p, &bytes)?;
        files.push(p);
    }
    Ok(files)
}

/// Reduces `records` and writes the report tables into `out_dir` (created if needed).
/// `plants` maps plant fingerprints to the plants (as `Job::plant` holds them); `reference` and
/// `library` give the full-order bounds not computed here.
pub fn write_reports(
    out_dir: &Path,
    records: &[JobRecord],
    plants: &PlantMap,
    reference: &[ReferenceRow],
    library: &LibraryIndex,
) -> Result<ReportSummary, ReportError> {
    write_problem_reports(out_dir, records, plants, &ProblemMap::new(), reference, library)
}

/// [`write_reports`] with the campaign's problems of several plants (`problems`, by
/// fingerprint): their rows are verified on every plant, and `plants.csv` gives each plant's
/// value.
pub fn write_problem_reports(
    out_dir: &Path,
    records: &[JobRecord],
    plants: &PlantMap,
    problems: &ProblemMap,
    reference: &[ReferenceRow],
    library: &LibraryIndex,
) -> Result<ReportSummary, ReportError> {
    crate::fs_atomic::create_dir_all(out_dir)
        .map_err(|source| ReportError::Io { path: out_dir.to_path_buf(), source })?;
    let data = ReportData::reduce(out_dir, records, plants, problems, reference, library);
    let files = write_exports(&data, &TABLES)?;
    Ok(ReportSummary { files, best: data.best, compare: data.compare })
}

/// Writes the page `<dir>/report/index.html` (atomically; `campaign::report_html`); returns its
/// path.
pub fn write_html_report(
    dir: &Path,
    best: &[BestRow],
    compare: &[CompareRow],
    records: &[JobRecord],
) -> Result<PathBuf, ReportError> {
    let data = ReportData {
        dir,
        records,
        reference: &[],
        best: best.to_vec(),
        full: Vec::new(),
        compare: compare.to_vec(),
        about: CampaignAbout::of(records),
    };
    write_exports(&data, &[HTML_PAGE])?;
    Ok(dir.join(HTML_PAGE.file()))
}

/// Why the report files could not be made.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum CampaignReportError {
    /// The paper's built-in reference table.
    #[error("reading the paper's reference table: {0}")]
    Reference(#[source] ReferenceError),
    /// The plant library's index of full-order values.
    #[error(transparent)]
    LibraryIndex(#[from] LibraryIndexError),
    /// Writing a report file.
    #[error(transparent)]
    Report(#[from] ReportError),
}

/// What [`report`] wrote: the files and the comparison, and the jobs journaled more than once.
#[derive(Debug, Clone)]
pub struct CampaignReport {
    /// The report files and the comparison with the paper.
    pub summary: ReportSummary,
    /// Jobs with more than one record (each counts once, by its best verified record).
    pub duplicates: Vec<(JobId, usize)>,
}

/// The campaign's plants by content fingerprint (their identity in records): each single-plant
/// problem's plant (named as the problem, when a structure gives it a fingerprint of its own).
/// Problems of several plants are in [`problem_map`].
pub fn plant_map(c: &Campaign) -> PlantMap {
    let plant = |p: &Problem| {
        if p.plant.name == p.name {
            p.plant.clone()
        } else {
            Arc::new(Plant { name: p.name.clone(), ..(*p.plant).clone() })
        }
    };
    c.problems.iter().filter(|p| p.multi.is_none()).map(|p| (p.fingerprint.clone(), plant(p))).collect()
}

/// The campaign's problems of several plants (or another objective, weight or bound) by their
/// fingerprint.
pub fn problem_map(c: &Campaign) -> ProblemMap {
    c.problems.iter().filter_map(|p| Some((p.fingerprint.clone(), p.multi.clone()?))).collect()
}

/// Reduces `records` (the campaign's, duplicates included) to the report files in `dir`
/// (best.csv, tables.tex, compare.csv/.tex, library.tex, …), with the paper's reference table
/// and the index of the plant library in use (`LibraryIndex::load_default`).
pub fn report(dir: &Path, c: &Campaign, records: &[JobRecord]) -> Result<CampaignReport, CampaignReportError> {
    let reference = load_default_reference().map_err(CampaignReportError::Reference)?;
    let library = LibraryIndex::load_default()?;
    let summary = write_problem_reports(dir, records, &plant_map(c), &problem_map(c), &reference, &library)?;
    Ok(CampaignReport { summary, duplicates: duplicate_ids(records) })
}

#[cfg(test)]
mod tests {
    use crate::campaign::FULL_ORDER_MAX_N;

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
