//! The paper's published numbers (Gumussoy, Millstone & Overton, CDC 2008, Tables I–VIII), read
//! from the project's copy of the reference CSV for the comparison tables.
//!
//! Columns: `table, plant, method, source, order, gamma, controller`, where `method` is
//! `literature` (a value the paper quotes from earlier work), `full-order` (the optimal
//! full-order γ, `hinfsyn`) or `hifoo` (the paper's own result), and `controller` is `stable` or
//! `unstable` (whether that controller is itself stable). Rows are matched to plants by content
//! fingerprint, not by name ([`PAPER_PLANT_FINGERPRINTS`]).

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

/// The reference table's path inside the project.
pub const REFERENCE_CSV: &str = "plants/reference/gumussoy-millstone-overton-2008.csv";

/// Where a reference value comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum RefMethod {
    /// Earlier work quoted in the paper.
    Literature,
    /// The optimal full-order level (hinfsyn).
    FullOrder,
    /// The paper's HIFOO result.
    Hifoo,
}

/// One row of the reference table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ReferenceRow {
    /// Table number in the paper (Roman numeral).
    pub table: String,
    /// Plant name, as used for the files in `plants/`.
    pub plant: String,
    /// Kind of value.
    pub method: RefMethod,
    /// Citation of the value.
    pub source: String,
    /// Controller order.
    pub order: usize,
    /// Closed-loop H∞ norm reported.
    pub gamma: f64,
    /// Whether the reported controller is stable.
    #[serde(rename = "controller", with = "stable_word")]
    pub controller_stable: bool,
}

/// Content fingerprints ([`crate::lti::Plant::fingerprint`]) of the plants the paper's values
/// belong to: the shipped files `plants/<name>.json`. A reference row applies to a plant only when
/// the plant's fingerprint is the entry of the row's name ([`ReferenceRow::is_for`]): a changed
/// plant that keeps the name `HE1` is not compared with the paper's HE1, and a renamed copy of HE1
/// still is. Plants the project does not ship (the paper's other problems, `plants/MISSING.md`)
/// have no entry, so their rows match no plant: their content is unknown.
/// `tests/plant_files.rs` checks each entry against its shipped file.
pub const PAPER_PLANT_FINGERPRINTS: [(&str, &str); 8] = [
    ("AC8", "bbc66d267d01e31e99e260248159cec5f5d27db3d6f6854d533d8602ee0f8fad"),
    ("HE1", "4822dac1ddd3cc168d3a06071f6a15109a4f86177544dc0261c1f3c897035423"),
    ("REA2", "c6c6f4f68da5fc1c92ed13067e88e2425565a584b3882076844434b0dfc3ea52"),
    ("AC10", "e12e880ce104f5ea2933b97d1a98b321d773fc46057a0f73accf5fb8dfe1879d"),
    ("BDT2", "30fe9cf380550c2a76a4fb087f836388aafff567e640266c271bf23fc97a66a6"),
    ("HF1", "e81f6aaf6436b9564181dacf1f8cc3a30d5f9cd433985384bf27193e077b9fc7"),
    ("CM4", "6dc50d37ef732824264d51a8d331ef9b7ac0eb9a14f71f10b99033b1db3fb324"),
    ("Enns", "675edb773de947baea16efe8dad3ec569d0b0355068e0112318de0b0eaf39240"),
];

/// The paper's name of the plant with content fingerprint `fingerprint`, if the paper's values
/// belong to it ([`PAPER_PLANT_FINGERPRINTS`]).
pub fn paper_plant_name(fingerprint: &str) -> Option<&'static str> {
    PAPER_PLANT_FINGERPRINTS.iter().find(|(_, fp)| *fp == fingerprint).map(|(name, _)| *name)
}

impl ReferenceRow {
    /// Whether this row is a value of the plant with content fingerprint `fingerprint` (never
    /// decided by the plant's name: see [`PAPER_PLANT_FINGERPRINTS`]).
    pub fn is_for(&self, fingerprint: &str) -> bool {
        paper_plant_name(fingerprint) == Some(self.plant.as_str())
    }
}

/// The reference table could not be read.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ReferenceError {
    /// The file could not be opened.
    #[error("reference table {}: cannot read: {source}", path.display())]
    Io {
        /// File.
        path: PathBuf,
        /// Cause.
        #[source]
        source: std::io::Error,
    },
    /// A row is malformed.
    #[error("reference table {}, line {line}: {problem}", path.display())]
    Row {
        /// File.
        path: PathBuf,
        /// 1-based line in the file.
        line: u64,
        /// What is wrong.
        #[source]
        problem: RowProblem,
    },
}

/// What is wrong with a row of the reference table.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum RowProblem {
    /// Not a row of the table's columns (the CSV reader's message).
    #[error(transparent)]
    Csv(#[from] csv::Error),
    /// γ is not a positive number.
    #[error("gamma must be a positive number, found {0}")]
    Gamma(f64),
}

mod stable_word {
    use serde::{Deserialize, Deserializer, Serializer};
    pub(crate) fn serialize<S: Serializer>(b: &bool, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(if *b { "stable" } else { "unstable" })
    }
    pub(crate) fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<bool, D::Error> {
        match String::deserialize(d)?.as_str() {
            "stable" => Ok(true),
            "unstable" => Ok(false),
            other => {
                Err(serde::de::Error::custom(format!("controller must be `stable` or `unstable`, found `{other}`")))
            }
        }
    }
}

/// The paper's table, built into the program (a plant library chosen with `HINFIX_PLANTS` need
/// not, and usually does not, hold a copy).
pub(crate) const REFERENCE_TEXT: &str = include_str!("../../../plants/reference/gumussoy-millstone-overton-2008.csv");

/// Reads the reference table at `path`; every row is checked (γ finite and positive).
pub fn load_reference(path: &Path) -> Result<Vec<ReferenceRow>, ReferenceError> {
    let file = std::fs::File::open(path).map_err(|source| ReferenceError::Io { path: path.to_path_buf(), source })?;
    parse_reference(file, path)
}

/// Reads reference rows from CSV text (`path` names it in errors).
pub(crate) fn parse_reference(input: impl std::io::Read, path: &Path) -> Result<Vec<ReferenceRow>, ReferenceError> {
    let mut rows = Vec::new();
    let mut reader = csv::Reader::from_reader(input);
    for rec in reader.deserialize::<ReferenceRow>() {
        let row_err = |line: u64, problem: RowProblem| ReferenceError::Row { path: path.to_path_buf(), line, problem };
        let row = rec.map_err(|e| {
            let line = e.position().map_or(0, |p| p.line());
            row_err(line, e.into())
        })?;
        if !(row.gamma.is_finite() && row.gamma > 0.0) {
            return Err(row_err(rows.len() as u64 + 2, RowProblem::Gamma(row.gamma)));
        }
        rows.push(row);
    }
    Ok(rows)
}

/// The paper's reference table as built into the program (`REFERENCE_TEXT`); it does not
/// depend on the plant library folder or the working directory.
pub fn load_default_reference() -> Result<Vec<ReferenceRow>, ReferenceError> {
    parse_reference(REFERENCE_TEXT.as_bytes(), Path::new(REFERENCE_CSV))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn project_table_loads_with_all_three_kinds() {
        let rows = load_reference(&Path::new(env!("CARGO_MANIFEST_DIR")).join(REFERENCE_CSV)).unwrap();
        assert_eq!(rows.len(), 170);
        let he1: Vec<_> = rows.iter().filter(|r| r.plant == "HE1" && r.method == RefMethod::Hifoo).collect();
        assert_eq!(he1.len(), 4);
        assert!(he1.iter().any(|r| r.order == 1 && r.gamma == 0.1235 && r.controller_stable));
        assert!(rows.iter().any(|r| r.method == RefMethod::FullOrder && !r.controller_stable));
        assert!(rows.iter().any(|r| r.method == RefMethod::Literature));
    }

    #[test]
    fn built_in_table_equals_the_file() {
        let from_file = load_reference(&Path::new(env!("CARGO_MANIFEST_DIR")).join(REFERENCE_CSV)).unwrap();
        assert_eq!(load_default_reference().unwrap(), from_file);
    }

    #[test]
    fn bad_rows_name_the_line() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("r.csv");
        std::fs::write(
            &p,
            "table,plant,method,source,order,gamma,controller\nI,X,hifoo,s,1,0.5,stable\nI,X,guess,s,1,0.5,stable\n",
        )
        .unwrap();
        let e = load_reference(&p).unwrap_err().to_string();
        assert!(e.contains("line 3") && e.contains("guess"), "{e}");
        std::fs::write(&p, "table,plant,method,source,order,gamma,controller\nI,X,hifoo,s,1,-2,stable\n").unwrap();
        assert!(load_reference(&p).unwrap_err().to_string().contains("positive"));
    }
}
