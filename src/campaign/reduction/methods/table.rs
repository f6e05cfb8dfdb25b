//! The entries of a comparison of methods: the sources' values matched by (plant, order,
//! objective) into rows, each method's ratio to the best of its row. A plant is matched by
//! content fingerprint where both sides give one (two plants of one name and different
//! fingerprints are two entries), by name otherwise, and such a row is marked
//! [`Match::Name`].

use super::source::Source;
use crate::design::ObjectiveKind;

/// How the values of a row were matched.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Match {
    /// Only one source has the entry.
    Single,
    /// Every pair of sources of the row gave the plant's fingerprint, and they agree.
    Fingerprint,
    /// At least one source gave no fingerprint: the plant was matched by name only.
    Name,
}

impl Match {
    /// The word in the tables.
    pub fn name(self) -> &'static str {
        match self {
            Match::Single => "single",
            Match::Fingerprint => "fingerprint",
            Match::Name => "name",
        }
    }
}

/// One method's value in a row.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Cell {
    /// The source has no such entry.
    Missing,
    /// The source has it but found no (strongly) stabilising controller.
    Failed,
    /// γ, and the CPU seconds when known.
    Solved {
        /// γ.
        gamma: f64,
        /// CPU seconds.
        cpu_s: Option<f64>,
    },
}

impl Cell {
    /// γ, or +∞ for a missing or failed entry (Dolan & Moré's convention).
    pub fn gamma(self) -> f64 {
        match self {
            Cell::Solved { gamma, .. } => gamma,
            _ => f64::INFINITY,
        }
    }

    /// CPU seconds of a solved entry, +∞ for a missing or failed one, NaN when unknown.
    pub fn cpu(self) -> f64 {
        match self {
            Cell::Solved { cpu_s, .. } => cpu_s.unwrap_or(f64::NAN),
            _ => f64::INFINITY,
        }
    }
}

/// One entry (plant, order, objective) with every method's value.
#[derive(Debug, Clone, PartialEq)]
pub struct EntryRow {
    /// Plant name (the first source's that has the entry).
    pub plant: String,
    /// The plant's fingerprint, when a source gave it.
    pub fingerprint: Option<String>,
    /// n_K.
    pub order: usize,
    /// Objective.
    pub objective: ObjectiveKind,
    /// How the sources were matched.
    pub matched: Match,
    /// One cell per source, in the sources' order.
    pub cells: Vec<Cell>,
}

impl EntryRow {
    /// The best γ of the row (+∞ when no method solved it).
    pub fn best(&self) -> f64 {
        self.cells.iter().map(|c| c.gamma()).fold(f64::INFINITY, f64::min)
    }

    /// Each method's γ divided by the row's best: 1 for the best, +∞ for a failure or a missing
    /// entry (and for every method when none solved the entry).
    pub fn ratios(&self) -> Vec<f64> {
        ratios_to_best(&self.cells.iter().map(|c| c.gamma()).collect::<Vec<_>>())
    }

    /// Whether every method solved the entry.
    pub fn all_solved(&self) -> bool {
        self.cells.iter().all(|c| matches!(c, Cell::Solved { .. }))
    }

    /// Whether method `i` is within a relative `rtol` of the row's best.
    pub fn is_best(&self, i: usize, rtol: f64) -> bool {
        let g = self.cells[i].gamma();
        g.is_finite() && g <= self.best() * (1.0 + rtol)
    }
}

/// `values` divided by their least value; +∞ stays +∞ (so does everything when nothing is
/// finite). A NaN value (unknown) stays NaN.
pub fn ratios_to_best(values: &[f64]) -> Vec<f64> {
    let best = values.iter().copied().filter(|v| !v.is_nan()).fold(f64::INFINITY, f64::min);
    values
        .iter()
        .map(|&v| match v.is_nan() {
            true => f64::NAN,
            false if best.is_finite() && v.is_finite() => v / best,
            false => f64::INFINITY,
        })
        .collect()
}

/// Matches the sources' entries into rows, in the order of first appearance (the first
/// source's entries first).
pub fn entry_rows(sources: &[Source]) -> Vec<EntryRow> {
    let n = sources.len();
    let mut rows: Vec<EntryRow> = Vec::new();
    for (s, src) in sources.iter().enumerate() {
        for e in &src.entries {
            let same_plant = |r: &EntryRow| match (&r.fingerprint, &e.fingerprint) {
                (Some(a), Some(b)) => a == b,
                _ => r.plant == e.plant,
            };
            let found = rows.iter_mut().position(|r| {
                r.order == e.order && r.objective == e.objective && r.cells[s] == Cell::Missing && same_plant(r)
            });
            let cell = if e.solved() { Cell::Solved { gamma: e.gamma, cpu_s: e.cpu_s } } else { Cell::Failed };
            match found {
                Some(i) => {
                    let r = &mut rows[i];
                    let by_fingerprint = r.fingerprint.is_some() && e.fingerprint.is_some();
                    r.matched = match (r.matched, by_fingerprint) {
                        (Match::Name, _) | (_, false) => Match::Name,
                        _ => Match::Fingerprint,
                    };
                    if r.fingerprint.is_none() {
                        r.fingerprint.clone_from(&e.fingerprint);
                    }
                    r.cells[s] = cell;
                }
                None => {
                    let mut cells = vec![Cell::Missing; n];
                    cells[s] = cell;
                    rows.push(EntryRow {
                        plant: e.plant.clone(),
                        fingerprint: e.fingerprint.clone(),
                        order: e.order,
                        objective: e.objective,
                        matched: Match::Single,
                        cells,
                    });
                }
            }
        }
    }
    rows
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::campaign::reduction::methods::source::SourceEntry;
    use std::path::PathBuf;

    fn entry(plant: &str, fp: Option<&str>, order: usize, gamma: f64) -> SourceEntry {
        SourceEntry {
            plant: plant.into(),
            fingerprint: fp.map(String::from),
            order,
            objective: ObjectiveKind::Strong,
            gamma,
            cpu_s: None,
            stable: None,
        }
    }

    fn source(label: &str, entries: Vec<SourceEntry>) -> Source {
        Source { label: label.into(), path: PathBuf::from(label), entries }
    }

    #[test]
    fn rows_match_by_fingerprint_then_name() {
        let a = source("a", vec![entry("P", Some("f1"), 1, 2.0), entry("Q", Some("f2"), 1, 3.0)]);
        // R is P renamed (same fingerprint); Q here is another plant of the same name; S has no
        // fingerprint and is matched by name
        let b =
            source("b", vec![entry("R", Some("f1"), 1, 4.0), entry("Q", Some("f9"), 1, 1.0), entry("P", None, 2, 1.0)]);
        let c = source("c", vec![entry("P", None, 1, f64::INFINITY)]);
        let rows = entry_rows(&[a, b, c]);
        assert_eq!(rows.len(), 4);
        assert_eq!(rows[0].plant, "P");
        assert_eq!(rows[0].matched, Match::Name);
        assert_eq!(
            rows[0].cells,
            vec![Cell::Solved { gamma: 2.0, cpu_s: None }, Cell::Solved { gamma: 4.0, cpu_s: None }, Cell::Failed]
        );
        assert_eq!(rows[0].ratios(), vec![1.0, 2.0, f64::INFINITY]);
        assert_eq!(rows[1].matched, Match::Single);
        assert_eq!(rows[2].fingerprint.as_deref(), Some("f9"));
        assert_eq!(rows[3].cells[0], Cell::Missing);
        assert!(!rows[3].all_solved());
    }

    #[test]
    fn ratios_are_to_the_least_value() {
        assert_eq!(ratios_to_best(&[3.0, 1.5, f64::INFINITY]), vec![2.0, 1.0, f64::INFINITY]);
        assert_eq!(ratios_to_best(&[f64::INFINITY, f64::INFINITY]), vec![f64::INFINITY; 2]);
        let r = ratios_to_best(&[f64::NAN, 2.0]);
        assert!(r[0].is_nan() && r[1] == 1.0);
    }
}
