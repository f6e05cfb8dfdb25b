//! Termination signals, handled in one place for every command: SIGINT (Ctrl-C), SIGTERM and
//! SIGHUP all set the run's cancel flag, so a design or a campaign stops at its next check,
//! writes what it has (summary, journal, best controller), removes its temporary files and
//! exits with 128 + the signal number (130, 143, 129). A second signal while the first is being
//! handled ends the process at once with that code.
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Arc, OnceLock};

use signal_hook::consts::{SIGHUP, SIGINT, SIGTERM};

/// The signals treated as a request to stop.
pub const STOP_SIGNALS: [i32; 3] = [SIGINT, SIGTERM, SIGHUP];

/// The signal received first (0 = none yet).
fn received() -> &'static Arc<AtomicUsize> {
    static R: OnceLock<Arc<AtomicUsize>> = OnceLock::new();
    R.get_or_init(|| Arc::new(AtomicUsize::new(0)))
}

/// Makes SIGINT, SIGTERM and SIGHUP set `cancel` (and a second one exit at once). Returns an
/// error only if the handlers cannot be registered.
pub fn install_into(cancel: &Arc<AtomicBool>) -> std::io::Result<()> {
    for sig in STOP_SIGNALS {
        // Registered first, so it sees the flag as it was before this signal: set means a
        // previous signal is already being handled.
        signal_hook::flag::register_conditional_shutdown(sig, 128 + sig, Arc::clone(cancel))?;
        signal_hook::flag::register(sig, Arc::clone(cancel))?;
        // Remember the first signal only (for the exit code).
        let r = Arc::clone(received());
        // SAFETY: the action only does an atomic compare-exchange, which is async-signal-safe.
        unsafe {
            signal_hook::low_level::register(sig, move || {
                let _ = r.compare_exchange(0, sig as usize, Ordering::SeqCst, Ordering::SeqCst);
            })?;
        }
    }
    Ok(())
}

/// A fresh cancel flag wired to the stop signals (see [`install_into`]); if the handlers cannot
/// be installed the flag simply never fires.
pub fn install() -> Arc<AtomicBool> {
    let cancel = Arc::new(AtomicBool::new(false));
    if let Err(e) = install_into(&cancel) {
        eprintln!("warning: cannot install the signal handlers ({e}); Ctrl-C will kill the process");
    }
    cancel
}

/// The exit code of a run stopped by a signal: 128 + the first signal received (130 if none
/// was recorded, e.g. a cancel from elsewhere).
pub fn exit_code() -> u8 {
    match received().load(Ordering::SeqCst) {
        0 => super::EXIT_INTERRUPTED,
        s => (128 + s).min(255) as u8,
    }
}

/// Restores the default action of SIGPIPE (the Rust runtime ignores it, so a closed pipe turns
/// `println!` into a panic): a printing command piped into `head` then ends quietly, as Unix
/// tools do, instead of panicking with "failed printing to stdout". Only for the commands that
/// print and write no files; `run`, `design` and `plot` keep their own clean-up on signals.
pub fn end_quietly_on_closed_stdout() {
    // SAFETY: setting a signal's disposition to SIG_DFL has no preconditions; it is done
    // before any thread is started.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}
