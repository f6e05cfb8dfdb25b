//! The comparison behind the report tables: per plant the full-order bound, per (plant, n_K)
//! our best verified γ against the paper's HIFOO value and the literature. Pure functions of the
//! best rows, the plants and the paper's reference rows; [`super::report`] writes them as CSV and
//! [`super::latex`] renders them.
//!
//! Full-order bound: computed with `lti::full_order_gamma` for plants with n ≤
//! [`FULL_ORDER_MAX_N`]; above that (minutes of CPU, or failure, e.g. AC10) the paper's
//! full-order value is used and marked `from_paper`.

use super::reduce::{BestRow, PlantMap};
use super::reference::{RefMethod, ReferenceRow};
use crate::lti::full_order_gamma;

/// Largest plant order for which the full-order bound is computed here.
pub const FULL_ORDER_MAX_N: usize = 60;

/// The full-order bound of one plant.
#[derive(Debug, Clone, PartialEq)]
pub struct FullOrderRow {
    /// Plant.
    pub plant: String,
    /// γ_opt (NaN if unavailable).
    pub gamma: f64,
    /// True if taken from the paper rather than computed.
    pub from_paper: bool,
}

/// One row of `compare.csv`.
#[derive(Debug, Clone, PartialEq)]
pub struct CompareRow {
    /// Plant.
    pub plant: String,
    /// n_K.
    pub order: usize,
    /// Our best re-verified γ.
    pub ours: f64,
    /// The paper's HIFOO γ (NaN if none).
    pub paper: f64,
    /// Literature rows (source, γ).
    pub literature: Vec<(String, f64)>,
    /// Full-order bound.
    pub full_order: f64,
    /// ours / paper.
    pub ratio: f64,
}

/// Full-order bounds of the plants that appear in `best` (`plants` keyed by fingerprint).
pub fn full_order_rows(best: &[BestRow], plants: &PlantMap, reference: &[ReferenceRow]) -> Vec<FullOrderRow> {
    let mut seen: Vec<(&str, &str)> = best.iter().map(|r| (r.plant.as_str(), r.plant_fingerprint.as_str())).collect();
    seen.dedup();
    seen.into_iter()
        .map(|(name, fp)| {
            let paper = reference.iter().find(|r| r.is_for(fp) && r.method == RefMethod::FullOrder).map(|r| r.gamma);
            let computed = plants
                .get(fp)
                .filter(|p| p.dims.n <= FULL_ORDER_MAX_N)
                .and_then(|p| full_order_gamma(p).ok())
                .map(|g| g.gamma);
            match computed {
                Some(g) => FullOrderRow { plant: name.into(), gamma: g, from_paper: false },
                None => {
                    FullOrderRow { plant: name.into(), gamma: paper.unwrap_or(f64::NAN), from_paper: paper.is_some() }
                }
            }
        })
        .collect()
}

/// Joins our best rows with the reference.
pub fn compare_rows(best: &[BestRow], full: &[FullOrderRow], reference: &[ReferenceRow]) -> Vec<CompareRow> {
    best.iter()
        .map(|b| {
            let at = |m: RefMethod| {
                reference.iter().filter(move |r| r.is_for(&b.plant_fingerprint) && r.order == b.order && r.method == m)
            };
            let paper = at(RefMethod::Hifoo).map(|r| r.gamma).fold(f64::NAN, f64::min);
            let literature = at(RefMethod::Literature).map(|r| (r.source.clone(), r.gamma)).collect();
            let full_order = full.iter().find(|f| f.plant == b.plant).map_or(f64::NAN, |f| f.gamma);
            CompareRow {
                plant: b.plant.clone(),
                order: b.order,
                ours: b.gamma,
                paper,
                literature,
                full_order,
                ratio: b.gamma / paper,
            }
        })
        .collect()
}
