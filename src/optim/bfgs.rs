//! BFGS for nonsmooth functions (Lewis & Overton 2013, "Nonsmooth optimization via quasi-Newton
//! methods", Math. Program. 141; HANSO 2.x `bfgs1run`, docs/ALGORITHMS.md §7.1).
//!
//! Iteration k, with H ≈ (∇²f)⁻¹ the inverse-Hessian approximation (H₀ = I):
//!
//! 1. p = −H g; stop (`NotDescent`) unless gᵀp < 0.
//! 2. Weak-Wolfe line search along p ([`linesearch`](super::linesearch)), t = 1 first.
//! 3. Gradient bundle ([`bundle`](super::bundle)): reset if t‖p‖ > evaldist, else prepend ∇f;
//!    dnorm = ‖min-norm element of the hull‖.
//! 4. s = t p, y = g⁺ − g. If sᵀy > 0: on the first iteration H ← (sᵀy/yᵀy) H (scaling), then
//!    H⁺ = H − ρ(H y sᵀ + s yᵀ H) + (ρ² yᵀHy + ρ) s sᵀ, ρ = 1/sᵀy (the explicitly symmetric form of
//!    (I − ρsyᵀ)H(I − ρysᵀ) + ρssᵀ). If sᵀy ≤ 0 the update is **skipped** (only happens after a
//!    failed line search; HANSO); so is an update that would produce a non-finite H (GRANSO).
//!    Optional GRANSO-style damping (Curtis, Mitchell & Overton 2017), off by default; optional relative
//!    eigenvalue floor H ← H + δ·maxᵢHᵢᵢ·I (`h_floor`), off by default.
//!
//! With `restart_every` = R > 0 (not in HANSO), H is set back to I, unscaled, before iterations
//! R + 1, 2R + 1, …; the run keeps its point and its gradient bundle. (Scaling the reset H by
//! sᵀy/yᵀy, as the first update does, undid the gain: near a kink y is a jump of the gradient,
//! the scale is tiny and the steps crawl again; docs/ALGORITHMS.md §7.1.)
//!
//! Termination tests, in HANSO's order: f < fvalquit, ‖x‖ > xnormquit, line search bracketed but
//! failed (the usual end at a nonsmooth minimiser, where H becomes very ill conditioned), line
//! search never bracketed (unbounded), dnorm ≤ normtol, CPU budget, maxit; then the observer
//! and the cancel flag. On nonsmooth problems BFGS typically converges linearly, on smooth ones
//! superlinearly.
//!
//! Hand-written: no Rust crate offers BFGS with a weak-Wolfe search tolerant of +∞ values and the
//! gradient-bundle certificate.

use super::bundle::GradBundle;
use super::control::RunControl;
use super::error::OptimError;
use super::linesearch::{weak_wolfe, LsParams, LsStatus};
use super::objective::{usable, Evaluator, Objective};
use super::observer::{Observer, SolverKind};
use super::options::BfgsOptions;
use super::solver::{run, solver_state, Limits, OptimResult, Solver};
use super::termination::Termination;
use crate::numeric::dot;

/// The state of a BFGS run.
#[derive(Debug, Clone)]
pub struct BfgsState {
    /// Current point.
    pub x: Vec<f64>,
    /// f(x).
    pub f: f64,
    /// ∇f(x).
    pub g: Vec<f64>,
    /// Inverse-Hessian approximation, row-major n × n, symmetric.
    pub h: Vec<f64>,
    /// Certificate norm of the current bundle.
    pub dnorm: f64,
    /// Last step length.
    pub t: f64,
    /// Iterations done.
    pub iter: usize,
    /// How the last line search ended.
    pub(crate) ls: LsStatus,
    pub(crate) bundle: GradBundle,
    /// Number of BFGS updates skipped because sᵀy ≤ 0 or H would be non-finite.
    pub skipped_updates: usize,
}

solver_state!(BfgsState);

pub(crate) struct Bfgs<'o> {
    pub(crate) opts: &'o BfgsOptions,
}

/// The n × n identity, row-major: H₀, and H after a restart.
fn identity(n: usize) -> Vec<f64> {
    let mut h = vec![0.0; n * n];
    (0..n).for_each(|i| h[i * n + i] = 1.0);
    h
}

fn symv(h: &[f64], v: &[f64]) -> Vec<f64> {
    let n = v.len();
    (0..n).map(|i| dot(&h[i * n..(i + 1) * n], v)).collect()
}

impl BfgsState {
    /// H ← I (a restart, `BfgsOptions::restart_every`).
    fn restart(&mut self) {
        self.h = identity(self.x.len());
    }

    /// The BFGS update with s, y (and Bs for damping); returns false if skipped.
    fn update(&mut self, s: &[f64], y: &mut [f64], bs: &[f64], opts: &BfgsOptions) -> bool {
        let n = s.len();
        if let Some(delta) = opts.damping {
            let sbs = dot(s, bs);
            let sty = dot(s, y);
            if sbs > 0.0 && sty < delta * sbs {
                let theta = (1.0 - delta) * sbs / (sbs - sty);
                for i in 0..n {
                    y[i] = theta * y[i] + (1.0 - theta) * bs[i];
                }
            }
        }
        let sty = dot(s, y);
        if !(sty > 0.0) {
            return false;
        }
        let mut h = self.h.clone();
        if self.iter == 1 && opts.scale {
            let yty = dot(y, y);
            let c = sty / yty;
            if c.is_finite() {
                h.iter_mut().for_each(|v| *v *= c);
            }
        }
        let rho = 1.0 / sty;
        let hy = symv(&h, y);
        let coef = (rho * rho * dot(y, &hy) + rho).max(0.0);
        for i in 0..n {
            for j in 0..n {
                h[i * n + j] += -rho * (hy[i] * s[j] + s[i] * hy[j]) + coef * s[i] * s[j];
            }
        }
        if let Some(floor) = opts.h_floor {
            let shift = floor * (0..n).map(|i| h[i * n + i]).fold(0.0, f64::max);
            (0..n).for_each(|i| h[i * n + i] += shift);
        }
        if h.iter().all(|v| v.is_finite()) {
            self.h = h;
            true
        } else {
            false
        }
    }
}

impl Solver for Bfgs<'_> {
    type State = BfgsState;
    const KIND: SolverKind = SolverKind::Bfgs;

    fn limits(&self) -> Limits {
        Limits { maxit: self.opts.maxit, fvalquit: self.opts.fvalquit, xnormquit: self.opts.xnormquit }
    }

    fn init(&mut self, ev: &mut Evaluator<'_>, x0: &[f64]) -> Result<BfgsState, OptimError> {
        let n = x0.len();
        let mut g = vec![0.0; n];
        let f = ev.eval(x0, &mut g);
        if !usable(f, &g) || x0.iter().any(|v| !v.is_finite()) {
            return Err(OptimError::NonFiniteStart { f });
        }
        let h = identity(n);
        let bundle = GradBundle::new(self.opts.ngrad_for(n), x0, &g, ev.gradient_unit(x0));
        let dnorm = bundle.dnorm();
        Ok(BfgsState {
            x: x0.to_vec(),
            f,
            g,
            h,
            dnorm,
            t: 0.0,
            iter: 0,
            ls: LsStatus::Success,
            bundle,
            skipped_updates: 0,
        })
    }

    fn step(&mut self, ev: &mut Evaluator<'_>, s: &mut BfgsState) -> Result<f64, Termination> {
        let n = s.x.len();
        let r = self.opts.restart_every;
        if r > 0 && s.iter > 0 && s.iter.is_multiple_of(r) {
            s.restart();
        }
        s.iter += 1;
        let p: Vec<f64> = symv(&s.h, &s.g).into_iter().map(|v| -v).collect();
        let gtp = dot(&s.g, &p);
        if !(gtp < 0.0) {
            return Err(Termination::NotDescent);
        }
        let params = LsParams { c1: self.opts.wolfe1, c2: self.opts.wolfe2, fvalquit: self.opts.fvalquit };
        let ls = weak_wolfe(ev, &s.x, s.f, &s.g, &p, params);
        s.t = ls.t;
        s.ls = ls.status;
        if ls.t > 0.0 {
            let step: Vec<f64> = (0..n).map(|i| ls.x[i] - s.x[i]).collect();
            let mut y: Vec<f64> = (0..n).map(|i| ls.g[i] - s.g[i]).collect();
            // B s = t·B p = −t·g exactly, since p = −H g and H is B⁻¹ (used only for damping).
            let bs: Vec<f64> = s.g.iter().map(|v| -ls.t * v).collect();
            let pnorm = dot(&p, &p).sqrt();
            let unit = ev.gradient_unit(&ls.x);
            if ls.t * pnorm > self.opts.evaldist {
                s.bundle.reset(&ls.x, &ls.g, unit);
            } else {
                s.bundle.push(&ls.x, &ls.g, unit);
            }
            s.dnorm = s.bundle.dnorm();
            s.x = ls.x;
            s.f = ls.f;
            s.g = ls.g;
            // Skip when sᵀy ≤ 0 (HANSO); only expected after a failed line search.
            if !s.update(&step, &mut y, &bs, self.opts) {
                s.skipped_updates += 1;
            }
        } else {
            // No move (line search failed at α = 0): nothing to update.
            s.skipped_updates += 1;
        }
        match ls.status {
            LsStatus::Stopped(reason) => Err(reason),
            _ => Ok(ls.t),
        }
    }

    fn converged(&self, s: &BfgsState, initial: bool) -> Option<Termination> {
        if !initial {
            match s.ls {
                LsStatus::Bracketed if self.opts.quit_ls_fail => return Some(Termination::LineSearchFailed),
                LsStatus::Unbounded => return Some(Termination::Unbounded),
                _ => {}
            }
        }
        (s.dnorm <= self.opts.normtol).then_some(Termination::Certified)
    }

    fn result(&self, ev: &mut Evaluator<'_>, s: BfgsState, termination: Termination, iters: usize) -> OptimResult {
        let evaldist = s.bundle.evaldist(&s.x);
        OptimResult {
            dnorm: s.dnorm,
            evaldist,
            x: s.x,
            f: s.f,
            g: s.g,
            termination,
            iters,
            evals: ev.evals,
            cpu_s: ev.ctl.cpu_elapsed(),
        }
    }
}

/// One BFGS run from x0 (start index `start` is only passed to the observer).
///
/// `Err` for invalid options, a wrong dimension, or a start where f or ∇f is not finite
/// (`NonFiniteStart`); every other ending is an `Ok` with its [`Termination`].
pub fn bfgs(
    obj: &mut dyn Objective,
    x0: &[f64],
    start: usize,
    opts: &BfgsOptions,
    ctl: &RunControl,
    obs: &mut dyn Observer,
) -> Result<OptimResult, OptimError> {
    opts.validate()?;
    run(&mut Bfgs { opts }, obj, x0, start, ctl, obs)
}
