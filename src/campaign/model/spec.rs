//! The campaign file (TOML): a name, defaults, and a list of problems. The format is documented
//! with a full example in `campaigns/FORMAT.md`.
//!
//! Every unknown key, wrong type and impossible value is a [`SpecError`] naming the file, line and
//! column (toml 1.x gives byte spans; values that are checked after parsing are read as
//! [`toml::Spanned`] so their position is known).
//!
//! Resolution rules: a plant that is a bare name (`HE1`) is looked up in the plant library
//! ([`crate::lti::resolve_plant`]); a relative path (contains `/` or ends in `.json`) is relative
//! to the campaign file's folder. Per-problem keys override `[defaults]`, which override
//! [`DesignOptions::default`].
//!
//! A problem names one plant (`plant`) or several (`plants`, one controller for all), each with
//! its objective, weight and bound (`objectives`, `weights`, `bounds`: one value for every plant
//! or a list of one per plant), and optionally a controller structure (`structure`); these keys
//! are per problem only. Their values are judged by `design::Problem::validate` and
//! `design::Structure::load` before any job starts.

use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::Deserialize;
use toml::Spanned;

pub use super::campaign::{Campaign, Location, Problem, ProblemStructure, DEFAULT_THREADS};
use super::jobs::{problem_fingerprint, ProblemKey};
use crate::campaign::leaves::trace_filter::TraceLevel;
use crate::design::{
    ControllerShape, DesignOptions, OptionValue, PlantObjective, PlantTerm, ProblemError, Structure, StructureError,
    UnknownObjective,
};
use crate::lti::Plant;

/// Largest controller order accepted in a campaign file (a typo guard, far above the paper's 8).
pub const MAX_ORDER: usize = 200;
/// Largest number of seeds of one problem (`seeds = N` or a list).
pub const MAX_SEEDS: usize = 10_000;
/// Largest number of jobs a campaign file may expand to.
pub const MAX_JOBS: usize = 100_000;
/// Largest `threads` (as on the command line).
pub const MAX_THREADS: usize = 256;
/// Longest campaign name, in characters (it names the results folder).
pub const MAX_NAME_CHARS: usize = 100;

fn location_suffix(l: &Location) -> String {
    if l.line == 0 {
        String::new()
    } else {
        format!(":{}:{}", l.line, l.column)
    }
}

/// A campaign file that cannot be used: where and why.
/// Displayed as `file:line:column: message`, or `file: message` when the error has no position
/// in the file (it could not be read: line 0).
#[derive(Debug, thiserror::Error)]
#[error("{}{}: {message}", file.display(), location_suffix(location))]
pub struct SpecError {
    /// The campaign file.
    pub file: PathBuf,
    /// Where in it.
    pub location: Location,
    /// What is wrong.
    pub message: SpecProblem,
}

/// What is wrong in a campaign file: the message of a [`SpecError`].
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SpecProblem {
    /// The file could not be read.
    #[error("cannot read the campaign file: {0}")]
    Read(std::io::Error),
    /// Not TOML, an unknown key or a value of the wrong type (toml's message, its serde jargon
    /// in the project's words: `plain_words`).
    #[error("{}", plain_words(.0.message().trim()))]
    Toml(Box<toml::de::Error>),
    /// The campaign name is longer than [`MAX_NAME_CHARS`].
    #[error("campaign name is longer than {MAX_NAME_CHARS} characters")]
    NameTooLong,
    /// The campaign name (given) cannot name a folder.
    #[error("campaign name {0:?} must be non-empty, use only letters, digits, '-', '_' and '.', and not begin with '.' (it names the results folder)")]
    BadName(String),
    /// `threads` (given) outside 1..=[`MAX_THREADS`].
    #[error("threads must be in 1..={MAX_THREADS}, found {0}")]
    Threads(usize),
    /// No `[[problem]]`.
    #[error("the campaign has no [[problem]] entries")]
    NoProblems,
    /// `eps = []`.
    #[error("eps must list at least one weight")]
    NoEps,
    /// A weight listed twice.
    #[error("eps lists the same weight twice")]
    RepeatedEps,
    /// `seeds = []`.
    #[error("seeds must list at least one seed")]
    NoSeeds,
    /// A negative seed (given).
    #[error("seeds must be non-negative integers, found {0}")]
    NegativeSeed(i64),
    /// A seed listed twice.
    #[error("seeds lists the same seed twice")]
    RepeatedSeed,
    /// `orders = []`.
    #[error("orders must list at least one controller order")]
    NoOrders,
    /// An order (given) outside 0..=[`MAX_ORDER`].
    #[error("controller orders must be integers in 0..={MAX_ORDER}, found {0}")]
    OrderOutOfRange(i64),
    /// An order listed twice.
    #[error("orders lists the same order twice")]
    RepeatedOrder,
    /// `plant = ""`.
    #[error("plant must name a plant (e.g. \"HE1\") or a plant file")]
    NoPlant,
    /// A plant path that is no file (why).
    #[error("plant file {} {why}", path.display())]
    NotAFile {
        /// The path, resolved against the campaign file's folder.
        path: PathBuf,
        /// What it is instead (`crate::input::not_a_file`).
        why: String,
    },
    /// The plant could not be found or loaded.
    #[error("{0}")]
    Plant(Box<crate::lti::PlantError>),
    /// A `[[problem]]` with neither `plant` nor `plants`.
    #[error("a [[problem]] needs plant = \"…\" (one plant) or plants = [\"…\", …] (several plants, one controller)")]
    MissingPlant,
    /// Both `plant` and `plants`.
    #[error("give either plant (one plant) or plants (a list), not both")]
    PlantAndPlants,
    /// `plants = []`.
    #[error("plants must list at least one plant")]
    NoPlants,
    /// A per-plant list (`objectives`, `weights`, `bounds`) of another length than `plants`.
    #[error(
        "{key} lists {found} values for {plants} plants: give one value for every plant, or a list of one per plant"
    )]
    PerPlantLength {
        /// The key.
        key: &'static str,
        /// Its number of values.
        found: usize,
        /// The number of plants.
        plants: usize,
    },
    /// An objective name that is not hinf, h2, abscissa or radius.
    #[error("objectives: {0}")]
    UnknownObjective(UnknownObjective),
    /// A bound that is a string other than "none".
    #[error("bounds: {0:?} is not a number or \"none\"")]
    BadBound(String),
    /// The plants, objectives, weights and bounds as `design::Problem::validate` judges them.
    #[error("{key}: {source}")]
    Problem {
        /// The key the error is about (`plants`, `objectives`, `weights`, `bounds`).
        key: &'static str,
        /// Why.
        source: Box<ProblemError>,
    },
    /// `name` empty, or given to a single-plant H∞ problem without a structure (which is named by
    /// its plant).
    #[error("name must be non-empty, and is for a problem of several plants, another objective, weight or bound, or a structure (a single plant is named by its plant file)")]
    BadProblemName,
    /// The structure file does not load, or does not fit an order of the problem.
    #[error("{0}")]
    Structure(Box<StructureError>),
    /// The problem's design options, as `design::validate` judges them.
    #[error("{0}")]
    Options(Box<crate::design::DesignError>),
    /// More than [`MAX_JOBS`] jobs.
    #[error("the campaign expands to more than {MAX_JOBS} jobs (orders × eps × seeds, summed over problems)")]
    TooManyJobs,
    /// A problem is an earlier problem (same plants, objectives, weights, bounds and structure:
    /// one fingerprint, one row per order and objective in the report) under another name.
    #[error(
        "this problem is the problem at line {first_line} under another name ({name:?}, there {first_name:?}): their \
         jobs share the report's rows, which carry one name; give both the same name"
    )]
    RenamedProblem {
        /// The line of the earlier problem.
        first_line: usize,
        /// Its name.
        first_name: String,
        /// This problem's name.
        name: String,
    },
    /// A problem makes a job an earlier problem makes.
    #[error("this problem repeats a job of the problem at line {first_line} (plant {plant}, order {order}, ε {eps}, seed {seed})")]
    RepeatedJob {
        /// The line of the earlier problem.
        first_line: usize,
        /// The plant's name.
        plant: String,
        /// The job's order.
        order: usize,
        /// Its ε.
        eps: f64,
        /// Its seed.
        seed: u64,
    },
}

// ---------------------------------------------------------------------------------------------
// Raw (serde) form

/// The campaign's design settings come from the option table
/// ([`crate::design::design_option_table!`], in design/options.rs): this callback declares the
/// raw tables `[defaults]` and `[[problem]]` and their layering ([`Layered`]) with one key per
/// option marked `key layered` there, after the campaign's own settings given as its arguments
/// (`key: type`). A new design option thus becomes a campaign key, with its span for errors,
/// without a line here.
macro_rules! campaign_settings {
    ({ $($args:tt)* } $($entries:tt)*) => {
        campaign_settings!(@walk { $($args)* } [] $($entries)*);
    };
    // keep the layered options as `field: the type of its setting`
    (@walk $args:tt [$($keep:tt)*]
        $(#[$attr:meta])* $field:ident : $ty:ty = $default:expr, key layered, flag $flag:literal,
        accepts $accepts:expr, check $check:expr, doc $doc:literal;
        $($rest:tt)*
    ) => {
        campaign_settings!(@walk $args [$($keep)* $field: <$ty as OptionValue>::Setting,] $($rest)*);
    };
    // skip the others (order, eps, seed: lists of jobs, below; options without a key)
    (@walk $args:tt [$($keep:tt)*]
        $(#[$attr:meta])* $field:ident : $ty:ty = $default:expr, key $key:literal, flag $flag:literal,
        accepts $accepts:expr, check $check:expr, doc $doc:literal;
        $($rest:tt)*
    ) => {
        campaign_settings!(@walk $args [$($keep)*] $($rest)*);
    };
    (@walk { $($own:ident : $own_ty:ty,)* } [$($design:ident : $design_ty:ty,)*]) => {
        /// `[defaults]`: the settings, plus the campaign-wide `threads`.
        #[derive(Debug, Default, Deserialize)]
        #[serde(deny_unknown_fields)]
        struct RawDefaults {
            $($own: Option<Spanned<$own_ty>>,)*
            $($design: Option<Spanned<$design_ty>>,)*
            threads: Option<Spanned<usize>>,
        }

        /// One `[[problem]]`: its plant(s), their objectives, weights and bounds, its structure
        /// and orders, then the settings.
        #[derive(Debug, Deserialize)]
        #[serde(deny_unknown_fields)]
        struct RawProblem {
            plant: Option<Spanned<String>>,
            plants: Option<Spanned<Vec<Spanned<String>>>>,
            name: Option<Spanned<String>>,
            objectives: Option<Spanned<PerPlant<String>>>,
            weights: Option<Spanned<PerPlant<Number>>>,
            bounds: Option<Spanned<PerPlant<BoundValue>>>,
            structure: Option<Spanned<String>>,
            orders: Spanned<Orders>,
            #[serde(default)]
            warm_start: bool,
            $($own: Option<Spanned<$own_ty>>,)*
            $($design: Option<Spanned<$design_ty>>,)*
        }

        /// Step 3a: the settings of one problem, each from the `[[problem]]`, else from
        /// `[defaults]` (else, in [`Layered::options`], from [`DesignOptions::default`]), with
        /// the span of the value used.
        struct Layered {
            $($own: Setting<$own_ty>,)*
            $($design: Setting<$design_ty>,)*
        }

        impl Layered {
            fn new(p: &RawProblem, d: &RawDefaults) -> Layered {
                Layered {
                    $($own: layer(&p.$own, &d.$own),)*
                    $($design: layer(&p.$design, &d.$design),)*
                }
            }

            /// The options common to the problem's jobs (order, ε and seed are set per job).
            /// Values are only collected here; `design::validate` judges them
            /// ([`check_options`]).
            fn options(&self) -> DesignOptions {
                let mut o = DesignOptions::default();
                $(
                    if let Some((v, _)) = &self.$design {
                        o.$design = OptionValue::from_setting(v.clone());
                    }
                )*
                o
            }

            /// The span of the value behind a `DesignError::Options` field (None: not a
            /// setting, or not given).
            fn span_of(&self, field: &str) -> Option<Range<usize>> {
                match field {
                    $(stringify!($own) => self.$own.as_ref().map(|(_, s)| s.clone()),)*
                    $(stringify!($design) => self.$design.as_ref().map(|(_, s)| s.clone()),)*
                    _ => None,
                }
            }
        }
    };
}

crate::design::design_option_table!(campaign_settings {
    eps: EpsList,
    seeds: Seeds,
    eps_continuation: bool,
    continued_cpumax: f64,
    continued_stall_starts: usize,
    order_chaining: bool,
    // Not a design setting (no `DesignOptions` field, not in the job id); layered alike.
    trace: TraceLevel,
});

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawCampaign {
    name: Spanned<String>,
    #[serde(default)]
    description: String,
    #[serde(default)]
    defaults: RawDefaults,
    #[serde(default, rename = "problem")]
    problems: Vec<RawProblem>,
}

/// A per-plant key: one value for every plant, or a list of one per plant.
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
enum PerPlant<T> {
    One(T),
    List(Vec<T>),
}

/// A number, integers accepted.
#[derive(Debug, Clone, Copy, Deserialize)]
#[serde(untagged)]
enum Number {
    F(f64),
    I(i64),
}

impl Number {
    fn value(self) -> f64 {
        match self {
            Number::F(x) => x,
            Number::I(i) => i as f64,
        }
    }
}

/// A bound: a number, or "none".
#[derive(Debug, Clone, Deserialize)]
#[serde(untagged)]
enum BoundValue {
    Number(Number),
    Text(String),
}

/// `orders = 3`, `orders = [1, 2, 4]` or `orders = { from = 1, to = 8 }` (inclusive).
#[derive(Debug, Clone, PartialEq)]
struct Orders(Vec<i64>);

impl<'de> Deserialize<'de> for Orders {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Orders;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("an order (integer), a list of orders, or a range { from = 1, to = 8 }")
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Orders, E> {
                Ok(Orders(vec![v]))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Orders, E> {
                Ok(Orders(vec![v.min(i64::MAX as u64) as i64]))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Orders, A::Error> {
                let mut v = Vec::new();
                while let Some(x) = seq.next_element::<i64>()? {
                    v.push(x);
                }
                Ok(Orders(v))
            }
            fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<Orders, A::Error> {
                let (mut from, mut to) = (None, None);
                while let Some(key) = map.next_key::<String>()? {
                    match key.as_str() {
                        "from" => from = Some(map.next_value::<i64>()?),
                        "to" => to = Some(map.next_value::<i64>()?),
                        other => return Err(de::Error::unknown_field(other, &["from", "to"])),
                    }
                }
                let from = from.ok_or_else(|| de::Error::missing_field("from"))?;
                let to = to.ok_or_else(|| de::Error::missing_field("to"))?;
                if to < from {
                    return Err(de::Error::custom(format!("empty order range: from = {from} > to = {to}")));
                }
                if from < 0 || to > MAX_ORDER as i64 {
                    return Err(de::Error::custom(format!(
                        "order range {from}..={to} leaves 0..={MAX_ORDER} (controller orders are integers in that range)"
                    )));
                }
                Ok(Orders((from..=to).collect()))
            }
        }
        d.deserialize_any(V)
    }
}

/// `seeds = 10` (seeds 0..9) or `seeds = [1, 7, 42]`.
#[derive(Debug, Clone, PartialEq)]
struct Seeds(Vec<i64>, bool /* given as a count */);

impl<'de> Deserialize<'de> for Seeds {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = Seeds;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a number of seeds (integer) or a list of seeds")
            }
            fn visit_i64<E: de::Error>(self, n: i64) -> Result<Seeds, E> {
                if n < 1 || n > MAX_SEEDS as i64 {
                    return Err(E::custom(format!("the number of seeds must be in 1..={MAX_SEEDS}, found {n}")));
                }
                Ok(Seeds((0..n).collect(), true))
            }
            fn visit_u64<E: de::Error>(self, n: u64) -> Result<Seeds, E> {
                self.visit_i64(n.min(i64::MAX as u64) as i64)
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<Seeds, A::Error> {
                let mut v = Vec::new();
                while let Some(x) = seq.next_element::<i64>()? {
                    if v.len() == MAX_SEEDS {
                        return Err(de::Error::custom(format!("more than {MAX_SEEDS} seeds")));
                    }
                    v.push(x);
                }
                Ok(Seeds(v, false))
            }
        }
        d.deserialize_any(V)
    }
}

/// `eps = 1e-3` or `eps = [1e-2, 1e-3]` (integers accepted as numbers).
#[derive(Debug, Clone, PartialEq)]
struct EpsList(Vec<f64>);

impl<'de> Deserialize<'de> for EpsList {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        #[derive(Deserialize)]
        #[serde(untagged)]
        enum One {
            F(f64),
            I(i64),
        }
        struct V;
        impl<'de> Visitor<'de> for V {
            type Value = EpsList;
            fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
                f.write_str("a weight ε (number) or a list of weights")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<EpsList, E> {
                Ok(EpsList(vec![v]))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<EpsList, E> {
                Ok(EpsList(vec![v as f64]))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<EpsList, E> {
                Ok(EpsList(vec![v as f64]))
            }
            fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<EpsList, A::Error> {
                let mut v = Vec::new();
                while let Some(x) = seq.next_element::<One>()? {
                    v.push(match x {
                        One::F(f) => f,
                        One::I(i) => i as f64,
                    });
                }
                Ok(EpsList(v))
            }
        }
        d.deserialize_any(V)
    }
}

// ---------------------------------------------------------------------------------------------
// Loading and validation: `from_toml_str` runs the steps below in order, each a function with
// one job; every error names the file, line and column of the value at fault.

impl Campaign {
    /// Reads and validates a campaign file.
    pub fn load(path: &Path) -> Result<Campaign, SpecError> {
        let text =
            crate::input::read_capped_string(path, crate::input::MAX_CAMPAIGN_BYTES, "campaign file").map_err(|e| {
                SpecError {
                    file: path.to_path_buf(),
                    location: Location { line: 0, column: 0 },
                    message: SpecProblem::Read(e),
                }
            })?;
        Campaign::from_toml_str(&text, path)
    }

    /// Parses and validates campaign text; `file` names it in errors and anchors relative plant
    /// paths.
    pub fn from_toml_str(text: &str, file: &Path) -> Result<Campaign, SpecError> {
        let src = Source { text, file };
        let raw = parse(&src)?;
        let name = check_name(&raw.name, &src)?;
        let threads = check_threads(raw.defaults.threads.as_ref(), &src)?;
        if raw.problems.is_empty() {
            return Err(src.error(0..0, SpecProblem::NoProblems));
        }
        let base_dir = file.parent().unwrap_or(Path::new("."));
        let problems = raw
            .problems
            .iter()
            .map(|p| resolve_problem(p, &raw.defaults, base_dir, &src))
            .collect::<Result<Vec<_>, _>>()?;
        check_job_count(&problems, &raw.problems, &src)?;
        let campaign = Campaign { name, description: raw.description, file: file.to_path_buf(), threads, problems };
        check_unique_jobs(&campaign)?;
        Ok(campaign)
    }
}

/// The campaign text and its file, for errors at a byte span.
struct Source<'a> {
    text: &'a str,
    file: &'a Path,
}

impl Source<'_> {
    /// An error at the start of `span`.
    fn error(&self, span: Range<usize>, message: SpecProblem) -> SpecError {
        SpecError { file: self.file.to_path_buf(), location: Location::of_offset(self.text, span.start), message }
    }
}

/// A TOML/serde message with the Rust type names it quotes said in words: "data did not match any
/// variant of untagged enum PerPlant" and "expected usize" meant nothing to a campaign author.
fn plain_words(message: &str) -> String {
    const UNTAGGED: &str = "data did not match any variant of untagged enum ";
    const WORDS: [(&str, &str); 7] = [
        (
            "PerPlant",
            "must be one value for every plant or a list of one value per plant (objectives: \"hinf\", \"h2\", \
             \"abscissa\" or \"radius\"; weights: numbers > 0; bounds: numbers or \"none\")",
        ),
        ("BoundValue", "must be a number or \"none\""),
        ("Number", "must be a number"),
        ("Seeds", "must be a count of seeds (a whole number) or a list of seeds"),
        ("One", "must be a number"),
        ("OptionValue", "has a value of the wrong kind"),
        ("", "has a value of the wrong kind"),
    ];
    let mut out = match message.find(UNTAGGED) {
        Some(at) => {
            let name = message[at + UNTAGGED.len()..].split(|c: char| !c.is_alphanumeric()).next().unwrap_or("");
            let words = WORDS.iter().find(|(n, _)| *n == name || n.is_empty()).map_or("", |(_, w)| w);
            format!("{}{words}{}", &message[..at], &message[at + UNTAGGED.len() + name.len()..])
        }
        None => message.to_string(),
    };
    for (rust, words) in [
        ("expected usize", "expected a whole number ≥ 0"),
        ("expected u64", "expected a whole number ≥ 0"),
        ("expected u32", "expected a whole number ≥ 0"),
        ("expected i64", "expected a whole number"),
        ("expected f64", "expected a number"),
        ("expected a sequence", "expected a list [ … ]"),
        ("expected a map", "expected a table { … }"),
    ] {
        out = out.replace(rust, words);
    }
    out
}

/// Step 1: the TOML into the raw tables (unknown keys and wrong types fail here, at their span).
fn parse(src: &Source) -> Result<RawCampaign, SpecError> {
    toml::from_str(src.text).map_err(|e| src.error(e.span().unwrap_or(0..0), SpecProblem::Toml(Box::new(e))))
}

/// Step 2a: the campaign name, which names the results folder.
fn check_name(name: &Spanned<String>, src: &Source) -> Result<String, SpecError> {
    let text = name.get_ref().clone();
    if text.chars().count() > MAX_NAME_CHARS {
        return Err(src.error(name.span(), SpecProblem::NameTooLong));
    }
    if text.is_empty() || !text.chars().all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c)) || text.starts_with('.')
    {
        return Err(src.error(name.span(), SpecProblem::BadName(text)));
    }
    Ok(text)
}

/// Step 2b: `defaults.threads`.
fn check_threads(threads: Option<&Spanned<usize>>, src: &Source) -> Result<Option<usize>, SpecError> {
    match threads {
        Some(t) if !(1..=MAX_THREADS).contains(t.get_ref()) => {
            Err(src.error(t.span(), SpecProblem::Threads(*t.get_ref())))
        }
        Some(t) => Ok(Some(*t.get_ref())),
        None => Ok(None),
    }
}

/// Step 3: one `[[problem]]` — its settings layered over `[defaults]`, its lists checked, its
/// plants loaded and its options judged (for each plant), its plants' objectives, weights and
/// bounds judged, its structure loaded for each order.
fn resolve_problem(p: &RawProblem, d: &RawDefaults, base_dir: &Path, src: &Source) -> Result<Problem, SpecError> {
    let settings = Layered::new(p, d);
    let eps = check_eps(&settings.eps, src)?;
    let seeds = check_seeds(&settings.seeds, src)?;
    let orders = check_orders(&p.orders, src)?;
    let base = settings.options();
    let args = plant_args(p, src)?;
    let mut paths = Vec::with_capacity(args.len());
    let mut plants = Vec::with_capacity(args.len());
    for a in &args {
        let (path, plant) = load_plant(a, base_dir, src)?;
        paths.push(path);
        plants.push(plant);
    }
    for plant in &plants {
        check_options(plant, &base, &orders, &eps, &settings, p, src)?;
    }
    let problem = resolve_terms(p, &args, plants, src)?;
    let plant = problem.first().clone();
    let multi = (!problem.is_single_hinf()).then(|| Arc::new(problem));
    let structure = p.structure.as_ref().map(|s| load_structure(s, &plant, &orders, base_dir, src)).transpose()?;
    let name = problem_name(p, &plant, multi.as_deref(), structure.is_some(), src)?;
    // any order's structure: the fingerprint takes the file, not one order's entries
    let some_structure = structure.as_ref().and_then(|(s, _)| s.per_order.values().next().map(Arc::as_ref));
    let fingerprint = match ProblemKey::of(&plant, multi.as_deref(), some_structure) {
        None => plant.fingerprint(),
        Some(key) => problem_fingerprint(&key, structure.as_ref().map(|(_, bytes)| bytes.as_slice())),
    };
    Ok(Problem {
        plant_arg: args[0].get_ref().clone(),
        plant_path: paths.swap_remove(0),
        fingerprint,
        name,
        multi,
        structure: structure.map(|(s, _)| s),
        plant: Arc::new(plant),
        orders,
        eps,
        seeds,
        warm_start: p.warm_start,
        eps_continuation: settings.eps_continuation.as_ref().is_some_and(|(b, _)| *b),
        continued_cpumax: settings.continued_cpumax.as_ref().map(|(x, _)| *x),
        continued_stall_starts: settings.continued_stall_starts.as_ref().map(|(x, _)| *x),
        order_chaining: settings.order_chaining.as_ref().is_some_and(|(b, _)| *b),
        base,
        trace: settings.trace.as_ref().map(|(t, _)| *t).unwrap_or_default(),
        location: Location::of_offset(src.text, plant_span(p).start),
    })
}

/// Where a problem's plants are named (`plant` or `plants`; `orders` if neither is given).
fn plant_span(p: &RawProblem) -> Range<usize> {
    match (&p.plant, &p.plants) {
        (Some(a), _) => a.span(),
        (None, Some(list)) => list.span(),
        (None, None) => p.orders.span(),
    }
}

/// Step 3e: the plant arguments, from `plant` or `plants` (exactly one of them).
fn plant_args(p: &RawProblem, src: &Source) -> Result<Vec<Spanned<String>>, SpecError> {
    match (&p.plant, &p.plants) {
        (Some(one), None) => Ok(vec![one.clone()]),
        (None, Some(list)) if list.get_ref().is_empty() => Err(src.error(list.span(), SpecProblem::NoPlants)),
        (None, Some(list)) => Ok(list.get_ref().clone()),
        (Some(_), Some(list)) => Err(src.error(list.span(), SpecProblem::PlantAndPlants)),
        (None, None) => Err(src.error(p.orders.span(), SpecProblem::MissingPlant)),
    }
}

/// A per-plant key's values for `n` plants (`default` for each when it is not given) and its
/// span.
fn per_plant<T: Clone>(
    value: &Option<Spanned<PerPlant<T>>>,
    n: usize,
    key: &'static str,
    default: T,
    src: &Source,
) -> Result<(Vec<T>, Option<Range<usize>>), SpecError> {
    let Some(v) = value else { return Ok((vec![default; n], None)) };
    let values = match v.get_ref() {
        PerPlant::One(x) => vec![x.clone(); n],
        PerPlant::List(list) if list.len() == n => list.clone(),
        PerPlant::List(list) => {
            return Err(src.error(v.span(), SpecProblem::PerPlantLength { key, found: list.len(), plants: n }))
        }
    };
    Ok((values, Some(v.span())))
}

/// Step 3h: the plants with their objectives, weights and bounds, judged by
/// `design::Problem::validate`; an error points at the key it is about (a plant's channels or
/// time domain: that plant).
fn resolve_terms(
    p: &RawProblem,
    args: &[Spanned<String>],
    plants: Vec<Plant>,
    src: &Source,
) -> Result<crate::design::Problem, SpecError> {
    let n = plants.len();
    let (objectives, objectives_span) = per_plant(&p.objectives, n, "objectives", "hinf".to_string(), src)?;
    let (weights, weights_span) = per_plant(&p.weights, n, "weights", Number::F(1.0), src)?;
    let (bounds, bounds_span) = per_plant(&p.bounds, n, "bounds", BoundValue::Text("none".into()), src)?;
    let at = |span: &Option<Range<usize>>| span.clone().unwrap_or_else(|| plant_span(p));
    let mut terms = Vec::with_capacity(n);
    for (((plant, objective), weight), bound) in plants.into_iter().zip(&objectives).zip(&weights).zip(&bounds) {
        let objective = objective
            .parse::<PlantObjective>()
            .map_err(|e| src.error(at(&objectives_span), SpecProblem::UnknownObjective(e)))?;
        let bound = match bound {
            BoundValue::Number(b) => Some(b.value()),
            BoundValue::Text(t) if t == "none" => None,
            BoundValue::Text(t) => return Err(src.error(at(&bounds_span), SpecProblem::BadBound(t.clone()))),
        };
        terms.push(PlantTerm { plant, objective, weight: weight.value(), bound });
    }
    let problem = crate::design::Problem { terms };
    if let Err(source) = problem.validate() {
        let (key, span) = match &source {
            ProblemError::Channels { index, .. } | ProblemError::Domain { index, .. } => {
                ("plants", args[index - 1].span())
            }
            ProblemError::Weight { .. } => ("weights", at(&weights_span)),
            ProblemError::Bound { .. } => ("bounds", at(&bounds_span)),
            _ => ("objectives", at(&objectives_span)),
        };
        return Err(src.error(span, SpecProblem::Problem { key, source: Box::new(source) }));
    }
    Ok(problem)
}

/// Step 3i: the structure file (a path, relative to the campaign file's folder), loaded for each
/// order of the problem (`design::Structure::load`: it must fit each), and the file's bytes (for
/// the problem's fingerprint).
fn load_structure(
    arg: &Spanned<String>,
    plant: &Plant,
    orders: &[usize],
    base_dir: &Path,
    src: &Source,
) -> Result<(ProblemStructure, Vec<u8>), SpecError> {
    let path = base_dir.join(arg.get_ref());
    let fail = |e: StructureError| src.error(arg.span(), SpecProblem::Structure(Box::new(e)));
    let mut per_order = std::collections::BTreeMap::new();
    for &order in orders {
        let s = Structure::load(&path, ControllerShape::for_plant(plant, order)).map_err(fail)?;
        per_order.insert(order, Arc::new(s));
    }
    let bytes = std::fs::read(&path)
        .map_err(|e| fail(StructureError::Io { file: path.display().to_string(), message: e.to_string() }))?;
    Ok((ProblemStructure { path, per_order }, bytes))
}

/// Step 3j: the problem's name: `name`, else the plants' names joined with `+` (one plant: its
/// name). `name` is refused on the single-plant H∞ problem without a structure, named by its
/// plant in every report.
fn problem_name(
    p: &RawProblem,
    plant: &Plant,
    multi: Option<&crate::design::Problem>,
    structured: bool,
    src: &Source,
) -> Result<String, SpecError> {
    match &p.name {
        Some(n) if n.get_ref().is_empty() || (multi.is_none() && !structured) => {
            Err(src.error(n.span(), SpecProblem::BadProblemName))
        }
        Some(n) => Ok(n.get_ref().clone()),
        None => Ok(multi.map_or_else(
            || plant.name.clone(),
            |m| m.terms.iter().map(|t| t.plant.name.as_str()).collect::<Vec<_>>().join("+"),
        )),
    }
}

/// A setting's value and the span it was read from.
type Setting<T> = Option<(T, Range<usize>)>;

/// The problem's value of a key, else the `[defaults]` one.
fn layer<T: Clone>(problem: &Option<Spanned<T>>, defaults: &Option<Spanned<T>>) -> Setting<T> {
    problem.as_ref().or(defaults.as_ref()).map(|s| (s.get_ref().clone(), s.span()))
}

/// Step 3b: the weights ε (default: [`DesignOptions::default`]'s).
fn check_eps(eps: &Setting<EpsList>, src: &Source) -> Result<Vec<f64>, SpecError> {
    let Some((EpsList(v), span)) = eps else { return Ok(vec![DesignOptions::default().eps]) };
    let v = v.clone();
    if v.is_empty() {
        return Err(src.error(span.clone(), SpecProblem::NoEps));
    }
    if has_duplicates(&v.iter().map(|x| x.to_bits()).collect::<Vec<_>>()) {
        return Err(src.error(span.clone(), SpecProblem::RepeatedEps));
    }
    Ok(v)
}

/// Step 3c: the seeds (default: seed 0).
fn check_seeds(seeds: &Setting<Seeds>, src: &Source) -> Result<Vec<u64>, SpecError> {
    let Some((Seeds(v, _), span)) = seeds else { return Ok(vec![DesignOptions::default().seed]) };
    let v = v.clone();
    if v.is_empty() {
        return Err(src.error(span.clone(), SpecProblem::NoSeeds));
    }
    if let Some(bad) = v.iter().find(|x| **x < 0) {
        return Err(src.error(span.clone(), SpecProblem::NegativeSeed(*bad)));
    }
    if has_duplicates(&v) {
        return Err(src.error(span.clone(), SpecProblem::RepeatedSeed));
    }
    Ok(v.into_iter().map(|x| x as u64).collect())
}

/// Step 3d: the controller orders, returned ascending.
fn check_orders(orders: &Spanned<Orders>, src: &Source) -> Result<Vec<usize>, SpecError> {
    let (v, span) = (&orders.get_ref().0, orders.span());
    if v.is_empty() {
        return Err(src.error(span, SpecProblem::NoOrders));
    }
    if let Some(bad) = v.iter().find(|o| **o < 0 || **o > MAX_ORDER as i64) {
        return Err(src.error(span, SpecProblem::OrderOutOfRange(*bad)));
    }
    if has_duplicates(v) {
        return Err(src.error(span, SpecProblem::RepeatedOrder));
    }
    let mut sorted: Vec<usize> = v.iter().map(|o| *o as usize).collect();
    sorted.sort_unstable();
    Ok(sorted)
}

/// Step 3f: the plant, resolved ([`resolve_plant_arg`]) and loaded; errors point at `plant`.
fn load_plant(plant: &Spanned<String>, base_dir: &Path, src: &Source) -> Result<(PathBuf, Plant), SpecError> {
    let path = resolve_plant_arg(plant.get_ref(), base_dir).map_err(|m| src.error(plant.span(), m))?;
    let loaded = Plant::load(&path).map_err(|e| src.error(plant.span(), SpecProblem::Plant(Box::new(e))))?;
    Ok((path, loaded))
}

/// Step 3g: the very check `design` makes, for the largest order (the only option that depends
/// on the order is order ≤ n) and every ε, before any job starts; the error points at the value
/// of the field it names, else at `plant`.
fn check_options(
    plant: &Plant,
    base: &DesignOptions,
    orders: &[usize],
    eps: &[f64],
    settings: &Layered,
    p: &RawProblem,
    src: &Source,
) -> Result<(), SpecError> {
    let max_order = *orders.last().expect("orders is not empty");
    // every job's cpumax: the problem's, and that of its ε-continued jobs (with its own span)
    let continued = settings.continued_cpumax.as_ref().map(|(c, span)| (*c, Some(span.clone())));
    for (cpumax, cpumax_span) in std::iter::once((base.cpumax, None)).chain(continued) {
        for &e in eps {
            let opts = DesignOptions { order: max_order, eps: e, cpumax, ..base.clone() };
            if let Err(err) = crate::design::validate(plant, &opts, None) {
                let span = match &err {
                    crate::design::DesignError::Options { field: "order", .. } => Some(p.orders.span()),
                    crate::design::DesignError::Options { field: "cpumax", .. } if cpumax_span.is_some() => {
                        cpumax_span.clone()
                    }
                    crate::design::DesignError::Options { field, .. } => settings.span_of(field),
                    _ => None,
                };
                return Err(src.error(span.unwrap_or(plant_span(p)), SpecProblem::Options(Box::new(err))));
            }
        }
    }
    Ok(())
}

/// Step 4: at most [`MAX_JOBS`] jobs in all (the error points at the problem that crosses it).
fn check_job_count(problems: &[Problem], raw: &[RawProblem], src: &Source) -> Result<(), SpecError> {
    let mut total: usize = 0;
    for (p, raw_p) in problems.iter().zip(raw) {
        let n = p.orders.len().saturating_mul(p.eps.len()).saturating_mul(p.seeds.len());
        total = total.saturating_add(n);
        if total > MAX_JOBS {
            return Err(src.error(plant_span(raw_p), SpecProblem::TooManyJobs));
        }
    }
    Ok(())
}

/// Step 5: one problem under two names is refused (the report's rows are per problem, with one
/// name); then expand the jobs: two problems that produce the same job would run it twice under
/// one id.
fn check_unique_jobs(campaign: &Campaign) -> Result<(), SpecError> {
    for (i, p) in campaign.problems.iter().enumerate() {
        if let Some(first) = campaign.problems[..i].iter().find(|q| q.fingerprint == p.fingerprint && q.name != p.name)
        {
            return Err(SpecError {
                file: campaign.file.clone(),
                location: p.location,
                message: SpecProblem::RenamedProblem {
                    first_line: first.location.line,
                    first_name: first.name.clone(),
                    name: p.name.clone(),
                },
            });
        }
    }
    let jobs = super::jobs::expand(campaign, super::jobs::RunnerTag::Design);
    let mut seen = std::collections::HashMap::new();
    for j in &jobs {
        if let Some(first) = seen.insert(j.id.clone(), j.problem) {
            let p = &campaign.problems[j.problem];
            return Err(SpecError {
                file: campaign.file.clone(),
                location: p.location,
                message: SpecProblem::RepeatedJob {
                    first_line: campaign.problems[first].location.line,
                    plant: p.name.clone(),
                    order: j.options.order,
                    eps: j.options.eps,
                    seed: j.options.seed,
                },
            });
        }
    }
    Ok(())
}

fn has_duplicates<T: Ord + Clone>(v: &[T]) -> bool {
    let mut s = v.to_vec();
    s.sort();
    s.windows(2).any(|w| w[0] == w[1])
}

/// A bare name goes to the plant library; a path is taken relative to the campaign file.
fn resolve_plant_arg(arg: &str, base_dir: &Path) -> Result<PathBuf, SpecProblem> {
    if arg.is_empty() {
        return Err(SpecProblem::NoPlant);
    }
    let is_path = arg.contains('/') || arg.ends_with(".json") || arg.ends_with(".mat");
    if is_path {
        let p = Path::new(arg);
        let p = if p.is_absolute() { p.to_path_buf() } else { base_dir.join(p) };
        if let Some(why) = crate::input::not_a_file(&p) {
            return Err(SpecProblem::NotAFile { path: p, why });
        }
        Ok(p)
    } else {
        crate::lti::resolve_plant(arg).map_err(|e| SpecProblem::Plant(Box::new(e)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::design::{ObjectiveKind, VariableScaling};

    fn parse(text: &str) -> Result<Campaign, SpecError> {
        Campaign::from_toml_str(text, Path::new("test.toml"))
    }

    fn err(text: &str) -> SpecError {
        parse(text).expect_err("expected an error")
    }

    const GOOD: &str = r#"
name = "t"
[defaults]
eps = [1e-2, 1e-3]
seeds = 3
cpumax = 5.0
threads = 3

[[problem]]
plant = "HE1"
orders = { from = 1, to = 3 }
warm_start = true

[[problem]]
plant = "REA2"
orders = [2, 1]
seeds = [7]
eps = 1e-4
nrand = 2
objective = "plain"
"#;

    #[test]
    fn good_file_resolves_layers() {
        let c = parse(GOOD).unwrap();
        assert_eq!(c.name, "t");
        assert_eq!(c.threads(None), 3);
        assert_eq!(c.threads(Some(1)), 1);
        assert_eq!(c.problems.len(), 2);
        let he1 = &c.problems[0];
        assert_eq!(he1.plant.name, "HE1");
        assert_eq!(he1.orders, vec![1, 2, 3]);
        assert_eq!(he1.eps, vec![1e-2, 1e-3]);
        assert_eq!(he1.seeds, vec![0, 1, 2]);
        assert!(he1.warm_start);
        assert_eq!(he1.base.cpumax, 5.0);
        assert_eq!(he1.location.line, 10);
        let rea2 = &c.problems[1];
        assert_eq!(rea2.orders, vec![1, 2]);
        assert_eq!(rea2.seeds, vec![7]);
        assert_eq!(rea2.eps, vec![1e-4]);
        assert_eq!(rea2.base.nrand, 2);
        assert_eq!(rea2.base.objective, ObjectiveKind::Plain);
        assert_eq!(rea2.base.cpumax, 5.0);
    }

    #[test]
    fn search_start_keys_layer_and_bad_scales_are_located() {
        let c = parse(
            "name = \"t\"\n[defaults]\nrandom_scales = [1.0, 1e-3]\nopen_loop_start = false\n\
             [[problem]]\nplant = \"HE1\"\norders = [1]\n[[problem]]\nplant = \"REA2\"\norders = [1]\n\
             open_loop_start = true\nrandom_scales = [0.5]\n",
        )
        .unwrap();
        assert_eq!(
            (c.problems[0].base.random_scales.clone(), c.problems[0].base.open_loop_start),
            (vec![1.0, 1e-3], false)
        );
        assert_eq!((c.problems[1].base.random_scales.clone(), c.problems[1].base.open_loop_start), (vec![0.5], true));
        // The booleans of older builds (false: off, true: always) and the mode names.
        let c = parse(
            "name = \"t\"\n[defaults]\nvariable_scaling = true\n[[problem]]\nplant = \"HE1\"\norders = [1]\n\
             [[problem]]\nplant = \"REA2\"\norders = [1]\nvariable_scaling = false\n\
             [[problem]]\nplant = \"REA2\"\norders = [2]\nvariable_scaling = \"off\"\n",
        )
        .unwrap();
        let modes: Vec<_> = c.problems.iter().map(|p| p.base.variable_scaling).collect();
        assert_eq!(modes, [VariableScaling::Always, VariableScaling::Off, VariableScaling::Off]);
        let c = parse("name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [1]\nvariable_scaling = \"always\"\n");
        assert_eq!(c.unwrap().problems[0].base.variable_scaling, VariableScaling::Always);
        let c = parse("name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [1]\n").unwrap();
        assert_eq!(c.problems[0].base.variable_scaling, VariableScaling::Alternate, "the default");
        let e = err("name = \"t\"\n[defaults]\nvariable_scaling = 1\n[[problem]]\nplant = \"HE1\"\norders = [1]\n");
        assert!(e.message.to_string().contains("variable_scaling") || e.location.line == 3, "{e}");
        let e = err(
            "name = \"t\"\n[defaults]\nvariable_scaling = \"sometimes\"\n[[problem]]\nplant = \"HE1\"\norders = [1]\n",
        );
        assert_eq!(e.location.line, 3, "{e}");
        assert!(e.message.to_string().contains("alternate") && e.message.to_string().contains("sometimes"), "{e}");
        let e = err("name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [1]\nrandom_scales = [1.0, 0.0]\n");
        assert_eq!((e.location.line, e.location.column), (5, 17), "{e}");
        assert!(e.message.to_string().contains("random_scales"), "{e}");
    }

    #[test]
    fn spend_budget_layers_and_a_wrong_type_is_located() {
        let c = parse(
            "name = \"t\"\n[defaults]\nspend_budget = false\n[[problem]]\nplant = \"HE1\"\norders = [1]\n\
             [[problem]]\nplant = \"REA2\"\norders = [1]\nspend_budget = true\n[[problem]]\nplant = \"Enns\"\n\
             orders = [1]\n",
        )
        .unwrap();
        let spend: Vec<bool> = c.problems.iter().map(|p| p.base.spend_budget).collect();
        assert_eq!(spend, [false, true, false]);
        assert!(
            parse("name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [1]\n").unwrap().problems[0].base.spend_budget
        );
        let e = err("name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [1]\nspend_budget = 1\n");
        assert_eq!(e.location.line, 5, "{e}");
        assert!(e.message.to_string().contains("bool"), "{e}");
    }

    #[test]
    fn eps_continuation_keys_layer_and_a_bad_continued_cpumax_is_located() {
        let c = parse(
            "name = \"t\"\n[defaults]\neps_continuation = true\ncontinued_cpumax = 30.0\n[[problem]]\nplant = \"HE1\"\n\
             orders = [1]\n[[problem]]\nplant = \"REA2\"\norders = [1]\neps_continuation = false\n",
        )
        .unwrap();
        let got: Vec<(bool, Option<f64>)> =
            c.problems.iter().map(|p| (p.eps_continuation, p.continued_cpumax)).collect();
        assert_eq!(got, [(true, Some(30.0)), (false, Some(30.0))]);
        let d = parse("name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [1]\n").unwrap();
        assert_eq!((d.problems[0].eps_continuation, d.problems[0].continued_cpumax), (false, None));
        let e = err("name = \"t\"\n[defaults]\ncpumax = 5.0\n[[problem]]\nplant = \"HE1\"\norders = [1]\ncontinued_cpumax = -1.0\n");
        assert_eq!(e.location.line, 7, "{e}");
        assert!(e.message.to_string().contains("cpumax"), "{e}");
    }

    #[test]
    fn reserve_and_continued_maxit_keys_layer_and_bad_values_are_located() {
        let c = parse(
            "name = \"t\"\n[defaults]\ncontinued_maxit = 500\nreturn_gs_reserve = false\n[[problem]]\nplant = \"HE1\"\n\
             orders = [1]\n[[problem]]\nplant = \"REA2\"\norders = [1]\ncontinued_maxit = 0\nreturn_gs_reserve = true\n",
        )
        .unwrap();
        let got: Vec<(usize, bool)> =
            c.problems.iter().map(|p| (p.base.continued_maxit, p.base.return_gs_reserve)).collect();
        assert_eq!(got, [(500, false), (0, true)]);
        let d = parse("name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [1]\n").unwrap();
        assert_eq!(
            (d.problems[0].base.continued_maxit, d.problems[0].base.return_gs_reserve),
            (DesignOptions::default().continued_maxit, true)
        );
        let e = err("name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [1]\nreturn_gs_reserve = \"yes\"\n");
        assert_eq!(e.location.line, 5, "{e}");
        let e = err("name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [1]\ncontinued_maxit = -3\n");
        assert_eq!((e.location.line, e.location.column), (5, 19), "{e}");
        let e = err("name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [1]\ncontinued_maxit = 1000000000\n");
        assert_eq!((e.location.line, e.location.column), (5, 19), "{e}");
        assert!(e.message.to_string().contains("continued_maxit"), "{e}");
    }

    #[test]
    fn trace_level_layers_stays_out_of_the_job_ids_and_a_bad_value_is_located() {
        let text = |defaults: &str, problem: &str| {
            format!(
                "name = \"t\"\n[defaults]\n{defaults}\n[[problem]]\nplant = \"HE1\"\norders = [1]\n{problem}\n\
                 [[problem]]\nplant = \"REA2\"\norders = [1]\n"
            )
        };
        let levels = |d: &str, p: &str| parse(&text(d, p)).unwrap().trace_levels(None);
        assert_eq!(levels("", ""), [TraceLevel::Sparse, TraceLevel::Sparse]);
        assert_eq!(levels("trace = \"off\"", ""), [TraceLevel::Off, TraceLevel::Off]);
        assert_eq!(levels("trace = \"off\"", "trace = \"full\""), [TraceLevel::Full, TraceLevel::Off]);
        let c = parse(&text("trace = \"off\"", "trace = \"full\"")).unwrap();
        assert_eq!(c.trace_levels(Some(TraceLevel::Sparse)), [TraceLevel::Sparse, TraceLevel::Sparse]);
        // Not a design option: the same jobs, with the same ids, at every level.
        let ids = |c: &Campaign| -> Vec<_> {
            crate::campaign::model::jobs::expand(c, crate::campaign::model::jobs::RunnerTag::Design)
                .into_iter()
                .map(|j| j.id)
                .collect()
        };
        assert_eq!(ids(&c), ids(&parse(&text("", "")).unwrap()));
        let e = err(&text("", "trace = \"verbose\""));
        assert_eq!((e.location.line, e.location.column), (7, 9), "{e}");
        assert!(e.message.to_string().contains("verbose") && e.message.to_string().contains("sparse"), "{e}");
        let e = err(&text("trace = true", ""));
        assert_eq!((e.location.line, e.location.column), (3, 9), "{e}");
        assert!(e.message.to_string().contains(r#"one of "sparse", "full", "off""#), "{e}");
        assert!(e.to_string().starts_with("test.toml:3:9: "), "{e}");
    }

    #[test]
    fn unknown_key_names_line_and_column() {
        let e = err("name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [1]\nordres = [2]\n");
        assert_eq!((e.location.line, e.location.column), (5, 1), "{e}");
        assert!(e.message.to_string().contains("ordres"), "{e}");
        let text = e.to_string();
        assert!(text.starts_with("test.toml:5:1: "), "{text}");

        let e = err("name = \"t\"\n[defaults]\n  cpu_max = 3\n[[problem]]\nplant = \"HE1\"\norders = [1]\n");
        assert_eq!((e.location.line, e.location.column), (3, 3), "{e}");
        assert!(e.message.to_string().contains("cpu_max"), "{e}");
    }

    #[test]
    fn wrong_types_name_line_and_column() {
        let e = err("name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [1]\ncpumax = \"fast\"\n");
        assert_eq!(e.location.line, 5, "{e}");
        assert_eq!(e.location.column, 10, "{e}");
        let e = err("name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = \"1-4\"\n");
        assert_eq!((e.location.line, e.location.column), (4, 10), "{e}");
        let e = err("name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [1]\nobjective = \"h2\"\n");
        assert_eq!(e.location.line, 5, "{e}");
        assert!(e.message.to_string().contains("h2"), "{e}");
        let e = err("name = 3\n[[problem]]\nplant = \"HE1\"\norders = [1]\n");
        assert_eq!((e.location.line, e.location.column), (1, 8), "{e}");
    }

    #[test]
    fn impossible_values_name_line_and_column() {
        let cases: &[(&str, usize, usize, &str)] = &[
            (
                "name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [1]\neps = [1e-2, -1e-3]\n",
                5,
                7,
                "ε must be a number from 1e-50 to 1e50, got -0.001",
            ),
            ("name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [1]\ncpumax = 0.0\n", 5, 10, "cpumax"),
            ("name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [1, -2]\n", 4, 10, "orders"),
            ("name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [1, 1]\n", 4, 10, "twice"),
            ("name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = { from = 3, to = 1 }\n", 4, 10, "empty"),
            ("name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [1]\nseeds = 0\n", 5, 9, "1..=10000"),
            ("name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [1]\nseeds = [1, -1]\n", 5, 9, "non-negative"),
            ("name = \"t\"\n[[problem]]\nplant = \"NOPE\"\norders = [1]\n", 3, 9, "NOPE"),
            ("name = \"t\"\n[[problem]]\nplant = \"nope/x.json\"\norders = [1]\n", 3, 9, "does not exist"),
            ("name = \"t\"\n[defaults]\nthreads = 0\n[[problem]]\nplant = \"HE1\"\norders = [1]\n", 3, 11, "threads"),
            ("name = \"a b\"\n[[problem]]\nplant = \"HE1\"\norders = [1]\n", 1, 8, "name"),
            ("name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [1]\nhinf_tol = 2.0\n", 5, 12, "hinf_tol"),
            ("name = \"t\"\n", 1, 1, "no [[problem]]"),
        ];
        for (text, line, col, word) in cases {
            let e = err(text);
            assert_eq!((e.location.line, e.location.column), (*line, *col), "{text}\n→ {e}");
            assert!(e.message.to_string().contains(word), "{text}\n→ {e}");
        }
    }

    #[test]
    fn repeated_jobs_are_refused() {
        let e = err(
            "name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [1, 2]\n[[problem]]\nplant = \"HE1\"\norders = [2]\n",
        );
        assert_eq!(e.location.line, 6, "{e}");
        assert!(e.message.to_string().contains("repeats"), "{e}");
    }

    #[test]
    fn location_counts_characters() {
        let t = "ab\nεx = 1\n";
        assert_eq!(Location::of_offset(t, 0), Location { line: 1, column: 1 });
        assert_eq!(Location::of_offset(t, 3), Location { line: 2, column: 1 });
        assert_eq!(Location::of_offset(t, 5), Location { line: 2, column: 2 });
    }
}
