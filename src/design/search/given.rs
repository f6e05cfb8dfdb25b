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
//!
//! A chained start that is not its run's first search ([`super::FirstStarts::chained_first`] false:
//! in a campaign, every seed but the first of an order's jobs) is still an incumbent from the
//! outset, but its local search and its coupled copy's come after the run's own first starts. The
//! best controller of the order below is the same for every seed, so each seed that searched from
//! it first spent its budget on the same local search: in the fast protocol the four seeds of
//! BDT2's order 3 ended within 0.4 % of one another at every ε, and seven of the eight jobs of its
//! orders 3 and 4 at ε = 1e-6 at the same 0.5360. One seed still refines the chained start first;
//! the others search as independent replicates, each never worse than the order below.

use super::plan::StartPlan;
use super::{Best, Coords, Search, State};

impl Search<'_, '_, '_> {
    /// f_h of each given point `given` (controller parameters) that verifies, +∞ for the others
    /// (and for a NaN).
    pub(super) fn given_values(&mut self, st: &mut State<'_>, given: &[Vec<f64>]) -> Vec<f64> {
        given
            .iter()
            .map(|x| if self.verifies(st, x) { self.perf_value(st, x) } else { f64::INFINITY })
            .map(|f| if f.is_nan() { f64::INFINITY } else { f })
            .collect()
    }

    /// Offers the given points `given`, of f_h `values` ([`Self::given_values`]), to the
    /// incumbents (module docs) in the order `order` ([`lowest_first`] of `values`: on a tie the
    /// first offered stays). A given point is recorded as found by the local search of `plan`
    /// that starts from it.
    pub(super) fn offer_given(
        &self,
        st: &mut State<'_>,
        given: &[Vec<f64>],
        values: &[f64],
        order: &[usize],
        plan: &StartPlan,
    ) {
        for &i in order {
            let f = values[i];
            if f.is_finite() && st.perf.as_ref().is_none_or(|b| f < b.f) {
                let x = given[i].clone();
                let (dnorm, evaldist, coords) = (f64::INFINITY, f64::NAN, Coords::Raw);
                let start = plan.position_of(i);
                st.perf = Some(Best { x, f, dnorm, evaldist, start, moved: false, coords, verified: true });
                st.stabilised = true;
            }
        }
    }
}

/// The indices of `values` in increasing order (+∞ last, ties in index order): the order the
/// local searches from the given points are made in (module docs).
pub(super) fn lowest_first(values: &[f64]) -> Vec<usize> {
    let mut order: Vec<usize> = (0..values.len()).collect();
    order.sort_by(|&a, &b| values[a].total_cmp(&values[b]));
    order
}
