//! Reading and writing dense real matrices as JSON arrays of rows.
//!
//! A `r × c` matrix is `[[a11, …, a1c], …, [ar1, …, arc]]`. Empty blocks are unambiguous only
//! together with the expected shape: a `0 × c` matrix is `[]`, an `r × 0` one is `[[], …, []]`
//! (`r` empty rows) and is also accepted as `[]`. The reader checks the shape against what the
//! caller expects and names the row and column of the first bad entry (1-based, as a person
//! counts them in a file).

use faer::Mat;
use serde_json::Value;

/// Largest accepted matrix dimension (rows or columns): 1 048 576. Far above any plant this
/// program can handle; it keeps a typo in `dims` from becoming a huge allocation or loop.
pub(crate) const MAX_MATRIX_DIM: usize = 1 << 20;

/// What is wrong with one matrix in a JSON document (the caller adds file and matrix name).
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MatrixJsonError {
    /// The matrix key is absent.
    #[error("is missing")]
    Missing,
    /// The value is not an array of rows.
    #[error("must be an array of rows (arrays of numbers), found {found}")]
    NotArray {
        /// JSON type found.
        found: &'static str,
    },
    /// A row is not an array.
    #[error("row {row} must be an array of numbers, found {found}")]
    RowNotArray {
        /// 1-based row.
        row: usize,
        /// JSON type found.
        found: &'static str,
    },
    /// Wrong number of rows.
    #[error("has {got} rows, expected {expected}")]
    RowCount {
        /// Expected rows.
        expected: usize,
        /// Rows found.
        got: usize,
    },
    /// A row of the wrong length.
    #[error("row {row} has {got} entries, expected {expected}")]
    RowLength {
        /// 1-based row.
        row: usize,
        /// Expected columns.
        expected: usize,
        /// Columns found.
        got: usize,
    },
    /// An entry that is not a number (a string such as "NaN", null, …).
    #[error("entry ({row}, {col}) is not a number: {found}")]
    NotNumber {
        /// 1-based row.
        row: usize,
        /// 1-based column.
        col: usize,
        /// The JSON text found.
        found: String,
    },
    /// A matrix that must have entries has none.
    #[error("must have at least one row and one column, found {rows}×{cols}")]
    Empty {
        /// Rows found.
        rows: usize,
        /// Columns found.
        cols: usize,
    },
    /// The expected shape exceeds `MAX_MATRIX_DIM`.
    #[error("would be {rows}×{cols}, larger than the limit of {MAX_MATRIX_DIM} rows or columns")]
    TooLarge {
        /// Expected rows.
        rows: usize,
        /// Expected columns.
        cols: usize,
    },
    /// A plant entry larger than [`MAX_PLANT_MAGNITUDE`] in absolute value.
    #[error(
        "entry ({row}, {col}) = {value:e} is larger than {MAX_PLANT_MAGNITUDE:e} in absolute value, the limit for \
         a plant entry (products of such numbers overflow, and the H∞ norm would come out NaN or ∞); rescale the \
         plant's inputs, outputs or states"
    )]
    Magnitude {
        /// 1-based row.
        row: usize,
        /// 1-based column.
        col: usize,
        /// The value.
        value: f64,
    },
    /// A non-zero plant matrix whose entries are all below [`MIN_PLANT_MAGNITUDE`].
    #[error(
        "is not zero but its largest entry is {largest:e}, below {MIN_PLANT_MAGNITUDE:e} in absolute value (products \
         of such numbers underflow, and the H∞ norm would come out 0 or ∞); write it as zeros or rescale the plant"
    )]
    Negligible {
        /// Its largest entry's magnitude.
        largest: f64,
    },
    /// A number that is not finite.
    #[error("entry ({row}, {col}) is not finite ({value})")]
    NotFinite {
        /// 1-based row.
        row: usize,
        /// 1-based column.
        col: usize,
        /// The value.
        value: f64,
    },
}

/// Largest magnitude of a plant entry: 1e50. The closed loop, the Hamiltonian of the H∞ norm and
/// its level set multiply entries (γ², B·Bᵀ, C1ᵀC1 and products of three or four of them), so
/// large entries overflow to ∞ and then NaN: D11 = 1e200 gave γ = NaN, and HE1 with every
/// matrix scaled by 1e60 (or more) gave γ = ∞ for a stable loop, while scaled by 1e50 its norm
/// is finite. The bound keeps fourth powers of entries far below f64's 1.8e308.
pub const MAX_PLANT_MAGNITUDE: f64 = 1e50;
/// Smallest largest-entry of a non-zero plant matrix: 1e-50, the mirror bound. Single tiny entries
/// are harmless (CM4's A has entries of 1e-70 next to 1e4), but a matrix made only of them is a
/// plant on a scale the absolute parts of the stability and norm tests cannot resolve: HE1 scaled
/// by 1e-140 could not be stabilised, and scaled by 1e-300 it gave γ = ∞ for stable loops.
pub const MIN_PLANT_MAGNITUDE: f64 = 1e-50;

/// Checks a plant matrix against the magnitude bounds: no entry above [`MAX_PLANT_MAGNITUDE`] (the
/// first one is named, 1-based), and a non-zero matrix has an entry of at least
/// [`MIN_PLANT_MAGNITUDE`].
pub fn check_magnitudes(m: faer::MatRef<'_, f64>) -> Result<(), MatrixJsonError> {
    let mut largest = 0.0f64;
    for j in 0..m.ncols() {
        for i in 0..m.nrows() {
            let x = m[(i, j)];
            if !(x.abs() <= MAX_PLANT_MAGNITUDE) {
                return Err(MatrixJsonError::Magnitude { row: i + 1, col: j + 1, value: x });
            }
            largest = largest.max(x.abs());
        }
    }
    if largest > 0.0 && largest < MIN_PLANT_MAGNITUDE {
        return Err(MatrixJsonError::Negligible { largest });
    }
    Ok(())
}

pub(crate) fn json_type(v: &Value) -> &'static str {
    match v {
        Value::Null => "null",
        Value::Bool(_) => "a boolean",
        Value::Number(_) => "a number",
        Value::String(_) => "a string",
        Value::Array(_) => "an array",
        Value::Object(_) => "an object",
    }
}

/// Reads a matrix of the expected shape from `value` (None when the key was absent).
pub fn matrix_from_json(value: Option<&Value>, rows: usize, cols: usize) -> Result<Mat<f64>, MatrixJsonError> {
    let value = value.ok_or(MatrixJsonError::Missing)?;
    let arr = value.as_array().ok_or(MatrixJsonError::NotArray { found: json_type(value) })?;
    if rows > MAX_MATRIX_DIM || cols > MAX_MATRIX_DIM {
        return Err(MatrixJsonError::TooLarge { rows, cols });
    }
    // `[]` stands for any matrix with no entries.
    if arr.is_empty() && (rows == 0 || cols == 0) {
        return Ok(Mat::zeros(rows, cols));
    }
    if arr.len() != rows {
        return Err(MatrixJsonError::RowCount { expected: rows, got: arr.len() });
    }
    // Every row is checked before anything is allocated: the expected shape comes from the
    // file's `dims`, and a huge dimension must be an error, not a rows × cols allocation.
    let mut entries = Vec::with_capacity(rows);
    for (i, row) in arr.iter().enumerate() {
        let r = row.as_array().ok_or(MatrixJsonError::RowNotArray { row: i + 1, found: json_type(row) })?;
        if r.len() != cols {
            return Err(MatrixJsonError::RowLength { row: i + 1, expected: cols, got: r.len() });
        }
        entries.push(r);
    }
    let mut m = Mat::zeros(rows, cols);
    for (i, r) in entries.into_iter().enumerate() {
        for (j, e) in r.iter().enumerate() {
            let x = e.as_f64().ok_or_else(|| MatrixJsonError::NotNumber {
                row: i + 1,
                col: j + 1,
                found: e.to_string(),
            })?;
            if !x.is_finite() {
                return Err(MatrixJsonError::NotFinite { row: i + 1, col: j + 1, value: x });
            }
            m[(i, j)] = x;
        }
    }
    Ok(m)
}

/// Writes a matrix as a JSON array of rows.
pub fn matrix_to_json(m: faer::MatRef<'_, f64>) -> Value {
    Value::Array((0..m.nrows()).map(|i| Value::Array((0..m.ncols()).map(|j| number(m[(i, j)])).collect())).collect())
}

/// A finite f64 as a JSON number; non-finite values (which valid matrices never hold) as strings.
fn number(x: f64) -> Value {
    serde_json::Number::from_f64(x).map(Value::Number).unwrap_or_else(|| Value::String(x.to_string()))
}

/// Shape of a JSON array of rows, if it is one (rows, length of the first row).
pub(crate) fn json_shape(value: &Value) -> Option<(usize, usize)> {
    let arr = value.as_array()?;
    let cols = arr.first().and_then(|r| r.as_array()).map_or(0, |r| r.len());
    Some((arr.len(), cols))
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn reads_and_writes_round_trip() {
        let v = json!([[1.0, 2.0], [3.0, -4.5]]);
        let m = matrix_from_json(Some(&v), 2, 2).unwrap();
        assert_eq!(m[(1, 1)], -4.5);
        assert_eq!(matrix_to_json(m.as_ref()), v);
    }

    #[test]
    fn empty_blocks() {
        assert_eq!(matrix_from_json(Some(&json!([])), 0, 3).unwrap().nrows(), 0);
        assert_eq!(matrix_from_json(Some(&json!([])), 2, 0).unwrap().nrows(), 2);
        assert_eq!(matrix_from_json(Some(&json!([[], []])), 2, 0).unwrap().ncols(), 0);
    }

    #[test]
    fn huge_expected_width_is_an_error_not_an_allocation() {
        // Found by the fuzz test: a plant with dims.m1 = 10^15 and B1 of n rows made the reader
        // allocate n × 10^15 before it looked at a row.
        let e = matrix_from_json(Some(&json!([[1.0], [2.0]])), 2, 1_000_000_000_000_000).unwrap_err();
        assert!(matches!(e, MatrixJsonError::TooLarge { .. }), "{e}");
        let e = matrix_from_json(Some(&json!([[1.0], [2.0]])), 2, usize::MAX).unwrap_err();
        assert!(matches!(e, MatrixJsonError::TooLarge { .. }), "{e}");
        // within the limit, the rows are checked before the allocation
        let e = matrix_from_json(Some(&json!([[1.0], [2.0]])), 2, MAX_MATRIX_DIM).unwrap_err();
        assert!(matches!(e, MatrixJsonError::RowLength { row: 1, .. }), "{e}");
        // an empty block with a huge other dimension
        let e = matrix_from_json(Some(&json!([])), 0, 1 << 40).unwrap_err();
        assert!(matches!(e, MatrixJsonError::TooLarge { .. }), "{e}");
        let e = matrix_from_json(Some(&json!([])), usize::MAX, 0).unwrap_err();
        assert!(matches!(e, MatrixJsonError::TooLarge { .. }), "{e}");
        assert_eq!(matrix_from_json(Some(&json!([])), 0, 1000).unwrap().ncols(), 1000);
    }

    #[test]
    fn magnitudes_outside_the_bounds_are_named() {
        // D11 = 1e200 gave γ = NaN with exit 0; scaled plants gave γ = ∞.
        let m = Mat::from_fn(2, 2, |i, j| [[1.0, 0.0], [-1e200, 1e-300]][i][j]);
        let e = check_magnitudes(m.as_ref()).unwrap_err();
        assert_eq!(e, MatrixJsonError::Magnitude { row: 2, col: 1, value: -1e200 });
        // a tiny entry next to ordinary ones is fine, a matrix of tiny entries is not
        let m = Mat::from_fn(1, 4, |_, j| [0.0, MAX_PLANT_MAGNITUDE, 1e-300, -MIN_PLANT_MAGNITUDE][j]);
        check_magnitudes(m.as_ref()).unwrap();
        let m = Mat::from_fn(1, 2, |_, j| [1e-300, 0.0][j]);
        assert_eq!(check_magnitudes(m.as_ref()).unwrap_err(), MatrixJsonError::Negligible { largest: 1e-300 });
        check_magnitudes(Mat::<f64>::zeros(2, 2).as_ref()).unwrap();
    }

    #[test]
    fn names_the_bad_entry() {
        let e = matrix_from_json(Some(&json!([[1.0, 2.0], [3.0, "NaN"]])), 2, 2).unwrap_err();
        assert_eq!(e, MatrixJsonError::NotNumber { row: 2, col: 2, found: "\"NaN\"".into() });
        let e = matrix_from_json(Some(&json!([[1.0], [3.0, 1.0]])), 2, 2).unwrap_err();
        assert_eq!(e, MatrixJsonError::RowLength { row: 1, expected: 2, got: 1 });
        assert_eq!(matrix_from_json(None, 1, 1).unwrap_err(), MatrixJsonError::Missing);
    }
}
