//! The H2 norm and the complex stability radius against independent references, and the affine
//! parameterisation of the strictly proper loops' feedthroughs (docs/ALGORITHMS.md §13).
//!
//! * tests/fixtures/h2/cases.json (written once by its `gen_h2.py` with SLICOT's AB13BD and a
//!   numpy ω sweep): every H2 norm (continuous and discrete systems, closed loops of shipped
//!   plants formed here from the stored controller) to [`H2_REL_TOL`]; every 1/r_C to
//!   [`RADIUS_REL_TOL`] and never below the sweep's attained value by more, with the returned
//!   frequency attaining the returned value.
//! * The parameterisation: D11 + D12·Dk·D21 = 0 to rounding for random z, the basis orthonormal and
//!   orthogonal to Dk0, its dimension m2·p2 − rank D12·rank D21, every solution reached, and the
//!   errors (D22 ≠ 0, D11 outside the reachable set, non-finite data).
//! * The +∞ cases: D ≠ 0 in continuous time, unstable systems and loops, a loop whose feedthrough
//!   is not zero.
//!
//! The finite-difference checks of the gradients are in tests/lti_gradients.rs.

use std::path::PathBuf;

use faer::{c64, Mat};
use hinfix::lti::{
    closed_loop, closed_loop_h2_grad, closed_loop_inverse_stability_radius_grad, h2_feedthrough_parameterisation,
    h2_norm, h2_norm_discrete, h2_norm_grad, inverse_stability_radius, Controller, FeedthroughError, HinfParams,
    LtiError, Plant, StateSpace, H2_FEEDTHROUGH_RTOL,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;
use serde_json::Value;

/// Relative agreement required with AB13BD.
const H2_REL_TOL: f64 = 1e-10;
/// Relative agreement required with the ω sweep of σmin(iωI − A).
const RADIUS_REL_TOL: f64 = 1e-8;
/// The H∞ tolerance of the radius computation.
const RADIUS_HINF_TOL: f64 = 1e-12;

mod common;
use common::{json_matrix as mat, json_system};

fn len(v: &Value) -> usize {
    v.as_array().unwrap().len()
}

fn repo(path: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// σmin(iωI − A) by a dense complex SVD.
fn sigma_min(a: &Mat<f64>, w: f64) -> f64 {
    let n = a.nrows();
    let z = Mat::<c64>::from_fn(n, n, |i, j| c64::new(-a[(i, j)], if i == j { w } else { 0.0 }));
    z.singular_values().unwrap().into_iter().fold(f64::INFINITY, f64::min)
}

/// The stored controller of a closed-loop case (matrices of the stored shapes; empty ones from
/// the plant's dimensions).
fn stored_controller(case: &Value, plant: &Plant) -> Controller {
    let k = &case["controller"];
    let nk = len(&k["AK"]);
    let (m2, p2) = (plant.dims.m2, plant.dims.p2);
    Controller {
        ak: mat(&k["AK"], nk, nk),
        bk: mat(&k["BK"], nk, p2),
        ck: mat(&k["CK"], m2, nk),
        dk: mat(&k["DK"], m2, p2),
        domain: Default::default(),
    }
}

#[test]
fn h2_and_radius_cases_match_the_references() {
    let doc: Value =
        serde_json::from_str(&std::fs::read_to_string(repo("tests/fixtures/h2/cases.json")).unwrap()).unwrap();
    let cases = doc["cases"].as_array().unwrap();
    assert!(cases.len() >= 45, "{} cases", cases.len());
    let params = HinfParams::new(RADIUS_HINF_TOL);
    let (mut failures, mut worst_h2, mut worst_radius, mut radius_checked) = (Vec::new(), 0.0f64, 0.0f64, 0);
    let mut kinds = std::collections::BTreeMap::new();
    for case in cases {
        let name = case["name"].as_str().unwrap();
        let kind = case["kind"].as_str().unwrap();
        *kinds.entry(kind).or_insert(0) += 1;
        let sys = json_system(case);
        let discrete = case["time"] == "discrete";
        let want = case["h2"].as_f64().unwrap();
        let mut got = vec![if discrete { h2_norm_discrete(&sys) } else { h2_norm(&sys) }];
        if !discrete {
            got.push(h2_norm_grad(&sys).0);
        }
        let mut loop_radius = None;
        if kind == "closed-loop" {
            let plant = Plant::load(repo(&format!("plants/{}.json", case["plant"].as_str().unwrap()))).unwrap();
            let k = stored_controller(case, &plant);
            let cl = closed_loop(&plant, &k).unwrap();
            let scale = (sys.a.norm_l2() + sys.b.norm_l2() + sys.c.norm_l2()) * 1e-12;
            if (&cl.a - &sys.a).norm_l2() + (&cl.b - &sys.b).norm_l2() + (&cl.c - &sys.c).norm_l2() > scale {
                failures.push(format!("{name}: hinfix's loop is not the generator's"));
            }
            got.push(closed_loop_h2_grad(&plant, &k).unwrap().0);
            let lr = closed_loop_inverse_stability_radius_grad(&plant, &k, &params).unwrap().0;
            if lr != inverse_stability_radius(cl.a.as_ref(), &params).unwrap() {
                failures.push(format!("{name}: the loop's 1/r_C {lr:?} is not its matrix's"));
            }
            loop_radius = Some(lr);
        }
        let mut rel_h2 = 0.0f64;
        for g in got {
            let rel = (g - want).abs() / want;
            rel_h2 = rel_h2.max(rel);
            if rel.is_nan() || rel > H2_REL_TOL {
                failures.push(format!("{name} ({kind}): ‖G‖₂ {g} vs {want} (rel {rel:.2e})"));
            }
        }
        worst_h2 = worst_h2.max(rel_h2);
        eprint!("{name:40} {kind:15} ‖G‖₂ {want:.15e} (rel {rel_h2:.1e})");
        let Some(want_r) = case["radius_recip"].as_f64() else {
            eprintln!();
            continue;
        };
        let r = inverse_stability_radius(sys.a.as_ref(), &params).unwrap();
        if let Some(lr) = loop_radius {
            if (lr.value - r.value).abs() > 1e-9 * r.value {
                failures.push(format!("{name}: 1/r_C of hinfix's loop {lr:?}, of the generator's {r:?}"));
            }
        }
        let rel = (r.value - want_r).abs() / want_r;
        worst_radius = worst_radius.max(rel);
        radius_checked += 1;
        if rel.is_nan() || rel > RADIUS_REL_TOL || r.value < want_r * (1.0 - RADIUS_REL_TOL) {
            failures.push(format!("{name} ({kind}): 1/r_C {} vs sweep {want_r} (rel {rel:.2e})", r.value));
        }
        // σmin by a dense SVD is exact to about ε‖A‖, i.e. to ε‖A‖·(1/r_C) relative.
        let attained = 1.0 / sigma_min(&sys.a, r.peak_freq);
        let rounding = 10.0 * f64::EPSILON * sys.a.norm_l2() * r.value;
        if (attained - r.value).abs() > (1e-10 + rounding) * r.value {
            failures.push(format!("{name}: 1/σmin at ω = {} is {attained}, not {}", r.peak_freq, r.value));
        }
        eprintln!("  1/r_C {:.15e} at ω = {:.9} (rel {rel:.1e})", r.value, r.peak_freq);
    }
    eprintln!("{kinds:?}: worst relative error ‖G‖₂ {worst_h2:.2e}, 1/r_C {worst_radius:.2e} ({radius_checked} radii)");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

fn randn(rng: &mut ChaCha8Rng, r: usize, c: usize) -> Mat<f64> {
    Mat::from_fn(r, c, |_, _| rng.sample::<f64, _>(StandardNormal))
}

/// A random matrix of the given rank.
fn of_rank(rng: &mut ChaCha8Rng, r: usize, c: usize, rank: usize) -> Mat<f64> {
    randn(rng, r, rank) * randn(rng, rank, c)
}

/// A plant of which only the feedthroughs matter (n = 1).
fn feedthrough_plant(d11: Mat<f64>, d12: Mat<f64>, d21: Mat<f64>, d22: Mat<f64>) -> Plant {
    let (p1, m1, m2, p2) = (d11.nrows(), d11.ncols(), d12.ncols(), d21.nrows());
    let one = |r, c| Mat::from_fn(r, c, |_, _| 1.0);
    let a = Mat::from_fn(1, 1, |_, _| -1.0);
    common::plant_of("feedthrough", [a, one(1, m1), one(1, m2), one(p1, 1), one(p2, 1), d11, d12, d21, d22])
}

/// Every Dk = Dk0 + Σ zᵢEᵢ solves D11 + D12·Dk·D21 = 0 to rounding, the Eᵢ are orthonormal and
/// orthogonal to Dk0, there are m2·p2 − r1·r2 of them, and any solution is reached (its
/// components reproduce it): over shapes and ranks, zero and empty blocks included.
#[test]
fn the_feedthrough_parameterisation_is_the_solution_set() {
    let mut rng = ChaCha8Rng::seed_from_u64(20261209);
    let shapes = [
        // (p1, m1, m2, p2, rank D12, rank D21)
        (2, 2, 1, 1, 1, 1),
        (3, 2, 2, 2, 2, 2),
        (3, 2, 2, 2, 1, 2),
        (2, 4, 3, 3, 2, 1),
        (4, 3, 2, 3, 0, 2),
        (2, 2, 2, 2, 2, 0),
        (5, 5, 3, 4, 3, 4),
        (1, 1, 0, 2, 0, 1),
        (3, 1, 2, 0, 2, 0),
    ];
    for (p1, m1, m2, p2, r1, r2) in shapes {
        let (d12, d21) = (of_rank(&mut rng, p1, m2, r1), of_rank(&mut rng, p2, m1, r2));
        let x = randn(&mut rng, m2, p2);
        let d11 = &d12 * &x * &d21;
        let plant = feedthrough_plant(d11.clone(), d12.clone(), d21.clone(), Mat::zeros(p2, m2));
        let label = format!("p1={p1} m1={m1} m2={m2} p2={p2} ranks {r1}, {r2}");
        let aff = h2_feedthrough_parameterisation(&plant).unwrap_or_else(|e| panic!("{label}: {e}"));
        assert_eq!(aff.dim(), m2 * p2 - r1 * r2, "{label}");
        let residual_of = |dk: &Mat<f64>| {
            let scale = d11.norm_l2() + d12.norm_l2() * dk.norm_l2() * d21.norm_l2();
            (&d11 + &d12 * dk * &d21).norm_l2() / scale.max(f64::MIN_POSITIVE)
        };
        for _ in 0..5 {
            let z: Vec<f64> = (0..aff.dim()).map(|_| 3.0 * rng.sample::<f64, _>(StandardNormal)).collect();
            let dk = aff.dk(&z).unwrap();
            assert!(residual_of(&dk) <= 1e-14, "{label}: residual {:e}", residual_of(&dk));
            let back = aff.components((&dk - &aff.dk0).as_ref()).unwrap();
            assert!(back.iter().zip(&z).all(|(a, b)| (a - b).abs() <= 1e-13 * (1.0 + b.abs())), "{label}");
        }
        // Orthonormal, orthogonal to Dk0.
        for (i, e) in aff.basis.iter().enumerate() {
            let c = aff.components(e.as_ref()).unwrap();
            assert!(c.iter().enumerate().all(|(j, &x)| (x - (i == j) as u8 as f64).abs() <= 1e-14), "{label}");
        }
        assert!(aff.components(aff.dk0.as_ref()).unwrap().iter().all(|x| x.abs() <= 1e-13 * (1.0 + aff.dk0.norm_l2())));
        // −X solves the equation (D11 = D12·X·D21) and −X − Dk0 is a random element of the kernel:
        // it is reached, −X = Dk0 + Σ ⟨Eᵢ, −X − Dk0⟩ Eᵢ. With the dimension count and every
        // Dk0 + Eᵢ solving (above), the Eᵢ span the kernel.
        let target = -&x;
        let z = aff.components((&target - &aff.dk0).as_ref()).unwrap();
        let reached = aff.dk(&z).unwrap();
        assert!((&reached - &target).norm_l2() <= 1e-12 * (1.0 + target.norm_l2()), "{label}: −X not reached");
        // Wrong lengths and shapes are errors, not panics.
        assert!(matches!(aff.dk(&vec![0.0; aff.dim() + 1]), Err(LtiError::Shape { .. })));
        assert!(matches!(aff.components(Mat::<f64>::zeros(m2 + 1, p2).as_ref()), Err(LtiError::Shape { .. })));
    }
}

#[test]
fn the_feedthrough_parameterisation_reports_what_it_cannot_do() {
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let (d12, d21) = (of_rank(&mut rng, 3, 2, 1), of_rank(&mut rng, 2, 3, 2));
    let reachable = &d12 * randn(&mut rng, 2, 2) * &d21;
    let plant = |d11: &Mat<f64>, d22: Mat<f64>| feedthrough_plant(d11.clone(), d12.clone(), d21.clone(), d22);
    assert!(h2_feedthrough_parameterisation(&plant(&reachable, Mat::zeros(2, 2))).is_ok());
    let d22 = Mat::from_fn(2, 2, |i, j| (i == j) as u8 as f64 * 0.1);
    assert_eq!(h2_feedthrough_parameterisation(&plant(&reachable, d22)), Err(FeedthroughError::D22NotZero));
    // D11 with a part outside the range of D12 (rank 1 in ℝ³).
    let outside = &reachable + randn(&mut rng, 3, 3);
    match h2_feedthrough_parameterisation(&plant(&outside, Mat::zeros(2, 2))) {
        Err(FeedthroughError::NoSolution { residual }) => assert!(residual > 1e-3, "{residual}"),
        other => panic!("{other:?}"),
    }
    let mut nan = reachable.clone();
    nan[(0, 0)] = f64::NAN;
    assert_eq!(h2_feedthrough_parameterisation(&plant(&nan, Mat::zeros(2, 2))), Err(FeedthroughError::NonFinite));
}

/// +∞ where the H2 norm is infinite: D ≠ 0 in continuous time, A not Hurwitz (or not Schur), a
/// loop whose feedthrough is not zero (with a NaN gradient); 1/r_C of an unstable matrix; a
/// non-square A is an error.
#[test]
fn infinite_cases() {
    let a = Mat::from_fn(2, 2, |i, j| [[-1.0, 2.0], [0.0, -3.0]][i][j]);
    let sys = StateSpace { a: a.clone(), b: Mat::identity(2, 2), c: Mat::identity(2, 2), d: Mat::zeros(2, 2) };
    assert!(h2_norm(&sys).is_finite());
    let with_d = StateSpace { d: Mat::from_fn(2, 2, |i, j| ((i, j) == (1, 0)) as u8 as f64 * 1e-300), ..sys.clone() };
    assert_eq!(h2_norm(&with_d), f64::INFINITY);
    assert_eq!(h2_norm_grad(&with_d).0, f64::INFINITY);
    assert!(h2_norm_grad(&with_d).1.a[(0, 0)].is_nan());
    let unstable = StateSpace { a: -&a, ..sys.clone() };
    assert_eq!(h2_norm(&unstable), f64::INFINITY);
    assert_eq!(h2_norm_discrete(&StateSpace { a: &a * faer::Scale(0.5), ..sys.clone() }), f64::INFINITY);
    assert!(
        h2_norm_discrete(&StateSpace { a: &a * faer::Scale(0.3), d: Mat::identity(2, 2), ..sys.clone() }).is_finite()
    );
    let params = HinfParams::new(RADIUS_HINF_TOL);
    assert_eq!(inverse_stability_radius(unstable.a.as_ref(), &params).unwrap().value, f64::INFINITY);
    assert!(matches!(inverse_stability_radius(Mat::<f64>::zeros(2, 3).as_ref(), &params), Err(LtiError::Shape { .. })));
    // A normal matrix: 1/r_C = 1/min |Re λ| exactly (the nearest eigenvalue to the axis).
    let normal = Mat::from_fn(2, 2, |i, j| [[-0.5, 3.0], [-3.0, -0.5]][i][j]);
    let r = inverse_stability_radius(normal.as_ref(), &params).unwrap();
    assert!((r.value - 2.0).abs() <= 1e-12 * 2.0 && (r.peak_freq - 3.0).abs() <= 1e-6, "{r:?}");

    // A loop with D11 ≠ 0 that D12·Dk·D21 does not cancel.
    let plant = feedthrough_plant(
        Mat::from_fn(1, 1, |_, _| 1.0),
        Mat::from_fn(1, 1, |_, _| 1.0),
        Mat::from_fn(1, 1, |_, _| 1.0),
        Mat::zeros(1, 1),
    );
    let k = |dk: f64| Controller {
        ak: Mat::zeros(0, 0),
        bk: Mat::zeros(0, 1),
        ck: Mat::zeros(1, 0),
        dk: Mat::from_fn(1, 1, |_, _| dk),
        domain: Default::default(),
    };
    let (h2, g) = closed_loop_h2_grad(&plant, &k(-0.5)).unwrap();
    assert_eq!(h2, f64::INFINITY);
    assert!(g.dk[(0, 0)].is_nan());
    // Dk = −1 cancels it exactly; within the tolerance it still counts as cancelled.
    assert!(closed_loop_h2_grad(&plant, &k(-1.0)).unwrap().0.is_finite());
    assert!(closed_loop_h2_grad(&plant, &k(-1.0 + 0.1 * H2_FEEDTHROUGH_RTOL)).unwrap().0.is_finite());
    assert_eq!(closed_loop_h2_grad(&plant, &k(-1.0 + 100.0 * H2_FEEDTHROUGH_RTOL)).unwrap().0, f64::INFINITY);
}
