//! Reduction of journal records to "best γ per (plant, order)", counting only controllers that
//! are re-verified by recomputation: the closed loop is formed again (`lti::closed_loop`), both
//! α(A_cl) < 0 and α(Ak) < 0 are checked, and γ = ‖Tzw‖∞ is recomputed. The reported γ is
//! always the recomputed one, never the journal's.

use std::collections::BTreeMap;
use std::sync::Arc;

use super::record::JobRecord;
use crate::lti::{closed_loop, hinf_norm, spectral_abscissa, Controller, Plant, DEFAULT_HINF_TOL};

/// Plants by name (the journal's `plant` field), as `Job::plant` holds them.
pub type PlantMap = BTreeMap<String, Arc<Plant>>;

/// Result of re-verifying one record.
#[derive(Debug, Clone, PartialEq)]
pub enum Verdict {
    /// Stable, stabilising; recomputed γ.
    Verified {
        /// Recomputed ‖Tzw‖∞.
        gamma: f64,
        /// α(A_cl).
        alpha_cl: f64,
        /// α(Ak) (None for order 0).
        alpha_k: Option<f64>,
    },
    /// Not counted, with the reason.
    Rejected(String),
}

/// Re-verifies one record's controller against `plant`.
pub fn verify(record: &JobRecord, plant: &Plant) -> Verdict {
    if record.failed() {
        return Verdict::Rejected("job failed".into());
    }
    let Some(doc) = record.controller.as_ref() else { return Verdict::Rejected("no controller".into()) };
    let k = match Controller::from_json_value(doc) {
        Ok(k) => k,
        Err(e) => return Verdict::Rejected(format!("bad controller: {e}")),
    };
    if let Err(e) = k.check_fits(plant) {
        return Verdict::Rejected(format!("controller does not fit the plant: {e}"));
    }
    let cl = match closed_loop(plant, &k) {
        Ok(cl) => cl,
        Err(e) => return Verdict::Rejected(format!("closed loop: {e}")),
    };
    let alpha_cl = spectral_abscissa(cl.a.as_ref());
    if !(alpha_cl < 0.0) {
        return Verdict::Rejected(format!("closed loop not stable (α = {alpha_cl})"));
    }
    let alpha_k = (k.order() > 0).then(|| spectral_abscissa(k.ak.as_ref()));
    if let Some(a) = alpha_k {
        if !(a < 0.0) {
            return Verdict::Rejected(format!("controller not stable (α_K = {a})"));
        }
    }
    let gamma = hinf_norm(&cl, DEFAULT_HINF_TOL).value;
    if !gamma.is_finite() {
        return Verdict::Rejected(format!("γ not finite ({gamma})"));
    }
    Verdict::Verified { gamma, alpha_cl, alpha_k }
}

/// Best result of one (plant, order).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BestRow {
    /// Plant name.
    pub plant: String,
    /// Controller order n_K.
    pub order: usize,
    /// Best recomputed γ (NaN if no job verified).
    #[serde(with = "crate::design::serde_f64_or_string")]
    pub gamma: f64,
    /// Job that gave it.
    pub job_id: Option<String>,
    /// Its ε.
    #[serde(default, with = "crate::design::serde_opt_f64_or_string")]
    pub eps: Option<f64>,
    /// Its seed.
    pub seed: Option<u64>,
    /// Journaled jobs of this (plant, order).
    pub runs: usize,
    /// Jobs whose controller re-verified stable and stabilising.
    pub verified: usize,
    /// Jobs that failed (status `failed`: no trustworthy result), the same count as `campaign
    /// status` and the run's exit code use.
    pub failed: usize,
    /// Jobs that did not fail but whose controller did not re-verify (e.g. not stabilised).
    #[serde(default)]
    pub unverified: usize,
}

/// Best γ per (plant, order), sorted by plant then order. Records of plants missing from
/// `plants` count as runs that failed verification.
pub fn best_per_order(records: &[JobRecord], plants: &PlantMap) -> Vec<BestRow> {
    let mut rows: BTreeMap<(String, usize), BestRow> = BTreeMap::new();
    for r in records {
        let row = rows.entry((r.plant.clone(), r.order)).or_insert_with(|| BestRow {
            plant: r.plant.clone(),
            order: r.order,
            gamma: f64::NAN,
            job_id: None,
            eps: None,
            seed: None,
            runs: 0,
            verified: 0,
            failed: 0,
            unverified: 0,
        });
        row.runs += 1;
        let verdict = match plants.get(&r.plant) {
            Some(p) => verify(r, p),
            None => Verdict::Rejected("unknown plant".into()),
        };
        match verdict {
            Verdict::Verified { gamma, .. } => {
                row.verified += 1;
                if !(gamma >= row.gamma) {
                    row.gamma = gamma;
                    row.job_id = Some(r.job_id.0.clone());
                    row.eps = Some(r.eps);
                    row.seed = Some(r.seed);
                }
            }
            Verdict::Rejected(_) if r.failed() => row.failed += 1,
            Verdict::Rejected(_) => row.unverified += 1,
        }
    }
    rows.into_values().collect()
}
