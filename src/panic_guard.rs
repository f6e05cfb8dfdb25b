//! Running a third-party parser that may panic on damaged input, with the panic turned into an
//! error ([`catch_quietly`]).
//!
//! Readers of outside input validate what they can themselves; this is the last resort for code
//! we do not own (the `mcap` and `matfile` readers index slices with lengths read from the file,
//! and a few overwritten bytes made them panic). The panic is caught with
//! [`std::panic::catch_unwind`] and its message returned; the process-wide panic hook stays quiet
//! for a panic caught here (the error that replaces it is the message a user sees) and prints
//! every other panic as before.

use std::cell::Cell;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::Once;

thread_local! {
    /// Whether this thread is inside [`catch_quietly`].
    static QUIET: Cell<bool> = const { Cell::new(false) };
}

/// Runs `f`; a panic inside it is `Err(message)` instead of unwinding further. `f` must leave
/// nothing half-updated that the caller reads after an `Err` (the callers parse into fresh
/// values and drop them on error).
pub fn catch_quietly<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    static HOOK: Once = Once::new();
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if !QUIET.with(Cell::get) {
                previous(info);
            }
        }));
    });
    let was = QUIET.with(|q| q.replace(true));
    let result = catch_unwind(AssertUnwindSafe(f));
    QUIET.with(|q| q.set(was));
    result.map_err(|payload| {
        payload
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| payload.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "unknown panic".into())
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_becomes_its_message() {
        let v: Vec<u8> = vec![1, 2];
        let n = 5;
        let e = catch_quietly(|| v[..n].len()).unwrap_err();
        assert!(e.contains("out of range"), "{e}");
        assert_eq!(catch_quietly(|| 3), Ok(3));
        assert_eq!(catch_quietly(|| panic!("{}", "boom".to_string())), Err::<(), _>("boom".into()));
    }
}
