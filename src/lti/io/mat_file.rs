//! MATLAB level-5 MAT-files as named real matrices: reading ([`read_mat_vars`]) and writing
//! ([`write_mat`]). This module knows nothing of plants or controllers; `plant.rs` and
//! `controller.rs` turn their variables (`A B1 B2 C1 C2 D11 D12 D21 D22`, `AK BK CK DK`) into
//! plants and controllers, so a model can come from MATLAB (or `scipy.io.savemat`) and a
//! designed controller go back.
//!
//! Reading uses the `matfile` crate (pure Rust; uncompressed and zlib-compressed variables; it
//! returns numeric arrays and skips character, cell, struct and sparse variables), after
//! `mat_inflate` has decompressed the compressed variables within a size limit. No maintained
//! Rust crate writes MAT-files, so [`write_mat`] is a minimal level-5 writer: a 128-byte header
//! and one uncompressed `miMATRIX` element per variable (class `mxDOUBLE_CLASS`, 2-D, real),
//! little-endian, following MathWorks' "MAT-File Format" (level 5) document. MATLAB, Octave and
//! `scipy.io.loadmat` read it. Values are copied bit for bit.

use std::collections::BTreeMap;
use std::path::Path;

use faer::{Mat, MatRef};
use serde_json::Value;

/// A real 2-D variable of a MAT-file, column-major.
#[derive(Debug, Clone, PartialEq)]
pub struct MatVar {
    /// Rows.
    pub rows: usize,
    /// Columns.
    pub cols: usize,
    /// Entries, column-major (MATLAB's order).
    pub data: Vec<f64>,
}

impl MatVar {
    /// The variable as a dense matrix.
    pub fn to_mat(&self) -> Mat<f64> {
        Mat::from_fn(self.rows, self.cols, |i, j| self.data[i + j * self.rows])
    }

    /// A matrix as a variable.
    pub fn from_mat(m: MatRef<'_, f64>) -> Self {
        let mut data = Vec::with_capacity(m.nrows() * m.ncols());
        for j in 0..m.ncols() {
            for i in 0..m.nrows() {
                data.push(m[(i, j)]);
            }
        }
        MatVar { rows: m.nrows(), cols: m.ncols(), data }
    }

    /// Whether the variable has no entries (`[]`, or a 0-wide block).
    pub(crate) fn is_empty(&self) -> bool {
        self.rows == 0 || self.cols == 0
    }
}

/// Why a MAT-file could not be read as plain real matrices.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum MatReadError {
    /// Not a level-5 MAT-file, or a damaged one.
    #[error("not a readable MATLAB level-5 .mat file ({0}); save it with `save(..., '-v7')` or scipy.io.savemat")]
    Format(String),
    /// A variable this program needs is not a real 2-D array.
    #[error("variable `{name}` {problem}")]
    Variable {
        /// Variable name.
        name: String,
        /// What is wrong.
        problem: String,
    },
}

/// Reads every numeric variable of a level-5 MAT-file (`bytes`) as a real 2-D matrix, by name.
/// Complex or N-d (N > 2) variables are errors; integer and single classes are converted to f64
/// exactly. A variable of any other class (char, cell, struct, object, sparse, …) is an error
/// naming it and its class: `matfile` skips them, and a skipped `Ts` or structure block was once
/// silently read as absent (continuous time, a free block).
pub fn read_mat_vars(bytes: &[u8]) -> Result<BTreeMap<String, MatVar>, MatReadError> {
    read_mat_vars_with_text(bytes, &[])
}

/// As [`read_mat_vars`], with character variables of the names in `text` allowed (and left out
/// of the result: `read_char_var` reads them), such as a plant's `name`.
pub(crate) fn read_mat_vars_with_text(bytes: &[u8], text: &[&str]) -> Result<BTreeMap<String, MatVar>, MatReadError> {
    if bytes.len() < 128 {
        return Err(MatReadError::Format(format!("{} bytes, shorter than the 128-byte header", bytes.len())));
    }
    if bytes.get(512..).is_some_and(|b| b.starts_with(b"\x89HDF")) {
        return Err(MatReadError::Format("an HDF5-based v7.3 file".into()));
    }
    let plain = super::mat_inflate::inflate_elements(bytes, super::mat_inflate::MAX_MAT_INFLATED_BYTES)
        .map_err(MatReadError::Format)?;
    let classes = variable_classes(&plain)?;
    if let Some(name) =
        classes.iter().enumerate().find_map(|(i, (n, _))| classes[..i].iter().any(|(m, _)| m == n).then_some(n))
    {
        // `matfile` keeps both and the last one won: a plant's `A` was silently the second one
        return Err(MatReadError::Variable {
            name: name.clone(),
            problem: "appears twice in the file; a name may hold only one matrix".into(),
        });
    }
    for (name, class) in classes.iter().cloned() {
        let allowed = class == MX_CHAR_CLASS && text.contains(&name.as_str());
        if !allowed && !(MX_DOUBLE_CLASS..=MX_UINT64_CLASS).contains(&class) {
            return Err(MatReadError::Variable {
                name,
                problem: format!(
                    "is {}; only full real numeric matrices are read here (in MATLAB: `X = full(double(X))`)",
                    class_name(class)
                ),
            });
        }
    }
    // The last resort for a parser we do not own: a panic on damaged data is a format error.
    let file = crate::panic_guard::catch_quietly(|| matfile::MatFile::parse(plain.as_slice()))
        .map_err(|panic| MatReadError::Format(format!("damaged file: {panic}")))?
        .map_err(|e| match classes.iter().find(|(_, c)| *c != MX_DOUBLE_CLASS) {
            // matfile fails on some integer and single arrays (data stored in a smaller type):
            // name the variable rather than call the whole file unreadable
            Some((name, class)) => MatReadError::Variable {
                name: name.clone(),
                problem: format!(
                    "is {} and could not be decoded ({e}); save it as a double matrix (`X = double(X)`)",
                    class_name(*class)
                ),
            },
            None => MatReadError::Format(e.to_string()),
        })?;
    let mut out = BTreeMap::new();
    for a in file.arrays() {
        let bad = |problem: String| MatReadError::Variable { name: a.name().to_string(), problem };
        if a.ndims() != 2 {
            return Err(bad(format!("has {} dimensions {:?}; a matrix has 2", a.ndims(), a.size())));
        }
        let data = real_f64(a.data()).ok_or_else(|| bad("is complex; a matrix here must be real".into()))?;
        let (rows, cols) = (a.size()[0], a.size()[1]);
        if rows.checked_mul(cols) != Some(data.len()) {
            return Err(bad(format!("holds {} entries for a {rows}×{cols} array", data.len())));
        }
        out.insert(a.name().to_string(), MatVar { rows, cols, data });
    }
    Ok(out)
}

/// The (name, array class) of every top-level variable of an uncompressed level-5 file (after
/// `mat_inflate`), in either byte order; elements whose inside cannot be parsed are left to
/// `matfile`, which reports them. An element that claims more bytes than the file has left, or
/// a partial element header at its end, is a truncated or damaged file (`matfile` stopped there
/// and returned the variables before it, so a cut file read as a file with missing matrices).
fn variable_classes(plain: &[u8]) -> Result<Vec<(String, u8)>, MatReadError> {
    let big = plain.get(126..128) == Some(b"MI");
    let u32_at = |b: &[u8], i: usize| -> Option<u32> {
        let w: [u8; 4] = b.get(i..i.checked_add(4)?)?.try_into().ok()?;
        Some(if big { u32::from_be_bytes(w) } else { u32::from_le_bytes(w) })
    };
    // one sub-element of a miMATRIX body at `pos`: (data, next position), long or small form
    let sub = |b: &[u8], pos: usize| -> Option<(Vec<u8>, usize)> {
        let tag = u32_at(b, pos)?;
        if tag >> 16 != 0 {
            let len = (tag >> 16) as usize;
            return Some((b.get(pos + 4..pos + 4 + len.min(4))?.to_vec(), pos + 8));
        }
        let len = u32_at(b, pos + 4)? as usize;
        let end = (pos + 8).checked_add(len)?;
        Some((b.get(pos + 8..end)?.to_vec(), pos + 8 + len.div_ceil(8) * 8))
    };
    let mut out = Vec::new();
    let mut pos = 128;
    let truncated = |what: String| MatReadError::Format(format!("truncated or damaged file: {what}"));
    while pos < plain.len() {
        let (Some(ty), Some(len)) = (u32_at(plain, pos), u32_at(plain, pos + 4)) else {
            return Err(truncated(format!("{} stray bytes after the last element", plain.len() - pos)));
        };
        let len = len as usize;
        let Some(body) = plain.get(pos + 8..(pos + 8).saturating_add(len)) else {
            return Err(truncated(format!(
                "the element at byte {pos} claims {len} bytes, {} remain",
                plain.len().saturating_sub(pos + 8)
            )));
        };
        if ty == MI_MATRIX {
            let parsed = (|| {
                let (flags, next) = sub(body, 0)?;
                // the class is the low byte of the first flags word, in the file's byte order
                let class = if big { *flags.get(3)? } else { *flags.first()? };
                let (_, next) = sub(body, next)?; // dimensions
                let (name, _) = sub(body, next)?;
                Some((String::from_utf8_lossy(&name).into_owned(), class))
            })();
            out.extend(parsed);
        }
        pos += 8 + len.div_ceil(8) * 8;
    }
    Ok(out)
}

/// A MATLAB array class as the error messages name it.
fn class_name(class: u8) -> String {
    match class {
        1 => "a cell array".into(),
        2 => "a struct".into(),
        3 => "an object".into(),
        MX_CHAR_CLASS => "a char array (text)".into(),
        5 => "a sparse matrix".into(),
        16 => "a function handle".into(),
        17 => "an opaque object (a string, table or class instance)".into(),
        7 => "a single-precision array".into(),
        8..=15 => {
            let names = ["int8", "uint8", "int16", "uint16", "int32", "uint32", "int64", "uint64"];
            let name = names[usize::from(class - 8)];
            format!("{} {name} array", if name.starts_with('i') { "an" } else { "a" })
        }
        c => format!("of MATLAB array class {c}"),
    }
}

/// The real part as f64, or None when the data are complex.
fn real_f64(d: &matfile::NumericData) -> Option<Vec<f64>> {
    use matfile::NumericData as N;
    fn conv<T: Copy + Into<f64>, U>(real: &[T], imag: &Option<Vec<U>>) -> Option<Vec<f64>> {
        imag.is_none().then(|| real.iter().map(|&x| x.into()).collect())
    }
    match d {
        N::Double { real, imag } => conv(real, imag),
        N::Single { real, imag } => conv(real, imag),
        N::Int8 { real, imag } => conv(real, imag),
        N::UInt8 { real, imag } => conv(real, imag),
        N::Int16 { real, imag } => conv(real, imag),
        N::UInt16 { real, imag } => conv(real, imag),
        N::Int32 { real, imag } => conv(real, imag),
        N::UInt32 { real, imag } => conv(real, imag),
        // 64-bit integers above 2^53 would not be exact; MATLAB users have no reason for them here.
        N::Int64 { real, imag } => imag.is_none().then(|| real.iter().map(|&x| x as f64).collect()),
        N::UInt64 { real, imag } => imag.is_none().then(|| real.iter().map(|&x| x as f64).collect()),
    }
}

/// The first character variable called `name` (uncompressed `mxCHAR_CLASS`, as MATLAB's `save`
/// without compression and `scipy.io.savemat` write it), if any. Best effort: anything unexpected
/// gives None and the caller falls back to the file stem.
pub(crate) fn read_char_var(bytes: &[u8], wanted: &str) -> Option<String> {
    let u32_at = |i: usize| bytes.get(i..i + 4).map(|b| u32::from_le_bytes([b[0], b[1], b[2], b[3]]));
    if bytes.get(126..128) != Some(b"IM") {
        return None; // big-endian or not level 5: not worth supporting for an optional name
    }
    let mut pos = 128;
    while pos + 8 <= bytes.len() {
        let (ty, len) = (u32_at(pos)?, u32_at(pos + 4)? as usize);
        let body = bytes.get(pos + 8..pos + 8 + len)?;
        if ty == MI_MATRIX {
            if let Some(s) = char_matrix(body, wanted) {
                return Some(s);
            }
        }
        pos += 8 + len.div_ceil(8) * 8;
    }
    None
}

/// Parses one uncompressed miMATRIX body as a 1-row char array named `wanted`.
fn char_matrix(body: &[u8], wanted: &str) -> Option<String> {
    let mut sub = SubElements { b: body, pos: 0 };
    let (_, flags) = sub.next()?;
    if flags.first().copied()? != MX_CHAR_CLASS {
        return None;
    }
    let (_, dims) = sub.next()?;
    if dims.len() != 8 || u32::from_le_bytes(dims[..4].try_into().ok()?) != 1 {
        return None;
    }
    let (_, name) = sub.next()?;
    if name != wanted.as_bytes() {
        return None;
    }
    let (ty, text) = sub.next()?;
    match ty {
        MI_UTF8 | MI_UINT8 => String::from_utf8(text.to_vec()).ok(),
        MI_UINT16 | MI_UTF16 => {
            let units: Vec<u16> = text.chunks_exact(2).map(|c| u16::from_le_bytes([c[0], c[1]])).collect();
            String::from_utf16(&units).ok()
        }
        MI_INT32 | MI_UINT32 | MI_UTF32 => {
            text.chunks_exact(4).map(|c| char::from_u32(u32::from_le_bytes([c[0], c[1], c[2], c[3]]))).collect()
        }
        _ => None,
    }
}

/// Sub-elements of a miMATRIX, in the long or the small (≤ 4 bytes) tag form.
struct SubElements<'a> {
    b: &'a [u8],
    pos: usize,
}

impl<'a> SubElements<'a> {
    fn next(&mut self) -> Option<(u32, &'a [u8])> {
        let tag = u32::from_le_bytes(self.b.get(self.pos..self.pos + 4)?.try_into().ok()?);
        if tag >> 16 != 0 {
            // small data element: size in the upper half, data in the next 4 bytes
            let (ty, len) = (tag & 0xffff, (tag >> 16) as usize);
            let data = self.b.get(self.pos + 4..self.pos + 4 + len)?;
            self.pos += 8;
            return Some((ty, data));
        }
        let len = u32::from_le_bytes(self.b.get(self.pos + 4..self.pos + 8)?.try_into().ok()?) as usize;
        let data = self.b.get(self.pos + 8..self.pos + 8 + len)?;
        self.pos += 8 + len.div_ceil(8) * 8;
        Some((tag, data))
    }
}

// Level-5 data types and array classes used here (MAT-File Format, tables 1-2 and 1-3).
const MI_INT8: u32 = 1;
const MI_UINT8: u32 = 2;
const MI_UINT16: u32 = 4;
const MI_INT32: u32 = 5;
const MI_UINT32: u32 = 6;
const MI_DOUBLE: u32 = 9;
const MI_MATRIX: u32 = 14;
const MI_UTF8: u32 = 16;
const MI_UTF16: u32 = 17;
const MI_UTF32: u32 = 18;
const MX_CHAR_CLASS: u8 = 4;
const MX_DOUBLE_CLASS: u8 = 6;
const MX_UINT64_CLASS: u8 = 15;

/// Writes `vars` (name, matrix) as a level-5 MAT-file (see the module docs). Names must be valid
/// MATLAB identifiers (the callers' names are fixed ones such as `AK`).
pub fn write_mat(vars: &[(&str, MatRef<'_, f64>)], description: &str) -> Vec<u8> {
    let mut out = Vec::new();
    // Header: 116 bytes of text, 8 bytes of subsystem offset, version 0x0100, endian "IM".
    let mut text = format!("MATLAB 5.0 MAT-file, {description}").into_bytes();
    text.truncate(116);
    text.resize(116, b' ');
    out.extend_from_slice(&text);
    out.extend_from_slice(&[0u8; 8]);
    out.extend_from_slice(&0x0100u16.to_le_bytes());
    out.extend_from_slice(b"IM");
    for (name, m) in vars {
        let mut body = Vec::new();
        // Array flags: class double, no complex/global/logical bits.
        element(&mut body, MI_UINT32, &[MX_DOUBLE_CLASS as u32, 0].map(u32::to_le_bytes).concat());
        let dims = [m.nrows() as i32, m.ncols() as i32].map(i32::to_le_bytes).concat();
        element(&mut body, MI_INT32, &dims);
        element(&mut body, MI_INT8, name.as_bytes());
        let v = MatVar::from_mat(*m);
        let re: Vec<u8> = v.data.iter().flat_map(|x| x.to_le_bytes()).collect();
        element(&mut body, MI_DOUBLE, &re);
        element(&mut out, MI_MATRIX, &body);
    }
    out
}

/// Appends one data element (8-byte tag, data, padding to a multiple of 8).
fn element(out: &mut Vec<u8>, ty: u32, data: &[u8]) {
    out.extend_from_slice(&ty.to_le_bytes());
    out.extend_from_slice(&(data.len() as u32).to_le_bytes());
    out.extend_from_slice(data);
    out.resize(out.len() + (8 - data.len() % 8) % 8, 0);
}

/// A variable as a JSON array of rows.
pub(crate) fn var_to_json(v: &MatVar) -> Value {
    Value::Array(
        (0..v.rows).map(|i| Value::Array((0..v.cols).map(|j| json_number(v.data[i + j * v.rows])).collect())).collect(),
    )
}

/// A variable meant as a scalar (such as a sampling time `Ts`) as JSON: a number when it is 1×1
/// and finite, else its array of rows (or, non-finite, its text), which the JSON checks then
/// reject with the file's field named.
pub(crate) fn scalar_var_to_json(v: &MatVar) -> Value {
    match v.data.as_slice() {
        [x] if x.is_finite() => json_number(*x),
        [x] => Value::String(x.to_string()),
        _ => var_to_json(v),
    }
}

pub(crate) fn json_number(x: f64) -> Value {
    serde_json::Number::from_f64(x).map(Value::Number).expect("finite values were checked")
}

/// Whether a path names a MAT-file (extension `.mat`, any case).
pub fn is_mat_path(path: &Path) -> bool {
    path.extension().is_some_and(|e| e.eq_ignore_ascii_case("mat"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn writer_output_reads_back_bit_for_bit() {
        let a = Mat::from_fn(3, 2, |i, j| (i as f64 + 1.0) / (j as f64 + 3.0) - 1e-300);
        let e = Mat::<f64>::zeros(2, 0);
        let bytes = write_mat(&[("A", a.as_ref()), ("E", e.as_ref())], "test");
        assert_eq!(&bytes[126..128], b"IM");
        let vars = read_mat_vars(&bytes).unwrap();
        let back = vars["A"].to_mat();
        assert_eq!((back.nrows(), back.ncols()), (3, 2));
        for i in 0..3 {
            for j in 0..2 {
                assert_eq!(back[(i, j)].to_bits(), a[(i, j)].to_bits());
            }
        }
        assert_eq!((vars["E"].rows, vars["E"].cols), (2, 0));
    }

    #[test]
    fn garbage_is_a_format_error() {
        let e = read_mat_vars(&[7u8; 300]).unwrap_err();
        assert!(matches!(e, MatReadError::Format(_)), "{e}");
        assert!(matches!(read_mat_vars(b"short").unwrap_err(), MatReadError::Format(_)));
    }
}
