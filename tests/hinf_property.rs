//! Property test of the H∞ norm near its hardest regime: G = D + δ·G₀ with σmax(D) = 1 and
//! δ from 1e-7 to 1e-1, so that the peak sits barely above σmax(D) (or is approached as ω → ∞)
//! and the level-set matrices are ill-conditioned (κ = γ²/(γ² − σmax(D)²) up to ~1e14).
//!
//! The truth is independent of the library's Hessenberg evaluation and of any Hamiltonian: G₀ is
//! built in modal form, A = Q·blockdiag(2×2 modes, real pole)·Qᵀ with Q orthogonal, and
//! G(iω) = (δ·C₀Q)(iωI − Λ)⁻¹(QᵀB₀) + D is evaluated block by block; σmax is taken over a dense
//! logarithmic sweep (plus points packed around every mode at its damping's scale, ω = 0 and
//! ω = ∞), and the best local maxima of the sweep are refined by golden-section search.
//!
//! Asserted for every system, for `hinf_norm` and for `hinf_norm` with `HinfParams::hints` warm-started at a
//! frequency unrelated to the peak: the norm is never below the truth by more than [`REL_TOL`], and
//! the returned frequency attains the returned value (no over-estimate).
//!
//! `cargo test --test hinf_property` runs a fast subset; the full family (4000 systems) is
//! `cargo test --release --test hinf_property -- --ignored --nocapture`, which prints the counts
//! and the worst relative error.
//!
//! A second, large-order family ([`member_large`]) covers n = 30…60, where the level-set
//! test takes Van Loan's squared spectrum, with hard shapes (modes spread over seven decades, two
//! nearly equal peaks, a dominant peak near ω = 0 or at high ω); its warm-started norm is hinted
//! at the best lower local peak. Fast subset in `cargo test`; full family (1500 systems) ignored.
//! `HINF_LARGE_SEEDS=a..b` picks seeds, `HINF_NMAX=80` raises the largest order.

use faer::{c64, Mat};
use hinfix::lti::{hinf_norm, HinfParams, StateSpace, DEFAULT_HINF_TOL};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

mod common;
use common::add_modal_pair;

/// Allowed relative shortfall of `hinf_norm` below the truth: the norm's tolerance plus the
/// rounding difference between two evaluations of σmax(G(iω)) by different methods, plus
/// [`EVAL_ERROR_FACTOR`]·ρ (see [`eval_error`]).
const REL_TOL: f64 = DEFAULT_HINF_TOL + 1e-12;
/// Multiple of ρ = ε‖A‖_F / dist(iω, λ(A)) allowed on top of [`REL_TOL`]: any evaluation of
/// G(iω) from the stored A (Hessenberg, LU, the Hamiltonian) has a backward error of order ε‖A‖,
/// which moves a resonance at distance dist from the axis by that relative amount. Forming
/// A = Q Λ Qᵀ in floating point is itself such a perturbation, so the modal truth and the
/// library legitimately differ by O(ρ) (seen: 7e-10 for a mode with ζω ≈ 1e-6 and ‖A‖ ≈ 100).
const EVAL_ERROR_FACTOR: f64 = 100.0;

/// One member of the family, with its modal data for the independent evaluation.
struct Member {
    sys: StateSpace,
    /// Modes: (σ, ω) of a 2×2 block [σ ω; −ω σ], or (σ, NaN) for a real pole σ.
    modes: Vec<(f64, f64)>,
    /// δ·C₀·Q (p×n) and Qᵀ·B₀ (n×m): the output and input maps in modal coordinates.
    c_modal: Mat<f64>,
    b_modal: Mat<f64>,
    delta: f64,
    lightly_damped: bool,
    square: bool,
}

fn randn(rng: &mut ChaCha8Rng, r: usize, c: usize) -> Mat<f64> {
    Mat::from_fn(r, c, |_, _| StandardNormal.sample(&mut *rng))
}

fn log_uniform(rng: &mut ChaCha8Rng, lo: f64, hi: f64) -> f64 {
    (lo.ln() + (hi.ln() - lo.ln()) * rng.random::<f64>()).exp()
}

/// Input and output counts: m = p, or m ≠ p.
fn dims(rng: &mut ChaCha8Rng) -> (bool, usize, usize) {
    let square = rng.random_bool(0.5);
    let m = rng.random_range(1..=3usize);
    let p = if square {
        m
    } else {
        let mut p = rng.random_range(1..=4usize);
        if p == m {
            p += 1;
        }
        p
    };
    (square, m, p)
}

/// A random p×m D with σmax(D) = 1; one in four (with min(p, m) ≥ 2) has a repeated largest
/// singular value.
fn unit_d(rng: &mut ChaCha8Rng, p: usize, m: usize) -> Mat<f64> {
    let d0 = randn(rng, p, m);
    let svd = d0.svd().unwrap();
    let k = p.min(m);
    let repeated = k >= 2 && rng.random_bool(0.25);
    let s: Vec<f64> =
        (0..k).map(|i| if i == 0 || (repeated && i == 1) { 1.0 } else { svd.S()[i] / svd.S()[0] }).collect();
    Mat::from_fn(p, m, |i, j| (0..k).map(|l| svd.U()[(i, l)] * s[l] * svd.V()[(j, l)]).sum::<f64>())
}

/// The mode of natural frequency `w` and damping `zeta` ((σ, ω) of `Member::modes`); a real pole
/// −w if `zeta` is NaN.
fn mode(w: f64, zeta: f64) -> (f64, f64) {
    if zeta.is_nan() {
        (-w, f64::NAN)
    } else {
        (-zeta * w, w * (1.0 - zeta * zeta).sqrt())
    }
}

/// blockdiag of the modes: [σ ω; −ω σ] per complex mode, σ per real pole.
fn modal_blocks(modes: &[(f64, f64)], n: usize) -> Mat<f64> {
    let mut blocks = Mat::<f64>::zeros(n, n);
    let mut i = 0;
    for &(re, im) in modes {
        blocks[(i, i)] = re;
        if im.is_nan() {
            i += 1;
        } else {
            blocks[(i + 1, i + 1)] = re;
            blocks[(i, i + 1)] = im;
            blocks[(i + 1, i)] = -im;
            i += 2;
        }
    }
    blocks
}

/// Member `seed` of the family (n from 2 to 30).
fn member(seed: u64) -> Member {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let n = rng.random_range(2..=30usize);
    let (square, m, p) = dims(&mut rng);
    let d = unit_d(&mut rng, p, m);
    let lightly_damped = rng.random_bool(0.5);
    let mut modes = Vec::new();
    let mut i = 0;
    while i < n {
        let w = log_uniform(&mut rng, 1e-2, 1e2);
        if i + 1 == n {
            modes.push(mode(w, f64::NAN));
            i += 1;
            continue;
        }
        let zeta = if lightly_damped { log_uniform(&mut rng, 1e-4, 1e-2) } else { rng.random_range(0.2..0.95) };
        modes.push(mode(w, zeta));
        i += 2;
    }
    let blocks = modal_blocks(&modes, n);
    let q = randn(&mut rng, n, n).qr().compute_Q();
    let a = &q * &blocks * q.transpose();
    let b0 = randn(&mut rng, n, m);
    let c0 = randn(&mut rng, p, n);
    let delta = log_uniform(&mut rng, 1e-7, 1e-1);
    let c = &c0 * faer::Scale(delta);
    let c_modal = &c * &q;
    let b_modal = q.transpose() * &b0;
    Member { sys: StateSpace::new(a, b0, c, d).unwrap(), modes, c_modal, b_modal, delta, lightly_damped, square }
}

/// The shapes of the large-order family ([`member_large`]).
const LARGE_SHAPES: [&str; 5] = ["random", "spread", "twin peaks", "peak near 0", "peak at high ω"];

/// Member `seed` of the large-order family: n from 30 to `n_max`, where the level-set test takes
/// the squared (explicit Hamiltonian) path whenever κ ≤ 1e3. G = D + δ·G₀ with σmax(D) = 1 and δ
/// from 1e-3 to 3, or D = 0 (κ = 1). Shapes ([`LARGE_SHAPES`]): random modes in [1e-2, 1e2];
/// modes spread over [1e-3, 1e4] (very different magnitudes: ‖H‖ large against the low
/// crossings); two lightly damped modes with equal resonance heights (two nearly equal peaks);
/// a dominant low mode or pole in [1e-4, 1e-2] (peak near ω = 0); a dominant mode in [1e3, 1e4].
/// Each mode's input map is scaled to give it a resonance height (≈ ‖cₖ‖‖bₖ‖/(2ζω)) drawn
/// below the dominant ones'.
fn member_large(seed: u64, n_max: usize) -> (Member, &'static str) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x13_0000_0000);
    let n = rng.random_range(30..=n_max);
    let (square, m, p) = dims(&mut rng);
    let zero_d = rng.random_bool(0.25);
    let d = if zero_d { Mat::zeros(p, m) } else { unit_d(&mut rng, p, m) };
    let shape = rng.random_range(0..LARGE_SHAPES.len());
    let lightly_damped = shape == 2 || rng.random_bool(0.5);
    let damping = |rng: &mut ChaCha8Rng| {
        if lightly_damped {
            log_uniform(rng, 1e-4, 1e-2)
        } else {
            rng.random_range(0.05..0.9)
        }
    };
    let (lo, hi) = if shape == 1 { (1e-3, 1e4) } else { (1e-2, 1e2) };
    let mut modes = Vec::new();
    let mut heights = Vec::new();
    let mut i = 0;
    while i < n {
        let w = log_uniform(&mut rng, lo, hi);
        let zeta = if i + 1 == n { f64::NAN } else { damping(&mut rng) };
        modes.push(mode(w, zeta));
        heights.push(log_uniform(&mut rng, 1e-2, 0.5));
        i += if zeta.is_nan() { 1 } else { 2 };
    }
    // The dominant modes.
    let k = modes.len();
    match shape {
        2 if k >= 3 => {
            let (a, b) = (0, k / 2);
            heights[a] = 1.0;
            heights[b] = 1.0 + log_uniform(&mut rng, 1e-6, 1e-2);
        }
        3 => {
            let w = log_uniform(&mut rng, 1e-4, 1e-2);
            modes[0] = mode(w, if rng.random_bool(0.5) { f64::NAN } else { damping(&mut rng) });
            heights[0] = 1.0;
        }
        4 => {
            modes[0] = mode(log_uniform(&mut rng, 1e3, 1e4), damping(&mut rng));
            heights[0] = 1.0;
        }
        _ => {}
    }
    // A dominant real pole replacing a complex mode: one state to fill, to keep the order n.
    let dim: usize = modes.iter().map(|m| if m.1.is_nan() { 1 } else { 2 }).sum();
    if dim < n {
        modes.push(mode(log_uniform(&mut rng, lo, hi), f64::NAN));
        heights.push(log_uniform(&mut rng, 1e-2, 0.5));
    }
    let blocks = modal_blocks(&modes, n);
    let q = randn(&mut rng, n, n).qr().compute_Q();
    let a = &q * &blocks * q.transpose();
    let c_unit = randn(&mut rng, p, n);
    let mut b_modal = randn(&mut rng, n, m);
    let mut i = 0;
    for (&(re, im), &h) in modes.iter().zip(&heights) {
        let rows = if im.is_nan() { 1 } else { 2 };
        let norm = |mat: faer::MatRef<'_, f64>| mat.norm_l2();
        let gain = norm(c_unit.as_ref().submatrix(0, i, p, rows)) * norm(b_modal.as_ref().submatrix(i, 0, rows, m));
        let scale = h * rows as f64 * re.abs() / gain;
        for r in i..i + rows {
            for j in 0..m {
                b_modal[(r, j)] *= scale;
            }
        }
        i += rows;
    }
    let delta = if zero_d { 1.0 } else { log_uniform(&mut rng, 1e-3, 3.0) };
    let c_modal = &c_unit * faer::Scale(delta);
    let b = &q * &b_modal;
    let c = &c_modal * q.transpose();
    let mb =
        Member { sys: StateSpace::new(a, b, c, d).unwrap(), modes, c_modal, b_modal, delta, lightly_damped, square };
    (mb, LARGE_SHAPES[shape])
}

/// σmax(G(iω)) in modal coordinates (ω = ∞ gives σmax(D)).
fn sigma_modal(mb: &Member, w: f64) -> f64 {
    let (p, m) = (mb.sys.outputs(), mb.sys.inputs());
    let mut g = Mat::<c64>::from_fn(p, m, |i, j| c64::new(mb.sys.d[(i, j)], 0.0));
    if w.is_finite() {
        let iw = c64::new(0.0, w);
        let mut i = 0;
        for &(re, im) in &mb.modes {
            if im.is_nan() {
                // (iω − σ)⁻¹ on one state.
                let r = c64::new(1.0, 0.0) / (iw - re);
                for a in 0..p {
                    for b in 0..m {
                        g[(a, b)] += r * mb.c_modal[(a, i)] * mb.b_modal[(i, b)];
                    }
                }
                i += 1;
            } else {
                add_modal_pair(&mut g, iw, (re, im), &mb.c_modal, &mb.b_modal, i);
                i += 2;
            }
        }
    }
    g.singular_values().unwrap().into_iter().fold(0.0, f64::max)
}

/// ρ = ε‖A‖_F / dist(iω, λ(A)): the relative sensitivity of G(iω) to rounding in A.
fn eval_error(mb: &Member, w: f64) -> f64 {
    if !w.is_finite() {
        return 0.0;
    }
    let dist = mb
        .modes
        .iter()
        .map(|&(re, im)| if im.is_nan() { re.hypot(w) } else { re.hypot(w - im.abs()) })
        .fold(f64::INFINITY, f64::min);
    f64::EPSILON * mb.sys.a.norm_l2() / dist
}

/// The truth: max σmax and its frequency over a dense sweep, refined around the best peaks, and
/// the frequency of the best other local maximum of the sweep (a lower peak, where a warm start
/// from a nearby system would put its hint).
struct Truth {
    value: f64,
    freq: f64,
    runner_up: Option<f64>,
}

fn truth(mb: &Member) -> Truth {
    let mut ws: Vec<f64> = Vec::new();
    let wn: Vec<(f64, f64)> = mb
        .modes
        .iter()
        .map(|&(re, im)| {
            if im.is_nan() {
                (-re, 1.0)
            } else {
                let r = re.hypot(im);
                (r, -re / r)
            }
        })
        .collect();
    let lo = wn.iter().map(|x| x.0).fold(f64::INFINITY, f64::min).max(1e-300) * 1e-3;
    let hi = wn.iter().map(|x| x.0).fold(0.0, f64::max) * 1e4;
    let npts = 3000;
    for k in 0..=npts {
        ws.push(lo * (hi / lo).powf(k as f64 / npts as f64));
    }
    for &(w, z) in &wn {
        for j in -24..=24 {
            ws.push(w * (1.0 + z * j as f64 / 6.0).max(1e-3));
        }
    }
    ws.push(0.0);
    ws.sort_by(f64::total_cmp);
    ws.dedup();
    let s: Vec<f64> = ws.iter().map(|&w| sigma_modal(mb, w)).collect();
    let mut best = (sigma_modal(mb, f64::INFINITY), f64::INFINITY);
    // Local maxima of the sweep, best first.
    let mut peaks: Vec<usize> =
        (0..ws.len()).filter(|&i| (i == 0 || s[i] >= s[i - 1]) && (i + 1 == ws.len() || s[i] >= s[i + 1])).collect();
    peaks.sort_by(|&a, &b| s[b].total_cmp(&s[a]));
    for &i in peaks.iter().take(6) {
        if s[i] > best.0 {
            best = (s[i], ws[i]);
        }
        if i == 0 || i + 1 == ws.len() {
            continue;
        }
        // Golden section on ω in [ω_{i−1}, ω_{i+1}].
        let (mut a, mut b) = (ws[i - 1], ws[i + 1]);
        const R: f64 = 0.618_033_988_749_894_9;
        let (mut x1, mut x2) = (b - R * (b - a), a + R * (b - a));
        let (mut f1, mut f2) = (sigma_modal(mb, x1), sigma_modal(mb, x2));
        for _ in 0..80 {
            if f1 > f2 {
                b = x2;
                (x2, f2) = (x1, f1);
                x1 = b - R * (b - a);
                f1 = sigma_modal(mb, x1);
            } else {
                a = x1;
                (x1, f1) = (x2, f2);
                x2 = a + R * (b - a);
                f2 = sigma_modal(mb, x2);
            }
            if b - a <= 1e-13 * b {
                break;
            }
        }
        for (f, x) in [(f1, x1), (f2, x2)] {
            if f > best.0 {
                best = (f, x);
            }
        }
    }
    // The best sweep maximum whose frequency differs from the peak's by more than 1 %.
    let runner_up = peaks
        .iter()
        .map(|&i| ws[i])
        .find(|&w| w > 0.0 && w.is_finite() && !(best.1.is_finite() && (w / best.1).ln().abs() < 0.01));
    Truth { value: best.0, freq: best.1, runner_up }
}

#[derive(Default)]
struct Tally {
    count: usize,
    square: usize,
    non_square: usize,
    light: usize,
    peak_at_infinity: usize,
    worst_under: f64,
    worst_under_seed: u64,
    worst_over: f64,
    failures: Vec<String>,
}

/// The family's members with the hints of their warm-started norm.
type Family = fn(u64) -> (Member, &'static str);

/// The first family: n from 2 to 30, hinted at a frequency unrelated to the peak.
fn small(seed: u64) -> (Member, &'static str) {
    (member(seed), "")
}

/// The large-order family up to n = 60.
fn large(seed: u64) -> (Member, &'static str) {
    member_large(seed, std::env::var("HINF_NMAX").ok().and_then(|v| v.parse().ok()).unwrap_or(60))
}

fn check(family: Family, seeds: impl IntoIterator<Item = u64>) -> Tally {
    let mut t = Tally::default();
    for seed in seeds {
        let (mb, shape) = family(seed);
        let Truth { value: want, freq: want_w, runner_up } = truth(&mb);
        let got = hinf_norm(&mb.sys, &HinfParams::default()).unwrap();
        if let Ok(dir) = std::env::var("HINF_DUMP") {
            let j = |m: &Mat<f64>| hinfix::lti::matrix_to_json(m.as_ref());
            let doc = serde_json::json!({"A": j(&mb.sys.a), "B": j(&mb.sys.b), "C": j(&mb.sys.c), "D": j(&mb.sys.d),
                "truth": want, "truth_freq": want_w, "runner_up": runner_up});
            std::fs::write(format!("{dir}/seed{seed}.json"), doc.to_string()).unwrap();
        }
        // The warm-started norm (design runs). The first family: a misleading hint, a frequency
        // unrelated to the peak, so its certification has to find the peak. The large family: a
        // hint on the best lower local peak, as a warm start from a nearby system gives it.
        let unrelated = 10f64.powf(-2.0 + 4.0 * ((seed * 7919) % 1000) as f64 / 1000.0);
        let hint = if shape.is_empty() { unrelated } else { runner_up.unwrap_or(unrelated) };
        let hinted = hinf_norm(&mb.sys, &HinfParams::default().with_hints(&[hint])).unwrap();
        t.count += 1;
        t.square += mb.square as usize;
        t.non_square += !mb.square as usize;
        t.light += mb.lightly_damped as usize;
        t.peak_at_infinity += want_w.is_infinite() as usize;
        for (label, got) in [("", got), (" (hinted)", hinted)] {
            let under = (want - got.value) / want;
            let attained = sigma_modal(&mb, got.peak_freq);
            let over = (got.value - attained) / got.value;
            if under > t.worst_under {
                t.worst_under = under;
                t.worst_under_seed = seed;
            }
            t.worst_over = t.worst_over.max(over);
            let allowed = REL_TOL + EVAL_ERROR_FACTOR * eval_error(&mb, want_w).max(eval_error(&mb, got.peak_freq));
            // NaN-aware: a NaN error counts as a failure.
            #[allow(clippy::neg_cmp_op_on_partial_ord)]
            let failed = !(under <= allowed) || !(over <= allowed);
            if failed {
                t.failures.push(format!(
                    "seed {seed}{label} {shape}: n={} m={} p={} δ={:.2e} light={}: hinf {} at ω={} (attains {attained}), truth {want} at ω={want_w}, under {under:.2e}",
                    mb.sys.order(), mb.sys.inputs(), mb.sys.outputs(), mb.delta, mb.lightly_damped, got.value, got.peak_freq
                ));
            }
        }
    }
    t
}

fn report(t: &Tally) {
    println!(
        "{} systems ({} square D, {} non-square; {} lightly damped; {} with the peak at ω = ∞): worst under-estimate {:.3e} (seed {}), worst over-estimate {:.3e}, {} failures",
        t.count, t.square, t.non_square, t.light, t.peak_at_infinity, t.worst_under, t.worst_under_seed, t.worst_over, t.failures.len()
    );
    for f in t.failures.iter().take(200) {
        println!("  {f}");
    }
}

#[test]
fn hinf_norm_never_under_estimates_near_sigma_max_d_fast_subset() {
    let t = match std::env::var("HINF_SEED").ok().and_then(|s| s.parse::<u64>().ok()) {
        Some(s) => check(small, s..s + 1),
        None => check(small, 0..120),
    };
    report(&t);
    assert!(t.failures.is_empty(), "{} of {} systems failed", t.failures.len(), t.count);
}

#[test]
#[ignore = "full property family (4000 systems): run with --release -- --ignored --nocapture"]
fn hinf_norm_never_under_estimates_near_sigma_max_d_full_family() {
    let t = check(small, 0..4000);
    report(&t);
    assert!(t.failures.is_empty(), "{} of {} systems failed", t.failures.len(), t.count);
}

/// Seeds `HINF_LARGE_SEEDS` (`a..b`) of the large-order family, else `default`.
fn large_seeds(default: std::ops::Range<u64>) -> std::ops::Range<u64> {
    std::env::var("HINF_LARGE_SEEDS")
        .ok()
        .and_then(|s| s.split_once("..").and_then(|(a, b)| Some(a.parse().ok()?..b.parse().ok()?)))
        .unwrap_or(default)
}

/// Members of the large family that main 7d158f7 got wrong (0.3 % to 1.8 % low): a pencil
/// crossing mapped to ω = ∞ (188), crossings of narrow low-frequency peaks lost or misplaced by
/// the squared spectrum (246, 323, 951); and that main 835c93f got wrong: the two crossings of a
/// peak 2e-7 rad/s wide at 1.2e-4 rad/s returned as one complex pair and merged into one
/// crossing (327, hinted: 1.6 % low), a peak at 1.4e7 rad/s 4e-10 above σmax(D) whose upper
/// crossing the pencil put at ω = ∞ (3522: 4e-10 low).
const LARGE_REGRESSIONS: [u64; 6] = [188, 246, 323, 951, 327, 3522];

#[test]
fn hinf_norm_never_under_estimates_at_large_order_fast_subset() {
    let t = match std::env::var("HINF_LARGE_SEEDS") {
        Ok(_) => check(large, large_seeds(0..0)),
        Err(_) => check(large, (0..20).chain(LARGE_REGRESSIONS)),
    };
    report(&t);
    assert!(t.failures.is_empty(), "{} of {} systems failed", t.failures.len(), t.count);
}

#[test]
#[ignore = "full large-order family (1500 systems, n = 30..60): run with --release -- --ignored --nocapture"]
fn hinf_norm_never_under_estimates_at_large_order_full_family() {
    let t = check(large, large_seeds(0..1500));
    report(&t);
    assert!(t.failures.is_empty(), "{} of {} systems failed", t.failures.len(), t.count);
}

/// A flat family: G = U·diag((s − pᵢ)/(s + pᵢ))·Vᵀ + δ·G₀, an inner (all-pass) part with
/// σmax ≡ 1 on the whole axis (U, V orthogonal, pᵢ > 0) plus a small random stable G₀, δ from
/// 1e-8 to 1e-3: σmax(G(iω)) = 1 + O(δ) everywhere with bumps at many frequencies, the shape of
/// an optimal design's equalised loop, where the level-set test just above σmax(D) = 1 is at its
/// most ill-conditioned. Asserted: the norm is never below max σmax over a dense log grid
/// (4001 points over [1e-4, 1e4] times the system's scale, direct complex solves) by more than
/// the tolerance, and it is attained at the returned frequency.
fn flat_member(seed: u64) -> StateSpace {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let m = rng.random_range(1..=3usize);
    let k = rng.random_range(1..=3usize); // all-pass factors per channel
    let n0 = rng.random_range(2..=6usize);
    let delta = log_uniform(&mut rng, 1e-8, 1e-3);
    let orth = |rng: &mut ChaCha8Rng| {
        let q = randn(rng, m, m).qr();
        q.compute_Q()
    };
    let (u, v) = (orth(&mut rng), orth(&mut rng));
    // Inner part: per channel j, the product of k first-order all-passes (a chain), then U·(·)·Vᵀ.
    let na = m * k;
    let n = na + n0;
    let mut a = Mat::<f64>::zeros(n, n);
    let mut b = Mat::<f64>::zeros(n, m);
    let mut c = Mat::<f64>::zeros(m, n);
    for j in 0..m {
        // Chain x' = −p x + in, out = −2p x + in: in of the first is (Vᵀw)ⱼ, out of the last is yⱼ.
        let poles: Vec<f64> = (0..k).map(|_| log_uniform(&mut rng, 0.1, 10.0)).collect();
        for (l, &p) in poles.iter().enumerate() {
            let i = j * k + l;
            a[(i, i)] = -p;
            // Input of stage l: the output of stage l − 1 = −2p' x' + (its input), recursively.
            for (l2, &p2) in poles.iter().enumerate().take(l) {
                a[(i, j * k + l2)] = -2.0 * p2;
            }
            for r in 0..m {
                b[(i, r)] = v[(r, j)];
            }
        }
        for (l, &p) in poles.iter().enumerate() {
            for r in 0..m {
                c[(r, j * k + l)] += u[(r, j)] * (-2.0 * p);
            }
        }
    }
    let d = &u * v.transpose();
    // δ·G₀: random stable modes.
    let mut a0 = randn(&mut rng, n0, n0) * faer::Scale(1.0 / (n0 as f64).sqrt());
    let shift = a0.eigenvalues().unwrap().iter().map(|l| l.re).fold(f64::NEG_INFINITY, f64::max);
    for i in 0..n0 {
        a0[(i, i)] -= shift + log_uniform(&mut rng, 1e-2, 1.0);
    }
    let (b0, c0) = (randn(&mut rng, n0, m), randn(&mut rng, m, n0) * faer::Scale(delta));
    for i in 0..n0 {
        for j in 0..n0 {
            a[(na + i, na + j)] = a0[(i, j)];
        }
        for r in 0..m {
            b[(na + i, r)] = b0[(i, r)];
            c[(r, na + i)] = c0[(r, i)];
        }
    }
    StateSpace { a, b, c, d }
}

#[test]
fn hinf_norm_is_never_below_a_dense_grid_on_flat_loops() {
    use common::sigma_direct;
    let mut worst = 0.0f64;
    for seed in 0..60u64 {
        let sys = flat_member(seed);
        let h = hinf_norm(&sys, &HinfParams::default()).unwrap();
        assert!(h.value.is_finite(), "seed {seed}: unstable member");
        let grid = (0..=4000).map(|i| 10f64.powf(-4.0 + 8.0 * i as f64 / 4000.0));
        let (wmax, smax) = grid
            .chain([0.0, f64::INFINITY])
            .map(|w| (w, sigma_direct(&sys, w)))
            .fold((0.0, 0.0), |acc, x| if x.1 > acc.1 { x } else { acc });
        let short = 1.0 - h.value / smax;
        worst = worst.max(short);
        assert!(
            h.value >= smax * (1.0 - DEFAULT_HINF_TOL - 1e-12),
            "seed {seed}: norm {} at ω = {}, below σmax {smax} at ω = {wmax} by {short:e}",
            h.value,
            h.peak_freq
        );
        let at = sigma_direct(&sys, h.peak_freq);
        assert!((at - h.value).abs() <= 1e-12 * h.value, "seed {seed}: {} not attained ({at})", h.value);
    }
    eprintln!("flat family: worst shortfall below the dense grid {worst:e}");
}
