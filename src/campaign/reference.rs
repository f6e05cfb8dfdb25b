//! The paper's published numbers (Gumussoy, Millstone & Overton, CDC 2008, Tables I–VIII), read
//! from the project's copy of the reference CSV for the comparison tables.
//!
//! Columns: `table, plant, method, source, order, gamma, controller`, where `method` is
//! `literature` (a value the paper quotes from earlier work), `full-order` (the optimal
//! full-order γ, `hinfsyn`) or `hifoo` (the paper's own result), and `controller` is `stable` or
//! `unstable` (whether that controller is itself stable).

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
    #[error("reference table {}, line {line}: {message}", path.display())]
    Row {
        /// File.
        path: PathBuf,
        /// 1-based line in the file.
        line: u64,
        /// What is wrong.
        message: String,
    },
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
pub(crate) const REFERENCE_TEXT: &str = include_str!("../../plants/reference/gumussoy-millstone-overton-2008.csv");

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
        let row_err = |line: u64, message: String| ReferenceError::Row { path: path.to_path_buf(), line, message };
        let row = rec.map_err(|e| {
            let line = e.position().map_or(0, |p| p.line());
            row_err(line, e.to_string())
        })?;
        if !(row.gamma.is_finite() && row.gamma > 0.0) {
            return Err(row_err(
                rows.len() as u64 + 2,
                format!("gamma must be a positive number, found {}", row.gamma),
            ));
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
