//! What the H∞ norm computation (`hinf.rs`) tells the benchmarks, in one place: it reports
//! [`NormEvent`]s and runs its whole computations through [`measured`]; this hook turns them into
//! the step counters and timers of `kernels::step_stats` (`benches/lti.rs --steps`) and, with
//! the `test-support` feature, into the recorded norms of `benches/lti.rs --record`
//! (`lti::kernel_bench`). No computed value depends on it.

use crate::lti::kernels::step_stats::{count, for_order};
pub(crate) use crate::lti::kernels::step_stats::{timed, Step};
use crate::lti::system::state_space::StateSpace;

/// What happened in a norm computation, as far as the benchmarks care.
#[derive(Debug, Clone, Copy)]
pub(crate) enum NormEvent<'a> {
    /// The norm of a large system (order ≥ `HESSENBERG_QR_FROM`) is computed with the
    /// tolerance `tol` and the peak hints `hints`: what `--record` keeps for its replay.
    Large {
        /// The system.
        sys: &'a StateSpace,
        /// The relative tolerance asked for.
        tol: f64,
        /// The peak hints.
        hints: &'a [f64],
    },
    /// A level-set test reported crossings, so the level-set loop went on.
    Crossings,
    /// A level-set test without crossings probed the eigenvalues just off the axis; `raised`:
    /// a probe raised the lower bound, so the loop went on.
    Probed {
        /// Whether a probe raised γ_L.
        raised: bool,
    },
    /// An explicit level-set test's squared spectrum was doubtful, so the pencil decided.
    DoubtfulSquared,
    /// The norm's first level-set test on the pencil.
    FirstPencil,
}

/// Counts (or records) `event`.
pub(crate) fn note(event: NormEvent<'_>) {
    match event {
        NormEvent::Large { sys, tol, hints } => {
            #[cfg(feature = "test-support")]
            crate::lti::kernel_bench::note_norm(sys, tol, hints);
            let _ = (sys, tol, hints);
        }
        NormEvent::Crossings => count(Step::CrossingsFound),
        NormEvent::Probed { raised } => {
            count(Step::Probe);
            if raised {
                count(Step::ProbeFound);
            }
        }
        NormEvent::DoubtfulSquared => count(Step::DoubtfulSquared),
        NormEvent::FirstPencil => count(Step::NormUsingPencil),
    }
}

/// Runs `f`, a whole computation on `sys` (the norm, [`Step::Norm`], or its lower bound,
/// [`Step::LowerBound`]), as one measured `step`, its inner steps counted in `sys`'s order class.
pub(crate) fn measured<R>(sys: &StateSpace, step: Step, f: impl FnOnce() -> R) -> R {
    for_order(sys.order(), || timed(step, f))
}
