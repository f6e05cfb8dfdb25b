//! Small numeric helpers shared by [`crate::lti`] and [`crate::optim`], and the crate's one CPU clock.
//!
//! They live here, below both layers, so that `lti` and `optim` stay independent of each other
//! (docs/ARCHITECTURE.md §1) while keeping one copy of each helper.

use faer::MatRef;

/// A number as people read it and programs read back: Rust's shortest round-trip form, in
/// scientific notation outside [1e-4, 1e16) (Rust's `{}` never uses an exponent: a sampling time
/// of 1e-200 s printed 200 zeros). `readable(x).parse::<f64>()` is `x` bit for bit, −0 included.
pub fn readable(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-4..1e16).contains(&x.abs()) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// Σᵢ aᵢbᵢ, summed left to right (over the shorter length if the lengths differ).
///
/// The summation order is part of the result's rounding, and the optimiser's iterates depend on
/// it bit for bit (same seed ⇒ same path), so it must not be changed casually. The H∞ level-set
/// reduction uses [`dot_four_lanes`] instead, where vectorisation matters.
pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// Σ xᵢyᵢ with four partial sums (lets the compiler vectorise the reduction), the remainder
/// added last. A different rounding from [`dot`]: used where speed matters and no iterate path
/// depends on the bits (the Householder reflections of the H∞ level-set reduction,
/// `lti::square_reduced`).
pub(crate) fn dot_four_lanes(x: &[f64], y: &[f64]) -> f64 {
    let mut acc = [0.0f64; 4];
    let (xc, yc) = (x.chunks_exact(4), y.chunks_exact(4));
    let (xr, yr) = (xc.remainder(), yc.remainder());
    for (a, b) in xc.zip(yc) {
        for k in 0..4 {
            acc[k] += a[k] * b[k];
        }
    }
    let mut s = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    for (a, b) in xr.iter().zip(yr) {
        s += a * b;
    }
    s
}

/// Σ_j (ar_j + i·ai_j)(br_j + i·bi_j) on split real and imaginary parts, in four partial sums
/// (lane l takes j ≡ l mod 4; the tail goes to lane 0) added as (s₀ + s₁) + (s₂ + s₃): the
/// complex counterpart of [`dot_four_lanes`] in one pass (the back substitution of
/// `lti::hessenberg_solve`; its tail, unlike there, joins lane 0 before the lanes are added).
#[inline(always)]
pub(crate) fn complex_dot_four_lanes(ar: &[f64], ai: &[f64], br: &[f64], bi: &[f64]) -> (f64, f64) {
    const L: usize = 4;
    let (mut pr, mut pi) = ([0.0f64; L], [0.0f64; L]);
    let (car, cai, cbr, cbi) = (ar.chunks_exact(L), ai.chunks_exact(L), br.chunks_exact(L), bi.chunks_exact(L));
    let rest = (car.remainder(), cai.remainder(), cbr.remainder(), cbi.remainder());
    for (((a_re, a_im), b_re), b_im) in car.zip(cai).zip(cbr).zip(cbi) {
        for l in 0..L {
            pr[l] += a_re[l] * b_re[l] - a_im[l] * b_im[l];
            pi[l] += a_re[l] * b_im[l] + a_im[l] * b_re[l];
        }
    }
    for j in 0..rest.0.len() {
        pr[0] += rest.0[j] * rest.2[j] - rest.1[j] * rest.3[j];
        pi[0] += rest.0[j] * rest.3[j] + rest.1[j] * rest.2[j];
    }
    ((pr[0] + pr[1]) + (pr[2] + pr[3]), (pi[0] + pi[1]) + (pi[2] + pi[3]))
}

/// Whether every entry of a matrix is finite (no NaN, no ±∞).
pub(crate) fn all_finite(m: MatRef<'_, f64>) -> bool {
    (0..m.ncols()).all(|j| (0..m.nrows()).all(|i| m[(i, j)].is_finite()))
}

/// CPU seconds used so far by the calling thread: `clock_gettime(CLOCK_THREAD_CPUTIME_ID)`.
///
/// The one CPU clock of the crate (the optimiser's budget, the campaign's per-job `cpu_s` and the
/// benches all read it). Callers only ever take differences of two readings.
///
/// # Failure
/// If the clock cannot be read (the call cannot fail on Linux or macOS with a valid pointer;
/// a platform without a per-thread CPU clock would fail every time), this returns `0.0`: the
/// clock then stands still, elapsed CPU reads 0 and a CPU budget is never exhausted (runs end by
/// `maxit`, convergence or cancellation instead). Every derived number stays finite, so
/// journal lines and traces remain valid; a NaN here would turn every budget test false as
/// well, but would also reach the journal and make `RunControl::cpu_remaining` report 0.
pub fn thread_cpu_time() -> f64 {
    let mut ts = libc::timespec { tv_sec: 0, tv_nsec: 0 };
    // SAFETY: `ts` is a valid, writable timespec; clock_gettime only writes into it.
    let rc = unsafe { libc::clock_gettime(libc::CLOCK_THREAD_CPUTIME_ID, &mut ts) };
    if rc != 0 {
        return 0.0;
    }
    ts.tv_sec as f64 + ts.tv_nsec as f64 * 1e-9
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dot_and_all_finite() {
        assert_eq!(dot(&[1.0, 2.0, 3.0], &[4.0, -5.0, 6.0]), 12.0);
        assert_eq!(dot(&[], &[]), 0.0);
        let x: Vec<f64> = (1..=7).map(f64::from).collect();
        assert_eq!(dot_four_lanes(&x, &x), 140.0);
        assert_eq!(dot_four_lanes(&x[..3], &x[..3]), 14.0);
        let mut m = faer::Mat::<f64>::zeros(2, 3);
        assert!(all_finite(m.as_ref()));
        assert!(all_finite(faer::Mat::<f64>::zeros(0, 4).as_ref()));
        m[(1, 2)] = f64::NAN;
        assert!(!all_finite(m.as_ref()));
        m[(1, 2)] = f64::NEG_INFINITY;
        assert!(!all_finite(m.as_ref()));
    }

    #[test]
    fn readable_numbers_are_short_and_round_trip() {
        assert_eq!(readable(0.01), "0.01");
        assert_eq!(readable(1e-200), "1e-200");
        assert_eq!(readable(2.5e200), "2.5e200");
        assert_eq!(readable(1234.5), "1234.5");
        assert_eq!(readable(f64::INFINITY), "inf");
        for x in [0.1, -1.0 / 3.0, 1e-300, 5e-324, 1e16, 9.99e15, 1e-4, 9.9e-5, -0.0, f64::MAX] {
            let back: f64 = readable(x).parse().unwrap();
            assert_eq!(back.to_bits(), x.to_bits(), "{x}");
            assert!(readable(x).len() <= 24, "{}", readable(x));
        }
    }

    /// The tests run in the release profile (`cargo test --release`), where Cargo.toml turns
    /// overflow checks on for this crate: integer overflow must panic, not wrap.
    #[test]
    fn integer_overflow_panics() {
        let zero = std::hint::black_box(0usize);
        assert!(std::panic::catch_unwind(|| zero - 1).is_err(), "overflow checks are off (see Cargo.toml)");
    }
}
