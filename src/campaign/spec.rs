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

use std::fmt;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::Deserialize;
use toml::Spanned;

use crate::design::{DesignOptions, ObjectiveKind};
use crate::lti::Plant;

/// Default number of worker threads (`--threads` and `defaults.threads` override it).
pub const DEFAULT_THREADS: usize = 2;
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

/// A position in a campaign file (1-based line and column, columns counted in characters).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Location {
    /// 1-based line.
    pub line: usize,
    /// 1-based column.
    pub column: usize,
}

impl Location {
    /// The position of byte `offset` in `text`.
    pub fn of_offset(text: &str, offset: usize) -> Location {
        let offset = offset.min(text.len());
        let before = &text[..floor_char_boundary(text, offset)];
        let line = before.matches('\n').count() + 1;
        let line_start = before.rfind('\n').map_or(0, |i| i + 1);
        let column = before[line_start..].chars().count() + 1;
        Location { line, column }
    }
}

fn location_suffix(l: &Location) -> String {
    if l.line == 0 {
        String::new()
    } else {
        format!(":{}:{}", l.line, l.column)
    }
}

fn floor_char_boundary(s: &str, mut i: usize) -> usize {
    while i > 0 && !s.is_char_boundary(i) {
        i -= 1;
    }
    i
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
    pub message: String,
}

/// A validated campaign: every plant loaded, every value checked.
#[derive(Debug, Clone)]
pub struct Campaign {
    /// Name; also the results folder `results/<name>/`.
    pub name: String,
    /// Free text.
    pub description: String,
    /// The file it was read from.
    pub file: PathBuf,
    /// Worker threads asked for in the file (`defaults.threads`), if any.
    pub threads: Option<usize>,
    /// Problems in file order.
    pub problems: Vec<Problem>,
}

/// One `[[problem]]` entry, resolved.
#[derive(Debug, Clone)]
pub struct Problem {
    /// The `plant` value as written.
    pub plant_arg: String,
    /// The plant file it resolved to.
    pub plant_path: PathBuf,
    /// The loaded plant.
    pub plant: Arc<Plant>,
    /// [`Plant::fingerprint`] (part of every job id).
    pub fingerprint: String,
    /// Controller orders, ascending, distinct.
    pub orders: Vec<usize>,
    /// Weights ε, in file order, distinct.
    pub eps: Vec<f64>,
    /// Seeds, in file order, distinct.
    pub seeds: Vec<u64>,
    /// Chain orders: order k of a (plant, ε, seed) chain starts from the controller of the next
    /// lower order of the same chain.
    pub warm_start: bool,
    /// Options common to all this problem's jobs (`order`, `eps`, `seed` are set per job).
    pub base: DesignOptions,
    /// Where the problem's `plant` key is (for messages about the problem).
    pub location: Location,
}

// ---------------------------------------------------------------------------------------------
// Raw (serde) form

/// Design settings allowed both in `[defaults]` and in a `[[problem]]`.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDefaults {
    eps: Option<Spanned<EpsList>>,
    seeds: Option<Spanned<Seeds>>,
    cpumax: Option<Spanned<f64>>,
    nrand: Option<Spanned<usize>>,
    objective: Option<ObjectiveKind>,
    maxit: Option<Spanned<usize>>,
    normtol: Option<Spanned<f64>>,
    evaldist: Option<Spanned<f64>>,
    hinf_tol: Option<Spanned<f64>>,
    gradient_sampling: Option<bool>,
    maxevals: Option<Spanned<usize>>,
    stall_starts: Option<Spanned<usize>>,
    stall_rtol: Option<Spanned<f64>>,
    max_starts: Option<Spanned<usize>>,
    hop_scales: Option<Spanned<Vec<f64>>>,
    central_gammas: Option<Spanned<Vec<f64>>>,
    threads: Option<Spanned<usize>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawProblem {
    plant: Spanned<String>,
    orders: Spanned<Orders>,
    #[serde(default)]
    warm_start: bool,
    eps: Option<Spanned<EpsList>>,
    seeds: Option<Spanned<Seeds>>,
    cpumax: Option<Spanned<f64>>,
    nrand: Option<Spanned<usize>>,
    objective: Option<ObjectiveKind>,
    maxit: Option<Spanned<usize>>,
    normtol: Option<Spanned<f64>>,
    evaldist: Option<Spanned<f64>>,
    hinf_tol: Option<Spanned<f64>>,
    gradient_sampling: Option<bool>,
    maxevals: Option<Spanned<usize>>,
    stall_starts: Option<Spanned<usize>>,
    stall_rtol: Option<Spanned<f64>>,
    max_starts: Option<Spanned<usize>>,
    hop_scales: Option<Spanned<Vec<f64>>>,
    central_gammas: Option<Spanned<Vec<f64>>>,
}

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
// Loading and validation

impl Campaign {
    /// Reads and validates a campaign file.
    pub fn load(path: &Path) -> Result<Campaign, SpecError> {
        let text =
            crate::input::read_capped_string(path, crate::input::MAX_CAMPAIGN_BYTES, "campaign file").map_err(|e| {
                SpecError {
                    file: path.to_path_buf(),
                    location: Location { line: 0, column: 0 },
                    message: format!("cannot read the campaign file: {e}"),
                }
            })?;
        Campaign::from_toml_str(&text, path)
    }

    /// Parses and validates campaign text; `file` names it in errors and anchors relative plant
    /// paths.
    pub fn from_toml_str(text: &str, file: &Path) -> Result<Campaign, SpecError> {
        let at = |span: Range<usize>, message: String| SpecError {
            file: file.to_path_buf(),
            location: Location::of_offset(text, span.start),
            message,
        };
        let raw: RawCampaign =
            toml::from_str(text).map_err(|e| at(e.span().unwrap_or(0..0), e.message().trim().to_string()))?;

        let name = raw.name.get_ref().clone();
        if name.chars().count() > MAX_NAME_CHARS {
            return Err(at(raw.name.span(), format!("campaign name is longer than {MAX_NAME_CHARS} characters")));
        }
        if name.is_empty()
            || !name.chars().all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c))
            || name.starts_with('.')
        {
            return Err(at(
                raw.name.span(),
                format!("campaign name {name:?} must be non-empty and use only letters, digits, '-', '_' and '.' (it names the results folder)"),
            ));
        }
        let d = &raw.defaults;
        let threads = match &d.threads {
            Some(t) if !(1..=MAX_THREADS).contains(t.get_ref()) => {
                return Err(at(t.span(), format!("threads must be in 1..={MAX_THREADS}, found {}", t.get_ref())))
            }
            Some(t) => Some(*t.get_ref()),
            None => None,
        };
        if raw.problems.is_empty() {
            return Err(at(0..0, "the campaign has no [[problem]] entries".into()));
        }
        let base_dir = file.parent().unwrap_or(Path::new("."));
        let mut problems = Vec::with_capacity(raw.problems.len());
        for p in &raw.problems {
            let layer = |pv: &Option<Spanned<EpsList>>| pv.clone().or_else(|| d.eps.clone());
            let eps_s = layer(&p.eps);
            let eps = match &eps_s {
                Some(s) => {
                    let v = s.get_ref().0.clone();
                    if v.is_empty() {
                        return Err(at(s.span(), "eps must list at least one weight".into()));
                    }
                    if has_duplicates(&v.iter().map(|x| x.to_bits()).collect::<Vec<_>>()) {
                        return Err(at(s.span(), "eps lists the same weight twice".into()));
                    }
                    v
                }
                None => vec![DesignOptions::default().eps],
            };
            let seeds = match p.seeds.clone().or_else(|| d.seeds.clone()) {
                Some(s) => {
                    let Seeds(v, _) = s.get_ref().clone();
                    if v.is_empty() {
                        return Err(at(s.span(), "seeds must list at least one seed".into()));
                    }
                    if let Some(bad) = v.iter().find(|x| **x < 0) {
                        return Err(at(s.span(), format!("seeds must be non-negative integers, found {bad}")));
                    }
                    if has_duplicates(&v) {
                        return Err(at(s.span(), "seeds lists the same seed twice".into()));
                    }
                    v.into_iter().map(|x| x as u64).collect()
                }
                None => vec![0],
            };
            let orders_v = &p.orders.get_ref().0;
            let ospan = p.orders.span();
            if orders_v.is_empty() {
                return Err(at(ospan, "orders must list at least one controller order".into()));
            }
            if let Some(bad) = orders_v.iter().find(|o| **o < 0 || **o > MAX_ORDER as i64) {
                return Err(at(ospan, format!("controller orders must be integers in 0..={MAX_ORDER}, found {bad}")));
            }
            if has_duplicates(orders_v) {
                return Err(at(ospan, "orders lists the same order twice".into()));
            }
            let mut orders: Vec<usize> = orders_v.iter().map(|o| *o as usize).collect();
            orders.sort_unstable();

            let mut base = DesignOptions::default();
            // Values are only collected here; `design::validate` below judges them (one rule
            // for `campaign design` and campaign files).
            let pick = |v: &Option<Spanned<f64>>, dv: &Option<Spanned<f64>>| {
                v.as_ref().or(dv.as_ref()).map(|s| (*s.get_ref(), s.span()))
            };
            let pick_n = |v: &Option<Spanned<usize>>, dv: &Option<Spanned<usize>>| {
                v.as_ref().or(dv.as_ref()).map(|s| (*s.get_ref(), s.span()))
            };
            let cpumax = pick(&p.cpumax, &d.cpumax);
            let normtol = pick(&p.normtol, &d.normtol);
            let evaldist = pick(&p.evaldist, &d.evaldist);
            let hinf_tol = pick(&p.hinf_tol, &d.hinf_tol);
            let nrand = pick_n(&p.nrand, &d.nrand);
            let maxit = pick_n(&p.maxit, &d.maxit);
            for (slot, v) in [
                (&mut base.cpumax, &cpumax),
                (&mut base.normtol, &normtol),
                (&mut base.evaldist, &evaldist),
                (&mut base.hinf_tol, &hinf_tol),
            ] {
                if let Some((x, _)) = v {
                    *slot = *x;
                }
            }
            for (slot, v) in [(&mut base.nrand, &nrand), (&mut base.maxit, &maxit)] {
                if let Some((x, _)) = v {
                    *slot = *x;
                }
            }
            if let Some(o) = p.objective.or(d.objective) {
                base.objective = o;
            }
            if let Some(g) = p.gradient_sampling.or(d.gradient_sampling) {
                base.gradient_sampling = g;
            }
            let maxevals = pick_n(&p.maxevals, &d.maxevals);
            let max_starts = pick_n(&p.max_starts, &d.max_starts);
            let stall_starts = pick_n(&p.stall_starts, &d.stall_starts);
            let stall_rtol = pick(&p.stall_rtol, &d.stall_rtol);
            let hop_scales = p.hop_scales.as_ref().or(d.hop_scales.as_ref()).map(|s| (s.get_ref().clone(), s.span()));
            if let Some((x, _)) = &maxevals {
                base.maxevals = Some(*x);
            }
            if let Some((x, _)) = &max_starts {
                base.max_starts = Some(*x);
            }
            if let Some((x, _)) = &stall_starts {
                base.stall_starts = *x;
            }
            if let Some((x, _)) = &stall_rtol {
                base.stall_rtol = *x;
            }
            if let Some((x, _)) = &hop_scales {
                base.hop_scales = x.clone();
            }
            let central_gammas =
                p.central_gammas.as_ref().or(d.central_gammas.as_ref()).map(|s| (s.get_ref().clone(), s.span()));
            if let Some((x, _)) = &central_gammas {
                base.central_gammas = x.clone();
            }

            let plant_arg = p.plant.get_ref().clone();
            let pspan = p.plant.span();
            let plant_path = resolve_plant_arg(&plant_arg, base_dir).map_err(|m| at(pspan.clone(), m))?;
            let plant = Plant::load(&plant_path).map_err(|e| at(pspan.clone(), e.to_string()))?;

            // The very check `design` makes, for the largest order (the only option that depends
            // on the order is order ≤ n) and every ε, before any job starts.
            let max_order = *orders.last().expect("orders is not empty");
            for &e in &eps {
                let opts = DesignOptions { order: max_order, eps: e, ..base.clone() };
                if let Err(err) = crate::design::validate(&plant, &opts, None) {
                    let field = match &err {
                        crate::design::DesignError::Options { field, .. } => *field,
                        _ => "",
                    };
                    let span = match field {
                        "order" => Some(ospan.clone()),
                        "eps" => eps_s.as_ref().map(|s| s.span()),
                        "cpumax" => cpumax.as_ref().map(|c| c.1.clone()),
                        "normtol" => normtol.as_ref().map(|c| c.1.clone()),
                        "evaldist" => evaldist.as_ref().map(|c| c.1.clone()),
                        "hinf_tol" => hinf_tol.as_ref().map(|c| c.1.clone()),
                        "nrand" => nrand.as_ref().map(|c| c.1.clone()),
                        "maxit" => maxit.as_ref().map(|c| c.1.clone()),
                        "maxevals" => maxevals.as_ref().map(|c| c.1.clone()),
                        "max_starts" => max_starts.as_ref().map(|c| c.1.clone()),
                        "stall_starts" => stall_starts.as_ref().map(|c| c.1.clone()),
                        "stall_rtol" => stall_rtol.as_ref().map(|c| c.1.clone()),
                        "hop_scales" => hop_scales.as_ref().map(|c| c.1.clone()),
                        "central_gammas" => central_gammas.as_ref().map(|c| c.1.clone()),
                        _ => None,
                    };
                    return Err(at(span.unwrap_or(pspan.clone()), err.to_string()));
                }
            }
            problems.push(Problem {
                plant_arg,
                plant_path,
                fingerprint: plant.fingerprint(),
                plant: Arc::new(plant),
                orders,
                eps,
                seeds,
                warm_start: p.warm_start,
                base,
                location: Location::of_offset(text, pspan.start),
            });
        }

        let mut total: usize = 0;
        for (p, raw_p) in problems.iter().zip(&raw.problems) {
            let n = p.orders.len().saturating_mul(p.eps.len()).saturating_mul(p.seeds.len());
            total = total.saturating_add(n);
            if total > MAX_JOBS {
                return Err(at(
                    raw_p.plant.span(),
                    format!("the campaign expands to more than {MAX_JOBS} jobs (orders × eps × seeds, summed over problems)"),
                ));
            }
        }
        let campaign = Campaign { name, description: raw.description, file: file.to_path_buf(), threads, problems };
        // Two problems that produce the same job would run it twice under one id.
        let jobs = super::jobs::expand(&campaign, super::jobs::RunnerTag::Design);
        let mut seen = std::collections::HashMap::new();
        for j in &jobs {
            if let Some(first) = seen.insert(j.id.clone(), j.problem) {
                let p = &campaign.problems[j.problem];
                return Err(SpecError {
                    file: file.to_path_buf(),
                    location: p.location,
                    message: format!(
                        "this problem repeats a job of the problem at line {} (plant {}, order {}, ε {}, seed {})",
                        campaign.problems[first].location.line,
                        p.plant.name,
                        j.options.order,
                        j.options.eps,
                        j.options.seed
                    ),
                });
            }
        }
        Ok(campaign)
    }

    /// Worker threads: the command line's, else the file's, else [`DEFAULT_THREADS`].
    pub fn threads(&self, cli: Option<usize>) -> usize {
        cli.or(self.threads).unwrap_or(DEFAULT_THREADS).max(1)
    }
}

fn has_duplicates<T: Ord + Clone>(v: &[T]) -> bool {
    let mut s = v.to_vec();
    s.sort();
    s.windows(2).any(|w| w[0] == w[1])
}

/// A bare name goes to the plant library; a path is taken relative to the campaign file.
fn resolve_plant_arg(arg: &str, base_dir: &Path) -> Result<PathBuf, String> {
    if arg.is_empty() {
        return Err("plant must name a plant (e.g. \"HE1\") or a plant file".into());
    }
    let is_path = arg.contains('/') || arg.ends_with(".json") || arg.ends_with(".mat");
    if is_path {
        let p = Path::new(arg);
        let p = if p.is_absolute() { p.to_path_buf() } else { base_dir.join(p) };
        if !p.is_file() {
            return Err(format!("plant file {} does not exist", p.display()));
        }
        Ok(p)
    } else {
        crate::lti::resolve_plant(arg).map_err(|e| e.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

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
    fn unknown_key_names_line_and_column() {
        let e = err("name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [1]\nordres = [2]\n");
        assert_eq!((e.location.line, e.location.column), (5, 1), "{e}");
        assert!(e.message.contains("ordres"), "{e}");
        let text = e.to_string();
        assert!(text.starts_with("test.toml:5:1: "), "{text}");

        let e = err("name = \"t\"\n[defaults]\n  cpu_max = 3\n[[problem]]\nplant = \"HE1\"\norders = [1]\n");
        assert_eq!((e.location.line, e.location.column), (3, 3), "{e}");
        assert!(e.message.contains("cpu_max"), "{e}");
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
        assert!(e.message.contains("h2"), "{e}");
        let e = err("name = 3\n[[problem]]\nplant = \"HE1\"\norders = [1]\n");
        assert_eq!((e.location.line, e.location.column), (1, 8), "{e}");
    }

    #[test]
    fn impossible_values_name_line_and_column() {
        let cases: &[(&str, usize, usize, &str)] = &[
            ("name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [1]\neps = [1e-2, -1e-3]\n", 5, 7, "positive"),
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
            assert!(e.message.contains(word), "{text}\n→ {e}");
        }
    }

    #[test]
    fn repeated_jobs_are_refused() {
        let e = err(
            "name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [1, 2]\n[[problem]]\nplant = \"HE1\"\norders = [2]\n",
        );
        assert_eq!(e.location.line, 6, "{e}");
        assert!(e.message.contains("repeats"), "{e}");
    }

    #[test]
    fn location_counts_characters() {
        let t = "ab\nεx = 1\n";
        assert_eq!(Location::of_offset(t, 0), Location { line: 1, column: 1 });
        assert_eq!(Location::of_offset(t, 3), Location { line: 2, column: 1 });
        assert_eq!(Location::of_offset(t, 5), Location { line: 2, column: 2 });
    }
}
