//! Eigenvalues (no vectors) of a real upper Hessenberg matrix by the Francis double-shift QR
//! iteration.
//!
//! Written by hand because faer 0.24 keeps its Hessenberg QR (`multishift_qr`) crate-private:
//! its public `evd_real` always starts with a Hessenberg reduction, which is wasted work when the
//! matrix is already Hessenberg (the W of the square-reduced method, `square_reduced.rs`) or its
//! Hessenberg form is computed anyway (the frequency response's, `freq_response.rs`): at the
//! orders of BDT2's and CM4's closed loops that second reduction was a measurable part of a
//! design run.
//!
//! # Method
//! J. G. F. Francis, "The QR transformation", Computer Journal 4 (1961–62); Golub & Van Loan,
//! *Matrix Computations* (4th ed.), Alg. 7.5.1 (Francis QR step) and 7.5.2 (the QR iteration),
//! with the refinements of LAPACK's `dlahqr` (values-only variant):
//! * **Deflation**: a subdiagonal entry h_{k,k−1} is set to zero when it is negligible next to its
//!   diagonal neighbours, |h_{k,k−1}| ≤ ε(|h_{k−1,k−1}| + |h_{kk}|), refined by the test of
//!   Ahues & Tisseur (LAPACK Working Note 122, 1997), which keeps small eigenvalues of graded
//!   matrices accurate.
//! * **Shifts**: the eigenvalues of the trailing 2×2 block of the active window (the double
//!   shift; two real ones are replaced by the one closer to h_{ii}, taken twice). Every 10th
//!   iteration without a deflation uses an *exceptional shift* (alternating between the bottom and
//!   the top of the window) to break cycles.
//! * **Where the bulge starts**: the step starts below any pair of consecutive small subdiagonal
//!   entries (GVL §7.5.6 / `dlahqr`), which the shifted first column then barely couples.
//! * **Values only**: no Schur vectors and no full Schur form are wanted, so each step updates only
//!   the active window (rows and columns l..=i) rather than the whole matrix: about half the
//!   flops of a Schur-form computation.
//! * 1×1 blocks give real eigenvalues; 2×2 blocks are split by the standardisation of `dlanv2`
//!   (a rotation making the diagonal equal), which computes a complex pair or two real
//!   eigenvalues without cancellation.
//!
//! Backward stable: the computed eigenvalues are exact for H + E with ‖E‖ = O(ε‖H‖), as for
//! faer's solver. At most [`ITERATIONS_PER_EIGENVALUE`]·max(10, n) iterations (the limit of
//! `dlahqr`); beyond that a [`HessenbergQrError`], never a panic or an endless loop.

use faer::c64;
use pulp::{Arch, Simd, WithSimd};

/// From this size n on, the H∞ computation takes its eigenvalues from this QR (the closed loop's
/// poles from the frequency response's Hessenberg form, the square-reduced method's W directly);
/// below it from faer's `evd_real`, whose rounding the small plants' design results (the smoke
/// campaign's table) were obtained with. The same size as the square-reduced method's switch to
/// faer's kernels.
pub(crate) const HESSENBERG_QR_FROM: usize = 30;
/// The iteration limit is this many times max(10, n) (as in LAPACK's `dlahqr`).
pub(crate) const ITERATIONS_PER_EIGENVALUE: usize = 30;
/// An exceptional shift every this many iterations without a deflation (`dlahqr`'s KEXSH).
const EXCEPTIONAL_SHIFT_EVERY: usize = 10;
/// The exceptional shift's coefficients (`dlahqr`'s DAT1, DAT2).
const EXCEPTIONAL_DIAG: f64 = 0.75;
const EXCEPTIONAL_OFF: f64 = -0.4375;

/// The QR iteration did not converge within its iteration limit.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("Hessenberg QR: no convergence after {iterations} iterations ({converged} of {n} eigenvalues found)")]
pub(crate) struct HessenbergQrError {
    /// The matrix size.
    pub n: usize,
    /// Eigenvalues found before giving up.
    pub converged: usize,
    /// The iteration limit that was reached.
    pub iterations: usize,
}

/// The eigenvalues of the n×n upper Hessenberg matrix stored column-major in `h` (h[i + j·n] =
/// H(i, j); entries below the first subdiagonal are ignored). `h` is overwritten. A complex
/// conjugate pair is returned as (λ, λ̄) with Im λ > 0 first. The entries must be finite.
pub(crate) fn hessenberg_eigenvalues(h: &mut [f64], n: usize) -> Result<Vec<c64>, HessenbergQrError> {
    hessenberg_eigenvalues_capped(h, n, ITERATIONS_PER_EIGENVALUE * n.max(10))
}

/// [`hessenberg_eigenvalues`] with an explicit iteration limit.
///
/// Compiled for the best instruction set the processor has (pulp's run-time dispatch, as the
/// PVL kernels in `pvl_update.rs`): with AVX2 the column updates of the reflections run four
/// lanes wide. The code makes no use of fused multiply-adds or reordered sums, so every
/// instruction set gives the same result bit for bit.
fn hessenberg_eigenvalues_capped(h: &mut [f64], n: usize, max_iters: usize) -> Result<Vec<c64>, HessenbergQrError> {
    Arch::new().dispatch(Iteration { h, n, max_iters })
}

/// [`hessenberg_eigenvalues_capped`] for one instruction set.
struct Iteration<'a> {
    h: &'a mut [f64],
    n: usize,
    max_iters: usize,
}

impl WithSimd for Iteration<'_> {
    type Output = Result<Vec<c64>, HessenbergQrError>;

    #[inline(always)]
    fn with_simd<S: Simd>(self, _: S) -> Self::Output {
        let Iteration { h, n, max_iters } = self;
        francis_iteration(h, n, max_iters)
    }
}

/// The double-shift iteration (module docs); inlined into each instruction set's copy.
#[inline(always)]
fn francis_iteration(h: &mut [f64], n: usize, max_iters: usize) -> Result<Vec<c64>, HessenbergQrError> {
    assert_eq!(h.len(), n * n, "hessenberg_eigenvalues: storage does not match the size");
    let mut ev = vec![c64::new(0.0, 0.0); n];
    if n == 0 {
        return Ok(ev);
    }
    // Entries below the subdiagonal are read by the first bulge-chasing step: clear them.
    for j in 0..n {
        for i in j + 2..n {
            h[i + j * n] = 0.0;
        }
    }
    let ulp = f64::EPSILON;
    let smlnum = f64::MIN_POSITIVE * (n as f64 / ulp);
    let mut qr = Window { h, n };
    // Iterations since the last deflation (selects the exceptional shifts).
    let mut since_deflation = 0usize;
    // i: the bottom of the active window; everything below it has converged.
    let mut i = n - 1;
    loop {
        let mut l = 0;
        let mut deflated = false;
        for _ in 0..=max_iters {
            l = qr.small_subdiagonal(l, i, ulp, smlnum);
            if l > 0 {
                qr.set(l, l - 1, 0.0);
            }
            if l + 1 >= i {
                deflated = true;
                break;
            }
            since_deflation += 1;
            let shifts = qr.shifts(l, i, since_deflation);
            let (m, v) = qr.bulge_start(l, i, shifts, ulp);
            qr.double_shift_step(l, m, i, v);
        }
        if !deflated {
            let converged = n - 1 - i;
            return Err(HessenbergQrError { n, converged, iterations: max_iters });
        }
        if l == i {
            ev[i] = c64::new(qr.at(i, i), 0.0);
        } else {
            let [a, b] = eigenvalues_2x2(qr.at(i - 1, i - 1), qr.at(i - 1, i), qr.at(i, i - 1), qr.at(i, i));
            ev[i - 1] = a;
            ev[i] = b;
        }
        since_deflation = 0;
        if l == 0 {
            return Ok(ev);
        }
        i = l - 1;
    }
}

/// The two shifts of a double-shift step as real and imaginary parts (a complex pair has
/// `im1 = −im2`; two real shifts are equal).
#[derive(Clone, Copy)]
struct Shifts {
    re1: f64,
    im1: f64,
    re2: f64,
    im2: f64,
}

/// The Hessenberg matrix being iterated on (column-major).
struct Window<'a> {
    h: &'a mut [f64],
    n: usize,
}

impl Window<'_> {
    #[inline(always)]
    fn at(&self, i: usize, j: usize) -> f64 {
        self.h[i + j * self.n]
    }

    #[inline(always)]
    fn set(&mut self, i: usize, j: usize, x: f64) {
        self.h[i + j * self.n] = x;
    }

    /// The largest k in l+1..=i whose subdiagonal entry h_{k,k−1} is negligible (dlahqr's test,
    /// module docs), or l if there is none.
    #[inline(always)]
    fn small_subdiagonal(&self, l: usize, i: usize, ulp: f64, smlnum: f64) -> usize {
        let mut k = i;
        while k > l {
            let sub = self.at(k, k - 1).abs();
            if sub <= smlnum {
                return k;
            }
            let mut tst = self.at(k - 1, k - 1).abs() + self.at(k, k).abs();
            if tst == 0.0 {
                if k >= 2 {
                    tst += self.at(k - 1, k - 2).abs();
                }
                if k + 1 < self.n {
                    tst += self.at(k + 1, k).abs();
                }
            }
            if sub <= ulp * tst {
                // Ahues & Tisseur's refinement.
                let up = self.at(k - 1, k).abs();
                let (ab, ba) = (sub.max(up), sub.min(up));
                let diff = (self.at(k - 1, k - 1) - self.at(k, k)).abs();
                let hkk = self.at(k, k).abs();
                let (aa, bb) = (hkk.max(diff), hkk.min(diff));
                let s = aa + ab;
                if ba * (ab / s) <= smlnum.max(ulp * (bb * (aa / s))) {
                    return k;
                }
            }
            k -= 1;
        }
        l
    }

    /// The double shift for the window l..=i (l + 1 < i): the trailing 2×2 block's eigenvalues,
    /// or an exceptional shift every [`EXCEPTIONAL_SHIFT_EVERY`] iterations without deflation.
    #[inline(always)]
    fn shifts(&self, l: usize, i: usize, since_deflation: usize) -> Shifts {
        let (h11, h12, h21, h22);
        if since_deflation.is_multiple_of(2 * EXCEPTIONAL_SHIFT_EVERY) {
            let s = self.at(i, i - 1).abs() + self.at(i - 1, i - 2).abs();
            h11 = EXCEPTIONAL_DIAG * s + self.at(i, i);
            (h12, h21, h22) = (EXCEPTIONAL_OFF * s, s, h11);
        } else if since_deflation.is_multiple_of(EXCEPTIONAL_SHIFT_EVERY) {
            let s = self.at(l + 1, l).abs() + self.at(l + 2, l + 1).abs();
            h11 = EXCEPTIONAL_DIAG * s + self.at(l, l);
            (h12, h21, h22) = (EXCEPTIONAL_OFF * s, s, h11);
        } else {
            (h11, h12, h21, h22) = (self.at(i - 1, i - 1), self.at(i - 1, i), self.at(i, i - 1), self.at(i, i));
        }
        let s = h11.abs() + h12.abs() + h21.abs() + h22.abs();
        if s == 0.0 {
            return Shifts { re1: 0.0, im1: 0.0, re2: 0.0, im2: 0.0 };
        }
        let (h11, h12, h21, h22) = (h11 / s, h12 / s, h21 / s, h22 / s);
        let tr = 0.5 * (h11 + h22);
        let det = (h11 - tr) * (h22 - tr) - h12 * h21;
        let rtdisc = det.abs().sqrt();
        if det >= 0.0 {
            // A complex conjugate pair.
            Shifts { re1: tr * s, im1: rtdisc * s, re2: tr * s, im2: -rtdisc * s }
        } else {
            // Two real shifts: use the one closer to h22 twice.
            let (r1, r2) = (tr + rtdisc, tr - rtdisc);
            let r = if (r1 - h22).abs() <= (r2 - h22).abs() { r1 } else { r2 };
            Shifts { re1: r * s, im1: 0.0, re2: r * s, im2: 0.0 }
        }
    }

    /// Where the bulge starts: the largest m in l..=i−2 below which two consecutive subdiagonal
    /// entries are small enough to decouple the step (GVL §7.5.6), with the first column of
    /// (H − σ₁I)(H − σ₂I) restricted to rows m..m+2, scaled.
    #[inline(always)]
    fn bulge_start(&self, l: usize, i: usize, sh: Shifts, ulp: f64) -> (usize, [f64; 3]) {
        let mut m = i - 2;
        loop {
            let hmm = self.at(m, m);
            let h21s = self.at(m + 1, m);
            let s = (hmm - sh.re2).abs() + sh.im2.abs() + h21s.abs();
            let h21s = h21s / s;
            let mut v = [
                h21s * self.at(m, m + 1) + (hmm - sh.re1) * ((hmm - sh.re2) / s) - sh.im1 * (sh.im2 / s),
                h21s * (hmm + self.at(m + 1, m + 1) - sh.re1 - sh.re2),
                h21s * self.at(m + 2, m + 1),
            ];
            let s = v[0].abs() + v[1].abs() + v[2].abs();
            v.iter_mut().for_each(|x| *x /= s);
            if m == l {
                return (m, v);
            }
            let h00 = self.at(m, m - 1).abs() * (v[1].abs() + v[2].abs());
            let h01 = v[0].abs() * (self.at(m - 1, m - 1).abs() + hmm.abs() + self.at(m + 1, m + 1).abs());
            if h00 <= ulp * h01 {
                return (m, v);
            }
            m -= 1;
        }
    }

    /// One Francis double-shift step on the window l..=i, the bulge introduced at row m with the
    /// first-column vector `v` and chased to the bottom by 3×3 (last: 2×2) Householder
    /// reflections (GVL Alg. 7.5.1). Only rows and columns l..=i are updated (values only).
    #[inline(always)]
    fn double_shift_step(&mut self, l: usize, m: usize, i: usize, mut v: [f64; 3]) {
        let n = self.n;
        for k in m..i {
            let nr = 3.min(i - k + 1);
            if k > m {
                for (r, x) in v.iter_mut().enumerate().take(nr) {
                    *x = self.at(k + r, k - 1);
                }
            }
            let (beta, tau) = householder(v[0], &mut v[1..nr]);
            if k > m {
                self.set(k, k - 1, beta);
                self.set(k + 1, k - 1, 0.0);
                if k + 1 < i {
                    self.set(k + 2, k - 1, 0.0);
                }
            } else if m > l {
                // (1 − τ)·h instead of −h: correct also when v₂, v₃ underflow (dlahqr).
                let x = self.at(k, k - 1) * (1.0 - tau);
                self.set(k, k - 1, x);
            }
            if tau == 0.0 {
                continue;
            }
            let (v2, t1) = (v[1], tau);
            let t2 = t1 * v2;
            let last_row = (k + 3).min(i);
            if nr == 3 {
                let v3 = v[2];
                let t3 = t1 * v3;
                // Rows k..k+2, columns k..=i.
                for col in self.h[k * n..(i + 1) * n].chunks_exact_mut(n) {
                    let x = &mut col[k..k + 3];
                    let sum = x[0] + v2 * x[1] + v3 * x[2];
                    x[0] -= sum * t1;
                    x[1] -= sum * t2;
                    x[2] -= sum * t3;
                }
                // Columns k..k+2, rows l..=min(k+3, i).
                let (c0, rest) = self.h[k * n..(k + 3) * n].split_at_mut(n);
                let (c1, c2) = rest.split_at_mut(n);
                for ((a, b), c) in c0[l..=last_row].iter_mut().zip(&mut c1[l..=last_row]).zip(&mut c2[l..=last_row]) {
                    let sum = *a + v2 * *b + v3 * *c;
                    *a -= sum * t1;
                    *b -= sum * t2;
                    *c -= sum * t3;
                }
            } else {
                for col in self.h[k * n..(i + 1) * n].chunks_exact_mut(n) {
                    let x = &mut col[k..k + 2];
                    let sum = x[0] + v2 * x[1];
                    x[0] -= sum * t1;
                    x[1] -= sum * t2;
                }
                let (c0, c1) = self.h[k * n..(k + 2) * n].split_at_mut(n);
                for (a, b) in c0[l..=i].iter_mut().zip(&mut c1[l..=i]) {
                    let sum = *a + v2 * *b;
                    *a -= sum * t1;
                    *b -= sum * t2;
                }
            }
        }
    }
}

/// Entries of this size range can be squared and summed without overflow or harmful underflow.
const SAFE_SQUARES_MIN: f64 = 1e-150;
const SAFE_SQUARES_MAX: f64 = 1e150;

/// An elementary reflector P = I − τ[1; x̂][1; x̂]ᵀ with P[α; x] = [β; 0] (LAPACK `dlarfg`): `x`
/// is overwritten with x̂; returns (β, τ), τ = 0 (P = I) when x = 0.
#[inline(always)]
fn householder(alpha: f64, x: &mut [f64]) -> (f64, f64) {
    // Norms by plain sums of squares when no square can overflow or matter by underflowing
    // (|entries| within 1e±150: an underflowed square is below ε² of the largest), else by
    // hypot (libm's hypot was 8 % of a BDT2 design run).
    let big = x.iter().fold(alpha.abs(), |b, t| b.max(t.abs()));
    let (xnorm, full) = if (SAFE_SQUARES_MIN..=SAFE_SQUARES_MAX).contains(&big) {
        let ss: f64 = x.iter().map(|t| t * t).sum();
        (ss.sqrt(), (alpha * alpha + ss).sqrt())
    } else {
        let xnorm = x.iter().fold(0.0f64, |s, &t| s.hypot(t));
        (xnorm, alpha.hypot(xnorm))
    };
    if xnorm == 0.0 {
        return (alpha, 0.0);
    }
    let mut alpha = alpha;
    let mut xnorm = xnorm;
    let mut beta = -full.copysign(alpha);
    // Rescale if β would be tiny (dlarfg), so that 1/(α − β) is accurate.
    let safmin = f64::MIN_POSITIVE / f64::EPSILON;
    let mut rescaled = 0;
    while beta.abs() < safmin && rescaled < 20 {
        rescaled += 1;
        x.iter_mut().for_each(|t| *t /= safmin);
        beta /= safmin;
        alpha /= safmin;
        xnorm /= safmin;
    }
    if rescaled > 0 {
        beta = -alpha.hypot(xnorm).copysign(alpha);
    }
    let tau = (beta - alpha) / beta;
    let scale = 1.0 / (alpha - beta);
    x.iter_mut().for_each(|t| *t *= scale);
    for _ in 0..rescaled {
        beta *= safmin;
    }
    (beta, tau)
}

/// The eigenvalues of the real 2×2 matrix [a b; c d] by LAPACK's `dlanv2` standardisation (a
/// rotation making the diagonal equal, or the matrix triangular): a complex pair (Im > 0 first)
/// or two real values, computed without cancellation.
#[inline(always)]
fn eigenvalues_2x2(a: f64, b: f64, c: f64, d: f64) -> [c64; 2] {
    let (mut a, mut b, mut c, mut d) = (a, b, c, d);
    const MULTPL: f64 = 4.0;
    let eps = f64::EPSILON;
    // 2^-485 = base^(log_base(safmin/eps)/2) (dlanv2's SAFMN2).
    let safmn2 = 2f64.powi(-485);
    let safmx2 = 1.0 / safmn2;
    let sign = |x: f64| if x >= 0.0 { 1.0 } else { -1.0 };
    if c == 0.0 {
    } else if b == 0.0 {
        // Swap rows and columns.
        std::mem::swap(&mut a, &mut d);
        b = -c;
        c = 0.0;
    } else if (a - d) == 0.0 && sign(b) != sign(c) {
    } else {
        let temp = a - d;
        let mut p = 0.5 * temp;
        let bcmax = b.abs().max(c.abs());
        let bcmis = b.abs().min(c.abs()) * sign(b) * sign(c);
        let scale = p.abs().max(bcmax);
        let z = (p / scale) * p + (bcmax / scale) * bcmis;
        if z >= MULTPL * eps {
            // Real eigenvalues.
            let z = p + (scale.sqrt() * z.sqrt()).copysign(p);
            a = d + z;
            d -= (bcmax / z) * bcmis;
            b -= c;
            c = 0.0;
        } else {
            // Complex or nearly equal real eigenvalues: make the diagonal entries equal.
            let mut sigma = b + c;
            let mut temp = temp;
            for _ in 0..=20 {
                let scale = temp.abs().max(sigma.abs());
                if scale >= safmx2 {
                    sigma *= safmn2;
                    temp *= safmn2;
                } else if scale <= safmn2 {
                    sigma *= safmx2;
                    temp *= safmx2;
                } else {
                    break;
                }
            }
            p = 0.5 * temp;
            let tau = sigma.hypot(temp);
            let cs = (0.5 * (1.0 + sigma.abs() / tau)).sqrt();
            let sn = -(p / (tau * cs)) * sign(sigma);
            // [aa bb; cc dd] = [a b; c d]·[cs −sn; sn cs], then [a b; c d] = [cs sn; −sn cs]·(·).
            let (aa, bb) = (a * cs + b * sn, -a * sn + b * cs);
            let (cc, dd) = (c * cs + d * sn, -c * sn + d * cs);
            b = bb * cs + dd * sn;
            c = -aa * sn + cc * cs;
            let temp = 0.5 * ((aa * cs + cc * sn) + (-bb * sn + dd * cs));
            a = temp;
            d = temp;
            if c != 0.0 {
                if b != 0.0 {
                    if sign(b) == sign(c) {
                        // Real eigenvalues after all.
                        let p = (b.abs().sqrt() * c.abs().sqrt()).copysign(c);
                        a = temp + p;
                        d = temp - p;
                        b -= c;
                        c = 0.0;
                    }
                } else {
                    b = -c;
                    c = 0.0;
                }
            }
        }
    }
    if c == 0.0 {
        [c64::new(a, 0.0), c64::new(d, 0.0)]
    } else {
        let im = b.abs().sqrt() * c.abs().sqrt();
        [c64::new(a, im), c64::new(d, -im)]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, StandardNormal};

    /// faer's eigenvalues of a dense matrix (the reference; `lti::eigenvalues_of` uses this QR
    /// from n = HESSENBERG_QR_FROM on).
    fn reference(a: &Mat<f64>) -> Vec<c64> {
        a.eigenvalues().unwrap()
    }

    /// Ours, from faer's Hessenberg reduction of `a` (or of `a` itself if it is Hessenberg).
    fn ours(a: &Mat<f64>) -> Vec<c64> {
        let n = a.nrows();
        let mut h: Vec<f64> = (0..n * n).map(|k| a[(k % n, k / n)]).collect();
        hessenberg_eigenvalues(&mut h, n).unwrap()
    }

    fn hessenberg_part(a: &Mat<f64>) -> Mat<f64> {
        Mat::from_fn(a.nrows(), a.ncols(), |i, j| if i <= j + 1 { a[(i, j)] } else { 0.0 })
    }

    /// Largest distance from each eigenvalue of `got` to its partner in `want` (greedy nearest
    /// unused match; both are multisets of the same size).
    fn spectrum_distance(got: &[c64], want: &[c64]) -> f64 {
        assert_eq!(got.len(), want.len());
        let mut used = vec![false; want.len()];
        let mut worst = 0.0f64;
        for g in got {
            let (k, d) = want
                .iter()
                .enumerate()
                .filter(|(k, _)| !used[*k])
                .map(|(k, w)| (k, (g - w).norm()))
                .fold((usize::MAX, f64::INFINITY), |b, x| if x.1 < b.1 { x } else { b });
            used[k] = true;
            worst = worst.max(d);
        }
        worst
    }

    fn random(n: usize, seed: u64) -> Mat<f64> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        Mat::from_fn(n, n, |_, _| StandardNormal.sample(&mut rng))
    }

    fn check(h: &Mat<f64>, rel_tol: f64, what: &str) {
        let got = ours(h);
        let want = reference(h);
        let norm = h.norm_l2().max(f64::MIN_POSITIVE);
        let d = spectrum_distance(&got, &want);
        assert!(
            d <= rel_tol * norm,
            "{what}: n = {}: distance {d:e} > {rel_tol:e}·‖H‖ = {:e}",
            h.nrows(),
            rel_tol * norm
        );
        // Conjugate pairs come as (λ, λ̄), Im λ > 0 first, so the imaginary parts sum to zero.
        let im: f64 = got.iter().map(|z| z.im).sum();
        assert!(im.abs() <= 1e-10 * norm, "{what}: unpaired complex eigenvalues");
        let trace: f64 = (0..h.nrows()).map(|i| h[(i, i)]).sum();
        let sum: f64 = got.iter().map(|z| z.re).sum();
        assert!((trace - sum).abs() <= 1e-11 * norm * h.nrows() as f64, "{what}: trace {trace} vs Σλ {sum}");
    }

    #[test]
    fn random_hessenberg_matrices_match_faer() {
        for (n, seed) in [(1usize, 1u64), (2, 2), (3, 3), (4, 4), (7, 5), (20, 6), (64, 7), (150, 8)] {
            check(&hessenberg_part(&random(n, seed)), 1e-11, "random Hessenberg");
        }
    }

    #[test]
    fn badly_scaled_and_graded_matrices_match_faer() {
        for (n, seed) in [(6usize, 21u64), (30, 22), (80, 23)] {
            // Graded: H(i, j)·10^(−(i + j)/2)... from 1 down to ~1e-12 along the diagonal.
            let g = |i: usize| 10f64.powf(-12.0 * i as f64 / n as f64);
            let a = random(n, seed);
            let graded = hessenberg_part(&Mat::from_fn(n, n, |i, j| a[(i, j)] * g(i) * g(j)));
            check(&graded, 1e-11, "graded");
            // Badly scaled: a diagonal similarity with entries 10^±3 (no balancing here, as in
            // faer): ours and faer's agree relative to the scaled matrix's size.
            let s = |i: usize| 10f64.powf(if i.is_multiple_of(2) { 3.0 } else { -3.0 });
            let scaled = hessenberg_part(&Mat::from_fn(n, n, |i, j| a[(i, j)] * s(i) / s(j)));
            check(&scaled, 1e-9, "badly scaled");
        }
    }

    #[test]
    fn nearly_defective_and_structured_matrices() {
        // A Jordan block of size 4 at −1 (transposed, so Hessenberg) with 1e-10 in the corner:
        // eigenvalues −1 + 1e-2.5·(4th roots of unity), ε^(1/4)-sensitive in general but here
        // ~1e-9 (the perturbation is far above rounding); compared with faer to 1e-6.
        let n = 4;
        let mut j = Mat::from_fn(n, n, |i, k| {
            if i == k {
                -1.0
            } else if i == k + 1 {
                1.0
            } else {
                0.0
            }
        });
        j[(0, n - 1)] = 1e-10;
        check(&j, 1e-6, "perturbed Jordan block");
        for z in ours(&j) {
            assert!(((z + 1.0).norm() - 10f64.powf(-2.5)).abs() <= 1e-8, "Jordan: {z}");
        }
        // Companion matrix of (x−1)(x−2)(x−3)(x−4)(x−5), upper Hessenberg.
        let coeffs = [-120.0, 274.0, -225.0, 85.0, -15.0]; // x⁵ + c₄x⁴ + … + c₀
        let n = 5;
        let comp = Mat::from_fn(n, n, |i, k| {
            if i == 0 {
                -coeffs[n - 1 - k]
            } else if i == k + 1 {
                1.0
            } else {
                0.0
            }
        });
        let mut got: Vec<f64> = ours(&comp).iter().map(|z| z.re).collect();
        got.sort_by(f64::total_cmp);
        for (k, g) in got.iter().enumerate() {
            assert!((g - (k + 1) as f64).abs() <= 1e-9, "companion root {k}: {g}");
        }
        // Zero matrix, diagonal matrix, a rotation (purely imaginary pair), already triangular.
        assert!(ours(&Mat::zeros(5, 5)).iter().all(|z| *z == c64::new(0.0, 0.0)));
        let rot = Mat::from_fn(2, 2, |i, k| [[0.0, -2.0], [2.0, 0.0]][i][k]);
        let r = ours(&rot);
        assert!((r[0] - c64::new(0.0, 2.0)).norm() <= 4.0 * f64::EPSILON, "{r:?}");
        assert!((r[1] - c64::new(0.0, -2.0)).norm() <= 4.0 * f64::EPSILON, "{r:?}");
        let tri = Mat::from_fn(6, 6, |i, k| if i <= k { (i + 1) as f64 + k as f64 * 0.1 } else { 0.0 });
        check(&tri, 1e-13, "triangular");
        // Block diagonal with many 2×2 rotation blocks: exact pairs ±iω.
        let n = 40;
        let rots = Mat::from_fn(n, n, |i, k| {
            let w = 1.0 + (i / 2) as f64;
            match (i % 2, k as isize - i as isize) {
                (0, 1) => w,
                (1, -1) => -w,
                _ => 0.0,
            }
        });
        check(&rots, 1e-13, "rotation blocks");
    }

    #[test]
    fn dense_matrices_through_faers_hessenberg_reduction() {
        // The use in freq_response.rs: faer's Hessenberg form of a dense matrix, then our QR.
        for (n, seed) in [(31usize, 41u64), (83, 42)] {
            let a = random(n, seed);
            let sys =
                crate::lti::StateSpace { a: a.clone(), b: Mat::zeros(n, 1), c: Mat::zeros(1, n), d: Mat::zeros(1, 1) };
            let got = crate::lti::kernels::freq_response::FreqResponse::new(&sys).poles().unwrap();
            let d = spectrum_distance(&got, &reference(&a));
            assert!(d <= 1e-10 * a.norm_l2(), "n = {n}: {d:e}");
        }
    }

    #[test]
    fn every_instruction_set_gives_the_same_bits() {
        // The dispatched iteration (AVX2 where the processor has it) against the same code
        // inlined here, compiled for the baseline instruction set.
        for (n, seed) in [(31usize, 51u64), (83, 52), (166, 53)] {
            let a = random(n, seed);
            let g = |i: usize| 10f64.powf(-8.0 * i as f64 / n as f64);
            for m in [hessenberg_part(&a), hessenberg_part(&Mat::from_fn(n, n, |i, j| a[(i, j)] * g(i) * g(j)))] {
                let h: Vec<f64> = (0..n * n).map(|k| m[(k % n, k / n)]).collect();
                let dispatched = hessenberg_eigenvalues(&mut h.clone(), n).unwrap();
                let baseline = francis_iteration(&mut h.clone(), n, ITERATIONS_PER_EIGENVALUE * n.max(10)).unwrap();
                let bits = |v: &[c64]| v.iter().flat_map(|z| [z.re.to_bits(), z.im.to_bits()]).collect::<Vec<_>>();
                assert_eq!(bits(&dispatched), bits(&baseline), "n = {n}");
            }
        }
    }

    #[test]
    fn two_by_two_blocks() {
        for (m, want) in [
            ([1.0, 2.0, 3.0, 4.0], [(5.372281323269014, 0.0), (-0.3722813232690143, 0.0)]),
            ([0.0, 1.0, -1.0, 0.0], [(0.0, 1.0), (0.0, -1.0)]),
            ([1.0, -5.0, 2.0, 1.0], [(1.0, 10f64.sqrt()), (1.0, -(10f64.sqrt()))]),
            ([3.0, 0.0, 7.0, -2.0], [(-2.0, 0.0), (3.0, 0.0)]),
            ([2.0, 1e-20, 1e-20, 2.0], [(2.0 + 1e-20, 0.0), (2.0 - 1e-20, 0.0)]),
        ] {
            let got = eigenvalues_2x2(m[0], m[1], m[2], m[3]);
            let mut got: Vec<(f64, f64)> = got.iter().map(|z| (z.re, z.im)).collect();
            let mut want = want.to_vec();
            let key = |a: &(f64, f64), b: &(f64, f64)| a.0.total_cmp(&b.0).then(b.1.total_cmp(&a.1));
            got.sort_by(key);
            want.sort_by(key);
            for (g, w) in got.iter().zip(&want) {
                assert!(
                    (g.0 - w.0).abs() <= 1e-14 * 6.0 && (g.1 - w.1).abs() <= 1e-14 * 6.0,
                    "{m:?}: {got:?} vs {want:?}"
                );
            }
        }
    }

    #[test]
    fn iteration_limit_is_an_error() {
        let n = 12;
        let a = hessenberg_part(&random(n, 99));
        let mut h: Vec<f64> = (0..n * n).map(|k| a[(k % n, k / n)]).collect();
        let err = hessenberg_eigenvalues_capped(&mut h, n, 1).unwrap_err();
        assert_eq!(err.n, n);
        assert!(err.converged < n);
        assert!(err.to_string().contains("no convergence"), "{err}");
    }
}
