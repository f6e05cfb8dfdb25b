//! Regression cases of the H∞ norm found by users, each with a value checked independently of
//! the library (dense complex solves on a fine grid, refined; see each case).

use std::path::PathBuf;

use hinfix::lti::{
    closed_loop, closed_loop_hinf_grad, hinf_norm, hinf_norm_checked, matrix_from_json, Controller, HinfNorm,
    HinfParams, Plant, StateSpace, TimeDomain, DEFAULT_HINF_TOL,
};

mod common;
use common::{sigma_at, sigma_direct};

fn fixture(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/hinf-regression").join(name)
}

/// Plant "my3" with a second-order controller: σmax(D_cl) = 1.8446145 lies 4.2e-6
/// (relative) below the peak 1.8446223 at 7.3665 rad/s, and a lower local maximum 1.8446154 at
/// 0.833 rad/s. The norm used to stop at the local maximum: the level-set test at that level has
/// κ = γ²/(γ² − σmax(D)²) ≈ 1e6. The reference peak was located with numpy/scipy (dense solves on
/// a 20 001-point log grid over [1e-3, 1e4] rad/s, then Brent refinement to 1e-12 in log ω); the
/// test re-checks it with its own dense evaluation.
#[test]
fn my3_with_second_order_controller_reaches_the_true_peak() {
    const PEAK: f64 = 1.84462227006357;
    const PEAK_FREQ: f64 = 7.366547824461476;
    let (cl, h) = assert_closed_loop_reaches_peak("my3", PEAK, PEAK_FREQ, 1e-13, 1e-12);
    let sigma_d = sigma_direct(&cl, f64::INFINITY);
    assert!(PEAK / sigma_d - 1.0 < 5e-6, "the case must stay in the γ ≈ σmax(D) regime");
    assert!((h.peak_freq / PEAK_FREQ).ln().abs() < 1e-3, "peak at {} instead of {PEAK_FREQ}", h.peak_freq);
}

/// COMPleib NN5 (v1.1, not a shipped plant) with a first-order controller from a design run
/// (a check of designs on held-out COMPleib entries): σmax(T(iω)) rises from 238.9220 at ω = 0 to the peak 238.9575 at
/// ω = 0.0548. At the level (1 + tol)·σ(0) the crossing just above ω = 0 was lost (one crossing
/// found, at 0.0808), the interval [0, 0.0808] was never evaluated, and the norm came out
/// 238.9220, 1.5e-4 low. Reference: SLICOT AB13DD (python-control 0.10.2 / slycot 0.7.1,
/// tol 1e-12) on this closed loop, re-checked below by a dense evaluation.
#[test]
fn nn5_with_first_order_controller_finds_the_peak_near_zero() {
    assert_closed_loop_reaches_peak("nn5", 238.95750917874545, 0.05483152189579664, 1e-11, 1e-10);
}

/// COMPleib AC12 with a third-order controller of the COMPleib campaign (plain, results/compleib,
/// n_K = 3): ‖K‖∞ = 550 against ‖Tzw‖∞ ≈ 2.4e-4, so the closed loop is badly scaled (‖A‖ = 6.6e3,
/// ‖C‖ = 1.1e3, σmax(D) = 1.9e-4). σmax(T(iω)) has a local peak 2.2628025e-4 at 5.663 rad/s and
/// the peak 2.3958726e-4 at 18.4254 rad/s. The norm reported the local peak, 5.6 % low: the
/// level-set test at that level missed the crossings around 18.4 rad/s. Reference: SLICOT AB13DD
/// (python-control 0.10.2 / slycot, `linfnorm`) and a 50-digit mpmath evaluation at the peak
/// frequency agree to 1e-11; re-checked here by the dense evaluation.
#[test]
fn ac12_with_third_order_controller_finds_the_higher_peak() {
    // σmax of this loop is evaluated to about 1e-8 in its own (unbalanced) coordinates
    assert_closed_loop_reaches_peak("ac12", 2.3958726299370354e-4, 18.425426879431075, 1e-10, 1e-7);
}

/// COMPleib AC12 with a third-order plain controller of the COMPleib campaign (results/compleib,
/// n_K = 3) that makes ‖Tzw‖∞ tiny against the loop's data: 1.147e-7 with ‖C‖ = 1e3 and
/// ‖A‖ = 5.8e3 (σmax(D) = 2.6e-8). The Hamiltonian of the level-set test then has blocks of size
/// ‖C‖²/γ ≈ 1e13 and loses its eigenvalues near the crossings: the norm reported 9.42e-8, a
/// value attained at a mode frequency, 18 % low. What verification uses,
/// `lti::hinf_norm_checked`, evaluates σmax on a log grid of the loop's band and computes the
/// norm again from a grid point above it. Reference: 40-digit mpmath, a golden-section search on
/// σmax(T(iω)) of the closed loop built in that arithmetic: 1.14703221e-7 at 5.742409 rad/s
/// (SLICOT's AB13DD, python-control 0.10.2: 1.1428e-7, itself 0.4 % low); double-precision
/// σmax near there agrees to about 1e-6.
#[test]
fn ac12_with_a_tiny_norm_is_checked_on_a_grid() {
    let plant = Plant::load(fixture("ac12.json")).unwrap();
    let k = Controller::load(fixture("ac12_tiny_controller.json")).unwrap();
    let cl = closed_loop(&plant, &k).unwrap();
    let (peak, peak_freq) = (1.14703221e-7, 5.742409);
    assert!((sigma_direct(&cl, peak_freq) - peak).abs() <= 1e-7 * peak);
    let h = hinf_norm_checked(TimeDomain::Continuous, &cl);
    // σmax carries a rounding error of about 1e-6 (relative) here: the loop's 1e-7 is what is
    // left after much larger terms cancel
    assert!(h.value >= peak * (1.0 - 2e-6) && h.value <= peak * (1.0 + 2e-6), "{h:?}");
    assert!((sigma_direct(&cl, h.peak_freq) - h.value).abs() <= 2e-6 * h.value, "{h:?}");
    // a loop whose level-set test is right is not changed by the check, bit for bit
    let roc8 = closed_loop(
        &Plant::load(fixture("roc8.json")).unwrap(),
        &Controller::load(fixture("roc8_controller.json")).unwrap(),
    )
    .unwrap();
    let plain = hinf_norm(&roc8, &HinfParams::default()).unwrap();
    assert_eq!(hinf_norm_checked(TimeDomain::Continuous, &roc8), plain);
}

/// COMPleib AC12 with a first-order controller of the COMPleib campaign (plain, results/compleib,
/// n_K = 1): ‖Tzw‖∞ ≈ 1.0851e-7, at ω = 0, against ‖A_cl‖_F = 5.8e3 (balanced: 63). σmax from the
/// Hessenberg form of the unbalanced A came out 1.08474e-7, 3.4e-4 low, and the norm with it;
/// the check's grid, in balanced coordinates, reads it. Reference: the closed loop's G(0) solved
/// in 40-digit mpmath, σmax 1.0851159205e-7 (SLICOT's AB13DD, python-control 0.10.2:
/// 1.0851146e-7); σmax in balanced coordinates is within 1.3e-6 of it.
#[test]
fn ac12_with_its_peak_at_zero_is_read_in_balanced_coordinates() {
    let plant = Plant::load(fixture("ac12.json")).unwrap();
    let k = Controller::load(fixture("ac12_order1_controller.json")).unwrap();
    let cl = closed_loop(&plant, &k).unwrap();
    let peak = 1.0851159205e-7;
    let h = hinf_norm_checked(TimeDomain::Continuous, &cl);
    assert!((h.value - peak).abs() <= 5e-6 * peak, "{h:?}");
    // what the check mends: the norm in the loop's own coordinates is low (balancing lowers
    // ‖A‖_F 92-fold here, below the factor from which the norm itself balances, `hinf::Working`;
    // if this fails, the norm itself has been mended, and the line can go)
    let unchecked = hinf_norm(&cl, &HinfParams::default()).unwrap();
    assert!(unchecked.value < peak * (1.0 - 1e-4), "{unchecked:?}");
}

/// COMPleib ROC8 with a second-order controller of the COMPleib campaign (plain, results/compleib,
/// n_K = 2): a well-scaled loop (‖A‖ = 6.4, cond(A) = 84) with a nearly unobservable mode at
/// −1.0e-7 ± 0.44504j. σmax(T(iω)) has a broad peak 3.4926731167 at 1.787 rad/s and a spike of
/// width 2e-7 rad/s to 3.4927086472 at 0.445041352 rad/s, 1.0e-5 higher. The norm reported the
/// broad peak: the level-set test returned the spike's crossings as one frequency. Reference:
/// SLICOT AB13DD (python-control 0.10.2 / slycot, `linfnorm`) found the
/// spike (3.4927085094, off its top); its top by a golden-section search in 40-digit mpmath.
/// σmax is evaluated to about 1e-9 there in double precision (the mode's damping), hence the
/// tolerances.
#[test]
fn roc8_with_second_order_controller_finds_the_spike() {
    assert_closed_loop_reaches_peak("roc8", 3.49270864715556, 0.44504135238410937, 1e-9, 1e-9);
}

/// COMPleib AC1 with a second-order controller of the COMPleib campaign (strong, results/compleib,
/// n_K = 2): a mode at −2.36e-5 ± 0.0639j makes a spike of σmax(T(iω)) to 2.2329882e-3 at
/// 0.0638613 rad/s. The norm reported 2.2328500e-3, 6.2e-5 low. Reference: SLICOT AB13DD
/// (python-control 0.10.2 / slycot) near the top, located by a golden-section search in 40-digit
/// mpmath (on this closed loop and on python-control's LFT of it, to 1e-14).
#[test]
fn ac1_with_second_order_controller_reaches_the_spike_top() {
    assert_closed_loop_reaches_peak("ac1", 2.23298824602258e-3, 0.0638612647248825, 1e-7, 1e-7);
    // the same controller padded to order 3 with a decoupled stable mode (the campaign's chained
    // start of n_K = 3): the same transfer function, one state more
    assert_closed_loop_reaches_peak_with("ac1", "ac1_order3", 2.23298824602258e-3, 0.0638612647248825, 1e-7, 1e-7);
}

/// A nearly flat optimal loop: the cross-term plant (tests/fixtures/full_order/cross_terms.py)
/// with an order-3 controller designed on it. σmax(T(iω)) stays within 2.3e-7 (relative) of
/// σmax(D_cl) = 0.5853817014 from ω = 0 to ∞, and rises above it only in one bump,
/// [1.0016, 1.0306] rad/s, to the peak 0.58538183730 at 1.00851 rad/s. The norm used to report
/// σmax(D_cl) at ω = ∞, 2.3e-7 low against the tolerance 1e-10: γ_L stayed at ω = ∞, and the
/// computed crossings of the ill-conditioned level just above σmax(D) (κ ≈ 5e9) missed the bump.
/// Reference: 40-digit mpmath (tests/fixtures/hinf-regression/flat_loop.py), re-checked here
/// by the dense evaluation.
#[test]
fn flat_loop_of_the_cross_term_plant_reaches_the_interior_peak() {
    let r: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(fixture("two_mass_cross_flat_reference.json")).unwrap()).unwrap();
    let (peak, peak_freq) = (r["peak"].as_f64().unwrap(), r["peak_freq"].as_f64().unwrap());
    let (cl, h) = assert_closed_loop_reaches_peak("two_mass_cross_flat", peak, peak_freq, 1e-13, 1e-12);
    let sigma_d = sigma_direct(&cl, f64::INFINITY);
    assert!((sigma_d / r["sigma_max_d"].as_f64().unwrap() - 1.0).abs() < 1e-13);
    assert!(peak / sigma_d - 1.0 < 3e-7, "the case must stay in the flat regime");
    assert!((h.peak_freq / peak_freq).ln().abs() < 1e-3, "peak at {} instead of {peak_freq}", h.peak_freq);
}

/// The closed loop of the fixtures `{name}.json` (plant) and `{name}_controller.json`: the
/// reference `peak` is attained at `peak_freq` (to `ref_tol`, relative), and ‖T‖∞ reaches it
/// (to twice the norm's tolerance), does not exceed it (by more than `tol`), is attained at the
/// returned frequency (to `tol`), and the design objective's path (norm + gradient) gives the same
/// value. Returns the closed loop and its norm for case-specific checks.
fn assert_closed_loop_reaches_peak(
    name: &str,
    peak: f64,
    peak_freq: f64,
    ref_tol: f64,
    tol: f64,
) -> (StateSpace, HinfNorm) {
    assert_closed_loop_reaches_peak_with(name, name, peak, peak_freq, ref_tol, tol)
}

/// [`assert_closed_loop_reaches_peak`] with the controller of fixture `controller`.
fn assert_closed_loop_reaches_peak_with(
    name: &str,
    controller: &str,
    peak: f64,
    peak_freq: f64,
    ref_tol: f64,
    tol: f64,
) -> (StateSpace, HinfNorm) {
    let plant = Plant::load(fixture(&format!("{name}.json"))).unwrap();
    let k = Controller::load(fixture(&format!("{controller}_controller.json"))).unwrap();
    let cl = closed_loop(&plant, &k).unwrap();
    // The reference is an attained value.
    let at_ref = sigma_direct(&cl, peak_freq);
    assert!((at_ref - peak).abs() <= ref_tol * peak, "{name}: reference not attained ({at_ref} at {peak_freq})");
    let h = hinf_norm(&cl, &HinfParams::default()).unwrap();
    assert!(
        h.value >= peak * (1.0 - tol.max(2.0 * DEFAULT_HINF_TOL)),
        "{name}: ‖Tzw‖∞ = {} at ω = {}, below the peak {peak}",
        h.value,
        h.peak_freq
    );
    assert!(h.value <= peak * (1.0 + tol), "{name}: {} exceeds the peak", h.value);
    assert!(
        (sigma_direct(&cl, h.peak_freq) - h.value).abs() <= tol * h.value,
        "{name}: not attained at the returned frequency"
    );
    let (h2, _) = closed_loop_hinf_grad(&plant, &k, &HinfParams::default()).unwrap();
    assert!((h2.value - h.value).abs() <= 1e-12 * h.value, "{name}: the objective's path differs");
    (cl, h)
}

/// Closed loops of COMPleib AC4 with second-order controllers, met in one design run (ε = 1e-3,
/// seed 1, max_starts 44, a check on held-out COMPleib entries), where the norm warm-started at the previous
/// peak (the design objective's path) came out low by 9e-6 to 6.6e-4 (`old_warm_value` in the
/// fixture): started on a hinted local peak, the level-set test missed the slightly higher true
/// peak. Reference: SLICOT AB13DD on each closed loop (tol 1e-12), re-checked by dense evaluation.
#[test]
fn ac4_warm_started_norms_reach_the_true_peak() {
    assert_cases_reach_reference("ac4_warm_cases.json", 5, 5e-6);
}

/// Systems of order 30 to 59 (the squared level-set path) from the large-order property
/// family, on which the cold or the hinted norm came out low by 2.7e-4 to 2.8e-2: the squared
/// spectrum lost the crossings of narrow low-frequency peaks (seeds 323, 243, 850, 15) or placed
/// them at the wrong frequency (1588), and the pencil's crossing mapped to ω = ∞ hid a peak at
/// 9e3 rad/s (204). Reference: σmax at the peak of the family's independent modal sweep (dense
/// numpy solve; AB13DD is itself low on four of them, see the fixture).
#[test]
fn large_order_norms_reach_the_true_peak() {
    assert_cases_reach_reference("large_order_cases.json", 6, 5e-6);
}

/// A system of order 45 from the large-order property family (seed 2313) on which the norm hinted
/// at the runner-up peak came out 1.1e-6 low: at the level (1 + tol)·γ_L of that peak the true
/// peak's two crossings were a near-tangent pair that rounding split off the imaginary axis by
/// three times the axis threshold, so the squared spectrum reported none. Eigenvalues
/// that close to the axis are now probed. Reference: the family's modal sweep truth.
#[test]
fn near_tangent_crossings_split_off_the_axis_are_probed() {
    assert_cases_reach_reference("near_tangent_cases.json", 1, 5e-7);
}

/// Every case of the fixture `file` (keys A, B, C, D, reference, reference_freq, hints,
/// old_warm_value, optional eval_tol): the reference is attained, the old value was low (by more
/// than `old_gap` relative, or 10·eval_tol), and both the cold and the hinted norm reach the
/// reference without exceeding it.
fn assert_cases_reach_reference(file: &str, count: usize, old_gap: f64) {
    let text = std::fs::read_to_string(fixture(file)).unwrap();
    let doc: serde_json::Value = serde_json::from_str(&text).unwrap();
    let cases = doc["cases"].as_array().unwrap();
    assert_eq!(cases.len(), count);
    for (i, c) in cases.iter().enumerate() {
        let rows = |key: &str| c[key].as_array().unwrap().len();
        let cols = |key: &str| c[key][0].as_array().unwrap().len();
        let m = |key: &str| matrix_from_json(Some(&c[key]), rows(key), cols(key)).unwrap();
        let cl = StateSpace::new(m("A"), m("B"), m("C"), m("D")).unwrap();
        let peak = c["reference"].as_f64().unwrap();
        let old = c["old_warm_value"].as_f64().unwrap();
        let hints: Vec<f64> = c["hints"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect();
        // Two dense evaluations of a very sharp peak may differ by more than 1e-10 (`eval_tol`).
        let tol = c["eval_tol"].as_f64().unwrap_or(1e-10);
        let attained = sigma_direct(&cl, c["reference_freq"].as_f64().unwrap());
        assert!((attained - peak).abs() <= tol * peak, "case {i}: σ at the reference frequency {attained} vs {peak}");
        assert!(old < peak * (1.0 - (10.0 * tol).max(old_gap)), "case {i} must be one the old norm got wrong");
        for h in [
            hinf_norm(&cl, &HinfParams::default().with_hints(&hints)).unwrap(),
            hinf_norm(&cl, &HinfParams::default()).unwrap(),
        ] {
            assert!(
                h.value >= peak * (1.0 - tol.max(1e-9)),
                "case {i}: ‖T‖∞ = {} at ω = {}, below the reference {peak}",
                h.value,
                h.peak_freq
            );
            assert!(h.value <= peak * (1.0 + tol.max(1e-9)), "case {i}: {} above the reference {peak}", h.value);
        }
    }
}

/// COMPleib HE1 sampled at Ts = 1e-7 s (exact zero-order hold, he1_ts1e-7.json) with a
/// first-order controller of a 3-s design: after the bilinear transform the loop's modes range
/// from 6e-9 to 1.1, and the level-set norm of the image read 0.152088 (SLICOT's AB13DD,
/// python-control 0.10.2 `linfnorm`: 0.15208 too), while σmax on the unit circle reaches
/// 0.1547954 at 0.8362 rad/s (a dense sweep in numpy, refined; re-checked here). The grid check
/// finds it, and the design reports γ by the checked norm, as `check` and the reports do (its
/// summary said ‖Tzw‖∞ = 0.152088).
#[test]
fn a_discrete_loop_sampled_fast_is_checked_on_a_grid() {
    use hinfix::design::{Design, DesignOptions};
    let plant = Plant::load(fixture("he1_ts1e-7.json")).unwrap();
    let k = Controller::load(fixture("he1_ts1e-7_controller.json")).unwrap().in_domain(plant.domain);
    let cl = closed_loop(&plant, &k).unwrap();
    let TimeDomain::Discrete { ts } = plant.domain else { panic!("a discrete plant") };
    let (peak, peak_freq) = (0.1547954, 0.8361664);
    let sigma = |w: f64| sigma_at(&cl, faer::c64::new((w * ts).cos(), (w * ts).sin()));
    assert!((sigma(peak_freq) - peak).abs() <= 1e-6 * peak, "{}", sigma(peak_freq));
    let h = hinf_norm_checked(plant.domain, &cl);
    assert!(h.value >= peak * (1.0 - 1e-6), "{h:?}");
    let opts = DesignOptions { order: 1, maxevals: Some(1), ..Default::default() };
    let o = Design::for_plant(&plant, &opts).init(Some(&k)).run().unwrap();
    let again = hinf_norm_checked(plant.domain, &closed_loop(&plant, &o.controller).unwrap());
    assert!(o.gamma >= peak * (1.0 - 1e-3), "the design's γ {} against σmax {peak}", o.gamma);
    assert!((o.gamma - again.value).abs() <= 1e-9 * again.value, "{} against {again:?}", o.gamma);
}
