//! The C allocator's reuse of freed memory, tuned for the H∞ computation's allocation pattern.
//!
//! An objective evaluation on a large plant allocates and frees matrices of a few hundred kB to a
//! few MB many times (the Hamiltonian and its square, the pencil, the PVL and QR work arrays; CM4:
//! n + nK = 241, H² blocks of 464 kB, the pencil 1.9 MB). glibc serves blocks above its mmap
//! threshold (dynamic, from 128 kB) by `mmap` and returns them by `munmap`, and trims freed memory
//! at the top of the heap: every evaluation then faults in and zeroes fresh pages. Measured with
//! `perf`: 12 % of a BDT2 design run's CPU time in the kernel and 2 % in libc, 7 % on CM4.
//!
//! [`keep_freed_memory`] raises both thresholds so that freed blocks stay in the process and are
//! reused: the resident memory stays at the run's peak instead of shrinking between evaluations.
//! Measured (`campaign design --order 1 --eps 1e-3 --seed 1`, a fixed `--maxevals`, the same
//! controller either way): BDT2, 1500 evaluations, system time 1.1–1.25 s → 0.09–0.12 s of
//! ~10.5 s; CM4, 200 evaluations, 0.87–0.91 s → 0.05–0.06 s of ~15.4 s. User time unchanged.
//! Results do not depend on it (no computed value does), only the time. glibc on Linux only;
//! elsewhere it does nothing. The `campaign` binary and the benches call it at start.

/// Blocks up to this size come from the heap, not from `mmap` (glibc's largest allowed value on
/// 64-bit systems, 32 MiB).
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const MMAP_THRESHOLD: libc::c_int = 32 << 20;
/// Freed memory at the top of the heap is returned to the system only beyond this much.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
const TRIM_THRESHOLD: libc::c_int = 512 << 20;

/// Keep freed memory for reuse (module docs). Returns whether the allocator took the settings.
pub fn keep_freed_memory() -> bool {
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    {
        // SAFETY: mallopt only sets allocator parameters; both values are within glibc's ranges.
        unsafe {
            libc::mallopt(libc::M_MMAP_THRESHOLD, MMAP_THRESHOLD) == 1
                && libc::mallopt(libc::M_TRIM_THRESHOLD, TRIM_THRESHOLD) == 1
        }
    }
    #[cfg(not(all(target_os = "linux", target_env = "gnu")))]
    {
        false
    }
}

#[cfg(test)]
mod tests {
    /// glibc accepts both settings (they are within its documented ranges).
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    #[test]
    fn glibc_takes_the_settings() {
        assert!(super::keep_freed_memory());
    }
}
