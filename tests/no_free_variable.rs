//! A design with no free variable is evaluated once and answered at once (search stop
//! `no_free_variable`), under a budget that would otherwise let the search restart for minutes:
//! the continuous H2 objective on a plant whose feedthrough constraint D11 + D12·Dk·D21 = 0 has
//! one solution (`common::he1_with_feedthrough`: Dk = −[0.3; −0.2]), at order 0; and a structure that fixes every entry. Its figures are those of
//! the one controller, recomputed here by the norms themselves.

use std::time::Instant;

use hinfix::design::{
    ControllerShape, Design, DesignOptions, DesignStatus, PlantObjective, PlantTerm, Problem, SearchStop, Structure,
};
use hinfix::lti::{closed_loop, h2_norm, hinf_norm, resolve_plant, HinfParams, Plant};

mod common;

#[test]
fn h2_at_order_zero_with_a_forced_feedthrough_is_answered_at_once() {
    let p = common::he1_with_feedthrough();
    let problem = Problem {
        terms: vec![PlantTerm { plant: p.clone(), objective: PlantObjective::H2, weight: 1.0, bound: None }],
    };
    let opts = DesignOptions { order: 0, cpumax: 60.0, ..Default::default() };
    let t0 = Instant::now();
    let o = Design::new(&problem, &opts).run().unwrap();
    let secs = t0.elapsed().as_secs_f64();
    // not a timing target: the budget (60 s) was not spent; the evaluation count says "at once"
    assert!(secs < opts.cpumax / 2.0, "{secs} s");
    assert_eq!(o.search.stop, SearchStop::NoFreeVariable);
    assert_eq!((o.evaluations, o.search.starts), (1, 0));
    assert!((o.controller.dk[(0, 0)] + 0.3).abs() < 1e-12 && (o.controller.dk[(1, 0)] - 0.2).abs() < 1e-12);
    // the figures are the one controller's
    let cl = closed_loop(&p, &o.controller).unwrap();
    let alpha = hinfix::lti::spectral_abscissa(cl.a.as_ref());
    assert_eq!(o.alpha_cl, alpha);
    if alpha < 0.0 {
        assert_eq!(o.status, DesignStatus::Converged);
        let g = h2_norm(&cl);
        assert!((o.gamma - g).abs() <= 1e-10 * g, "{} against {g}", o.gamma);
    } else {
        assert_eq!(o.status, DesignStatus::NotStabilised { best_alpha: alpha });
    }
}

#[test]
fn a_structure_that_fixes_every_entry_is_evaluated_once() {
    let p = Plant::load(resolve_plant("HE1").unwrap()).unwrap();
    // a stabilising controller of order 1 to fix: a short design's
    let base = DesignOptions { order: 1, maxevals: Some(2000), ..Default::default() };
    let k = Design::for_plant(&p, &base).run().unwrap().controller;
    let shape = ControllerShape::for_plant(&p, 1);
    let entries = hinfix::design::controller_to_x(&k).into_iter().map(Some).collect();
    let s = Structure::from_entries(shape, entries).unwrap();
    assert_eq!(s.nfree(), 0);
    let opts = DesignOptions { order: 1, cpumax: 60.0, ..Default::default() };
    let t0 = Instant::now();
    let o = Design::new(&Problem::single(p.clone()), &opts).structure(Some(&s)).run().unwrap();
    let secs = t0.elapsed().as_secs_f64();
    // not a timing target: the budget (60 s) was not spent; the evaluation count says "at once"
    assert!(secs < opts.cpumax / 2.0, "{secs} s");
    assert_eq!(o.search.stop, SearchStop::NoFreeVariable);
    assert_eq!(o.controller, k);
    assert_eq!(o.status, DesignStatus::Converged);
    let cl = closed_loop(&p, &k).unwrap();
    let g = hinf_norm(&cl, &HinfParams::default()).unwrap().value;
    assert!((o.gamma - g).abs() <= 1e-8 * g, "{} against {g}", o.gamma);
    assert!(o.objective >= o.gamma);
}
