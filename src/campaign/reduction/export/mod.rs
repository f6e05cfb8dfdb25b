//! The report files, one [`Exporter`] each (one small file per output format): `best.csv`,
//! `tables.tex`, `strong_vs_plain.csv`, `plants.csv`, `compare.csv`, `compare.tex`,
//! `library.tex` (the tables that `campaign run` and `campaign report` write, [`TABLES`]) and the
//! page `report/index.html` ([`HTML_PAGE`], `campaign report` only). Every exporter is a pure
//! function of the reduced report ([`ReportData`]); `super::report` writes what they return,
//! atomically.
//!
//! A new output format is one file here: a unit struct implementing [`Exporter`] (its file name
//! and its bytes; a CSV file implements [`CsvFile`], its rows), listed in [`TABLES`], and one line
//! in the snapshot tests below: its output for the fixture journal
//! `tests/fixtures/report/runs.jsonl` is committed as `tests/fixtures/report/expected/<file>.snap`.

mod best_csv;
mod compare_csv;
mod compare_tex;
mod html_page;
mod library_tex;
mod plants_csv;
mod strong_vs_plain_csv;
mod tables_tex;

use std::path::Path;

use crate::campaign::leaves::library_index::LibraryIndex;
use crate::campaign::leaves::reference::ReferenceRow;
use crate::campaign::records::record::JobRecord;
use crate::campaign::reduction::compare::{compare_rows, full_order_rows, CampaignAbout, CompareRow, FullOrderRow};
use crate::campaign::reduction::reduce::{best_per_problem, BestRow, PlantMap, ProblemMap};

pub use best_csv::BestCsv;
pub use compare_csv::CompareCsv;
pub use compare_tex::CompareTex;
pub use html_page::HtmlPage;
pub use library_tex::LibraryTex;
pub use plants_csv::PlantsCsv;
pub use strong_vs_plain_csv::StrongVsPlainCsv;
pub use tables_tex::TablesTex;

/// What every report file is made from: a campaign's records reduced to the best verified
/// controller per entry, its full-order bounds and its comparison with the paper.
#[derive(Debug, Clone)]
pub struct ReportData<'a> {
    /// The campaign's results folder (the HTML page links the figures found in its `plots/`).
    pub dir: &'a Path,
    /// The journaled records, duplicates included.
    pub records: &'a [JobRecord],
    /// The paper's reference rows.
    pub reference: &'a [ReferenceRow],
    /// The best verified controller per (problem, order, objective).
    pub best: Vec<BestRow>,
    /// The full-order bound per plant.
    pub full: Vec<FullOrderRow>,
    /// Ours against the paper.
    pub compare: Vec<CompareRow>,
    /// The campaign's ε, seeds, budgets and plants (the captions of `tables.tex` and `library.tex`).
    pub about: CampaignAbout,
}

impl<'a> ReportData<'a> {
    /// Reduces `records` (`plants` and `problems` by fingerprint, as `Job::plant` and
    /// `Job::multi` hold them): each controller re-verified, the best per entry, the full-order
    /// bounds (computed, else the paper's, else `library`'s) and the comparison rows.
    pub fn reduce(
        dir: &'a Path,
        records: &'a [JobRecord],
        plants: &PlantMap,
        problems: &ProblemMap,
        reference: &'a [ReferenceRow],
        library: &LibraryIndex,
    ) -> Self {
        let best = best_per_problem(records, plants, problems);
        let full = full_order_rows(&best, plants, reference, library);
        let compare = compare_rows(&best, &full, reference);
        let about = CampaignAbout::of(records).with_plants(plants);
        ReportData { dir, records, reference, best, full, compare, about }
    }
}

/// One output format of the report.
pub trait Exporter {
    /// The file, relative to the campaign's results folder.
    fn file(&self) -> &'static str;

    /// The file's contents; `None` when the campaign has nothing for it (no file is written).
    fn export(&self, data: &ReportData) -> Result<Option<Vec<u8>>, csv::Error>;
}

/// A CSV report file: its rows under a header (no bytes at all for no rows). Every `CsvFile` is
/// an [`Exporter`].
pub trait CsvFile {
    /// The file, relative to the campaign's results folder.
    const FILE: &'static str;
    /// Whether the file is written (empty) when it has no rows.
    const WRITTEN_EMPTY: bool = true;
    /// One row.
    type Row: serde::Serialize;

    /// The rows, in file order.
    fn rows(data: &ReportData) -> Vec<Self::Row>;
}

impl<T: CsvFile> Exporter for T {
    fn file(&self) -> &'static str {
        T::FILE
    }

    fn export(&self, data: &ReportData) -> Result<Option<Vec<u8>>, csv::Error> {
        let rows = T::rows(data);
        if rows.is_empty() && !T::WRITTEN_EMPTY {
            return Ok(None);
        }
        let mut w = csv::Writer::from_writer(Vec::new());
        for r in rows {
            w.serialize(r)?;
        }
        w.into_inner().map(Some).map_err(|e| e.into_error().into())
    }
}

/// The tables, in the order they are written.
pub const TABLES: [&(dyn Exporter + Sync); 7] =
    [&BestCsv, &TablesTex, &StrongVsPlainCsv, &PlantsCsv, &CompareCsv, &CompareTex, &LibraryTex];

/// The HTML page.
pub const HTML_PAGE: &(dyn Exporter + Sync) = &HtmlPage;

/// A number cell: non-finite values as "inf", "-inf", "nan", as in best.csv and every JSON file
/// (builds before left the cell empty).
fn csv_num(x: f64) -> String {
    crate::design::f64_text(x)
}

/// Each exporter against the fixture campaign `tests/fixtures/report/report.toml`: its output
/// for the journal `runs.jsonl` is `expected/<file name>.snap` byte for byte.
#[cfg(test)]
mod snapshots {
    use std::path::{Path, PathBuf};

    use super::*;
    use crate::campaign::leaves::reference::load_default_reference;
    use crate::campaign::records::journal::read_journal;
    use crate::campaign::reduction::report::{plant_map, problem_map};
    use crate::campaign::Campaign;

    fn dir() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/report")
    }

    /// `f` of the fixture journal's report data (with the project's plant library index).
    pub(super) fn with_fixture<T>(f: impl FnOnce(ReportData) -> T) -> T {
        let dir = dir();
        let campaign = Campaign::load(&dir.join("report.toml")).unwrap();
        let records = read_journal(&dir.join("runs.jsonl")).unwrap().records;
        let reference = load_default_reference().unwrap();
        let library = LibraryIndex::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("plants")).unwrap();
        f(ReportData::reduce(&dir, &records, &plant_map(&campaign), &problem_map(&campaign), &reference, &library))
    }

    fn assert_snapshot(exporter: &dyn Exporter) {
        let got = with_fixture(|data| exporter.export(&data).unwrap().unwrap_or_default());
        let name = Path::new(exporter.file()).file_name().unwrap().to_string_lossy();
        let snap = dir().join("expected").join(format!("{name}.snap"));
        if std::env::var_os("HINFIX_BLESS_SNAPSHOTS").is_some() {
            // a deliberate change of a report file: write the new snapshot, review it in the diff
            std::fs::write(&snap, &got).unwrap();
            return;
        }
        let want = std::fs::read_to_string(&snap).unwrap();
        assert_eq!(String::from_utf8(got).unwrap(), want, "{}", exporter.file());
    }

    /// One test per exporter, named after its file.
    macro_rules! snapshot_tests {
        ($($test:ident: $exporter:expr),* $(,)?) => {
            $(
                #[test]
                fn $test() {
                    assert_snapshot(&$exporter);
                }
            )*
        };
    }

    snapshot_tests!(
        best_csv: BestCsv,
        tables_tex: TablesTex,
        strong_vs_plain_csv: StrongVsPlainCsv,
        plants_csv: PlantsCsv,
        compare_csv: CompareCsv,
        compare_tex: CompareTex,
        library_tex: LibraryTex,
        html_page: HtmlPage,
    );
}
