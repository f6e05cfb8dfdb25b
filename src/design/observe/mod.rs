//! Watching a design run: the one iteration record ([`DesignIterRecord`], the optimiser's
//! [`Iteration`] extended with the design's phase and the objective's components), the one
//! observer trait ([`DesignObserver`]), where the best objective value so far is tracked
//! ([`BestSoFar`], once per run, by `objective::ObserverAdapter`, which fills the record's
//! `improved`), and which iterations an observer is told of, as configuration
//! ([`ObserverMode`], applied by [`ModeFilter`] and [`Observed`]).
//!
//! The stream: `optim::Observer` → `objective::ObserverAdapter` (the one translation: components
//! from the objective's cache, run-wide evaluation count, best so far) → a [`DesignObserver`]
//! (the campaign's worker observer, which passes the same record on to the job's trace writer;
//! the Python package's watcher; tests).

mod best;
mod mode;
mod sparse;

use std::ops::ControlFlow;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use serde::Serialize;

use super::components::Components;
use super::outcome::Phase;
use crate::optim::Iteration;

pub use best::{BestSoFar, Improvement};
pub use mode::{ModeFilter, Observed, ObserverMode};
pub use sparse::{Keep, SparseFilter, IMPROVE_RTOL, SAMPLE_CPU_S, SAMPLE_RATIO};

/// One iteration as a design observer sees it: the optimiser's [`Iteration`] (its evaluation
/// count made run-wide, its start index that of the search) extended with the phase and the
/// objective's components at the iterate. Derefs to the [`Iteration`] (`rec.f`, `rec.iter`, …).
#[derive(Debug, Clone, Serialize)]
pub struct DesignIterRecord {
    /// Phase.
    pub phase: Phase,
    /// The optimiser's record: start, iteration within this start and phase, f, dnorm, step,
    /// evaluations so far in the run, CPU seconds since the run started.
    #[serde(flatten)]
    pub it: Iteration,
    /// ‖Tzw‖∞ at the iterate (+∞ if unstable; NaN if not computed in this phase).
    pub gamma: f64,
    /// ‖K‖∞ at the iterate (NaN if not computed).
    pub k_hinf: f64,
    /// α(A_cl).
    pub alpha_cl: f64,
    /// α(Ak) (NaN for order 0).
    pub alpha_k: f64,
    /// Whether f lowered the best value so far of its objective (stabilisation, or performance
    /// in the other phases) in this run ([`BestSoFar`]).
    pub improved: bool,
}

impl DesignIterRecord {
    /// The optimiser's iteration `it` extended: its `phase`, the components `c` at the iterate
    /// (f is `it`'s) and whether f is a new best of its objective.
    pub fn new(phase: Phase, it: Iteration, c: &Components, improved: bool) -> Self {
        let Components { gamma, k_hinf, alpha_cl, alpha_k, f: _ } = *c;
        DesignIterRecord { phase, it, gamma, k_hinf, alpha_cl, alpha_k, improved }
    }
}

impl std::ops::Deref for DesignIterRecord {
    type Target = Iteration;
    fn deref(&self) -> &Iteration {
        &self.it
    }
}

/// Watches a design run; `Break` stops it (status `Interrupted`).
pub trait DesignObserver {
    /// Whether the records should carry ‖Tzw‖∞, ‖K‖∞, α(Acl), α(Ak) even where that costs an
    /// extra computation (α(Acl) in the optimisation phase: one eigenvalue computation per
    /// iteration). Default true; [`NoDesignObserver`] says false.
    fn wants_components(&self) -> bool {
        true
    }

    /// Called once per optimiser iteration.
    fn on_iter(&mut self, _rec: &DesignIterRecord) -> ControlFlow<()> {
        ControlFlow::Continue(())
    }

    /// A cancel flag that [`Design::run`](crate::design::Design::run) attaches to its `RunControl`, so that setting it
    /// stops the run inside a long evaluation, not only at the next iteration (`on_iter`
    /// returning `Break` takes effect only there). Default: none.
    fn cancel_flag(&self) -> Option<Arc<AtomicBool>> {
        None
    }
}

/// An observer that watches nothing.
pub struct NoDesignObserver;
impl DesignObserver for NoDesignObserver {
    fn wants_components(&self) -> bool {
        false
    }
}
