//! [`Design`]: the one way to run a design, a builder in the style of argmin's `Executor`.
//!
//! ```no_run
//! # use hinfix::design::{Design, DesignOptions};
//! # let plant = hinfix::lti::Plant::load(std::path::Path::new("plants/AC1.json")).unwrap();
//! let opts = DesignOptions { order: 1, ..DesignOptions::default() };
//! let outcome = Design::for_plant(&plant, &opts).run()?;
//! # Ok::<(), hinfix::design::DesignError>(())
//! ```
//!
//! What a run needs is the [`Problem`] (one plant, or several with their objectives, weights and
//! bounds) and the [`DesignOptions`]; everything else is optional and has a default: an initial
//! controller ([`Design::init`]), a chained start ([`Design::chained`]), a controller structure
//! ([`Design::structure`]), an observer of the iterations ([`Design::observe`], default none)
//! and a cancel flag ([`Design::cancel`], default the observer's
//! [`DesignObserver::cancel_flag`]). [`Design::run`] makes the run's budget (`optim::RunControl`)
//! from `opts.cpumax`, `opts.maxevals` and the cancel flag — the only place it is made — and runs
//! the design (`design/run.rs`, docs/ALGORITHMS.md §8).

use std::borrow::Cow;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;

use crate::lti::{Controller, Plant};
use crate::optim::RunControl;

use super::observe::{DesignObserver, NoDesignObserver};
use super::options::DesignOptions;
use super::outcome::{DesignError, DesignOutcome};
use super::problem::Problem;
use super::structure::Structure;

/// One design run, configured step by step and started by [`Design::run`].
pub struct Design<'a> {
    problem: Cow<'a, Problem>,
    opts: &'a DesignOptions,
    init: Option<&'a Controller>,
    chained: Option<&'a Controller>,
    chained_first: bool,
    structure: Option<&'a Structure>,
    observer: Option<&'a mut dyn DesignObserver>,
    cancel: Option<Arc<AtomicBool>>,
}

impl<'a> Design<'a> {
    /// A design of `problem` with `opts` (several plants, each with its objective, weight and
    /// bound: `design::problem`, docs/ALGORITHMS.md §14). The first plant gives the starting
    /// points (random, the initial controller, open loop, its central starts) and the variable
    /// scaling.
    pub fn new(problem: &'a Problem, opts: &'a DesignOptions) -> Self {
        Design::with_problem(Cow::Borrowed(problem), opts)
    }

    /// A design for the one plant `plant` with the H∞ objective ([`Problem::single`]).
    pub fn for_plant(plant: &Plant, opts: &'a DesignOptions) -> Self {
        Design::with_problem(Cow::Owned(Problem::single(plant.clone())), opts)
    }

    fn with_problem(problem: Cow<'a, Problem>, opts: &'a DesignOptions) -> Self {
        Design {
            problem,
            opts,
            init: None,
            chained: None,
            chained_first: true,
            structure: None,
            observer: None,
            cancel: None,
        }
    }

    /// An initial controller of order ≤ `opts.order`: a lower order is padded with decoupled
    /// stable modes (docs/ALGORITHMS.md §8.2), and it is used together with `opts.nrand` relative
    /// perturbations of itself in place of the random starts. `None`: random starts.
    pub fn init(mut self, k: Option<&'a Controller>) -> Self {
        self.init = k;
        self
    }

    /// One more initial controller of order ≤ `opts.order` (a campaign's order chaining passes
    /// the best controller of the order below, `campaign::jobs`), padded as [`Design::init`]'s
    /// and projected onto the structure. The padded controller, if it verifies, is an incumbent
    /// before any local search (`design::search` module `given`): the run never returns a
    /// controller whose objective is above the padded controller's, which (same ε) is the
    /// objective of `k` itself, however soon a budget ends it. A local search starts from it
    /// (kind [`StartKind::Chained`](super::StartKind::Chained), no perturbations of it), and, if
    /// `k`'s order is below `opts.order`, another from the padded controller with its new modes
    /// coupled (`starts::couple_padded_modes`, docs/ALGORITHMS.md §8.2: the padded point is a
    /// saddle for them); these come first or last as [`Design::chained_first`] says. `None`: no
    /// chained start.
    pub fn chained(mut self, k: Option<&'a Controller>) -> Self {
        self.chained = k;
        self
    }

    /// Whether the chained start's local searches ([`Design::chained`]) are the run's first
    /// (`true`, the default; among the given controllers, lowest objective first) or come after
    /// all its own first starts (`false`: a campaign's order chaining asks this of every seed but
    /// the first, so that its seeds stay independent searches, `campaign::jobs`). Either way the
    /// chained start is an incumbent from the outset.
    pub fn chained_first(mut self, first: bool) -> Self {
        self.chained_first = first;
        self
    }

    /// Controllers of `structure` (`design::structure`, docs/ALGORITHMS.md §1.1): the
    /// optimiser's variables are the free entries, and every fixed entry of the returned
    /// controller is bit for bit its value. Random starts draw the free entries only; the
    /// initial, chained, open-loop and central starts are projected onto the structure. A
    /// structure of other sizes than `opts.order` on the plant is an `Options` error (field
    /// `structure`); one with no free entry (and no free Dk entry left by the H2 objective) is
    /// evaluated once and answered at once (search stop `no_free_variable`). `None`: every entry
    /// free.
    pub fn structure(mut self, structure: Option<&'a Structure>) -> Self {
        self.structure = structure;
        self
    }

    /// The observer of every iteration (default: none).
    pub fn observe(mut self, obs: &'a mut dyn DesignObserver) -> Self {
        self.observer = Some(obs);
        self
    }

    /// A cancel flag: once set, the run stops (inside a long evaluation too) with
    /// [`DesignStatus::Interrupted`](super::DesignStatus::Interrupted). Default: the observer's
    /// [`DesignObserver::cancel_flag`], if any.
    pub fn cancel(mut self, flag: Arc<AtomicBool>) -> Self {
        self.cancel = Some(flag);
        self
    }

    /// Runs the design within `opts.cpumax` CPU seconds (of the calling thread, counted from
    /// here) and `opts.maxevals` evaluations (HIFOO, strong stabilisation unless `opts.objective`
    /// is [`ObjectiveKind::Plain`](super::ObjectiveKind::Plain)).
    ///
    /// Failing to stabilise is an outcome
    /// ([`DesignStatus::NotStabilised`](super::DesignStatus::NotStabilised)), not an error; `Err`
    /// is for invalid options, a structure that does not fit, a plant that is not strongly
    /// stabilisable (strong objective) or an initial controller that does not fit. γ, ‖K‖∞ and
    /// the abscissas of the outcome are recomputed from the returned controller.
    pub fn run(self) -> Result<DesignOutcome, DesignError> {
        let Design { problem, opts, init, chained, chained_first, structure, observer, cancel } = self;
        let mut none = NoDesignObserver;
        let obs: &mut dyn DesignObserver = match observer {
            Some(o) => o,
            None => &mut none,
        };
        let mut ctl = RunControl::new(opts.cpumax).with_maxevals(opts.maxevals);
        if let Some(flag) = cancel.or_else(|| obs.cancel_flag()) {
            ctl = ctl.with_cancel(flag);
        }
        let starts = super::run::Starts { init, chained, chained_first };
        super::run::design(&problem, opts, starts, structure, &ctl, obs)
    }
}
