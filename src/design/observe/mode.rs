//! Which iterations an observer is told of, as configuration rather than code in the observer
//! (in the style of argmin's `ObserverMode`): [`ObserverMode`], applied to a stream of records by
//! [`ModeFilter`] (the trace writer keeps its own payload per record) or around any observer by
//! [`Observed`].

use std::ops::ControlFlow;
use std::sync::atomic::AtomicBool;
use std::sync::Arc;
use std::time::{Duration, Instant};

use super::sparse::SparseFilter;
use super::{DesignIterRecord, DesignObserver};

/// Which of a run's iterations an observer sees.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum ObserverMode {
    /// Every iteration (a full trace).
    #[default]
    Always,
    /// Every k-th iteration offered: the 1st, the (k+1)-th, … (k = 0 counts as 1).
    Every(usize),
    /// The iterations that lower their objective's best value so far
    /// ([`DesignIterRecord::improved`]).
    OnImprovement,
    /// At most one per interval of wall time: the first, then the first after each interval
    /// (the campaign's progress display).
    Throttled(Duration),
    /// The sparse trace ([`SparseFilter`]): the end of every local search, the first iterations
    /// that need showing, improvements and a thinned sample. Holds an iteration until it is
    /// known whether it ends its local search, so records come out later, in order.
    Sparse,
}

/// [`ObserverMode`] applied to a stream of records, each with the item to pass on for it (`T`:
/// the record itself, or what a writer makes of it at its arrival).
#[derive(Debug)]
pub enum ModeFilter<T> {
    /// [`ObserverMode::Always`].
    Always,
    /// [`ObserverMode::Every`]: k, and the records offered so far.
    Every(usize, usize),
    /// [`ObserverMode::OnImprovement`].
    OnImprovement,
    /// [`ObserverMode::Throttled`]: the interval and when the last record was passed on.
    Throttled(Duration, Option<Instant>),
    /// [`ObserverMode::Sparse`].
    Sparse(SparseFilter<T>),
}

impl<T> ModeFilter<T> {
    /// A filter for `mode` that has seen nothing.
    pub fn new(mode: ObserverMode) -> Self {
        match mode {
            ObserverMode::Always => ModeFilter::Always,
            ObserverMode::Every(k) => ModeFilter::Every(k.max(1), 0),
            ObserverMode::OnImprovement => ModeFilter::OnImprovement,
            ObserverMode::Throttled(interval) => ModeFilter::Throttled(interval, None),
            ObserverMode::Sparse => ModeFilter::Sparse(SparseFilter::new()),
        }
    }

    /// Offers `rec` (passed on as `item`): the items to pass on now, in order.
    pub fn push(&mut self, rec: &DesignIterRecord, item: T) -> Vec<T> {
        let pass = match self {
            ModeFilter::Always => true,
            ModeFilter::Every(k, seen) => {
                *seen += 1;
                (*seen - 1) % *k == 0
            }
            ModeFilter::OnImprovement => rec.improved,
            ModeFilter::Throttled(interval, last) => {
                let due = last.is_none_or(|t| t.elapsed() >= *interval);
                if due {
                    *last = Some(Instant::now());
                }
                due
            }
            ModeFilter::Sparse(f) => return f.push(rec, item),
        };
        if pass {
            vec![item]
        } else {
            Vec::new()
        }
    }

    /// The run ended: the items still held (only [`ObserverMode::Sparse`] holds any), in order.
    pub fn finish(&mut self) -> Vec<T> {
        match self {
            ModeFilter::Sparse(f) => f.finish(),
            _ => Vec::new(),
        }
    }
}

/// An observer told only of the iterations its mode passes on. Its cancel flag and whether it
/// wants the components are the inner observer's.
pub struct Observed<O> {
    filter: ModeFilter<DesignIterRecord>,
    inner: O,
}

impl<O: DesignObserver> Observed<O> {
    /// `inner`, watching in `mode`.
    pub fn new(mode: ObserverMode, inner: O) -> Self {
        Observed { filter: ModeFilter::new(mode), inner }
    }

    /// The run ended: passes on what the mode still holds, then gives back the inner observer.
    pub fn finish(mut self) -> O {
        for rec in self.filter.finish() {
            let _ = self.inner.on_iter(&rec);
        }
        self.inner
    }
}

impl<O: DesignObserver> DesignObserver for Observed<O> {
    fn wants_components(&self) -> bool {
        self.inner.wants_components()
    }

    fn on_iter(&mut self, rec: &DesignIterRecord) -> ControlFlow<()> {
        let mut flow = ControlFlow::Continue(());
        for r in self.filter.push(rec, rec.clone()) {
            if self.inner.on_iter(&r).is_break() {
                flow = ControlFlow::Break(());
            }
        }
        flow
    }

    fn cancel_flag(&self) -> Option<Arc<AtomicBool>> {
        self.inner.cancel_flag()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::design::{Components, Phase};
    use crate::optim::{Iteration, SolverKind};

    fn rec(iter: usize, f: f64, improved: bool) -> DesignIterRecord {
        let it =
            Iteration { solver: SolverKind::Bfgs, start: 0, iter, f, dnorm: 1.0, step: 1.0, evals: iter, cpu_s: 0.0 };
        let c = Components { f, gamma: f, k_hinf: 1.0, alpha_cl: -1.0, alpha_k: -1.0 };
        DesignIterRecord::new(Phase::Optimisation, it, &c, improved)
    }

    fn passed(mode: ObserverMode, recs: &[DesignIterRecord]) -> Vec<usize> {
        let mut m = ModeFilter::new(mode);
        let mut out: Vec<usize> = recs.iter().flat_map(|r| m.push(r, r.iter)).collect();
        out.extend(m.finish());
        out
    }

    #[test]
    fn each_mode_passes_what_it_says() {
        let recs: Vec<DesignIterRecord> = (0..10).map(|i| rec(i, 10.0 - (i % 4) as f64, i % 4 != 0)).collect();
        assert_eq!(passed(ObserverMode::Always, &recs), (0..10).collect::<Vec<_>>());
        assert_eq!(passed(ObserverMode::Every(3), &recs), [0, 3, 6, 9]);
        assert_eq!(passed(ObserverMode::Every(0), &recs).len(), 10);
        assert_eq!(passed(ObserverMode::OnImprovement, &recs), [1, 2, 3, 5, 6, 7, 9]);
        assert_eq!(passed(ObserverMode::Throttled(Duration::from_secs(3600)), &recs), [0]);
        assert_eq!(passed(ObserverMode::Throttled(Duration::ZERO), &recs).len(), 10);
        // One local search without CPU time: its first, the values below the best before them
        // (f and ‖Tzw‖∞ 9, 8, 7), its last.
        assert_eq!(passed(ObserverMode::Sparse, &recs), [0, 1, 2, 3, 9]);
    }

    #[test]
    fn an_observed_observer_sees_what_its_mode_passes() {
        struct Seen(Vec<usize>);
        impl DesignObserver for Seen {
            fn on_iter(&mut self, rec: &DesignIterRecord) -> ControlFlow<()> {
                self.0.push(rec.iter);
                ControlFlow::Continue(())
            }
        }
        let mut o = Observed::new(ObserverMode::Sparse, Seen(Vec::new()));
        for i in 0..5 {
            assert!(o.on_iter(&rec(i, 1.0, i == 0)).is_continue());
        }
        assert_eq!(o.finish().0, [0, 4]);
    }
}
