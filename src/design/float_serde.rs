//! JSON has no infinity or NaN: floats that may be non-finite (γ of an unstable loop is +∞) are
//! written as the strings "inf", "-inf", "nan" and read back from either form.

use serde::{Deserialize, Deserializer, Serializer};

/// `#[serde(with = "serde_f64_or_string")]` for an `f64` that may be non-finite.
pub mod serde_f64_or_string {
    use super::*;

    /// Finite values as numbers, others as "inf" / "-inf" / "nan".
    pub fn serialize<S: Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
        if x.is_finite() {
            s.serialize_f64(*x)
        } else if x.is_nan() {
            s.serialize_str("nan")
        } else if *x > 0.0 {
            s.serialize_str("inf")
        } else {
            s.serialize_str("-inf")
        }
    }

    /// Accepts a number or one of the three strings.
    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<f64, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum NumOrStr {
            Num(f64),
            Str(String),
        }
        match NumOrStr::deserialize(d)? {
            NumOrStr::Num(x) => Ok(x),
            NumOrStr::Str(s) => match s.as_str() {
                "inf" | "Infinity" => Ok(f64::INFINITY),
                "-inf" | "-Infinity" => Ok(f64::NEG_INFINITY),
                "nan" | "NaN" => Ok(f64::NAN),
                other => Err(serde::de::Error::custom(format!("expected a number, \"inf\", \"-inf\" or \"nan\", found {other:?}"))),
            },
        }
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
        serde_json::Value::String(s) => match s.as_str() {
            "inf" => f64::INFINITY,
            "-inf" => f64::NEG_INFINITY,
            _ => f64::NAN,
        },
        _ => f64::NAN,
    }
}
