//! The two design objectives as [`optim::Objective`](crate::optim::Objective)s
//! (docs/ALGORITHMS.md §3), and the observer adapter that reports their components.
//!
//! With weights (1, ε) on the plant and on the controller "plant" `'K'` (HIFOO 3.5's strong
//! stabilisation, Gumussoy–Millstone–Overton 2008):
//!
//! ```text
//! stabilisation:  f_s(x) = max( α(Acl), ε·α(Ak) )        (plain mode: α(Acl))
//! performance:    f_h(x) = max( ‖Tzw‖∞, ε·‖K‖∞ )        (plain mode: ‖Tzw‖∞)
//! ```
//!
//! f_h = +∞ where Acl or Ak is not Hurwitz (‖·‖∞ = +∞ there) or the loop is ill-posed
//! (I − Dk·D22 numerically singular, [`LtiError::IllPosed`](crate::lti::LtiError)); f_s = +∞ only
//! where the loop is ill-posed or an eigenvalue computation fails. The gradient is that of the
//! term attaining the max (ties: the plant term, HIFOO's "ties broken arbitrarily"); where f is
//! not finite the gradient is NaN, which the optimiser's line search treats as a failed trial.
//!
//! In discrete time (a plant with a sampling time, docs/ALGORITHMS.md §10) α is replaced by the
//! stability measure ρ − 1 (`lti::stability_measure`: negative iff stable, as α) and ‖·‖∞ is on
//! the unit circle; the line-search screen (continuous-time only) is not used.
//!
//! For order 0 the controller term is dropped from f_s (a static gain has no dynamics) but kept
//! in f_h as ε·σmax(Dk) (docs/ALGORITHMS.md §3.2).
//!
//! Interruption: an objective given a stop hook ([`DesignObjective::with_interrupt`]: the run's
//! "CPU budget spent or cancelled") polls it inside the closed-loop H∞ norm (`lti::Interrupt`) when
//! the closed loop has at least [`MIN_ORDER_FOR_INTERRUPT`] states. An interrupted evaluation
//! returns f = NaN with a NaN gradient and caches nothing: the solvers treat it as a failed trial,
//! and since the hook's conditions only ever become true, their next budget check ends the run
//! with its honest reason (CPU budget or interrupted). No value of a half-finished norm is ever
//! returned.
//!
//! Cost: ε·‖K‖∞ (an nk-state system) is evaluated before ‖Tzw‖∞ (n + nk states), so an unstable
//! controller costs almost nothing. Each evaluation stores its components (‖Tzw‖∞, ‖K‖∞, α's) in
//! a small cache keyed by x, from which [`ObserverAdapter`] reports them per iteration.

use std::cell::{Cell, RefCell};
use std::collections::VecDeque;
use std::ops::ControlFlow;
use std::rc::Rc;

use crate::lti::{
    closed_loop, closed_loop_hinf_grad, closed_loop_stability_grad, controller_hinf_grad, controller_stability_grad,
    hinf_lower_bound_sharing, stability_measure, Controller, ControllerGradient, HinfParams, Interrupt, LtiError,
    Plant, ResponseSlot,
};
use crate::optim::{thread_cpu_time, IterRecord, Iteration, Objective, Observer, SolverKind};

pub use super::components::Components;
use super::multi_objective;
use super::observe::{BestSoFar, DesignIterRecord, DesignObserver, Improvement};
use super::outcome::Phase;
use super::params::ControllerShape;
use super::problem::{H2Feedthrough, Problem};
use super::structure::Structure;

/// Number of recently evaluated points whose components are kept for the observer.
pub const COMPONENT_CACHE_LEN: usize = 32;

/// Closed-loop order from which line-search trials are first screened by a cheap lower bound
/// ([`Objective::eval_below`]): on small plants the bound costs too large a share of a full
/// evaluation (HE1, n + nK = 5: 0.11–0.18 ms/eval with screening against 0.08–0.12 without), on
/// large ones it saves the eigenvalue and Hamiltonian work of rejected trials.
pub const MIN_ORDER_FOR_REJECTION: usize = 30;

/// Closed-loop order (n + nK) from which an objective with a stop hook polls it inside an
/// evaluation. Below it an evaluation takes milliseconds, so the solvers' checks between
/// evaluations already honour the budget, and not polling keeps small plants' evaluations
/// exactly as fast as without a hook.
pub const MIN_ORDER_FOR_INTERRUPT: usize = 50;

/// A stop test for [`DesignObjective::with_interrupt`].
pub type StopHook = Rc<dyn Fn() -> bool>;

/// Which of the two objectives.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ObjectivePhase {
    /// max(α(Acl), ε·α(Ak)).
    Stabilisation,
    /// max(‖Tzw‖∞, ε·‖K‖∞).
    Performance,
}

/// Components at the most recently evaluated points (exact bitwise match on x).
#[derive(Debug, Default)]
pub struct ComponentCache {
    entries: VecDeque<(Vec<f64>, Components)>,
}

impl ComponentCache {
    /// Components stored for exactly this x.
    pub fn lookup(&self, x: &[f64]) -> Option<Components> {
        self.entries.iter().rev().find(|(y, _)| y.as_slice() == x).map(|(_, c)| *c)
    }

    fn insert(&mut self, x: &[f64], c: Components) {
        if self.entries.len() == COMPONENT_CACHE_LEN {
            self.entries.pop_front();
        }
        self.entries.push_back((x.to_vec(), c));
    }

    fn update(&mut self, x: &[f64], c: Components) {
        if let Some(e) = self.entries.iter_mut().rev().find(|(y, _)| y.as_slice() == x) {
            e.1 = c;
        } else {
            self.insert(x, c);
        }
    }
}

/// A design objective on x = [vec Ak; vec Bk; vec Ck; vec Dk].
pub struct DesignObjective<'p> {
    plant: &'p Plant,
    shape: ControllerShape,
    phase: ObjectivePhase,
    strong: bool,
    eps: f64,
    hinf_tol: f64,
    cache: Rc<RefCell<ComponentCache>>,
    /// Peak frequency of ‖Tzw‖∞ at the last finite performance evaluation (NaN: none yet), where
    /// σmax(Tzw(iω)) gives a line search's trial point a cheap lower bound of f.
    peak_hint: Cell<f64>,
    /// The last peak frequency before `peak_hint` that was another peak (NaN: none yet). Near a
    /// minimum where two peaks are equally high (the usual nonsmooth optimum), the peak jumps
    /// between them from one evaluation to the next, and a trial point fails the line search's
    /// test at either; the screen looks at both.
    other_peak: Cell<f64>,
    /// The closed loop's frequency-response evaluator left by the last screened trial
    /// ([`Objective::eval_below`]), for its norm if it passes the screen (`lti::ResponseSlot`).
    screened: ResponseSlot,
    /// Polled inside long evaluations (module docs).
    stop: Option<StopHook>,
    /// Whether the last evaluation was abandoned because `stop` fired.
    abandoned: Cell<bool>,
    /// While [`Objective::eval_below`] evaluates a trial point that passed the screen: its
    /// threshold, at which the closed-loop norm stops early (`lti::HinfParams::enough`);
    /// +∞ otherwise.
    reject_at: Cell<f64>,
    /// Told the CPU seconds of every complete closed-loop evaluation where `stop` applies (large
    /// plants), so the run can hold back what recomputing its result will cost.
    on_eval_cpu: Option<Rc<dyn Fn(f64)>>,
    /// Variable scaling d: the objective's x is x̃ with controller parameters d ∘ x̃
    /// (`design::scaling`); `None`: x are the parameters.
    scaling: Option<Rc<[f64]>>,
    /// A controller structure (`design::structure`): the objective's x (after scaling) holds only
    /// the free entries; `None`: x is the whole parameter vector.
    structure: Option<Rc<Structure>>,
    /// Several plants, or other objectives than one plant's H∞ norm (`design::problem`,
    /// `design::multi_objective`); `None`: the single-plant H∞ objective of `plant`.
    problem: Option<&'p Problem>,
    /// The continuous H2 plants' set of controller feedthroughs, onto which every controller's
    /// Dk is projected (`design::problem::H2Feedthrough`); `None`: Dk is free.
    h2: Option<Rc<H2Feedthrough>>,
}

impl<'p> DesignObjective<'p> {
    /// The objective `phase` for controllers of `shape` on `plant`; `strong` adds the ε-weighted
    /// controller term. `cache` receives the components of every evaluation.
    pub fn new(
        plant: &'p Plant,
        shape: ControllerShape,
        phase: ObjectivePhase,
        strong: bool,
        eps: f64,
        hinf_tol: f64,
        cache: Rc<RefCell<ComponentCache>>,
    ) -> Self {
        DesignObjective {
            plant,
            shape,
            phase,
            strong,
            eps,
            hinf_tol,
            cache,
            peak_hint: Cell::new(f64::NAN),
            other_peak: Cell::new(f64::NAN),
            screened: ResponseSlot::default(),
            stop: None,
            abandoned: Cell::new(false),
            reject_at: Cell::new(f64::INFINITY),
            on_eval_cpu: None,
            scaling: None,
            structure: None,
            problem: None,
            h2: None,
        }
    }

    /// Evaluates `problem` (several plants, or other objectives: `design::multi_objective`) in
    /// place of the single-plant H∞ objective; `h2` projects every controller's Dk onto the
    /// continuous H2 plants' set ([`Problem::validate`]). The objective's `plant` must be the
    /// problem's first. `None`: the single-plant objective.
    pub fn with_problem(mut self, problem: Option<&'p Problem>, h2: Option<Rc<H2Feedthrough>>) -> Self {
        assert!(problem.is_none_or(|p| std::ptr::eq(p.first(), self.plant)), "the plant must be the problem's first");
        self.problem = problem;
        self.h2 = h2;
        self
    }

    /// Takes x (after scaling) as the free entries of `structure` (`design::structure`): the
    /// controller is the structure's template with them in place, the gradient ∇ₓ restricted to
    /// them. `None`: x is the whole parameter vector. Set it before [`Self::with_scaling`].
    pub fn with_structure(mut self, structure: Option<Rc<Structure>>) -> Self {
        assert!(structure.as_ref().is_none_or(|s| s.fits(self.shape)), "structure does not fit the shape");
        self.structure = structure;
        self
    }

    /// Takes x as scaled variables x̃ with controller parameters d ∘ x̃ (`design::scaling`);
    /// gradients are then with respect to x̃ (d ∘ ∇ₓ). `None`: unscaled.
    pub fn with_scaling(mut self, d: Option<Rc<[f64]>>) -> Self {
        assert!(d.as_ref().is_none_or(|d| d.len() == Objective::nvar(&self)), "scaling length must be nvar");
        self.scaling = d;
        self
    }

    /// The controller at the objective's variables `x` (scaled if [`Self::with_scaling`]).
    fn controller(&self, x: &[f64]) -> Controller {
        let k = match (&self.scaling, &self.structure) {
            (Some(d), None) => self.shape.controller(&super::scaling::from_scaled(x, Some(d))),
            (None, None) => self.shape.controller(x),
            (Some(d), Some(s)) => s.controller(self.shape, &super::scaling::from_scaled(x, Some(d))),
            (None, Some(s)) => s.controller(self.shape, x),
        };
        match &self.h2 {
            None => k,
            Some(h2) => Controller { dk: h2.project(&k.dk), ..k },
        }
    }

    /// The controller at the objective's variables `x`: the structure's template with the free
    /// entries in place, Dk projected for the H2 objective (what the design returns).
    pub fn controller_at(&self, x: &[f64]) -> Controller {
        self.controller(x)
    }

    /// Polls `stop` inside evaluations of closed loops of at least [`MIN_ORDER_FOR_INTERRUPT`]
    /// states; once it returns true, evaluations are abandoned with f = NaN (module docs). The
    /// hook must stay true once it has fired (a spent budget, a cancel flag).
    pub fn with_interrupt(mut self, stop: Option<StopHook>) -> Self {
        self.stop = stop;
        self
    }

    /// Reports the CPU seconds of each complete closed-loop H∞ evaluation on plants where the
    /// stop hook applies (at least [`MIN_ORDER_FOR_INTERRUPT`] states) to `report`.
    pub fn with_eval_cpu_report(mut self, report: Option<Rc<dyn Fn(f64)>>) -> Self {
        self.on_eval_cpu = report;
        self
    }

    /// A copy of this objective sharing its cache, stop hook and CPU report (not its peak hint).
    fn sibling(&self) -> Self {
        let o = self;
        DesignObjective::new(o.plant, o.shape, o.phase, o.strong, o.eps, o.hinf_tol, o.cache())
            .with_interrupt(o.stop.clone())
            .with_eval_cpu_report(o.on_eval_cpu.clone())
            .with_structure(o.structure.clone())
            .with_scaling(o.scaling.clone())
            .with_problem(o.problem, o.h2.clone())
    }

    /// True if the stop hook applies to this plant and has fired.
    fn stop_fired(&self) -> bool {
        self.plant.dims.n + self.shape.nk >= MIN_ORDER_FOR_INTERRUPT && self.stop.as_ref().is_some_and(|s| s())
    }

    /// The cache this objective writes to.
    pub fn cache(&self) -> Rc<RefCell<ComponentCache>> {
        Rc::clone(&self.cache)
    }

    /// f and its components at controller `k`; the gradient (as controller matrices) if `grad`.
    pub fn components(&self, k: &Controller, grad: bool) -> (Components, Option<ControllerGradient>) {
        if let Some(problem) = self.problem {
            return self.problem_components(problem, k);
        }
        match self.phase {
            ObjectivePhase::Stabilisation => self.stabilisation(k, grad),
            ObjectivePhase::Performance => self.performance(k, grad),
        }
    }

    fn stabilisation(&self, k: &Controller, _grad: bool) -> (Components, Option<ControllerGradient>) {
        let mut c = Components::UNKNOWN;
        let nk = k.order();
        // α(Ak) is cheap (nk × nk); its gradient is needed only when it is in the objective.
        let (alpha_k, g_k) = if nk > 0 {
            let (a, g) = controller_stability_grad(k);
            (a, Some(g))
        } else {
            (f64::NAN, None)
        };
        c.alpha_k = alpha_k;
        let (alpha_cl, g_cl) = match closed_loop_stability_grad(self.plant, k) {
            Ok((a, g)) => (a, Some(g)),
            Err(_) => (f64::INFINITY, None),
        };
        c.alpha_cl = alpha_cl;
        let k_term = if self.strong && nk > 0 { self.eps * alpha_k } else { f64::NEG_INFINITY };
        // NaN-safe max: a NaN term makes f NaN (treated like +∞ by the line search).
        let (f, g) = if k_term.is_nan() || self.controller_term_sets_f(&c) {
            (k_term, g_k.map(|g| scale(g, self.eps)))
        } else {
            (alpha_cl, g_cl)
        };
        c.f = f;
        (c, g)
    }

    fn performance(&self, k: &Controller, _grad: bool) -> (Components, Option<ControllerGradient>) {
        let mut c = Components::UNKNOWN;
        if k.order() > 0 {
            c.alpha_k = stability_measure(k.domain, k.ak.as_ref());
        }
        let mut k_term = (f64::NEG_INFINITY, None);
        if self.strong {
            let (norm, g) = controller_hinf_grad(k, self.hinf_tol);
            c.k_hinf = norm.value;
            if !norm.value.is_finite() {
                c.f = f64::INFINITY;
                return (c, None);
            }
            k_term = (self.eps * norm.value, Some(g));
        }
        let hook = self.stop.as_deref().filter(|_| self.plant.dims.n + k.order() >= MIN_ORDER_FOR_INTERRUPT);
        let stop = hook.map_or(Interrupt::NEVER, Interrupt::new);
        // Warm start at the last peak (Benner & Mitchell 2018), in addition to the mode-based test
        // frequencies (`lti::HinfParams::hints`); the level-set certification is unchanged.
        let hint = [self.peak_hint.get()];
        let cpu0 = hook.map(|_| thread_cpu_time());
        let reject_at = self.reject_at.get();
        let params = HinfParams::new(self.hinf_tol)
            .with_hints(&hint)
            .with_stop(stop)
            .with_enough(reject_at)
            .with_reuse(&self.screened);
        let (gamma, g_cl) = match closed_loop_hinf_grad(self.plant, k, &params) {
            Ok((norm, _)) if norm.value >= reject_at => {
                // A lower bound that fails the line search's test: no gradient, no new peak.
                c.gamma = norm.value;
                c.f = norm.value.max(k_term.0);
                return (c, None);
            }
            Ok((norm, g)) => {
                if let (Some(t0), Some(report)) = (cpu0, &self.on_eval_cpu) {
                    report(thread_cpu_time() - t0);
                }
                if norm.value.is_finite() {
                    let last = self.peak_hint.replace(norm.peak_freq);
                    if other_peak(last, norm.peak_freq) {
                        self.other_peak.set(last);
                    }
                }
                (norm.value, Some(g))
            }
            Err(LtiError::Interrupted(_)) => {
                // Abandoned: no value (module docs).
                self.abandoned.set(true);
                c.f = f64::NAN;
                c.k_hinf = f64::NAN;
                return (c, None);
            }
            Err(_) => (f64::INFINITY, None),
        };
        c.gamma = gamma;
        if !gamma.is_finite() {
            c.f = f64::INFINITY;
            return (c, None);
        }
        if self.controller_term_sets_f(&c) {
            c.f = k_term.0;
            (c, k_term.1.map(|g| scale(g, self.eps)))
        } else {
            c.f = gamma;
            (c, g_cl)
        }
    }
}

impl DesignObjective<'_> {
    /// [`Self::components`] of a [`Problem`] (`design::multi_objective`).
    fn problem_components(&self, problem: &Problem, k: &Controller) -> (Components, Option<ControllerGradient>) {
        match self.phase {
            ObjectivePhase::Stabilisation => multi_objective::stabilisation(problem, k, self.strong, self.eps),
            ObjectivePhase::Performance => {
                let hook = self.stop.as_deref().filter(|_| self.plant.dims.n + k.order() >= MIN_ORDER_FOR_INTERRUPT);
                let params = HinfParams::new(self.hinf_tol).with_stop(hook.map_or(Interrupt::NEVER, Interrupt::new));
                match multi_objective::performance(problem, k, self.strong, self.eps, self.hinf_tol, &params) {
                    Ok(v) => v,
                    Err(multi_objective::NoValue::Interrupted) => {
                        self.abandoned.set(true);
                        (Components::UNKNOWN, None)
                    }
                }
            }
        }
    }

    /// Whether the controller's term of the strong objective sets f at a point of components `c`:
    /// ε‖K‖∞ > ‖Tzw‖∞ in the performance phase, ε·α(Ak) > α(A_cl) when stabilising (false for
    /// order 0, whose α(Ak) is NaN, and without `strong`). For a problem of several plants
    /// (`multi_objective`), `c.gamma` is the largest weighted value of the unbounded plants (NaN
    /// if every plant has a bound: then the controller's term, where there is one, is the only
    /// one), and the term is ε·α(Ak) where [`Problem::controller_term_is_abscissa`].
    fn controller_term_sets_f(&self, c: &Components) -> bool {
        self.strong
            && match (self.phase, self.problem) {
                (ObjectivePhase::Performance, None) => self.eps * c.k_hinf > c.gamma,
                (ObjectivePhase::Performance, Some(p)) => {
                    let term = if p.controller_term_is_abscissa() { c.alpha_k } else { c.k_hinf } * self.eps;
                    term > c.gamma || (c.gamma.is_nan() && term.is_finite())
                }
                (ObjectivePhase::Stabilisation, _) => self.eps * c.alpha_k > c.alpha_cl,
            }
    }

    /// The closed loops' stability measure at `k`: the plant's, or the largest of a problem's.
    fn closed_loop_measure(&self, k: &Controller) -> f64 {
        let measure = |plant: &Plant| {
            closed_loop(plant, k).map(|cl| stability_measure(plant.domain, cl.a.as_ref())).unwrap_or(f64::INFINITY)
        };
        match self.problem {
            None => measure(self.plant),
            Some(p) => p.terms.iter().map(|t| measure(&t.plant)).fold(f64::NEG_INFINITY, super::problem::nan_max),
        }
    }

    /// [`Objective::eval`], with the closed-loop norm stopping once it reaches `reject_at`
    /// (`lti::HinfParams::enough`): a value f ≥ `reject_at` may then be a lower bound,
    /// comes with a NaN gradient and is not cached (the line search only needs to know that f
    /// fails its test there).
    fn eval_unless(&mut self, x: &[f64], g: &mut [f64], reject_at: f64) -> f64 {
        let k = self.controller(x);
        self.abandoned.set(false);
        self.reject_at.set(reject_at);
        let (c, grad) = self.components(&k, true);
        self.reject_at.set(f64::INFINITY);
        match grad {
            Some(mut gk) if c.f.is_finite() => {
                if let Some(h2) = &self.h2 {
                    gk.dk = h2.project_gradient(&gk.dk);
                }
                match &self.structure {
                    None => self.shape.write_x(&gk, g),
                    Some(s) => {
                        let mut full = vec![0.0; self.shape.nvar()];
                        self.shape.write_x(&gk, &mut full);
                        g.copy_from_slice(&s.restrict(&full));
                    }
                }
                if let Some(d) = &self.scaling {
                    g.iter_mut().zip(d.iter()).for_each(|(v, s)| *v *= s);
                }
            }
            _ => g.iter_mut().for_each(|v| *v = f64::NAN),
        }
        let rejected = reject_at < f64::INFINITY && c.f >= reject_at;
        if !self.abandoned.get() && !rejected {
            self.cache.borrow_mut().insert(x, c);
        }
        c.f
    }

    /// A lower bound of the performance objective at `k` without any eigenvalue computation of
    /// the closed loop: max(σmax(Tzw(iω)) at ω = ∞, at the last peak frequency and up the peak
    /// next to it while below `threshold` (`lti::hinf_lower_bound_sharing`), ε‖K‖∞) (‖K‖∞ is
    /// of the small controller, computed in full). +∞ for an ill-posed loop. Exact: f(k) ≥ it
    /// whether or not the loop is stable (f = +∞ when it is not).
    fn performance_lower_bound(&self, k: &Controller, threshold: f64) -> f64 {
        let mut lb = f64::NEG_INFINITY;
        if self.strong {
            let (norm, _) = controller_hinf_grad(k, self.hinf_tol);
            lb = self.eps * norm.value;
        }
        match closed_loop(self.plant, k) {
            Ok(cl) => lb.max(hinf_lower_bound_sharing(
                &cl,
                &[self.peak_hint.get(), self.other_peak.get()],
                threshold,
                &self.screened,
            )),
            Err(_) => f64::INFINITY,
        }
    }
}

/// Whether the peak frequency `last` is another peak than `new` (not NaN, and more than 10 %
/// away: the same peak drifts by less between evaluations), to be kept as the objective's
/// `other_peak`.
fn other_peak(last: f64, new: f64) -> bool {
    if last.is_nan() || last == new {
        return false;
    }
    !(last > 0.0 && new > 0.0 && last.is_finite() && new.is_finite() && (last / new).ln().abs() < 0.1)
}

fn scale(mut g: ControllerGradient, s: f64) -> ControllerGradient {
    for m in [&mut g.ak, &mut g.bk, &mut g.ck, &mut g.dk] {
        for j in 0..m.ncols() {
            for i in 0..m.nrows() {
                m[(i, j)] *= s;
            }
        }
    }
    g
}

impl Objective for DesignObjective<'_> {
    fn nvar(&self) -> usize {
        self.structure.as_ref().map_or(self.shape.nvar(), |s| s.nfree())
    }

    fn eval(&mut self, x: &[f64], g: &mut [f64]) -> f64 {
        self.eval_unless(x, g, f64::INFINITY)
    }

    /// ε where the controller's term ε·‖K‖∞ (ε·α(Ak) when stabilising) sets f at `x`, else 1:
    /// the certificate then weighs that term's gradient as ∇‖K‖∞, not ε∇‖K‖∞
    /// (docs/ALGORITHMS.md §7.3), for one plant or several. A point no longer cached: 1.
    fn gradient_unit(&self, x: &[f64]) -> f64 {
        if !self.strong || !(self.eps > 0.0) {
            return 1.0;
        }
        let Some(c) = self.cache.borrow().lookup(x) else { return 1.0 };
        if self.controller_term_sets_f(&c) {
            self.eps
        } else {
            1.0
        }
    }

    /// In the performance phase, a trial point whose cheap lower bound
    /// (`performance_lower_bound`: σmax(Tzw) at ω = ∞ and up the last peak, ε‖K‖∞) already
    /// reaches `threshold` is rejected
    /// without the closed loop's eigenvalues, Hamiltonian or gradient: the line search only
    /// needs to know that the trial fails its Armijo test, and the bound is attained, so the
    /// value returned is exact (docs/ALGORITHMS.md §8.4, "Line-search screen"); one that passes
    /// is evaluated by `eval_unless`, whose norm still stops once it reaches `threshold`.
    fn eval_below(&mut self, x: &[f64], g: &mut [f64], threshold: f64) -> f64 {
        if self.phase == ObjectivePhase::Performance
            && self.problem.is_none()
            && self.plant.dims.n + self.shape.nk >= MIN_ORDER_FOR_REJECTION
            && !self.plant.domain.is_discrete()
        {
            let lb = self.performance_lower_bound(&self.controller(x), threshold);
            if lb >= threshold {
                g.iter_mut().for_each(|v| *v = f64::NAN);
                return lb;
            }
            return self.eval_unless(x, g, threshold);
        }
        self.eval(x, g)
    }
}

/// Extends the optimiser's [`IterRecord`]s into [`DesignIterRecord`]s for a
/// [`DesignObserver`]: the design's phase, the run-wide evaluation count, the objective's
/// components taken from the [`ComponentCache`], and whether f is a new best of its objective
/// (the run's one [`BestSoFar`], which the search also asks for its time to best).
///
/// Missing components: if x is no longer cached (e.g. after many gradient-sampling samples) it is
/// evaluated again without gradient; in the performance phase α(Acl) (one eigenvalue computation
/// of Acl) is computed here, once per iteration, only if the observer
/// [wants components](DesignObserver::wants_components).
pub struct ObserverAdapter<'a, 'p> {
    inner: &'a mut dyn DesignObserver,
    objective_for_misses: DesignObjective<'p>,
    phase: Phase,
    evals_base: usize,
    interrupted: bool,
    best: BestSoFar,
}

/// The phase whose objective `p` is, as [`BestSoFar`] files it.
fn objective_phase(p: ObjectivePhase) -> Phase {
    match p {
        ObjectivePhase::Stabilisation => Phase::Stabilisation,
        ObjectivePhase::Performance => Phase::Optimisation,
    }
}

impl<'a, 'p> ObserverAdapter<'a, 'p> {
    /// An adapter for `inner`, reading components from `objective`'s cache.
    pub fn new(inner: &'a mut dyn DesignObserver, objective: &DesignObjective<'p>, phase: Phase) -> Self {
        let objective_for_misses = objective.sibling();
        ObserverAdapter {
            inner,
            objective_for_misses,
            phase,
            evals_base: 0,
            interrupted: false,
            best: BestSoFar::new(),
        }
    }

    /// Reports the iterations of `objective` as `phase` from now on (one adapter serves a whole
    /// search, whose local searches alternate between the two objectives).
    pub fn switch(&mut self, objective: &DesignObjective<'p>, phase: Phase) {
        self.objective_for_misses = objective.sibling();
        self.phase = phase;
    }

    /// The first iterate of objective `phase` whose value was within a relative `rtol` of `f`
    /// (|f_i − f| ≤ rtol·|f|, or below f): when the value f was first reached.
    pub fn first_reached(&self, phase: ObjectivePhase, f: f64, rtol: f64) -> Option<Improvement> {
        self.best.first_reached(objective_phase(phase), f, rtol)
    }

    /// Sets the number of evaluations made in the run before the next optimiser call.
    pub fn set_evals_base(&mut self, base: usize) {
        self.evals_base = base;
    }

    /// Whether the design observer asked to stop.
    pub fn interrupted(&self) -> bool {
        self.interrupted
    }

    /// Gives back the inner observer.
    pub fn into_inner(self) -> &'a mut dyn DesignObserver {
        self.inner
    }
}

impl Observer for ObserverAdapter<'_, '_> {
    fn on_iter(&mut self, rec: &IterRecord<'_>) -> ControlFlow<()> {
        if self.interrupted {
            return ControlFlow::Break(());
        }
        let evals = self.evals_base + rec.evals;
        let reached = Improvement { f: rec.f, cpu_s: rec.cpu_s, evals };
        let improved = self.best.offer(objective_phase(self.objective_for_misses.phase), reached);
        let wants = self.inner.wants_components();
        let obj = &self.objective_for_misses;
        let cached = obj.cache.borrow().lookup(rec.x);
        let mut c = match cached {
            Some(c) => c,
            None if wants => {
                let (c, _) = obj.components(&obj.controller(rec.x), false);
                obj.cache.borrow_mut().update(rec.x, c);
                c
            }
            None => Components::UNKNOWN,
        };
        if wants && c.alpha_cl.is_nan() && obj.phase == ObjectivePhase::Performance && !obj.stop_fired() {
            c.alpha_cl = obj.closed_loop_measure(&obj.controller(rec.x));
            obj.cache.borrow_mut().update(rec.x, c);
        }
        let phase = match (self.phase, rec.solver) {
            (Phase::Optimisation, SolverKind::GradientSampling) => Phase::GradientSampling,
            (p, _) => p,
        };
        let out = DesignIterRecord::new(phase, Iteration { evals, ..rec.it }, &c, improved);
        let flow = self.inner.on_iter(&out);
        if flow.is_break() {
            self.interrupted = true;
        }
        flow
    }
}
