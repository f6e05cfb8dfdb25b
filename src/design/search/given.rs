//! The given controllers of a run — a campaign's warm start from the ε before (the initial
//! controller of `Design::init`) and its chained start from the order below (`Design::chained`),
//! each padded to the run's order — are incumbents before any local search is made
//! (docs/ALGORITHMS.md §8.2, §8.7).
//!
//! Each given point that is stable with the verification margin ([`Search::verifies`]) is
//! evaluated once (f_h) and offered to the incumbents as it is (uncertified, dnorm = +∞), and the
//! local searches from the given points are made lowest f_h first. So a run returns nothing
//! worse than its best given controller however soon a budget ends it: a continued-ε job is at
//! most its warm start's max(γ, ε‖K‖∞), a chained job at most the order below's, even when the
//! first local search spends the whole budget. (Before, the given points were offered only as the
//! end points of their own local searches, in a fixed order: in the fast protocol 19 of BDT2's
//! continued jobs ended above their warm start, e.g. n_K = 2, ε = 1e-3: a 6-s budget spent in the
//! chained start's local search, 0.6326 returned against the warm start's 0.5673.)
//!
//! A run whose given points are unstable, or that has at most one given point, makes its local
//! searches in the order it always did.

use crate::optim::Objective;

use super::{Best, Coords, Search, State};

impl Search<'_, '_, '_> {
    /// Offers the given points `given` (controller parameters) to the incumbents (module docs)
    /// and returns their indices in the order their local searches are made: increasing f_h, the
    /// points that do not verify last, ties in the given order. The given point with rank r is
    /// recorded as found by local search number r, the one that starts from it.
    pub(super) fn offer_given(&mut self, st: &mut State<'_>, given: &[Vec<f64>]) -> Vec<usize> {
        let mut values = Vec::with_capacity(given.len());
        for x in given {
            let f = if self.verifies(st, x) {
                let mut g = vec![0.0; x.len()];
                let f = self.perf_obj.eval(x, &mut g);
                st.stats[1].evals += 1;
                f
            } else {
                f64::INFINITY
            };
            values.push(if f.is_nan() { f64::INFINITY } else { f });
        }
        let mut order: Vec<usize> = (0..given.len()).collect();
        order.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
        for (rank, &i) in order.iter().enumerate() {
            let f = values[i];
            if f.is_finite() && st.perf.as_ref().is_none_or(|b| f < b.f) {
                let x = given[i].clone();
                let (dnorm, evaldist, coords) = (f64::INFINITY, f64::NAN, Coords::Raw);
                st.perf = Some(Best { from: x.clone(), x, f, dnorm, evaldist, start: rank, coords, verified: true });
                st.stabilised = true;
            }
        }
        order
    }
}
