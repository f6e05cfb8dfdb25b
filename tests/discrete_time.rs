//! Discrete-time plants end to end (docs/ALGORITHMS.md §10): the `Ts` key of plant and controller
//! files, the domain check of the closed loop, the design objectives' gradients against finite
//! differences, central starts through the bilinear image, a design of HE1 sampled at
//! Ts = 0.1 s verified against an independent recomputation, and the full-order γ approaching the
//! continuous one as Ts shrinks. The plants are `examples/discrete/HE1_Ts*.json`
//! (`make_plants.py` there: HE1 with a zero-order hold).

mod common;

use std::cell::RefCell;
use std::path::PathBuf;
use std::rc::Rc;

use hinfix::design::{
    central_starts, controller_to_x, ComponentCache, ControllerShape, Design, DesignObjective, DesignOptions,
    ObjectivePhase,
};
use hinfix::lti::{
    closed_loop, controller_to_mat, full_order_gamma, hinf_norm, hinf_norm_discrete, plant_to_mat, resolve_plant,
    spectral_radius, Controller, ControllerErrorKind, HinfParams, LtiError, Plant, PlantErrorKind, PlantImage,
    TimeDomain,
};

fn example(name: &str) -> Plant {
    Plant::load(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("examples/discrete").join(name)).unwrap()
}

fn he1() -> Plant {
    Plant::load(resolve_plant("HE1").unwrap()).unwrap()
}

/// HE1's JSON with `extra` added at the top level.
fn he1_text_with(extra: &str) -> String {
    let text = std::fs::read_to_string(resolve_plant("HE1").unwrap()).unwrap();
    let open = text.find('{').unwrap();
    format!("{{{extra}, {}", &text[open + 1..])
}

#[test]
fn a_sampling_time_makes_a_discrete_plant_and_a_bad_one_is_named() {
    let continuous = he1();
    assert_eq!(continuous.domain, TimeDomain::Continuous);
    let p = Plant::from_json_str(&he1_text_with(r#""Ts": 0.25"#), "he1.json").unwrap();
    assert_eq!(p.domain, TimeDomain::Discrete { ts: 0.25 });
    // same matrices, another plant: its identity (job ids) differs; Ts = 0 is continuous time
    assert_ne!(p.fingerprint(), continuous.fingerprint());
    let zero = Plant::from_json_str(&he1_text_with(r#""Ts": 0"#), "he1.json").unwrap();
    assert_eq!((zero.domain, zero.fingerprint()), (TimeDomain::Continuous, continuous.fingerprint()));
    // round trips: JSON and MAT-file keep Ts
    let back = Plant::from_json_str(&p.to_json().to_string(), "back.json").unwrap();
    assert_eq!((back.domain, back.fingerprint()), (p.domain, p.fingerprint()));
    let mat = Plant::from_mat_bytes(&plant_to_mat(&p), "HE1.mat").unwrap();
    assert_eq!((mat.domain, mat.fingerprint()), (p.domain, p.fingerprint()));
    for (bad, says) in [
        (r#""Ts": -0.1"#, "from 1e-50 to 1e50"),
        (r#""Ts": "0.1""#, "must be a number"),
        (r#""Ts": [0.1]"#, "must be a number"),
        (r#""Ts": 1e400"#, "invalid JSON"),
    ] {
        let e = Plant::from_json_str(&he1_text_with(bad), "he1.json").unwrap_err();
        let text = e.to_string();
        assert!(text.contains("he1.json") && text.contains(says), "{bad}: {text}");
        if !says.contains("JSON") {
            assert!(matches!(&e.kind, PlantErrorKind::BadField { field, .. } if field == "Ts"), "{bad}: {e}");
        }
    }
}

#[test]
fn a_controller_carries_its_sampling_time_and_must_match_the_plant() {
    let p = example("HE1_Ts0.1.json");
    let k = Controller::zeros(1, 2, 1).in_domain(p.domain);
    let json = k.to_json();
    assert_eq!(json["Ts"], serde_json::json!(0.1));
    assert_eq!(Controller::from_json_value(&json).unwrap(), k);
    let mat = hinfix::lti::read_mat_vars(&controller_to_mat(&k)).unwrap();
    assert_eq!(mat["Ts"].data, vec![0.1]);
    assert!(k.check_fits(&p).is_ok());
    // a continuous controller on the discrete plant, and the discrete one on HE1, do not fit
    let kc = Controller::zeros(1, 2, 1);
    let e = kc.check_fits(&p).unwrap_err();
    assert!(matches!(&e, ControllerErrorKind::Mismatch { problem, .. } if problem.contains("continuous time")), "{e}");
    assert!(k.check_fits(&he1()).is_err());
    let e = closed_loop(&p, &kc).unwrap_err();
    assert!(matches!(e, LtiError::DomainMismatch { .. }), "{e}");
    let e = Controller::from_json_str(r#"{"AK": [], "BK": [], "CK": [[]], "DK": [[1.0]], "Ts": -1}"#, "k.json")
        .unwrap_err();
    assert!(e.to_string().contains("k.json") && e.to_string().contains("`Ts`"), "{e}");
}

/// Central differences of the stabilisation (ρ − 1) and performance (unit-circle norm) objectives
/// of a discrete-time design against their gradients, at controllers where they are smooth.
#[test]
fn discrete_design_objectives_have_exact_gradients() {
    let p = example("HE1_Ts0.1.json");
    let shape = ControllerShape::for_plant(&p, 2);
    // a stabilising, strongly stable controller early in a search (not at a nonsmooth optimum)
    let opts = DesignOptions { order: 2, seed: 4, maxevals: Some(300), ..Default::default() };
    let k = Design::for_plant(&p, &opts).run().unwrap().controller;
    let x0: Vec<f64> =
        controller_to_x(&k).iter().enumerate().map(|(i, v)| v * (1.0 + 1e-3 * (i as f64).sin())).collect();
    for (phase, strong, eps) in [
        (ObjectivePhase::Stabilisation, false, 0.0),
        (ObjectivePhase::Stabilisation, true, 10.0),
        (ObjectivePhase::Performance, false, 0.0),
        (ObjectivePhase::Performance, true, 1e-3),
    ] {
        let cache = Rc::new(RefCell::new(ComponentCache::default()));
        let mut obj = DesignObjective::new(&p, shape, phase, strong, eps, 1e-12, cache);
        let worst = common::worst_fd_error(&mut obj, &x0, &format!("{phase:?}"));
        assert!(worst < 1e-5, "{phase:?} strong={strong}: worst relative error {worst:.2e}");
    }
}

/// A small discrete-time plant with an unstable mode (z = 1.05) and regular D12, D21.
fn small_discrete_plant() -> Plant {
    let text = r#"{
        "name": "small-discrete", "Ts": 0.05,
        "A": [[1.05, 0.1, 0.0], [0.0, 0.5, 0.2], [0.1, 0.0, -0.3]],
        "B1": [[0.5, 0.0], [0.2, 0.0], [0.0, 0.0]], "B2": [[1.0], [0.5], [0.2]],
        "C1": [[1.0, 0.0, 0.0], [0.0, 0.0, 0.0]], "C2": [[1.0, 0.5, 0.0]],
        "D11": [[0.0, 0.0], [0.0, 0.0]], "D12": [[0.0], [1.0]],
        "D21": [[0.0, 1.0]], "D22": [[0.0]]
    }"#;
    Plant::from_json_str(text, "<inline>").unwrap()
}

/// The central starts of a discrete plant are those of its bilinear image taken back: discrete,
/// stabilising, and each with exactly the closed-loop norm its image has on the image plant (the
/// loop commutes with the map, docs/ALGORITHMS.md §10.4–10.5). (The sampled HE1's image has
/// D21, P21 at z = −1, of 2e-3, nearly singular; where its central controllers fail, the starts
/// are skipped, as for any plant.)
#[test]
fn central_starts_of_a_discrete_plant_are_its_images_taken_back() {
    let p = small_discrete_plant();
    let image = PlantImage::new(&p).unwrap();
    let ours = central_starts(&p, p.dims.n, &[1.1, 2.0]);
    let of_image = central_starts(&image.plant, p.dims.n, &[1.1, 2.0]);
    assert!(!ours.is_empty() && ours.len() == of_image.len(), "{} vs {}", ours.len(), of_image.len());
    for ((f, k), (_, kc)) in ours.iter().zip(&of_image) {
        assert_eq!((k.domain, kc.domain), (p.domain, TimeDomain::Continuous));
        assert_eq!(*k, image.controller_back(kc).unwrap());
        let cl = closed_loop(&p, k).unwrap();
        assert!(spectral_radius(cl.a.as_ref()) < 1.0, "f = {f}: unstable");
        let g = hinf_norm_discrete(&cl, &HinfParams::new(1e-12)).unwrap().value;
        let gc = hinf_norm(&closed_loop(&image.plant, kc).unwrap(), &HinfParams::new(1e-12)).unwrap().value;
        assert!((g - gc).abs() <= 1e-8 * gc, "f = {f}: discrete {g} vs image {gc}");
    }
    // the sampled HE1's image has D21 = 2e-3, nearly singular: with the Riccati constant terms as
    // Gram products (docs/ALGORITHMS.md §9.1) its central controllers are built; whatever starts
    // there are must be discrete and stabilising
    let he1 = example("HE1_Ts0.1.json");
    for (f, k) in central_starts(&he1, 4, &[1.1, 2.0]) {
        assert_eq!(k.domain, he1.domain);
        let cl = closed_loop(&he1, &k).unwrap();
        assert!(spectral_radius(cl.a.as_ref()) < 1.0, "HE1 f = {f}: unstable");
    }
}

/// A strong design of the sampled HE1: a discrete controller, stable, stabilising, whose γ and
/// ‖K‖∞ are those an independent recomputation finds, at or above the full-order γ.
#[test]
fn a_sampled_plant_is_designed_and_verified_in_discrete_time() {
    let p = example("HE1_Ts0.1.json");
    let opts = DesignOptions { order: 1, eps: 1e-3, seed: 1, maxevals: Some(20_000), ..Default::default() };
    let o = Design::for_plant(&p, &opts).run().unwrap();
    let k = &o.controller;
    assert_eq!(k.domain, TimeDomain::Discrete { ts: 0.1 });
    let cl = closed_loop(&p, k).unwrap();
    let rho_cl = spectral_radius(cl.a.as_ref());
    let rho_k = spectral_radius(k.ak.as_ref());
    assert!(rho_cl < 1.0 && rho_k < 1.0, "ρ(Acl) = {rho_cl}, ρ(Ak) = {rho_k}");
    assert_eq!((o.alpha_cl, o.alpha_k), (rho_cl - 1.0, Some(rho_k - 1.0)));
    let gamma = hinf_norm_discrete(&cl, &HinfParams::new(1e-10)).unwrap().value;
    assert!((o.gamma - gamma).abs() <= 1e-8 * gamma, "{} vs {gamma}", o.gamma);
    let full = full_order_gamma(&p).unwrap().gamma;
    assert!(o.gamma >= full * (1.0 - 1e-6), "γ = {} below the full-order {full}", o.gamma);
    // a continuous-time reading of the same matrices is another problem: its γ differs
    let mut as_continuous = p.clone();
    as_continuous.domain = TimeDomain::Continuous;
    let kc = k.clone().in_domain(TimeDomain::Continuous);
    let clc = closed_loop(&as_continuous, &kc).unwrap();
    assert!(hinfix::lti::spectral_abscissa(clc.a.as_ref()) > 0.0, "ρ < 1 is not α < 0");
}

/// As the sampling time shrinks, the sampled plant's full-order γ approaches the continuous
/// plant's from above (a zero-order hold loses what happens between samples).
#[test]
fn the_full_order_gamma_approaches_the_continuous_one_as_ts_shrinks() {
    let c = full_order_gamma(&he1()).unwrap().gamma;
    let g01 = full_order_gamma(&example("HE1_Ts0.1.json")).unwrap().gamma;
    let g001 = full_order_gamma(&example("HE1_Ts0.01.json")).unwrap().gamma;
    assert!(g01 > g001 && g001 > c * (1.0 - 1e-6), "{g01} {g001} {c}");
    assert!((g001 - c) / c < 0.01 && (g01 - c) / c > 0.05, "{g01} {g001} {c}");
}
