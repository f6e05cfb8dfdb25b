//! Per-evaluation cost of the design objectives on shipped plants (docs/ALGORITHMS.md §14): the
//! single-plant H∞ objective (today's path), the same plant with the H2 objective, with the
//! stability-radius objective, and two- and three-plant H∞ problems (HE1 at the operating points
//! of examples/multi-model). Each objective is evaluated with its gradient at one stabilising,
//! strongly stable controller (from a short single-plant design), in the performance phase of
//! strong stabilisation; the figure is the median over 7 rounds of the mean thread-CPU time per
//! evaluation. Run: `cargo bench --bench objectives`.

use std::cell::RefCell;
use std::path::PathBuf;
use std::rc::Rc;

use hinfix::design::{
    controller_to_x, ComponentCache, ControllerShape, Design, DesignObjective, DesignOptions, ObjectivePhase,
    PlantObjective, PlantTerm, Problem,
};
use hinfix::lti::{resolve_plant, Plant};
use hinfix::optim::{thread_cpu_time, Objective};

fn shipped(name: &str) -> Plant {
    Plant::load(resolve_plant(name).unwrap()).unwrap()
}

fn example(name: &str) -> Plant {
    Plant::load(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("examples/multi-model").join(name)).unwrap()
}

/// Median over rounds of the mean CPU seconds of one evaluation with gradient.
fn per_eval(obj: &mut DesignObjective<'_>, x: &[f64], evals: usize) -> f64 {
    let mut g = vec![0.0; x.len()];
    let f = obj.eval(x, &mut g);
    assert!(f.is_finite(), "the bench point must be stabilising: f = {f}");
    let mut rounds: Vec<f64> = (0..7)
        .map(|_| {
            let t0 = thread_cpu_time();
            for _ in 0..evals {
                std::hint::black_box(obj.eval(std::hint::black_box(x), &mut g));
            }
            (thread_cpu_time() - t0) / evals as f64
        })
        .collect();
    rounds.sort_by(f64::total_cmp);
    rounds[3]
}

/// The performance objective of strong stabilisation on `plant`, or on `problem` (whose first plant
/// must be `plant`'s) if given.
fn objective<'a>(
    plant: &'a Plant,
    shape: ControllerShape,
    problem: Option<&'a Problem>,
    eps: f64,
) -> DesignObjective<'a> {
    let plant = problem.map_or(plant, |q| q.first());
    let cache = Rc::new(RefCell::new(ComponentCache::default()));
    DesignObjective::new(plant, shape, ObjectivePhase::Performance, true, eps, 1e-10, cache).with_problem(problem, None)
}

fn main() {
    let eps = 1e-3;
    println!("{:<8} {:>3} {:<34} {:>12} {:>8}", "plant", "nK", "objective", "ms/eval", "× H∞");
    for (name, order, evals) in [("HE1", 2, 2000), ("AC8", 2, 300), ("REA2", 2, 2000)] {
        let p = shipped(name);
        let opts = DesignOptions { order, seed: 1, maxevals: Some(2000), ..Default::default() };
        let k = Design::for_plant(&p, &opts).run().unwrap().controller;
        let x = controller_to_x(&k);
        let shape = ControllerShape::for_plant(&p, order);
        let mk = |plant: &Plant, objective: PlantObjective| PlantTerm {
            plant: plant.clone(),
            objective,
            weight: 1.0,
            bound: None,
        };
        let single = |problem| objective(&p, shape, problem, eps);
        let base = per_eval(&mut single(None), &x, evals);
        let row = |what: &str, t: f64| println!("{name:<8} {order:>3} {what:<34} {:>12.4} {:>8.2}", 1e3 * t, t / base);
        row("H∞ (single-plant path)", base);
        let h2 = Problem { terms: vec![mk(&p, PlantObjective::H2)] };
        if h2.validate().is_ok_and(|s| s.is_none()) {
            row("H2", per_eval(&mut single(Some(&h2)), &x, evals));
        }
        let radius = Problem { terms: vec![mk(&p, PlantObjective::Radius)] };
        row("1/r_C", per_eval(&mut single(Some(&radius)), &x, evals));
        let twice = Problem { terms: vec![mk(&p, PlantObjective::Hinf), mk(&p, PlantObjective::Hinf)] };
        row("two-plant H∞ (the plant twice)", per_eval(&mut single(Some(&twice)), &x, evals));
    }
    // HE1 at its operating points (examples/multi-model)
    let ops: Vec<Plant> = (1..=3).map(|j| example(&format!("HE1_op{j}.json"))).collect();
    let opts = DesignOptions { order: 1, seed: 0, maxevals: Some(2000), ..Default::default() };
    let three = Problem {
        terms: ops
            .iter()
            .map(|p| PlantTerm { plant: p.clone(), objective: PlantObjective::Hinf, weight: 1.0, bound: None })
            .collect(),
    };
    let k = Design::new(&three, &opts).run().unwrap().controller;
    let x = controller_to_x(&k);
    let shape = ControllerShape::for_plant(&ops[0], 1);
    let cache = || Rc::new(RefCell::new(ComponentCache::default()));
    let base = per_eval(
        &mut DesignObjective::new(&ops[0], shape, ObjectivePhase::Performance, true, eps, 1e-10, cache()),
        &x,
        2000,
    );
    for n in 1..=3 {
        let problem = Problem { terms: three.terms[..n].to_vec() };
        let mut obj =
            DesignObjective::new(problem.first(), shape, ObjectivePhase::Performance, true, eps, 1e-10, cache())
                .with_problem(if n == 1 { None } else { Some(&problem) }, None);
        let t = per_eval(&mut obj, &x, 2000);
        println!(
            "{:<8} {:>3} {:<34} {:>12.4} {:>8.2}",
            "HE1_op",
            1,
            format!("H∞ on {n} operating point(s)"),
            1e3 * t,
            t / base
        );
    }
}
