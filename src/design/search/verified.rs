//! Incumbents that verify (docs/ALGORITHMS.md §8.3): the search keeps as its best point a
//! controller that is stable with the verification margin whenever it has found one.
//!
//! The local searches call a point stable once its measure is below 0 (`lti::is_stable`: the
//! objective must not move), while the returned controller is judged with the verification
//! margin (`lti::verified_stability`, [`crate::design::evaluate::stabilises`]). Where the
//! closed-loop norm rises to +∞ at the stability boundary, as it does whenever ‖Tzw‖∞ sees the
//! loop's modes, no local search ends near the boundary and the two tests agree. Where nothing
//! holds the search back — COMPleib's NN10, whose ‖Tzw‖∞ is 0 for every controller, so that
//! under strong stabilisation f_h = ε‖K‖∞ falls towards the closed loop's stability boundary —
//! a local search can end at α(A_cl) ≈ −1e-13, inside the margin. Such an end point used to
//! become the incumbent, and the run ended "not stabilised" although its chained start (a
//! verified controller of the order below, α(A_cl) = −0.016) was stabilising.
//!
//! So every end point of an f_h local search is checked with the verification margin:
//! * it verifies: offered as before (every run whose end points verify is unchanged, bit for
//!   bit);
//! * it does not, but the point its local search started from does: it is pulled back along the
//!   segment from that start, to the last point that verifies (bisection on the segment,
//!   [`PULL_BACK_STEPS`] halvings), whose f_h is evaluated once; that point, uncertified
//!   (dnorm = +∞), is offered instead;
//! * neither verifies: offered as it is, marked unverified.
//!
//! A verified point always beats an unverified one ([`super::State::offer_perf`]); among points
//! of one kind the smaller f_h wins, as before.

use crate::optim::{Objective, OptimResult};

use super::{Search, State};
use crate::design::evaluate::stabilises;

/// Halvings of the segment from a verified start to an end point that does not verify: the
/// pulled-back point is within 2⁻³⁰ of the segment's length of the last verified point on it.
pub const PULL_BACK_STEPS: usize = 30;

impl Search<'_, '_, '_> {
    /// Whether the controller at `x` (controller parameters) is stable with the verification
    /// margin, as `st.opts` asks (the closed loops; the controller too under strong
    /// stabilisation).
    pub(super) fn verifies(&self, st: &State<'_>, x: &[f64]) -> bool {
        stabilises(self.problem, st.opts, &self.perf_obj.controller_at(x)).is_ok()
    }

    /// f_h at `x` (controller parameters), evaluated once outside a local search and counted
    /// with the performance phase's evaluations.
    pub(super) fn perf_value(&mut self, st: &mut State<'_>, x: &[f64]) -> f64 {
        let mut g = vec![0.0; x.len()];
        st.stats[1].evals += 1;
        self.perf_obj.eval(x, &mut g)
    }

    /// The end point `r` (controller parameters) of an f_h local search that started from
    /// `from`, made to verify where it can (module docs): unchanged if it verifies, else
    /// replaced by its pull-back towards `from` if `from` verifies. Returns whether `r`, as it
    /// is left, verifies.
    pub(super) fn verified_end(&mut self, st: &mut State<'_>, r: &mut OptimResult, from: &[f64]) -> bool {
        if !r.f.is_finite() || self.verifies(st, &r.x) {
            return r.f.is_finite();
        }
        if !self.verifies(st, from) {
            return false;
        }
        let point = |t: f64| -> Vec<f64> { from.iter().zip(&r.x).map(|(a, b)| a + t * (b - a)).collect() };
        let (mut lo, mut hi) = (0.0_f64, 1.0_f64);
        for _ in 0..PULL_BACK_STEPS {
            let mid = 0.5 * (lo + hi);
            if self.verifies(st, &point(mid)) {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let x = point(lo);
        let f = self.perf_value(st, &x);
        if !f.is_finite() {
            return false;
        }
        r.x = x;
        r.f = f;
        r.dnorm = f64::INFINITY;
        r.evaldist = f64::NAN;
        true
    }
}
