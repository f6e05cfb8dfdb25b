//! Per-thread counters of the H∞ computation's steps, for the benches (`benches/lti.rs --steps`): how many
//! evaluations take the explicit-Hamiltonian path or the pencil path, how many level-set
//! eigenproblems each needs, and, when timing is switched on, the thread-CPU time of each step.
//!
//! Counting is always on (a thread-local integer increment per step, far below the cost of any
//! step). Timing reads the thread's CPU clock twice per step, so it is off unless a bench turns
//! it on ([`set_timing`]); either way no computed value depends on it.
//!
//! Steps nest: [`Step::Norm`] contains all others but [`Step::LowerBound`] and
//! [`Step::Gradient`]; [`Step::LowerBound`] contains its own [`Step::Hessenberg`] and
//! [`Step::FreqEval`]s; a level-set test contains its PVL reduction and QR of W, which are
//! counted apart for the two paths ([`Step::Pvl`] inside [`Step::PencilLevelSet`] counts as
//! [`Step::PvlPencil`]). Each row is the time measured around that step, so nested times appear
//! in several rows.

use std::cell::{Cell, RefCell};

use crate::numeric::thread_cpu_time;

/// One measured step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Step {
    /// One H∞ norm computation (`hinf.rs`), all of it.
    Norm,
    /// The eigenvalues of A (the poles) for the stability test and the test frequencies.
    Poles,
    /// Hessenberg reduction of A and transformation of B, C (`freq_response.rs`).
    Hessenberg,
    /// One evaluation of σmax(G(iω)).
    FreqEval,
    /// One level-set test on the explicit Hamiltonian (forming H and H², PVL, QR of W).
    ExplicitLevelSet,
    /// Forming the explicit Hamiltonian and its square.
    HamiltonianSquare,
    /// One level-set test on the pencil (LU, solve, PVL, QR of W; every shift tried).
    PencilLevelSet,
    /// The LU and solve of the shifted pencil.
    PencilSolve,
    /// The PVL reduction of a skew-Hamiltonian matrix (`square_reduced.rs`), explicit path.
    Pvl,
    /// The Hessenberg QR of the PVL form's W, explicit path.
    QrW,
    /// [`Step::Pvl`] on the pencil path.
    PvlPencil,
    /// [`Step::QrW`] on the pencil path.
    QrWPencil,
    /// The singular vectors and resolvent solves of the gradient at the peak.
    Gradient,
    /// The cheap lower bound of the line-search screening (`hinf_lower_bound`).
    LowerBound,
    /// An H∞ norm computation that needed at least one pencil level-set test (count only).
    NormUsingPencil,
    /// An explicit level-set test whose squared spectrum was doubtful, so that the pencil
    /// decided at the same γ (count only).
    DoubtfulSquared,
    /// A level-set test that reported crossings, so that the level-set loop went on (count only).
    CrossingsFound,
    /// A level-set test without crossings whose eigenvalues just off the axis were probed
    /// (count only).
    Probe,
    /// A probe that raised the lower bound, so that the level-set loop went on (count only).
    ProbeFound,
}

impl Step {
    /// Whether the step is only counted, never timed.
    pub fn count_only(self) -> bool {
        matches!(
            self,
            Step::NormUsingPencil | Step::DoubtfulSquared | Step::CrossingsFound | Step::Probe | Step::ProbeFound
        )
    }

    /// All steps, in report order.
    pub const ALL: [Step; 19] = [
        Step::Norm,
        Step::Poles,
        Step::Hessenberg,
        Step::FreqEval,
        Step::ExplicitLevelSet,
        Step::HamiltonianSquare,
        Step::Pvl,
        Step::QrW,
        Step::PencilLevelSet,
        Step::PencilSolve,
        Step::PvlPencil,
        Step::QrWPencil,
        Step::Gradient,
        Step::LowerBound,
        Step::NormUsingPencil,
        Step::DoubtfulSquared,
        Step::CrossingsFound,
        Step::Probe,
        Step::ProbeFound,
    ];

    fn index(self) -> usize {
        self as usize
    }

    /// A short name for reports.
    pub fn name(self) -> &'static str {
        match self {
            Step::Norm => "H∞ norm (whole)",
            Step::Poles => "poles (QR of A)",
            Step::Hessenberg => "Hessenberg of A",
            Step::FreqEval => "σmax(G(iω))",
            Step::ExplicitLevelSet => "level set, explicit",
            Step::HamiltonianSquare => "  form H, H²",
            Step::PencilLevelSet => "level set, pencil",
            Step::PencilSolve => "  pencil LU+solve",
            Step::Pvl | Step::PvlPencil => "  PVL reduction",
            Step::QrW | Step::QrWPencil => "  QR of W",
            Step::Gradient => "gradient vectors",
            Step::LowerBound => "lower bound (screen)",
            Step::NormUsingPencil => "norms using the pencil",
            Step::DoubtfulSquared => "doubtful squared spectra",
            Step::CrossingsFound => "tests finding crossings",
            Step::Probe => "tests with probes",
            Step::ProbeFound => "probes raising γ_L",
        }
    }
}

const STEPS: usize = Step::ALL.len();

/// Systems of at least this order are counted apart from smaller ones (in a design, the closed
/// loops of large plants apart from the controller's own norm).
pub const LARGE_ORDER: usize = 30;

/// Calls and thread-CPU seconds of every step since the last [`reset`], for systems of order
/// below [`LARGE_ORDER`] (`large = false`) and from it on (`large = true`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StepStats {
    calls: [[u64; STEPS]; 2],
    cpu_s: [[f64; STEPS]; 2],
}

impl StepStats {
    /// Number of times `step` ran on small or large systems.
    pub fn calls(&self, step: Step, large: bool) -> u64 {
        self.calls[usize::from(large)][step.index()]
    }

    /// Thread-CPU seconds spent in `step` on small or large systems (0 unless timing was on).
    pub fn cpu_s(&self, step: Step, large: bool) -> f64 {
        self.cpu_s[usize::from(large)][step.index()]
    }
}

thread_local! {
    static STATS: RefCell<StepStats> = RefCell::new(StepStats::default());
    static TIMING: Cell<bool> = const { Cell::new(false) };
    static IN_PENCIL: Cell<bool> = const { Cell::new(false) };
    static LARGE: Cell<bool> = const { Cell::new(false) };
}

/// Runs `f` with its steps counted for a system of order `order` (small or large).
#[inline]
pub(crate) fn for_order<R>(order: usize, f: impl FnOnce() -> R) -> R {
    let was = LARGE.with(|l| l.replace(order >= LARGE_ORDER));
    let out = f();
    LARGE.with(|l| l.set(was));
    out
}

/// Switches the timing of steps on or off for the calling thread.
pub fn set_timing(on: bool) {
    TIMING.with(|t| t.set(on));
}

/// Clears the calling thread's counters.
pub fn reset() {
    STATS.with(|s| *s.borrow_mut() = StepStats::default());
}

/// The calling thread's counters.
pub fn snapshot() -> StepStats {
    STATS.with(|s| s.borrow().clone())
}

/// Counts one `step` (no timing).
pub(crate) fn count(step: Step) {
    let class = usize::from(LARGE.with(|l| l.get()));
    STATS.with(|s| s.borrow_mut().calls[class][step.index()] += 1);
}

/// Runs `f` as one `step`: counts it and, if timing is on, adds its thread-CPU time.
#[inline]
pub(crate) fn timed<R>(step: Step, f: impl FnOnce() -> R) -> R {
    let step = match (step, IN_PENCIL.with(|p| p.get())) {
        (Step::Pvl, true) => Step::PvlPencil,
        (Step::QrW, true) => Step::QrWPencil,
        (s, _) => s,
    };
    let outer = (step == Step::PencilLevelSet).then(|| IN_PENCIL.with(|p| p.replace(true)));
    let t0 = TIMING.with(|t| t.get()).then(thread_cpu_time);
    let out = f();
    if let Some(was) = outer {
        IN_PENCIL.with(|p| p.set(was));
    }
    let dt = t0.map_or(0.0, |t0| thread_cpu_time() - t0);
    let class = usize::from(LARGE.with(|l| l.get()));
    STATS.with(|s| {
        let mut s = s.borrow_mut();
        s.calls[class][step.index()] += 1;
        s.cpu_s[class][step.index()] += dt;
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_always_and_times_only_when_asked() {
        reset();
        set_timing(false);
        let x = timed(Step::Pvl, || 2 + 2);
        for_order(LARGE_ORDER, || timed(Step::Pvl, || ()));
        assert_eq!(snapshot().calls(Step::Pvl, true), 1);
        assert_eq!(x, 4);
        let s = snapshot();
        assert_eq!(s.calls(Step::Pvl, false), 1);
        assert_eq!(s.cpu_s(Step::Pvl, false), 0.0);
        set_timing(true);
        timed(Step::QrW, || (0..200_000u64).map(|i| i ^ (i >> 3)).sum::<u64>());
        set_timing(false);
        let s = snapshot();
        assert_eq!(s.calls(Step::QrW, false), 1);
        assert!(s.cpu_s(Step::QrW, false) >= 0.0);
        reset();
        assert_eq!(snapshot(), StepStats::default());
    }
}
