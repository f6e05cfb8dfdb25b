//! Benchmark of the nonsmooth optimiser: iterations, evaluations and CPU time per test problem,
//! plus the simplex QP (dense interior point vs clarabel). Run: `cargo bench --bench optim`.

use hinfix::optim::test_problems::*;
use hinfix::optim::*;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

fn opts(normtol: f64, evaldist: f64, maxit: usize, gs: bool) -> HansoOptions {
    HansoOptions {
        bfgs: BfgsOptions { normtol, evaldist, maxit, ..Default::default() },
        gradsamp: GradSampOptions { only_if_uncertified: false, ..Default::default() },
        gradient_sampling: gs,
    }
}

fn bench(name: &str, obj: &mut dyn Objective, fmin: f64, o: &HansoOptions, nstarts: usize, seed: u64) {
    bench_scaled(name, obj, fmin, o, nstarts, seed, 1.0)
}

/// Starting points randn·scale.
fn bench_scaled(
    name: &str,
    obj: &mut dyn Objective,
    fmin: f64,
    o: &HansoOptions,
    nstarts: usize,
    seed: u64,
    scale: f64,
) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut starts = random_starts(obj.nvar(), nstarts, &mut rng);
    starts.iter_mut().for_each(|x| x.iter_mut().for_each(|v| *v *= scale));
    let ctl = RunControl::new(f64::INFINITY);
    let t0 = thread_cpu_time();
    let r = hanso(obj, &starts, o, &mut rng, &ctl, &mut NoObserver).expect("finite start");
    let cpu = thread_cpu_time() - t0;
    let bfgs_it: usize = r.starts.iter().filter_map(|s| s.as_ref().ok()).map(|s| s.iters).sum();
    let gs_it = r.gradient_sampling.as_ref().map_or(0, |g| g.iters);
    println!(
        "{name:<28} {:>3} {:>7} {:>6} {:>8} {:>10.3e} {:>9.2e} {:>9.2e} {:>9.1} {:>8.1}  {:?}",
        obj.nvar(),
        bfgs_it,
        gs_it,
        r.evals,
        r.best.f - fmin,
        r.best.dnorm,
        r.best.evaldist,
        cpu * 1e3,
        cpu * 1e6 / r.evals as f64,
        r.best.termination
    );
}

fn main() {
    println!("HANSO-style runs (3 random starts, seed fixed); times are thread CPU time");
    println!(
        "{:<28} {:>3} {:>7} {:>6} {:>8} {:>10} {:>9} {:>9} {:>9} {:>8}  termination",
        "problem", "n", "bfgs_it", "gs_it", "evals", "f - f*", "dnorm", "evaldist", "cpu_ms", "us/eval"
    );
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    bench("rosenbrock (smooth)", &mut Rosenbrock { n: 2 }, 0.0, &opts(1e-10, 1e-4, 1000, false), 3, 1);
    bench("rosenbrock (smooth)", &mut Rosenbrock { n: 10 }, 0.0, &opts(1e-10, 1e-4, 1000, false), 3, 1);
    for n in [2usize, 10, 30] {
        bench("max-quad", &mut MaxQuad::random(n, &mut rng), 0.0, &opts(1e-8, 1e-10, 1000, false), 3, 4);
    }
    for n in [2usize, 10, 30] {
        bench("l1 ||Mx||_1", &mut L1Norm::random(n, &mut rng), 0.0, &opts(1e-8, 1e-10, 1000, false), 3, 5);
    }
    for n in [2usize, 4] {
        bench(
            "max-eigenvalue (6x6)",
            &mut MaxEigenvalue::random(n, &mut rng),
            1.0,
            &opts(1e-8, 1e-10, 1000, true),
            3,
            12,
        );
    }
    bench_scaled("walled (+inf outside)", &mut Walled::new(4), 0.0, &opts(1e-8, 1e-6, 1000, false), 3, 2, 0.2);
    for n in 2..=10 {
        let gs = n <= 4;
        bench(
            if gs { "cheb-rosenbrock +GS" } else { "cheb-rosenbrock" },
            &mut ChebyshevRosenbrock { n },
            0.0,
            &opts(1e-8, 1e-6, 5000, gs),
            3,
            1,
        );
    }
    // The relative eigenvalue floor on H lets BFGS follow the valley to the minimiser.
    let mut floored = opts(1e-8, 1e-6, 100_000, true);
    floored.bfgs.h_floor = Some(1e-14);
    for n in 2..=5 {
        bench("cheb-rosenbrock h_floor +GS", &mut ChebyshevRosenbrock { n }, 0.0, &floored, 3, 1);
    }

    println!();
    println!("simplex QP min ||Gw||^2 (median of repeats): dense interior point vs clarabel");
    println!(
        "{:>4} {:>4} {:>12} {:>12} {:>12} {:>12}",
        "n", "m", "dense_ms", "clarabel_ms", "dense_obj", "clarabel_obj"
    );
    use rand::Rng;
    let mut rng = ChaCha8Rng::seed_from_u64(9);
    for &(n, m) in &[(10usize, 3usize), (20, 30), (60, 100), (300, 100)] {
        let cols: Vec<Vec<f64>> = (0..m).map(|_| (0..n).map(|_| rng.random::<f64>() - 0.45).collect()).collect();
        let refs: Vec<&[f64]> = cols.iter().map(|c| c.as_slice()).collect();
        let time = |f: &dyn Fn() -> f64| {
            let mut ts = vec![];
            let mut obj = 0.0;
            for _ in 0..15 {
                let t0 = thread_cpu_time();
                obj = f();
                ts.push(thread_cpu_time() - t0);
            }
            ts.sort_by(f64::total_cmp);
            (ts[ts.len() / 2] * 1e3, obj)
        };
        let (td, od) = time(&|| min_norm_dense(&refs).map_or(f64::NAN, |r| r.dnorm.powi(2)));
        let (tc, oc) = time(&|| min_norm_clarabel(&refs).map_or(f64::NAN, |r| r.dnorm.powi(2)));
        println!("{n:>4} {m:>4} {td:>12.4} {tc:>12.4} {od:>12.6e} {oc:>12.6e}");
    }
}
