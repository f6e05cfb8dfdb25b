//! The validated campaign: what [`super::spec`] builds from a campaign file and
//! [`super::jobs::expand`] turns into jobs. Below both, so neither imports the other's types.

use std::collections::BTreeMap;
use std::path::PathBuf;
use std::sync::Arc;

use crate::campaign::leaves::trace_filter::TraceLevel;
use crate::design::{DesignOptions, Structure};
use crate::lti::Plant;

/// Default number of worker threads (`--threads` and `defaults.threads` override it).
pub const DEFAULT_THREADS: usize = 2;

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

fn floor_char_boundary(s: &str, mut i: usize) -> usize {
    while i > 0 && !s.is_char_boundary(i) {
        i -= 1;
    }
    i
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
    /// The `plant` value as written (the first of `plants`).
    pub plant_arg: String,
    /// The plant file it resolved to.
    pub plant_path: PathBuf,
    /// The loaded plant (the first of `plants`: it gives the controller's sizes and the
    /// starting points).
    pub plant: Arc<Plant>,
    /// The problem's identity in job ids and journal records: [`Plant::fingerprint`] of a
    /// single-plant H∞ problem without a structure (as it always was), else
    /// [`crate::campaign::problem_fingerprint`] of the plants, their objectives, weights and
    /// bounds and the structure file.
    pub fingerprint: String,
    /// The problem's name in tables, the journal's `plant` and job labels: the plant's name, or
    /// for several plants the `name` key (default: their names joined with `+`).
    pub name: String,
    /// Several plants, or an objective, weight or bound other than H∞, 1, none: every plant with
    /// its objective, weight and bound (`design::Problem`). `None`: the single-plant H∞ problem of
    /// `plant`.
    pub multi: Option<Arc<crate::design::Problem>>,
    /// The controller structure (`structure` key), loaded for each order of the problem.
    pub structure: Option<ProblemStructure>,
    /// Controller orders, ascending, distinct.
    pub orders: Vec<usize>,
    /// Weights ε, in file order, distinct.
    pub eps: Vec<f64>,
    /// Seeds, in file order, distinct.
    pub seeds: Vec<u64>,
    /// Chain orders: order k of a (plant, ε, seed) chain starts from the controller of the next
    /// lower order of the same chain.
    pub warm_start: bool,
    /// Continuation in ε: the job at the i-th ε of an (order, seed) starts from the controller of
    /// the (i−1)-th ε of the same order and seed (module docs of `campaign::jobs`).
    pub eps_continuation: bool,
    /// CPU budget of an ε-continued job (None: `base.cpumax`, as every other job).
    pub continued_cpumax: Option<f64>,
    /// Stall rule of an ε-continued job (`stall_starts`; None: `base.stall_starts`).
    pub continued_stall_starts: Option<usize>,
    /// Order chaining: every job of an order also starts from the best verified controller of
    /// the order below at the same ε (module docs of `campaign::jobs`).
    pub order_chaining: bool,
    /// Options common to all this problem's jobs (`order`, `eps`, `seed` are set per job).
    pub base: DesignOptions,
    /// How much of its jobs' iterations their traces keep (`trace`). Not a design option: it is
    /// not in `base` and never enters a job id.
    pub trace: TraceLevel,
    /// Where the problem's `plant` key is (for messages about the problem).
    pub location: Location,
}

/// A problem's `structure` key: the file, and the structure it gives each order of the problem.
#[derive(Debug, Clone)]
pub struct ProblemStructure {
    /// The file, resolved against the campaign file's folder.
    pub path: PathBuf,
    /// The structure for each order of the problem.
    pub per_order: BTreeMap<usize, Arc<Structure>>,
}

impl Campaign {
    /// Worker threads: the command line's, else the file's, else [`DEFAULT_THREADS`].
    pub fn threads(&self, cli: Option<usize>) -> usize {
        cli.or(self.threads).unwrap_or(DEFAULT_THREADS).max(1)
    }

    /// Trace level of each problem's jobs (indexed like [`Campaign::problems`]): the command
    /// line's for all, else the problem's `trace` (itself the problem's key, else the one in
    /// `[defaults]`, else [`TraceLevel::Sparse`]).
    pub fn trace_levels(&self, cli: Option<TraceLevel>) -> Vec<TraceLevel> {
        self.problems.iter().map(|p| cli.unwrap_or(p.trace)).collect()
    }
}
