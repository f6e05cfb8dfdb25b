//! The generalised plant and its JSON file format.
//!
//! ```text
//! x' = A x + B1 w + B2 u
//! z  = C1 x + D11 w + D12 u
//! y  = C2 x + D21 w + D22 u
//! ```
//! with n = dim x, m1 = dim w, m2 = dim u, p1 = dim z, p2 = dim y (docs/ALGORITHMS.md §1).
//!
//! A plant file is a JSON object with `name`, optional `description`, `source` (a citation string
//! or an object with at least `citation`), `dims` {n, m1, m2, p1, p2}, and the nine matrices
//! `A, B1, B2, C1, C2, D11, D12, D21, D22` as arrays of rows; optional `notes` and `check` are
//! kept as provenance, and an optional `order` must equal `dims.n`. An optional `Ts` is the
//! sampling time in seconds of a discrete-time plant (absent or 0: continuous time; else from
//! 1e-50 to 1e50, [`TimeDomain`]). No entry may exceed 1e50
//! in absolute value, and a non-zero matrix needs an entry of 1e-50 or more
//! (`matrix_json::check_magnitudes`). Any other top-level
//! key is an error naming it ([`PlantErrorKind::UnknownKey`]): a misspelt `D12` or a key this version does
//! not know must not be silently ignored; so is a key given twice (`input::parse_json_unique_keys`). [`Plant::from_json_str`] validates everything and names
//! the file, the field and the row/column of the first thing wrong.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use faer::{Mat, MatRef};
use serde::Serialize;
use serde_json::{Map, Value};
use sha2::{Digest, Sha256};

use crate::lti::io::mat_file::{
    json_number, read_char_var, read_mat_vars_with_text, scalar_var_to_json, var_to_json, write_mat, MatReadError,
    MatVar,
};
use crate::lti::io::matrix_json::{check_magnitudes, json_shape, matrix_from_json, MatrixJsonError};

use super::time_domain::TimeDomain;

/// Sizes of a generalised plant.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, serde::Deserialize)]
pub struct Dims {
    /// States.
    pub n: usize,
    /// Disturbance inputs w.
    pub m1: usize,
    /// Control inputs u.
    pub m2: usize,
    /// Performance outputs z.
    pub p1: usize,
    /// Measured outputs y.
    pub p2: usize,
}

/// A validated generalised plant.
#[derive(Debug, Clone)]
pub struct Plant {
    /// Name (as in the reference tables, e.g. `HE1`).
    pub name: String,
    /// One-line description.
    pub description: String,
    /// Citation of the data's source.
    pub citation: String,
    /// The file's whole `source` value (repository, path, commit, …), kept as provenance.
    pub source: Value,
    /// Free-text notes on conventions.
    pub notes: String,
    /// The file's `check` block (full-order γ computed from the data vs the paper's), if any.
    pub check: Option<Value>,
    /// Sizes.
    pub dims: Dims,
    /// Continuous or discrete time (the file's `Ts`).
    pub domain: TimeDomain,
    /// State matrix (n × n).
    pub a: Mat<f64>,
    /// Disturbance input matrix (n × m1).
    pub b1: Mat<f64>,
    /// Control input matrix (n × m2).
    pub b2: Mat<f64>,
    /// Performance output matrix (p1 × n).
    pub c1: Mat<f64>,
    /// Measurement matrix (p2 × n).
    pub c2: Mat<f64>,
    /// w → z feedthrough (p1 × m1).
    pub d11: Mat<f64>,
    /// u → z feedthrough (p1 × m2).
    pub d12: Mat<f64>,
    /// w → y feedthrough (p2 × m1).
    pub d21: Mat<f64>,
    /// u → y feedthrough (p2 × m2).
    pub d22: Mat<f64>,
}

/// A plant file that could not be read, with the file it came from.
#[derive(Debug, thiserror::Error)]
#[error("plant file {}: {kind}", file.display())]
pub struct PlantError {
    /// The file (or a label such as `<inline>`).
    pub file: PathBuf,
    /// What is wrong (part of the message, so not also a `source`: a chain printer would repeat
    /// it).
    pub kind: PlantErrorKind,
}

/// What is wrong with a plant file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PlantErrorKind {
    /// The file could not be read.
    #[error("cannot read: {0}")]
    Io(std::io::Error),
    /// Not valid JSON.
    #[error("invalid JSON at line {line}, column {column}: {message}")]
    Json {
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// The parser's message.
        message: String,
    },
    /// A `.mat` file that is not a readable level-5 MAT-file of real matrices.
    #[error("{0}")]
    Mat(#[from] MatReadError),
    /// The document is not a JSON object.
    #[error("the top level must be a JSON object")]
    NotObject,
    /// A required field is absent.
    #[error("field `{field}` is missing")]
    MissingField {
        /// Field name.
        field: &'static str,
    },
    /// A top-level key the plant format does not have.
    #[error("unknown key `{key}` (a plant file holds {})", PLANT_KEYS.join(", "))]
    UnknownKey {
        /// The key as written in the file.
        key: String,
    },
    /// A field has the wrong type or an impossible value.
    #[error("field `{field}`: {problem}")]
    BadField {
        /// Field name (e.g. `dims.n`).
        field: String,
        /// What is wrong.
        problem: String,
    },
    /// No plant of that name in the plant library.
    #[error("no plant named `{name}` in the library ({hint}known: {known}); give a path to use another file")]
    UnknownName {
        /// The name asked for.
        name: String,
        /// `did you mean `HE1`? ` when a library name differs only in case, else empty.
        hint: String,
        /// The library's plant names, comma-separated.
        known: String,
    },
    /// Several library collections hold a plant of that name.
    #[error("the plant name `{name}` is in more than one library folder ({files}); give the path of the one you mean")]
    AmbiguousName {
        /// The name asked for.
        name: String,
        /// The files that have it, comma-separated.
        files: String,
    },
    /// A gzip-compressed plant file (`.json.gz`) that does not decompress.
    #[error("not a readable gzip file: {0}")]
    Gzip(String),
    /// A matrix is missing, mis-shaped or holds a bad entry.
    #[error("matrix `{matrix}` {problem}{hint}")]
    Matrix {
        /// Matrix name (`A`, `B1`, …).
        matrix: &'static str,
        /// What is wrong.
        problem: MatrixJsonError,
        /// Extra context (e.g. which dims the expected shape comes from).
        hint: String,
    },
}

/// The nine matrices with the dims their shapes come from.
pub(crate) const MATRICES: [(&str, &str, &str); 9] = [
    ("A", "n", "n"),
    ("B1", "n", "m1"),
    ("B2", "n", "m2"),
    ("C1", "p1", "n"),
    ("C2", "p2", "n"),
    ("D11", "p1", "m1"),
    ("D12", "p1", "m2"),
    ("D21", "p2", "m1"),
    ("D22", "p2", "m2"),
];

/// Every top-level key of a plant file: the provenance fields, `dims`, `order`, the sampling time
/// `Ts` and the nine matrices.
pub(crate) const PLANT_KEYS: [&str; 17] = [
    "name",
    "description",
    "source",
    "notes",
    "check",
    "order",
    "dims",
    "Ts",
    "A",
    "B1",
    "B2",
    "C1",
    "C2",
    "D11",
    "D12",
    "D21",
    "D22",
];

impl Dims {
    fn get(&self, name: &str) -> usize {
        match name {
            "n" => self.n,
            "m1" => self.m1,
            "m2" => self.m2,
            "p1" => self.p1,
            "p2" => self.p2,
            _ => unreachable!("dimension names are fixed in MATRICES"),
        }
    }
}

impl Plant {
    /// Reads and validates a plant file: JSON, or a MATLAB `.mat` file (`lti::mat_file`) that
    /// goes through the same checks.
    pub fn load(path: impl AsRef<Path>) -> Result<Plant, PlantError> {
        let path = path.as_ref();
        if crate::lti::io::mat_file::is_mat_path(path) {
            let err = |kind| PlantError { file: path.to_path_buf(), kind };
            let bytes = crate::input::read_capped(path, crate::input::MAX_PLANT_BYTES, "plant file")
                .map_err(|e| err(PlantErrorKind::Io(e)))?;
            return Self::from_mat_bytes(&bytes, path);
        }
        let err = |kind| PlantError { file: path.to_path_buf(), kind };
        if is_gzip_json_path(path) {
            let text = read_gzip_text(path).map_err(err)?;
            return Self::from_json_str(&text, path);
        }
        let text = crate::input::read_capped_string(path, crate::input::MAX_PLANT_BYTES, "plant file")
            .map_err(|e| err(PlantErrorKind::Io(e)))?;
        Self::from_json_str(&text, path)
    }

    /// Reads and validates a plant from the bytes of a MAT-file; `file` names it in errors, and
    /// its stem names the plant when the file has no `name` variable.
    pub fn from_mat_bytes(bytes: &[u8], file: impl AsRef<Path>) -> Result<Plant, PlantError> {
        let file = file.as_ref();
        plant_from_mat(bytes, file).map_err(|kind| PlantError { file: file.to_path_buf(), kind })
    }

    /// Parses and validates a plant from JSON text; `file` names it in errors.
    ///
    /// As in a MAT-file, `name` and `dims` may be left out: the file's stem names the plant and
    /// the dimensions are inferred from the blocks (an empty `[]` block is then a zero block).
    pub fn from_json_str(text: &str, file: impl AsRef<Path>) -> Result<Plant, PlantError> {
        let err = |kind| PlantError { file: file.as_ref().to_path_buf(), kind };
        let mut doc: Value = crate::input::parse_json_unique_keys(text)
            .map_err(|e| err(PlantErrorKind::Json { line: e.line(), column: e.column(), message: e.to_string() }))?;
        if let Value::Object(o) = &mut doc {
            let stem = file.as_ref().file_stem().map_or_else(|| "plant".into(), |s| s.to_string_lossy().into_owned());
            let stem = stem.strip_suffix(".json").map(str::to_string).unwrap_or(stem);
            complete_document(o, &stem);
        }
        Self::from_json_value(&doc).map_err(err)
    }

    pub(crate) fn from_json_value(doc: &Value) -> Result<Plant, PlantErrorKind> {
        let obj = doc.as_object().ok_or(PlantErrorKind::NotObject)?;
        if let Some(key) = obj.keys().find(|k| !PLANT_KEYS.contains(&k.as_str())) {
            return Err(PlantErrorKind::UnknownKey { key: key.clone() });
        }
        let name = match obj.get("name") {
            None => return Err(PlantErrorKind::MissingField { field: "name" }),
            Some(Value::String(s)) if !s.trim().is_empty() => s.clone(),
            Some(_) => return Err(bad("name", "must be a non-empty string")),
        };
        let description = optional_string(obj.get("description"), "description")?;
        let notes = optional_string(obj.get("notes"), "notes")?;
        let source = obj.get("source").cloned().unwrap_or(Value::Null);
        let citation = match &source {
            Value::Null => String::new(),
            Value::String(s) => s.clone(),
            Value::Object(o) => optional_string(o.get("citation"), "source.citation")?,
            _ => return Err(bad("source", "must be a citation string or an object")),
        };
        let dims = read_dims(obj.get("dims"))?;
        if let Some(order) = obj.get("order") {
            if order.as_u64() != Some(dims.n as u64) {
                return Err(bad("order", &format!("is {order}, but dims.n is {}", dims.n)));
            }
        }
        let domain = TimeDomain::from_json(obj.get("Ts")).map_err(|problem| bad("Ts", &problem))?;
        let mut mats: Vec<Mat<f64>> = Vec::with_capacity(9);
        for (key, r, c) in MATRICES {
            let (rows, cols) = (dims.get(r), dims.get(c));
            let m = matrix_from_json(obj.get(key), rows, cols).map_err(|problem| {
                let got = obj.get(key).and_then(json_shape);
                let hint = match (&problem, got) {
                    (MatrixJsonError::RowCount { .. } | MatrixJsonError::RowLength { .. }, Some((gr, gc))) => {
                        format!(" (expected {rows}×{cols} = {r}×{c} from dims, file holds {gr}×{gc})")
                    }
                    _ => String::new(),
                };
                PlantErrorKind::Matrix { matrix: key, problem, hint }
            })?;
            check_magnitudes(m.as_ref()).map_err(|problem| PlantErrorKind::Matrix {
                matrix: key,
                problem,
                hint: String::new(),
            })?;
            mats.push(m);
        }
        let mut it = mats.into_iter();
        let mut next = || it.next().expect("nine matrices were read");
        Ok(Plant {
            name,
            description,
            citation,
            source,
            notes,
            check: obj.get("check").cloned(),
            dims,
            domain,
            a: next(),
            b1: next(),
            b2: next(),
            c1: next(),
            c2: next(),
            d11: next(),
            d12: next(),
            d21: next(),
            d22: next(),
        })
    }

    /// A plant from its nine matrices in file order (A, B1, B2, C1, C2, D11, D12, D21, D22), e.g.
    /// handed over by another program: `dims` are read off A (n), B1 (m1), B2 (m2), C1 (p1) and
    /// C2 (p2), and the plant goes through the checks of a plant file (shapes, magnitudes, n, m2,
    /// p2 ≥ 1), with the same messages; a non-finite entry is named by matrix, row and column.
    /// Values are kept bit for bit (same matrices, same fingerprint as the plant's JSON file).
    pub fn from_matrices(name: &str, mats: [MatRef<'_, f64>; 9]) -> Result<Plant, PlantErrorKind> {
        use crate::lti::io::matrix_json::matrix_to_json;
        let mut doc = Map::new();
        for ((key, _, _), m) in MATRICES.iter().zip(mats) {
            for j in 0..m.ncols() {
                if let Some(i) = (0..m.nrows()).find(|&i| !m[(i, j)].is_finite()) {
                    let problem = MatrixJsonError::NotFinite { row: i + 1, col: j + 1, value: m[(i, j)] };
                    return Err(PlantErrorKind::Matrix { matrix: key, problem, hint: String::new() });
                }
            }
            doc.insert((*key).into(), matrix_to_json(m));
        }
        let [a, b1, b2, c1, c2, ..] = mats;
        let dims = Dims { n: a.nrows(), m1: b1.ncols(), m2: b2.ncols(), p1: c1.nrows(), p2: c2.nrows() };
        doc.insert("name".into(), name.into());
        doc.insert("dims".into(), serde_json::to_value(dims).expect("dims serialise"));
        Self::from_json_value(&Value::Object(doc))
    }

    /// The plant as a JSON document in the file format (provenance kept).
    pub fn to_json(&self) -> Value {
        use crate::lti::io::matrix_json::matrix_to_json;
        let mut o = serde_json::Map::new();
        o.insert("name".into(), self.name.clone().into());
        o.insert("description".into(), self.description.clone().into());
        o.insert("source".into(), self.source.clone());
        o.insert("notes".into(), self.notes.clone().into());
        o.insert("dims".into(), serde_json::to_value(self.dims).expect("dims serialise"));
        if let Some(ts) = self.domain.ts() {
            o.insert("Ts".into(), ts.into());
        }
        for ((key, _, _), m) in MATRICES.iter().zip(self.matrices()) {
            o.insert((*key).into(), matrix_to_json(m));
        }
        if let Some(c) = &self.check {
            o.insert("check".into(), c.clone());
        }
        Value::Object(o)
    }

    /// The nine matrices in file order (A, B1, B2, C1, C2, D11, D12, D21, D22).
    pub fn matrices(&self) -> [MatRef<'_, f64>; 9] {
        [
            self.a.as_ref(),
            self.b1.as_ref(),
            self.b2.as_ref(),
            self.c1.as_ref(),
            self.c2.as_ref(),
            self.d11.as_ref(),
            self.d12.as_ref(),
            self.d21.as_ref(),
            self.d22.as_ref(),
        ]
    }

    /// Whether D22 is exactly zero (the closed loop then takes its simpler linear form).
    pub fn d22_is_zero(&self) -> bool {
        let d = self.d22.as_ref();
        (0..d.nrows()).all(|i| (0..d.ncols()).all(|j| d[(i, j)] == 0.0))
    }

    /// A content fingerprint (SHA-256, hex) of the dims, the matrices' exact bits and, for a
    /// discrete-time plant, its sampling time: the plant's identity in job ids, independent of
    /// formatting and provenance text. (A continuous-time plant's fingerprint does not mention
    /// the domain, so it is the one fingerprints had before sampling times existed.)
    pub fn fingerprint(&self) -> String {
        let mut h = Sha256::new();
        for d in [self.dims.n, self.dims.m1, self.dims.m2, self.dims.p1, self.dims.p2] {
            h.update((d as u64).to_le_bytes());
        }
        for m in self.matrices() {
            for j in 0..m.ncols() {
                for i in 0..m.nrows() {
                    h.update(m[(i, j)].to_bits().to_le_bytes());
                }
            }
        }
        if let Some(ts) = self.domain.ts() {
            h.update(b"Ts");
            h.update(ts.to_bits().to_le_bytes());
        }
        h.finalize().iter().map(|b| format!("{b:02x}")).collect()
    }
}

/// Whether `path` names a gzip-compressed plant file (`*.json.gz`).
pub fn is_gzip_json_path(path: &Path) -> bool {
    path.to_str().is_some_and(|s| s.to_ascii_lowercase().ends_with(".json.gz"))
}

/// The text of a gzip-compressed plant file: at most `MAX_PLANT_BYTES` read, and at most as many
/// after decompression (a small file that inflates without end is refused, not read until memory
/// runs out); a leading UTF-8 byte-order mark is dropped as for a plain file.
fn read_gzip_text(path: &Path) -> Result<String, PlantErrorKind> {
    use std::io::Read;
    let limit = crate::input::MAX_PLANT_BYTES;
    let bytes = crate::input::read_capped(path, limit, "plant file").map_err(PlantErrorKind::Io)?;
    let decoder = libflate::gzip::Decoder::new(bytes.as_slice()).map_err(|e| PlantErrorKind::Gzip(e.to_string()))?;
    let mut text = Vec::new();
    decoder.take(limit + 1).read_to_end(&mut text).map_err(|e| PlantErrorKind::Gzip(e.to_string()))?;
    if text.len() as u64 > limit {
        return Err(PlantErrorKind::Gzip(format!(
            "it holds more than {} MiB of JSON, the limit for a plant file",
            limit >> 20
        )));
    }
    let text = text.strip_prefix(b"\xef\xbb\xbf").map(<[u8]>::to_vec).unwrap_or(text);
    String::from_utf8(text)
        .map_err(|e| PlantErrorKind::Gzip(format!("its content is not UTF-8 text ({})", e.utf8_error())))
}

fn bad(field: &str, problem: &str) -> PlantErrorKind {
    PlantErrorKind::BadField { field: field.to_string(), problem: problem.to_string() }
}

fn optional_string(v: Option<&Value>, field: &str) -> Result<String, PlantErrorKind> {
    match v {
        None | Some(Value::Null) => Ok(String::new()),
        Some(Value::String(s)) => Ok(s.clone()),
        Some(_) => Err(bad(field, "must be a string")),
    }
}

fn read_dims(v: Option<&Value>) -> Result<Dims, PlantErrorKind> {
    let obj = match v {
        None => return Err(PlantErrorKind::MissingField { field: "dims" }),
        Some(Value::Object(o)) => o,
        Some(_) => return Err(bad("dims", "must be an object {n, m1, m2, p1, p2}")),
    };
    if let Some(k) = obj.keys().find(|k| !["n", "m1", "m2", "p1", "p2"].contains(&k.as_str())) {
        return Err(bad(&format!("dims.{k}"), "unknown key (expected n, m1, m2, p1, p2)"));
    }
    let get = |k: &str, min: u64| -> Result<usize, PlantErrorKind> {
        let field = format!("dims.{k}");
        match obj.get(k) {
            None => Err(bad(&field, "is missing")),
            Some(x) => match x.as_u64() {
                Some(u) if u >= min => Ok(u as usize),
                _ => Err(bad(&field, &format!("must be an integer ≥ {min}, found {x}"))),
            },
        }
    };
    Ok(Dims { n: get("n", 1)?, m1: get("m1", 0)?, m2: get("m2", 1)?, p1: get("p1", 0)?, p2: get("p2", 1)? })
}
// ---------------------------------------------------------------------------------------------
// The MAT-file form (`lti::mat_file` reads and writes the variables).
//
// A plant file is turned into the same JSON document a plant JSON file holds and validated by the
// same code, so the checks and the error messages are the same; `dims` is inferred from the
// blocks' sizes: n = rows of A, m1 = columns of B1 (else of D11 or D21), m2 = columns of B2 (else
// D12, D22), p1 = rows of C1 (else D11, D12), p2 = rows of C2 (else D21, D22). A variable with no
// entries (`[]`, or a 0-wide block) stands for a zero block of the size the others imply. The
// plant's name is the file's stem, or the character variable `name` when the file has one. Values
// are copied bit for bit: the same plant as `.mat` and as JSON is the same plant (same
// fingerprint, same job ids, same designs).

const PLANT_HINT: &str =
    " (a plant .mat file holds A B1 B2 C1 C2 D11 D12 D21 D22 as real full numeric arrays; character, cell, struct and sparse variables are not read)";

/// Infers one dimension from the first block with entries that carries it (`shape` gives a
/// block's rows and columns, `None` when absent).
fn infer(shape: &impl Fn(&str) -> Option<(usize, usize)>, dim: &str) -> usize {
    for (key, r, c) in MATRICES {
        let Some((rows, cols)) = shape(key).filter(|(r, c)| r * c > 0) else { continue };
        if r == dim {
            return rows;
        }
        if c == dim {
            return cols;
        }
    }
    0
}

/// Completes a plant document the way a MAT-file needs and a JSON file may ask for: without
/// `name`, the file's `stem` names the plant; without `dims`, they are inferred from the blocks'
/// sizes (n = rows of A, m1 = columns of B1, else of D11 or D21, and so on) and every block with
/// no entries (`[]`) becomes a zero block of the size the others imply. A document with `dims`
/// keeps its blocks as they are (and is checked against them).
fn complete_document(doc: &mut Map<String, Value>, stem: &str) {
    if !doc.contains_key("name") {
        doc.insert("name".into(), stem.into());
    }
    if doc.contains_key("dims") {
        return;
    }
    let shape = |key: &str| doc.get(key).and_then(json_shape);
    let dims: BTreeMap<&str, usize> =
        ["n", "m1", "m2", "p1", "p2"].into_iter().map(|d| (d, infer(&shape, d))).collect();
    let empty: Vec<_> =
        MATRICES.into_iter().filter(|(key, _, _)| shape(key).is_some_and(|(rows, cols)| rows * cols == 0)).collect();
    for (key, r, c) in empty {
        let (rows, cols) = (dims[r], dims[c]);
        let zero = Value::Array((0..rows).map(|_| Value::Array(vec![json_number(0.0); cols])).collect());
        doc.insert(key.into(), zero);
    }
    doc.insert("dims".into(), serde_json::to_value(&dims).expect("dims serialise"));
}

fn first_non_finite(name: &'static str, v: &MatVar) -> Result<(), PlantErrorKind> {
    let bad = |i: usize| {
        let (row, col) = (i % v.rows + 1, i / v.rows + 1);
        PlantErrorKind::Matrix {
            matrix: name,
            problem: MatrixJsonError::NotFinite { row, col, value: v.data[i] },
            hint: String::new(),
        }
    };
    match v.data.iter().position(|x| !x.is_finite()) {
        Some(i) => Err(bad(i)),
        None => Ok(()),
    }
}

/// The JSON plant document a plant MAT-file stands for (validated by the caller with the JSON
/// plant checks). `stem` names the plant when the file has no `name` variable.
fn plant_document(bytes: &[u8], stem: &str) -> Result<Value, PlantErrorKind> {
    let vars = read_mat_vars_with_text(bytes, &["name"])?;
    for (key, _, _) in MATRICES {
        match vars.get(key) {
            None => {
                return Err(PlantErrorKind::Matrix {
                    matrix: key,
                    problem: MatrixJsonError::Missing,
                    hint: PLANT_HINT.into(),
                })
            }
            Some(v) => first_non_finite(key, v)?,
        }
    }
    let name = read_char_var(bytes, "name").filter(|s| !s.trim().is_empty()).unwrap_or_else(|| stem.to_string());
    let mut doc = Map::new();
    doc.insert("name".into(), name.into());
    doc.insert("description".into(), format!("read from the MATLAB file {stem}.mat").into());
    for (key, _, _) in MATRICES {
        let v = &vars[key];
        // an empty variable is a zero block of the inferred size (`complete_document`)
        let value = if v.is_empty() { Value::Array(Vec::new()) } else { var_to_json(v) };
        doc.insert(key.into(), value);
    }
    if let Some(ts) = vars.get("Ts") {
        doc.insert("Ts".into(), scalar_var_to_json(ts));
    }
    complete_document(&mut doc, stem);
    Ok(Value::Object(doc))
}

/// Reads a plant from the bytes of a MAT-file (see the module docs).
fn plant_from_mat(bytes: &[u8], path: &Path) -> Result<Plant, PlantErrorKind> {
    let stem = path.file_stem().map_or_else(|| "plant".to_string(), |s| s.to_string_lossy().into_owned());
    Plant::from_json_value(&plant_document(bytes, &stem)?)
}

/// The plant as a MAT-file (the nine matrices, and `Ts` for a discrete-time plant; `name` is not
/// written, the file stem names it).
pub fn plant_to_mat(p: &Plant) -> Vec<u8> {
    let names = MATRICES.map(|(k, _, _)| k);
    let mut vars: Vec<(&str, MatRef<'_, f64>)> = names.into_iter().zip(p.matrices()).collect();
    let ts = p.domain.ts().map(|ts| Mat::from_fn(1, 1, |_, _| ts));
    if let Some(ts) = &ts {
        vars.push(("Ts", ts.as_ref()));
    }
    write_mat(&vars, &format!("hinfix plant {}", p.name))
}
