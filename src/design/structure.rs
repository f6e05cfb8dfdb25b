//! Structured controllers (docs/ALGORITHMS.md §1.1): a mask over (Ak, Bk, Ck, Dk) in which each
//! entry is free or fixed at a value.
//!
//! ```text
//! x_full = template + P·x_free
//! ```
//!
//! where `template` holds the fixed values (zeros at free entries) and P places the free
//! entries, in the order of x = [vec Ak; vec Bk; vec Ck; vec Dk] (column-major). The optimiser
//! sees x_free only; the gradient is ∇ₓ restricted to the free entries (Pᵀ∇ₓ). A fixed entry is
//! copied from the structure into every controller, so it stays bit for bit at its value.
//!
//! File format (JSON): `{"AK": [[null, 0.0], …], "BK": …, "CK": …, "DK": …}`, rows of entries,
//! `null` = free, a number = fixed at that value. Each block given must have the shape of the
//! order designed (nk×nk, nk×p2, m2×nk, m2×p2); a block left out is entirely free (so an
//! order-0 structure may give only `DK`). Any other key is an error. A MATLAB .mat file with
//! variables AK, BK, CK, DK is read the same way, NaN = free.

use std::path::Path;

use serde_json::Value;

use crate::lti::{is_mat_path, read_mat_vars, Controller};

use super::params::{controller_to_x, ControllerShape};

/// The four blocks, in the order of x.
pub const BLOCKS: [&str; 4] = ["AK", "BK", "CK", "DK"];

/// A structure for controllers of one shape: each entry of (Ak, Bk, Ck, Dk) free (`None`) or
/// fixed (`Some(value)`), in the layout of x ([`ControllerShape`]).
#[derive(Debug, Clone, PartialEq)]
pub struct Structure {
    nk: usize,
    m: usize,
    p: usize,
    entries: Vec<Option<f64>>,
    free: Vec<usize>,
}

/// Why a structure cannot be used. `file` names the structure's source (a path, or what the
/// caller passed to [`Structure::from_json`]).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum StructureError {
    /// The file could not be read.
    #[error("structure file {file}: {message}")]
    Io {
        /// The file.
        file: String,
        /// The I/O error.
        message: String,
    },
    /// Not JSON, or not a JSON object.
    #[error("structure file {file}: {message}")]
    Syntax {
        /// The file.
        file: String,
        /// What is wrong.
        message: String,
    },
    /// A key other than AK, BK, CK, DK.
    #[error("structure file {file}: unknown key {key:?} (expected AK, BK, CK, DK)")]
    UnknownKey {
        /// The file.
        file: String,
        /// The key.
        key: String,
    },
    /// A block of the wrong shape (not a list of rows, wrong number of rows, or a row of the
    /// wrong length).
    #[error("structure file {file}: block {block} must be {rows}×{cols} for order {order}: {problem}")]
    Shape {
        /// The file.
        file: String,
        /// AK, BK, CK or DK.
        block: &'static str,
        /// Expected rows.
        rows: usize,
        /// Expected columns.
        cols: usize,
        /// The controller order.
        order: usize,
        /// What was found.
        problem: String,
    },
    /// An entry that is neither null nor a number.
    #[error("structure file {file}: block {block} entry ({row}, {col}) (1-based) is {found}, not null (free) or a number (fixed)")]
    NotANumber {
        /// The file.
        file: String,
        /// AK, BK, CK or DK.
        block: &'static str,
        /// 1-based row.
        row: usize,
        /// 1-based column.
        col: usize,
        /// The JSON found.
        found: String,
    },
    /// A fixed value that is not finite.
    #[error(
        "structure file {file}: block {block} entry ({row}, {col}) (1-based) is fixed at {value}, which is not finite"
    )]
    NonFinite {
        /// The file.
        file: String,
        /// AK, BK, CK or DK.
        block: &'static str,
        /// 1-based row.
        row: usize,
        /// 1-based column.
        col: usize,
        /// The value.
        value: f64,
    },
}

/// Rows and columns of the four blocks for `shape`.
fn block_dims(shape: ControllerShape) -> [(usize, usize); 4] {
    let (nk, m, p) = (shape.nk, shape.m, shape.p);
    [(nk, nk), (nk, p), (m, nk), (m, p)]
}

/// Offset of each block in x.
fn block_offsets(shape: ControllerShape) -> [usize; 4] {
    let d = block_dims(shape);
    let mut off = [0; 4];
    for b in 1..4 {
        off[b] = off[b - 1] + d[b - 1].0 * d[b - 1].1;
    }
    off
}

impl Structure {
    /// Every entry free (the unstructured design).
    pub fn all_free(shape: ControllerShape) -> Self {
        Self::from_entries(shape, vec![None; shape.nvar()]).expect("the right length")
    }

    /// A structure from its entries in the layout of x (`entries.len()` must be `shape.nvar()`;
    /// fixed values must be finite, or the error is [`StructureError::NonFinite`] with file
    /// "(entries)"). A structure with no free entry is allowed here; [`Self::load`] and the
    /// design run refuse it.
    pub fn from_entries(shape: ControllerShape, entries: Vec<Option<f64>>) -> Result<Self, StructureError> {
        assert_eq!(entries.len(), shape.nvar(), "structure length does not match the controller shape");
        if let Some(i) = entries.iter().position(|e| e.is_some_and(|v| !v.is_finite())) {
            let (block, row, col) = Self::locate(shape, i);
            return Err(StructureError::NonFinite {
                file: "(entries)".into(),
                block,
                row: row + 1,
                col: col + 1,
                value: entries[i].unwrap_or(f64::NAN),
            });
        }
        let free = (0..entries.len()).filter(|&i| entries[i].is_none()).collect();
        Ok(Structure { nk: shape.nk, m: shape.m, p: shape.p, entries, free })
    }

    /// Block name, 0-based row and column of entry `i` of x.
    fn locate(shape: ControllerShape, i: usize) -> (&'static str, usize, usize) {
        let (dims, offs) = (block_dims(shape), block_offsets(shape));
        let b = (0..4).rev().find(|&b| i >= offs[b] && dims[b].0 * dims[b].1 > 0).unwrap_or(0);
        let k = i - offs[b];
        (BLOCKS[b], k % dims[b].0.max(1), k / dims[b].0.max(1))
    }

    /// Reads a structure file (module docs) for controllers of `shape`.
    pub fn load(path: &Path, shape: ControllerShape) -> Result<Self, StructureError> {
        let file = path.display().to_string();
        let io = |e: std::io::Error| StructureError::Io { file: file.clone(), message: e.to_string() };
        // bounded like every input file (`--structure /dev/zero` read until memory ran out), and a
        // JSON file with a UTF-8 byte-order mark read as plant files are
        let limit = crate::input::MAX_STRUCTURE_BYTES;
        let s = if is_mat_path(path) {
            Self::from_mat_bytes(&crate::input::read_capped(path, limit, "structure file").map_err(io)?, &file, shape)?
        } else {
            let text = crate::input::read_capped_string(path, limit, "structure file").map_err(io)?;
            Self::from_json(&text, &file, shape)?
        };
        Ok(s)
    }

    /// Parses the JSON `text` of a structure (module docs); `file` names it in errors. A
    /// structure with no free entry is not refused here.
    pub fn from_json(text: &str, file: &str, shape: ControllerShape) -> Result<Self, StructureError> {
        let syntax = |message: String| StructureError::Syntax { file: file.into(), message };
        let text = text.strip_prefix('\u{feff}').unwrap_or(text);
        let v: Value =
            crate::input::parse_json_unique_keys(text).map_err(|e| syntax(format!("not valid JSON: {e}")))?;
        Self::from_value(v, file, shape)
    }

    /// Parses a MATLAB level-5 .mat file (`bytes`) with variables AK, BK, CK, DK (any of them;
    /// a variable left out is free): NaN = free, a finite number = fixed; `file` names it in
    /// errors. An empty variable (`[]`) stands for a block with no entries.
    pub fn from_mat_bytes(bytes: &[u8], file: &str, shape: ControllerShape) -> Result<Self, StructureError> {
        let vars =
            read_mat_vars(bytes).map_err(|e| StructureError::Syntax { file: file.into(), message: e.to_string() })?;
        let dims = block_dims(shape);
        let mut map = serde_json::Map::new();
        for (name, v) in vars {
            let Some(b) = BLOCKS.iter().position(|&k| k == name) else {
                return Err(StructureError::UnknownKey { file: file.into(), key: name });
            };
            if v.is_empty() && dims[b].0 * dims[b].1 == 0 {
                continue;
            }
            let mut rows = Vec::with_capacity(v.rows);
            for i in 0..v.rows {
                let mut row = Vec::with_capacity(v.cols);
                for j in 0..v.cols {
                    let x = v.data[i + j * v.rows];
                    row.push(match serde_json::Number::from_f64(x) {
                        _ if x.is_nan() => Value::Null,
                        Some(n) => Value::Number(n),
                        None => {
                            return Err(StructureError::NonFinite {
                                file: file.into(),
                                block: BLOCKS[b],
                                row: i + 1,
                                col: j + 1,
                                value: x,
                            })
                        }
                    });
                }
                rows.push(Value::Array(row));
            }
            map.insert(name, Value::Array(rows));
        }
        Self::from_value(Value::Object(map), file, shape)
    }

    /// The structure of a parsed JSON value (module docs).
    fn from_value(v: Value, file: &str, shape: ControllerShape) -> Result<Self, StructureError> {
        let syntax = |message: String| StructureError::Syntax { file: file.into(), message };
        let Value::Object(map) = v else {
            return Err(syntax("must be a JSON object with keys AK, BK, CK, DK".into()));
        };
        if let Some(key) = map.keys().find(|k| !BLOCKS.contains(&k.as_str())) {
            return Err(StructureError::UnknownKey { file: file.into(), key: key.clone() });
        }
        let (dims, offs) = (block_dims(shape), block_offsets(shape));
        let mut entries = vec![None; shape.nvar()];
        for (b, &block) in BLOCKS.iter().enumerate() {
            let Some(value) = map.get(block) else { continue };
            let (rows, cols) = dims[b];
            let shape_err = |problem: String| StructureError::Shape {
                file: file.into(),
                block,
                rows,
                cols,
                order: shape.nk,
                problem,
            };
            let Value::Array(rs) = value else {
                return Err(shape_err(format!("found {value}, not a list of rows")));
            };
            if rs.len() != rows {
                return Err(shape_err(format!("found {} rows", rs.len())));
            }
            for (i, r) in rs.iter().enumerate() {
                let Value::Array(cs) = r else {
                    return Err(shape_err(format!("row {} is {r}, not a list", i + 1)));
                };
                if cs.len() != cols {
                    return Err(shape_err(format!("row {} has {} entries", i + 1, cs.len())));
                }
                for (j, e) in cs.iter().enumerate() {
                    let at = offs[b] + i + j * rows;
                    entries[at] = match e {
                        Value::Null => None,
                        Value::Number(n) => match n.as_f64() {
                            Some(x) if x.is_finite() => Some(x),
                            _ => {
                                return Err(StructureError::NonFinite {
                                    file: file.into(),
                                    block,
                                    row: i + 1,
                                    col: j + 1,
                                    value: n.as_f64().unwrap_or(f64::NAN),
                                })
                            }
                        },
                        other => {
                            return Err(StructureError::NotANumber {
                                file: file.into(),
                                block,
                                row: i + 1,
                                col: j + 1,
                                found: other.to_string(),
                            })
                        }
                    };
                }
            }
        }
        Self::from_entries(shape, entries).map_err(|e| match e {
            StructureError::NonFinite { block, row, col, value, .. } => {
                StructureError::NonFinite { file: file.into(), block, row, col, value }
            }
            e => e,
        })
    }

    /// The controller shape's sizes (nk, m, p) this structure is for.
    pub fn sizes(&self) -> (usize, usize, usize) {
        (self.nk, self.m, self.p)
    }

    /// Whether this structure is for controllers of `shape`'s sizes.
    pub fn fits(&self, shape: ControllerShape) -> bool {
        self.sizes() == (shape.nk, shape.m, shape.p)
    }

    /// The entries in the layout of x (`None` = free).
    pub fn entries(&self) -> &[Option<f64>] {
        &self.entries
    }

    /// Number of free entries (the optimiser's variables).
    pub fn nfree(&self) -> usize {
        self.free.len()
    }

    /// Indices of the free entries in x.
    pub fn free_indices(&self) -> &[usize] {
        &self.free
    }

    /// x_full = template + P·x_free (`x_free.len()` must be [`Self::nfree`]).
    pub fn expand(&self, x_free: &[f64]) -> Vec<f64> {
        assert_eq!(x_free.len(), self.nfree(), "free vector length does not match the structure");
        let mut it = x_free.iter();
        self.entries.iter().map(|e| e.unwrap_or_else(|| *it.next().expect("counted"))).collect()
    }

    /// Pᵀ·x_full: the free entries of a full vector (a point or a gradient).
    pub fn restrict(&self, x_full: &[f64]) -> Vec<f64> {
        assert_eq!(x_full.len(), self.entries.len(), "full vector length does not match the structure");
        self.free.iter().map(|&i| x_full[i]).collect()
    }

    /// The controller with the free entries `x_free`.
    pub fn controller(&self, shape: ControllerShape, x_free: &[f64]) -> Controller {
        assert!(self.fits(shape), "structure does not have this shape");
        shape.controller(&self.expand(x_free))
    }

    /// `k` (of this structure's sizes) with its fixed entries overwritten by their values.
    pub fn project(&self, k: &Controller) -> Controller {
        let x = controller_to_x(k);
        ControllerShape::of(k).controller(&self.expand(&self.restrict(&x)))
    }

    /// The first fixed entry of `k` not equal (bit for bit) to its value: (block, 1-based row,
    /// 1-based column, value in `k`); `None` if `k` satisfies the structure.
    pub fn violation(&self, k: &Controller) -> Option<(&'static str, usize, usize, f64)> {
        let shape = ControllerShape::of(k);
        let x = controller_to_x(k);
        let i = (0..x.len()).find(|&i| self.entries[i].is_some_and(|v| v.to_bits() != x[i].to_bits()))?;
        let (b, r, c) = Self::locate(shape, i);
        Some((b, r + 1, c + 1, x[i]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lti::TimeDomain;

    fn shape(nk: usize, m: usize, p: usize) -> ControllerShape {
        ControllerShape { nk, m, p, domain: TimeDomain::Continuous }
    }

    #[test]
    fn parses_in_the_layout_of_x() {
        let s = Structure::from_json(
            r#"{"AK": [[null, 0.0], [1.5, null]], "BK": [[null], [2.0]], "DK": [[-0.0]]}"#,
            "t.json",
            shape(2, 1, 1),
        )
        .unwrap();
        // x = [Ak11 Ak21 Ak12 Ak22 | Bk11 Bk21 | Ck11 Ck12 | Dk11]
        let e = s.entries();
        assert_eq!(e[0], None);
        assert_eq!(e[1], Some(1.5));
        assert_eq!(e[2], Some(0.0));
        assert_eq!(e[5], Some(2.0));
        assert_eq!(e[8].map(f64::to_bits), Some((-0.0f64).to_bits()));
        assert_eq!(s.free_indices(), &[0, 3, 4, 6, 7]);
        let full = s.expand(&[10.0, 11.0, 12.0, 13.0, 14.0]);
        assert_eq!(s.restrict(&full), vec![10.0, 11.0, 12.0, 13.0, 14.0]);
        assert_eq!(Structure::locate(shape(2, 1, 1), 5), ("BK", 1, 0));
        assert_eq!(Structure::locate(shape(2, 1, 1), 7), ("CK", 0, 1));
        assert_eq!(Structure::locate(shape(0, 1, 1), 0), ("DK", 0, 0));
    }

    #[test]
    fn a_mat_file_uses_nan_for_free() {
        use crate::lti::write_mat;
        let sh = shape(1, 1, 2);
        let ak = faer::Mat::from_fn(1, 1, |_, _| -1.0);
        let dk = faer::Mat::from_fn(1, 2, |_, j| if j == 0 { f64::NAN } else { 0.0 });
        let bytes = write_mat(&[("AK", ak.as_ref()), ("DK", dk.as_ref())], "structure");
        let s = Structure::from_mat_bytes(&bytes, "s.mat", sh).unwrap();
        // x = [Ak | Bk11 Bk12 | Ck | Dk11 Dk12]
        assert_eq!(s.entries(), &[Some(-1.0), None, None, None, None, Some(0.0)]);
        let bad = write_mat(&[("EK", ak.as_ref())], "structure");
        assert!(Structure::from_mat_bytes(&bad, "s.mat", sh).unwrap_err().to_string().contains("unknown key \"EK\""));
        let inf = faer::Mat::from_fn(1, 1, |_, _| f64::INFINITY);
        let bytes = write_mat(&[("AK", inf.as_ref())], "structure");
        let msg = Structure::from_mat_bytes(&bytes, "s.mat", sh).unwrap_err().to_string();
        assert!(msg.contains("block AK entry (1, 1)") && msg.contains("not finite"), "{msg}");
    }

    #[test]
    fn errors_name_the_block_and_the_entry() {
        let sh = shape(1, 1, 2);
        let err = |t: &str| Structure::from_json(t, "s.json", sh).unwrap_err().to_string();
        assert!(err(r#"{"DK": [[1.0]]}"#).contains("block DK must be 1×2"));
        assert!(err(r#"{"AK": [[1.0], [2.0]]}"#).contains("found 2 rows"));
        assert!(err(r#"{"BK": [[1.0, "x"]]}"#).contains("block BK entry (1, 2)"));
        assert!(err(r#"{"Ak": [[1.0]]}"#).contains("unknown key \"Ak\""));
        assert!(err(r#"[1]"#).contains("s.json"));
        assert!(Structure::from_entries(sh, vec![None, None, Some(f64::INFINITY), None, None, None]).is_err());
    }
}
