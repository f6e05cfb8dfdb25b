//! The sparse trace's thinning ([`super::ObserverMode::Sparse`]): which of a run's iteration
//! records a sparse trace keeps (`campaign trace`'s level `sparse`, the default).
//!
//! A sparse trace keeps, of the iteration messages (campaigns/FORMAT.md, "Traces"):
//! * the last message of every *run* — the consecutive messages of one local search in one phase
//!   (a run ends where the phase or the start index changes, or where the iteration count does
//!   not increase) — so every phase change and every restart is seen, at the end point of the
//!   run before it, and the step count of every run is known (runs count from iteration 0);
//! * the first message of a run only where something needs it: the job's first message and the
//!   first of every phase not seen before (`campaign trace`'s first f, overall and per phase);
//!   the first of every gradient-sampling run (the best point it refines: the phase's gain is
//!   measured from it); and the first of a run that goes on in the same phase and start (the
//!   iteration count starts again), without which its boundary would not show. The other runs —
//!   a restart, or the change from stabilisation to optimisation of one start — begin in the
//!   trace at their first message kept for another reason (or their last);
//! * every message whose objective value f is below the best f of the run so far, the
//!   stabilisation objective (phase `stabilisation`) and the performance objective (the other
//!   phases) apart — the record's `improved`, from the run's one [`super::BestSoFar`], which
//!   the search also reads for its time to best;
//! * every message whose ‖Tzw‖∞ (`gamma`) is below the smallest one so far, so that
//!   `campaign trace`'s best ‖Tzw‖∞ is that of the full trace;
//! * a thinned sample of the rest: a message is a sample if its iteration count has reached the
//!   run's next point of a geometric grid (iterations 1, 2, 3, 5, 8, 12, 18, … when every point
//!   is sampled: each point [`SAMPLE_RATIO`] times the previous sample, rounded up) *and* at
//!   least [`SAMPLE_CPU_S`] CPU seconds have passed since the last message kept for any reason.
//!   Samples are therefore at most one per [`SAMPLE_CPU_S`] of the job's CPU time, and at most
//!   logarithmically many per run.
//!
//! Everything depends only on the messages offered (their phase, start, iteration, f, ‖Tzw‖∞ and
//! CPU seconds), so the same messages give the same trace. The last message of a run is only
//! known to be the last when the next one arrives (or the job ends: [`SparseFilter::finish`]), so
//! the filter holds the latest message it did not keep and releases it then; messages come out
//! in the order they went in.

use crate::design::{DesignIterRecord, Phase};

/// Least CPU time between two thinned samples (seconds of the job's CPU clock).
pub const SAMPLE_CPU_S: f64 = 0.25;
/// Growth of the geometric grid of thinned samples within a run.
pub const SAMPLE_RATIO: f64 = 1.5;
/// Resolution of the kept improvements: a new best is kept when it lies at least this much
/// (relative) below the last best kept; the others are held, and the last of them is written
/// when its run ends (or before the next message written).
pub const IMPROVE_RTOL: f64 = 1e-3;

/// Where a run stands: what identifies it and the last iteration count seen.
#[derive(Debug, Clone, Copy, PartialEq)]
struct RunPos {
    phase: Phase,
    start: usize,
    iter: usize,
}

impl RunPos {
    fn of(rec: &DesignIterRecord) -> Self {
        RunPos { phase: rec.phase, start: rec.start, iter: rec.iter }
    }

    /// Whether `rec` starts a new run after this one.
    fn ends_before(&self, rec: &DesignIterRecord) -> bool {
        self.phase != rec.phase || self.start != rec.start || rec.iter <= self.iter
    }

    /// Whether `rec` goes on in this run's phase and start (so, if it starts a new run, only
    /// its iteration count shows it).
    fn same_search(&self, rec: &DesignIterRecord) -> bool {
        self.phase == rec.phase && self.start == rec.start
    }
}

/// Index of a phase among the three (for the phases seen).
fn phase_index(p: Phase) -> usize {
    match p {
        Phase::Stabilisation => 0,
        Phase::Optimisation => 1,
        Phase::GradientSampling => 2,
    }
}

/// One value whose records (new lowest values) the filter follows: f of one objective, or
/// ‖Tzw‖∞.
#[derive(Debug, Clone, Copy)]
struct Record {
    /// Lowest value offered.
    best: f64,
    /// Lowest value kept as an [`Keep::Improvement`].
    kept: f64,
}

/// What a new value is to a [`Record`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Lowers {
    /// Not below the best.
    No,
    /// Below the best, but within [`IMPROVE_RTOL`] of the last one kept.
    Slightly,
    /// Below the last one kept by at least [`IMPROVE_RTOL`] (relative).
    Clearly,
}

impl Record {
    const NONE: Record = Record { best: f64::INFINITY, kept: f64::INFINITY };

    /// Offers `x`, a new lowest value if `lower` (for ‖Tzw‖∞: [`Self::offer`]; for f: the
    /// record's `improved`, from the run's [`super::BestSoFar`]).
    fn offer_lower(&mut self, x: f64, lower: bool) -> Lowers {
        if !lower {
            return Lowers::No;
        }
        self.best = x;
        if self.kept.is_finite() && x > self.kept - IMPROVE_RTOL * self.kept.abs() {
            return Lowers::Slightly;
        }
        self.kept = x;
        Lowers::Clearly
    }

    /// Offers `x`: a new lowest value if it is finite and below the best so far.
    fn offer(&mut self, x: f64) -> Lowers {
        self.offer_lower(x, x.is_finite() && x < self.best)
    }
}

/// The roles of a message not (yet) kept: the reasons it may still have to be written.
mod role {
    /// The latest message of its run: written if the next one starts a new run.
    pub const LAST: u8 = 1;
    /// The lowest stabilisation objective so far.
    pub const STAB_RECORD: u8 = 2;
    /// The lowest performance objective so far.
    pub const PERF_RECORD: u8 = 4;
    /// The lowest ‖Tzw‖∞ so far.
    pub const GAMMA_RECORD: u8 = 8;
}

/// The sparse level's filter: see the module doc. `T` is what the caller writes for a message
/// (the trace writer: the record with its sequence number and time).
#[derive(Debug)]
pub struct SparseFilter<T> {
    /// The previous message offered.
    last: Option<RunPos>,
    /// Messages not kept that may still have to be written, in order, with their roles (each
    /// role held by one message at most, so at most four).
    held: Vec<(T, u8)>,
    /// Stabilisation objective, performance objective, ‖Tzw‖∞.
    records: [Record; 3],
    /// Iteration count the current run's next sample must have reached.
    next_sample_iter: usize,
    /// CPU seconds of the last message kept.
    last_kept_cpu_s: f64,
    /// Phases of the messages offered so far (by [`phase_index`]).
    seen: [bool; 3],
}

impl<T> Default for SparseFilter<T> {
    fn default() -> Self {
        SparseFilter {
            last: None,
            held: Vec::new(),
            records: [Record::NONE; 3],
            next_sample_iter: 1,
            last_kept_cpu_s: f64::NEG_INFINITY,
            seen: [false; 3],
        }
    }
}

/// Why the filter writes a message.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Keep {
    /// First message of a run, where it is kept (module doc): the job's first, the first of a
    /// phase, of a gradient-sampling run, or of a run in the same phase and start as the one
    /// before.
    RunStart,
    /// Lowers the best objective of its kind, or the smallest ‖Tzw‖∞, by at least
    /// [`IMPROVE_RTOL`] since the last one kept.
    Improvement,
    /// A thinned sample.
    Sample,
    /// Held, then written: the last message of its run, or the latest of the new lowest values
    /// that were not kept as improvements.
    Held,
}

impl<T> SparseFilter<T> {
    /// A filter that has seen nothing.
    pub fn new() -> Self {
        Self::default()
    }

    /// Why `rec` is written now, if it is, and the roles it holds if it is not. `new_run`: it
    /// is the first message of a run; `start_kept`: one whose first message is kept. Updates the
    /// records and the sample clock.
    fn judge(&mut self, rec: &DesignIterRecord, new_run: bool, start_kept: bool) -> Result<Keep, u8> {
        let (slot, f_role) = match rec.phase {
            Phase::Stabilisation => (0, role::STAB_RECORD),
            Phase::Optimisation | Phase::GradientSampling => (1, role::PERF_RECORD),
        };
        let f = self.records[slot].offer_lower(rec.f, rec.improved);
        let gamma = self.records[2].offer(rec.gamma);
        if new_run {
            self.next_sample_iter = 1;
        }
        let due = rec.iter >= self.next_sample_iter && rec.cpu_s >= self.last_kept_cpu_s + SAMPLE_CPU_S;
        let keep = if start_kept {
            Some(Keep::RunStart)
        } else if f == Lowers::Clearly || gamma == Lowers::Clearly {
            Some(Keep::Improvement)
        } else if due {
            Some(Keep::Sample)
        } else {
            None
        };
        if keep == Some(Keep::Sample) {
            let grown = (rec.iter.max(1) as f64 * SAMPLE_RATIO).ceil() as usize;
            self.next_sample_iter = grown.max(rec.iter + 1);
        }
        // The roles this message takes over (a message written takes them too: what it
        // supersedes need not be written).
        let mut roles = role::LAST;
        if f != Lowers::No {
            roles |= f_role;
        }
        if gamma != Lowers::No {
            roles |= role::GAMMA_RECORD;
        }
        for (_, r) in &mut self.held {
            *r &= !roles;
        }
        match keep {
            Some(k) => {
                self.last_kept_cpu_s = rec.cpu_s;
                Ok(k)
            }
            None => Err(roles),
        }
    }

    /// Moves the held messages that still have a role into `out`, in order.
    fn release(&mut self, out: &mut Vec<(T, Keep)>) {
        out.extend(self.held.drain(..).filter(|(_, r)| *r != 0).map(|(t, _)| (t, Keep::Held)));
    }

    /// Offers the next message (`rec`, written as `item`). Returns what to write now, in order:
    /// held messages that must be written before it (all, when `rec` starts a new run), then
    /// `item` if it is kept; an `item` not kept is held.
    pub fn push(&mut self, rec: &DesignIterRecord, item: T) -> Vec<T> {
        self.push_why(rec, item).into_iter().map(|(t, _)| t).collect()
    }

    /// [`Self::push`], with the reason each message is written.
    pub fn push_why(&mut self, rec: &DesignIterRecord, item: T) -> Vec<(T, Keep)> {
        let new_run = self.last.is_none_or(|l| l.ends_before(rec));
        let seen = &mut self.seen[phase_index(rec.phase)];
        let start_kept = new_run
            && (!*seen || rec.phase == Phase::GradientSampling || self.last.is_some_and(|l| l.same_search(rec)));
        *seen = true;
        self.last = Some(RunPos::of(rec));
        let mut out = Vec::new();
        if new_run {
            self.release(&mut out);
        }
        match self.judge(rec, new_run, start_kept) {
            Ok(why) => {
                self.release(&mut out);
                out.push((item, why));
            }
            Err(roles) => {
                self.held.retain(|(_, r)| *r != 0);
                self.held.push((item, roles));
            }
        }
        out
    }

    /// The job ended: the held messages still to be written (the last one offered among them),
    /// in order.
    pub fn finish(&mut self) -> Vec<T> {
        let mut out = Vec::new();
        self.release(&mut out);
        out.into_iter().map(|(t, _)| t).collect()
    }
}

#[cfg(test)]
mod tests {
    use super::super::{BestSoFar, Improvement};
    use super::*;
    use crate::optim::{Iteration, SolverKind};

    fn rec(phase: Phase, start: usize, iter: usize, f: f64, cpu_s: f64) -> DesignIterRecord {
        let it = Iteration { solver: SolverKind::Bfgs, start, iter, f, dnorm: 1.0, step: 1.0, evals: iter, cpu_s };
        let nan = f64::NAN;
        DesignIterRecord { phase, it, gamma: nan, k_hinf: nan, alpha_cl: nan, alpha_k: nan, improved: false }
    }

    /// `recs` with their `improved` as a run's [`BestSoFar`] sets it.
    fn tracked(recs: &[DesignIterRecord]) -> Vec<DesignIterRecord> {
        let mut best = BestSoFar::new();
        let improvement = |r: &DesignIterRecord| Improvement { f: r.f, cpu_s: r.cpu_s, evals: r.evals };
        recs.iter().map(|r| DesignIterRecord { improved: best.offer(r.phase, improvement(r)), ..r.clone() }).collect()
    }

    /// Runs `recs` through a filter: the indices written, in order, with why.
    fn written(recs: &[DesignIterRecord]) -> Vec<(usize, Keep)> {
        let recs = &tracked(recs);
        let mut f = SparseFilter::new();
        let mut out: Vec<(usize, Keep)> = recs.iter().enumerate().flat_map(|(i, r)| f.push_why(r, i)).collect();
        out.extend(f.finish().into_iter().map(|i| (i, Keep::Held)));
        out
    }

    fn kept(recs: &[DesignIterRecord]) -> Vec<usize> {
        let out: Vec<usize> = written(recs).into_iter().map(|(i, _)| i).collect();
        assert!(out.windows(2).all(|w| w[0] < w[1]), "out of order: {out:?}");
        out
    }

    /// A run of `n + 1` messages (iterations 0..=n) with values `f(i)`, CPU `dt` apart from `t0`.
    fn run(phase: Phase, start: usize, n: usize, t0: f64, dt: f64, f: impl Fn(usize) -> f64) -> Vec<DesignIterRecord> {
        (0..=n).map(|i| rec(phase, start, i, f(i), t0 + dt * i as f64)).collect()
    }

    #[test]
    fn improvements_are_kept_per_objective() {
        // Start 0 descends from 10 to 1; start 1 goes below 1 only from iteration 9 on; the
        // stabilisation values (negative) never count against the performance ones.
        let mut recs = run(Phase::Stabilisation, 0, 5, 0.0, 0.0, |i| 1.0 - i as f64);
        recs.extend(run(Phase::Optimisation, 0, 9, 0.0, 0.0, |i| 10.0 - i as f64));
        recs.extend(run(Phase::Stabilisation, 1, 5, 0.0, 0.0, |i| 0.5 - i as f64));
        recs.extend(run(Phase::Optimisation, 1, 12, 0.0, 0.0, |i| 9.0 - i as f64));
        let out = kept(&recs);
        let mut best = [f64::INFINITY; 2];
        for (i, r) in recs.iter().enumerate() {
            let b = &mut best[(r.phase != Phase::Stabilisation) as usize];
            if r.f < *b {
                *b = r.f;
                assert!(out.contains(&i), "improvement {i} ({r:?}) dropped: {out:?}");
            }
        }
        // No CPU time passes, so no samples: start 1's first iterations, above the best, go, its
        // first message too (the change from stabilisation to optimisation of a later start).
        let n = recs.len();
        assert_eq!(out.iter().filter(|&&i| i >= n - 13).count(), 4, "{out:?}");
    }

    #[test]
    fn small_improvements_are_thinned_but_the_lowest_value_is_always_written() {
        // f falls by 1.3e-5 (relative) per iteration, then flattens: one improvement kept per
        // IMPROVE_RTOL (about every 77 iterations), and the lowest value (before the flat tail)
        // written when the run ends.
        let f = |i: usize| if i <= 500 { 2.0 * (1.0 - 1.3e-5 * i as f64) } else { 2.0 * (1.0 - 5e-3) };
        let mut recs = run(Phase::Optimisation, 0, 800, 0.0, 0.0, f);
        recs.extend(run(Phase::Optimisation, 1, 3, 0.0, 0.0, |_| 3.0));
        let out = written(&recs);
        let improvements = out.iter().filter(|(_, k)| *k == Keep::Improvement).count();
        assert!((5..=7).contains(&improvements), "{out:?}");
        assert!(out.contains(&(500, Keep::Held)), "the lowest value: {out:?}");
        // The restart's first message (801) is not kept, its last is.
        assert!(out.contains(&(800, Keep::Held)) && out.contains(&(804, Keep::Held)), "{out:?}");
        assert_eq!(out.len(), 1 + improvements + 2 + 1, "{out:?}");
    }

    #[test]
    fn the_lowest_gamma_is_written_even_when_f_is_not_lower() {
        let mut recs = run(Phase::Optimisation, 0, 10, 0.0, 0.0, |i| if i == 0 { 1.0 } else { 2.0 });
        recs[3].gamma = 0.5;
        recs[6].gamma = 0.49999; // a new lowest value within IMPROVE_RTOL: held, then written
        recs[7].gamma = 0.7;
        assert_eq!(written(&recs), [(0, Keep::RunStart), (3, Keep::Improvement), (6, Keep::Held), (10, Keep::Held)]);
    }

    #[test]
    fn last_of_every_run_and_only_the_needed_firsts_are_kept() {
        let flat = |_: usize| 5.0;
        let mut recs = run(Phase::Stabilisation, 0, 20, 0.0, 0.0, |_| 1.0);
        recs.extend(run(Phase::Optimisation, 0, 30, 0.0, 0.0, flat));
        recs.extend(run(Phase::Optimisation, 1, 30, 0.0, 0.0, flat)); // a restart
        recs.extend(run(Phase::Optimisation, 1, 30, 0.0, 0.0, flat)); // same start, iterations restart
        recs.extend(run(Phase::GradientSampling, 1, 7, 0.0, 0.0, flat));
        recs.push(rec(Phase::GradientSampling, 1, 9, 5.0, 0.0)); // one more, a gap in the count
        recs.extend(run(Phase::Stabilisation, 2, 4, 0.0, 0.0, |_| 2.0)); // out of gradient sampling
        recs.extend(run(Phase::Optimisation, 2, 6, 0.0, 0.0, flat)); // a later start's optimisation
        recs.extend(run(Phase::GradientSampling, 0, 3, 0.0, 0.0, flat)); // a second gradient sampling
        let out = written(&recs);
        let lasts = [20, 51, 82, 113, 122, 127, 134, 138];
        // The job's first message, the first of the optimisation and gradient-sampling phases
        // and of every gradient-sampling run, and the first of the run that goes on in start 1
        // after its iteration count restarted; not those of the restart (52), of the run out of
        // gradient sampling (123) or of start 2's optimisation (128).
        let firsts = [0, 21, 83, 114, 135];
        let mut expected: Vec<usize> = firsts.iter().chain(&lasts).copied().collect();
        expected.sort_unstable();
        assert_eq!(out.iter().map(|(i, _)| *i).collect::<Vec<_>>(), expected, "{out:?}");
        for i in firsts {
            assert!(out.contains(&(i, Keep::RunStart)), "{i}: {out:?}");
        }
        for i in lasts {
            assert!(out.contains(&(i, Keep::Held)), "{i}: {out:?}");
        }
        // Every run boundary shows in what is kept: the last message before it and the first one
        // kept after it differ in phase or start, or the iteration count does not increase.
        let kept: Vec<&DesignIterRecord> = expected.iter().map(|&i| &recs[i]).collect();
        let boundaries = kept.windows(2).filter(|w| RunPos::of(w[0]).ends_before(w[1])).count();
        assert_eq!(boundaries, lasts.len() - 1);
    }

    #[test]
    fn the_last_message_is_released_at_finish() {
        let recs = run(Phase::Optimisation, 0, 100, 0.0, 0.0, |_| 3.0);
        let mut f = SparseFilter::new();
        let mut out = Vec::new();
        for (i, r) in tracked(&recs).iter().enumerate() {
            out.extend(f.push_why(r, i));
        }
        assert_eq!(out, [(0, Keep::RunStart)]);
        assert_eq!(f.finish(), [100]);
        assert!(f.finish().is_empty());
    }

    #[test]
    fn samples_are_bounded_by_cpu_time_and_by_a_geometric_grid() {
        let samples = |recs: &[DesignIterRecord]| -> Vec<usize> {
            written(recs).into_iter().filter(|(_, why)| *why == Keep::Sample).map(|(i, _)| i).collect()
        };
        // One long flat run, CPU time passing fast: the geometric grid bounds the samples.
        let n = 100_000;
        let recs = run(Phase::Optimisation, 0, n, 0.0, 1.0, |_| 1.0);
        let s = samples(&recs);
        let grid_bound = ((n as f64).ln() / SAMPLE_RATIO.ln()).ceil() as usize + 2;
        assert!(!s.is_empty() && s.len() <= grid_bound, "{} samples > {grid_bound}", s.len());
        assert!(s.windows(2).all(|w| w[1] as f64 >= w[0] as f64 * SAMPLE_RATIO - 1.0), "{s:?}");

        // Runs of 2000 iterations, CPU time passing slowly (2 s a run): the CPU interval bounds
        // the samples (the grid alone would allow about 20 a run).
        let dt = 1e-3;
        let mut recs = Vec::new();
        for start in 0..20 {
            recs.extend(run(Phase::Optimisation, start, 2000, recs.len() as f64 * dt, dt, |_| 1.0));
        }
        let total_cpu = recs.last().unwrap().cpu_s;
        let t: Vec<f64> = samples(&recs).into_iter().map(|i| recs[i].cpu_s).collect();
        assert!(t.len() >= 20, "{} samples", t.len());
        assert!(t.len() as f64 <= total_cpu / SAMPLE_CPU_S + 1.0, "{} samples", t.len());
        assert!(t.windows(2).all(|w| w[1] - w[0] >= SAMPLE_CPU_S), "{t:?}");
    }

    #[test]
    fn the_same_messages_give_the_same_selection() {
        let mut recs = Vec::new();
        for s in 0..20 {
            recs.extend(run(Phase::Optimisation, s, 40 + s, s as f64, 0.01, |i| {
                2.0 + ((i * 7 + s) % 11) as f64 / 10.0
            }));
        }
        assert_eq!(written(&recs), written(&recs));
    }
}
