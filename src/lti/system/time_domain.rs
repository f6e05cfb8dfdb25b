//! Continuous or discrete time: the domain of a plant, a controller and their closed loop
//! (docs/ALGORITHMS.md §10).
//!
//! A plant or controller file states its domain by the key `Ts` (a `Ts` variable in a MAT-file):
//! absent or 0 is continuous time (x' = Ax + Bu), a finite Ts > 0 is discrete time with sampling
//! time Ts seconds (x⁺ = Ax + Bu). Everything that depends on the domain asks this type:
//! stability is α(A) < 0 or ρ(A) < 1, the H∞ norm is a supremum over the imaginary axis or over
//! the unit circle, and a discrete frequency θ (rad/sample) is θ/Ts rad/s up to the Nyquist
//! frequency π/Ts.

use std::f64::consts::PI;
use std::fmt;

/// The time domain of a system.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum TimeDomain {
    /// Continuous time (`Ts` absent or 0).
    #[default]
    Continuous,
    /// Discrete time with sampling time `ts` > 0 seconds.
    Discrete {
        /// Sampling time in seconds (finite, > 0).
        ts: f64,
    },
}

/// Smallest sampling time accepted (seconds): the smallest magnitude a plant's entries may
/// have (`MIN_PLANT_MAGNITUDE`). Outside [`MIN_TS`, `MAX_TS`] frequencies in rad/s (θ/Ts up to
/// the Nyquist frequency π/Ts) leave the range where a frequency grid, a plot axis or a printed
/// frequency can be formed (Ts = 5e-324 made π/Ts infinite and the σ-plot's axis NaN).
pub const MIN_TS: f64 = crate::lti::io::matrix_json::MIN_PLANT_MAGNITUDE;
/// Largest sampling time accepted (seconds): the largest magnitude of a plant's entries
/// (`MAX_PLANT_MAGNITUDE`); see [`MIN_TS`].
pub const MAX_TS: f64 = crate::lti::io::matrix_json::MAX_PLANT_MAGNITUDE;

/// What is wrong with a sampling time.
#[derive(Debug, Clone, Copy, PartialEq, thiserror::Error)]
#[error(
    "must be 0 (continuous time) or a number of seconds from {MIN_TS:e} to {MAX_TS:e} (the magnitude limits of a \
     plant's entries), found {}",
    crate::numeric::readable(*.0)
)]
pub struct BadSamplingTime(pub f64);

impl TimeDomain {
    /// The domain of a file's `Ts`: 0 is continuous time, Ts in [[`MIN_TS`], [`MAX_TS`]] discrete
    /// time; anything else (negative, NaN, infinite, subnormal, out of that range) is an error. (python-control's `dt = True`, "discrete with
    /// unspecified sampling time", has no file form here: a sampling time must be given.)
    pub fn from_ts(ts: f64) -> Result<Self, BadSamplingTime> {
        if ts == 0.0 {
            Ok(TimeDomain::Continuous)
        } else if (MIN_TS..=MAX_TS).contains(&ts) {
            Ok(TimeDomain::Discrete { ts })
        } else {
            Err(BadSamplingTime(ts))
        }
    }

    /// The domain of a file's optional `Ts` value (a number; absent, `null` or 0: continuous
    /// time); the error says what is wrong with it.
    pub(crate) fn from_json(v: Option<&serde_json::Value>) -> Result<Self, String> {
        match v {
            None | Some(serde_json::Value::Null) => Ok(TimeDomain::Continuous),
            Some(x) => match x.as_f64() {
                Some(ts) => TimeDomain::from_ts(ts).map_err(|e| e.to_string()),
                None => Err(format!("must be a number of seconds (0: continuous time), found {x}")),
            },
        }
    }

    /// The sampling time, `None` in continuous time.
    pub fn ts(self) -> Option<f64> {
        match self {
            TimeDomain::Continuous => None,
            TimeDomain::Discrete { ts } => Some(ts),
        }
    }

    /// The sampling time, 0 in continuous time (the convention of python-control's `dt` and of
    /// MATLAB's `Ts`).
    pub fn ts_or_zero(self) -> f64 {
        self.ts().unwrap_or(0.0)
    }

    /// Whether this is discrete time.
    pub fn is_discrete(self) -> bool {
        matches!(self, TimeDomain::Discrete { .. })
    }

    /// A frequency of the domain's own norm routines in rad/s: ω itself in continuous time, θ/Ts
    /// for θ in rad/sample in discrete time.
    pub fn to_rad_per_s(self, freq: f64) -> f64 {
        match self {
            TimeDomain::Continuous => freq,
            TimeDomain::Discrete { ts } => freq / ts,
        }
    }

    /// A frequency in rad/s as the domain's norm routines take it: ω in continuous time, θ = ω·Ts
    /// rad/sample in discrete time.
    pub fn from_rad_per_s(self, w: f64) -> f64 {
        match self {
            TimeDomain::Continuous => w,
            TimeDomain::Discrete { ts } => w * ts,
        }
    }

    /// The symbol of the domain's stability measure (`lti::stability_measure`) in messages and
    /// reports: "α" (the spectral abscissa) or "ρ − 1" (the spectral radius less 1).
    pub fn stability_symbol(self) -> &'static str {
        match self {
            TimeDomain::Continuous => "α",
            TimeDomain::Discrete { .. } => "ρ − 1",
        }
    }

    /// What a stability measure s (`lti::stability_measure`) stands for, as printed: ("α", s) in
    /// continuous time, ("ρ", s + 1) in discrete time (the spectral radius itself).
    pub fn stability_quantity(self, measure: f64) -> (&'static str, f64) {
        match self {
            TimeDomain::Continuous => ("α", measure),
            TimeDomain::Discrete { .. } => ("ρ", measure + 1.0),
        }
    }

    /// The Nyquist frequency π/Ts in rad/s (discrete time), the end of a discrete system's
    /// frequency axis; `None` in continuous time.
    pub fn nyquist(self) -> Option<f64> {
        self.ts().map(|ts| PI / ts)
    }
}

/// "continuous time" or "discrete time (Ts = 0.01 s)" (Ts as `numeric::readable` prints it:
/// "1e-40", not forty zeros).
impl fmt::Display for TimeDomain {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            TimeDomain::Continuous => write!(f, "continuous time"),
            TimeDomain::Discrete { ts } => write!(f, "discrete time (Ts = {} s)", crate::numeric::readable(*ts)),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sampling_times() {
        assert_eq!(TimeDomain::from_ts(0.0), Ok(TimeDomain::Continuous));
        assert_eq!(TimeDomain::from_ts(0.1), Ok(TimeDomain::Discrete { ts: 0.1 }));
        for bad in [-0.1, f64::NAN, f64::INFINITY, 5e-324, 1e-51, 1e51, f64::MAX] {
            assert!(TimeDomain::from_ts(bad).is_err(), "{bad}");
        }
        for good in [MIN_TS, MAX_TS] {
            assert_eq!(TimeDomain::from_ts(good), Ok(TimeDomain::Discrete { ts: good }));
        }
        assert_eq!(TimeDomain::Discrete { ts: 1e-40 }.to_string(), "discrete time (Ts = 1e-40 s)");
        let e = TimeDomain::from_ts(5e-324).unwrap_err().to_string();
        assert!(e.contains("found 5e-324") && e.contains("1e-50"), "{e}");
        let d = TimeDomain::Discrete { ts: 0.5 };
        assert_eq!(d.to_rad_per_s(PI), 2.0 * PI);
        assert_eq!(d.from_rad_per_s(2.0 * PI), PI);
        assert_eq!(d.nyquist(), Some(2.0 * PI));
        assert_eq!(TimeDomain::Continuous.nyquist(), None);
        assert_eq!(d.to_string(), "discrete time (Ts = 0.5 s)");
        assert_eq!(
            (d.stability_quantity(-0.25), TimeDomain::Continuous.stability_quantity(-0.25)),
            (("ρ", 0.75), ("α", -0.25))
        );
    }
}
