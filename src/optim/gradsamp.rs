//! Gradient sampling: "Algorithm GS" of Burke, Curtis, Lewis, Overton and Simões (2020),
//! "Gradient sampling methods for nonsmooth optimization" (in Numerical Nonsmooth Optimization,
//! Springer), the variant of HANSO 3.0 (docs/ALGORITHMS.md §7.4).
//!
//! At iteration k, with sampling radius ρ and stationarity target ν (the literature's ε, renamed
//! so that ε keeps one meaning in the project, docs/ARCHITECTURE.md §5):
//!
//! 1. sample m points uniformly in the Euclidean ball B(x, ρ) (direction u/‖u‖ with u ~ N(0, I),
//!    radius ρ·U^{1/n}, U ~ U[0, 1]); G = [∇f(x), ∇f(x₁), …, ∇f(x_m)];
//! 2. d = the min-norm element of conv G (the simplex QP, [`qp`](super::qp)), an approximation of
//!    the min-norm element of the Clarke ρ-subdifferential;
//! 3. if ‖d‖ ≤ ν_opt and ρ ≤ ρ_opt: stop (`GradSampConverged`);
//! 4. if ‖d‖ ≤ ν: ν ← θ_ν ν, ρ ← θ_ρ ρ, no step;
//! 5. else backtrack from t = 1 along −d (unnormalised) until
//!    f(x − t d) < f(x) − β t ‖d‖², t ← γ t; give up (`LineSearchFailed`) when
//!    t < 10⁻¹⁶·max(‖x‖, 1)/‖d‖; stop (`NotDescent`) if ∇f(x)ᵀd ≤ 0.
//!
//! Under mild assumptions the limit points are Clarke stationary with probability one (BCLOS 2020).
//! A sample where f or ∇f is not finite (outside the domain) is pulled halfway towards x, up to
//! [`GS_MAX_CONTRACT`] times (the HANSO 2.0 rule), and dropped if still outside.
//!
//! # Deviation
//! BCLOS's Algorithm GS perturbs x_{k+1} if f is not differentiable there (a probability-zero
//! event, checked only in theory); this is omitted, as in practical implementations.
//! The certificate returned is the one of [`bundle::certificate_at`](super::bundle) at the final x.

use super::bundle::certificate_at;
use super::control::RunControl;
use super::error::OptimError;
use super::objective::{usable, Evaluator, Objective};
use super::observer::{Observer, SolverKind};
use super::options::GradSampOptions;
use super::qp::min_norm_in_hull;
use super::solver::{run, solver_state, Limits, OptimResult, Solver};
use super::termination::Termination;
use crate::numeric::dot;
use rand::{Rng, RngCore};
use rand_distr::{Distribution, StandardNormal};

/// Maximum number of halvings of a sample's offset when f or ∇f is not finite there.
pub const GS_MAX_CONTRACT: usize = 100;
/// Backtracking gives up when t < GS_MIN_STEP_REL·max(‖x‖, 1)/‖d‖ (x would no longer change).
pub const GS_MIN_STEP_REL: f64 = 1e-16;

/// The state of a gradient-sampling run.
#[derive(Debug, Clone)]
pub struct GradSampState {
    /// Current point.
    pub x: Vec<f64>,
    /// f(x).
    pub f: f64,
    /// ∇f(x).
    pub g: Vec<f64>,
    /// Current sampling radius ρ.
    pub sampling_radius: f64,
    /// Current stationarity target ν.
    pub nu: f64,
    /// ‖d‖ of the last sampled bundle.
    pub dnorm: f64,
    /// Points and gradients of the last sampled bundle, and the gradients' units
    /// ([`Objective::gradient_unit`], for the certificate only).
    xs: Vec<Vec<f64>>,
    gs: Vec<Vec<f64>>,
    units: Vec<f64>,
}

solver_state!(GradSampState);

pub(crate) struct GradSamp<'a> {
    pub(crate) opts: &'a GradSampOptions,
    pub(crate) rng: &'a mut dyn RngCore,
}

impl GradSamp<'_> {
    /// A point uniformly distributed in the ball B(x, radius).
    fn sample_ball(&mut self, x: &[f64], radius: f64) -> Vec<f64> {
        let n = x.len();
        let mut u: Vec<f64> = (0..n).map(|_| StandardNormal.sample(&mut *self.rng)).collect();
        let un = dot(&u, &u).sqrt();
        let r = radius * self.rng.random::<f64>().powf(1.0 / n as f64);
        let c = if un > 0.0 { r / un } else { 0.0 };
        for (ui, xi) in u.iter_mut().zip(x) {
            *ui = xi + c * *ui;
        }
        u
    }
}

impl Solver for GradSamp<'_> {
    type State = GradSampState;
    const KIND: SolverKind = SolverKind::GradientSampling;

    fn limits(&self) -> Limits {
        Limits { maxit: self.opts.maxit, fvalquit: self.opts.fvalquit, xnormquit: f64::INFINITY }
    }

    fn init(&mut self, ev: &mut Evaluator<'_>, x0: &[f64]) -> Result<GradSampState, OptimError> {
        let mut g = vec![0.0; x0.len()];
        let f = ev.eval(x0, &mut g);
        if !usable(f, &g) || x0.iter().any(|v| !v.is_finite()) {
            return Err(OptimError::NonFiniteStart { f });
        }
        let dnorm = dot(&g, &g).sqrt();
        Ok(GradSampState {
            x: x0.to_vec(),
            f,
            g: g.clone(),
            sampling_radius: self.opts.samprad0,
            nu: self.opts.target0,
            dnorm,
            xs: vec![x0.to_vec()],
            gs: vec![g],
            units: vec![ev.gradient_unit(x0)],
        })
    }

    fn step(&mut self, ev: &mut Evaluator<'_>, s: &mut GradSampState) -> Result<f64, Termination> {
        let n = s.x.len();
        let m = self.opts.ngrad_for(n);
        let mut xs = vec![s.x.clone()];
        let mut gs = vec![s.g.clone()];
        let mut units = vec![ev.gradient_unit(&s.x)];
        let mut gj = vec![0.0; n];
        for _ in 0..m {
            let mut xj = self.sample_ball(&s.x, s.sampling_radius);
            let mut ok = false;
            for _ in 0..=GS_MAX_CONTRACT {
                let fj = ev.eval_checked(&xj, &mut gj)?;
                if usable(fj, &gj) {
                    ok = true;
                    break;
                }
                for (a, b) in xj.iter_mut().zip(&s.x) {
                    *a = 0.5 * (*a + b);
                }
            }
            if ok {
                units.push(ev.gradient_unit(&xj));
                xs.push(xj);
                gs.push(gj.clone());
            }
        }
        let cols: Vec<&[f64]> = gs.iter().map(|v| v.as_slice()).collect();
        let qp = min_norm_in_hull(&cols);
        s.dnorm = qp.dnorm;
        s.xs = xs;
        s.gs = gs;
        s.units = units;
        let d = qp.d;
        let dn = qp.dnorm;
        if dn <= self.opts.target_opt && s.sampling_radius <= self.opts.samprad_opt {
            return Err(Termination::GradSampConverged);
        }
        if dn <= s.nu {
            s.nu *= self.opts.target_factor;
            s.sampling_radius *= self.opts.samprad_factor;
            return Ok(0.0);
        }
        if !(dot(&s.g, &d) > 0.0) {
            return Err(Termination::NotDescent);
        }
        let xnorm = dot(&s.x, &s.x).sqrt();
        let tmin = GS_MIN_STEP_REL * xnorm.max(1.0) / dn;
        let mut t = 1.0_f64;
        let mut xt = vec![0.0; n];
        let mut gt = vec![0.0; n];
        loop {
            for i in 0..n {
                xt[i] = s.x[i] - t * d[i];
            }
            let ft = ev.eval_checked(&xt, &mut gt)?;
            if usable(ft, &gt) && (ft < self.opts.fvalquit || ft < s.f - self.opts.armijo * t * dn * dn) {
                s.x = xt;
                s.f = ft;
                s.g = gt;
                return Ok(t);
            }
            t *= self.opts.backtrack;
            if t < tmin {
                return Err(Termination::LineSearchFailed);
            }
        }
    }

    fn converged(&self, _s: &GradSampState, _initial: bool) -> Option<Termination> {
        None
    }

    fn result(&self, ev: &mut Evaluator<'_>, s: GradSampState, termination: Termination, iters: usize) -> OptimResult {
        let unit = ev.gradient_unit(&s.x);
        let (dnorm, evaldist) = certificate_at((&s.x, &s.g, unit), &s.xs, &s.gs, &s.units);
        OptimResult {
            x: s.x,
            f: s.f,
            g: s.g,
            dnorm,
            evaldist,
            termination,
            iters,
            evals: ev.evals,
            cpu_s: ev.ctl.cpu_elapsed(),
        }
    }
}

/// Gradient sampling from x0 (typically the best BFGS point). All randomness comes from `rng`.
pub fn gradient_sampling(
    obj: &mut dyn Objective,
    x0: &[f64],
    opts: &GradSampOptions,
    rng: &mut dyn RngCore,
    ctl: &RunControl,
    obs: &mut dyn Observer,
) -> Result<OptimResult, OptimError> {
    opts.validate()?;
    run(&mut GradSamp { opts, rng }, obj, x0, 0, ctl, obs)
}
