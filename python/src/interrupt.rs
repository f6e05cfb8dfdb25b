//! Long calls off the GIL, stoppable with Ctrl-C.
//!
//! Python runs signal handlers only in its main thread, and `PyErr_CheckSignals` does nothing in
//! any other. So the work runs in a worker thread while the calling thread waits for it without
//! the GIL, waking every [`POLL`] to take the GIL and check for signals. A KeyboardInterrupt (or
//! any exception a signal handler raises) sets the run's cancel flag, the same flag the
//! `campaign` command's SIGINT handler sets: the design stops at its next check, inside an
//! evaluation of a large plant (docs/ALGORITHMS.md §5), and returns its best point so far. The
//! worker is always joined; the exception is then raised in place of the result.
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, RecvTimeoutError};
use std::sync::Arc;
use std::time::Duration;

use pyo3::prelude::*;

use crate::errors::HinfixError;

/// How often the waiting thread checks for signals.
const POLL: Duration = Duration::from_millis(20);

/// Stack of the worker thread: as a main thread's (the `campaign` command runs designs there).
const STACK_BYTES: usize = 8 << 20;

/// Runs `work(cancel)` in a worker thread, the GIL released, until it returns. A signal handler's
/// exception (KeyboardInterrupt) sets `cancel` and is returned once `work` has returned; a panic
/// of `work` is a `HinfixError` with its message.
pub fn run_interruptible<T: Send>(
    py: Python<'_>,
    cancel: Arc<AtomicBool>,
    work: impl FnOnce(&AtomicBool) -> T + Send,
) -> PyResult<T> {
    run_interruptible_with(py, cancel, work, |_, _| Ok(()))
}

/// As [`run_interruptible`], calling `on_poll(py, done)` in the calling thread with the GIL at
/// each poll (`done` false) and once after `work` has returned (`done` true): where a progress
/// callback runs, so that what it prints goes where the caller's output goes (a Jupyter cell).
/// An exception of `on_poll` is handled as a signal handler's: the run is cancelled and the
/// exception raised once `work` has returned.
pub fn run_interruptible_with<T: Send>(
    py: Python<'_>,
    cancel: Arc<AtomicBool>,
    work: impl FnOnce(&AtomicBool) -> T + Send,
    mut on_poll: impl FnMut(Python<'_>, bool) -> PyResult<()>,
) -> PyResult<T> {
    let (tx, rx) = channel();
    let flag = Arc::clone(&cancel);
    std::thread::scope(|s| {
        std::thread::Builder::new()
            .name("hinfix".into())
            .stack_size(STACK_BYTES)
            .spawn_scoped(s, move || {
                let _ = tx.send(catch_unwind(AssertUnwindSafe(|| work(&flag))));
            })
            .map_err(|e| HinfixError::new_err(format!("cannot start the worker thread: {e}")))?;
        let mut rx = rx;
        let mut raised: Option<PyErr> = None;
        let done = loop {
            let (back, got) = py.detach(move || {
                let got = rx.recv_timeout(POLL);
                (rx, got)
            });
            rx = back;
            match got {
                Ok(done) => break done,
                Err(RecvTimeoutError::Disconnected) => {
                    return Err(HinfixError::new_err("the worker thread ended without a result"))
                }
                Err(RecvTimeoutError::Timeout) => {}
            }
            if raised.is_none() {
                if let Err(e) = py.check_signals().and_then(|()| on_poll(py, false)) {
                    cancel.store(true, Ordering::SeqCst);
                    raised = Some(e);
                }
            }
        };
        if raised.is_none() && done.is_ok() {
            raised = on_poll(py, true).err();
        }
        match (raised, done) {
            (Some(e), _) => Err(e),
            (None, Ok(value)) => Ok(value),
            (None, Err(panic)) => Err(HinfixError::new_err(format!("internal error (panic): {}", panic_text(&*panic)))),
        }
    })
}

fn panic_text(p: &(dyn std::any::Any + Send)) -> String {
    p.downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| p.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "unknown".into())
}
