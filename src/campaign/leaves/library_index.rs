//! The plant library's own full-order values: `compleib/INDEX.csv` of the library folder
//! (`lti::plants_dir`) gives per COMPleib plant a `full_order_gamma` with the `method` that gave
//! it and a `note`; `compleib/FINGERPRINTS.csv` gives per plant its file and content fingerprint
//! (`lti::Plant::fingerprint`). Joined by name, they file each value under the fingerprint of the
//! plant it was computed for ([`LibraryIndex::get`]): a changed plant that keeps its name matches
//! nothing, a renamed copy still matches — as the paper's values are matched
//! (`super::reference::PAPER_PLANT_FINGERPRINTS`).
//!
//! Where the values come from (plants/compleib/README.md, "`INDEX.csv`", says it in full): not
//! from hinfix but from an offline computation — for n ≤ 60 bisection on γ with the two Riccati
//! equations of Glover and Doyle, checked against SLICOT's SB10AD (the norm its controller
//! achieves where that is smaller, method `sb10ad-achieved`); for a singular plant the problem
//! regularised (δ = 1e-5, or 1e-3 where that was unreliable); for n > 60 SB10AD alone, which
//! finished for CDP and EB6 only. So every regularised and every `sb10ad-achieved` value is an
//! upper bound of the full-order infimum, some of them approximate (TF2's does not settle in δ;
//! the `note` column says which plants are singular): a reference, not a lower bound. The report
//! uses a value only where γ_opt is neither computed here nor published by the paper
//! (`reduction::compare::full_order_rows`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The index of the plant library, relative to the library folder.
pub const LIBRARY_INDEX_CSV: &str = "compleib/INDEX.csv";

/// The plants' fingerprints, relative to the library folder.
pub const LIBRARY_FINGERPRINTS_CSV: &str = "compleib/FINGERPRINTS.csv";

/// One plant's row of the index.
#[derive(Debug, Clone, PartialEq)]
pub struct IndexEntry {
    /// The plant's name in the library.
    pub name: String,
    /// Its full-order γ (`None`: the index has none, method `failed`).
    pub full_order_gamma: Option<f64>,
    /// How the value was obtained (`riccati-bisection`, `regularized eps=1e-5 …`,
    /// `sb10ad-achieved …`).
    pub method: String,
    /// What is special about the plant (singular D12 or D21, scaling, why a method failed).
    pub note: String,
}

/// The index's rows by plant fingerprint; empty for a library without an index.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct LibraryIndex {
    by_fingerprint: BTreeMap<String, IndexEntry>,
}

/// The index could not be read.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LibraryIndexError {
    /// A file could not be read.
    #[error("plant library index {}: cannot read: {source}", path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        #[source]
        source: std::io::Error,
    },
    /// A line is not a CSV record of the header's length.
    #[error("plant library index {}, line {line}: {source}", path.display())]
    Csv {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: u64,
        /// The CSV reader's error.
        #[source]
        source: csv::Error,
    },
    /// The header lacks a column.
    #[error("plant library index {}, line 1: no column `{column}`", path.display())]
    Column {
        /// The file.
        path: PathBuf,
        /// The column.
        column: &'static str,
    },
    /// A field is malformed.
    #[error("plant library index {}, line {line}, field `{field}`: {problem}", path.display())]
    Field {
        /// The file.
        path: PathBuf,
        /// 1-based line.
        line: u64,
        /// The column.
        field: &'static str,
        /// What is wrong.
        problem: IndexFieldProblem,
    },
}

/// What is wrong with a field of the index.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum IndexFieldProblem {
    /// Empty where a value is needed.
    #[error("empty")]
    Empty,
    /// Not a number.
    #[error("`{0}` is not a number")]
    NotANumber(String),
    /// γ must be finite and not negative.
    #[error("γ must be a finite number ≥ 0, found {0}")]
    Gamma(f64),
    /// Not 64 lowercase hexadecimal digits.
    #[error("`{0}` is not a fingerprint (64 lowercase hex digits)")]
    Fingerprint(String),
    /// A plant (or fingerprint) with a row already.
    #[error("`{0}` is listed twice")]
    Duplicate(String),
    /// A fingerprint of a plant the index does not list.
    #[error("plant `{0}` has no row in {LIBRARY_INDEX_CSV}")]
    NotInIndex(String),
}

impl LibraryIndex {
    /// The index of the library folder `library` (the files [`LIBRARY_INDEX_CSV`] and
    /// [`LIBRARY_FINGERPRINTS_CSV`]); empty when it has no `INDEX.csv` (a library of one's own).
    /// Every row is checked: γ empty or a finite number ≥ 0, fingerprints of 64 hex digits, each
    /// name once, each fingerprinted plant in the index.
    pub fn load(library: &Path) -> Result<LibraryIndex, LibraryIndexError> {
        let index_path = library.join(LIBRARY_INDEX_CSV);
        if !index_path.is_file() {
            return Ok(LibraryIndex::default());
        }
        let mut entries = BTreeMap::new();
        for_each_row(&index_path, &["name", "full_order_gamma", "method", "note"], |f| {
            let gamma = match f[1] {
                "" => None,
                text => Some(text.parse::<f64>().map_err(|_| (1, IndexFieldProblem::NotANumber(text.into())))?),
            };
            if let Some(g) = gamma.filter(|g| !(g.is_finite() && *g >= 0.0)) {
                return Err((1, IndexFieldProblem::Gamma(g)));
            }
            let entry =
                IndexEntry { name: f[0].into(), full_order_gamma: gamma, method: f[2].into(), note: f[3].into() };
            match entries.insert(f[0].to_string(), entry) {
                Some(_) => Err((0, IndexFieldProblem::Duplicate(f[0].into()))),
                None => Ok(()),
            }
        })?;
        let prints_path = library.join(LIBRARY_FINGERPRINTS_CSV);
        let mut by_fingerprint = BTreeMap::new();
        for_each_row(&prints_path, &["name", "fingerprint"], |f| {
            if !(f[1].len() == 64 && f[1].bytes().all(|b| b.is_ascii_digit() || (b'a'..=b'f').contains(&b))) {
                return Err((1, IndexFieldProblem::Fingerprint(f[1].into())));
            }
            let Some(entry) = entries.get(f[0]) else { return Err((0, IndexFieldProblem::NotInIndex(f[0].into()))) };
            match by_fingerprint.insert(f[1].to_string(), entry.clone()) {
                Some(_) => Err((1, IndexFieldProblem::Duplicate(f[1].into()))),
                None => Ok(()),
            }
        })?;
        Ok(LibraryIndex { by_fingerprint })
    }

    /// The index of the plant library in use ([`crate::lti::plants_dir`]).
    pub fn load_default() -> Result<LibraryIndex, LibraryIndexError> {
        Self::load(&crate::lti::plants_dir())
    }

    /// The row of the plant with content fingerprint `fingerprint`, if the index lists it.
    pub fn get(&self, fingerprint: &str) -> Option<&IndexEntry> {
        self.by_fingerprint.get(fingerprint)
    }

    /// The full-order γ the index gives the plant with content fingerprint `fingerprint`.
    pub fn full_order_gamma(&self, fingerprint: &str) -> Option<f64> {
        self.get(fingerprint)?.full_order_gamma
    }

    /// How many plants the index lists by fingerprint.
    pub fn len(&self) -> usize {
        self.by_fingerprint.len()
    }

    /// Whether it lists none.
    pub fn is_empty(&self) -> bool {
        self.by_fingerprint.is_empty()
    }
}

/// Calls `row(fields)` on each record of the CSV file `path` with the fields of `columns`, in
/// that order, trimmed (the first, the row's key, must not be empty); `row`'s error
/// `(i, problem)` is about the field `columns[i]`.
fn for_each_row(
    path: &Path,
    columns: &[&'static str],
    mut row: impl FnMut(&[&str]) -> Result<(), (usize, IndexFieldProblem)>,
) -> Result<(), LibraryIndexError> {
    let file = std::fs::File::open(path).map_err(|source| LibraryIndexError::Io { path: path.into(), source })?;
    let mut reader = csv::Reader::from_reader(file);
    let csv_error = |source: csv::Error| LibraryIndexError::Csv {
        path: path.into(),
        line: source.position().map_or(1, |p| p.line()),
        source,
    };
    let header = reader.headers().map_err(csv_error)?.clone();
    let at: Vec<usize> = columns
        .iter()
        .map(|&column| {
            header.iter().position(|h| h == column).ok_or(LibraryIndexError::Column { path: path.into(), column })
        })
        .collect::<Result<_, _>>()?;
    for record in reader.records() {
        let record = record.map_err(csv_error)?;
        let line = record.position().map_or(0, |p| p.line());
        let fields: Vec<&str> = at.iter().map(|&i| record.get(i).unwrap_or("").trim()).collect();
        let field_error =
            |i: usize, problem| LibraryIndexError::Field { path: path.into(), line, field: columns[i], problem };
        if fields[0].is_empty() {
            return Err(field_error(0, IndexFieldProblem::Empty));
        }
        row(&fields).map_err(|(i, problem)| field_error(i, problem))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const INDEX: &str = "name,n,full_order_gamma,method,note\nA,2,1.5,riccati-bisection,\nB,3,,failed,timed out\n";
    const PRINTS: &str =
        "name,file,fingerprint\nA,A.json,aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa\n";

    fn library(index: &str, prints: &str) -> tempfile::TempDir {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("compleib")).unwrap();
        std::fs::write(dir.path().join(LIBRARY_INDEX_CSV), index).unwrap();
        std::fs::write(dir.path().join(LIBRARY_FINGERPRINTS_CSV), prints).unwrap();
        dir
    }

    fn error(index: &str, prints: &str) -> String {
        LibraryIndex::load(library(index, prints).path()).unwrap_err().to_string()
    }

    #[test]
    fn the_project_library_index_matches_by_fingerprint() {
        let index = LibraryIndex::load(&Path::new(env!("CARGO_MANIFEST_DIR")).join("plants")).unwrap();
        assert_eq!(index.len(), 142);
        // CDP (n = 120): the norm SB10AD's controller achieves
        let cdp = index.get("55fa33d328e7e430e06e2b20c2e45de47d9c588b3a73a947ba8fb6952c97770c").unwrap();
        assert_eq!((cdp.name.as_str(), cdp.full_order_gamma), ("CDP", Some(0.4779011414)));
        assert!(cdp.method.starts_with("sb10ad-achieved"), "{}", cdp.method);
        // a plant without a value, and a fingerprint of no library plant
        let cbm = index.by_fingerprint.values().find(|e| e.name == "CBM").unwrap();
        assert_eq!(cbm.full_order_gamma, None);
        assert_eq!(index.full_order_gamma(&"0".repeat(64)), None);
    }

    #[test]
    fn a_library_without_an_index_has_an_empty_one() {
        let dir = tempfile::tempdir().unwrap();
        assert!(LibraryIndex::load(dir.path()).unwrap().is_empty());
    }

    #[test]
    fn values_are_filed_under_fingerprints() {
        let dir = library(INDEX, PRINTS);
        let index = LibraryIndex::load(dir.path()).unwrap();
        assert_eq!(index.len(), 1);
        assert_eq!(index.full_order_gamma(&"a".repeat(64)), Some(1.5));
        assert_eq!(index.get(&"a".repeat(64)).unwrap().name, "A");
    }

    #[test]
    fn bad_input_is_an_error_naming_file_line_and_field() {
        let e = error(&INDEX.replace("1.5", "x1"), PRINTS);
        assert!(e.contains("INDEX.csv, line 2, field `full_order_gamma`") && e.contains("`x1` is not a number"), "{e}");
        let e = error(&INDEX.replace("1.5", "-1"), PRINTS);
        assert!(e.contains("line 2") && e.contains("≥ 0, found -1"), "{e}");
        let e = error(&INDEX.replace("1.5", "inf"), PRINTS);
        assert!(e.contains("found inf"), "{e}");
        let e = error(&format!("{INDEX}A,2,1.6,m,\n"), PRINTS);
        assert!(e.contains("line 4, field `name`: `A` is listed twice"), "{e}");
        let e = error(INDEX, &PRINTS.replace("aaaa", "AAAA"));
        assert!(e.contains("FINGERPRINTS.csv, line 2, field `fingerprint`"), "{e}");
        let e = error(INDEX, &PRINTS.replace("A,A.json", "C,C.json"));
        assert!(e.contains("line 2, field `name`: plant `C` has no row in compleib/INDEX.csv"), "{e}");
        let e = error(&INDEX.replace("full_order_gamma", "gamma"), PRINTS);
        assert!(e.contains("INDEX.csv, line 1: no column `full_order_gamma`"), "{e}");
        let e = error(&format!("{INDEX}C,1\n"), PRINTS);
        assert!(e.contains("INDEX.csv, line 4"), "{e}");
        let e = error(&INDEX.replace("\nA,", "\n,"), PRINTS);
        assert!(e.contains("line 2, field `name`: empty"), "{e}");
        let dir = library(INDEX, PRINTS);
        std::fs::remove_file(dir.path().join(LIBRARY_FINGERPRINTS_CSV)).unwrap();
        let e = LibraryIndex::load(dir.path()).unwrap_err().to_string();
        assert!(e.contains("FINGERPRINTS.csv: cannot read"), "{e}");
    }
}
