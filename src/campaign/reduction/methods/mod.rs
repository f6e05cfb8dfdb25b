//! `campaign compare`: comparisons of methods over many entries (plant, order, objective), as a
//! paper prints them. Two or more sources — results folders and external CSV files of other
//! methods' values ([`source`]) — are matched into rows ([`table`]), summarised as wins / ties /
//! losses and geometric means ([`summary`]) and drawn as performance profiles ([`profile`]).
//! [`compare_methods`] writes into one folder:
//!
//! * `entries.csv`, `entries.tex` — per entry each method's γ and ratio to the row's best;
//! * `summary.csv`, `summary.txt` — the totals, every missing and failed entry listed;
//! * `profile_gamma.{svg,png}` — the performance profile of γ;
//! * `profile_cpu.{svg,png}` — of CPU seconds, when every source gives them.
//!
//! Missing entries and failures are never dropped: they have ratio +∞. (The comparison with the
//! paper's column in a campaign's own report is `super::compare`.)

pub mod profile;
pub mod source;
pub mod summary;
pub mod table;
pub mod write;

use std::path::{Path, PathBuf};

use crate::campaign::reduction::plot::{write_png_and_svg, PlotError};
use crate::campaign::reduction::report::{write_atomic, ReportError};
use profile::ProfileFigure;
pub use source::{load_sources, Source, SourceEntry, SourceError};
pub use summary::{summarise, Summary, DEFAULT_RTOL};
pub use table::{entry_rows, Cell, EntryRow, Match};

/// A comparison could not be made or written.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum MethodsError {
    /// Fewer than two sources.
    #[error("a comparison needs at least two sources (LABEL=PATH), {0} given")]
    TooFew(usize),
    /// The tolerance is not a number in [0, 1).
    #[error("--rtol must be in [0, 1), found {0}")]
    Rtol(f64),
    /// No source has any entry.
    #[error("the sources have no entries")]
    Empty,
    /// Writing a file failed.
    #[error(transparent)]
    Write(#[from] ReportError),
    /// CSV serialisation failed.
    #[error("{}: {source}", path.display())]
    Csv {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: csv::Error,
    },
    /// A figure could not be drawn.
    #[error(transparent)]
    Plot(#[from] PlotError),
}

/// What a comparison found and wrote.
#[derive(Debug, Clone)]
pub struct MethodsOutcome {
    /// The rows.
    pub rows: Vec<EntryRow>,
    /// The summary.
    pub summary: Summary,
    /// `summary.txt`'s text.
    pub text: String,
    /// Files written.
    pub files: Vec<PathBuf>,
}

/// Compares `sources` at relative tolerance `rtol` and writes the files into `out` (created if
/// needed).
pub fn compare_methods(sources: &[Source], rtol: f64, out: &Path) -> Result<MethodsOutcome, MethodsError> {
    if sources.len() < 2 {
        return Err(MethodsError::TooFew(sources.len()));
    }
    if !(0.0..1.0).contains(&rtol) {
        return Err(MethodsError::Rtol(rtol));
    }
    let rows = entry_rows(sources);
    if rows.is_empty() {
        return Err(MethodsError::Empty);
    }
    crate::fs_atomic::create_dir_all(out).map_err(|source| ReportError::Io { path: out.to_path_buf(), source })?;
    let sm = summarise(&rows, sources.len(), rtol);
    let text = write::summary_text(sources, &rows, &sm);
    let mut files = Vec::new();
    let csv_file = |name: &str, bytes: Result<Vec<u8>, csv::Error>, files: &mut Vec<PathBuf>| {
        let p = out.join(name);
        let bytes = bytes.map_err(|source| MethodsError::Csv { path: p.clone(), source })?;
        write_atomic(&p, &bytes)?;
        files.push(p);
        Ok::<_, MethodsError>(())
    };
    csv_file("entries.csv", write::entries_csv(sources, &rows, rtol), &mut files)?;
    csv_file("summary.csv", write::summary_csv(sources, &sm), &mut files)?;
    for (name, text) in [("entries.tex", write::entries_tex(sources, &rows, rtol)), ("summary.txt", text.clone())] {
        let p = out.join(name);
        write_atomic(&p, text.as_bytes())?;
        files.push(p);
    }
    let profile = |f: fn(Cell) -> f64| -> Vec<(String, Vec<f64>)> {
        let per_row: Vec<Vec<f64>> =
            rows.iter().map(|r| table::ratios_to_best(&r.cells.iter().map(|c| f(*c)).collect::<Vec<_>>())).collect();
        sources.iter().enumerate().map(|(i, s)| (s.label.clone(), per_row.iter().map(|r| r[i]).collect())).collect()
    };
    let n = rows.len();
    let fig = ProfileFigure {
        title: format!("Performance profile of γ ({n} entries)"),
        x_desc: "τ: γ within a factor τ of the best (log scale)".into(),
        methods: profile(Cell::gamma),
    };
    files.extend(write_png_and_svg(&fig, &out.join("profile_gamma"))?);
    if sources.iter().all(Source::has_cpu) {
        let fig = ProfileFigure {
            title: format!("Performance profile of CPU time ({n} entries)"),
            x_desc: "τ: CPU seconds within a factor τ of the fastest (log scale)".into(),
            methods: profile(Cell::cpu),
        };
        files.extend(write_png_and_svg(&fig, &out.join("profile_cpu"))?);
    }
    Ok(MethodsOutcome { rows, summary: sm, text, files })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::campaign::leaves::reference::{load_default_reference, RefMethod, PAPER_PLANT_FINGERPRINTS};

    fn repo(p: &str) -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join(p)
    }

    fn csv_rows(bytes: &[u8]) -> Vec<csv::StringRecord> {
        csv::Reader::from_reader(bytes).records().map(Result::unwrap).collect()
    }

    /// The acceptance test of the issue: strong-stab against the paper's column reproduces the
    /// ratios of results/strong-stab/compare.csv exactly (the same text, so the same f64).
    #[test]
    fn strong_stab_vs_the_paper_reproduces_compare_csv() {
        let specs = [
            format!("strong-stab={}", repo("results/strong-stab").display()),
            format!("paper={}", repo("results/comparisons/paper-hifoo-2008.csv").display()),
        ];
        let sources = load_sources(&specs).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let out = compare_methods(&sources, DEFAULT_RTOL, dir.path()).unwrap();
        assert_eq!(out.rows.len(), 57);
        assert!(out.rows.iter().all(|r| r.matched == Match::Fingerprint));
        let entries = std::fs::read(dir.path().join("entries.csv")).unwrap();
        let mut reader = csv::Reader::from_reader(entries.as_slice());
        let head = reader.headers().unwrap().clone();
        let col = |n: &str| head.iter().position(|h| h == n).unwrap();
        let (plant, order, ratio) = (col("plant"), col("order"), col("strong-stab/paper"));
        let ours: Vec<(String, String, String)> = reader
            .records()
            .map(|r| r.unwrap())
            .map(|r| (r[plant].to_string(), r[order].to_string(), r[ratio].to_string()))
            .collect();
        let committed = csv_rows(&std::fs::read(repo("results/strong-stab/compare.csv")).unwrap());
        assert_eq!(committed.len(), 57);
        for c in committed {
            let want = (c[0].to_string(), c[1].to_string(), c[6].to_string());
            assert!(ours.contains(&want), "{want:?} not in entries.csv");
        }
        for name in ["summary.csv", "summary.txt", "entries.tex", "profile_gamma.svg", "profile_gamma.png"] {
            assert!(dir.path().join(name).is_file(), "{name}");
        }
        // the paper has no CPU times: no CPU profile
        assert!(!dir.path().join("profile_cpu.svg").exists());
    }

    /// results/comparisons/paper-hifoo-2008.csv is the reference table's HIFOO column of the
    /// plants the project ships, with their fingerprints.
    #[test]
    fn the_paper_csv_is_the_reference_tables_hifoo_column() {
        let src = source::load_source("paper".into(), &repo("results/comparisons/paper-hifoo-2008.csv")).unwrap();
        let reference = load_default_reference().unwrap();
        let want: Vec<_> = reference
            .iter()
            .filter(|r| r.method == RefMethod::Hifoo)
            .filter_map(|r| {
                let fp = PAPER_PLANT_FINGERPRINTS.iter().find(|(n, _)| *n == r.plant)?.1;
                Some((r.plant.clone(), fp.to_string(), r.order, r.gamma, r.controller_stable))
            })
            .collect();
        let got: Vec<_> = src
            .entries
            .iter()
            .map(|e| (e.plant.clone(), e.fingerprint.clone().unwrap(), e.order, e.gamma, e.stable.unwrap()))
            .collect();
        assert_eq!(got, want);
    }

    /// Two methods with CPU seconds: every file, the CPU profile too, and a failure listed.
    #[test]
    fn every_file_is_written_and_failures_listed() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a.csv");
        let b = dir.path().join("b.csv");
        std::fs::write(&a, "plant,order,objective,gamma,cpu_s\nP,1,strong,2,10\nP,2,strong,1,20\nQ,1,plain,3,5\n")
            .unwrap();
        std::fs::write(&b, "plant,order,objective,gamma,cpu_s\nP,1,strong,1,1\nP,2,strong,inf,\n").unwrap();
        let sources = load_sources(&[format!("A={}", a.display()), format!("B={}", b.display())]).unwrap();
        let out_dir = dir.path().join("out");
        let out = compare_methods(&sources, DEFAULT_RTOL, &out_dir).unwrap();
        assert_eq!(out.summary.pairs[0].wins, 2);
        assert_eq!(out.summary.pairs[0].losses, 1);
        assert!(out.text.contains("1 missing in B: Q n_K=1 plain"), "{}", out.text);
        assert!(out.text.contains("1 failed in B: P n_K=2 strong"), "{}", out.text);
        assert!(out_dir.join("profile_cpu.png").is_file());
        let rows = csv_rows(&std::fs::read(out_dir.join("entries.csv")).unwrap());
        assert_eq!(rows[0].iter().skip(5).collect::<Vec<_>>(), ["2", "2", "1", "1", "10", "1", "2"]);
        assert_eq!(rows[1].iter().skip(5).collect::<Vec<_>>(), ["1", "1", "failed", "inf", "20", "", ""]);
        assert_eq!(rows[2].iter().skip(5).collect::<Vec<_>>(), ["3", "1", "missing", "inf", "5", "", ""]);
        let tex = std::fs::read_to_string(out_dir.join("entries.tex")).unwrap();
        assert!(tex.contains("P & 1 & strong & 2.000 & \\textbf{1.000} & 2.0000 & 1.0000 \\\\"), "{tex}");
        assert!(matches!(compare_methods(&sources[..1], DEFAULT_RTOL, &out_dir), Err(MethodsError::TooFew(1))));
        assert!(matches!(compare_methods(&sources, 1.5, &out_dir), Err(MethodsError::Rtol(_))));
    }
}
