//! Order chaining (`order_chaining = true`, campaigns/FORMAT.md): on a small real-design
//! campaign under an evaluation budget (deterministic), every job of an order starts from the
//! best verified controller of the order below at its ε, chosen by (γ, job id) (the first seed's
//! job making its local search first, the others after their own first starts); it never ends
//! above that controller's objective; the best-γ table is non-increasing in n_K; and a resumed
//! run and a run in two shards journal the very records of one sitting.

use std::collections::{BTreeMap, HashMap};
use std::path::Path;

use hinfix::campaign::{
    best_per_order, design_job, execute, expand, no_observers, shard_jobs, verify, Campaign, ExecuteOptions, Job,
    JobId, JobRecord, PlantMap, RunnerTag, Shard, Solo, Verdict,
};

const TEXT: &str = r#"
name = "chain"
[defaults]
eps = [1e-2, 1e-4]
seeds = 2
cpumax = 1000.0
maxevals = 1500
stall_starts = 3
spend_budget = false
eps_continuation = true
order_chaining = true

[[problem]]
plant = "HE1"
orders = [1, 2, 3]

[[problem]]
plant = "REA2"
orders = [1, 2]
"#;

fn campaign(text: &str) -> Campaign {
    std::env::set_var("HINFIX_PLANTS", concat!(env!("CARGO_MANIFEST_DIR"), "/plants"));
    Campaign::from_toml_str(text, Path::new("chain.toml")).unwrap()
}

/// Runs `jobs` (those in `done` skipped) on `threads` workers; returns every record by job id.
fn run(jobs: &[Job], done: &HashMap<JobId, JobRecord>, threads: usize) -> BTreeMap<JobId, JobRecord> {
    let mut out = BTreeMap::new();
    let opts = ExecuteOptions::new("chain", threads);
    let stats = execute(jobs, done, &design_job, &no_observers, &mut Solo, &opts, |ev| {
        if let hinfix::campaign::CampaignEvent::JobFinished { record, .. } = ev {
            out.insert(record.job_id.clone(), *record);
        }
        Ok::<(), std::convert::Infallible>(())
    })
    .unwrap();
    assert_eq!(stats.failed, 0);
    out
}

fn comparable(records: &BTreeMap<JobId, JobRecord>) -> BTreeMap<JobId, serde_json::Value> {
    records.iter().map(|(id, r)| (id.clone(), r.comparable())).collect()
}

/// (γ, ‖K‖∞) re-verified as the report does.
fn figures(r: &JobRecord, plants: &PlantMap) -> Option<(f64, f64)> {
    match verify(r, &plants[&r.plant_fingerprint]) {
        Verdict::Verified { gamma, k_hinf, .. } => Some((gamma, k_hinf)),
        Verdict::Rejected(_) => None,
    }
}

#[test]
fn chained_jobs_start_from_the_best_of_the_order_below_and_tables_do_not_rise() {
    let c = campaign(TEXT);
    let jobs = expand(&c, RunnerTag::Design);
    assert_eq!(jobs.len(), (3 + 2) * 2 * 2);
    let plants: PlantMap = jobs.iter().map(|j| (j.plant_fingerprint.clone(), j.plant.clone())).collect();
    let whole = run(&jobs, &HashMap::new(), 2);
    assert_eq!(whole.len(), jobs.len());

    for j in &jobs {
        let r = &whole[&j.id];
        // the first seed's job makes its chained start's local search first, the others last
        assert_eq!(j.leads_chain, j.options.seed == 0, "{}", j.label());
        if j.chain_from.is_empty() {
            assert_eq!(r.chained_from, None, "{}", j.label());
            continue;
        }
        // the chained start is the least verified γ of the order below at this ε, ties by id
        let below: Vec<(&JobId, f64)> =
            j.chain_from.iter().filter_map(|id| figures(&whole[id], &plants).map(|(g, _)| (id, g))).collect();
        let want = below.iter().min_by(|a, b| a.1.total_cmp(&b.1).then(a.0.cmp(b.0))).map(|(id, _)| (*id).clone());
        assert_eq!(r.chained_from, want, "{}", j.label());
        for id in &j.chain_from {
            let p = &whole[id];
            assert_eq!(
                (p.order + 1, p.eps, p.plant_fingerprint.as_str()),
                (j.options.order, j.options.eps, j.plant_fingerprint.as_str())
            );
        }
        // never above the objective of the start it was given: max(γ, ε‖K‖∞) at the same ε
        let src = &whole[want.as_ref().expect("the order below verified")];
        let (g, kh) = figures(src, &plants).unwrap();
        let f_start = g.max(j.options.eps * kh);
        let (g1, kh1) = figures(r, &plants).expect("a chained job verifies");
        let f = g1.max(j.options.eps * kh1);
        assert!(f <= f_start * (1.0 + 1e-9), "{}: {f} above its chained start's {f_start}", j.label());
    }

    // the best-γ table is non-increasing in n_K for each plant
    let rows = best_per_order(&whole.values().cloned().collect::<Vec<_>>(), &plants);
    assert_eq!(rows.len(), 5);
    for w in rows.windows(2).filter(|w| w[0].plant == w[1].plant) {
        assert!(
            w[1].gamma <= w[0].gamma * (1.0 + 1e-9),
            "{} n_K={} {} > n_K={} {}",
            w[0].plant,
            w[1].order,
            w[1].gamma,
            w[0].order,
            w[0].gamma
        );
    }

    // resumed: the first half journaled, the rest run again, the same records
    let half: HashMap<JobId, JobRecord> =
        jobs.iter().take(jobs.len() / 2).map(|j| (j.id.clone(), whole[&j.id].clone())).collect();
    let mut resumed = run(&jobs, &half, 1);
    resumed.extend(half);
    assert_eq!(comparable(&resumed), comparable(&whole));

    // sharded: each shard on its own, with nothing of the other, the same records
    let mut sharded = BTreeMap::new();
    for k in 1..=2 {
        let part = shard_jobs(&jobs, Shard { k, n: 2 });
        assert!(!part.is_empty() && part.len() < jobs.len());
        sharded.extend(run(&part, &HashMap::new(), 1));
    }
    assert_eq!(comparable(&sharded), comparable(&whole));
}

#[test]
fn without_the_key_ids_and_starts_are_unchanged() {
    let on = expand(&campaign(TEXT), RunnerTag::Design);
    let off = expand(&campaign(&TEXT.replace("order_chaining = true", "")), RunnerTag::Design);
    let explicit_off =
        expand(&campaign(&TEXT.replace("order_chaining = true", "order_chaining = false")), RunnerTag::Design);
    assert!(off.iter().all(|j| j.chain_from.is_empty()));
    let ids = |v: &[Job]| v.iter().map(|j| j.id.clone()).collect::<Vec<_>>();
    assert_eq!(ids(&off), ids(&explicit_off));
    // the lowest order does not chain, so its ids are those without the key; every other differs
    for (a, b) in on.iter().zip(&off) {
        assert_eq!(a.id == b.id, a.chain_from.is_empty(), "{}", a.label());
        assert_eq!(a.chain_from.len(), if a.options.order == 1 { 0 } else { 2 }, "{}", a.label());
    }
}
