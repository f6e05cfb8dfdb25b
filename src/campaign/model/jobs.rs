//! Job expansion and job identity.
//!
//! [`expand`] turns a [`Campaign`] into jobs in a deterministic, order-stable sequence: problems
//! in file order, then orders ascending, then ε and seeds in file order. The same file always
//! gives the same jobs in the same order, which a future `--shard i/N` needs (docs/ARCHITECTURE.md §2).
//!
//! A [`JobId`] is the SHA-256 (hex) of a canonical JSON document holding the plant fingerprint,
//! every [`DesignOptions`] field (order, ε, seed, cpumax, nrand, objective, tolerances …) and, for
//! a warm-started job, its predecessor's id. A changed plant, option or default therefore makes
//! new jobs instead of mixing results. Cosmetic changes (plant name, file formatting, problem
//! order in the file) keep the ids.
//!
//! A problem of several plants, or with another objective, weight or bound than H∞, 1, none, or
//! with a controller structure, adds a [`ProblemKey`] to the document: every plant's
//! fingerprint, objective, weight and bound, and the entries of the structure of the job's order.
//! The single-plant H∞ problem without a structure leaves it out, so its ids are those of the
//! builds before several plants.
//!
//! Warm start: with `warm_start = true`, order k of a (plant, ε, seed) chain starts from the
//! controller of the next lower order of the same chain (the paper did this for AC10; the paper
//! took the best controller over all runs, here the chain stays within one seed so that a job
//! still needs nothing but its spec and its predecessor, and chains can be sharded).
//!
//! Order chaining: with `order_chaining = true`, every job of the i-th order of a problem (i > 0,
//! orders ascending) also starts from the best controller of the (i−1)-th order at the same ε — at
//! every ε, whatever `warm_start` and `eps_continuation` do. Its [`Job::chain_from`] lists every
//! job of that order and ε (one per seed, in seed order); the scheduler starts the job only when
//! all of them have finished and passes the controller of the best of them (`campaign::chain`:
//! least re-verified γ, ties by job id), padded as `--init` pads. It is an incumbent of every such
//! job from the outset, so no job ends above it; the job of the first seed ([`Job::leads_chain`])
//! makes its local search first, every other seed after its own first starts, so that the seeds
//! stay independent searches rather than all refining the same start (`design::search` module
//! `given`). The list enters the job id (absent when empty, so the ids of campaigns without the key
//! do not change): what a job starts from is decided by its id's inputs alone, the same in one
//! sitting, resumed or sharded.

use std::fmt;
use std::sync::Arc;

use serde::Serialize;
use sha2::{Digest, Sha256};

use super::campaign::Campaign;
use crate::design::{DesignOptions, PlantObjective, PlantTerm, Structure};
use crate::lti::Plant;

/// Version of the id recipe; bump it if the hashed document changes meaning.
pub const JOB_ID_VERSION: u32 = 1;

/// Stable identity of a job (64 hex digits).
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, serde::Deserialize)]
#[serde(transparent)]
pub struct JobId(pub String);

impl JobId {
    /// The first 12 hex digits, for display.
    pub fn short(&self) -> &str {
        &self.0[..self.0.len().min(12)]
    }
}

impl fmt::Display for JobId {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

/// Which runner executes the jobs. Only the test hook's fake runner enters the job id, so its
/// results can never be mistaken for real ones.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RunnerTag {
    /// `design::Design` (production).
    Design,
    /// The deterministic fake runner of the machinery tests (`campaign::fake`; only the test-only
    /// binary examples/fake_campaign.rs runs it).
    Fake,
}

/// One design run of a campaign.
#[derive(Debug, Clone)]
pub struct Job {
    /// Identity (journal key, trace file name).
    pub id: JobId,
    /// Position in the expansion (stable for a given file).
    pub index: usize,
    /// Index of its problem in the campaign.
    pub problem: usize,
    /// Plant name (from the plant file), or the name of a problem of several plants.
    pub plant_name: String,
    /// The plant (the first plant of a problem of several).
    pub plant: Arc<Plant>,
    /// Its fingerprint (the problem's, [`super::campaign::Problem::fingerprint`]).
    pub plant_fingerprint: String,
    /// The problem of several plants (or another objective, weight or bound); `None`: the
    /// single-plant H∞ problem of `plant`.
    pub multi: Option<Arc<crate::design::Problem>>,
    /// The controller structure of the job's order, if the problem has one.
    pub structure: Option<Arc<Structure>>,
    /// Full options of the run, including order, ε, seed and cpumax.
    pub options: DesignOptions,
    /// The job whose controller this one starts from (warm-start chains).
    pub warm_from: Option<JobId>,
    /// Order chaining (module docs): the jobs of the order below at the same ε, of which the best
    /// verified controller is one more start; empty without `order_chaining`.
    pub chain_from: Vec<JobId>,
    /// Order chaining: whether its seed is the first of its problem's seeds, whose job makes its
    /// chained start's local search first (module docs). Not in the id: the id's inputs decide it
    /// (`chain_from` is in seed order, and each of its ids holds its seed).
    pub leads_chain: bool,
    /// The runner the id was made for.
    pub runner: RunnerTag,
}

impl Job {
    /// The jobs this one waits for: its `warm_from` predecessor, then its `chain_from` jobs.
    pub fn predecessors(&self) -> impl Iterator<Item = &JobId> {
        self.warm_from.iter().chain(&self.chain_from)
    }

    /// `HE1 n_K=2 ε=1e-3 seed=4`.
    pub fn label(&self) -> String {
        format!(
            "{} n_K={} ε={:e} seed={}",
            crate::campaign::leaves::sanitise::for_terminal(&self.plant_name),
            self.options.order,
            self.options.eps,
            self.options.seed
        )
    }
}

#[derive(Serialize)]
struct IdDoc<'a> {
    recipe: &'static str,
    version: u32,
    plant: &'a str,
    options: &'a DesignOptions,
    warm_from: Option<&'a str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    runner: Option<&'static str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    problem: Option<&'a ProblemKey>,
    #[serde(skip_serializing_if = "<[_]>::is_empty")]
    chain_from: &'a [JobId],
}

/// What a job id holds of a problem other than the single-plant H∞ one (module docs): per plant,
/// in the order of the campaign file, its fingerprint, objective, weight and bound; and the
/// entries of the structure (column-major Ak, Bk, Ck, Dk; `null` = free), if any.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ProblemKey {
    /// [`Plant::fingerprint`] of each plant.
    pub plants: Vec<String>,
    /// Each plant's objective.
    pub objectives: Vec<PlantObjective>,
    /// Each plant's weight.
    pub weights: Vec<f64>,
    /// Each plant's bound (`null`: none).
    pub bounds: Vec<Option<f64>>,
    /// The structure's entries for the job's order.
    pub structure: Option<Vec<Option<f64>>>,
}

impl ProblemKey {
    /// The key of `multi` (else the single-plant H∞ problem of `plant`) with `structure`; `None`
    /// for the single-plant H∞ problem without a structure, whose ids have no key.
    pub fn of(plant: &Plant, multi: Option<&crate::design::Problem>, structure: Option<&Structure>) -> Option<Self> {
        if multi.is_none() && structure.is_none() {
            return None;
        }
        let single = [PlantTerm::hinf(plant.clone())];
        let terms = multi.map_or(&single[..], |p| &p.terms[..]);
        Some(ProblemKey {
            plants: terms.iter().map(|t| t.plant.fingerprint()).collect(),
            objectives: terms.iter().map(|t| t.objective).collect(),
            weights: terms.iter().map(|t| t.weight).collect(),
            bounds: terms.iter().map(|t| t.bound).collect(),
            structure: structure.map(|s| s.entries().to_vec()),
        })
    }
}

/// SHA-256 (hex) of a document's canonical JSON: serde_json writes struct fields in declaration
/// order and floats in shortest round-trip form.
fn digest_hex<T: Serialize>(doc: &T) -> String {
    let bytes = serde_json::to_vec(doc).expect("id document serialises");
    Sha256::digest(&bytes).iter().map(|b| format!("{b:02x}")).collect()
}

/// The id of a job of the single-plant H∞ problem with these inputs.
pub fn job_id(plant_fingerprint: &str, options: &DesignOptions, warm_from: Option<&JobId>, runner: RunnerTag) -> JobId {
    problem_job_id(plant_fingerprint, None, options, warm_from, runner)
}

/// The id of a job with these inputs; `problem`: the [`ProblemKey`] of any other problem (None
/// is [`job_id`]).
pub fn problem_job_id(
    plant_fingerprint: &str,
    problem: Option<&ProblemKey>,
    options: &DesignOptions,
    warm_from: Option<&JobId>,
    runner: RunnerTag,
) -> JobId {
    chained_job_id(plant_fingerprint, problem, options, warm_from, &[], runner)
}

/// [`problem_job_id`] of a job with order chaining: `chain_from` the jobs of the order below
/// ([`Job::chain_from`]; empty: [`problem_job_id`]).
pub fn chained_job_id(
    plant_fingerprint: &str,
    problem: Option<&ProblemKey>,
    options: &DesignOptions,
    warm_from: Option<&JobId>,
    chain_from: &[JobId],
    runner: RunnerTag,
) -> JobId {
    JobId(digest_hex(&IdDoc {
        recipe: "hinfix-job",
        version: JOB_ID_VERSION,
        plant: plant_fingerprint,
        options,
        warm_from: warm_from.map(|j| j.0.as_str()),
        runner: match runner {
            RunnerTag::Design => None,
            RunnerTag::Fake => Some("fake"),
        },
        problem,
        chain_from,
    }))
}

/// The identity of a problem other than the single-plant H∞ one without a structure
/// ([`super::campaign::Problem::fingerprint`]): the SHA-256 of its plants' fingerprints,
/// objectives, weights and bounds ([`ProblemKey`] without a structure) and the SHA-256 of the
/// structure file's bytes, if any. Its journal records and report rows are grouped by it.
pub fn problem_fingerprint(key: &ProblemKey, structure_file: Option<&[u8]>) -> String {
    #[derive(Serialize)]
    struct Doc<'a> {
        recipe: &'static str,
        key: &'a ProblemKey,
        structure_file: Option<String>,
    }
    let key = ProblemKey { structure: None, ..key.clone() };
    let structure_file = structure_file.map(|b| Sha256::digest(b).iter().map(|b| format!("{b:02x}")).collect());
    digest_hex(&Doc { recipe: "hinfix-problem", key: &key, structure_file })
}

/// Expands a campaign into its jobs (see the module docs for the order and the chains).
pub fn expand(c: &Campaign, runner: RunnerTag) -> Vec<Job> {
    let mut jobs = Vec::new();
    for (pi, p) in c.problems.iter().enumerate() {
        let ns = p.seeds.len();
        // the job of the previous order at each (ε, seed), by position in p.eps × p.seeds
        let mut prev_order: Vec<Option<JobId>> = vec![None; p.eps.len() * ns];
        let mut first_order = true;
        let keys: std::collections::BTreeMap<usize, Option<ProblemKey>> = p
            .orders
            .iter()
            .map(|&o| (o, ProblemKey::of(&p.plant, p.multi.as_deref(), structure_of(p, o).as_deref())))
            .collect();
        for &order in &p.orders {
            // the jobs of this order so far, by the same position
            let mut this_order: Vec<Option<JobId>> = vec![None; p.eps.len() * ns];
            for (ei, &eps) in p.eps.iter().enumerate() {
                for (si, &seed) in p.seeds.iter().enumerate() {
                    let chain = ei * ns + si;
                    let continued = p.eps_continuation && ei > 0;
                    let warm_from = if continued {
                        this_order[chain - ns].clone()
                    } else if p.warm_start {
                        // with ε-continuation only the first ε of an order chains orders
                        prev_order[if p.eps_continuation { si } else { chain }].clone()
                    } else {
                        None
                    };
                    let mut options = DesignOptions { order, eps, seed, ..p.base.clone() };
                    if continued {
                        continuation_options(&mut options, p.continued_cpumax, p.continued_stall_starts);
                    }
                    // order chaining: every job of the order below at this ε
                    let chain_from: Vec<JobId> = if p.order_chaining && !first_order {
                        prev_order[ei * ns..(ei + 1) * ns].iter().flatten().cloned().collect()
                    } else {
                        Vec::new()
                    };
                    let key = keys.get(&order).and_then(Option::as_ref);
                    let id = chained_job_id(&p.fingerprint, key, &options, warm_from.as_ref(), &chain_from, runner);
                    this_order[chain] = Some(id.clone());
                    jobs.push(Job {
                        id,
                        index: jobs.len(),
                        problem: pi,
                        plant_name: p.name.clone(),
                        plant: p.plant.clone(),
                        plant_fingerprint: p.fingerprint.clone(),
                        multi: p.multi.clone(),
                        structure: structure_of(p, order),
                        options,
                        warm_from,
                        chain_from,
                        leads_chain: si == 0,
                        runner,
                    });
                }
            }
            prev_order = this_order;
            first_order = false;
        }
    }
    jobs
}

/// The structure of `order` of problem `p`, if it has one.
fn structure_of(p: &super::campaign::Problem, order: usize) -> Option<Arc<Structure>> {
    p.structure.as_ref().and_then(|s| s.per_order.get(&order).cloned())
}

/// The options of an ε-continued job: its CPU budget `continued_cpumax` and its stall rule
/// `continued_stall_starts` (each if given), and as first starts only its predecessor's
/// controller and HIFOO's `nrand` perturbations of it — no open-loop and central-controller
/// starts, which do not depend on ε and were made by the head of the chain.
fn continuation_options(options: &mut DesignOptions, continued_cpumax: Option<f64>, stall_starts: Option<usize>) {
    options.open_loop_start = false;
    options.central_gammas.clear();
    if let Some(c) = continued_cpumax {
        options.cpumax = c;
    }
    if let Some(n) = stall_starts {
        options.stall_starts = n;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::Path;

    fn campaign(text: &str) -> Campaign {
        Campaign::from_toml_str(text, Path::new("t.toml")).unwrap()
    }

    const TEXT: &str = r#"
name = "t"
[defaults]
eps = [1e-2, 1e-3]
seeds = 2
[[problem]]
plant = "HE1"
orders = [2, 1]
warm_start = true
[[problem]]
plant = "REA2"
orders = [1]
"#;

    #[test]
    fn expansion_is_deterministic_and_ordered() {
        let a = expand(&campaign(TEXT), RunnerTag::Design);
        let b = expand(&campaign(TEXT), RunnerTag::Design);
        assert_eq!(a.len(), 2 * 2 * 2 + 2 * 2);
        let ids = |v: &[Job]| v.iter().map(|j| j.id.clone()).collect::<Vec<_>>();
        assert_eq!(ids(&a), ids(&b));
        let keys: Vec<_> = a.iter().map(|j| (j.problem, j.options.order, j.options.eps, j.options.seed)).collect();
        assert_eq!(keys[0], (0, 1, 1e-2, 0));
        assert_eq!(keys[1], (0, 1, 1e-2, 1));
        assert_eq!(keys[2], (0, 1, 1e-3, 0));
        assert_eq!(keys[4], (0, 2, 1e-2, 0));
        assert_eq!(keys[8], (1, 1, 1e-2, 0));
        assert!(a.iter().enumerate().all(|(i, j)| j.index == i));
        let mut sorted = ids(&a);
        sorted.sort();
        sorted.dedup();
        assert_eq!(sorted.len(), a.len(), "ids are distinct");
    }

    #[test]
    fn warm_start_chains_within_eps_and_seed() {
        let jobs = expand(&campaign(TEXT), RunnerTag::Design);
        for j in &jobs {
            match (&j.warm_from, j.problem, j.options.order) {
                (None, 0, 1) | (None, 1, _) => {}
                (Some(prev), 0, 2) => {
                    let p = jobs.iter().find(|k| &k.id == prev).unwrap();
                    assert_eq!((p.options.order, p.options.eps, p.options.seed), (1, j.options.eps, j.options.seed));
                }
                other => panic!("unexpected chain {other:?}"),
            }
        }
    }

    #[test]
    fn eps_continuation_chains_eps_within_order_and_seed() {
        let text = TEXT.replace(
            "eps = [1e-2, 1e-3]",
            "eps = [1e-2, 1e-3, 1e-4]\neps_continuation = true\ncpumax = 300.0\ncontinued_cpumax = 30.0",
        );
        let jobs = expand(&campaign(&text), RunnerTag::Design);
        let by_id = |id: &JobId| jobs.iter().find(|k| &k.id == id).unwrap();
        let key = |j: &Job| (j.problem, j.options.order, j.options.eps, j.options.seed);
        for j in &jobs {
            let first_eps = j.options.eps == 1e-2;
            match (&j.warm_from, first_eps, j.problem, j.options.order) {
                // heads: no predecessor, or (HE1 warm-started) the first ε of the order below
                (None, true, 1, _) | (None, true, 0, 1) => {}
                (Some(prev), true, 0, 2) => assert_eq!(key(by_id(prev)), (0, 1, 1e-2, j.options.seed)),
                // continued: the previous ε of the same order and seed, before it in the expansion
                (Some(prev), false, _, _) => {
                    let p = by_id(prev);
                    assert!(p.index < j.index);
                    assert_eq!(
                        (p.problem, p.options.order, p.options.seed),
                        (j.problem, j.options.order, j.options.seed)
                    );
                    assert_eq!(p.options.eps, if j.options.eps == 1e-3 { 1e-2 } else { 1e-3 });
                }
                other => panic!("unexpected chain {other:?} for {}", j.label()),
            }
            // a continued job's first starts are its predecessor's controller and perturbations
            // of it; the head made the open-loop and central starts
            assert_eq!(j.options.open_loop_start, first_eps, "{}", j.label());
            assert_eq!(j.options.central_gammas.is_empty(), !first_eps, "{}", j.label());
            assert_eq!(j.options.cpumax, if first_eps { 300.0 } else { 30.0 }, "{}", j.label());
        }
        // without the key, the same file keeps today's jobs
        let plain = expand(&campaign(&text.replace("eps_continuation = true", "")), RunnerTag::Design);
        assert!(plain.iter().filter(|j| j.problem == 1).all(|j| j.warm_from.is_none()));
    }

    #[test]
    fn ids_are_stable_and_sensitive() {
        let jobs = expand(&campaign(TEXT), RunnerTag::Design);
        // Pinned: a change here means every journal in the world loses its resume keys.
        let he1 = &jobs[0];
        let again = job_id(&he1.plant_fingerprint, &he1.options, None, RunnerTag::Design);
        assert_eq!(he1.id, again);
        assert_eq!(he1.id.0.len(), 64);
        // cosmetic changes keep ids: reordering problems and re-listing orders
        let swapped = TEXT.replace("orders = [2, 1]", "orders = { from = 1, to = 2 }");
        assert_eq!(expand(&campaign(&swapped), RunnerTag::Design)[0].id, he1.id);
        // any option change makes a new id
        for (what, opts) in [
            ("cpumax", DesignOptions { cpumax: he1.options.cpumax + 1.0, ..he1.options.clone() }),
            ("eps", DesignOptions { eps: 1e-5, ..he1.options.clone() }),
            ("seed", DesignOptions { seed: 99, ..he1.options.clone() }),
            ("order", DesignOptions { order: 3, ..he1.options.clone() }),
            ("nrand", DesignOptions { nrand: 9, ..he1.options.clone() }),
        ] {
            assert_ne!(job_id(&he1.plant_fingerprint, &opts, None, RunnerTag::Design), he1.id, "{what}");
        }
        assert_ne!(job_id("other-plant", &he1.options, None, RunnerTag::Design), he1.id);
        assert_ne!(job_id(&he1.plant_fingerprint, &he1.options, None, RunnerTag::Fake), he1.id);
        let warm = &jobs[4];
        assert_ne!(job_id(&warm.plant_fingerprint, &warm.options, None, RunnerTag::Design), warm.id);
    }

    #[test]
    fn problem_keys_enter_the_id_only_when_there_is_one() {
        let c = campaign(TEXT);
        let jobs = expand(&c, RunnerTag::Design);
        let he1 = &jobs[0];
        assert!(he1.multi.is_none() && he1.structure.is_none());
        // the single-plant H∞ problem: no key, the id of the builds before
        assert_eq!(ProblemKey::of(&he1.plant, None, None), None);
        let id = |key: Option<&ProblemKey>| {
            problem_job_id(&he1.plant_fingerprint, key, &he1.options, None, RunnerTag::Design)
        };
        assert_eq!(id(None), he1.id);
        let p2 = &c.problems[1].plant;
        let two = crate::design::Problem {
            terms: vec![PlantTerm::hinf((*he1.plant).clone()), PlantTerm::hinf((**p2).clone())],
        };
        let base = ProblemKey::of(&he1.plant, Some(&two), None).unwrap();
        assert_eq!(base.plants, [he1.plant.fingerprint(), p2.fingerprint()]);
        let shape = crate::design::ControllerShape::for_plant(&he1.plant, 1);
        let variants = [
            ("objective", ProblemKey { objectives: vec![PlantObjective::Hinf, PlantObjective::H2], ..base.clone() }),
            ("weight", ProblemKey { weights: vec![1.0, 2.0], ..base.clone() }),
            ("bound", ProblemKey { bounds: vec![None, Some(3.0)], ..base.clone() }),
            (
                "structure",
                ProblemKey { structure: Some(Structure::all_free(shape).entries().to_vec()), ..base.clone() },
            ),
            ("plants", ProblemKey { plants: vec![he1.plant.fingerprint()], ..base.clone() }),
        ];
        let mut ids = vec![he1.id.clone(), id(Some(&base))];
        ids.extend(variants.iter().map(|(_, k)| id(Some(k))));
        let distinct: std::collections::BTreeSet<_> = ids.iter().collect();
        assert_eq!(distinct.len(), ids.len(), "{variants:?}");
        // a structure alone makes a key
        let s = Structure::all_free(shape);
        let key = ProblemKey::of(&he1.plant, None, Some(&s)).unwrap();
        assert_eq!((key.plants.len(), key.structure.as_deref()), (1, Some(s.entries())));
        // the problem's fingerprint takes the structure file, not one order's entries
        assert_eq!(
            problem_fingerprint(&key, Some(b"x")),
            problem_fingerprint(&ProblemKey { structure: None, ..key.clone() }, Some(b"x"))
        );
        assert_ne!(problem_fingerprint(&key, Some(b"x")), problem_fingerprint(&key, Some(b"y")));
        assert_ne!(problem_fingerprint(&key, None), he1.plant.fingerprint());
    }
}
