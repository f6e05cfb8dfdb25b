//! One HIFOO design (docs/ALGORITHMS.md §8), as [`Design::run`](super::Design::run) starts it:
//! validate, build the starting points, stabilise, optimise, and report figures recomputed from
//! the returned controller.

use std::cell::RefCell;
use std::rc::Rc;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

use crate::lti::{
    closed_loop, continuous_time_image, controller_hinf_grad, eigenvalues_of, hinf_norm_checked_with, is_stable,
    stability_measure, stability_measure_of, verified_stability, Controller, HinfParams, Interrupt, Plant, TimeDomain,
    NORM_TIE_RTOL,
};
use crate::optim::RunControl;

use super::central_start::central_starts;
use super::objective::{
    ComponentCache, DesignObjective, ObjectivePhase, ObserverAdapter, StopHook, MIN_ORDER_FOR_INTERRUPT,
};
use super::observe::DesignObserver;
use super::options::{DesignOptions, ObjectiveKind, VariableScaling};
use super::outcome::{
    Certificate, DesignError, DesignOutcome, DesignStatus, InitError, Phase, PhaseStats, SearchStop, SearchSummary,
    StartKind,
};
use super::params::{controller_to_x, ControllerShape};
use super::problem::{
    nan_max, plant_part, plant_values, problem_gamma, H2Feedthrough, PlantValue, Problem, PENALTY_WEIGHT,
};
use super::scaling::variable_scaling;
use super::search::{FirstStarts, ScaledObjectives, Search, SearchResult};
use super::starts::{
    couple_padded_modes, open_loop_controller, pad_controller, padding_diagonal, perturbed_starts, random_starts,
    PADDED_COUPLING,
};
use super::structure::Structure;

/// The given starting controllers of a run: `init` (with its perturbations, in place of the
/// random starts) and `chained` (the first local search), each of order ≤ `opts.order`
/// ([`Design::init`](super::Design::init), [`Design::chained`](super::Design::chained)).
#[derive(Clone, Copy)]
pub(super) struct Starts<'a> {
    pub init: Option<&'a Controller>,
    pub chained: Option<&'a Controller>,
    /// Whether `chained`'s local searches come first ([`Design::chained_first`](super::Design::chained_first)).
    pub chained_first: bool,
}

/// The design of `problem` ([`Design::run`](super::Design::run), whose docs say what each
/// argument does) under the run control `ctl` (`opts.cpumax`, `opts.maxevals`, the cancel flag;
/// a cancel gives [`DesignStatus::Interrupted`]). The single-plant H∞ problem
/// ([`Problem::is_single_hinf`]) is evaluated by `design::objective` alone; any other by
/// `design::multi_objective`, every plant stabilised in the first phase. The first plant gives
/// the starting points and the variable scaling; every plant is checked by [`validate`] and,
/// strong objective, for strong stabilisability. The outcome's [`DesignOutcome::plants`] gives
/// each plant's recomputed value of a problem of several plants; its `gamma` is then the largest
/// weighted value w_j·g_j of the plants without a bound (of all plants if each has one),
/// `alpha_cl` the largest closed-loop stability measure.
pub(super) fn design(
    problem: &Problem,
    opts: &DesignOptions,
    starts: Starts<'_>,
    structure: Option<&Structure>,
    ctl: &RunControl,
    obs: &mut dyn DesignObserver,
) -> Result<DesignOutcome, DesignError> {
    let h2 = check(problem, opts, starts, structure)?;
    let plant = problem.first();
    let shape = ControllerShape::for_plant(plant, opts.order);
    match free_variables(shape, structure, h2.as_ref()) {
        0 => return Ok(fixed_design(problem, opts, shape, structure, h2.as_ref())),
        n if n > MAX_VARIABLES => {
            return Err(opt_err(
                "order",
                format!(
                    "{} gives {n} free controller variables on {}, more than {MAX_VARIABLES}: BFGS keeps a dense \
                     {n} × {n} inverse-Hessian approximation ({:.0} GB); lower the order, or fix entries with a structure",
                    opts.order,
                    plant.name,
                    (n as f64).powi(2) * 8e-9
                ),
            ))
        }
        _ => {}
    }
    let h2 = h2.map(Rc::new);
    let structure: Option<Rc<Structure>> = structure.map(|s| Rc::new(s.clone()));
    // The optimiser's variables of a controller (all of x, or its free entries: the fixed ones
    // are overwritten, i.e. the controller is projected onto the structure).
    let vars = |x: Vec<f64>| match &structure {
        None => x,
        Some(s) => s.restrict(&x),
    };
    let nvar = structure.as_ref().map_or(shape.nvar(), |s| s.nfree());
    let mut rng = ChaCha8Rng::seed_from_u64(opts.seed);
    let first = first_starts(plant, opts, starts, shape, nvar, &vars, &mut rng);
    // Local searches in plant-scaled variables x̃ (x = d ∘ x̃, `design::scaling`), if the mode
    // asks for them and the plant is scaled at all.
    let scaling: Option<Rc<[f64]>> = match opts.variable_scaling {
        VariableScaling::Off => None,
        VariableScaling::Alternate | VariableScaling::Always => variable_scaling(plant, shape).map(|d| vars(d).into()),
    };
    let multi = (!problem.is_single_hinf()).then_some(problem);
    let strong = opts.objective == ObjectiveKind::Strong;
    // Inside an evaluation the full budget and the cancel flag are polled (objective.rs); a
    // sub-budget of the search is checked between evaluations.
    let stop_ctl = ctl.clone();
    let stop: StopHook = Rc::new(move || stop_ctl.cancelled() || stop_ctl.cpu_exhausted());
    // On large plants, hold back the largest evaluation seen from the CPU budget: the returned
    // controller's figures (about one evaluation) are computed after the search, and should end
    // near cpumax, not one evaluation after it. (Small plants never report: their runs are
    // unchanged.)
    let reserve_ctl = ctl.clone();
    let report: Rc<dyn Fn(f64)> = Rc::new(move |s| reserve_ctl.reserve_cpu(s));
    // The two objectives in coordinates with scaling `d` (each coordinate system has its own
    // component cache: the cache is keyed by the objective's variables).
    let objectives = |d: Option<Rc<[f64]>>| {
        let cache = Rc::new(RefCell::new(ComponentCache::default()));
        let new = |phase, cache| DesignObjective::new(plant, shape, phase, strong, opts.eps, opts.hinf_tol, cache);
        let stab = new(ObjectivePhase::Stabilisation, Rc::clone(&cache))
            .with_problem(multi, h2.clone())
            .with_structure(structure.clone())
            .with_interrupt(Some(Rc::clone(&stop)))
            .with_scaling(d.clone());
        let perf = new(ObjectivePhase::Performance, cache)
            .with_problem(multi, h2.clone())
            .with_structure(structure.clone())
            .with_interrupt(Some(Rc::clone(&stop)))
            .with_eval_cpu_report(Some(Rc::clone(&report)))
            .with_scaling(d);
        (stab, perf)
    };
    let (mut stab_obj, mut perf_obj) = objectives(None);
    let mut scaled_objs = scaling.clone().map(|d| objectives(Some(d)));
    let mut adapter = ObserverAdapter::new(obs, &stab_obj, Phase::Stabilisation);
    let scaled = match (&mut scaled_objs, &scaling) {
        (Some((s, p)), Some(d)) => Some(ScaledObjectives { stab_obj: s, perf_obj: p, d: Rc::clone(d) }),
        _ => None,
    };
    let res = Search {
        stab_obj: &mut stab_obj,
        perf_obj: &mut perf_obj,
        adapter: &mut adapter,
        rng: &mut rng,
        ctl,
        problem,
        scaled,
    }
    .run(opts, &first, nvar)?;
    let interrupted = adapter.interrupted() || ctl.cancelled() || res.summary.stop == SearchStop::Interrupted;
    let (final_x, ended) = how_it_ended(&res, opts, interrupted);
    let k = perf_obj.controller_at(&final_x);
    let cancelled = || ctl.cancelled();
    let large = plant.dims.n + shape.nk >= MIN_ORDER_FOR_INTERRUPT;
    let (fig, plants) =
        outcome_figures(plant, multi, opts, &k, if large { Interrupt::new(&cancelled) } else { Interrupt::NEVER });
    Ok(outcome(problem, k, fig, plants, opts, ended, res.phases, ctl.cpu_elapsed(), res.summary))
}

/// The checks before a design: the problem, the options and the given controllers against every
/// plant ([`validate`]), the structure against the problem (sizes; Dk free under the h2
/// objective; a fixed A_K stable under the strong objective), and strong stabilisability. `Ok`
/// holds the h2 objective's feedthrough set, if the problem has one.
fn check(
    problem: &Problem,
    opts: &DesignOptions,
    starts: Starts<'_>,
    structure: Option<&Structure>,
) -> Result<Option<H2Feedthrough>, DesignError> {
    let h2 = problem.validate().map_err(DesignError::Problem)?;
    let plant = problem.first();
    for t in &problem.terms {
        validate(&t.plant, opts, starts.init)?;
        if starts.chained.is_some() {
            validate(&t.plant, opts, starts.chained)?;
        }
    }
    let shape = ControllerShape::for_plant(plant, opts.order);
    if let (Some(s), Some(_)) = (structure, &h2) {
        let dk = &s.entries()[shape.nvar() - shape.m * shape.p..];
        if dk.iter().any(Option::is_some) {
            return Err(opt_err(
                "structure",
                "fixes entries of DK, which the h2 objective constrains to D11 + D12·DK·D21 = 0: leave DK free",
            ));
        }
    }
    if let Some(s) = structure {
        if !s.fits(shape) {
            let (nk, m, p) = s.sizes();
            return Err(opt_err(
                "structure",
                format!(
                    "made for order {nk} with {m} controls and {p} measurements, not order {} with {} and {}",
                    shape.nk, shape.m, shape.p
                ),
            ));
        }
        fixed_ak_stable(s, shape, opts, plant.domain)?;
        fixed_dk_well_posed(s, shape, problem)?;
    }
    for t in &problem.terms {
        strongly_stabilisable(&t.plant, opts)?;
    }
    Ok(h2)
}

/// The first starting points, their kinds and how many of them are given controllers, in the
/// search's order: the given controllers themselves (the padded chained start, the padded
/// initial controller: the search offers them to its incumbents before any local search and
/// starts from them lowest objective first, `search` module docs), then the chained start's
/// coupled copy, the initial controller's perturbations or random starts, the open-loop start
/// (if asked for), the central starts. Without `starts.chained_first` the search makes the chained
/// starts' local searches last (`search` module docs). `vars` maps a controller's x to the
/// optimiser's variables.
fn first_starts(
    plant: &Plant,
    opts: &DesignOptions,
    starts: Starts<'_>,
    shape: ControllerShape,
    nvar: usize,
    vars: &dyn Fn(Vec<f64>) -> Vec<f64>,
    rng: &mut ChaCha8Rng,
) -> FirstStarts {
    let mut first = starting_points(plant, opts, starts.init, shape, nvar, vars, rng);
    let mut kinds = vec![if starts.init.is_some() { StartKind::Init } else { StartKind::Random }; first.len()];
    // `starting_points` begins with the initial controller itself, if there is one.
    let mut given = usize::from(starts.init.is_some());
    if let Some(k) = starts.chained {
        let padded_k = padded_to(plant, k, shape.nk);
        let padded = vars(controller_to_x(&padded_k));
        if k.order() < shape.nk {
            // the padded point is a saddle for its new modes (docs/ALGORITHMS.md §8.2); a
            // structure that fixes their coupling leaves nothing to couple
            let coupled = vars(controller_to_x(&couple_padded_modes(&padded_k, k.order(), PADDED_COUPLING, rng)));
            if coupled != padded {
                first.insert(given, coupled);
                kinds.insert(given, StartKind::Chained);
            }
        }
        first.insert(0, padded);
        kinds.insert(0, StartKind::Chained);
        given += 1;
    }
    if opts.open_loop_start {
        first.push(vars(controller_to_x(&open_loop_controller(plant, shape.nk))));
        kinds.push(StartKind::OpenLoop);
    }
    for (_, k) in central_starts(plant, shape.nk, &opts.central_gammas) {
        first.push(vars(controller_to_x(&k)));
        kinds.push(StartKind::Central);
    }
    FirstStarts { points: first, kinds, given, chained_first: starts.chained_first }
}

/// The point a search returns (the best of the performance phase, else of the stabilisation
/// phase) and how the search ended: its status and certificate.
fn how_it_ended(
    res: &SearchResult,
    opts: &DesignOptions,
    interrupted: bool,
) -> (Vec<f64>, (DesignStatus, Option<Certificate>)) {
    let (final_x, certificate) = match &res.perf {
        Some(b) => (b.x.clone(), Some(Certificate { dnorm: b.dnorm, evaldist: b.evaldist })),
        None => (res.stab.x.clone(), None),
    };
    let status = if interrupted {
        DesignStatus::Interrupted
    } else if !res.stabilised {
        DesignStatus::NotStabilised { best_alpha: res.stab.f }
    } else if res.truncated {
        DesignStatus::BudgetExhausted
    } else if res.perf.as_ref().is_none_or(|b| !b.moved) {
        DesignStatus::StabilisedOnly
    } else if res.perf.as_ref().is_some_and(|b| b.dnorm <= opts.normtol) {
        DesignStatus::Converged
    } else {
        DesignStatus::Stopped
    };
    (final_x, (status, certificate))
}

/// The outcome's figures of `k` on the first plant ([`figures`]), or the problem's with each
/// plant's value for a problem of several plants (`multi`). These are the optimiser's figures (its
/// stability measure, the norms to the run's `hinf_tol`, abandoned on a cancel): what the
/// controller is judged by after the run is [`design::evaluate`](super::evaluate)'s verification
/// ([`verified_status`]).
fn outcome_figures(
    plant: &Plant,
    multi: Option<&Problem>,
    opts: &DesignOptions,
    k: &Controller,
    stop: Interrupt<'_>,
) -> (Figures, Vec<PlantValue>) {
    let mut fig = figures(plant, opts, k, stop);
    let plants = match multi {
        None => Vec::new(),
        Some(p) => {
            let values = plant_values(p, k, opts.hinf_tol);
            problem_figures(&mut fig, p, &values, opts);
            values
        }
    };
    (fig, plants)
}

/// The outcome of a run of `problem` that returns `k` with figures `fig` (and `plants`), how it
/// ended (the status as the returned controller supports it: [`verified_status`]), its phases'
/// counters, CPU seconds and search summary.
#[allow(clippy::too_many_arguments)]
fn outcome(
    problem: &Problem,
    k: Controller,
    fig: Figures,
    plants: Vec<PlantValue>,
    opts: &DesignOptions,
    (status, certificate): (DesignStatus, Option<Certificate>),
    phases: Vec<PhaseStats>,
    design_cpu_s: f64,
    search: SearchSummary,
) -> DesignOutcome {
    let status = verified_status(status, problem, opts, &k, &plants);
    DesignOutcome {
        status,
        controller: k,
        gamma: fig.gamma,
        k_hinf: fig.k_hinf,
        alpha_cl: fig.alpha_cl,
        alpha_k: fig.alpha_k,
        objective: fig.objective,
        controller_norm_active: search.stop != SearchStop::NoFreeVariable
            && problem_norm_active(problem, opts, &fig, &plants),
        certificate,
        iterations: phases.iter().map(|p| p.iters).sum(),
        evaluations: phases.iter().map(|p| p.evals).sum(),
        phases,
        design_cpu_s,
        search,
        plants,
    }
}

/// [`controller_norm_active`] for the outcome of `problem`: for several plants (`plants` not
/// empty) against the minimised plants' max — not γ, which is the bounded plants' max when every
/// plant has a bound — and never where a violated bound's penalty is in the objective or the
/// controller's term is ε·s(Ak).
fn problem_norm_active(problem: &Problem, opts: &DesignOptions, fig: &Figures, plants: &[PlantValue]) -> bool {
    if plants.is_empty() {
        return controller_norm_active(opts, fig.gamma, fig.k_hinf);
    }
    let (free_max, violation) = plant_part(plants);
    !problem.controller_term_is_abscissa()
        && free_max > f64::NEG_INFINITY
        && violation == 0.0
        && controller_norm_active(opts, free_max, fig.k_hinf)
}

/// The most free controller variables a design takes: BFGS (`optim::bfgs`) keeps a dense
/// inverse-Hessian approximation of nvar² numbers, 3.2 GB at this size, allocated before any
/// budget is looked at (an order-400 controller of a 400-state plant asked for 207 GB and the
/// process was aborted). The method is for low orders: the largest design of the shipped
/// campaigns has a few hundred variables.
pub const MAX_VARIABLES: usize = 20_000;

/// The design's free variables: the structure's free entries (every entry without one), Dk's
/// counted as the dimension of the H2 feedthrough set when the h2 objective constrains Dk (a
/// structure then leaves Dk free, checked by [`check`]).
fn free_variables(shape: ControllerShape, structure: Option<&Structure>, h2: Option<&H2Feedthrough>) -> usize {
    let ndk = shape.m * shape.p;
    let split = shape.nvar() - ndk;
    let (others, dk) = match structure {
        None => (split, ndk),
        Some(s) => {
            let free = |e: &[Option<f64>]| e.iter().filter(|v| v.is_none()).count();
            (free(&s.entries()[..split]), free(&s.entries()[split..]))
        }
    };
    others + h2.map_or(dk, |h| h.0.dim())
}

/// The outcome of a design with no free variable ([`free_variables`] = 0): its one controller
/// (the structure's fixed entries, Dk projected onto the H2 feedthrough set), evaluated once.
/// Stable and stabilising (K stable too for the strong objective): [`DesignStatus::Converged`],
/// with the certificate dnorm = 0 of a point that is the whole feasible set; else
/// [`DesignStatus::NotStabilised`]. Either way the search's stop is
/// [`SearchStop::NoFreeVariable`].
fn fixed_design(
    problem: &Problem,
    opts: &DesignOptions,
    shape: ControllerShape,
    structure: Option<&Structure>,
    h2: Option<&H2Feedthrough>,
) -> DesignOutcome {
    let cpu0 = crate::optim::thread_cpu_time();
    let plant = problem.first();
    let k = match structure {
        Some(s) => s.controller(shape, &[]),
        None => shape.controller(&vec![0.0; shape.nvar()]),
    };
    let k = match h2 {
        Some(h) => Controller { dk: h.project(&k.dk), ..k },
        None => k,
    };
    let multi = (!problem.is_single_hinf()).then_some(problem);
    let (fig, plants) = outcome_figures(plant, multi, opts, &k, Interrupt::NEVER);
    let strong = opts.objective == ObjectiveKind::Strong;
    let alpha = match fig.alpha_k {
        Some(a) if strong => nan_max(fig.alpha_cl, opts.eps * a),
        _ => fig.alpha_cl,
    };
    let ended = if is_stable(alpha) {
        (DesignStatus::Converged, Some(Certificate { dnorm: 0.0, evaldist: 0.0 }))
    } else {
        (DesignStatus::NotStabilised { best_alpha: alpha }, None)
    };
    let cpu = crate::optim::thread_cpu_time() - cpu0;
    let phases = vec![PhaseStats { phase: Phase::Stabilisation, iters: 0, evals: 1, cpu_s: cpu }];
    let search = SearchSummary {
        starts: 0,
        best_start: 0,
        best_start_kind: None,
        best_start_scaled: false,
        cpu_to_best_s: cpu,
        evals_to_best: 1,
        stop: SearchStop::NoFreeVariable,
    };
    outcome(problem, k, fig, plants, opts, ended, phases, cpu, search)
}

/// The status the returned controller itself supports. The search calls a point stable once
/// its measure is below 0, so it can end on the boundary (the abscissa objective under strong
/// stabilisation ended at α ≈ −4e-12 and was journaled "stopped" while `design` refused to write
/// the controller): a controller that is not stable with the verification margin
/// ([`stabilises`](super::stabilises)) is [`DesignStatus::NotStabilised`] whatever the search said, and a
/// stabilising one that violates a plant's bound is [`DesignStatus::BoundViolated`]. Interrupted
/// and not-stabilised runs keep their status.
fn verified_status(
    status: DesignStatus,
    problem: &Problem,
    opts: &DesignOptions,
    k: &Controller,
    plants: &[PlantValue],
) -> DesignStatus {
    if matches!(status, DesignStatus::Interrupted | DesignStatus::NotStabilised { .. }) {
        return status;
    }
    match super::evaluate::stabilises(problem, opts, k) {
        Err(best_alpha) => DesignStatus::NotStabilised { best_alpha },
        Ok(()) if plants.iter().any(|v| !v.bound_met()) => DesignStatus::BoundViolated,
        Ok(()) => status,
    }
}

/// A problem's figures in place of the first plant's ([`design`]): γ the largest weighted value
/// of the unbounded plants (of all if each has a bound), α(A_cl) the largest, the objective
/// max(γ, ε‖K‖∞) (ε·s(Ak) in place of ε‖K‖∞ where [`Problem::controller_term_is_abscissa`]) plus
/// the penalty of violated bounds.
fn problem_figures(fig: &mut Figures, problem: &Problem, values: &[PlantValue], opts: &DesignOptions) {
    let (free_max, violation) = plant_part(values);
    fig.gamma = problem_gamma(values);
    fig.alpha_cl = values.iter().map(|v| v.alpha_cl).fold(f64::NEG_INFINITY, nan_max);
    let k_term = match opts.objective {
        ObjectiveKind::Strong if problem.controller_term_is_abscissa() => {
            fig.alpha_k.map_or(f64::NEG_INFINITY, |a| opts.eps * a)
        }
        ObjectiveKind::Strong => opts.eps * fig.k_hinf,
        ObjectiveKind::Plain => f64::NEG_INFINITY,
    };
    let top = nan_max(free_max, k_term);
    fig.objective = if top == f64::NEG_INFINITY { 0.0 } else { top } + PENALTY_WEIGHT * violation;
}

/// Refuses at once a structure that fixes every entry of D_K at a matrix for which a plant's
/// loop is ill posed (I − D_K·D22 singular, `lti::MAX_LOOP_CONDITION`): every controller of it
/// is, and the search spent its whole budget before the closed loop could not be formed.
fn fixed_dk_well_posed(s: &Structure, shape: ControllerShape, problem: &Problem) -> Result<(), DesignError> {
    let ndk = shape.m * shape.p;
    let split = shape.nvar() - ndk;
    if ndk == 0 || s.entries()[split..].iter().any(Option::is_none) {
        return Ok(());
    }
    // D_K alone decides well-posedness: the free entries may be anything (0 here)
    let x: Vec<f64> = s.entries().iter().map(|e| e.unwrap_or(0.0)).collect();
    let k = shape.controller(&x);
    for t in &problem.terms {
        let k = k.clone().in_domain(t.plant.domain);
        if let Err(crate::lti::LtiError::IllPosed { cond }) = closed_loop(&t.plant, &k) {
            return Err(opt_err(
                "structure",
                format!(
                    "fixes every entry of DK at a matrix for which the loop with {} is ill posed (I − DK·D22 has \
                     condition number {cond:.3e}): no controller of this structure can be evaluated; free an entry of DK",
                    t.plant.name
                ),
            ));
        }
    }
    Ok(())
}

/// With the strong objective, refuses at once a structure that fixes every entry of A_K at a
/// matrix that is not stable with the verification margin: no controller of it is stable, and
/// the search would spend its whole budget and then not say why.
fn fixed_ak_stable(
    s: &Structure,
    shape: ControllerShape,
    opts: &DesignOptions,
    domain: TimeDomain,
) -> Result<(), DesignError> {
    let nk = shape.nk;
    if opts.objective != ObjectiveKind::Strong || nk == 0 {
        return Ok(());
    }
    let Some(ak) = s.entries()[..nk * nk].iter().copied().collect::<Option<Vec<f64>>>() else { return Ok(()) };
    let ak = faer::Mat::from_fn(nk, nk, |i, j| ak[i + j * nk]);
    let verified = verified_stability(domain, ak.as_ref());
    if verified.is_stable() {
        return Ok(());
    }
    let (name, value) = domain.stability_quantity(verified.measure);
    Err(opt_err(
        "structure",
        format!(
            "fixes every entry of AK at a matrix that is not stable ({name}(AK) = {value:+.6e}): no controller of this \
             structure is stable, as the strong objective requires; free an entry of AK or use the plain objective"
        ),
    ))
}

/// With the strong objective, refuses at once a plant that no stable controller stabilises:
/// the parity interlacing property of its P22 fails (`lti::parity_interlacing`, Youla,
/// Bongiorno & Lu 1974), so the search could only spend its budget without a result. The error
/// names the zeros and the poles that prove it. Not part of [`validate`]: a campaign with such a
/// plant is a valid file whose strong jobs each fail at once with this message.
pub fn strongly_stabilisable(plant: &Plant, opts: &DesignOptions) -> Result<(), DesignError> {
    if opts.objective != ObjectiveKind::Strong {
        return Ok(());
    }
    // A discrete-time plant is strongly stabilisable iff its bilinear image is (stable
    // controllers and stabilising ones correspond, `lti::PlantImage`); the violation then names
    // the image's zeros and poles.
    match crate::lti::parity_interlacing(&continuous_time_image(plant)).and_then(|p| p.violation) {
        Some(v) => Err(DesignError::NotStronglyStabilisable(v)),
        None => Ok(()),
    }
}

fn opt_err(field: &'static str, problem: impl Into<String>) -> DesignError {
    DesignError::Options { field, problem: problem.into() }
}

/// Checks the options and the initial controller against the plant. This is the one validation
/// of design options: `campaign design` calls it through [`Design::run`](super::Design::run), and a campaign file calls it
/// for every problem before any job starts.
pub fn validate(plant: &Plant, opts: &DesignOptions, init: Option<&Controller>) -> Result<(), DesignError> {
    // each option on its own: the option table's checks (design/options.rs)
    opts.check_each().map_err(|(field, problem)| opt_err(field, problem))?;
    if opts.stall_starts > 0
        && !opts.cpumax.is_finite()
        && opts.maxevals.is_none()
        && opts.max_starts.is_none()
        && opts.stall_rtol == 0.0
    {
        return Err(opt_err(
            "stall_rtol",
            "must be > 0 when no budget (cpumax, maxevals, max_starts) bounds the search",
        ));
    }
    if opts.order > plant.dims.n {
        return Err(opt_err(
            "order",
            format!("{} exceeds the plant order n = {} of {} (HIFOO's limit)", opts.order, plant.dims.n, plant.name),
        ));
    }
    if let Some(k) = init {
        k.check_fits(plant).map_err(|e| DesignError::Init(InitError::Shape(e)))?;
        if k.order() > opts.order {
            return Err(DesignError::Init(InitError::OrderTooHigh { order: k.order(), target: opts.order }));
        }
        if !k.is_finite() {
            return Err(DesignError::Init(InitError::NonFinite));
        }
    }
    Ok(())
}

/// The starting points: perturbations of the (padded) initial controller, or random.
fn starting_points(
    plant: &Plant,
    opts: &DesignOptions,
    init: Option<&Controller>,
    shape: ControllerShape,
    nvar: usize,
    vars: &dyn Fn(Vec<f64>) -> Vec<f64>,
    rng: &mut ChaCha8Rng,
) -> Vec<Vec<f64>> {
    match init {
        Some(k) => perturbed_starts(&vars(controller_to_x(&padded_to(plant, k, shape.nk))), opts.nrand, rng),
        None => random_starts(nvar, opts.nrand, rng),
    }
}

/// `k` (of order ≤ `nk`, checked by [`validate`]) padded to order `nk` with decoupled stable
/// modes at [`padding_diagonal`] (`--init`'s padding, docs/ALGORITHMS.md §8.2).
fn padded_to(plant: &Plant, k: &Controller, nk: usize) -> Controller {
    if k.order() < nk {
        pad_controller(k, nk, padding_diagonal(plant, k)).expect("order checked by validate")
    } else {
        k.clone()
    }
}

/// Figures recomputed from a controller (never from optimiser bookkeeping).
struct Figures {
    gamma: f64,
    k_hinf: f64,
    alpha_cl: f64,
    alpha_k: Option<f64>,
    objective: f64,
}

/// The figures of `k`, γ by the norm `check` and the reports use (`lti::hinf_norm_checked`: the
/// level-set norm checked on a frequency grid). On large plants these figures are what a run
/// spends after its budget (the evaluation in flight is abandoned, these are not). `stop` fires
/// only for a cancelled run (Ctrl-C) of a large plant: then α(Acl) and γ may be left NaN ("not
/// computed") rather than keep the user waiting.
fn figures(plant: &Plant, opts: &DesignOptions, k: &Controller, stop: Interrupt<'_>) -> Figures {
    let (alpha_cl, gamma) = match closed_loop(plant, k) {
        Ok(_) if stop.poll().is_err() => (f64::NAN, f64::NAN),
        Ok(cl) => match eigenvalues_of(cl.a.as_ref()) {
            Some(poles) => {
                let a = stability_measure_of(plant.domain, &poles);
                let g = if is_stable(a) && cl.is_finite() {
                    let params = HinfParams::new(opts.hinf_tol).with_stop(stop);
                    // checked on a frequency grid, as `check` and the reports are (a discrete
                    // loop sampled at Ts = 1e-7 read 1.8 % low unchecked: `lti::hinf_norm_checked`)
                    hinf_norm_checked_with(plant.domain, &cl, &params).map_or(f64::NAN, |h| h.value)
                } else {
                    f64::INFINITY
                };
                (a, g)
            }
            None => (f64::INFINITY, f64::INFINITY),
        },
        Err(_) => (f64::INFINITY, f64::INFINITY),
    };
    let k_hinf = controller_hinf_grad(k, opts.hinf_tol).0.value;
    let alpha_k = (k.order() > 0).then(|| stability_measure(k.domain, k.ak.as_ref()));
    let objective = match opts.objective {
        _ if gamma.is_nan() => f64::NAN, // not computed (f64::max would drop it)
        ObjectiveKind::Strong => gamma.max(opts.eps * k_hinf),
        ObjectiveKind::Plain => gamma,
    };
    Figures { gamma, k_hinf, alpha_cl, alpha_k, objective }
}

/// Whether ε‖K‖∞ ≥ ‖Tzw‖∞ within [`NORM_TIE_RTOL`] (0.1 %), i.e. the controller-norm term sets
/// max(‖Tzw‖∞, ε‖K‖∞) (false for an unstable controller, ‖K‖∞ = ∞: then the controller is simply
/// not strongly stabilising). A search often ends on the ridge ‖Tzw‖∞ = ε‖K‖∞, where which of the
/// two computed norms is the larger is rounding (REA2 n_K = 0, ε = 1e3: 827.6063929658643 against
/// 827.6063929658555) or the last few iterations (ε‖K‖∞ 0.03 % below γ on a user's plant, which
/// the norms' own tolerance `hinf_tol` called inactive): within what a reader of 4 significant
/// figures sees as one number the term counts as active.
pub(crate) fn controller_norm_active(opts: &DesignOptions, gamma: f64, k_hinf: f64) -> bool {
    opts.objective == ObjectiveKind::Strong
        && gamma.is_finite()
        && k_hinf.is_finite()
        && opts.eps * k_hinf >= gamma * (1.0 - NORM_TIE_RTOL)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// ε‖K‖∞ 0.03 % below γ is active (the user's case), 1 % below is not, a plain design never.
    #[test]
    fn the_controller_norm_is_active_within_what_a_reader_sees() {
        let strong = DesignOptions { eps: 1.0, ..DesignOptions::default() };
        assert!(controller_norm_active(&strong, 1.0, 1.0 - 3e-4));
        assert!(controller_norm_active(&strong, 1.0, 1.2));
        assert!(!controller_norm_active(&strong, 1.0, 0.99));
        assert!(!controller_norm_active(&strong, 1.0, f64::INFINITY));
        let plain = DesignOptions { objective: ObjectiveKind::Plain, ..strong };
        assert!(!controller_norm_active(&plain, 1.0, 1.2));
    }
}
