//! The sources of `campaign compare`: each `LABEL=PATH` is a results folder (its `best.csv`, and
//! the CPU seconds of its journals) or an external CSV file of one method's values (columns
//! `plant, order, objective, gamma`, optional `cpu_s`, `stable`, `plant_fingerprint`; any other
//! column is ignored). Every bad cell of an external file is an error naming the file, the line
//! and the column (campaigns/FORMAT.md, "Comparing methods").

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::campaign::records::journal::{journals_in, read_journal, JournalError};
use crate::campaign::reduction::reduce::BestRow;
use crate::design::ObjectiveKind;

/// Largest source file read (an external CSV or a `best.csv`): 64 MiB.
pub const MAX_SOURCE_BYTES: u64 = 64 << 20;

/// Longest method label, in characters.
pub const MAX_LABEL_CHARS: usize = 40;

/// One method's value of one entry (plant, order, objective).
#[derive(Debug, Clone, PartialEq)]
pub struct SourceEntry {
    /// Plant name.
    pub plant: String,
    /// The plant's content fingerprint, when the source gives it.
    pub fingerprint: Option<String>,
    /// Controller order n_K.
    pub order: usize,
    /// Design objective.
    pub objective: ObjectiveKind,
    /// γ; not finite when the method found no (strongly) stabilising controller.
    pub gamma: f64,
    /// CPU seconds spent on the entry, when the source gives them.
    pub cpu_s: Option<f64>,
    /// Whether the method's controller is stable, when the source says.
    pub stable: Option<bool>,
}

impl SourceEntry {
    /// Whether the method solved the entry: a finite positive γ, and for the strong objective a
    /// controller not declared unstable.
    pub fn solved(&self) -> bool {
        self.gamma.is_finite()
            && self.gamma > 0.0
            && !(self.objective == ObjectiveKind::Strong && self.stable == Some(false))
    }
}

/// One method: its label, where its values came from, and the values.
#[derive(Debug, Clone, PartialEq)]
pub struct Source {
    /// The label (a table column, a legend entry).
    pub label: String,
    /// The results folder or CSV file.
    pub path: PathBuf,
    /// Its entries, in the file's order.
    pub entries: Vec<SourceEntry>,
}

impl Source {
    /// Whether every solved entry has its CPU seconds (the CPU profile needs them all).
    pub fn has_cpu(&self) -> bool {
        self.entries.iter().filter(|e| e.solved()).all(|e| e.cpu_s.is_some())
    }
}

/// A source could not be read.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SourceError {
    /// Not `LABEL=PATH`, or a bad label.
    #[error("source `{spec}`: {problem}")]
    Spec {
        /// The argument.
        spec: String,
        /// What is wrong.
        problem: String,
    },
    /// Two sources share a label.
    #[error("two sources are labelled `{0}`")]
    DuplicateLabel(String),
    /// A file could not be read.
    #[error("{}: cannot read: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// The CSV structure is broken (e.g. a row with another number of fields).
    #[error("{}, line {line}: {source}", path.display())]
    Csv {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: u64,
        /// The CSV reader's error.
        #[source]
        source: csv::Error,
    },
    /// A bad cell, or a missing column (line 1, the header).
    #[error("{}, line {line}, column `{column}`: {problem}", path.display())]
    Cell {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: u64,
        /// The column's name.
        column: String,
        /// What is wrong.
        problem: String,
    },
    /// A results folder's journal could not be read.
    #[error(transparent)]
    Journal(#[from] JournalError),
}

/// Parses `LABEL=PATH` (the label: letters, digits and `-_.+`, at most [`MAX_LABEL_CHARS`]).
pub fn parse_spec(spec: &str) -> Result<(String, PathBuf), SourceError> {
    let bad = |problem: &str| SourceError::Spec { spec: spec.to_string(), problem: problem.to_string() };
    let Some((label, path)) = spec.split_once('=') else { return Err(bad("expected LABEL=PATH")) };
    if label.is_empty() || path.is_empty() {
        return Err(bad("expected LABEL=PATH, both non-empty"));
    }
    if label.chars().count() > MAX_LABEL_CHARS
        || !label.chars().all(|c| c.is_ascii_alphanumeric() || "-_.+".contains(c))
    {
        return Err(bad(&format!("a label is 1 to {MAX_LABEL_CHARS} letters, digits or -_.+")));
    }
    Ok((label.to_string(), PathBuf::from(path)))
}

/// Reads every `LABEL=PATH` source; labels must differ.
pub fn load_sources(specs: &[String]) -> Result<Vec<Source>, SourceError> {
    let mut out: Vec<Source> = Vec::new();
    for spec in specs {
        let (label, path) = parse_spec(spec)?;
        if out.iter().any(|s| s.label == label) {
            return Err(SourceError::DuplicateLabel(label));
        }
        out.push(load_source(label, &path)?);
    }
    Ok(out)
}

/// Reads one source: a results folder or an external CSV file.
pub fn load_source(label: String, path: &Path) -> Result<Source, SourceError> {
    let entries = if path.is_dir() { results_entries(path)? } else { external_entries(path)? };
    Ok(Source { label, path: path.to_path_buf(), entries })
}

fn read(path: &Path) -> Result<Vec<u8>, SourceError> {
    crate::input::read_capped(path, MAX_SOURCE_BYTES, "comparison source")
        .map_err(|source| SourceError::Io { path: path.to_path_buf(), source })
}

/// A results folder's entries: its `best.csv` rows (a row with no verified controller is a
/// failure), each with the CPU seconds of every journaled job of its (plant, order, objective)
/// (a job journaled twice counts once) when the folder holds journals.
fn results_entries(dir: &Path) -> Result<Vec<SourceEntry>, SourceError> {
    let best_path = dir.join("best.csv");
    let bytes = read(&best_path)?;
    let mut reader = csv::Reader::from_reader(bytes.as_slice());
    let mut rows: Vec<BestRow> = Vec::new();
    for (i, rec) in reader.deserialize::<BestRow>().enumerate() {
        let row = rec.map_err(|source| SourceError::Csv {
            path: best_path.clone(),
            line: source.position().map_or(0, |p| p.line()),
            source,
        })?;
        // `campaign report` writes these rows; one that contradicts itself was edited or damaged
        // (γ ≤ 0 counted as a failure, a row of 0 verified jobs with a job as solved, a second
        // row of one entry as another plant)
        let line = i as u64 + 2;
        let bad = |column: &str, problem: String| SourceError::Cell {
            path: best_path.clone(),
            line,
            column: column.into(),
            problem: format!("{problem}; best.csv is damaged (`campaign report` writes it again from the journal)"),
        };
        if row.job_id.is_some() && !(row.gamma > 0.0 && row.gamma.is_finite()) {
            return Err(bad("gamma", format!("a row with a verified job has γ = {}", row.gamma)));
        }
        if row.job_id.is_some() && row.verified == 0 {
            return Err(bad("verified", "a row with a job counts 0 verified jobs".into()));
        }
        let same = |o: &BestRow| {
            (&o.plant_fingerprint, o.order, o.objective) == (&row.plant_fingerprint, row.order, row.objective)
        };
        if let Some(j) = rows.iter().position(same) {
            return Err(bad(
                "plant",
                format!("{} n_K = {}, {} is on line {} too", row.plant, row.order, row.objective.name(), j + 2),
            ));
        }
        rows.push(row);
    }
    let cpu = journal_cpu(dir)?;
    Ok(rows
        .into_iter()
        .map(|r| {
            let key = (r.plant_fingerprint.clone(), r.order, r.objective.name());
            SourceEntry {
                cpu_s: cpu.as_ref().and_then(|c| c.get(&key).copied()),
                plant: r.plant,
                fingerprint: Some(r.plant_fingerprint),
                order: r.order,
                objective: r.objective,
                gamma: if r.job_id.is_some() { r.gamma } else { f64::INFINITY },
                stable: r.controller_stable,
            }
        })
        .collect())
}

/// CPU seconds per (fingerprint, order, objective) over the folder's journals (None without
/// journals).
type CpuMap = BTreeMap<(String, usize, &'static str), f64>;

fn journal_cpu(dir: &Path) -> Result<Option<CpuMap>, SourceError> {
    let files = journals_in(dir)?;
    if files.is_empty() {
        return Ok(None);
    }
    let mut seen = std::collections::BTreeSet::new();
    let mut cpu = CpuMap::new();
    for f in files {
        for r in read_journal(&f)?.records {
            if seen.insert(r.job_id.0.clone()) {
                *cpu.entry((r.plant_fingerprint.clone(), r.order, r.options.objective.name())).or_default() += r.cpu_s;
            }
        }
    }
    Ok(Some(cpu))
}

/// The columns of an external CSV: required, then optional.
const REQUIRED: [&str; 4] = ["plant", "order", "objective", "gamma"];

/// An external CSV's entries, every cell checked.
fn external_entries(path: &Path) -> Result<Vec<SourceEntry>, SourceError> {
    let bytes = read(path)?;
    let csv_err = |source: csv::Error| SourceError::Csv {
        path: path.to_path_buf(),
        line: source.position().map_or(1, |p| p.line()),
        source,
    };
    let mut reader = csv::ReaderBuilder::new().trim(csv::Trim::All).from_reader(bytes.as_slice());
    let header = reader.headers().map_err(csv_err)?.clone();
    let col = |name: &str| header.iter().position(|h| h == name);
    let mut idx = [0usize; 4];
    for (i, name) in REQUIRED.iter().enumerate() {
        idx[i] = col(name).ok_or_else(|| SourceError::Cell {
            path: path.to_path_buf(),
            line: 1,
            column: name.to_string(),
            problem: format!("missing column (the header has: {})", header.iter().collect::<Vec<_>>().join(", ")),
        })?;
    }
    let (cpu_col, stable_col, fp_col) = (col("cpu_s"), col("stable"), col("plant_fingerprint"));
    let mut out = Vec::new();
    let mut lines: Vec<(String, Option<String>, usize, &'static str, u64)> = Vec::new();
    for rec in reader.records() {
        let rec = rec.map_err(csv_err)?;
        let line = rec.position().map_or(0, |p| p.line());
        let cell = |i: usize| rec.get(i).unwrap_or("");
        let bad = |column: &str, problem: String| SourceError::Cell {
            path: path.to_path_buf(),
            line,
            column: column.to_string(),
            problem,
        };
        let plant = cell(idx[0]).to_string();
        if plant.is_empty() {
            return Err(bad("plant", "empty plant name".into()));
        }
        let order: usize = cell(idx[1])
            .parse()
            .map_err(|_| bad("order", format!("`{}` is not an order (0, 1, 2, …)", cell(idx[1]))))?;
        let objective = match cell(idx[2]) {
            "strong" => ObjectiveKind::Strong,
            "plain" => ObjectiveKind::Plain,
            other => return Err(bad("objective", format!("`{other}` is neither `strong` nor `plain`"))),
        };
        let gamma = parse_gamma(cell(idx[3])).map_err(|p| bad("gamma", p))?;
        let cpu_s = match cpu_col.map(cell).unwrap_or("") {
            "" => None,
            s => match s.parse::<f64>() {
                Ok(x) if x.is_finite() && x >= 0.0 => Some(x),
                _ => return Err(bad("cpu_s", format!("`{s}` is not a number of seconds ≥ 0"))),
            },
        };
        let stable = match stable_col.map(cell).unwrap_or("") {
            "" => None,
            "true" | "stable" => Some(true),
            "false" | "unstable" => Some(false),
            s => return Err(bad("stable", format!("`{s}` is not true/false (or stable/unstable)"))),
        };
        let fingerprint = match fp_col.map(cell).unwrap_or("") {
            "" => None,
            s if s.len() == 64 && s.chars().all(|c| c.is_ascii_hexdigit()) => Some(s.to_ascii_lowercase()),
            s => return Err(bad("plant_fingerprint", format!("`{s}` is not 64 hexadecimal digits"))),
        };
        // One plant is one fingerprint whatever its name: two rows at one order and objective
        // are one entry twice when their fingerprints agree, or when their names agree and one
        // gives no fingerprint (rows of one fingerprint under two names were taken as two
        // plants, and the comparison then found one of them "missing").
        let same = |(p, fp, k, o, _): &(String, Option<String>, usize, &str, u64)| {
            *k == order
                && *o == objective.name()
                && match (fp, &fingerprint) {
                    (Some(a), Some(b)) => a == b,
                    _ => *p == plant,
                }
        };
        let first = lines.iter().find(|e| same(e)).map(|e| e.4);
        lines.push((plant.clone(), fingerprint.clone(), order, objective.name(), line));
        if let Some(first) = first {
            return Err(bad(
                "plant",
                format!("duplicate entry: {plant}, order {order}, {} is on line {first} too", objective.name()),
            ));
        }
        out.push(SourceEntry { plant, fingerprint, order, objective, gamma, cpu_s, stable });
    }
    Ok(out)
}

/// A γ cell: a positive number, or empty / `inf` (any letter case, `+inf`, `infinity`) for a
/// failure (no controller found). A number out of f64's range (1e999, 1e-400) is an error that
/// quotes the cell (it was "found inf" or "found 0").
fn parse_gamma(s: &str) -> Result<f64, String> {
    let word = s.strip_prefix('+').unwrap_or(s).to_ascii_lowercase();
    if s.is_empty() || word == "inf" || word == "infinity" {
        return Ok(f64::INFINITY);
    }
    match s.parse::<f64>() {
        Ok(g) if g > 0.0 && g.is_finite() => Ok(g),
        Ok(g) if g.is_infinite() || (g == 0.0 && s.chars().any(|c| ('1'..='9').contains(&c))) => {
            Err(format!("`{s}` is out of the range of a double-precision number"))
        }
        Ok(_) => Err(format!("γ must be positive and finite (or empty/inf for a failure), found `{s}`")),
        Err(_) => Err(format!("`{s}` is not a number")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn write(dir: &Path, text: &str) -> PathBuf {
        let p = dir.join("m.csv");
        std::fs::write(&p, text).unwrap();
        p
    }

    fn err(text: &str) -> String {
        let d = tempfile::tempdir().unwrap();
        let p = write(d.path(), text);
        load_source("m".into(), &p).unwrap_err().to_string()
    }

    #[test]
    fn a_good_file_reads_with_optional_columns() {
        let d = tempfile::tempdir().unwrap();
        let p = write(
            d.path(),
            "plant,order,objective,gamma,cpu_s,stable,note\nHE1,1,strong,0.1235,2.5,true,x\nHE1,2,strong,inf,,,\nAC8,0,plain,2,,false,\n",
        );
        let s = load_source("m".into(), &p).unwrap();
        assert_eq!(s.entries.len(), 3);
        assert_eq!(s.entries[0].gamma, 0.1235);
        assert_eq!(s.entries[0].cpu_s, Some(2.5));
        assert!(s.entries[0].solved() && !s.entries[1].solved());
        // plain: an unstable controller is still a solution
        assert!(s.entries[2].solved());
        assert!(!s.has_cpu());
    }

    #[test]
    fn bad_files_name_the_file_line_and_column() {
        let cases: [(&str, &[&str]); 8] = [
            ("plant,order,gamma\nHE1,1,0.5\n", &["m.csv, line 1, column `objective`: missing column"]),
            (
                "plant,order,objective,gamma\nHE1,1,strong,0.5\nHE1,2,strong,abc\n",
                &["m.csv, line 3, column `gamma`", "`abc` is not a number"],
            ),
            ("plant,order,objective,gamma\nHE1,1,strong,0.5\nHE1,x,strong,1\n", &["line 3, column `order`"]),
            (
                "plant,order,objective,gamma\nHE1,1,strong,0.5\nAC8,1,strong,2\nHE1,1,strong,0.6\n",
                &["line 4, column `plant`", "duplicate", "line 2"],
            ),
            ("plant,order,objective,gamma\nHE1,1,weak,0.5\n", &["line 2, column `objective`"]),
            ("plant,order,objective,gamma\nHE1,1,strong,-1\n", &["line 2, column `gamma`", "positive"]),
            ("plant,order,objective,gamma,cpu_s\nHE1,1,strong,1,-3\n", &["line 2, column `cpu_s`"]),
            ("plant,order,objective,gamma\nHE1,1,strong\n", &["m.csv, line 2"]),
        ];
        for (text, wants) in cases {
            let e = err(text);
            assert!(wants.iter().all(|w| e.contains(w)), "{e}");
        }
    }

    /// One fingerprint under two names, or a name once with and once without its fingerprint,
    /// is one entry twice; `inf` in any case is a failure, a number out of range an error that
    /// quotes it.
    #[test]
    fn duplicates_by_content_and_gamma_words() {
        let fp = "4822dac1ddd3cc168d3a06071f6a15109a4f86177544dc0261c1f3c897035423";
        let other = "e12e880ce104f5ea2933b97d1a98b321d773fc46057a0f73accf5fb8dfe1879d";
        let head = "plant,order,objective,gamma,plant_fingerprint\n";
        for rows in [
            format!("HE1,1,strong,0.2,{fp}\nHEONE,1,strong,0.1,{fp}\n"),
            format!("HE1,1,strong,0.2,{fp}\nHE1,1,strong,0.1,\n"),
            format!("HE1,1,strong,0.2,\nHE1,1,strong,0.1,{fp}\n"),
        ] {
            let e = err(&format!("{head}{rows}"));
            assert!(e.contains("line 3, column `plant`") && e.contains("duplicate") && e.contains("line 2"), "{e}");
        }
        // two plants of one name, told apart by their fingerprints, are two entries
        let d = tempfile::tempdir().unwrap();
        let p = write(d.path(), &format!("{head}HE1,1,strong,0.2,{fp}\nHE1,1,strong,0.1,{other}\n"));
        assert_eq!(load_source("m".into(), &p).unwrap().entries.len(), 2);
        for word in ["", "inf", "INF", "+inf", "Infinity", "+Infinity"] {
            assert_eq!(parse_gamma(word), Ok(f64::INFINITY), "{word}");
        }
        for (cell, says) in [("1e999", "out of the range"), ("1e-400", "out of the range"), ("0", "found `0`")] {
            let e = parse_gamma(cell).unwrap_err();
            assert!(e.contains(says) && e.contains(cell), "{cell}: {e}");
        }
    }

    /// A results folder's best.csv that contradicts itself is refused with its line and column.
    #[test]
    fn a_damaged_best_csv_is_refused() {
        use crate::campaign::reduction::reduce::BestRow;
        let row = |gamma: f64, verified: usize| BestRow {
            job_id: Some("j".into()),
            gamma,
            verified,
            runs: 1,
            ..BestRow::new("P".into(), "fp".into(), 1)
        };
        for (rows, says) in [
            (vec![row(-0.5, 1)], "line 2, column `gamma`: a row with a verified job has γ = -0.5"),
            (vec![row(0.5, 0)], "line 2, column `verified`"),
            (vec![row(0.5, 1), row(0.4, 1)], "line 3, column `plant`: P n_K = 1, strong is on line 2 too"),
        ] {
            let d = tempfile::tempdir().unwrap();
            let mut w = csv::Writer::from_path(d.path().join("best.csv")).unwrap();
            for r in rows {
                w.serialize(r).unwrap();
            }
            w.flush().unwrap();
            let e = results_entries(d.path()).unwrap_err().to_string();
            assert!(e.contains(says) && e.contains("best.csv is damaged"), "{e}");
        }
    }

    #[test]
    fn specs_need_a_label_and_a_path() {
        assert_eq!(parse_spec("ours=results/x").unwrap(), ("ours".to_string(), PathBuf::from("results/x")));
        assert!(parse_spec("results/x").is_err());
        assert!(parse_spec("=x").is_err());
        assert!(parse_spec("a b=x").is_err());
        let e = load_sources(&["a=/nonexistent/x.csv".into()]).unwrap_err().to_string();
        assert!(e.contains("/nonexistent/x.csv"), "{e}");
    }
}
