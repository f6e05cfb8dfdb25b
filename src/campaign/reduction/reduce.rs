//! Reduction of journal records to "best γ per (plant, order)", counting only controllers that
//! are re-verified by recomputation: the controller's shape is checked against the job's order
//! and the plant's channels (the journal's `order` and `options.order` must agree too), the
//! closed loop is formed again (`lti::closed_loop`), both α(A_cl) and α(Ak) (in discrete time
//! ρ − 1, `lti::verified_stability`, on the balanced matrix where that pays) are checked to be below minus the stability margin (1e-12 · max(1, ‖A‖_F) — ‖·‖_F of the balanced A where balancing lowers it more than 100-fold, docs/ALGORITHMS.md §5), and
//! γ = ‖Tzw‖∞ is recomputed — all of it `design::evaluate` and its verdict. The reported γ is always the recomputed one, never the journal's.
//! A job of the plain objective (no stability asked of K) counts with an unstable controller
//! too: its row says whether the controller is stable (`controller_stable`), which is what the
//! comparison of the two objectives needs. Rows are per (plant, order, objective).
//!
//! A plant is identified by its content fingerprint, never by its name: records are verified
//! against the plant with their `plant_fingerprint` and grouped by it, so two different plants
//! that share a name are never merged, and a renamed plant keeps its results (shown under its
//! current name). Two plants of one name in one report are told apart as `name@<8 hex digits>`.
//!
//! A problem of several plants (a `plants` key, or another objective, weight or bound) is
//! verified on every plant ([`verify_problem`]): each closed loop stable with the margin, the
//! controller stable for a strong job, and each plant's value g_j recomputed
//! (`design::plant_values`); its γ is then the problem's (`design::problem_gamma`: the largest
//! weighted value of the plants without a bound).
//!
//! Several records of one job id (a job run twice, e.g. by two folders merged with
//! `--journal`) count once: its best re-verified record.

use std::collections::BTreeMap;
use std::sync::Arc;

use rayon::prelude::*;

use crate::campaign::records::record::JobRecord;
use crate::design::{evaluate_job, Evaluation, ObjectiveKind, PlantValue, Problem, Rejection};
use crate::lti::{Controller, Plant};

/// Plants by content fingerprint (the journal's `plant_fingerprint`), as `Job::plant` holds
/// them.
pub type PlantMap = BTreeMap<String, Arc<Plant>>;

/// Problems of several plants (or another objective, weight or bound) by their fingerprint (the
/// journal's `plant_fingerprint` of their jobs).
pub type ProblemMap = BTreeMap<String, Arc<Problem>>;

/// Display names of plants given as (fingerprint, name) pairs: the name, or `name@<first 8 hex
/// digits of the fingerprint>` when several fingerprints share it.
pub fn plant_labels<'a>(plants: impl IntoIterator<Item = (&'a str, &'a str)>) -> BTreeMap<String, String> {
    let pairs: BTreeMap<&str, &str> = plants.into_iter().collect();
    let mut per_name: BTreeMap<&str, usize> = BTreeMap::new();
    for name in pairs.values() {
        *per_name.entry(name).or_default() += 1;
    }
    pairs
        .iter()
        .map(|(fp, name)| {
            let label =
                if per_name[name] > 1 { format!("{name}@{}", &fp[..fp.len().min(8)]) } else { name.to_string() };
            (fp.to_string(), label)
        })
        .collect()
}

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
        /// Recomputed ‖K‖∞ (+∞ for an unstable controller of a plain job).
        k_hinf: f64,
        /// Whether the controller is stable with the margin (always for a strong job).
        controller_stable: bool,
        /// Each plant's recomputed value, for a problem of several plants (empty for one).
        plants: Vec<PlantValue>,
    },
    /// Not counted, with the reason.
    Rejected(String),
}

/// Re-verifies one record's controller against `plant`.
pub fn verify(record: &JobRecord, plant: &Plant) -> Verdict {
    match recorded_controller(record) {
        Ok(k) => verify_controller(k, record.order, record.options.objective, plant),
        Err(why) => Verdict::Rejected(why),
    }
}

/// The record's controller, or why there is none to verify (a failed job, or orders that
/// disagree).
fn recorded_controller(record: &JobRecord) -> Result<&Controller, String> {
    let Some(k) = record.controller() else { return Err("job failed".into()) };
    if record.options.order != record.order {
        return Err(format!(
            "the record's order {} differs from its options' order {}",
            record.order, record.options.order
        ));
    }
    Ok(k)
}

/// Re-verifies controller `k` of a job of `order` and `objective` against `plant` ([`verify`]
/// without the record): `design::evaluate_job` and its verdict.
pub fn verify_controller(k: &Controller, order: usize, objective: ObjectiveKind, plant: &Plant) -> Verdict {
    verdict(evaluate_job(None, plant, k, order), objective)
}

/// The [`Verdict`] of an evaluation (`design::Evaluation::verdict`).
fn verdict(evaluation: Result<Evaluation, Rejection>, objective: ObjectiveKind) -> Verdict {
    let e = match evaluation {
        Ok(e) => e,
        Err(why) => return Verdict::Rejected(why.to_string()),
    };
    match e.verdict(objective) {
        Ok(gamma) => Verdict::Verified {
            gamma,
            alpha_cl: e.worst_loop_measure(),
            alpha_k: e.controller.stability.map(|s| s.measure),
            k_hinf: e.controller.hinf,
            controller_stable: e.controller.is_stable(),
            plants: e.values,
        },
        Err(why) => Verdict::Rejected(why.to_string()),
    }
}

/// Re-verifies one record's controller against every plant of `problem` ([`verify`] on each, a
/// rejection naming the plant), with each plant's value recomputed: γ is the problem's
/// (`design::problem_gamma`), α(A_cl) the largest. A controller that violates a plant's bound
/// is rejected (it does not solve the problem).
pub fn verify_problem(record: &JobRecord, problem: &Problem) -> Verdict {
    match (recorded_controller(record), problem.terms.first()) {
        (Ok(k), _) => verify_problem_controller(k, record.order, record.options.objective, problem),
        (Err(why), Some(t)) => Verdict::Rejected(format!("plant {}: {why}", t.plant.name)),
        (Err(_), None) => Verdict::Rejected("no plant".into()),
    }
}

/// [`verify_problem`] of controller `k` of a job of `order` and `objective` (without the record).
pub fn verify_problem_controller(k: &Controller, order: usize, objective: ObjectiveKind, problem: &Problem) -> Verdict {
    match problem.terms.first() {
        Some(t) => verdict(evaluate_job(Some(problem), &t.plant, k, order), objective),
        None => Verdict::Rejected("no plant".into()),
    }
}

/// A record verified against its plant (`plants`) or its problem of several plants (`problems`);
/// `None` when neither holds its fingerprint.
fn verify_any(r: &JobRecord, plants: &PlantMap, problems: &ProblemMap) -> Option<Verdict> {
    match problems.get(&r.plant_fingerprint) {
        Some(p) => Some(verify_problem(r, p)),
        None => plants.get(&r.plant_fingerprint).map(|p| verify(r, p)),
    }
}

/// Relative distance to the best γ within which a replicate counts as reaching it
/// ([`BestRow::near_best`]): the crate's one tie tolerance of norms, [`crate::lti::NORM_TIE_RTOL`].
pub const NEAR_BEST_RTOL: f64 = crate::lti::NORM_TIE_RTOL;

/// Best result of one (plant, order).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct BestRow {
    /// Plant name (its current name; `name@fingerprint` if two plants share it).
    pub plant: String,
    /// Plant content fingerprint (the plant's identity).
    pub plant_fingerprint: String,
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
    /// ‖K‖∞ of that controller (recomputed).
    #[serde(default, with = "crate::design::serde_opt_f64_or_string")]
    pub k_hinf: Option<f64>,
    /// α(A_K) of that controller (recomputed; none for n_K = 0).
    #[serde(default, with = "crate::design::serde_opt_f64_or_string")]
    pub alpha_k: Option<f64>,
    /// CPU seconds that job took to first reach its final objective (the journal's
    /// `search.cpu_to_best_s`; a continued or warm-started job counts from its own start).
    #[serde(default, with = "crate::design::serde_opt_f64_or_string")]
    pub cpu_to_best_s: Option<f64>,
    /// The same, plus the whole CPU seconds of the jobs it was started from (its `warm_from`
    /// predecessors, transitively: the ε-continuation and warm-start chain up to it); None if
    /// one of them is not in the journals.
    #[serde(default, with = "crate::design::serde_opt_f64_or_string")]
    pub chain_cpu_to_best_s: Option<f64>,
    /// Journaled jobs of this (plant, order) (a job journaled twice counts once).
    pub runs: usize,
    /// Jobs whose controller re-verified stable and stabilising.
    pub verified: usize,
    /// Verified jobs whose γ is within a relative [`NEAR_BEST_RTOL`] (0.1 %) of the best, the
    /// best job included: how many replicates (ε × seeds) reached the reported value.
    #[serde(default)]
    pub near_best: usize,
    /// Jobs that failed (status `failed`: no trustworthy result), the same count as `campaign
    /// status` and the run's exit code use.
    pub failed: usize,
    /// Jobs that did not fail but whose controller did not re-verify (e.g. not stabilised).
    #[serde(default)]
    pub unverified: usize,
    /// The design objective of the row's jobs: `strong` or `plain` (rows of best.csv files of
    /// older builds, which had no such column, read as `strong`).
    #[serde(default)]
    pub objective: ObjectiveKind,
    /// Whether the best controller is stable (with the margin of [`verify`]); always true for
    /// `strong`, and what a `plain` row's γ cost; empty when no job verified.
    #[serde(default)]
    pub controller_stable: Option<bool>,
    /// Each plant's recomputed value for the best controller of a problem of several plants
    /// (empty for one plant). Not a column of best.csv: plants.csv holds them.
    #[serde(skip)]
    pub plants: Vec<PlantValue>,
}

/// Best γ per (plant, order, objective), sorted by plant label, order, then objective (strong
/// before plain). Records of plants missing
/// from `plants` count as runs that failed verification; duplicate records of a job count once,
/// by their best verified one.
pub fn best_per_order(records: &[JobRecord], plants: &PlantMap) -> Vec<BestRow> {
    best_per_problem(records, plants, &ProblemMap::new())
}

/// [`best_per_order`], with the problems of several plants of `problems` (their records are
/// verified by [`verify_problem`], their rows named by the journal's `plant`).
pub fn best_per_problem(records: &[JobRecord], plants: &PlantMap, problems: &ProblemMap) -> Vec<BestRow> {
    let labels = plant_labels(records.iter().map(|r| {
        let name = plants.get(&r.plant_fingerprint).map_or(r.plant.as_str(), |p| p.name.as_str());
        (r.plant_fingerprint.as_str(), name)
    }));
    // Each record re-verified on its own (in parallel: the verdicts, and so the tables, do not
    // depend on the order or the thread they are computed in).
    let verdicts: Vec<Option<Verdict>> =
        records.par_iter().map(|r| verify_any(r, plants, problems).filter(|v| v.gamma().is_some())).collect();
    // job id → (record, verified figures) of its best record
    let mut per_job: BTreeMap<&str, (&JobRecord, Option<Verdict>)> = BTreeMap::new();
    for (r, verdict) in records.iter().zip(verdicts) {
        let better = |old: &Option<Verdict>| match (verdict.as_ref().and_then(Verdict::gamma), old) {
            (Some(g), Some(o)) => o.gamma().is_some_and(|o| g < o),
            (Some(_), None) => true,
            (None, _) => false,
        };
        match per_job.get_mut(r.job_id.0.as_str()) {
            Some(e) if better(&e.1) => *e = (r, verdict),
            Some(_) => {}
            None => {
                per_job.insert(r.job_id.0.as_str(), (r, verdict));
            }
        }
    }
    // CPU seconds of the chain before a job: its predecessors' whole jobs
    let cpu_of: BTreeMap<&str, (f64, Option<&str>)> =
        per_job.iter().map(|(id, (r, _))| (*id, (r.cpu_s, r.warm_from.as_ref().map(|p| p.0.as_str())))).collect();
    let chain_cpu_before = |r: &JobRecord| {
        let mut total = 0.0;
        let mut next = r.warm_from.as_ref().map(|p| p.0.as_str());
        while let Some(id) = next {
            let (cpu, prev) = cpu_of.get(id)?;
            total += cpu;
            next = *prev;
        }
        Some(total)
    };
    let mut rows: BTreeMap<(String, usize, u8), (BestRow, Vec<f64>)> = BTreeMap::new();
    for &(r, ref verdict) in per_job.values() {
        let label = labels[&r.plant_fingerprint].clone();
        let objective = r.options.objective;
        let (row, gammas) = rows.entry((label.clone(), r.order, objective as u8)).or_insert_with(|| {
            (BestRow { objective, ..BestRow::new(label, r.plant_fingerprint.clone(), r.order) }, Vec::new())
        });
        row.runs += 1;
        match verdict {
            Some(v @ Verdict::Verified { gamma, .. }) => {
                row.verified += 1;
                gammas.push(*gamma);
                row.offer(r, v, || chain_cpu_before(r));
            }
            _ if r.failed() => row.failed += 1,
            _ => row.unverified += 1,
        }
    }
    // Each objective's row also takes the other objective's controllers that solve its problem
    // (the row's job id then names that job; its counts stay those of its own jobs):
    // * a plain row, a strong job's: a stable K that stabilises is a plain solution too, so
    //   plain ≤ strong in every table;
    // * a strong row, a plain job's that is stable and whose controller term is inactive
    //   (ε‖K‖∞ ≤ γ at the job's ε): a solution of the strong problem with objective γ (CDP
    //   n_K = 1 in results/compleib: the strong job ended at 36.2 from its chained start, the
    //   plain job found γ = 3.95 with a stable K, ε‖K‖∞ = 1e-4).
    for &(r, ref verdict) in per_job.values() {
        let Some(v @ Verdict::Verified { gamma, k_hinf, controller_stable, .. }) = verdict else { continue };
        let other = match r.options.objective {
            ObjectiveKind::Strong => ObjectiveKind::Plain,
            ObjectiveKind::Plain if *controller_stable && r.eps * k_hinf <= *gamma => ObjectiveKind::Strong,
            ObjectiveKind::Plain => continue,
        };
        if let Some((row, _)) = rows.get_mut(&(labels[&r.plant_fingerprint].clone(), r.order, other as u8)) {
            row.offer(r, v, || chain_cpu_before(r));
        }
    }
    rows.into_values()
        .map(|(mut row, gammas)| {
            row.near_best = gammas.iter().filter(|&&g| g <= row.gamma * (1.0 + NEAR_BEST_RTOL)).count();
            row
        })
        .collect()
}

impl BestRow {
    /// Makes the verified record `r` (figures `verdict`) the row's best if its γ is lower
    /// (`chain_cpu_before`: the CPU seconds of the jobs it was started from, walked only then).
    fn offer(&mut self, r: &JobRecord, verdict: &Verdict, chain_cpu_before: impl FnOnce() -> Option<f64>) {
        let Verdict::Verified { gamma, alpha_k, k_hinf, controller_stable, plants, .. } = verdict else { return };
        if gamma >= &self.gamma {
            return;
        }
        self.gamma = *gamma;
        self.job_id = Some(r.job_id.0.clone());
        self.eps = Some(r.eps);
        self.seed = Some(r.seed);
        self.k_hinf = Some(*k_hinf);
        self.alpha_k = *alpha_k;
        self.controller_stable = Some(*controller_stable);
        self.plants = plants.clone();
        self.cpu_to_best_s = r.outcome().map(|o| o.search.cpu_to_best_s).filter(|t| t.is_finite());
        self.chain_cpu_to_best_s = self.cpu_to_best_s.zip(chain_cpu_before()).map(|(t, before)| t + before);
    }

    /// The row of a (plant, order) before any record: γ NaN, no best job, every count 0.
    pub fn new(plant: String, plant_fingerprint: String, order: usize) -> BestRow {
        BestRow {
            plant,
            plant_fingerprint,
            order,
            gamma: f64::NAN,
            job_id: None,
            eps: None,
            seed: None,
            k_hinf: None,
            alpha_k: None,
            cpu_to_best_s: None,
            chain_cpu_to_best_s: None,
            runs: 0,
            verified: 0,
            near_best: 0,
            failed: 0,
            unverified: 0,
            objective: ObjectiveKind::Strong,
            controller_stable: None,
            plants: Vec::new(),
        }
    }
}

impl Verdict {
    /// The recomputed γ of a verified record.
    pub fn gamma(&self) -> Option<f64> {
        match self {
            Verdict::Verified { gamma, .. } => Some(*gamma),
            Verdict::Rejected(_) => None,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::campaign::model::jobs::{job_id, RunnerTag};
    use crate::campaign::records::record::JobResult;
    use crate::design::DesignOptions;

    /// ẋ = −x + w + u, z = c·x, y = x: with K = 0, ‖Tzw‖∞ = c.
    fn plant(name: &str, c: f64) -> Arc<Plant> {
        plant_with_pole(name, -1.0, c)
    }

    /// ẋ = a·x + w + u, z = c·x, y = x.
    fn plant_with_pole(name: &str, a: f64, c: f64) -> Arc<Plant> {
        let text = format!(
            r#"{{"name":"{name}","dims":{{"n":1,"m1":1,"m2":1,"p1":1,"p2":1}},
            "A":[[{a:e}]],"B1":[[1]],"B2":[[1]],"C1":[[{c}]],"C2":[[1]],
            "D11":[[0]],"D12":[[0]],"D21":[[0]],"D22":[[0]]}}"#
        );
        Arc::new(Plant::from_json_str(&text, "test.json").unwrap())
    }

    /// A record of the zero static controller on `p`, journaled under plant name `name`.
    fn record(p: &Plant, name: &str, seed: u64) -> JobRecord {
        let options = DesignOptions { order: 0, seed, ..DesignOptions::default() };
        let fp = p.fingerprint();
        let id = job_id(&fp, &options, None, RunnerTag::Design);
        let mut v = serde_json::json!({
            "schema_version": 1, "job_id": id, "campaign": "t", "plant": name, "plant_fingerprint": fp,
            "order": 0, "eps": options.eps, "seed": seed, "cpumax": options.cpumax, "options": options,
            "warm_from": null, "warm_started": false, "status": {"kind": "optimised"},
            "gamma": 0.5, "k_hinf": 0.0, "alpha_cl": -1.0, "alpha_k": null, "objective": 0.5,
            "certificate": null, "iterations": 1, "evaluations": 1, "phases": [], "design_cpu_s": 0.0,
            "cpu_s": 0.0, "wall_s": 0.0, "finished_unix_s": 0.0,
            "controller": crate::lti::Controller::zeros(0, 1, 1).to_json(),
        });
        // a journal line of an older hinfix: no provenance
        v.as_object_mut().unwrap().remove("provenance");
        serde_json::from_value(v).unwrap()
    }

    fn map(plants: &[&Arc<Plant>]) -> PlantMap {
        plants.iter().map(|p| (p.fingerprint(), Arc::clone(p))).collect()
    }

    /// A problem of several plants is verified on each: K = 0 stabilises the stable plants, not
    /// the unstable one, and γ is the largest weighted value.
    #[test]
    fn a_problem_is_verified_on_every_plant() {
        use crate::design::PlantTerm;
        let (p1, p2, unstable) = (plant("P1", 1.0), plant("P2", 2.0), plant_with_pole("U", 1.0, 1.0));
        let problem = |plants: &[&Arc<Plant>], weights: &[f64]| Problem {
            terms: plants
                .iter()
                .zip(weights)
                .map(|(p, &weight)| PlantTerm { weight, ..PlantTerm::hinf((***p).clone()) })
                .collect(),
        };
        let rec = record(&p1, "P1+P2", 0);
        let Verdict::Verified { gamma, plants, .. } = verify_problem(&rec, &problem(&[&p1, &p2], &[3.0, 1.0])) else {
            panic!("K = 0 stabilises both")
        };
        assert_eq!(plants.len(), 2);
        assert!((plants[0].value - 1.0).abs() < 1e-9 && (plants[1].value - 2.0).abs() < 1e-9, "{plants:?}");
        assert!((gamma - 3.0).abs() < 1e-9, "γ = max(3·1, 1·2) = {gamma}");
        let Verdict::Rejected(why) = verify_problem(&rec, &problem(&[&p1, &unstable], &[1.0, 1.0])) else {
            panic!("K = 0 does not stabilise U")
        };
        assert!(why.starts_with("plant U: closed loop not stable"), "{why}");
        // best_per_problem takes the problem's γ and keeps each plant's value for plants.csv
        let mut problems = ProblemMap::new();
        problems.insert(rec.plant_fingerprint.clone(), Arc::new(problem(&[&p1, &p2], &[3.0, 1.0])));
        let rows = best_per_problem(std::slice::from_ref(&rec), &PlantMap::new(), &problems);
        assert_eq!((rows.len(), rows[0].plant.as_str(), rows[0].verified, rows[0].plants.len()), (1, "P1+P2", 1, 2));
        assert!((rows[0].gamma - 3.0).abs() < 1e-9);
    }

    #[test]
    fn two_plants_with_one_name_are_never_merged() {
        let (p1, p2) = (plant("P", 1.0), plant("P", 2.0));
        let recs = [record(&p1, "P", 0), record(&p2, "P", 0)];
        let rows = best_per_order(&recs, &map(&[&p1, &p2]));
        assert_eq!(rows.len(), 2, "{rows:?}");
        for (p, c) in [(&p1, 1.0), (&p2, 2.0)] {
            let fp = p.fingerprint();
            let row = rows.iter().find(|r| r.plant_fingerprint == fp).unwrap();
            assert_eq!(row.plant, format!("P@{}", &fp[..8]));
            assert_eq!((row.runs, row.verified), (1, 1));
            assert!((row.gamma - c).abs() < 1e-8, "{row:?}");
        }
    }

    #[test]
    fn a_renamed_plant_keeps_its_results_under_its_new_name() {
        let p = plant("NEW", 1.0);
        let recs = [record(&p, "OLD", 0), record(&p, "OLD", 1)];
        let rows = best_per_order(&recs, &map(&[&p]));
        assert_eq!(rows.len(), 1);
        assert_eq!((rows[0].plant.as_str(), rows[0].runs, rows[0].verified), ("NEW", 2, 2));
        assert!((rows[0].gamma - 1.0).abs() < 1e-8);
        // and a record of a plant the campaign no longer has does not verify against another
        let other = plant("NEW", 3.0);
        let rows = best_per_order(&[record(&other, "NEW", 0)], &map(&[&p]));
        assert_eq!((rows[0].verified, rows[0].failed, rows[0].unverified), (0, 0, 1));
    }

    /// `record` with the static gain `d` (γ = c/(1 − d)), `cpu_s` and a predecessor.
    fn gain_record(p: &Plant, seed: u64, d: f64, cpu_s: f64, warm_from: Option<&JobRecord>) -> JobRecord {
        let mut r = record(p, "P", seed);
        let JobResult::Designed(o) = &mut r.result else { unreachable!("a designed record") };
        o.controller.dk[(0, 0)] = d;
        o.search.cpu_to_best_s = 0.25;
        r.cpu_s = cpu_s;
        r.warm_from = warm_from.map(|w| w.job_id.clone());
        r.job_id = job_id(&p.fingerprint(), &r.options, r.warm_from.as_ref(), RunnerTag::Design);
        r
    }

    #[test]
    fn best_row_reports_the_best_controller_its_chain_cpu_and_the_replicates_near_it() {
        let p = plant("P", 1.0);
        // γ = 1/(1 − d): 2.0 (head), 1.0005/… and 1.01 (continued from the head), 1.0 (seed 3)
        let head = gain_record(&p, 0, 0.5, 10.0, None);
        let near = gain_record(&p, 1, 1.0 - 1.0 / 1.0005, 4.0, Some(&head));
        let far = gain_record(&p, 2, 1.0 - 1.0 / 1.01, 3.0, Some(&head));
        let best = gain_record(&p, 3, 0.0, 7.0, Some(&near));
        let rows = best_per_order(&[head, near, far, best.clone()], &map(&[&p]));
        let r = &rows[0];
        assert!((r.gamma - 1.0).abs() < 1e-9, "{r:?}");
        assert_eq!(r.job_id.as_deref(), Some(best.job_id.0.as_str()));
        assert_eq!((r.runs, r.verified, r.near_best), (4, 4, 2), "γ 1.0 and 1.0005 are within 0.1 %");
        assert!((r.k_hinf.unwrap() - 0.0).abs() < 1e-12 && r.alpha_k.is_none(), "static gain 0: ‖K‖∞ 0, no α_K");
        assert_eq!(r.cpu_to_best_s, Some(0.25));
        assert_eq!(r.chain_cpu_to_best_s, Some(10.0 + 4.0 + 0.25), "head and continued job, then its own 0.25 s");
        // a chain whose head is not in the journals has no chain figure
        let rows = best_per_order(&[gain_record(&p, 3, 0.0, 7.0, Some(&best))], &map(&[&p]));
        assert_eq!(rows[0].chain_cpu_to_best_s, None);
    }

    /// A plain row takes a strong job's controller of its (plant, order) when it is better (a
    /// stable K is a plain solution too), keeping its own counts; a strong-only campaign gets no
    /// plain row, and a better plain job keeps its row. A strong row takes a plain job's stable
    /// controller whose ε‖K‖∞ ≤ γ.
    #[test]
    fn a_plain_row_is_never_above_the_strong_row() {
        let p = plant("P", 1.0);
        let with = |objective, seed, d| {
            let mut r = gain_record(&p, seed, d, 1.0, None);
            r.options.objective = objective;
            r.job_id = job_id(&p.fingerprint(), &r.options, None, RunnerTag::Design);
            r
        };
        // γ = 1/(1 − d): plain 2.0, strong 1.0
        let (plain, strong) = (with(ObjectiveKind::Plain, 0, 0.5), with(ObjectiveKind::Strong, 1, 0.0));
        let rows = best_per_order(&[plain.clone(), strong.clone()], &map(&[&p]));
        let (s, pl) = (&rows[0], &rows[1]);
        assert_eq!((s.objective, pl.objective), (ObjectiveKind::Strong, ObjectiveKind::Plain));
        assert!((pl.gamma - 1.0).abs() < 1e-9 && pl.gamma == s.gamma, "{pl:?}");
        assert_eq!(pl.job_id.as_deref(), Some(strong.job_id.0.as_str()));
        assert_eq!((pl.runs, pl.verified, pl.controller_stable, pl.seed), (1, 1, Some(true), Some(1)));
        // strong only: no plain row
        assert_eq!(best_per_order(std::slice::from_ref(&strong), &map(&[&p])).len(), 1);
        // a better plain job keeps its own row
        let better = with(ObjectiveKind::Plain, 2, -1.0); // γ 0.5
        let rows = best_per_order(&[better.clone(), strong], &map(&[&p]));
        assert_eq!(rows[1].job_id.as_deref(), Some(better.job_id.0.as_str()));
        assert!((rows[1].gamma - 0.5).abs() < 1e-9);
        // and the strong row takes that plain job's controller: stable (a static gain), its
        // ε‖K‖∞ below its γ; its counts stay the strong jobs'
        assert_eq!(rows[0].objective, ObjectiveKind::Strong);
        assert_eq!(rows[0].job_id.as_deref(), Some(better.job_id.0.as_str()));
        assert!((rows[0].gamma - 0.5).abs() < 1e-9 && rows[0].runs == 1 && rows[0].controller_stable == Some(true));
        // unless its controller term is active at its ε: then it is no strong solution of value γ
        let mut costly = with(ObjectiveKind::Plain, 3, -1.0);
        costly.eps = 1e3; // ε‖K‖∞ = 1e3 · 1 > γ = 0.5
        let strong = with(ObjectiveKind::Strong, 1, 0.0);
        let rows = best_per_order(&[costly, strong.clone()], &map(&[&p]));
        assert_eq!(rows[0].job_id.as_deref(), Some(strong.job_id.0.as_str()));
    }

    #[test]
    fn duplicate_records_of_a_job_count_once_by_the_best_verified() {
        let p = plant("P", 1.0);
        let good = record(&p, "P", 0);
        let mut bad = good.clone();
        let JobResult::Designed(o) = &mut bad.result else { unreachable!("a designed record") };
        o.controller = crate::lti::Controller::zeros(0, 2, 2); // does not fit
        let rows = best_per_order(&[bad.clone(), good.clone(), bad], &map(&[&p]));
        assert_eq!((rows[0].runs, rows[0].verified, rows[0].failed), (1, 1, 0));
        assert_eq!(rows[0].job_id.as_deref(), Some(good.job_id.0.as_str()));
    }

    #[test]
    fn a_closed_loop_inside_the_stability_margin_is_not_verified() {
        // A closed loop with α = −4.4e-16 was called stable.
        let p = plant_with_pole("P", -4.4e-16, 1.0);
        let Verdict::Rejected(why) = verify(&record(&p, "P", 0), &p) else { panic!("α = −4.4e-16 verified") };
        assert!(why.contains("must be below −1.0e-12"), "{why}");
        let p = plant_with_pole("P", -1e-9, 1.0);
        assert!(matches!(verify(&record(&p, "P", 0), &p), Verdict::Verified { .. }));
    }

    /// A plain job (no stability asked of K) whose stabilising controller is unstable counts,
    /// with `controller_stable = false`, in a row of its own; the same controller in a strong
    /// job does not verify.
    #[test]
    fn a_plain_job_with_an_unstable_controller_counts_as_such() {
        // ẋ = −x + w + u, y = x; K: ẋk = 0.5 xk + y, u = −2 xk: A_cl = [[−1, −2], [1, 0.5]] is
        // stable (trace −0.5, det 1.5), Ak = 0.5 is not.
        let p = plant("P", 1.0);
        let unstable_k = |objective| {
            let mut rec = record(&p, "P", 0);
            rec.order = 1;
            rec.options = DesignOptions { order: 1, objective, ..rec.options.clone() };
            let JobResult::Designed(o) = &mut rec.result else { unreachable!("a designed record") };
            let mut k = crate::lti::Controller::zeros(1, 1, 1);
            (k.ak[(0, 0)], k.bk[(0, 0)], k.ck[(0, 0)]) = (0.5, 1.0, -2.0);
            o.controller = k;
            rec.job_id = job_id(&p.fingerprint(), &rec.options, None, RunnerTag::Design);
            rec
        };
        let plain = unstable_k(ObjectiveKind::Plain);
        assert!(matches!(verify(&plain, &p), Verdict::Verified { controller_stable: false, .. }));
        let strong = unstable_k(ObjectiveKind::Strong);
        assert!(matches!(verify(&strong, &p), Verdict::Rejected(_)));
        let rows = best_per_order(&[plain, strong], &map(&[&p]));
        assert_eq!(rows.len(), 2, "{rows:?}");
        let (s, pl) = (&rows[0], &rows[1]);
        assert_eq!((s.objective, s.verified, s.unverified, s.controller_stable), (ObjectiveKind::Strong, 0, 1, None));
        assert_eq!((pl.objective, pl.verified, pl.controller_stable), (ObjectiveKind::Plain, 1, Some(false)));
        assert!(pl.gamma.is_finite() && pl.k_hinf == Some(f64::INFINITY), "{pl:?}");
    }

    #[test]
    fn a_controller_of_another_order_than_its_job_is_rejected() {
        // An order-0 job's record carrying a stable order-2 controller was
        // re-verified and reported.
        let p = plant("P", 1.0);
        let mut rec = record(&p, "P", 0);
        let JobResult::Designed(o) = &mut rec.result else { unreachable!("a designed record") };
        o.controller = crate::lti::Controller::zeros(2, 1, 1);
        o.controller.ak[(0, 0)] = -1.0;
        o.controller.ak[(1, 1)] = -1.0;
        let Verdict::Rejected(why) = verify(&rec, &p) else { panic!("accepted an order-2 controller for order 0") };
        assert!(why.contains("order 2") && why.contains("order is 0"), "{why}");
        // blocks that disagree with each other (Bk of the wrong height)
        let mut rec = record(&p, "P", 0);
        let JobResult::Designed(o) = &mut rec.result else { unreachable!("a designed record") };
        o.controller.bk = faer::Mat::zeros(1, 1);
        let Verdict::Rejected(why) = verify(&rec, &p) else { panic!("accepted inconsistent blocks") };
        assert!(why.contains("BK is 1×1"), "{why}");
        // the journal's order and its options' order must agree
        let mut rec = record(&p, "P", 0);
        rec.order = 2;
        assert!(matches!(verify(&rec, &p), Verdict::Rejected(_)));
        assert!(matches!(verify(&record(&p, "P", 0), &p), Verdict::Verified { .. }));
    }
}
