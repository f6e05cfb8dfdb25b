//! How much of a job's optimiser iterations its trace keeps: the trace level ([`TraceLevel`],
//! campaign key `trace`, `campaign run --trace`), which names an observer mode of the trace
//! writer ([`TraceLevel::mode`]; the sparse level's thinning is `design`'s
//! [`ObserverMode::Sparse`]).
//!
//! The level is not a design option: it is carried by the campaign model to the trace observer
//! factory ([`crate::campaign::execution::trace::trace_observers`]), never enters a job id and changes no result.

use crate::design::ObserverMode;

/// How much of the optimiser's iterations a job's trace keeps.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize, clap::ValueEnum)]
#[serde(rename_all = "lowercase")]
pub enum TraceLevel {
    /// What the summary, `campaign trace` and the convergence figure need
    /// ([`ObserverMode::Sparse`]).
    #[default]
    Sparse,
    /// Every iteration.
    Full,
    /// No trace file.
    Off,
}

impl TraceLevel {
    /// The name used in campaign files and on the command line.
    pub fn name(self) -> &'static str {
        match self {
            TraceLevel::Sparse => "sparse",
            TraceLevel::Full => "full",
            TraceLevel::Off => "off",
        }
    }

    /// The trace writer's observer mode: [`ObserverMode::Sparse`], [`ObserverMode::Always`];
    /// `None` for no trace.
    pub fn mode(self) -> Option<ObserverMode> {
        match self {
            TraceLevel::Sparse => Some(ObserverMode::Sparse),
            TraceLevel::Full => Some(ObserverMode::Always),
            TraceLevel::Off => None,
        }
    }
}

/// From its name; anything else — another word, or another type (`trace = true`, which TOML's
/// enum reading called "wanted string or table" without the key's values) — is an error that
/// lists the three names.
impl<'de> serde::Deserialize<'de> for TraceLevel {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Names;
        impl serde::de::Visitor<'_> for Names {
            type Value = TraceLevel;
            fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
                f.write_str("one of \"sparse\", \"full\", \"off\"")
            }
            fn visit_str<E: serde::de::Error>(self, v: &str) -> Result<TraceLevel, E> {
                [TraceLevel::Sparse, TraceLevel::Full, TraceLevel::Off]
                    .into_iter()
                    .find(|l| l.name() == v)
                    .ok_or_else(|| E::invalid_value(serde::de::Unexpected::Str(v), &self))
            }
        }
        d.deserialize_any(Names)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn level_names_parse_as_in_campaign_files() {
        for level in [TraceLevel::Sparse, TraceLevel::Full, TraceLevel::Off] {
            let v: TraceLevel = serde_json::from_value(serde_json::json!(level.name())).unwrap();
            assert_eq!(v, level);
        }
        assert_eq!(TraceLevel::default(), TraceLevel::Sparse);
        for bad in [serde_json::json!(true), serde_json::json!("verbose"), serde_json::json!(1)] {
            let e = serde_json::from_value::<TraceLevel>(bad.clone()).unwrap_err().to_string();
            assert!(e.contains(r#"one of "sparse", "full", "off""#), "{bad}: {e}");
        }
    }
}
