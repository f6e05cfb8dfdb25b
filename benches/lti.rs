//! Benchmark of the LTI numerics: H∞-norm time on 2×2 systems of order
//! n = 10, 50, 100, 250, 500 (random stable, and lightly damped modal), and objective+gradient evaluations per second of the design
//! objective for HE1 (nK = 2) and CM4 (nK = 4). Times are thread CPU time, one thread (faer is
//! built without its rayon feature), medians over repeated runs.
//!
//! Run: `cargo bench --bench lti --features test-support` (the feature builds the library's
//! `lti::kernel_bench` entry points this bench calls). Options:
//! * `--dump DIR`: also write the random systems as JSON (`random_n{n}.json`, `damped_n{n}.json`, keys A, B, C, D) so
//!   that `scripts/ab13dd_bench.py DIR` can time SLICOT's AB13DD on exactly the same data;
//! * `--quick`: fewer repetitions;
//! * `--only N`: just the H∞ norm at order N, 200 times (for a profiler);
//! * `--design-cpumax S`: CPU budget of each design run of the last table (default 20, as in
//!   the large-plant timings `campaign design --order 1 --eps 1e-3 --seed 1 --cpumax 20`); `--no-design`
//!   skips that table;
//! * `--design-only [NAMES]`: just the last table, optionally only the plants in the
//!   comma-separated NAMES (e.g. `BDT2,CM4`; for a profiler);
//! * `--qr`: just the Hessenberg QR microbenchmark: per-call thread-CPU time of the
//!   eigenvalues of random Hessenberg matrices (n = 40, 83, 166, 241) and of the two matrices the
//!   H∞ norm hands to the QR for the BDT2 and CM4 closed loops with the designed controllers of
//!   `--pvl` (the Hessenberg form of A, the W of the square-reduced method), our QR (`lti::kernel_bench`) against faer's dense `evd_real` (values
//!   only; it first reduces the matrix to Hessenberg form again), alternated in the same process;
//! * `--pvl`: just the per-call table of the PVL reduction of the square-reduced method
//!   (`lti::kernel_bench::pvl_w`), alternated with faer's Hessenberg reduction of the same A as a
//!   yardstick (a quarter of the flops), on random skew-Hamiltonian matrices (n = 40, 83, 166,
//!   241) and on H² of the BDT2
//!   and CM4 closed loops at γ = 1.01‖Tzw‖∞ (controllers `benches/fixtures/{BDT2,CM4}_nk1.json`:
//!   `campaign design --order 1 --eps 1e-3 --seed 1`, BDT2 `--maxevals 1500`, CM4 200);
//! * `--steps`: after each design run of the last table, the H∞ steps it took (`lti::step_stats`:
//!   norms, explicit and pencil level-set tests per norm, and the thread-CPU time of each step;
//!   the timing adds two clock reads per step).
//! * `--record FILE` (with `--design-only NAME`): also writes every closed-loop H∞ norm of the
//!   design run (system, tolerance, peak hints; `lti::kernel_bench::record_norms`) to FILE;
//! * `--replay FILE [--rounds R]`: computes those norms again, R times (default 3), and prints
//!   the thread-CPU ms per norm (median over rounds), a checksum of the values and, with
//!   `--steps`, the step table. A change to the norm is then timed on the same systems before
//!   and after, independent of the design path it would otherwise change.
//!
//! The last table is machine-independent: CPU ms per objective evaluation over a whole design run
//! (`cpu_s / evals` of the outcome) divided by the CPU time of one dense eigenvalue solve (faer,
//! values only) of a random matrix of size 2(n + nK), timed in the same process (the mean of its
//! medians before and after the design run, both printed).

use std::cell::RefCell;
use std::path::PathBuf;
use std::rc::Rc;

use faer::linalg::solvers::DenseSolveCore;
use faer::Mat;
use hinfix::design::ComponentCache;
use hinfix::design::{controller_to_x, ControllerShape, Design, DesignObjective, DesignOptions, ObjectivePhase};
use hinfix::lti::kernel_bench;
use hinfix::lti::step_stats::{self, Step};
use hinfix::lti::{
    hinf_norm, matrix_to_json, resolve_plant, spectral_abscissa, Controller, HinfParams, Plant, StateSpace,
    DEFAULT_HINF_TOL,
};
use hinfix::optim::{thread_cpu_time, Objective};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

/// An r×c matrix of independent N(0, scale²) entries.
fn randn(rng: &mut ChaCha8Rng, r: usize, c: usize, scale: f64) -> Mat<f64> {
    Mat::from_fn(r, c, |_, _| {
        let z: f64 = StandardNormal.sample(rng);
        scale * z
    })
}

/// A random stable system: A = M/√n − 1.2·I with M standard normal (the spectrum of M/√n lies
/// in the unit disc up to O(n^{-1/2}), so Re λ(A) ≲ −0.2); stability is checked.
fn random_stable(n: usize, m: usize, p: usize, seed: u64) -> StateSpace {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut a = randn(&mut rng, n, n, 1.0 / (n as f64).sqrt());
    for i in 0..n {
        a[(i, i)] -= 1.2;
    }
    let (b, c, d) = (randn(&mut rng, n, m, 1.0), randn(&mut rng, p, n, 1.0), randn(&mut rng, p, m, 0.3));
    let sys = StateSpace::new(a, b, c, d).unwrap();
    assert!(hinf_norm(&sys, &HinfParams::default()).unwrap().value.is_finite(), "random system n={n} not stable");
    sys
}

/// A lightly damped modal system: n/2 modes with natural frequencies log-spaced over
/// [0.1, 100] rad/s and damping ratios log-spaced over [1e-3, 1e-1], behind a random orthogonal
/// similarity (so A is full, not block diagonal). Its peak is sharp (ζ = 1e-3 at 0.1 rad/s).
fn lightly_damped(n: usize, m: usize, p: usize, seed: u64) -> StateSpace {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let k = n / 2;
    let mut blocks = Mat::<f64>::zeros(n, n);
    for i in 0..k {
        let t = if k > 1 { i as f64 / (k - 1) as f64 } else { 0.5 };
        let w = 10f64.powf(-1.0 + 3.0 * t);
        let z = 10f64.powf(-3.0 + 2.0 * ((7 * i) % k) as f64 / k.max(1) as f64);
        let (re, im) = (-z * w, w * (1.0 - z * z).sqrt());
        blocks[(2 * i, 2 * i)] = re;
        blocks[(2 * i + 1, 2 * i + 1)] = re;
        blocks[(2 * i, 2 * i + 1)] = im;
        blocks[(2 * i + 1, 2 * i)] = -im;
    }
    let q = randn(&mut rng, n, n, 1.0).qr().compute_Q();
    let a = &q * &blocks * q.transpose();
    let (b, c) = (randn(&mut rng, n, m, 1.0), randn(&mut rng, p, n, 1.0));
    StateSpace::new(a, b, c, Mat::zeros(p, m)).unwrap()
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Median thread-CPU seconds of `f` over `reps` runs.
fn time<R>(reps: usize, mut f: impl FnMut() -> R) -> (f64, R) {
    let mut out = None;
    let times = (0..reps)
        .map(|_| {
            let t0 = thread_cpu_time();
            out = Some(f());
            thread_cpu_time() - t0
        })
        .collect();
    (median(times), out.unwrap())
}

fn plant(name: &str) -> Plant {
    resolve_plant(name).and_then(Plant::load).unwrap_or_else(|e| panic!("{e}"))
}

/// Objective+gradient evaluations per second at controller `k` (performance phase, strong
/// stabilisation, ε = 1e-3), with a small perturbation per evaluation so no cache can help.
fn evals_per_second(name: &str, plant: &Plant, k: &Controller, seconds: f64) {
    let shape = ControllerShape { nk: k.order(), m: k.outputs(), p: k.inputs(), domain: Default::default() };
    let cache = Rc::new(RefCell::new(ComponentCache::default()));
    let mut obj = DesignObjective::new(plant, shape, ObjectivePhase::Performance, true, 1e-3, DEFAULT_HINF_TOL, cache);
    let x0 = controller_to_x(k);
    let mut g = vec![0.0; x0.len()];
    let f0 = obj.eval(&x0, &mut g);
    assert!(f0.is_finite(), "{name}: the bench controller does not stabilise (f = {f0})");
    let t0 = thread_cpu_time();
    let mut count = 0usize;
    let mut x = x0.clone();
    while thread_cpu_time() - t0 < seconds || count < 3 {
        let i = count % x0.len();
        x[i] = x0[i] * (1.0 + 1e-9 * (count + 1) as f64);
        let f = obj.eval(&x, &mut g);
        assert!(f.is_finite());
        count += 1;
    }
    let cpu = thread_cpu_time() - t0;
    println!(
        "{name:<10} n={:<4} nK={:<2} f = {f0:<12.6} {:>10.1} evals/s  {:>9.3} ms/eval  ({count} evals)",
        plant.dims.n,
        k.order(),
        count as f64 / cpu,
        cpu * 1e3 / count as f64
    );
}

/// A stable controller of order `nk` with Ck = 0, Dk = 0: the closed loop is block triangular
/// with the poles of the (open-loop stable) plant and of Ak, so it is stable however lightly damped
/// the plant is (CM4's α is −5.7e-6); the objective and its gradient cost the same as for any K.
fn output_free_controller(nk: usize, m: usize, p: usize, gain: f64) -> Controller {
    let mut k = Controller::zeros(nk, m, p);
    for i in 0..nk {
        k.ak[(i, i)] = -1.0 - i as f64;
        for j in 0..p {
            k.bk[(i, j)] = gain * ((i + 2 * j) as f64).sin();
        }
    }
    k
}

/// CPU seconds of one dense eigenvalue solve (faer `evd_real`, values only) of a random
/// standard-normal matrix of size `size` (median of `reps`).
fn dense_eig_seconds(size: usize, reps: usize) -> f64 {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::linalg::evd;
    let mut rng = ChaCha8Rng::seed_from_u64(size as u64);
    let a = randn(&mut rng, size, size, 1.0);
    let par = faer::Par::Seq;
    let mut mem = MemBuffer::new(evd::evd_scratch::<f64>(
        size,
        evd::ComputeEigenvectors::No,
        evd::ComputeEigenvectors::No,
        par,
        Default::default(),
    ));
    let (t, _) = time(reps, || {
        let mut wr = faer::diag::Diag::<f64>::zeros(size);
        let mut wi = faer::diag::Diag::<f64>::zeros(size);
        evd::evd_real(
            a.as_ref(),
            wr.as_mut(),
            wi.as_mut(),
            None,
            None,
            par,
            MemStack::new(&mut mem),
            Default::default(),
        )
        .unwrap();
        wr[0] + wi[0]
    });
    t
}

/// One design run (order `nk`, ε = 1e-3, seed 1, budget `cpumax`): CPU ms per evaluation and its
/// ratio to one dense eigensolve of size 2(n + nK); with `steps`, the H∞ steps it took.
fn design_ratio(name: &str, nk: usize, cpumax: f64, steps: bool, record: Option<&PathBuf>) {
    let p = plant(name);
    let size = 2 * (p.dims.n + nk);
    let reps = if size > 300 { 9 } else { 31 };
    let eig_before = dense_eig_seconds(size, reps);
    let opts = DesignOptions { order: nk, eps: 1e-3, seed: 1, cpumax, ..DesignOptions::default() };
    step_stats::reset();
    step_stats::set_timing(steps);
    if record.is_some() {
        kernel_bench::record_norms();
    }
    let o = Design::for_plant(&p, &opts).run().unwrap_or_else(|e| panic!("{name}: {e}"));
    step_stats::set_timing(false);
    if let Some(path) = record {
        let norms = kernel_bench::take_recorded_norms();
        write_recorded(path, &norms).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        println!("recorded {} norms to {}", norms.len(), path.display());
    }
    // The machine's speed drifts over a 20 s run (shared cores): the eig is timed before and after
    // the design run, and their mean is the unit.
    let eig_after = dense_eig_seconds(size, reps);
    let eig = 0.5 * (eig_before + eig_after);
    let ms = o.design_cpu_s * 1e3 / o.evaluations as f64;
    println!(
        "{name:<6} n={:<4} nK={nk} γ = {:<12.6} {:>6} evals {:>7.2} s {:>9.3} ms/eval   eig({size}) {:>8.3} ms ({:.3}/{:.3})  ratio {:>6.3}",
        p.dims.n,
        o.gamma,
        o.evaluations,
        o.design_cpu_s,
        ms,
        eig * 1e3,
        eig_before * 1e3,
        eig_after * 1e3,
        ms / (eig * 1e3)
    );
    if steps {
        print_steps(&step_stats::snapshot(), o.evaluations, o.design_cpu_s);
    }
}

/// Writes recorded norms (`--record`): per norm, little-endian u64 n, m, p, number of hints,
/// then f64 tol, the hints and A, B, C, D column-major.
fn write_recorded(path: &PathBuf, norms: &[kernel_bench::RecordedNorm]) -> std::io::Result<()> {
    let mut out: Vec<u8> = Vec::new();
    for r in norms {
        let s = &r.sys;
        for k in [s.order(), s.inputs(), s.outputs(), r.hints.len()] {
            out.extend((k as u64).to_le_bytes());
        }
        let mats = [&s.a, &s.b, &s.c, &s.d];
        let values = std::iter::once(r.tol).chain(r.hints.iter().copied()).chain(
            mats.into_iter().flat_map(|m| (0..m.ncols()).flat_map(move |j| (0..m.nrows()).map(move |i| m[(i, j)]))),
        );
        for x in values {
            out.extend(x.to_le_bytes());
        }
    }
    std::fs::write(path, out)
}

/// Reads what [`write_recorded`] wrote.
fn read_recorded(path: &PathBuf) -> std::io::Result<Vec<kernel_bench::RecordedNorm>> {
    let bytes = std::fs::read(path)?;
    let mut norms = Vec::new();
    let mut it = bytes.chunks_exact(8).map(|c| <[u8; 8]>::try_from(c).expect("8 bytes"));
    while let Some(w) = it.next() {
        let n = u64::from_le_bytes(w) as usize;
        let mut next_int = || u64::from_le_bytes(it.next().expect("truncated record")) as usize;
        let (m, p, nh) = (next_int(), next_int(), next_int());
        let mut next = || f64::from_le_bytes(it.next().expect("truncated record"));
        let tol = next();
        let hints = (0..nh).map(|_| next()).collect();
        let mut mat = |r: usize, c: usize| {
            let v: Vec<f64> = (0..r * c).map(|_| next()).collect();
            Mat::from_fn(r, c, |i, j| v[i + j * r])
        };
        let (a, b, c, d) = (mat(n, n), mat(n, m), mat(p, n), mat(p, m));
        norms.push(kernel_bench::RecordedNorm { sys: StateSpace { a, b, c, d }, tol, hints });
    }
    Ok(norms)
}

/// `--compare FILE` of the replay: writes the values to FILE if it does not exist, else compares
/// them with FILE's (from another build) and prints the largest relative differences.
fn compare_values(file: &PathBuf, values: &[f64]) {
    let Ok(text) = std::fs::read_to_string(file) else {
        let text: String = values.iter().map(|v| format!("{v:e}\n")).collect();
        std::fs::write(file, text).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
        println!("values written to {}", file.display());
        return;
    };
    let old: Vec<f64> = text.lines().map(|l| l.parse().expect("a number per line")).collect();
    assert_eq!(old.len(), values.len(), "{}: another recording", file.display());
    let (mut lower, mut higher, mut differ) = (0.0f64, 0.0f64, 0usize);
    for (&o, &v) in old.iter().zip(values) {
        if o.to_bits() != v.to_bits() {
            differ += 1;
        }
        if o.is_finite() && v.is_finite() {
            let r = v / o - 1.0;
            lower = lower.min(r);
            higher = higher.max(r);
        } else if o.is_finite() != v.is_finite() {
            println!("  finite/infinite mismatch: {o:e} against {v:e}");
        }
    }
    println!("  against {}: {differ} values differ; new/old − 1 in [{lower:.3e}, {higher:.3e}]", file.display());
}

/// The replay (`--replay`, module docs).
fn replay(path: &PathBuf, rounds: usize, steps: bool, compare: Option<&PathBuf>) {
    let norms = read_recorded(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut times = Vec::new();
    let mut values = Vec::with_capacity(norms.len());
    for round in 0..rounds {
        step_stats::reset();
        step_stats::set_timing(steps && round + 1 == rounds);
        let t0 = thread_cpu_time();
        for r in &norms {
            let h = hinf_norm(&r.sys, &HinfParams::new(r.tol).with_hints(&r.hints)).unwrap();
            if round == 0 {
                values.push(h.value);
            }
        }
        let t = thread_cpu_time() - t0;
        step_stats::set_timing(false);
        times.push(t * 1e3 / norms.len().max(1) as f64);
        if steps && round + 1 == rounds {
            print_steps(&step_stats::snapshot(), norms.len(), t);
        }
    }
    let order = norms.first().map_or(0, |r| r.sys.order());
    let sum: f64 = values.iter().filter(|v| v.is_finite()).sum();
    let bits = values.iter().fold(0u64, |b, v| b.rotate_left(5) ^ v.to_bits());
    if let Some(file) = compare {
        compare_values(file, &values);
    }
    println!(
        "replay {}: {} norms (order {order}), {:.4} ms/norm (median of {rounds}; {:?}), Σ finite ‖·‖∞ = {sum:.12e}, bits {bits:016x}",
        path.display(),
        norms.len(),
        median(times.clone()),
        times.iter().map(|t| format!("{t:.4}")).collect::<Vec<_>>()
    );
}

/// The step table of `--steps` (module docs), for the small (order < 30: the controller's own
/// norm on large plants) and the large systems.
fn print_steps(s: &step_stats::StepStats, evals: usize, cpu_s: f64) {
    for large in [false, true] {
        let norms = s.calls(Step::Norm, large);
        if norms == 0 {
            continue;
        }
        let per_norm = |st: Step| s.calls(st, large) as f64 / norms as f64;
        println!(
            "    order {} {}: {norms} norms ({:.2} per evaluation), {} using the pencil; level-set tests per norm: {:.3} explicit ({:.3} doubtful), {:.3} pencil, {:.3} finding crossings, {:.3} only probes ({:.3} raising γ_L)",
            if large { ">=" } else { "<" },
            step_stats::LARGE_ORDER,
            norms as f64 / evals.max(1) as f64,
            s.calls(Step::NormUsingPencil, large),
            per_norm(Step::ExplicitLevelSet),
            per_norm(Step::DoubtfulSquared),
            per_norm(Step::PencilLevelSet),
            per_norm(Step::CrossingsFound),
            per_norm(Step::Probe),
            per_norm(Step::ProbeFound),
        );
        println!("      {:<24} {:>9} {:>10} {:>9} {:>7}", "step", "calls", "CPU s", "ms/call", "% run");
        for step in Step::ALL.into_iter().filter(|&st| !st.count_only() && s.calls(st, large) > 0) {
            let (c, t) = (s.calls(step, large), s.cpu_s(step, large));
            println!(
                "      {:<24} {c:>9} {t:>10.3} {:>9.4} {:>6.1}%",
                step.name(),
                t * 1e3 / c as f64,
                100.0 * t / cpu_s
            );
        }
    }
}

fn main() {
    hinfix::malloc_tuning::keep_freed_memory();
    let args: Vec<String> = std::env::args().collect();
    let quick = args.iter().any(|a| a == "--quick");
    let dump = args.iter().position(|a| a == "--dump").and_then(|i| args.get(i + 1)).map(PathBuf::from);
    let only: Option<usize> =
        args.iter().position(|a| a == "--only").and_then(|i| args.get(i + 1)).and_then(|s| s.parse().ok());
    let design_only: Option<Vec<String>> = args.iter().position(|a| a == "--design-only").map(|i| {
        args.get(i + 1)
            .filter(|s| !s.starts_with("--"))
            .map_or(Vec::new(), |s| s.split(',').map(String::from).collect())
    });
    if let Some(path) = args.iter().position(|a| a == "--replay").and_then(|i| args.get(i + 1)) {
        let rounds =
            args.iter().position(|a| a == "--rounds").and_then(|i| args.get(i + 1)).and_then(|s| s.parse().ok());
        let compare = args.iter().position(|a| a == "--compare").and_then(|i| args.get(i + 1)).map(PathBuf::from);
        replay(&PathBuf::from(path), rounds.unwrap_or(3), args.iter().any(|a| a == "--steps"), compare.as_ref());
        return;
    }
    if args.iter().any(|a| a == "--qr") {
        qr_table(quick);
        return;
    }
    if let Some(names) = &design_only {
        design_table(&args, names);
        return;
    }
    if args.iter().any(|a| a == "--pvl") {
        pvl_table();
        return;
    }

    for (family, make) in [
        ("random stable (A = M/√n − 1.2 I)", random_stable as fn(usize, usize, usize, u64) -> StateSpace),
        ("lightly damped modes (ζ 1e-3…1e-1, ω 0.1…100)", lightly_damped),
    ] {
        println!("H∞ norm, {family}, 2 inputs, 2 outputs, tol {DEFAULT_HINF_TOL:e}, thread CPU time (median)");
        println!("{:>5} {:>12} {:>14} {:>12} {:>5} {:>12}", "n", "seconds", "‖G‖∞", "peak ω", "reps", "eig(A) s");
        for &n in [10usize, 50, 100, 250, 500].iter().filter(|&&n| only.is_none_or(|o| o == n)) {
            let sys = make(n, 2, 2, n as u64);
            if let Some(dir) = &dump {
                std::fs::create_dir_all(dir).unwrap();
                let doc = serde_json::json!({
                    "A": matrix_to_json(sys.a.as_ref()), "B": matrix_to_json(sys.b.as_ref()),
                    "C": matrix_to_json(sys.c.as_ref()), "D": matrix_to_json(sys.d.as_ref()),
                });
                let tag = if family.starts_with("random") { "random" } else { "damped" };
                std::fs::write(dir.join(format!("{tag}_n{n}.json")), doc.to_string()).unwrap();
            }
            let reps = match (n, quick) {
                _ if only.is_some() => 200,
                (_, true) => 3,
                (0..=100, _) => 21,
                (101..=250, _) => 9,
                _ => 5,
            };
            let (t, h) = time(reps, || hinf_norm(&sys, &HinfParams::default()).unwrap());
            let (t_poles, _) = time(reps, || spectral_abscissa(sys.a.as_ref()));
            println!("{n:>5} {t:>12.6} {:>14.10} {:>12.6} {reps:>5} {t_poles:>12.6}", h.value, h.peak_freq);
        }
        println!();
    }
    if only.is_some() {
        return;
    }
    println!("Design objective max(‖Tzw‖∞, ε‖K‖∞) + gradient (ε = 1e-3, strong), thread CPU time");
    let secs = if quick { 1.0 } else { 5.0 };
    let he1 = plant("HE1");
    let k = Controller::load(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("benches/fixtures/HE1_nk2.json"))
        .unwrap_or_else(|e| panic!("{e}"));
    evals_per_second("HE1", &he1, &k, secs);
    let cm4 = plant("CM4");
    let d = cm4.dims;
    evals_per_second("CM4", &cm4, &output_free_controller(4, d.m2, d.p2, 1e-2), secs);
    if args.iter().any(|a| a == "--no-design") {
        return;
    }
    design_table(&args, &[]);
}

/// The blocks [A, G, Q] of a random skew-Hamiltonian [A G; Q Aᵀ] of size 2n (G, Q skew).
fn random_skew_hamiltonian(n: usize, seed: u64) -> [Mat<f64>; 3] {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let a = randn(&mut rng, n, n, 1.0);
    let (g, q) = (randn(&mut rng, n, n, 1.0), randn(&mut rng, n, n, 1.0));
    [a, &g - g.transpose(), &q - q.transpose()]
}

/// The blocks of H² for the Hamiltonian H = [F Gₕ; K −Fᵀ] of `sys` at level γ (D ≠ 0 allowed):
/// R = γ²I − DᵀD, F = A + BR⁻¹DᵀC, Gₕ = BR⁻¹Bᵀ, K = −Cᵀ(I + DR⁻¹Dᵀ)C; H² = [F² + GₕK,
/// FGₕ − (FGₕ)ᵀ; KF − (KF)ᵀ, ·].
fn squared_hamiltonian(sys: &StateSpace, gamma: f64) -> [Mat<f64>; 3] {
    let (a, b, c, d) = (&sys.a, &sys.b, &sys.c, &sys.d);
    let r = Mat::<f64>::identity(d.ncols(), d.ncols()) * faer::Scale(gamma * gamma) - d.transpose() * d;
    let r_inv = r.as_ref().partial_piv_lu().inverse();
    let f = a + b * &r_inv * d.transpose() * c;
    let gh = b * &r_inv * b.transpose();
    let k = -(c.transpose() * (Mat::<f64>::identity(d.nrows(), d.nrows()) + d * &r_inv * d.transpose()) * c);
    let (fg, kf) = (&f * &gh, &k * &f);
    [&f * &f + &gh * &k, &fg - fg.transpose(), &kf - kf.transpose()]
}

/// Thread-CPU ms of faer's Hessenberg reduction (values only, no Q) of a copy of `a`.
fn faer_hessenberg_ms(a: &Mat<f64>) -> f64 {
    use faer::dyn_stack::{MemBuffer, MemStack};
    use faer::linalg::evd::hessenberg;
    let n = a.nrows();
    let block = 32.min(n.saturating_sub(1)).max(1);
    let par = faer::Par::Seq;
    let mut mem = MemBuffer::new(hessenberg::hessenberg_in_place_scratch::<f64>(n, block, par, Default::default()));
    let (mut h, mut tau) = (a.clone(), Mat::<f64>::zeros(block, n.saturating_sub(1)));
    let t0 = thread_cpu_time();
    hessenberg::hessenberg_in_place(h.as_mut(), tau.as_mut(), par, MemStack::new(&mut mem), Default::default());
    (thread_cpu_time() - t0) * 1e3
}

/// The `--pvl` table (module docs): thread-CPU ms per PVL reduction and per faer Hessenberg
/// reduction, medians of rounds that alternate the two, and their flop rates.
fn pvl_table() {
    let mut cases: Vec<(String, [Mat<f64>; 3])> = [40usize, 83, 166, 241]
        .iter()
        .map(|&n| (format!("random n={n}"), random_skew_hamiltonian(n, n as u64)))
        .collect();
    for name in ["BDT2", "CM4"] {
        let sys = designed_closed_loop(name);
        let norm = hinf_norm(&sys, &HinfParams::default()).unwrap().value;
        assert!(norm.is_finite(), "{name}: closed loop not stable");
        cases.push((format!("{name} H² n={}", sys.a.nrows()), squared_hamiltonian(&sys, 1.01 * norm)));
    }
    println!("PVL reduction per call (as used from closed-loop order 30) and faer's Hessenberg reduction of the");
    println!("block A alone, alternated; thread CPU ms, median (range); GFlop/s: PVL 40n³/3 flops, Hessenberg 10n³/3");
    println!(
        "{:<16} {:>24} {:>24} {:>8} {:>8} {:>9}",
        "case", "PVL", "faer Hessenberg", "GF/s PVL", "GF/s H", "PVL/Hess"
    );
    for (what, [a, g, q]) in &cases {
        let n = a.nrows();
        let reps = if n > 150 { 15 } else { 61 };
        let (mut pvl, mut hess) = (Vec::new(), Vec::new());
        for _ in 0..reps {
            let t0 = thread_cpu_time();
            let w = kernel_bench::pvl_w(a.as_ref(), g.as_ref(), q.as_ref());
            pvl.push((thread_cpu_time() - t0) * 1e3);
            assert!(w.iter().all(|x| x.is_finite()), "{what}: W not finite");
            hess.push(faer_hessenberg_ms(a));
        }
        let range = |t: &[f64]| {
            let (lo, hi) = t.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), &x| (lo.min(x), hi.max(x)));
            format!("{:.3} ({lo:.3}–{hi:.3})", median(t.to_vec()))
        };
        let (p, h) = (median(pvl.clone()), median(hess.clone()));
        let n3 = (n as f64).powi(3) / 3.0 * 1e-6;
        println!(
            "{what:<16} {:>24} {:>24} {:>8.1} {:>8.1} {:>9.2}",
            range(&pvl),
            range(&hess),
            40.0 * n3 / p,
            10.0 * n3 / h,
            p / h
        );
    }
}

/// The design-run table (module docs) for the plants `names` (all three if empty).
fn design_table(args: &[String], names: &[String]) {
    let cpumax: f64 = args
        .iter()
        .position(|a| a == "--design-cpumax")
        .and_then(|i| args.get(i + 1))
        .and_then(|s| s.parse().ok())
        .unwrap_or(20.0);
    println!();
    println!("Design run (order nK, ε = 1e-3, seed 1, cpumax {cpumax} s): ms per evaluation / one dense eig of size 2(n + nK)");
    for (name, nk) in [("HE1", 1), ("BDT2", 1), ("CM4", 1)] {
        if names.is_empty() || names.iter().any(|n| n == name) {
            let record = args.iter().position(|a| a == "--record").and_then(|i| args.get(i + 1)).map(PathBuf::from);
            design_ratio(name, nk, cpumax, args.iter().any(|a| a == "--steps"), record.as_ref());
        }
    }
}

/// The closed loop of plant `name` with its designed order-1 controller
/// (`benches/fixtures/{name}_nk1.json`, module docs): the matrices of a converged design, which
/// the microbenchmarks time (a made-up controller's closed loop splits into small blocks early
/// in the QR: BDT2 ≈ 0.13 ms per QR against ≈ 0.97 ms in design runs).
fn designed_closed_loop(name: &str) -> hinfix::lti::StateSpace {
    let p = plant(name);
    let k =
        Controller::load(PathBuf::from(env!("CARGO_MANIFEST_DIR")).join(format!("benches/fixtures/{name}_nk1.json")))
            .unwrap_or_else(|e| panic!("{e}"));
    hinfix::lti::closed_loop(&p, &k).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The Hessenberg QR microbenchmark (`--qr`, module docs).
fn qr_table(quick: bool) {
    let mut cases: Vec<(String, usize, Vec<f64>)> = Vec::new();
    for n in [40usize, 83, 166, 241] {
        let mut rng = ChaCha8Rng::seed_from_u64(n as u64);
        let a = randn(&mut rng, n, n, 1.0);
        let h = (0..n * n).map(|k| if k % n <= k / n + 1 { a[(k % n, k / n)] } else { 0.0 }).collect();
        cases.push((format!("random Hessenberg n={n}"), n, h));
    }
    for name in ["BDT2", "CM4"] {
        let cl = designed_closed_loop(name);
        let n = cl.order();
        cases.push((
            format!("{name} closed loop, Hessenberg form of A"),
            n,
            kernel_bench::hessenberg_form(cl.a.as_ref()),
        ));
        // The Hamiltonian [A, BBᵀ/γ; −CᵀC/γ, −Aᵀ] (the D = 0 form) at twice the norm.
        let gamma = 2.0 * hinf_norm(&cl, &HinfParams::default()).unwrap().value.max(1.0);
        let g = &cl.b * cl.b.transpose() * faer::Scale(1.0 / gamma);
        let kk = cl.c.transpose() * &cl.c * faer::Scale(-1.0 / gamma);
        let w = kernel_bench::hamiltonian_w(cl.a.as_ref(), g.as_ref(), kk.as_ref()).expect("finite W");
        cases.push((format!("{name} closed loop, W at γ = 2‖T‖∞"), n, w));
    }
    let rounds = if quick { 5 } else { 15 };
    println!("Hessenberg QR, eigenvalues only: thread-CPU ms per call, median [min–max] of {rounds} alternated rounds");
    println!(
        "{:<44} {:>5} {:>26} {:>26} {:>7} {:>10}",
        "matrix", "n", "faer evd_real", "ours", "ratio", "max |Δλ|/‖H‖"
    );
    for (what, n, h) in &cases {
        let n = *n;
        let norm = h.iter().map(|x| x * x).sum::<f64>().sqrt();
        // Calls per timing so that one timing is ≥ ~20 ms.
        let calls = (20_000_000 / (n * n * n)).max(1);
        let (mut old, mut new) = (Vec::new(), Vec::new());
        let mut diff = 0.0f64;
        for _ in 0..rounds {
            for (times, qr) in [
                (&mut old, faer_eigenvalues as fn(&mut [f64], usize) -> Option<Vec<faer::c64>>),
                (&mut new, kernel_bench::eigenvalues),
            ] {
                let t0 = thread_cpu_time();
                for _ in 0..calls {
                    let mut x = h.clone();
                    std::hint::black_box(qr(&mut x, n).expect("QR converges"));
                }
                times.push((thread_cpu_time() - t0) * 1e3 / calls as f64);
            }
        }
        // Each new eigenvalue's distance to the nearest old one not yet matched.
        let a = faer_eigenvalues(&mut h.clone(), n).expect("QR converges");
        let b = kernel_bench::eigenvalues(&mut h.clone(), n).expect("QR converges");
        let mut used = vec![false; n];
        for y in &b {
            let (k, d) = a
                .iter()
                .enumerate()
                .filter(|(k, _)| !used[*k])
                .map(|(k, x)| (k, (x - y).norm()))
                .fold((0, f64::INFINITY), |m, x| if x.1 < m.1 { x } else { m });
            used[k] = true;
            diff = diff.max(d / norm);
        }
        let span = |v: &[f64]| {
            let (lo, hi) = v.iter().fold((f64::INFINITY, 0.0f64), |(l, h), &t| (l.min(t), h.max(t)));
            format!("{:.3} [{lo:.3}–{hi:.3}]", median(v.to_vec()))
        };
        println!(
            "{what:<44} {n:>5} {:>26} {:>26} {:>7.2} {diff:>10.1e}",
            span(&old),
            span(&new),
            median(old.clone()) / median(new.clone())
        );
    }
}

/// faer's eigenvalues of the n×n column-major `h` (entries below the subdiagonal as zero).
fn faer_eigenvalues(h: &mut [f64], n: usize) -> Option<Vec<faer::c64>> {
    Mat::from_fn(n, n, |i, j| if i <= j + 1 { h[i + j * n] } else { 0.0 }).eigenvalues().ok()
}
