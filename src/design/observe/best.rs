//! The best objective value so far of a design run: tracked here, once, per objective (the
//! stabilisation objective and the performance objective), for the iteration records' `improved`
//! (which the sparse trace and the Python progress read) and the search's time to best.

use crate::design::Phase;

/// An iterate that lowered the best objective value seen so far (per objective).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Improvement {
    /// The objective value.
    pub f: f64,
    /// CPU seconds since the run started.
    pub cpu_s: f64,
    /// Evaluations made in the run so far.
    pub evals: usize,
}

/// The improvements of a run's two objectives, in order: every finite value below the best one
/// before it.
#[derive(Debug, Clone, Default)]
pub struct BestSoFar {
    improvements: [Vec<Improvement>; 2],
}

/// The objective of a phase: 0 stabilisation, 1 performance (optimisation, gradient sampling).
fn slot(phase: Phase) -> usize {
    match phase {
        Phase::Stabilisation => 0,
        Phase::Optimisation | Phase::GradientSampling => 1,
    }
}

impl BestSoFar {
    /// A run that has seen nothing.
    pub fn new() -> Self {
        Self::default()
    }

    /// Offers the value `i.f` of `phase`'s objective; whether it is a new best (finite and
    /// below every value of that objective so far).
    pub fn offer(&mut self, phase: Phase, i: Improvement) -> bool {
        let hist = &mut self.improvements[slot(phase)];
        let improved = i.f.is_finite() && hist.last().is_none_or(|last| i.f < last.f);
        if improved {
            hist.push(i);
        }
        improved
    }

    /// The best value so far of `phase`'s objective (+∞ before the first).
    pub fn best(&self, phase: Phase) -> f64 {
        self.improvements[slot(phase)].last().map_or(f64::INFINITY, |i| i.f)
    }

    /// The first iterate of `phase`'s objective whose value was within a relative `rtol` of `f`
    /// (|f_i − f| ≤ rtol·|f|, or below f): when the value f was first reached.
    pub fn first_reached(&self, phase: Phase, f: f64, rtol: f64) -> Option<Improvement> {
        let tol = rtol * f.abs();
        self.improvements[slot(phase)].iter().find(|i| i.f <= f + tol).copied()
    }
}
