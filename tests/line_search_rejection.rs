//! `Objective::eval_below`: an objective may reject a line-search trial point by a
//! lower bound that already fails the Armijo condition. The rejection must be exact — the
//! optimiser takes bit-for-bit the same path as with the full evaluation — and it must happen.

use hinfix::optim::test_problems::MaxQuad;
use hinfix::optim::{
    hanso, random_starts, BfgsOptions, GradSampOptions, HansoOptions, NoObserver, Objective, RunControl,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

/// MaxQuad whose `eval_below` returns a valid lower bound (f itself, rounded down to a
/// multiple of 1e-3, which is ≤ f) when that bound reaches the threshold.
struct Bounded {
    inner: MaxQuad,
    rejected: usize,
    full: usize,
}

impl Objective for Bounded {
    fn nvar(&self) -> usize {
        self.inner.nvar()
    }
    fn eval(&mut self, x: &[f64], g: &mut [f64]) -> f64 {
        self.full += 1;
        self.inner.eval(x, g)
    }
    fn eval_below(&mut self, x: &[f64], g: &mut [f64], threshold: f64) -> f64 {
        let mut scratch = vec![0.0; x.len()];
        let lb = (self.inner.eval(x, &mut scratch) * 1e3).floor() / 1e3;
        if lb >= threshold {
            self.rejected += 1;
            g.iter_mut().for_each(|v| *v = f64::NAN);
            return lb;
        }
        self.eval(x, g)
    }
}

#[test]
fn lower_bound_rejection_is_exact_and_used() {
    let opts = HansoOptions {
        bfgs: BfgsOptions { normtol: 1e-8, evaldist: 1e-6, maxit: 300, ..Default::default() },
        gradsamp: GradSampOptions::default(),
        gradient_sampling: false,
    };
    let problem = MaxQuad::random(6, &mut ChaCha8Rng::seed_from_u64(3));
    let run = |obj: &mut dyn Objective| {
        let mut rng = ChaCha8Rng::seed_from_u64(4);
        let starts = random_starts(obj.nvar(), 2, &mut rng);
        hanso(obj, &starts, &opts, &mut rng, &RunControl::new(f64::INFINITY), &mut NoObserver).unwrap()
    };
    let mut plain = problem.clone();
    let a = run(&mut plain);
    let mut bounded = Bounded { inner: problem, rejected: 0, full: 0 };
    let b = run(&mut bounded);
    assert_eq!(a.best.x, b.best.x, "same path");
    assert_eq!(a.best.f.to_bits(), b.best.f.to_bits());
    assert_eq!(a.evals, b.evals);
    assert!(bounded.rejected > 0, "no trial point was rejected by its bound");
    assert_eq!(bounded.rejected + bounded.full, b.evals);
}

/// The screen's frequency-response evaluator, reused by the norm of the same closed loop
/// (`lti::ResponseSlot`), gives bit for bit the norm and gradient of a fresh one, and saves the
/// second Hessenberg reduction; a slot holding another closed loop is not used.
#[test]
fn screened_evaluator_reuse_is_exact() {
    use hinfix::lti::step_stats::{self, Step};
    use hinfix::lti::{
        closed_loop, closed_loop_hinf_grad, hinf_lower_bound_sharing, resolve_plant, Controller, HinfParams, Plant,
        ResponseSlot,
    };
    let plant = resolve_plant("CM4").and_then(Plant::load).unwrap();
    let d = plant.dims;
    let mut k = Controller::zeros(1, d.m2, d.p2);
    k.ak[(0, 0)] = -2.0;
    k.bk[(0, 0)] = 0.01;
    let mut other = k.clone();
    other.ak[(0, 0)] = -3.0;
    let hint = [0.7];
    let fresh = closed_loop_hinf_grad(&plant, &k, &HinfParams::default().with_hints(&hint)).unwrap();
    assert!(fresh.0.value.is_finite(), "the test loop must be stable");
    for screened in [&k, &other] {
        let slot = ResponseSlot::default();
        let cl = closed_loop(&plant, screened).unwrap();
        assert!(cl.order() >= 30, "the large-order path");
        let lb = hinf_lower_bound_sharing(&cl, &hint, f64::INFINITY, &slot);
        step_stats::reset();
        let shared =
            closed_loop_hinf_grad(&plant, &k, &HinfParams::default().with_hints(&hint).with_reuse(&slot)).unwrap();
        let reductions = step_stats::snapshot().calls(Step::Hessenberg, true);
        assert_eq!(reductions, u64::from(!std::ptr::eq(screened, &k)), "Hessenberg reductions of the norm");
        assert_eq!(shared.0.value.to_bits(), fresh.0.value.to_bits());
        assert_eq!(shared.0.peak_freq.to_bits(), fresh.0.peak_freq.to_bits());
        assert_eq!(shared.1, fresh.1);
        if std::ptr::eq(screened, &k) {
            assert!(lb <= shared.0.value);
        }
    }
}

/// `closed_loop_hinf_grad` with a level, `HinfParams::enough` (the norm of a trial point that passed the screen): with the
/// level above the norm it gives bit for bit the full norm and gradient; with a level below the
/// norm it stops at an attained value that reaches the level, at most the norm, with no gradient
/// and (the level being below the scan's best) no level-set test.
#[test]
fn norm_stopping_at_a_level_is_exact_or_a_bound() {
    use hinfix::lti::step_stats::{self, Step};
    use hinfix::lti::{closed_loop_hinf_grad, resolve_plant, Controller, HinfParams, Plant, ResponseSlot};
    let plant = resolve_plant("CM4").and_then(Plant::load).unwrap();
    let d = plant.dims;
    let mut k = Controller::zeros(1, d.m2, d.p2);
    k.ak[(0, 0)] = -2.0;
    k.bk[(0, 0)] = 0.01;
    let hint = [0.7];
    let (norm, grad) = closed_loop_hinf_grad(&plant, &k, &HinfParams::default().with_hints(&hint)).unwrap();
    assert!(norm.value.is_finite(), "the test loop must be stable");
    let unless = |enough: f64| {
        let slot = ResponseSlot::default();
        closed_loop_hinf_grad(
            &plant,
            &k,
            &HinfParams::default().with_hints(&hint).with_enough(enough).with_reuse(&slot),
        )
        .unwrap()
    };
    let above = unless(norm.value * (1.0 + 1e-9));
    assert_eq!(above.0.value.to_bits(), norm.value.to_bits());
    assert_eq!(above.1, grad);
    step_stats::reset();
    let below = unless(0.5 * norm.value);
    let tests = step_stats::snapshot().calls(Step::ExplicitLevelSet, true)
        + step_stats::snapshot().calls(Step::PencilLevelSet, true);
    assert!(
        below.0.value >= 0.5 * norm.value && below.0.value <= norm.value,
        "{} against {}",
        below.0.value,
        norm.value
    );
    assert!(below.1.dk[(0, 0)].is_nan(), "no gradient for a rejected point");
    assert_eq!(tests, 0, "no level-set test once the scan reached the level");
}
