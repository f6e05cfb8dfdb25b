//! Tests of the optimiser on problems with known minimisers.

use super::test_problems::*;
use super::*;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use std::ops::ControlFlow;

fn norm(x: &[f64]) -> f64 {
    x.iter().map(|v| v * v).sum::<f64>().sqrt()
}

fn hanso_opts(normtol: f64, evaldist: f64, maxit: usize, gs: bool) -> HansoOptions {
    HansoOptions {
        bfgs: BfgsOptions { normtol, evaldist, maxit, ..Default::default() },
        gradsamp: GradSampOptions { only_if_uncertified: false, ..Default::default() },
        gradient_sampling: gs,
    }
}

fn run_hanso(obj: &mut dyn Objective, nstarts: usize, opts: &HansoOptions, seed: u64) -> HansoResult {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let starts = random_starts(obj.nvar(), nstarts, &mut rng);
    let ctl = RunControl::new(f64::INFINITY);
    hanso(obj, &starts, opts, &mut rng, &ctl, &mut NoObserver).expect("finite starts")
}

fn show(name: &str, r: &OptimResult) {
    println!(
        "{name}: f={:.3e} dnorm={:.2e} evaldist={:.2e} {:?} iters {} evals {}",
        r.f, r.dnorm, r.evaldist, r.termination, r.iters, r.evals
    );
}

/// Certificate sanity: finite, and dnorm really is the min-norm of gradients near x.
fn assert_certificate(r: &OptimResult, dnorm_max: f64, evaldist_max: f64) {
    assert!(r.dnorm.is_finite() && r.dnorm >= 0.0 && r.dnorm <= dnorm_max, "dnorm {:e} > {dnorm_max:e}", r.dnorm);
    assert!(
        r.evaldist.is_finite() && r.evaldist >= 0.0 && r.evaldist <= evaldist_max,
        "evaldist {:e} > {evaldist_max:e}",
        r.evaldist
    );
}

#[test]
fn chebyshev_rosenbrock_small_n_reaches_minimiser() {
    // BFGS + gradient sampling reaches f ≤ 1e-8 for n = 2…4 with the eigenvalue floor
    // h_floor = 1e-14 on H. Without it n = 4 ends at f ≈ 2e-5…2e-3 (see
    // chebyshev_rosenbrock_n4_needs_the_h_floor): BFGS follows the curved valley
    // x_{i+1} = 2x_i² − 1 linearly and slowly (about a decade of f per 10⁴ iterations at n = 4)
    // while it approaches the kinks much faster, so it sits on them to rounding level
    // (cond(H) ≈ 1e17) after a few thousand iterations and stops with NotDescent or
    // LineSearchFailed. The floor keeps H positive definite and the iterates just off the kinks;
    // n = 4 then takes 3–6·10⁴ iterations per start.
    for n in 2..=4 {
        let mut obj = ChebyshevRosenbrock { n };
        let mut opts = hanso_opts(1e-8, 1e-6, 100_000, true);
        opts.bfgs.h_floor = Some(1e-14);
        let r = run_hanso(&mut obj, 3, &opts, 1);
        show(&format!("chebyshev-rosenbrock n={n}"), &r.best);
        assert!(r.best.f <= 1e-8, "n={n}: f = {:e}", r.best.f);
        // f ≤ 1e-8 ⇒ |x₁ − 1| ≤ 2e-4, and along the valley x_{k+1} − 1 ≈ 4(x_k − 1).
        for (k, v) in r.best.x.iter().enumerate() {
            let tol = 3e-4 * 4f64.powi(k as i32);
            assert!((v - 1.0).abs() <= tol, "n={n}: |x_{} - 1| = {:e} > {tol:e}", k + 1, (v - 1.0).abs());
        }
        assert!(r.gradient_sampling.is_some());
        assert_certificate(&r.best, 1e-4, 1e-4);
    }
}

#[test]
fn chebyshev_rosenbrock_n4_needs_the_h_floor() {
    // HANSO's BFGS as published (no floor) on the same starts stalls far from the minimiser,
    // whatever the iteration limit: this is what h_floor is for.
    let mut obj = ChebyshevRosenbrock { n: 4 };
    let r = run_hanso(&mut obj, 3, &hanso_opts(1e-8, 1e-6, 100_000, false), 1);
    show("chebyshev-rosenbrock n=4, no floor", &r.best);
    assert!(r.best.f > 1e-6, "f = {:e}", r.best.f);
    for s in r.starts.iter().map(|s| s.as_ref().unwrap()) {
        assert!(
            matches!(s.termination, Termination::NotDescent | Termination::LineSearchFailed),
            "{:?}",
            s.termination
        );
        assert!(s.iters < 50_000, "{} iterations", s.iters);
    }
}

#[test]
fn chebyshev_rosenbrock_larger_n_makes_progress() {
    // n = 5…10: BFGS from randn starts; the function gets much harder with n
    // (Gurbuzbalaban & Overton 2012). Assert a large decrease and a finite certificate.
    for n in 5..=10 {
        let mut obj = ChebyshevRosenbrock { n };
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let starts = random_starts(n, 3, &mut rng);
        let mut g = vec![0.0; n];
        let f0 = starts.iter().map(|x| obj.eval(x, &mut g)).fold(f64::INFINITY, f64::min);
        let opts = hanso_opts(1e-8, 1e-6, 3000, false);
        let ctl = RunControl::new(f64::INFINITY);
        let r = hanso(&mut obj, &starts, &opts, &mut rng, &ctl, &mut NoObserver).unwrap();
        show(&format!("chebyshev-rosenbrock n={n} (f0 {f0:.2e})"), &r.best);
        assert!(r.best.f <= 0.5 && r.best.f <= 0.2 * f0, "n={n}: f = {:e} from {f0:e}", r.best.f);
        assert_certificate(&r.best, 20.0, 1.0);
    }
}

#[test]
fn max_of_quadratics_and_l1_reach_zero() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    for n in [2usize, 5, 10] {
        let mut mq = MaxQuad::random(n, &mut rng);
        // evaldist bounds the distance to the minimiser at which the certificate can fire, and
        // f is Lipschitz: a tight evaldist is needed for f ≤ 1e-8.
        let r = run_hanso(&mut mq, 3, &hanso_opts(1e-8, 1e-10, 1000, false), 4);
        show(&format!("max-quad n={n}"), &r.best);
        assert!(r.best.f <= 1e-8 && r.best.f >= -1e-12, "maxquad n={n}: f = {:e}", r.best.f);
        assert!(norm(&r.best.x) <= 1e-4);
        assert_certificate(&r.best, 1e-6, 1e-6);

        let mut l1 = L1Norm::random(n, &mut rng);
        let r = run_hanso(&mut l1, 3, &hanso_opts(1e-8, 1e-10, 1000, false), 5);
        show(&format!("l1 n={n}"), &r.best);
        assert!(r.best.f <= 1e-8, "l1 n={n}: f = {:e}", r.best.f);
        assert_certificate(&r.best, 1e-6, 1e-6);
    }
}

#[test]
fn smooth_rosenbrock_converges_superlinearly() {
    let mut obj = Rosenbrock { n: 2 };
    let opts = BfgsOptions { normtol: 1e-13, evaldist: 0.0, ..Default::default() };
    let ctl = RunControl::new(f64::INFINITY);
    let mut errs = vec![];
    let mut ob = FnObserver(|r: &IterRecord<'_>| {
        errs.push(r.x.iter().map(|v| (v - 1.0).powi(2)).sum::<f64>().sqrt());
        ControlFlow::Continue(())
    });
    let r = bfgs(&mut obj, &[-1.2, 1.0], 0, &opts, &ctl, &mut ob).unwrap();
    show("rosenbrock", &r);
    assert!(r.f <= 1e-20, "f = {:e}", r.f);
    assert_eq!(r.termination, Termination::Certified);
    assert!(r.dnorm <= 1e-13);
    // Error ratios over the iterations with 1e-12 < e_k < 1e-2 must tend to 0.
    let ratios: Vec<f64> = errs.windows(2).filter(|w| w[0] < 1e-2 && w[0] > 1e-12).map(|w| w[1] / w[0]).collect();
    println!("error ratios near the solution: {ratios:?}");
    assert!(ratios.len() >= 3);
    let tail = &ratios[ratios.len() - 3..];
    assert!(tail.iter().all(|&q| q < 0.2), "not superlinear: {ratios:?}");
    assert!(*tail.last().unwrap() < 0.05, "not superlinear: {ratios:?}");
}

#[test]
fn max_eigenvalue_of_affine_family() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    for n in [2usize, 4] {
        let mut obj = MaxEigenvalue::random(n, &mut rng);
        let r = run_hanso(&mut obj, 3, &hanso_opts(1e-8, 1e-10, 1000, true), 12);
        show(&format!("max-eig n={n}"), &r.best);
        assert!((r.best.f - 1.0).abs() <= 1e-8, "n={n}: f - f* = {:e}", r.best.f - 1.0);
        assert!(norm(&r.best.x) <= 1e-4, "n={n}: |x| = {:e}", norm(&r.best.x));
        assert_certificate(&r.best, 1e-3, 1e-2);
    }
}

#[test]
fn infinite_outside_region_backs_off() {
    let n = 4;
    let mut obj = Walled::new(n);
    let ctl = RunControl::new(f64::INFINITY);
    let mut fs = vec![];
    let mut ob = FnObserver(|r: &IterRecord<'_>| {
        fs.push(r.f);
        ControlFlow::Continue(())
    });
    let opts = BfgsOptions { normtol: 1e-8, ..Default::default() };
    let r = bfgs(&mut obj, &vec![0.0; n], 0, &opts, &ctl, &mut ob).unwrap();
    show("walled", &r);
    assert!(obj.infinite_evals > 0, "the test never left the domain");
    assert!(fs.iter().all(|f| f.is_finite()), "an infinite value was accepted");
    assert!(fs.windows(2).all(|w| w[1] <= w[0]), "f increased");
    assert!(r.f <= 1e-8, "f = {:e}", r.f);
    let err = r.x.iter().zip(&obj.c).map(|(a, b)| (a - b).abs()).fold(0.0, f64::max);
    assert!(err <= 1e-6, "x - c = {err:e}");
    assert_certificate(&r, 1e-3, 1e-3);
}

#[test]
fn same_seed_same_path_bitwise() {
    let path = |seed: u64| {
        let mut obj = ChebyshevRosenbrock { n: 3 };
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let starts = random_starts(3, 2, &mut rng);
        let ctl = RunControl::new(f64::INFINITY);
        let mut trace: Vec<u64> = vec![];
        let mut ob = FnObserver(|r: &IterRecord<'_>| {
            trace.push(r.f.to_bits());
            trace.push(r.dnorm.to_bits());
            trace.extend(r.x.iter().map(|v| v.to_bits()));
            ControlFlow::Continue(())
        });
        let mut opts = hanso_opts(1e-8, 1e-6, 500, true);
        opts.gradsamp.maxit = 200;
        let r = hanso(&mut obj, &starts, &opts, &mut rng, &ctl, &mut ob).unwrap();
        assert!(r.gradient_sampling.as_ref().is_some_and(|g| g.iters > 0));
        (trace, r.best.f.to_bits(), r.evals)
    };
    let a = path(5);
    let b = path(5);
    assert!(a.0.len() > 1000);
    assert_eq!(a, b);
    let c = path(6);
    assert_ne!(a.0, c.0);
}

#[test]
fn observer_break_interrupts() {
    let mut obj = Rosenbrock { n: 4 };
    let ctl = RunControl::new(f64::INFINITY);
    let mut seen = 0;
    let mut ob = FnObserver(|r: &IterRecord<'_>| {
        seen += 1;
        if r.iter == 5 {
            ControlFlow::Break(())
        } else {
            ControlFlow::Continue(())
        }
    });
    let r = bfgs(&mut obj, &[-1.2, 1.0, -1.2, 1.0], 0, &BfgsOptions::default(), &ctl, &mut ob).unwrap();
    assert_eq!(r.termination, Termination::Interrupted);
    assert_eq!(r.iters, 5);
    assert_eq!(seen, 6);
    // hanso: the break ends the whole run; later starts are NotRun.
    let starts = vec![vec![-1.2, 1.0, -1.2, 1.0]; 3];
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let mut ob =
        FnObserver(|r: &IterRecord<'_>| if r.iter == 3 { ControlFlow::Break(()) } else { ControlFlow::Continue(()) });
    let h = hanso(&mut obj, &starts, &hanso_opts(1e-6, 1e-4, 100, true), &mut rng, &ctl, &mut ob).unwrap();
    assert_eq!(h.best.termination, Termination::Interrupted);
    assert!(matches!(h.starts[1], Err(OptimError::NotRun { reason: Termination::Interrupted })));
    assert!(h.gradient_sampling.is_none());
    // Cancel flag set beforehand: stops at the starting point.
    let flag = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(true));
    let ctl = RunControl::new(f64::INFINITY).with_cancel(flag);
    let r = bfgs(&mut obj, &[-1.2, 1.0, -1.2, 1.0], 0, &BfgsOptions::default(), &ctl, &mut NoObserver).unwrap();
    assert_eq!((r.termination, r.iters, r.evals), (Termination::Interrupted, 0, 1));
}

#[test]
fn non_finite_start_is_rejected() {
    let mut obj = Walled::new(2);
    let ctl = RunControl::new(f64::INFINITY);
    let e = bfgs(&mut obj, &[2.0, 0.0], 0, &BfgsOptions::default(), &ctl, &mut NoObserver).unwrap_err();
    assert_eq!(e, OptimError::NonFiniteStart { f: f64::INFINITY });
    assert!(e.to_string().contains("not finite"));
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let starts = vec![vec![2.0, 0.0], vec![0.0, 0.0]];
    let h = hanso(&mut obj, &starts, &HansoOptions::default(), &mut rng, &ctl, &mut NoObserver).unwrap();
    assert!(matches!(h.starts[0], Err(OptimError::NonFiniteStart { .. })));
    assert_eq!(h.best_start, 1);
    assert!(h.best.f < 1e-8);
    let e = hanso(&mut obj, &[vec![5.0, 5.0]], &HansoOptions::default(), &mut rng, &ctl, &mut NoObserver).unwrap_err();
    assert!(matches!(e, OptimError::NonFiniteStart { .. }));
    let e = bfgs(&mut obj, &[0.0; 3], 0, &BfgsOptions::default(), &ctl, &mut NoObserver).unwrap_err();
    assert!(matches!(e, OptimError::DimensionMismatch { expected: 2, got: 3, .. }));
}

#[test]
fn cpu_budget_is_honoured_within_one_evaluation() {
    // Each evaluation burns about 2 ms of CPU.
    let mut obj = FnObjective::new(4, |x: &[f64], g: &mut [f64]| {
        let t0 = thread_cpu_time();
        let mut acc = 0.0_f64;
        while thread_cpu_time() - t0 < 2e-3 {
            acc += 1e-9;
        }
        let mut cr = ChebyshevRosenbrock { n: 4 };
        cr.eval(x, g) + acc * 0.0
    });
    let cpumax = 0.05;
    let ctl = RunControl::new(cpumax);
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    let starts = random_starts(4, 3, &mut rng);
    let h = hanso(&mut obj, &starts, &hanso_opts(1e-12, 1e-6, 100_000, true), &mut rng, &ctl, &mut NoObserver).unwrap();
    let used = ctl.cpu_elapsed();
    println!("cpu budget {cpumax}: used {used:.4}, evals {}", h.evals);
    assert_eq!(h.best.termination, Termination::CpuBudget);
    assert!(used <= cpumax + 0.01, "used {used}");
    assert!(matches!(h.starts[2], Err(OptimError::NotRun { reason: Termination::CpuBudget })));
}

#[test]
fn options_are_validated() {
    let bad = [
        BfgsOptions { wolfe2: 1e-5, ..Default::default() },
        BfgsOptions { normtol: -1.0, ..Default::default() },
        BfgsOptions { ngrad: Some(0), ..Default::default() },
        BfgsOptions { fvalquit: f64::NAN, ..Default::default() },
        BfgsOptions { h_floor: Some(0.0), ..Default::default() },
        BfgsOptions { h_floor: Some(f64::NAN), ..Default::default() },
    ];
    for o in bad {
        assert!(matches!(o.validate(), Err(OptimError::Options { .. })), "{o:?}");
    }
    assert!(BfgsOptions::default().validate().is_ok());
    assert!(GradSampOptions::default().validate().is_ok());
    assert!(GradSampOptions { samprad_factor: 1.5, ..Default::default() }.validate().is_err());
    assert_eq!(BfgsOptions::default().ngrad_for(5), 10);
    assert_eq!(BfgsOptions::default().ngrad_for(200), 100);
    let s = serde_json::to_string(&Termination::GradSampConverged).unwrap();
    assert_eq!(s, "\"grad_samp_converged\"");
}

/// w·‖x − c‖₁ with a small weight w; `in_units` says whether it reports w as its gradient unit.
struct WeightedL1 {
    c: Vec<f64>,
    w: f64,
    in_units: bool,
}

impl Objective for WeightedL1 {
    fn nvar(&self) -> usize {
        self.c.len()
    }
    fn eval(&mut self, x: &[f64], g: &mut [f64]) -> f64 {
        for ((gi, xi), ci) in g.iter_mut().zip(x).zip(&self.c) {
            *gi = self.w * (xi - ci).signum();
        }
        self.w * x.iter().zip(&self.c).map(|(xi, ci)| (xi - ci).abs()).sum::<f64>()
    }
    fn gradient_unit(&self, _x: &[f64]) -> f64 {
        if self.in_units {
            self.w
        } else {
            1.0
        }
    }
}

#[test]
fn a_small_weight_does_not_certify_a_point_when_gradients_are_taken_in_their_unit() {
    // ‖∇f‖ = w·√n = 4.5e-4 < normtol everywhere off the kinks: HANSO's absolute certificate
    // stops at the start; in the term's own unit the gradients have norm √n, and only the kink
    // at c (where their hull holds 0) certifies.
    let (n, w) = (5, 2e-4);
    let c: Vec<f64> = (0..n).map(|i| 0.3 * i as f64 - 0.5).collect();
    let x0 = vec![1.0; n];
    let opts = hanso_opts(1e-3, 1e-3, 1000, false);
    let run = |in_units: bool| {
        let mut obj = WeightedL1 { c: c.clone(), w, in_units };
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let ctl = RunControl::new(f64::INFINITY);
        hanso(&mut obj, std::slice::from_ref(&x0), &opts, &mut rng, &ctl, &mut NoObserver).expect("finite start").best
    };
    let f0 = WeightedL1 { c: c.clone(), w, in_units: false }.eval(&x0, &mut vec![0.0; n]);
    let absolute = run(false);
    show("weighted l1, absolute", &absolute);
    assert_eq!(absolute.termination, Termination::Certified);
    assert_eq!(absolute.f, f0, "certified at the start");
    let in_units = run(true);
    show("weighted l1, in units", &in_units);
    assert!(in_units.f <= 1e-3 * f0, "f = {:e} from {f0:e}", in_units.f);
    assert!(in_units.dnorm <= 1e-3, "the certificate is in the term's unit: dnorm {:e}", in_units.dnorm);
}

/// `restart_every`: a run no longer than the period is the run without restarts, bit for bit; a
/// restart sets H back to I, so with a period of 1 every step is along −∇f (steepest descent),
/// which plain BFGS's steps are not; and a restarted run still reaches the nonsmooth minimiser of
/// a max of quadratics.
#[test]
fn restarts_set_the_inverse_hessian_back_to_the_identity() {
    let ctl = RunControl::new(f64::INFINITY);
    let path = |restart_every: usize, maxit: usize| {
        let mut obj = Rosenbrock { n: 2 };
        let opts = BfgsOptions { normtol: 1e-13, evaldist: 0.0, maxit, restart_every, ..Default::default() };
        let mut xs: Vec<Vec<f64>> = vec![];
        let mut ob = FnObserver(|r: &IterRecord<'_>| {
            xs.push(r.x.to_vec());
            ControlFlow::Continue(())
        });
        let r = bfgs(&mut obj, &[-1.2, 1.0], 0, &opts, &ctl, &mut ob).unwrap();
        (xs, r.f.to_bits())
    };
    assert_eq!(path(0, 20), path(20, 20), "no restart within the period");
    assert_ne!(path(0, 21).0, path(20, 21).0, "a restart before iteration 21");
    // cos ∠(x_{k+1} − x_k, −∇f(x_k)) for every step of a run
    let cosines = |xs: &[Vec<f64>]| -> Vec<f64> {
        let mut obj = Rosenbrock { n: 2 };
        let mut g = vec![0.0; 2];
        xs.windows(2)
            .filter(|w| w[1] != w[0])
            .map(|w| {
                obj.eval(&w[0], &mut g);
                let s: Vec<f64> = (0..2).map(|i| w[1][i] - w[0][i]).collect();
                -crate::numeric::dot(&s, &g) / (norm(&s) * norm(&g))
            })
            .collect()
    };
    let steepest = cosines(&path(1, 50).0);
    assert!(steepest.len() >= 40 && steepest.iter().all(|c| *c > 1.0 - 1e-12), "{steepest:?}");
    let plain = cosines(&path(0, 50).0);
    assert!(plain.iter().any(|c| *c < 0.99), "{plain:?}");

    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let mut mq = MaxQuad::random(10, &mut rng);
    let mut opts = hanso_opts(1e-8, 1e-10, 3000, false);
    opts.bfgs.restart_every = 100;
    let r = run_hanso(&mut mq, 3, &opts, 4);
    show("max-quad n=10, restart every 100", &r.best);
    assert!(r.best.f <= 1e-6 && r.best.f >= -1e-12, "f = {:e}", r.best.f);
}
