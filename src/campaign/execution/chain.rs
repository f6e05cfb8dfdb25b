//! Order chaining's choice of a start (`order_chaining`, module docs of `campaign::jobs`): of the
//! finished jobs a job chains from (every job of the order below at its ε), the one whose
//! controller re-verifies (as the report verifies it: `design::evaluate_job` and its verdict) with
//! the least γ, ties broken by the smaller job id. The rule depends only on those jobs' records,
//! never on when or where they finished, so one sitting, a resumed run and a sharded one start a
//! job from the same controller.

use crate::campaign::model::jobs::{Job, JobId};
use crate::design::evaluate_job;
use crate::lti::Controller;

/// The γ of `k`, the controller of finished job `job`, as the report re-verifies it; `None` if it
/// does not verify.
pub fn verified_gamma(job: &Job, k: &Controller) -> Option<f64> {
    let evaluation = evaluate_job(job.multi.as_deref(), &job.plant, k, job.options.order).ok()?;
    evaluation.verdict(job.options.objective).ok()
}

/// The best of `candidates` (job id, verified γ if any): the least γ, ties by job id; `None` if
/// none verified.
pub fn best<'a>(candidates: impl IntoIterator<Item = (&'a JobId, Option<f64>)>) -> Option<&'a JobId> {
    candidates
        .into_iter()
        .filter_map(|(id, g)| g.filter(|g| g.is_finite()).map(|g| (g, id)))
        .min_by(|a, b| a.0.total_cmp(&b.0).then_with(|| a.1.cmp(b.1)))
        .map(|(_, id)| id)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_least_gamma_wins_and_ties_go_to_the_smaller_id() {
        let ids: Vec<JobId> = ["b", "a", "c", "d"].iter().map(|s| JobId(s.to_string())).collect();
        let pick = |g: [Option<f64>; 4]| best(ids.iter().zip(g)).map(|id| id.0.clone());
        assert_eq!(pick([Some(2.0), Some(1.0), None, Some(3.0)]).as_deref(), Some("a"));
        assert_eq!(pick([Some(1.0), Some(1.0), None, Some(3.0)]).as_deref(), Some("a"), "tie: smaller id");
        assert_eq!(pick([Some(1.0), Some(2.0), Some(0.5), Some(f64::NAN)]).as_deref(), Some("c"));
        assert_eq!(pick([None, None, None, Some(f64::INFINITY)]), None, "nothing verified");
        // the order of the candidates does not matter
        let rev: Vec<_> = ids.iter().rev().zip([Some(1.0), None, Some(1.0), Some(1.0)]).collect();
        assert_eq!(best(rev).map(|id| id.0.as_str()), Some("a"));
    }
}
