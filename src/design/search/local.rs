//! One local search, and the gradient sampling that may follow one (docs/ALGORITHMS.md §8.3,
//! §8.4, §7.4).
//!
//! From a start x₀: BFGS on f_s = max(α(Acl), ε·α(Ak)) with fvalquit = 0 (it stops as soon as
//! f_s < 0: Acl and Ak Hurwitz; a start that is already stable costs one evaluation); if the end
//! point is stable, BFGS on f_h = max(‖Tzw‖∞, ε·‖K‖∞) from it, whose end point carries the
//! certificate (dnorm, evaldist). Each local search has a fresh inverse-Hessian approximation —
//! restarting BFGS is itself useful on nonsmooth functions.
//!
//! Gradient sampling, when on, runs from single points:
//! * HIFOO's fallback when none of the first starts was stabilised: on f_s (fvalquit = 0) from
//!   the one point with the smallest f_s, then BFGS on f_h from its end point if stable;
//! * refining near-misses (`refine_rtol`): the incumbent is judged after gradient sampling, other
//!   local searches after BFGS alone, which stalls above the floor of a basin on a ridge of
//!   max(‖Tzw‖∞, ε‖K‖∞). An f_h local search of the continued search that ends uncertified
//!   (dnorm > normtol, not cut by a budget) at most a relative `refine_rtol` above the incumbent
//!   gets gradient sampling from its end point (same options and coordinates) before it is
//!   offered; it draws from the run's generator, so the run stays reproducible. The first starts
//!   are unchanged;
//! * the incumbent's (HANSO 2.0's rule: only if its certificate dnorm > normtol), whose end point
//!   replaces the incumbent if it lowers f_h; when it runs is [`super::budget`]'s business.

use crate::lti::is_stable;
use crate::optim::{bfgs, gradient_sampling, OptimError, OptimResult, RunControl};

use super::budget::{ctl_stop, stop_of};
use super::{pick, Coords, Search, State};
use crate::design::outcome::{DesignError, Phase, SearchStop};
use crate::design::phases::{bfgs_options, gradsamp_options, optim_error, perf_bfgs_options};

impl Search<'_, '_, '_> {
    /// One local search from `x0`, given in coordinates `c` (module docs). Returns the stop
    /// reason if a budget or an interrupt ended it, and whether it improved the incumbent (stall
    /// sense).
    pub(super) fn local(
        &mut self,
        st: &mut State<'_>,
        x0: &[f64],
        k: usize,
        c: Coords,
        ctl: &RunControl,
    ) -> Result<(Option<SearchStop>, bool), DesignError> {
        let opts = st.opts;
        let obj = pick(self.stab_obj, &mut self.scaled, false, c);
        self.adapter.switch(obj, Phase::Stabilisation);
        self.adapter.set_evals_base(st.evals());
        let c0 = ctl.cpu_elapsed();
        let (xs, fs) = match bfgs(obj, x0, k, &bfgs_options(opts, 0.0), ctl, self.adapter) {
            Ok(r) => {
                st.add(0, &r, c0, ctl.cpu_elapsed());
                if let Some(stop) = stop_of(r.termination) {
                    let better = st.offer_stab(self.to_raw(&r.x, c), r.f, k, c);
                    return Ok((Some(stop), better));
                }
                (r.x, r.f)
            }
            Err(OptimError::NonFiniteStart { f }) => {
                st.stats[0].evals += 1;
                (x0.to_vec(), f)
            }
            Err(e) => return Err(optim_error(e)),
        };
        let stab_better = st.offer_stab(self.to_raw(&xs, c), fs, k, c);
        if !is_stable(fs) {
            // Not stabilised: progress only counts while no stable point is known.
            return Ok((None, !st.stabilised && stab_better));
        }
        st.stabilised = true;
        self.optimise_from(st, &xs, k, c, ctl)
    }

    /// BFGS on f_h from the stable point `xs`, given in coordinates `c`.
    pub(super) fn optimise_from(
        &mut self,
        st: &mut State<'_>,
        xs: &[f64],
        k: usize,
        c: Coords,
        ctl: &RunControl,
    ) -> Result<(Option<SearchStop>, bool), DesignError> {
        let opts = st.opts;
        let obj = pick(self.perf_obj, &mut self.scaled, true, c);
        self.adapter.switch(obj, Phase::Optimisation);
        self.adapter.set_evals_base(st.evals());
        let c0 = ctl.cpu_elapsed();
        match bfgs(obj, xs, k, &perf_bfgs_options(opts, st.continued), ctl, self.adapter) {
            Ok(mut r) => {
                st.add(1, &r, c0, ctl.cpu_elapsed());
                if st.refines(&r) {
                    r = self.refine(st, r, c, ctl)?;
                }
                r.x = self.to_raw(&r.x, c);
                let from = self.to_raw(xs, c);
                let verified = self.verified_end(st, &mut r, &from);
                let better = st.offer_perf(&r, &from, k, c, verified);
                Ok((stop_of(r.termination), better))
            }
            // f_h = +∞ at a point with α just below 0 (the norm's stability test has a margin):
            // nothing to optimise from here.
            Err(OptimError::NonFiniteStart { .. }) => {
                st.stats[1].evals += 1;
                Ok((None, false))
            }
            Err(e) => Err(optim_error(e)),
        }
    }

    /// Gradient sampling on f_h from the end point `r` of a continued local search that
    /// [`State::refines`] (module docs, "Refining near-misses"), in its coordinates `c`, under
    /// `ctl`; returns its end point if it lowered f_h, else `r`.
    pub(super) fn refine(
        &mut self,
        st: &mut State<'_>,
        r: OptimResult,
        c: Coords,
        ctl: &RunControl,
    ) -> Result<OptimResult, DesignError> {
        let Some(g) = self.gs_perf(st, &r.x, c, ctl)? else { return Ok(r) };
        st.refinements += 1;
        Ok(if g.f < r.f { g } else { r })
    }

    /// Gradient sampling on f_h from `x0`, in coordinates `c` (its end point too), under `ctl`,
    /// counted in the gradient-sampling statistics; `None` if f_h is not finite at `x0`. Serves
    /// the incumbent's gradient sampling ([`Self::gs_incumbent`]) and the near-misses'
    /// ([`Self::refine`]).
    pub(super) fn gs_perf(
        &mut self,
        st: &mut State<'_>,
        x0: &[f64],
        c: Coords,
        ctl: &RunControl,
    ) -> Result<Option<OptimResult>, DesignError> {
        let obj = pick(self.perf_obj, &mut self.scaled, true, c);
        self.adapter.switch(obj, Phase::Optimisation);
        self.adapter.set_evals_base(st.evals());
        let c0 = ctl.cpu_elapsed();
        let gopts = gradsamp_options(st.opts, f64::NEG_INFINITY);
        match gradient_sampling(obj, x0, &gopts, self.rng, ctl, self.adapter) {
            Ok(r) => {
                st.add(2, &r, c0, ctl.cpu_elapsed());
                Ok(Some(r))
            }
            Err(OptimError::NonFiniteStart { .. }) => {
                st.stats[2].evals += 1;
                Ok(None)
            }
            Err(e) => Err(optim_error(e)),
        }
    }

    /// HIFOO's fallback when no first start was stabilised: gradient sampling on f_s from the
    /// best f_s point (in its local search's coordinates), then f_h from its end point if stable.
    pub(super) fn gs_stabilise(
        &mut self,
        st: &mut State<'_>,
        k: usize,
        ctl: &RunControl,
    ) -> Result<(Option<SearchStop>, bool), DesignError> {
        let opts = st.opts;
        let Some((x0, c)) = st.stab.as_ref().filter(|b| b.f.is_finite()).map(|b| (b.x.clone(), b.coords)) else {
            return Ok((None, false));
        };
        let x0 = self.to_coords(&x0, c);
        let obj = pick(self.stab_obj, &mut self.scaled, false, c);
        self.adapter.switch(obj, Phase::Stabilisation);
        self.adapter.set_evals_base(st.evals());
        let c0 = ctl.cpu_elapsed();
        match gradient_sampling(obj, &x0, &gradsamp_options(opts, 0.0), self.rng, ctl, self.adapter) {
            Ok(r) => {
                st.add(0, &r, c0, ctl.cpu_elapsed());
                let better = st.offer_stab(self.to_raw(&r.x, c), r.f, k, c);
                if let Some(stop) = stop_of(r.termination) {
                    return Ok((Some(stop), better));
                }
                if is_stable(r.f) {
                    st.stabilised = true;
                    return self.optimise_from(st, &r.x, k, c, ctl);
                }
                Ok((None, better))
            }
            Err(OptimError::NonFiniteStart { .. }) => {
                st.stats[0].evals += 1;
                Ok((None, false))
            }
            Err(e) => Err(optim_error(e)),
        }
    }

    /// Gradient sampling on f_h from the incumbent under `ctl`, if the incumbent is not
    /// certified (HANSO 2.0's rule: dnorm > normtol) and the budget is not spent; its end point
    /// replaces the incumbent if it lowers f_h. Returns whether it ran.
    pub(super) fn gs_incumbent(&mut self, st: &mut State<'_>, ctl: &RunControl) -> Result<bool, DesignError> {
        let opts = st.opts;
        let Some(best) = st.perf.clone() else { return Ok(false) };
        if !(best.dnorm > opts.normtol && ctl_stop(ctl).is_none()) {
            return Ok(false);
        }
        // In the coordinates of the local search that found the best point.
        let c = best.coords;
        let x0 = self.to_coords(&best.x, c);
        let Some(mut r) = self.gs_perf(st, &x0, c, ctl)? else { return Ok(false) };
        r.x = self.to_raw(&r.x, c);
        // A verified incumbent is replaced only by a point that verifies too (module `verified`).
        let verified = self.verified_end(st, &mut r, &best.x);
        let b = st.perf.as_mut().expect("checked above");
        if r.f < b.f && (verified || !b.verified) {
            b.x = r.x;
            b.f = r.f;
            b.dnorm = r.dnorm;
            b.evaldist = r.evaldist;
            b.verified = verified;
        } else if r.x == b.x && r.dnorm < b.dnorm {
            b.dnorm = r.dnorm;
            b.evaldist = r.evaldist;
        }
        Ok(true)
    }
}
