//! The LTI numerics against SLICOT reference values (tests/fixtures/oracle, copied from the
//! project's shared oracle; see its README): every H∞-norm case and every closed-loop case must
//! match to 1e-8 relative, with identical stability decisions.

use std::path::{Path, PathBuf};

use faer::Mat;
use hinfix::lti::{
    closed_loop, closed_loop_abscissa_grad, closed_loop_hinf_grad, controller_abscissa_grad, controller_hinf_grad,
    hinf_norm, spectral_abscissa, Controller, HinfParams, Plant, StateSpace, DEFAULT_HINF_TOL,
};
use serde_json::Value;

mod common;
use common::sigma_direct;

/// Relative agreement required on values.
const REL_TOL: f64 = 1e-8;

/// Oracle entries found wrong: the controller's ‖K‖∞ there is exactly σmax(DK), i.e. AB13DD
/// (through slycot) stopped at its initial lower bound although the frequency response rises above
/// it. Verified independently with numpy on a 200 001-point log grid over [1e-4, 1e4] rad/s
/// (dense complex solves, no Hessenberg form): the grid maxima below are attained values, so the
/// true norms are at least these. We require agreement with the grid value (1e-8) instead, and
/// the test below also re-evaluates σmax(G(iω)) at our peak by a dense solve.
const ORACLE_ERRATA_CONTROLLER_HINF: &[(&str, f64, f64)] = &[
    // (case, grid maximum, its frequency)
    ("HE1_nk2_1", 0.4645871804386493, 5.680152555590496),
    ("REA2_nk2_0", 0.12180401397282756, 1.310629684248824),
    ("REA2_nk3_0", 0.05350497202407391, 16.534840121711554),
];

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn fixtures(dir: &str) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(root().join("tests/fixtures").join(dir))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "json"))
        .collect();
    v.sort();
    assert!(!v.is_empty());
    v
}

fn load(p: &Path) -> Value {
    serde_json::from_str(&std::fs::read_to_string(p).unwrap()).unwrap()
}

/// A matrix from an array of rows with an explicit shape.
fn mat(v: &Value, rows: usize, cols: usize) -> Mat<f64> {
    let a = v.as_array().map(|a| a.as_slice()).unwrap_or(&[]);
    Mat::from_fn(rows, cols, |i, j| a[i].as_array().unwrap()[j].as_f64().unwrap())
}

fn shape(v: &Value) -> (usize, usize) {
    let a = v.as_array().unwrap();
    (a.len(), a.first().and_then(|r| r.as_array()).map_or(0, |r| r.len()))
}

/// A number, "inf", or null (→ None).
fn num(v: &Value) -> Option<f64> {
    match v {
        Value::Null => None,
        Value::String(s) if s == "inf" => Some(f64::INFINITY),
        Value::String(s) if s == "-inf" => Some(f64::NEG_INFINITY),
        v => Some(v.as_f64().unwrap()),
    }
}

fn close(x: f64, want: f64, floor: f64) -> bool {
    if want.is_infinite() {
        return x == want;
    }
    (x - want).abs() <= REL_TOL * want.abs() + floor
}

fn system(doc: &Value) -> StateSpace {
    let (n, _) = shape(&doc["A"]);
    let (p, m) = shape(&doc["D"]);
    StateSpace::new(mat(&doc["A"], n, n), mat(&doc["B"], n, m), mat(&doc["C"], p, n), mat(&doc["D"], p, m)).unwrap()
}

#[test]
fn hinfnorm_cases_match_slicot() {
    check_hinfnorm_cases("oracle/hinfnorm", 1e-9);
}

/// Further AB13DD references (scripts/gen_hinf_stress.py): many lightly damped modes over
/// decades, a slow peak beside fast modes, bad scaling, peaks near ω = ∞ — the cases where the
/// square-reduced Hamiltonian eigenvalues are least accurate. Some are badly scaled enough that
/// the library's Hessenberg evaluation of G(iω) and the test's dense one differ by more than on
/// the shared oracle (1.3e-9 relative seen on scaled_random_5): `attained_tol` is REL_TOL here.
#[test]
fn hinf_stress_cases_match_slicot() {
    check_hinfnorm_cases("hinf-stress", REL_TOL);
}

/// Every case in `tests/fixtures/{dir}` matches to REL_TOL, with the same stability decision, and
/// the returned frequency attains the value to `attained_tol` (dense re-evaluation).
fn check_hinfnorm_cases(dir: &str, attained_tol: f64) {
    let mut failures = Vec::new();
    for path in fixtures(dir) {
        let doc = load(&path);
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        let sys = system(&doc);
        let kind = doc["kind"].as_str().unwrap();
        let want = num(&doc["hinf"]).unwrap();
        let want_alpha = num(&doc["spectral_abscissa"]).unwrap();
        let alpha = spectral_abscissa(sys.a.as_ref());
        // absolute floor for α = 0 exactly (marginal case): rounding of the eigenvalues
        let alpha_floor = 1e-13 * (1.0 + sys.a.norm_l2());
        if !close(alpha, want_alpha, alpha_floor) {
            failures.push(format!("{name}: alpha {alpha} vs {want_alpha}"));
        }
        let t0 = std::time::Instant::now();
        let got = hinf_norm(&sys, &HinfParams::default()).unwrap();
        let dt = t0.elapsed();
        if want.is_infinite() != got.value.is_infinite() {
            failures.push(format!("{name}: stability decision differs: {} vs {want}", got.value));
            continue;
        }
        if !close(got.value, want, 0.0) {
            failures.push(format!(
                "{name} ({kind}): hinf {} vs {want} (rel {:.2e})",
                got.value,
                (got.value - want).abs() / want
            ));
        }
        if kind == "lightly-damped" {
            let wf = num(&doc["peak_freq"]).unwrap();
            if !close(got.peak_freq, wf, 0.0) {
                failures.push(format!("{name}: peak {} vs {wf}", got.peak_freq));
            }
        }
        // the returned frequency attains the value
        if got.value.is_finite() {
            let s = sigma_direct(&sys, got.peak_freq);
            assert!((s - got.value).abs() <= attained_tol * got.value, "{name}: σ at peak {s} vs {}", got.value);
        }
        if got.value.is_finite() && got.peak_freq.is_finite() {
            eprintln!("{name:28} {kind:15} hinf {:.12e} at {:.6e} ({dt:?})", got.value, got.peak_freq);
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn closed_loop_cases_match_slicot() {
    let mut failures = Vec::new();
    for path in fixtures("oracle/closed-loop") {
        let doc = load(&path);
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        let plant_file = doc["plant"].as_str().unwrap();
        let plant = Plant::load(root().join("plants").join(plant_file)).unwrap();
        let k = Controller::from_json_value(&doc["controller"]).unwrap();
        assert_eq!(k.order() as u64, doc["controller_order"].as_u64().unwrap());
        let exp = &doc["expected"];

        let cl = closed_loop(&plant, &k).unwrap();
        let a_cl = spectral_abscissa(cl.a.as_ref());
        let want = num(&exp["closed_loop_spectral_abscissa"]).unwrap();
        if !close(a_cl, want, 0.0) {
            failures.push(format!("{name}: alpha_cl {a_cl} vs {want} (rel {:.2e})", (a_cl - want).abs() / want.abs()));
        }
        let (a_cl2, _) = closed_loop_abscissa_grad(&plant, &k).unwrap();
        assert!((a_cl2 - a_cl).abs() <= 1e-12 * (1.0 + a_cl.abs()), "{name}");

        let (a_k, _) = controller_abscissa_grad(&k);
        match num(&exp["controller_spectral_abscissa"]) {
            None => assert_eq!(a_k, f64::NEG_INFINITY, "{name}"),
            Some(w) => {
                if !close(a_k, w, 0.0) {
                    failures.push(format!("{name}: alpha_k {a_k} vs {w}"));
                }
            }
        }

        let h = hinf_norm(&cl, &HinfParams::default()).unwrap();
        let want = num(&exp["closed_loop_hinf"]).unwrap();
        if want.is_infinite() != h.value.is_infinite() || want.is_finite() != (a_cl < 0.0) {
            failures.push(format!("{name}: stability decision {} vs {want}", h.value));
        } else if !close(h.value, want, 0.0) {
            failures.push(format!("{name}: hinf {} vs {want} (rel {:.2e})", h.value, (h.value - want).abs() / want));
        }
        let (h2, g) = closed_loop_hinf_grad(&plant, &k, &HinfParams::default()).unwrap();
        assert_eq!(h2.value.is_finite(), h.value.is_finite(), "{name}");
        if h.value.is_finite() {
            assert!((h2.value - h.value).abs() <= 1e-12 * h.value, "{name}");
            assert!(g.dk.norm_l2().is_finite(), "{name}");
            eprintln!(
                "{name:22} hinf {:.12e} at ω = {:.6e} (oracle ω = {:?})",
                h.value,
                h.peak_freq,
                num(&exp["closed_loop_peak_freq"])
            );
        } else {
            assert!(g.dk[(0, 0)].is_nan(), "{name}: unstable loop must give a NaN gradient");
        }

        if h.value.is_finite() {
            let s = sigma_direct(&cl, h.peak_freq);
            assert!((s - h.value).abs() <= 1e-9 * h.value, "{name}: σ at peak {s} vs {}", h.value);
        }

        let (hk, _) = controller_hinf_grad(&k, DEFAULT_HINF_TOL);
        let mut want = num(&exp["controller_hinf"]).unwrap();
        if let Some(&(_, grid, w)) = ORACLE_ERRATA_CONTROLLER_HINF.iter().find(|e| e.0 == name) {
            assert!(hk.value >= want * (1.0 + 1e-7), "{name}: erratum no longer needed?");
            eprintln!("{name}: oracle ‖K‖∞ {want} is σmax(DK); using the grid value {grid} at ω = {w}");
            want = grid;
        }
        if k.order() > 0 && hk.value.is_finite() {
            let ks = StateSpace { a: k.ak.clone(), b: k.bk.clone(), c: k.ck.clone(), d: k.dk.clone() };
            let s = sigma_direct(&ks, hk.peak_freq);
            assert!((s - hk.value).abs() <= 1e-9 * hk.value, "{name}: σ at peak {s} vs {}", hk.value);
        }
        if !close(hk.value, want, 0.0) {
            failures.push(format!("{name}: controller hinf {} vs {want}", hk.value));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
