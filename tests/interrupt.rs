//! Budget and cancellation inside one evaluation: the stop hook
//! (`lti::Interrupt`) is polled inside the H∞ norm, an interrupted evaluation yields no value, and
//! the optimiser then stops with its honest reason, keeping the last completed value.
//!
//! Every trigger is deterministic: a closure that fires after k polls, or a cancel flag.

use std::cell::{Cell, RefCell};
use std::rc::Rc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

use faer::Mat;
use hinfix::design::{ComponentCache, Design, MIN_ORDER_FOR_INTERRUPT};
use hinfix::design::{ControllerShape, DesignObjective, DesignOptions, ObjectivePhase, SearchStop};
use hinfix::lti::{
    closed_loop, closed_loop_hinf_grad, hinf_norm, Controller, HinfParams, Interrupt, Interrupted, LtiError, Plant,
    StateSpace, DEFAULT_HINF_TOL,
};
use hinfix::optim::{bfgs, BfgsOptions, NoObserver, Objective, OptimError, RunControl, Termination};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

mod common;

/// A random stable plant (A = R/√n − I with R uniform in [−1, 1]: spectral radius of R/√n ≈ 0.6).
fn random_plant(n: usize, seed: u64) -> Plant {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let s = 1.0 / (n as f64).sqrt();
    let mut m = |r: usize, c: usize, scale: f64| Mat::from_fn(r, c, |_, _| scale * (rng.random::<f64>() * 2.0 - 1.0));
    let mut a = m(n, n, s);
    for i in 0..n {
        a[(i, i)] -= 1.0;
    }
    let (m1, m2, p1, p2) = (2, 2, 2, 2);
    let mats = [
        a,
        m(n, m1, 1.0),
        m(n, m2, 1.0),
        m(p1, n, 1.0),
        m(p2, n, 1.0),
        m(p1, m1, 0.1),
        m(p1, m2, 1.0),
        m(p2, m1, 1.0),
        Mat::zeros(p2, m2),
    ];
    Plant { description: "random stable test plant".into(), ..common::plant_of(&format!("RAND{n}"), mats) }
}

/// A counter hook: fires from poll number `k + 1` on (so it lets exactly `k` polls pass).
fn after(k: usize, polls: &Cell<usize>) -> impl Fn() -> bool + '_ {
    move || {
        polls.set(polls.get() + 1);
        polls.get() > k
    }
}

#[test]
fn hinf_norm_is_interrupted_at_every_poll_or_exact() {
    let p = random_plant(40, 1);
    let sys = StateSpace { a: p.a.clone(), b: p.b1.clone(), c: p.c1.clone(), d: p.d11.clone() };
    let exact = hinf_norm(&sys, &HinfParams::default()).unwrap();
    assert!(exact.value.is_finite() && exact.value > 0.0);
    let polls = Cell::new(0);
    let count = after(usize::MAX, &polls);
    let counted = hinf_norm(&sys, &HinfParams::default().with_stop(Interrupt::new(&count))).unwrap();
    assert_eq!(counted.value.to_bits(), exact.value.to_bits(), "polling changes nothing");
    let total = polls.get();
    assert!(total >= 3, "the norm polls between its steps ({total} polls)");
    for k in 0..total {
        let polls = Cell::new(0);
        let hook = after(k, &polls);
        assert_eq!(
            hinf_norm(&sys, &HinfParams::default().with_stop(Interrupt::new(&hook))),
            Err(Interrupted),
            "hook firing at poll {} of {total} must interrupt",
            k + 1
        );
        assert_eq!(polls.get(), k + 1, "no poll after the hook fired");
    }
    let polls = Cell::new(0);
    let hook = after(total, &polls);
    assert_eq!(hinf_norm(&sys, &HinfParams::default().with_stop(Interrupt::new(&hook))), Ok(exact));
}

#[test]
fn closed_loop_gradient_is_interrupted() {
    let plant = random_plant(30, 2);
    let k = Controller::zeros(0, 2, 2);
    let exact = closed_loop_hinf_grad(&plant, &k, &HinfParams::default()).unwrap();
    let never = || false;
    let same = closed_loop_hinf_grad(&plant, &k, &HinfParams::default().with_stop(Interrupt::new(&never))).unwrap();
    assert_eq!(exact.0, same.0);
    let polls = Cell::new(0);
    let late = after(0, &polls);
    let hook = Interrupt::new(&late);
    assert!(matches!(
        closed_loop_hinf_grad(&plant, &k, &HinfParams::default().with_stop(hook)),
        Err(LtiError::Interrupted(Interrupted))
    ));
}

fn perf_objective(plant: &Plant, stop: Option<Rc<dyn Fn() -> bool>>) -> DesignObjective<'_> {
    let shape = ControllerShape { nk: 0, m: plant.dims.m2, p: plant.dims.p2, domain: Default::default() };
    let cache = Rc::new(RefCell::new(ComponentCache::default()));
    DesignObjective::new(plant, shape, ObjectivePhase::Performance, true, 1e-3, DEFAULT_HINF_TOL, cache)
        .with_interrupt(stop)
}

#[test]
fn interrupted_evaluation_has_no_value_and_is_not_cached() {
    let plant = random_plant(MIN_ORDER_FOR_INTERRUPT, 3);
    let x = vec![0.01, -0.02, 0.03, 0.0];
    let mut g = vec![0.0; 4];
    let f_exact = perf_objective(&plant, None).eval(&x, &mut g);
    assert!(f_exact.is_finite() && g.iter().all(|v| v.is_finite()));
    for k in [0, 1, 2, 5] {
        let polls = Rc::new(Cell::new(0usize));
        let p2 = Rc::clone(&polls);
        let hook: Rc<dyn Fn() -> bool> = Rc::new(move || {
            p2.set(p2.get() + 1);
            p2.get() > k
        });
        let mut obj = perf_objective(&plant, Some(hook));
        let mut g = vec![0.0; 4];
        let f = obj.eval(&x, &mut g);
        assert!(f.is_nan(), "k = {k}: interrupted evaluation returned {f}");
        assert!(g.iter().all(|v| v.is_nan()));
        assert_eq!(obj.cache().borrow().lookup(&x), None, "an abandoned evaluation is not cached");
        assert_eq!(polls.get(), k + 1);
    }
    // Below MIN_ORDER_FOR_INTERRUPT the hook is not polled at all.
    let small = random_plant(MIN_ORDER_FOR_INTERRUPT - 2, 3);
    let fired: Rc<dyn Fn() -> bool> = Rc::new(|| true);
    let f = perf_objective(&small, Some(fired)).eval(&x, &mut g);
    assert!(f.is_finite());
}

/// The hook fires inside an evaluation in the middle of a BFGS run and sets the run's cancel
/// flag (as Ctrl-C does): BFGS stops with `Interrupted` and returns the best completed point,
/// whose value a fresh, uninterrupted evaluation reproduces bit for bit.
#[test]
fn bfgs_stopped_inside_an_evaluation_keeps_the_last_complete_value() {
    let plant = random_plant(MIN_ORDER_FOR_INTERRUPT, 4);
    let x0 = vec![0.01, -0.02, 0.03, 0.0];
    let opts = BfgsOptions { maxit: 50, normtol: 1e-12, ..Default::default() };
    let full = bfgs(&mut perf_objective(&plant, None), &x0, 0, &opts, &RunControl::new(f64::INFINITY), &mut NoObserver)
        .unwrap();
    assert!(full.evals > 5, "the uninterrupted run makes several evaluations");
    for k in [40, 100, 250] {
        let flag = Arc::new(AtomicBool::new(false));
        let polls = Rc::new(Cell::new(0usize));
        let (p2, f2) = (Rc::clone(&polls), Arc::clone(&flag));
        let hook: Rc<dyn Fn() -> bool> = Rc::new(move || {
            p2.set(p2.get() + 1);
            if p2.get() > k {
                f2.store(true, Ordering::Relaxed);
            }
            f2.load(Ordering::Relaxed)
        });
        let ctl = RunControl::new(f64::INFINITY).with_cancel(Arc::clone(&flag));
        let r = bfgs(&mut perf_objective(&plant, Some(hook)), &x0, 0, &opts, &ctl, &mut NoObserver).unwrap();
        assert_eq!(r.termination, Termination::Interrupted, "k = {k}");
        assert!(r.evals < full.evals, "k = {k}: stopped early ({} of {} evaluations)", r.evals, full.evals);
        assert!(r.f.is_finite());
        let mut g = vec![0.0; 4];
        let again = perf_objective(&plant, None).eval(&r.x, &mut g);
        // Equal to the norm's tolerance, not bitwise: the design objective warm-starts the norm
        // at the previous peak, so a fresh objective may land on another attained σmax within it.
        assert!(
            (r.f - again).abs() <= 1e-9 * again.abs(),
            "k = {k}: the reported value {} is a complete evaluation ({again})",
            r.f
        );
    }
}

/// A spent CPU budget abandons even the starting evaluation: the solver reports no value.
#[test]
fn budget_spent_before_the_start_gives_no_value() {
    let plant = random_plant(MIN_ORDER_FOR_INTERRUPT, 5);
    let ctl = RunControl::new(0.0);
    let c2 = ctl.clone();
    let hook: Rc<dyn Fn() -> bool> = Rc::new(move || c2.cancelled() || c2.cpu_exhausted());
    let r = bfgs(&mut perf_objective(&plant, Some(hook)), &[0.0; 4], 0, &BfgsOptions::default(), &ctl, &mut NoObserver);
    assert!(matches!(r, Err(OptimError::NonFiniteStart { f }) if f.is_nan()), "{r:?}");
}

/// A whole design whose cancel flag is already set ends as interrupted. Below
/// `MIN_ORDER_FOR_INTERRUPT` its γ is recomputed from the returned controller; above, the final
/// figures are not waited for either (Ctrl-C): γ is NaN ("not computed"), never the value of an
/// abandoned evaluation.
#[test]
fn cancelled_design_reports_recomputed_figures_or_none() {
    for (n, recomputed) in [(MIN_ORDER_FOR_INTERRUPT - 10, true), (MIN_ORDER_FOR_INTERRUPT, false)] {
        let plant = random_plant(n, 6);
        let opts = DesignOptions { order: 0, nrand: 1, seed: 1, ..DesignOptions::default() };
        let flag = Arc::new(AtomicBool::new(true));
        let out = Design::for_plant(&plant, &opts).cancel(flag).run().unwrap();
        assert_eq!(out.search.stop, SearchStop::Interrupted);
        let k = &out.controller;
        let cl = closed_loop(&plant, k).unwrap();
        let gamma = hinf_norm(&cl, &HinfParams::new(opts.hinf_tol)).unwrap().value;
        if recomputed {
            assert_eq!(out.gamma.to_bits(), gamma.to_bits(), "n = {n}: γ {} vs recomputed {gamma}", out.gamma);
        } else {
            assert!(out.gamma.is_nan(), "n = {n}: γ {} should be left uncomputed", out.gamma);
            assert!(out.objective.is_nan(), "n = {n}: objective {} without γ", out.objective);
        }
    }
}
