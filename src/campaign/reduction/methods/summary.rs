//! The summary of a comparison of methods: per method the entries solved, failed and missing
//! and the geometric mean of its ratios to the best over the entries every method solved; per
//! pair of methods wins / ties / losses at a relative tolerance (a failure or a missing entry
//! counts as γ = +∞: it loses to any value and ties with another failure).

use super::table::{Cell, EntryRow};

/// The default relative tolerance of a tie.
pub const DEFAULT_RTOL: f64 = 1e-3;

/// One method's totals.
#[derive(Debug, Clone, PartialEq)]
pub struct MethodTotals {
    /// Entries it solved.
    pub solved: usize,
    /// Entries it has but did not solve.
    pub failed: usize,
    /// Entries it does not have.
    pub missing: usize,
    /// Entries on which it is within the tolerance of the best.
    pub best: usize,
    /// Geometric mean of γ / best-of-row over the entries every method solved (NaN if none).
    pub geomean_ratio: f64,
}

/// One pair of methods (a, b), a before b in the sources' order.
#[derive(Debug, Clone, PartialEq)]
pub struct PairTotals {
    /// Index of the first method.
    pub a: usize,
    /// Index of the second method.
    pub b: usize,
    /// Entries where a's γ is below b's by more than the tolerance (or only a solved it).
    pub wins: usize,
    /// Entries within the tolerance of each other (or both unsolved).
    pub ties: usize,
    /// Entries where b wins.
    pub losses: usize,
    /// Geometric mean of γ_a / γ_b over the entries every method solved (NaN if none).
    pub geomean_ratio: f64,
}

/// The whole summary.
#[derive(Debug, Clone, PartialEq)]
pub struct Summary {
    /// The tolerance of ties and of "best".
    pub rtol: f64,
    /// Number of entries.
    pub entries: usize,
    /// Entries every method solved.
    pub all_solved: usize,
    /// Per method, in the sources' order.
    pub methods: Vec<MethodTotals>,
    /// Per pair.
    pub pairs: Vec<PairTotals>,
}

/// Whether `a` beats (`Less`), ties with (`Equal`) or loses to (`Greater`) `b` at relative
/// tolerance `rtol`, +∞ standing for a failure.
pub fn outcome(a: f64, b: f64, rtol: f64) -> std::cmp::Ordering {
    use std::cmp::Ordering::*;
    match (a.is_finite(), b.is_finite()) {
        (false, false) => Equal,
        (true, false) => Less,
        (false, true) => Greater,
        (true, true) if a.max(b) <= a.min(b) * (1.0 + rtol) => Equal,
        (true, true) => a.total_cmp(&b),
    }
}

/// exp(mean(ln x)) of positive finite values; NaN for none.
pub fn geomean(values: impl IntoIterator<Item = f64>) -> f64 {
    let (sum, n) = values.into_iter().fold((0.0, 0usize), |(s, n), v| (s + v.ln(), n + 1));
    if n == 0 {
        f64::NAN
    } else {
        (sum / n as f64).exp()
    }
}

/// The summary of `rows` of `n` methods.
pub fn summarise(rows: &[EntryRow], n: usize, rtol: f64) -> Summary {
    let solved_rows: Vec<&EntryRow> = rows.iter().filter(|r| r.all_solved()).collect();
    let methods = (0..n)
        .map(|i| {
            let count = |f: &dyn Fn(&Cell) -> bool| rows.iter().filter(|r| f(&r.cells[i])).count();
            MethodTotals {
                solved: count(&|c| matches!(c, Cell::Solved { .. })),
                failed: count(&|c| *c == Cell::Failed),
                missing: count(&|c| *c == Cell::Missing),
                best: rows.iter().filter(|r| r.is_best(i, rtol)).count(),
                geomean_ratio: geomean(solved_rows.iter().map(|r| r.ratios()[i])),
            }
        })
        .collect();
    let mut pairs = Vec::new();
    for a in 0..n {
        for b in a + 1..n {
            let mut p = PairTotals { a, b, wins: 0, ties: 0, losses: 0, geomean_ratio: f64::NAN };
            for r in rows {
                match outcome(r.cells[a].gamma(), r.cells[b].gamma(), rtol) {
                    std::cmp::Ordering::Less => p.wins += 1,
                    std::cmp::Ordering::Equal => p.ties += 1,
                    std::cmp::Ordering::Greater => p.losses += 1,
                }
            }
            p.geomean_ratio = geomean(solved_rows.iter().map(|r| r.cells[a].gamma() / r.cells[b].gamma()));
            pairs.push(p);
        }
    }
    Summary { rtol, entries: rows.len(), all_solved: solved_rows.len(), methods, pairs }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::campaign::reduction::methods::table::Match;
    use crate::design::ObjectiveKind;

    fn row(cells: Vec<Cell>) -> EntryRow {
        EntryRow {
            plant: "P".into(),
            fingerprint: None,
            order: 1,
            objective: ObjectiveKind::Strong,
            matched: Match::Name,
            cells,
        }
    }

    fn s(g: f64) -> Cell {
        Cell::Solved { gamma: g, cpu_s: None }
    }

    #[test]
    fn wins_ties_losses_and_geometric_means() {
        let rows = vec![
            row(vec![s(1.0), s(2.0)]),              // a wins
            row(vec![s(4.0), s(1.0)]),              // b wins
            row(vec![s(1.0), s(1.0005)]),           // tie at 1e-3
            row(vec![Cell::Failed, s(3.0)]),        // b wins
            row(vec![Cell::Missing, Cell::Failed]), // tie: neither solved
        ];
        let sm = summarise(&rows, 2, 1e-3);
        assert_eq!((sm.entries, sm.all_solved), (5, 3));
        let p = &sm.pairs[0];
        assert_eq!((p.wins, p.ties, p.losses), (1, 2, 2));
        // γa/γb over the three rows both solved: 0.5, 4, 1/1.0005
        let want = (0.5f64 * 4.0 / 1.0005).powf(1.0 / 3.0);
        assert!((p.geomean_ratio - want).abs() < 1e-15, "{}", p.geomean_ratio);
        // ratios to best: a 1, 4, 1; b 2, 1, 1.0005
        assert!((sm.methods[0].geomean_ratio - 4f64.powf(1.0 / 3.0)).abs() < 1e-15);
        assert!((sm.methods[1].geomean_ratio - (2.0f64 * 1.0005).powf(1.0 / 3.0)).abs() < 1e-15);
        assert_eq!((sm.methods[0].solved, sm.methods[0].failed, sm.methods[0].missing), (3, 1, 1));
        assert_eq!((sm.methods[0].best, sm.methods[1].best), (2, 3));
        // at a tighter tolerance the third row is a win
        let p = &summarise(&rows, 2, 1e-4).pairs[0];
        assert_eq!((p.wins, p.ties, p.losses), (2, 1, 2));
    }

    #[test]
    fn geomean_of_nothing_is_nan() {
        assert!(geomean([]).is_nan());
        assert_eq!(geomean([2.0, 8.0]), 4.0);
    }
}
