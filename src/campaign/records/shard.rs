//! `--shard K/N`: a deterministic partition of a campaign's jobs into N parts, for running one
//! campaign as N processes (e.g. a Slurm job array, one task per shard).
//!
//! * The unit is the chain: jobs linked by waiting for one another (a job and every job
//!   warm-started from it, transitively; with order chaining, every job of an order and ε with
//!   those of the order below at that ε, so that a problem's chained jobs stay together), so a
//!   chain never spans shards; a job that waits for none and that none waits for is a chain of
//!   one.
//! * Chains are dealt out by longest-processing-time first: in decreasing total budget (Σ
//!   cpumax; ties by first job), each to the shard with the smallest total so far (ties to the
//!   lower shard). This balances the shards' CPU budgets, which is what bounds an array's wall
//!   time; with equal chains it is round-robin.
//! * The partition depends only on the job list, i.e. on the campaign file: every shard computes
//!   the same one, on any machine. Within a shard the jobs keep the campaign's order.
//!
//! Shards may share one results folder (claims make that safe anyway) or write to separate ones,
//! merged later with `campaign report --journal`.

use std::collections::HashMap;
use std::fmt;
use std::str::FromStr;

use crate::campaign::model::jobs::{Job, JobId};

/// Shard K of N (1-based).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Shard {
    /// This shard, 1..=n.
    pub k: usize,
    /// Number of shards, ≥ 1.
    pub n: usize,
}

/// A `--shard` value that is not `K/N` with 1 ≤ K ≤ N.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("invalid shard {text:?}: {reason} (expected K/N with 1 <= K <= N, e.g. 2/8)")]
pub struct ShardError {
    /// The value given.
    pub text: String,
    /// What is wrong.
    pub reason: ShardProblem,
}

/// What is wrong with a `--shard` value.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum ShardProblem {
    /// No `/` between K and N.
    #[error("no '/'")]
    NoSlash,
    /// K does not parse.
    #[error("K is not a whole number")]
    BadK,
    /// N does not parse.
    #[error("N is not a whole number")]
    BadN,
    /// N = 0.
    #[error("N must be at least 1")]
    ZeroN,
    /// K = 0 or K > N.
    #[error("K must be between 1 and N")]
    KOutOfRange,
}

impl FromStr for Shard {
    type Err = ShardError;
    fn from_str(text: &str) -> Result<Shard, ShardError> {
        let bad = |reason: ShardProblem| ShardError { text: text.to_string(), reason };
        let (k, n) = text.trim().split_once('/').ok_or_else(|| bad(ShardProblem::NoSlash))?;
        let k: usize = k.trim().parse().map_err(|_| bad(ShardProblem::BadK))?;
        let n: usize = n.trim().parse().map_err(|_| bad(ShardProblem::BadN))?;
        if n == 0 {
            return Err(bad(ShardProblem::ZeroN));
        }
        if k == 0 || k > n {
            return Err(bad(ShardProblem::KOutOfRange));
        }
        Ok(Shard { k, n })
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.k, self.n)
    }
}

/// The shard (0-based) of every job, in job order (see the module docs).
pub fn assign(jobs: &[Job], n: usize) -> Vec<usize> {
    let n = n.max(1);
    // chain root of every job: the smallest index of the jobs linked to it by waiting (union-find
    // over the links to earlier jobs; a job with one predecessor gets its predecessor's root)
    let pos: HashMap<&JobId, usize> = jobs.iter().enumerate().map(|(i, j)| (&j.id, i)).collect();
    let mut parent: Vec<usize> = (0..jobs.len()).collect();
    fn find(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for (i, j) in jobs.iter().enumerate() {
        for &p in j.predecessors().filter_map(|p| pos.get(p)).filter(|&&p| p < i) {
            let (a, b) = (find(&mut parent, p), find(&mut parent, i));
            parent[a.max(b)] = a.min(b);
        }
    }
    let root: Vec<usize> = (0..jobs.len()).map(|i| find(&mut parent, i)).collect();
    let mut cost: Vec<(usize, f64)> = Vec::new(); // (root, Σ cpumax), roots ascending
    let mut slot: HashMap<usize, usize> = HashMap::new();
    for (i, j) in jobs.iter().enumerate() {
        let s = *slot.entry(root[i]).or_insert_with(|| {
            cost.push((root[i], 0.0));
            cost.len() - 1
        });
        cost[s].1 += j.options.cpumax;
    }
    let mut order: Vec<usize> = (0..cost.len()).collect();
    order.sort_by(|&a, &b| cost[b].1.total_cmp(&cost[a].1).then(cost[a].0.cmp(&cost[b].0)));
    let mut load = vec![0.0f64; n];
    let mut shard_of_root: HashMap<usize, usize> = HashMap::new();
    for c in order {
        let best = (0..n).min_by(|&a, &b| load[a].total_cmp(&load[b]).then(a.cmp(&b))).expect("n ≥ 1");
        load[best] += cost[c].1;
        shard_of_root.insert(cost[c].0, best);
    }
    root.iter().map(|r| shard_of_root[r]).collect()
}

/// The jobs of `shard`, in campaign order.
pub fn select(jobs: &[Job], shard: Shard) -> Vec<Job> {
    let a = assign(jobs, shard.n);
    jobs.iter().zip(a).filter(|(_, s)| *s + 1 == shard.k).map(|(j, _)| j.clone()).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::campaign::{expand, Campaign, RunnerTag};
    use std::collections::HashSet;
    use std::path::Path;

    const TEXT: &str = r#"
name = "t"
[defaults]
eps = [1e-2, 1e-3]
seeds = 3
cpumax = 10.0
[[problem]]
plant = "HE1"
orders = { from = 1, to = 4 }
warm_start = true
[[problem]]
plant = "REA2"
orders = [1, 2]
cpumax = 5.0
[[problem]]
plant = "Enns"
orders = [1]
"#;

    fn jobs() -> Vec<Job> {
        expand(&Campaign::from_toml_str(TEXT, Path::new("t.toml")).unwrap(), RunnerTag::Design)
    }

    #[test]
    fn parse_accepts_k_of_n_and_refuses_the_rest() {
        assert_eq!("2/8".parse::<Shard>().unwrap(), Shard { k: 2, n: 8 });
        assert_eq!(" 1 / 1 ".parse::<Shard>().unwrap(), Shard { k: 1, n: 1 });
        for bad in ["0/3", "4/3", "1/0", "2", "a/3", "1/b", "-1/3", ""] {
            let e = bad.parse::<Shard>().unwrap_err();
            assert!(e.to_string().contains("K/N"), "{bad}: {e}");
        }
    }

    #[test]
    fn shards_are_disjoint_cover_the_campaign_and_keep_chains() {
        let jobs = jobs();
        assert_eq!(jobs.len(), 4 * 6 + 2 * 6 + 6);
        for n in 1..=7 {
            let parts: Vec<Vec<Job>> = (1..=n).map(|k| select(&jobs, Shard { k, n })).collect();
            let mut seen = HashSet::new();
            for (k, part) in parts.iter().enumerate() {
                let ids: HashSet<&JobId> = part.iter().map(|j| &j.id).collect();
                for j in part {
                    assert!(seen.insert(j.id.clone()), "n={n}: job {} in two shards", j.label());
                    for p in j.predecessors() {
                        assert!(ids.contains(p), "n={n} shard {}: chain of {} split", k + 1, j.label());
                    }
                }
                // campaign order kept
                assert!(part.windows(2).all(|w| w[0].index < w[1].index));
            }
            assert_eq!(seen.len(), jobs.len(), "n={n}: union is the campaign");
            // deterministic
            assert_eq!(assign(&jobs, n), assign(&self::jobs(), n));
        }
    }

    #[test]
    fn shards_balance_the_cpu_budget() {
        let jobs = jobs();
        // 6 HE1 chains of 40 s, 12 REA2 jobs of 5 s, 6 Enns jobs of 10 s: 360 s in all.
        let a = assign(&jobs, 3);
        let mut load = [0.0; 3];
        for (j, s) in jobs.iter().zip(&a) {
            load[*s] += j.options.cpumax;
        }
        assert_eq!(load.iter().sum::<f64>(), 360.0);
        assert!(load.iter().all(|l| (*l - 120.0).abs() <= 10.0), "{load:?}");
    }
}
