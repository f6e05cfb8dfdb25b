//! JSON has no infinity or NaN: floats that may be non-finite (γ of an unstable loop is +∞) are
//! written as the strings "inf", "-inf", "nan" and read back from either form.
//!
//! This is the one serialisation path of every `f64` the program writes to a journal, a trace
//! or an outcome: each such field carries `#[serde(with = "serde_f64_or_string")]` (or
//! [`serde_opt_f64_or_string`] for an `Option<f64>`). Readers also accept `null` as NaN, which
//! is what serde_json wrote for a non-finite number before every field went through here, so
//! journals written by older builds stay readable.

use serde::{Deserialize, Deserializer, Serializer};

/// Reads one float in any of the accepted forms (`None` for JSON `null`).
#[derive(Deserialize)]
#[serde(untagged)]
enum NumOrStr {
    Num(f64),
    Str(String),
}

fn from_str_form<E: serde::de::Error>(s: &str) -> Result<f64, E> {
    match s {
        "inf" | "+inf" | "Infinity" => Ok(f64::INFINITY),
        "-inf" | "-Infinity" => Ok(f64::NEG_INFINITY),
        "nan" | "NaN" => Ok(f64::NAN),
        other => Err(E::custom(format!("expected a number, \"inf\", \"-inf\" or \"nan\", found {other:?}"))),
    }
}

fn read_opt<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
    match Option::<NumOrStr>::deserialize(d)? {
        None => Ok(None),
        Some(NumOrStr::Num(x)) => Ok(Some(x)),
        Some(NumOrStr::Str(s)) => from_str_form(&s).map(Some),
    }
}

/// The text of a float in every file the program writes (JSON strings, CSV cells): a finite
/// value as Rust prints it (shortest round-trip form), others as "inf", "-inf", "nan".
pub fn f64_text(x: f64) -> String {
    if x.is_finite() {
        format!("{x}")
    } else {
        non_finite_word(x).to_string()
    }
}

fn non_finite_word(x: f64) -> &'static str {
    if x.is_nan() {
        "nan"
    } else if x > 0.0 {
        "inf"
    } else {
        "-inf"
    }
}

/// `#[serde(with = "serde_f64_or_string")]` for an `f64` that may be non-finite.
pub mod serde_f64_or_string {
    use super::*;

    /// Finite values as numbers, others as "inf" / "-inf" / "nan".
    pub fn serialize<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
        if x.is_finite() {
            s.serialize_f64(*x)
        } else {
            s.serialize_str(non_finite_word(*x))
        }
    }

    /// Accepts a number, one of the strings, or `null` (read as NaN: older journals).
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        Ok(read_opt(d)?.unwrap_or(f64::NAN))
    }
}

/// `#[serde(default, with = "serde_opt_f64_or_string")]` for an `Option<f64>` whose value may be
/// non-finite: `None` is `null`, `Some(x)` is written as [`serde_f64_or_string`] writes `x`.
pub mod serde_opt_f64_or_string {
    use super::*;

    /// `None` → null, `Some(x)` → number or "inf" / "-inf" / "nan".
    pub fn serialize<S: Serializer>(x: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
        match x {
            None => s.serialize_none(),
            Some(x) => serde_f64_or_string::serialize(x, s),
        }
    }

    /// null → `None`; a number or one of the strings → `Some`.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Option<f64>, D::Error> {
        read_opt(d)
    }
}

/// `#[serde(default, with = "serde_vec_f64_or_string")]` for a `Vec<f64>`: each element as
/// [`serde_f64_or_string`] writes it (and reads it, `null` as NaN).
pub(crate) mod serde_vec_f64_or_string {
    use super::*;
    use serde::ser::SerializeSeq;

    /// A JSON array of numbers or "inf" / "-inf" / "nan".
    pub(crate) fn serialize<S: Serializer>(xs: &[f64], s: S) -> Result<S::Ok, S::Error> {
        let mut seq = s.serialize_seq(Some(xs.len()))?;
        for x in xs {
            seq.serialize_element(&super::f64_to_json(*x))?;
        }
        seq.end()
    }

    /// An array whose elements are numbers, one of the strings, or `null` (NaN).
    pub(crate) fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<f64>, D::Error> {
        let raw = Vec::<Option<NumOrStr>>::deserialize(d)?;
        raw.into_iter()
            .map(|v| match v {
                None => Ok(f64::NAN),
                Some(NumOrStr::Num(x)) => Ok(x),
                Some(NumOrStr::Str(s)) => from_str_form(&s),
            })
            .collect()
    }
}

/// A float as a JSON value in the same convention: finite → number, else "inf" / "-inf" / "nan".
pub fn f64_to_json(x: f64) -> serde_json::Value {
    serde_f64_or_string::serialize(&x, serde_json::value::Serializer).unwrap_or(serde_json::Value::Null)
}

/// Reads a float written by [`f64_to_json`] (anything else, e.g. null, reads as NaN).
pub fn f64_from_json(v: &serde_json::Value) -> f64 {
    match v {
        serde_json::Value::Number(n) => n.as_f64().unwrap_or(f64::NAN),
        serde_json::Value::String(s) => from_str_form::<serde_json::Error>(s).unwrap_or(f64::NAN),
        _ => f64::NAN,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde::Serialize;

    #[derive(Debug, Serialize, Deserialize)]
    struct T {
        #[serde(with = "serde_f64_or_string")]
        x: f64,
        #[serde(default, with = "serde_opt_f64_or_string")]
        y: Option<f64>,
    }

    #[test]
    fn non_finite_round_trip_and_null_reads_as_nan() {
        for v in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN, 1e300, -0.5] {
            let s = serde_json::to_string(&T { x: v, y: Some(v) }).unwrap();
            assert!(!s.contains("null"), "{s}");
            let t: T = serde_json::from_str(&s).unwrap();
            assert!(t.x == v || (t.x.is_nan() && v.is_nan()), "{s}");
            assert!(t.y == Some(v) || (t.y.unwrap().is_nan() && v.is_nan()), "{s}");
        }
        let t: T = serde_json::from_str(r#"{"x": null, "y": null}"#).unwrap();
        assert!(t.x.is_nan() && t.y.is_none());
        let t: T = serde_json::from_str(r#"{"x": 1}"#).unwrap();
        assert_eq!((t.x, t.y), (1.0, None));
        assert!(serde_json::from_str::<T>(r#"{"x": "fast"}"#).unwrap_err().to_string().contains("fast"));
        assert_eq!(serde_json::to_string(&T { x: 1.0, y: None }).unwrap(), r#"{"x":1.0,"y":null}"#);
    }
}
