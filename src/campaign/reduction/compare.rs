//! The comparison behind the report tables: per plant the full-order bound, per (plant, n_K)
//! our best verified γ against the paper's HIFOO value and the literature. Pure functions of the
//! best rows, the plants, the paper's reference rows and the plant library's index;
//! [`super::report`] writes them as CSV and [`super::latex`] renders them.
//!
//! Full-order bound ([`FullOrderSource`]): computed with `lti::full_order_gamma` for plants with
//! n ≤ [`FULL_ORDER_MAX_N`]; where it is not (above that it takes minutes of CPU, and it fails on
//! some plants, e.g. AC10), the paper's full-order value; failing that, the plant library's
//! (`LibraryIndex`: `plants/compleib/INDEX.csv`, matched by fingerprint; an upper bound for the
//! singular plants, some values approximate).
//!
//! The paper's values (HIFOO and the literature it quotes) are all of stable controllers, strong
//! stabilisation (Gumussoy, Millstone & Overton 2008): they are set beside our `strong` rows only
//! ([`compare_rows`]); a `plain` row (K may be unstable) solves another problem.

use crate::campaign::records::record::JobRecord;
use std::collections::BTreeMap;

use super::reduce::{BestRow, PlantMap};
use crate::campaign::leaves::library_index::LibraryIndex;
use crate::campaign::leaves::reference::{RefMethod, ReferenceRow};
use crate::design::ObjectiveKind;
use crate::lti::{continuous_time_image, full_order_gamma, verified_stability, CentralProblem, Plant};

/// Largest plant order for which the full-order bound is computed here.
pub const FULL_ORDER_MAX_N: usize = 60;

/// Where a plant's full-order bound comes from, in the order they are tried.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FullOrderSource {
    /// Computed here (`lti::full_order_gamma`, n ≤ [`FULL_ORDER_MAX_N`]).
    Computed,
    /// The paper's full-order value (hinfsyn).
    Paper,
    /// The plant library's index (`LibraryIndex`, `plants/compleib/INDEX.csv`).
    LibraryIndex,
    /// None: γ is NaN.
    Unavailable,
}

/// The full-order bound of one plant.
#[derive(Debug, Clone, PartialEq)]
pub struct FullOrderRow {
    /// Plant.
    pub plant: String,
    /// The plant's order n, the full controller order (`None` for a problem of several plants).
    pub n: Option<usize>,
    /// γ_opt (NaN if unavailable).
    pub gamma: f64,
    /// Where γ_opt comes from.
    pub source: FullOrderSource,
    /// Whether the full-order central controller at 1.01·γ_opt ([`FULL_ORDER_CENTRAL_LEVEL`]) is
    /// stable; computed only for plants without a published reference (their tables say it),
    /// `None` otherwise or when it cannot be built.
    pub controller_stable: Option<bool>,
}

/// The level, relative to γ_opt, of the central controller whose stability the full-order row
/// of a table without a published reference reports (at γ_opt itself it is not defined).
pub const FULL_ORDER_CENTRAL_LEVEL: f64 = 1.01;

/// Whether the full-order central controller of `plant` at [`FULL_ORDER_CENTRAL_LEVEL`]·γ_opt is
/// stable (with the verification margin); `None` if it cannot be built.
///
/// A discrete-time plant's is that of its bilinear image (`lti::PlantImage`: the map keeps the
/// controller's stability).
pub fn full_order_controller_stable(plant: &Plant) -> Option<bool> {
    let c = CentralProblem::new(&continuous_time_image(plant)).ok()?;
    let k = c.controller(FULL_ORDER_CENTRAL_LEVEL * c.gamma_opt).ok()?;
    Some(k.order() == 0 || verified_stability(k.domain, k.ak.as_ref()).is_stable())
}

/// What a table's caption says of the campaign behind it: its name(s), ε values, number of
/// seeds, CPU budgets and number of jobs, from the journal records.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CampaignAbout {
    /// Campaign names, sorted.
    pub names: Vec<String>,
    /// ε values, ascending.
    pub eps: Vec<f64>,
    /// Distinct seeds.
    pub seeds: usize,
    /// CPU budgets (seconds per job), ascending.
    pub cpumax: Vec<f64>,
    /// Journaled jobs.
    pub jobs: usize,
    /// Sampling times of the discrete-time plants, by plant fingerprint (none: all continuous).
    pub sampling_times: BTreeMap<String, f64>,
}

impl CampaignAbout {
    /// The facts of `records` (a job journaled twice counts once).
    pub fn of(records: &[JobRecord]) -> CampaignAbout {
        let mut ids: Vec<&str> = records.iter().map(|r| r.job_id.0.as_str()).collect();
        ids.sort_unstable();
        ids.dedup();
        let mut names: Vec<String> = records.iter().map(|r| r.campaign.clone()).collect();
        names.sort();
        names.dedup();
        let sorted = |mut v: Vec<f64>| {
            v.sort_by(f64::total_cmp);
            v.dedup();
            v
        };
        let mut seeds: Vec<u64> = records.iter().map(|r| r.seed).collect();
        seeds.sort_unstable();
        seeds.dedup();
        CampaignAbout {
            names,
            eps: sorted(records.iter().map(|r| r.eps).collect()),
            seeds: seeds.len(),
            cpumax: sorted(records.iter().map(|r| r.cpumax).collect()),
            jobs: ids.len(),
            sampling_times: BTreeMap::new(),
        }
    }

    /// With the sampling times of the discrete-time plants among `plants` (by fingerprint).
    pub fn with_plants(mut self, plants: &PlantMap) -> Self {
        self.sampling_times = plants.iter().filter_map(|(fp, p)| Some((fp.clone(), p.domain.ts()?))).collect();
        self
    }
}

/// One row of `compare.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct CompareRow {
    /// Plant.
    pub plant: String,
    /// n_K.
    pub order: usize,
    /// The objective of our row (`strong` unless the campaign ran `plain` jobs).
    pub objective: ObjectiveKind,
    /// Our best re-verified γ.
    pub ours: f64,
    /// The paper's HIFOO γ (NaN if none, and for a `plain` row).
    pub paper: f64,
    /// Literature rows (source, γ; none for a `plain` row).
    pub literature: Vec<(String, f64)>,
    /// Full-order bound.
    pub full_order: f64,
    /// ours / paper (NaN without a paper value).
    pub ratio: f64,
}

/// Full-order bounds of the plants that appear in `best` (`plants` keyed by fingerprint), each
/// from the first [`FullOrderSource`] that has one.
pub fn full_order_rows(
    best: &[BestRow],
    plants: &PlantMap,
    reference: &[ReferenceRow],
    library: &LibraryIndex,
) -> Vec<FullOrderRow> {
    let mut seen: Vec<(&str, &str)> = best.iter().map(|r| (r.plant.as_str(), r.plant_fingerprint.as_str())).collect();
    seen.dedup();
    seen.into_iter()
        .map(|(name, fp)| {
            let plant = plants.get(fp);
            let paper = reference.iter().find(|r| r.is_for(fp) && r.method == RefMethod::FullOrder).map(|r| r.gamma);
            let computed =
                plant.filter(|p| p.dims.n <= FULL_ORDER_MAX_N).and_then(|p| full_order_gamma(p).ok()).map(|g| g.gamma);
            let has_reference = reference.iter().any(|r| r.is_for(fp));
            let controller_stable = match (has_reference, computed, plant) {
                (false, Some(_), Some(p)) => full_order_controller_stable(p),
                _ => None,
            };
            let (gamma, source) = [
                (computed, FullOrderSource::Computed),
                (paper, FullOrderSource::Paper),
                (library.full_order_gamma(fp), FullOrderSource::LibraryIndex),
            ]
            .into_iter()
            .find_map(|(g, source)| Some((g?, source)))
            .unwrap_or((f64::NAN, FullOrderSource::Unavailable));
            FullOrderRow { plant: name.into(), n: plant.map(|p| p.dims.n), gamma, source, controller_stable }
        })
        .collect()
}

/// Joins our best rows with the reference: the paper's and the literature's values beside the
/// `strong` rows only (all are of stable controllers); a `plain` row's `paper` and `ratio` are
/// NaN and its literature empty.
pub fn compare_rows(best: &[BestRow], full: &[FullOrderRow], reference: &[ReferenceRow]) -> Vec<CompareRow> {
    best.iter()
        .map(|b| {
            let strong = b.objective == ObjectiveKind::Strong;
            let at = |m: RefMethod| {
                reference
                    .iter()
                    .filter(move |r| strong && r.is_for(&b.plant_fingerprint) && r.order == b.order && r.method == m)
            };
            let paper = at(RefMethod::Hifoo).map(|r| r.gamma).fold(f64::NAN, f64::min);
            let literature = at(RefMethod::Literature).map(|r| (r.source.clone(), r.gamma)).collect();
            let full_order = full.iter().find(|f| f.plant == b.plant).map_or(f64::NAN, |f| f.gamma);
            CompareRow {
                plant: b.plant.clone(),
                order: b.order,
                objective: b.objective,
                ours: b.gamma,
                paper,
                literature,
                full_order,
                ratio: b.gamma / paper,
            }
        })
        .collect()
}

/// One row of the side-by-side table of the two objectives (`strong_vs_plain.csv`): the best
/// plain and the best strong γ of one (plant, n_K).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct CostRow {
    /// Plant.
    pub plant: String,
    /// n_K.
    pub order: usize,
    /// Best γ of the plain objective (controller may be unstable).
    #[serde(with = "crate::design::serde_f64_or_string")]
    pub gamma_plain: f64,
    /// Whether that controller is stable.
    pub plain_controller_stable: Option<bool>,
    /// Best γ of the strong objective (controller stable).
    #[serde(with = "crate::design::serde_f64_or_string")]
    pub gamma_strong: f64,
    /// γ strong / γ plain: what asking for a stable controller costs (≥ 1 up to the search's
    /// accuracy).
    #[serde(with = "crate::design::serde_f64_or_string")]
    pub ratio: f64,
}

/// The (plant, n_K) that have best rows of both objectives, side by side, in `best`'s order.
pub fn cost_rows(best: &[BestRow]) -> Vec<CostRow> {
    best.iter()
        .filter(|p| p.objective == ObjectiveKind::Plain)
        .filter_map(|p| {
            let s = best.iter().find(|s| {
                s.objective == ObjectiveKind::Strong && s.plant_fingerprint == p.plant_fingerprint && s.order == p.order
            })?;
            Some(CostRow {
                plant: p.plant.clone(),
                order: p.order,
                gamma_plain: p.gamma,
                plain_controller_stable: p.controller_stable,
                gamma_strong: s.gamma,
                ratio: s.gamma / p.gamma,
            })
        })
        .collect()
}
