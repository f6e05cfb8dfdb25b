//! A dynamic output-feedback controller and its JSON file format.
//!
//! ```text
//! xk' = Ak xk + Bk y,   u = Ck xk + Dk y        (positive feedback u = K y)
//! ```
//! with Ak nk×nk, Bk nk×p, Ck m×nk, Dk m×p (docs/ALGORITHMS.md §1). The file is a JSON object with
//! keys `AK, BK, CK, DK` as arrays of rows; for order 0, `AK, BK, CK` are empty (`[]`). An
//! optional `Ts` is the sampling time of a discrete-time controller (xk⁺ = Ak xk + Bk y; absent
//! or 0: continuous time, [`TimeDomain`]); it must be the plant's. Any other key is an error
//! naming it ([`ControllerErrorKind::UnknownKey`]).

use std::path::{Path, PathBuf};

use faer::Mat;
use serde_json::{Map, Value};

use crate::lti::io::mat_file::{is_mat_path, read_mat_vars, scalar_var_to_json, var_to_json, write_mat, MatReadError};
use crate::lti::io::matrix_json::{json_shape, json_type, matrix_from_json, matrix_to_json, MatrixJsonError};

use super::time_domain::TimeDomain;

/// Controller matrices (Ak, Bk, Ck, Dk) and the controller's time domain.
#[derive(Debug, Clone, PartialEq)]
pub struct Controller {
    /// nk × nk.
    pub ak: Mat<f64>,
    /// nk × p.
    pub bk: Mat<f64>,
    /// m × nk.
    pub ck: Mat<f64>,
    /// m × p.
    pub dk: Mat<f64>,
    /// Continuous or discrete time (the file's `Ts`); a closed loop needs the plant's.
    pub domain: TimeDomain,
}

/// As [`Controller::to_json`]: the `{AK, BK, CK, DK}` object of a controller file.
impl serde::Serialize for Controller {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        serde::Serialize::serialize(&self.to_json(), s)
    }
}

/// As [`Controller::from_json_value`] (shapes checked; the error says which matrix is wrong).
impl<'de> serde::Deserialize<'de> for Controller {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        let doc = <Value as serde::Deserialize>::deserialize(d)?;
        Controller::from_json_value(&doc).map_err(serde::de::Error::custom)
    }
}

/// A controller file that could not be read.
#[derive(Debug, thiserror::Error)]
#[error("controller file {}: {kind}", file.display())]
pub struct ControllerError {
    /// The file (or a label).
    pub file: PathBuf,
    /// What is wrong (part of the message, so not also a `source`).
    pub kind: ControllerErrorKind,
}

/// What is wrong with a controller file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ControllerErrorKind {
    /// Could not be read.
    #[error("cannot read: {0}")]
    Io(std::io::Error),
    /// Not valid JSON.
    #[error("invalid JSON at line {line}, column {column}: {message}")]
    Json {
        /// 1-based line.
        line: usize,
        /// 1-based column.
        column: usize,
        /// Parser message.
        message: String,
    },
    /// A `.mat` file that is not a readable level-5 MAT-file of real matrices.
    #[error("{0}")]
    Mat(#[from] MatReadError),
    /// Not an object with AK, BK, CK, DK.
    #[error("the top level must be a JSON object with keys AK, BK, CK, DK")]
    NotObject,
    /// A key other than AK, BK, CK, DK, Ts.
    #[error("unknown key `{key}` (a controller file holds AK, BK, CK, DK and optionally Ts)")]
    UnknownKey {
        /// The key as written in the file.
        key: String,
    },
    /// The sampling time `Ts` is not a number ≥ 0.
    #[error("field `Ts`: {problem}")]
    BadSamplingTime {
        /// What is wrong.
        problem: String,
    },
    /// A matrix is wrong.
    #[error("matrix `{matrix}` {problem}")]
    Matrix {
        /// AK, BK, CK or DK.
        matrix: &'static str,
        /// What is wrong.
        problem: MatrixJsonError,
    },
    /// The controller does not fit the plant.
    #[error("does not fit plant {plant}: {problem}")]
    Mismatch {
        /// Plant name.
        plant: String,
        /// What does not fit.
        problem: String,
    },
}

impl Controller {
    /// The zero controller of order `nk` for a plant with `m` control inputs u and `p`
    /// measurements y: Dk is m × p, so the controller has [`Self::outputs`] = m and
    /// [`Self::inputs`] = p. Continuous time ([`Self::in_domain`] for another).
    pub fn zeros(nk: usize, m: usize, p: usize) -> Self {
        Controller::continuous(Mat::zeros(nk, nk), Mat::zeros(nk, p), Mat::zeros(m, nk), Mat::zeros(m, p))
    }

    /// The continuous-time controller (Ak, Bk, Ck, Dk) (shapes not checked: [`Self::check_fits`]).
    pub fn continuous(ak: Mat<f64>, bk: Mat<f64>, ck: Mat<f64>, dk: Mat<f64>) -> Self {
        Controller { ak, bk, ck, dk, domain: TimeDomain::Continuous }
    }

    /// The same matrices in the time domain `domain`.
    pub fn in_domain(mut self, domain: TimeDomain) -> Self {
        self.domain = domain;
        self
    }

    /// Order nk (number of controller states).
    pub fn order(&self) -> usize {
        self.ak.nrows()
    }

    /// Whether every entry of Ak, Bk, Ck, Dk is finite.
    pub fn is_finite(&self) -> bool {
        [&self.ak, &self.bk, &self.ck, &self.dk].iter().all(|m| crate::numeric::all_finite(m.as_ref()))
    }

    /// Number of the controller's inputs: the plant's measurements y, p of them (columns of Dk).
    ///
    /// Named from the controller's own point of view, like [`super::state_space::StateSpace::inputs`]: the
    /// controller's inputs are the plant's outputs y and vice versa (u = K y).
    pub fn inputs(&self) -> usize {
        self.dk.ncols()
    }

    /// Number of the controller's outputs: the plant's control inputs u, m of them (rows of Dk).
    /// See [`Self::inputs`].
    pub fn outputs(&self) -> usize {
        self.dk.nrows()
    }

    /// Reads a controller file: JSON, or a MATLAB `.mat` file with `AK BK CK DK`.
    pub fn load(path: impl AsRef<Path>) -> Result<Controller, ControllerError> {
        let path = path.as_ref();
        if is_mat_path(path) {
            let err = |kind| ControllerError { file: path.to_path_buf(), kind };
            let bytes = crate::input::read_capped(path, crate::input::MAX_CONTROLLER_BYTES, "controller file")
                .map_err(|e| err(ControllerErrorKind::Io(e)))?;
            return controller_from_mat(&bytes).map_err(err);
        }
        let text = crate::input::read_capped_string(path, crate::input::MAX_CONTROLLER_BYTES, "controller file")
            .map_err(|e| ControllerError { file: path.to_path_buf(), kind: ControllerErrorKind::Io(e) })?;
        Self::from_json_str(&text, path)
    }

    /// Parses a controller from JSON text; `file` names it in errors. Shapes are taken from DK
    /// (m × p) and AK (nk × nk) and every block is checked against them.
    pub fn from_json_str(text: &str, file: impl AsRef<Path>) -> Result<Controller, ControllerError> {
        let err = |kind| ControllerError { file: file.as_ref().to_path_buf(), kind };
        let doc: Value = crate::input::parse_json_unique_keys(text).map_err(|e| {
            err(ControllerErrorKind::Json { line: e.line(), column: e.column(), message: e.to_string() })
        })?;
        Self::from_json_value(&doc).map_err(err)
    }

    /// Reads a controller from a parsed JSON value (`{AK, BK, CK, DK}`, optionally `Ts`).
    pub fn from_json_value(doc: &Value) -> Result<Controller, ControllerErrorKind> {
        let obj = doc.as_object().ok_or(ControllerErrorKind::NotObject)?;
        if let Some(key) = obj.keys().find(|k| !["AK", "BK", "CK", "DK", "Ts"].contains(&k.as_str())) {
            return Err(ControllerErrorKind::UnknownKey { key: key.clone() });
        }
        let mat = |key: &'static str, r: usize, c: usize| {
            matrix_from_json(obj.get(key), r, c).map_err(|problem| ControllerErrorKind::Matrix { matrix: key, problem })
        };
        let shape = |key: &'static str| -> Result<(usize, usize), ControllerErrorKind> {
            let v =
                obj.get(key).ok_or(ControllerErrorKind::Matrix { matrix: key, problem: MatrixJsonError::Missing })?;
            let problem = match v.as_array() {
                None => Some(MatrixJsonError::NotArray { found: json_type(v) }),
                Some(rows) => rows
                    .iter()
                    .position(|r| !r.is_array())
                    .map(|i| MatrixJsonError::RowNotArray { row: i + 1, found: json_type(&rows[i]) }),
            };
            match problem {
                Some(problem) => Err(ControllerErrorKind::Matrix { matrix: key, problem }),
                None => Ok(json_shape(v).expect("checked to be an array of rows")),
            }
        };
        let (m, p) = shape("DK")?;
        let nk = shape("AK")?.0;
        if m == 0 || p == 0 {
            return Err(ControllerErrorKind::Matrix {
                matrix: "DK",
                problem: MatrixJsonError::Empty { rows: m, cols: p },
            });
        }
        let domain =
            TimeDomain::from_json(obj.get("Ts")).map_err(|problem| ControllerErrorKind::BadSamplingTime { problem })?;
        Ok(Controller {
            ak: mat("AK", nk, nk)?,
            bk: mat("BK", nk, p)?,
            ck: mat("CK", m, nk)?,
            dk: mat("DK", m, p)?,
            domain,
        })
    }

    /// Writes the controller to `path`: a MATLAB `.mat` file (`AK BK CK DK`) when the extension is
    /// `.mat`, else pretty JSON, atomically (`fs_atomic::write_atomic`: a uniquely named tmp file
    /// renamed into place), so no reader sees half a file.
    pub fn save(&self, path: impl AsRef<Path>) -> std::io::Result<()> {
        let path = path.as_ref();
        let bytes = if is_mat_path(path) {
            controller_to_mat(self)
        } else {
            (serde_json::to_string_pretty(&self.to_json()).map_err(std::io::Error::other)? + "\n").into_bytes()
        };
        crate::fs_atomic::write_atomic(path, &bytes)
    }

    /// The controller as `{AK, BK, CK, DK}`, with `Ts` in discrete time.
    pub fn to_json(&self) -> Value {
        let mut doc = serde_json::json!({
            "AK": matrix_to_json(self.ak.as_ref()),
            "BK": matrix_to_json(self.bk.as_ref()),
            "CK": matrix_to_json(self.ck.as_ref()),
            "DK": matrix_to_json(self.dk.as_ref()),
        });
        if let Some(ts) = self.domain.ts() {
            doc["Ts"] = ts.into();
        }
        doc
    }

    /// Checks that the controller fits the plant: it is in the plant's time domain (same `Ts`),
    /// its outputs are the plant's m2 control inputs
    /// and its inputs the plant's p2 measurements (Dk is m2 × p2), and its four blocks agree on
    /// the order nk (Ak nk × nk, Bk nk × p2, Ck m2 × nk): the fields are public, so a controller
    /// need not come from a checked file.
    pub fn check_fits(&self, plant: &super::plant::Plant) -> Result<(), ControllerErrorKind> {
        let (m, p, nk) = (plant.dims.m2, plant.dims.p2, self.order());
        let blocks = [("AK", &self.ak, (nk, nk)), ("BK", &self.bk, (nk, p)), ("CK", &self.ck, (m, nk))];
        let mismatch = |problem| Err(ControllerErrorKind::Mismatch { plant: plant.name.clone(), problem });
        if self.domain != plant.domain {
            return mismatch(format!("the controller is in {}, the plant in {}", self.domain, plant.domain));
        }
        if self.outputs() != m || self.inputs() != p {
            return mismatch(format!("DK is {}×{}, the plant needs m2×p2 = {m}×{p}", self.outputs(), self.inputs()));
        }
        for (name, b, (r, c)) in blocks {
            if (b.nrows(), b.ncols()) != (r, c) {
                return mismatch(format!("{name} is {}×{}, order {nk} needs {r}×{c}", b.nrows(), b.ncols()));
            }
        }
        Ok(())
    }

    /// [`Self::check_fits`], and the order is `order` (a journal record's controller must be of
    /// its job's order).
    pub fn check_fits_order(&self, plant: &super::plant::Plant, order: usize) -> Result<(), ControllerErrorKind> {
        self.check_fits(plant)?;
        if self.order() != order {
            return Err(ControllerErrorKind::Mismatch {
                plant: plant.name.clone(),
                problem: format!("the controller has order {}, the job's order is {order}", self.order()),
            });
        }
        Ok(())
    }

    /// Number of free variables (nk+m)(nk+p) in x = [vec Ak; vec Bk; vec Ck; vec Dk].
    pub fn nvar(&self) -> usize {
        (self.order() + self.outputs()) * (self.order() + self.inputs())
    }
}

// The MAT-file form (`lti::mat_file` reads and writes the variables).

/// Reads a controller from the bytes of a MAT-file holding `AK BK CK DK` (AK, BK, CK may be
/// empty for a static gain). Shapes are checked as for a controller JSON file.
fn controller_from_mat(bytes: &[u8]) -> Result<Controller, ControllerErrorKind> {
    let vars = read_mat_vars(bytes)?;
    let mut doc = Map::new();
    for key in ["AK", "BK", "CK", "DK"] {
        let Some(v) = vars.get(key) else { continue };
        if let Some(i) = v.data.iter().position(|x| !x.is_finite()) {
            let (row, col) = (i % v.rows + 1, i / v.rows + 1);
            let problem = MatrixJsonError::NotFinite { row, col, value: v.data[i] };
            return Err(ControllerErrorKind::Matrix { matrix: key, problem });
        }
        doc.insert(key.into(), var_to_json(v));
    }
    if let Some(ts) = vars.get("Ts") {
        doc.insert("Ts".into(), scalar_var_to_json(ts));
    }
    // `[]` (a 0×0 AK, BK, CK of a static gain) is accepted for any block without entries.
    Controller::from_json_value(&Value::Object(doc))
}

/// The controller as a MAT-file `AK BK CK DK` (and `Ts` in discrete time).
pub fn controller_to_mat(k: &Controller) -> Vec<u8> {
    let ts = k.domain.ts().map(|ts| Mat::from_fn(1, 1, |_, _| ts));
    let mut vars = vec![("AK", k.ak.as_ref()), ("BK", k.bk.as_ref()), ("CK", k.ck.as_ref()), ("DK", k.dk.as_ref())];
    if let Some(ts) = &ts {
        vars.push(("Ts", ts.as_ref()));
    }
    write_mat(&vars, "hinfix controller (u = K y: xk' = AK xk + BK y, u = CK xk + DK y)")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn order_zero_round_trip() {
        let text = r#"{"AK": [], "BK": [], "CK": [[], []], "DK": [[1.0, 2.0], [3.0, 4.0]]}"#;
        let k = Controller::from_json_str(text, "k.json").unwrap();
        assert_eq!((k.order(), k.outputs(), k.inputs()), (0, 2, 2));
        let back = Controller::from_json_value(&k.to_json()).unwrap();
        assert_eq!(back, k);
    }

    #[test]
    fn flat_dk_is_named_as_such() {
        // a flat list `DK: [1.0, 2.0]` was once reported as "has 0 rows", which misled.
        let e =
            Controller::from_json_str(r#"{"AK": [], "BK": [], "CK": [[]], "DK": [1.0, 2.0]}"#, "k.json").unwrap_err();
        let s = e.to_string();
        assert!(s.contains("`DK` row 1 must be an array") && s.contains("a number"), "{s}");
        let e = Controller::from_json_str(r#"{"AK": [], "BK": [], "CK": [], "DK": []}"#, "k.json").unwrap_err();
        assert!(e.to_string().contains("at least one row and one column, found 0×0"), "{e}");
    }

    #[test]
    fn unknown_key_is_named() {
        // A misspelt or unknown key was ignored.
        let text = r#"{"AK": [], "BK": [], "CK": [[]], "DK": [[1.0]], "Dk": [[2.0]]}"#;
        let e = Controller::from_json_str(text, "k.json").unwrap_err();
        assert!(matches!(&e.kind, ControllerErrorKind::UnknownKey { key } if key == "Dk"), "{e}");
        assert!(e.to_string().contains("unknown key `Dk`"), "{e}");
    }

    #[test]
    fn wrong_block_shape_is_named() {
        let text = r#"{"AK": [[1.0]], "BK": [[1.0, 2.0]], "CK": [[1.0]], "DK": [[1.0]]}"#;
        let e = Controller::from_json_str(text, "k.json").unwrap_err();
        assert!(e.to_string().contains("`BK`"), "{e}");
    }
}
