//! The certificate's gradient units under strong stabilisation (`Objective::gradient_unit`,
//! docs/ALGORITHMS.md §7.3): ε exactly where the controller's term sets the objective, so that
//! the certificate weighs that term's gradient as ∇‖K‖∞ (∇α(Ak) when stabilising), not ε times it.

use std::cell::RefCell;
use std::rc::Rc;

use hinfix::design::{ComponentCache, ControllerShape, Design, DesignObjective, DesignOptions, ObjectivePhase};
use hinfix::lti::{Plant, DEFAULT_HINF_TOL};
use hinfix::optim::Objective;

#[test]
fn the_controller_term_is_measured_in_its_own_unit_and_only_where_it_sets_f() {
    let p = Plant::load(format!("{}/plants/HE1.json", env!("CARGO_MANIFEST_DIR"))).unwrap();
    // A stabilising, stable order-1 controller of HE1 from a short design.
    let opts = DesignOptions { order: 1, seed: 1, maxevals: Some(3000), stall_starts: 0, ..Default::default() };
    let k = Design::for_plant(&p, &opts).run().unwrap().controller;
    let shape = ControllerShape::for_plant(&p, 1);
    let mut x = vec![0.0; shape.nvar()];
    shape.write_x(&k, &mut x);
    let (mut set_by_k, mut set_by_loop) = (0, 0);
    for phase in [ObjectivePhase::Stabilisation, ObjectivePhase::Performance] {
        for eps in [1e-6, 1e-3, 1.0, 1e3] {
            for strong in [true, false] {
                let cache = Rc::new(RefCell::new(ComponentCache::default()));
                let mut obj = DesignObjective::new(&p, shape, phase, strong, eps, DEFAULT_HINF_TOL, Rc::clone(&cache));
                assert_eq!(obj.gradient_unit(&x), 1.0, "a point not evaluated yet");
                let mut g = vec![0.0; x.len()];
                let f = obj.eval(&x, &mut g);
                assert!(f.is_finite(), "{phase:?} ε = {eps}");
                let c = cache.borrow().lookup(&x).expect("evaluated, so cached");
                let k_term = match phase {
                    ObjectivePhase::Stabilisation => eps * c.alpha_k,
                    ObjectivePhase::Performance => eps * c.k_hinf,
                };
                let unit = obj.gradient_unit(&x);
                if strong && f == k_term {
                    assert_eq!(unit, eps, "{phase:?} ε = {eps}: the controller's term sets f = {f}");
                    set_by_k += 1;
                } else {
                    assert_eq!(unit, 1.0, "{phase:?} ε = {eps} strong = {strong}: f = {f}, controller term {k_term}");
                    set_by_loop += 1;
                }
            }
        }
    }
    assert!(set_by_k >= 2 && set_by_loop >= 2, "both cases are met: {set_by_k} and {set_by_loop}");
}

/// The same units for a problem of several plants (`multi_objective`): HE1 with weight
/// 1 + 1e-7, and HE1 twice, at order 0 (ε = 1e-3, the first starts only, deterministic) end where
/// HE1 alone does. With the unit 1 for problems, ε∇‖K‖∞ (of norm ε = 1e-3 for a static gain, =
/// normtol) certified itself: both ended "converged" at dnorm = 1.00e-3, 3.6e-4 (weighted) and
/// 6.6e-4 (twice) above HE1's objective, on the ridge ‖Tzw‖∞ = ε‖K‖∞ short of its optimum.
#[test]
fn a_problem_of_several_plants_is_certified_in_the_same_units() {
    use hinfix::design::{PlantObjective, PlantTerm, Problem};
    let p = Plant::load(format!("{}/plants/HE1.json", env!("CARGO_MANIFEST_DIR"))).unwrap();
    let opts = DesignOptions { order: 0, stall_starts: 0, ..Default::default() };
    let alone = Design::for_plant(&p, &opts).run().unwrap();
    let weighted = Problem {
        terms: vec![PlantTerm { plant: p.clone(), objective: PlantObjective::Hinf, weight: 1.0 + 1e-7, bound: None }],
    };
    let twice = Problem { terms: vec![PlantTerm::hinf(p.clone()), PlantTerm::hinf(p.clone())] };
    for (name, problem) in [("weighted", weighted), ("twice", twice)] {
        let o = Design::new(&problem, &opts).run().unwrap();
        let rel = (o.objective - alone.objective) / alone.objective;
        assert!(rel.abs() < 2e-6, "{name}: objective {} against HE1's {} ({rel:.1e})", o.objective, alone.objective);
        let dnorm = o.certificate.unwrap().dnorm;
        assert!(dnorm < 1e-4, "{name}: certified at dnorm = {dnorm:.2e}");
    }
}
