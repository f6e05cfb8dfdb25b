//! A cancellation hook for long computations: [`Interrupt`] is polled between the heavy steps of
//! the H∞ norm (before each dense eigenvalue problem, between frequency evaluations and level-set
//! iterations), so a CPU budget or a Ctrl-C takes effect inside one evaluation of a large plant
//! instead of after it. A single dense eigenvalue problem or LU factorisation is not split: the
//! delay after the hook fires is at most one such step (docs/ALGORITHMS.md §5).
//!
//! `lti` knows nothing of the optimiser: the hook is any `Fn() -> bool` (the design objective
//! passes "CPU budget spent or run cancelled"). An interrupted computation returns
//! [`Interrupted`], never a value from a half-finished computation.

/// A stop test polled between the heavy steps of a long computation; [`Interrupt::NEVER`] never
/// fires. Polling costs one call of the closure: keep it cheap (an atomic load, a clock read).
#[derive(Clone, Copy)]
pub struct Interrupt<'a> {
    check: Option<&'a dyn Fn() -> bool>,
}

impl Interrupt<'static> {
    /// A hook that never fires (the plain, uninterruptible computation).
    pub const NEVER: Interrupt<'static> = Interrupt { check: None };
}

impl<'a> Interrupt<'a> {
    /// A hook that fires once `stop()` returns true.
    pub fn new(stop: &'a dyn Fn() -> bool) -> Self {
        Interrupt { check: Some(stop) }
    }

    /// `Err(Interrupted)` if the hook fires now.
    pub fn poll(&self) -> Result<(), Interrupted> {
        match self.check {
            Some(stop) if stop() => Err(Interrupted),
            _ => Ok(()),
        }
    }
}

impl std::fmt::Debug for Interrupt<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(if self.check.is_some() { "Interrupt(hook)" } else { "Interrupt::NEVER" })
    }
}

/// A computation was abandoned because its [`Interrupt`] fired (budget spent or cancelled): no
/// value exists.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("computation interrupted (CPU budget spent or run cancelled)")]
pub struct Interrupted;

#[cfg(test)]
mod tests {
    use super::*;
    use std::cell::Cell;

    #[test]
    fn never_and_after_k_polls() {
        assert_eq!(Interrupt::NEVER.poll(), Ok(()));
        let polls = Cell::new(0);
        let stop = || {
            polls.set(polls.get() + 1);
            polls.get() > 2
        };
        let hook = Interrupt::new(&stop);
        assert_eq!(hook.poll(), Ok(()));
        assert_eq!(hook.poll(), Ok(()));
        assert_eq!(hook.poll(), Err(Interrupted));
    }
}
