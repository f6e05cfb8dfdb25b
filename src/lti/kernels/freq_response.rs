//! Fast evaluation of the frequency response G(iω) = C (iωI − A)⁻¹ B + D at many frequencies.
//!
//! A is reduced once to upper Hessenberg form A = Q H Qᵀ (faer's blocked Householder reduction,
//! O(n³)); then G(iω) = C̃ (iωI − H)⁻¹ B̃ + D with B̃ = QᵀB, C̃ = CQ, and each frequency costs one
//! complex Hessenberg solve, O(n²·m), by Gaussian elimination with adjacent-row partial
//! pivoting (backward stable, as for any GEPP on a Hessenberg matrix). This is the classical
//! Laub (1981) approach and what makes the many test frequencies of the level-set method cheap.
//! From order [`HESSENBERG_QR_FROM`] on the solve runs on split real and imaginary parts
//! (`hessenberg_solve.rs`: the elimination and the back substitution vectorise). It
//! is the same elimination as the interleaved solve used below that order, with the back
//! substitution's sums reassociated, so the two agree to rounding, not bit for bit.

use std::cell::Cell;

use faer::dyn_stack::{MemBuffer, MemStack, StackReq};
use faer::linalg::evd::hessenberg;
use faer::linalg::householder;
use faer::{c64, Conj, Mat, MatRef, Par};

use super::hessenberg_qr::{hessenberg_eigenvalues, HESSENBERG_QR_FROM};
use super::hessenberg_solve::ShiftedHessenbergSolve;
use super::step_stats::{timed, Step};
use crate::lti::system::state_space::StateSpace;

/// G(iω) evaluator for one system (reusable buffers).
pub(crate) struct FreqResponse {
    n: usize,
    m: usize,
    p: usize,
    /// Upper Hessenberg H, row-major.
    h: Vec<f64>,
    /// B̃ = QᵀB, row-major n×m.
    bt: Vec<f64>,
    /// C̃ = CQ (p×n).
    ct: Mat<f64>,
    d: Mat<f64>,
    work: Vec<c64>,
    rhs: Vec<c64>,
    /// The last G(iω), p×m.
    g: Mat<c64>,
    /// From order [`HESSENBERG_QR_FROM`] on: the split-complex solve and Q.
    large: Option<Large>,
}

/// What [`FreqResponse`] keeps from order [`HESSENBERG_QR_FROM`] on.
struct Large {
    /// The split-complex solve (`hessenberg_solve.rs`).
    solver: ShiftedHessenbergSolve,
    /// C̃ row-major (p×n).
    ct: Vec<f64>,
    /// Q of A = Q H Qᵀ as faer's block Householder sequence: the reduced matrix (the reflectors
    /// below its subdiagonal) and the block factors.
    reflectors: Mat<f64>,
    factors: Mat<f64>,
}

impl FreqResponse {
    /// Reduces A to Hessenberg form and transforms B, C (entries assumed finite).
    pub(crate) fn new(sys: &StateSpace) -> Self {
        timed(Step::Hessenberg, || Self::reduce(sys))
    }

    /// [`Self::new`] without the step count.
    fn reduce(sys: &StateSpace) -> Self {
        let (n, m, p) = (sys.order(), sys.inputs(), sys.outputs());
        let mut hm = sys.a.clone();
        let mut bt = sys.b.clone();
        let mut ct = sys.c.clone();
        let mut hh = Mat::<f64>::zeros(0, 0);
        if n > 2 {
            let par = Par::Seq;
            let bs = faer::linalg::qr::no_pivoting::factor::recommended_block_size::<f64>(n - 1, n - 1).max(1);
            hh = Mat::<f64>::zeros(bs, n - 1);
            let req = StackReq::any_of(&[
                hessenberg::hessenberg_in_place_scratch::<f64>(n, bs, par, Default::default()),
                householder::apply_block_householder_sequence_transpose_on_the_left_in_place_scratch::<f64>(
                    n - 1,
                    bs,
                    m,
                ),
                householder::apply_block_householder_sequence_on_the_right_in_place_scratch::<f64>(n - 1, bs, p),
            ]);
            let mut mem = MemBuffer::new(req);
            let stack = MemStack::new(&mut mem);
            hessenberg::hessenberg_in_place(hm.as_mut(), hh.as_mut(), par, stack, Default::default());
            let basis = hm.as_ref().submatrix(1, 0, n - 1, n - 1);
            if m > 0 {
                householder::apply_block_householder_sequence_transpose_on_the_left_in_place_with_conj(
                    basis,
                    hh.as_ref(),
                    Conj::No,
                    bt.as_mut().subrows_mut(1, n - 1),
                    par,
                    stack,
                );
            }
            if p > 0 {
                householder::apply_block_householder_sequence_on_the_right_in_place_with_conj(
                    basis,
                    hh.as_ref(),
                    Conj::No,
                    ct.as_mut().subcols_mut(1, n - 1),
                    par,
                    stack,
                );
            }
        }
        let mut h = vec![0.0; n * n];
        for i in 0..n {
            for j in i.saturating_sub(1)..n {
                h[i * n + j] = hm[(i, j)];
            }
        }
        let btv = (0..n * m).map(|k| bt[(k / m, k % m)]).collect();
        let large = (n >= HESSENBERG_QR_FROM).then(|| Large {
            solver: ShiftedHessenbergSolve::new(n, m),
            ct: (0..p * n).map(|k| ct[(k / n, k % n)]).collect(),
            reflectors: hm,
            factors: hh,
        });
        FreqResponse {
            n,
            m,
            p,
            h,
            bt: btv,
            ct: ct.clone(),
            d: sys.d.clone(),
            work: vec![c64::new(0.0, 0.0); n * n],
            rhs: vec![c64::new(0.0, 0.0); n * m],
            g: Mat::zeros(p, m),
            large,
        }
    }

    /// The eigenvalues of A (the poles), from the Hessenberg form H by our Francis QR
    /// (`hessenberg_qr.rs`). H is an orthogonal similarity of A by the same backward-stable
    /// reduction that faer's eigensolver starts with, so they are as accurate as faer's, for one
    /// Hessenberg reduction instead of two when the response is needed anyway. `None`
    /// if the QR does not converge.
    pub(crate) fn poles(&self) -> Option<Vec<c64>> {
        timed(Step::Poles, || self.poles_uncounted())
    }

    /// [`Self::poles`] without the step count.
    fn poles_uncounted(&self) -> Option<Vec<c64>> {
        hessenberg_eigenvalues(&mut self.hessenberg_column_major(), self.n).ok()
    }

    /// The Hessenberg form H of A, column-major (zero below the subdiagonal).
    pub(crate) fn hessenberg_column_major(&self) -> Vec<f64> {
        let n = self.n;
        let mut h = vec![0.0; n * n];
        for i in 0..n {
            for j in i.saturating_sub(1)..n {
                h[i + j * n] = self.h[i * n + j];
            }
        }
        h
    }

    /// G(iω) (p×m); D for ω = +∞. Entries are +∞ if iωI − H is exactly singular.
    pub(crate) fn eval(&mut self, w: f64) -> MatRef<'_, c64> {
        let (n, m, p) = (self.n, self.m, self.p);
        for i in 0..p {
            for j in 0..m {
                self.g[(i, j)] = c64::new(self.d[(i, j)], 0.0);
            }
        }
        if w.is_infinite() || n == 0 {
            return self.g.as_ref();
        }
        if let Some(Large { solver, ct, .. }) = &mut self.large {
            let (xr, xi) = solver.solve(&self.h, &self.bt, w);
            // G = D + C̃X, summed in the interleaved path's order.
            for i in 0..p {
                let row = &ct[i * n..(i + 1) * n];
                for c in 0..m {
                    let (mut re, mut im) = (self.d[(i, c)], 0.0);
                    for (k, &ctk) in row.iter().enumerate() {
                        re += xr[c * n + k] * ctk;
                        im += xi[c * n + k] * ctk;
                    }
                    self.g[(i, c)] = c64::new(re, im);
                }
            }
            return self.g.as_ref();
        }
        // T = iωI − H (upper Hessenberg, row-major), rhs = B̃.
        let t = &mut self.work;
        let x = &mut self.rhs;
        for i in 0..n {
            let lo = i.saturating_sub(1);
            for j in lo..n {
                t[i * n + j] = c64::new(-self.h[i * n + j], 0.0);
            }
            t[i * n + i].im += w;
        }
        for (xk, &b) in x[..n * m].iter_mut().zip(&self.bt[..n * m]) {
            *xk = c64::new(b, 0.0);
        }
        // Elimination with adjacent-row pivoting: after step k rows k+1.. are Hessenberg again.
        for k in 0..n.saturating_sub(1) {
            let (r0, r1) = (k * n, (k + 1) * n);
            if t[r1 + k].norm_sqr() > t[r0 + k].norm_sqr() {
                for j in k..n {
                    t.swap(r0 + j, r1 + j);
                }
                for c in 0..m {
                    x.swap(k * m + c, (k + 1) * m + c);
                }
            }
            let piv = t[r0 + k];
            if piv == c64::new(0.0, 0.0) {
                continue; // singular; caught in the back substitution
            }
            let l = t[r1 + k] / piv;
            if l != c64::new(0.0, 0.0) {
                t[r1 + k] = c64::new(0.0, 0.0);
                for j in k + 1..n {
                    let v = t[r0 + j];
                    t[r1 + j] -= l * v;
                }
                for c in 0..m {
                    let v = x[k * m + c];
                    x[(k + 1) * m + c] -= l * v;
                }
            }
        }
        for k in (0..n).rev() {
            let piv = t[k * n + k];
            for c in 0..m {
                let mut s = x[k * m + c];
                for j in k + 1..n {
                    s -= t[k * n + j] * x[j * m + c];
                }
                x[k * m + c] = if piv == c64::new(0.0, 0.0) { c64::new(f64::INFINITY, 0.0) } else { s / piv };
            }
        }
        for i in 0..p {
            for c in 0..m {
                let mut s = self.g[(i, c)];
                for k in 0..n {
                    s += x[k * m + c] * self.ct[(i, k)];
                }
                self.g[(i, c)] = s;
            }
        }
        self.g.as_ref()
    }

    /// a = (iωI − A)⁻ᴴ Cᵀ u and b = (iωI − A)⁻¹ B v for complex u (p) and v (m) and finite ω:
    /// the vectors of the H∞ gradient (`gradient.rs`), through the Hessenberg form instead of a
    /// dense complex LU of iωI − A (O(n²) instead of O(n³)); `None` below order
    /// [`HESSENBERG_QR_FROM`] (no Q kept there) or if iωI − H is exactly singular.
    ///
    /// With iωI − A = Q(iωI − H)Qᵀ, B̃ = QᵀB and C̃ = CQ: b = Q b̃ with (iωI − H) b̃ = B̃v, and
    /// a = Q ã with (iωI − H)ᴴ ã = C̃ᵀu. Conjugated, the second is (iωI − Hᵀ) ā = C̃ᵀū, and with
    /// the reversal R (R Hᵀ R is upper Hessenberg) it is solved as (iωI − RHᵀR)(Rā) = RC̃ᵀū by
    /// the same split solve. A complex right-hand side is solved as its real and imaginary parts.
    pub(crate) fn transfer_vectors(&self, w: f64, u: &[c64], v: &[c64]) -> Option<(Vec<c64>, Vec<c64>)> {
        let large = self.large.as_ref()?;
        let (n, m, p) = (self.n, self.m, self.p);
        let mut solver = ShiftedHessenbergSolve::new(n, 2);
        // B̃v, row-major n×2 (Re, Im).
        let mut rhs = vec![0.0; 2 * n];
        for k in 0..n {
            let row = &self.bt[k * m..(k + 1) * m];
            let bv = row.iter().zip(v).fold(c64::new(0.0, 0.0), |s, (&b, &vj)| s + vj * b);
            (rhs[2 * k], rhs[2 * k + 1]) = (bv.re, bv.im);
        }
        let b_tilde = split_solution(solver.solve(&self.h, &rhs, w), n, false)?;
        // R C̃ᵀū and R Hᵀ R (row-major: (RHᵀR)(i, j) = H(n−1−j, n−1−i)).
        for k in 0..n {
            let col = n - 1 - k;
            let ctu = (0..p).fold(c64::new(0.0, 0.0), |s, r| s + u[r].conj() * large.ct[r * n + col]);
            (rhs[2 * k], rhs[2 * k + 1]) = (ctu.re, ctu.im);
        }
        let h_rev: Vec<f64> = (0..n * n).map(|k| self.h[(n - 1 - k % n) * n + (n - 1 - k / n)]).collect();
        let mut a_tilde = split_solution(solver.solve(&h_rev, &rhs, w), n, true)?;
        a_tilde.reverse();
        // Back to the coordinates of A: columns Re ã, Im ã, Re b̃, Im b̃ times Q.
        let mut cols = Mat::<f64>::from_fn(n, 4, |i, j| match j {
            0 => a_tilde[i].re,
            1 => a_tilde[i].im,
            2 => b_tilde[i].re,
            _ => b_tilde[i].im,
        });
        if n > 2 {
            let bs = large.factors.nrows();
            let req = householder::apply_block_householder_sequence_on_the_left_in_place_scratch::<f64>(n - 1, bs, 4);
            let mut mem = MemBuffer::new(req);
            householder::apply_block_householder_sequence_on_the_left_in_place_with_conj(
                large.reflectors.as_ref().submatrix(1, 0, n - 1, n - 1),
                large.factors.as_ref(),
                Conj::No,
                cols.as_mut().subrows_mut(1, n - 1),
                Par::Seq,
                MemStack::new(&mut mem),
            );
        }
        let a = (0..n).map(|i| c64::new(cols[(i, 0)], cols[(i, 1)])).collect();
        let b = (0..n).map(|i| c64::new(cols[(i, 2)], cols[(i, 3)])).collect();
        Some((a, b))
    }

    /// The order n of the system.
    pub(crate) fn order(&self) -> usize {
        self.n
    }

    /// σmax(G(iω)) (+∞ if not finite).
    pub(crate) fn sigma_max(&mut self, w: f64) -> f64 {
        timed(Step::FreqEval, || {
            let s = sigma_max_c(self.eval(w));
            if s.is_finite() {
                s
            } else {
                f64::INFINITY
            }
        })
    }
}

/// The complex solution x = X₀ + iX₁ of a right-hand side solved as its real (column 0) and
/// imaginary (column 1) parts (`ShiftedHessenbergSolve::solve`'s Re X, Im X), conjugated if
/// `conj`; `None` if not finite.
fn split_solution((xr, xi): (&[f64], &[f64]), n: usize, conj: bool) -> Option<Vec<c64>> {
    let sign = if conj { -1.0 } else { 1.0 };
    let x: Vec<c64> = (0..n).map(|k| c64::new(xr[k] - xi[n + k], sign * (xi[k] + xr[n + k]))).collect();
    x.iter().all(|z| z.re.is_finite() && z.im.is_finite()).then_some(x)
}

/// One frequency-response evaluator kept for the next H∞ computation on the same system: the
/// line-search screen ([`hinf_lower_bound_sharing`](crate::lti::hinf_lower_bound_sharing)) leaves
/// the closed loop's Hessenberg form here, and the norm of a trial that passes the screen
/// ([`closed_loop_hinf_grad`](crate::lti::closed_loop_hinf_grad) with
/// [`HinfParams::reuse`](crate::lti::HinfParams::reuse)) takes it instead of reducing A again
/// (the reduction is one of the largest steps of a norm at large order). Taken only for a bitwise
/// identical system, and the evaluator's buffers are overwritten before they are read, so the
/// results are exactly those of a fresh one.
#[derive(Default)]
pub struct ResponseSlot {
    kept: Cell<Option<(StateSpace, FreqResponse)>>,
}

impl ResponseSlot {
    /// The evaluator of `sys` if one is kept (and empties the slot either way).
    pub(crate) fn take_for(&self, sys: &StateSpace) -> Option<FreqResponse> {
        self.kept.take().filter(|(kept, _)| same_bits(kept, sys)).map(|(_, fr)| fr)
    }

    /// Empties the slot.
    pub(crate) fn clear(&self) {
        self.kept.take();
    }

    /// Keeps the evaluator `fr` of `sys`.
    pub(crate) fn keep(&self, sys: &StateSpace, fr: FreqResponse) {
        self.kept.set(Some((sys.clone(), fr)));
    }
}

impl std::fmt::Debug for ResponseSlot {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("ResponseSlot")
    }
}

/// Whether two systems have the same dimensions and bitwise the same entries.
fn same_bits(x: &StateSpace, y: &StateSpace) -> bool {
    let eq = |a: &Mat<f64>, b: &Mat<f64>| {
        a.nrows() == b.nrows()
            && a.ncols() == b.ncols()
            && (0..a.ncols()).all(|j| (0..a.nrows()).all(|i| a[(i, j)].to_bits() == b[(i, j)].to_bits()))
    };
    eq(&x.a, &y.a) && eq(&x.b, &y.b) && eq(&x.c, &y.c) && eq(&x.d, &y.d)
}

/// The eigenvalues of a finite square matrix by [`FreqResponse::new`]'s Hessenberg reduction and
/// our Francis QR: bit for bit [`FreqResponse::poles`] of any system with this A, so the
/// stability decision and the H∞ norm's poles agree exactly. `None` if the QR does not converge.
pub(crate) fn hessenberg_qr_eigenvalues(a: MatRef<'_, f64>) -> Option<Vec<c64>> {
    of_matrix(a).poles()
}

/// The frequency response of the system with this A and no inputs or outputs: its Hessenberg
/// form (and poles).
pub(crate) fn of_matrix(a: MatRef<'_, f64>) -> FreqResponse {
    let n = a.nrows();
    let sys = StateSpace { a: a.to_owned(), b: Mat::zeros(n, 0), c: Mat::zeros(0, n), d: Mat::zeros(0, 0) };
    FreqResponse::new(&sys)
}

/// Largest singular value of a small complex matrix (closed forms for vectors and 2-column or
/// 2-row matrices, faer's SVD otherwise). NaN if the SVD fails.
pub(crate) fn sigma_max_c(g: MatRef<'_, c64>) -> f64 {
    let (p, m) = (g.nrows(), g.ncols());
    if p == 0 || m == 0 {
        return 0.0;
    }
    if p == 1 || m == 1 {
        let mut s = 0.0;
        for j in 0..m {
            for i in 0..p {
                s += g[(i, j)].norm_sqr();
            }
        }
        return s.sqrt();
    }
    if m == 2 || p == 2 {
        // Gram matrix of the two columns (or rows): [a b; b̄ d], λmax = (a+d)/2 + √(((a−d)/2)² + |b|²).
        let (mut a, mut d, mut b) = (0.0, 0.0, c64::new(0.0, 0.0));
        if m == 2 {
            for i in 0..p {
                let (x, y) = (g[(i, 0)], g[(i, 1)]);
                a += x.norm_sqr();
                d += y.norm_sqr();
                b += x.conj() * y;
            }
        } else {
            for j in 0..m {
                let (x, y) = (g[(0, j)], g[(1, j)]);
                a += x.norm_sqr();
                d += y.norm_sqr();
                b += x.conj() * y;
            }
        }
        let half = 0.5 * (a - d);
        let lam = 0.5 * (a + d) + (half * half + b.norm_sqr()).sqrt();
        return lam.sqrt();
    }
    match g.singular_values() {
        Ok(s) => s.into_iter().fold(0.0, f64::max),
        Err(_) => f64::NAN,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::linalg::solvers::Solve;

    fn direct(sys: &StateSpace, w: f64) -> Mat<c64> {
        let n = sys.order();
        let z = Mat::<c64>::from_fn(n, n, |i, j| c64::new(-sys.a[(i, j)], if i == j { w } else { 0.0 }));
        let b = Mat::<c64>::from_fn(n, sys.inputs(), |i, j| c64::new(sys.b[(i, j)], 0.0));
        let x = z.partial_piv_lu().solve(&b);
        Mat::from_fn(sys.outputs(), sys.inputs(), |i, j| {
            let mut s = c64::new(sys.d[(i, j)], 0.0);
            for k in 0..n {
                s += x[(k, j)] * sys.c[(i, k)];
            }
            s
        })
    }

    /// Uniform numbers in [−½, ½) from a 64-bit LCG (Knuth's MMIX constants), seeded.
    fn uniform(mut seed: u64) -> impl FnMut() -> f64 {
        move || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        }
    }

    /// A system of order n with m inputs and p outputs, entries from `rnd`.
    fn random_system(rnd: &mut impl FnMut() -> f64, n: usize, m: usize, p: usize) -> StateSpace {
        StateSpace {
            a: Mat::from_fn(n, n, |_, _| rnd()),
            b: Mat::from_fn(n, m, |_, _| rnd()),
            c: Mat::from_fn(p, n, |_, _| rnd()),
            d: Mat::from_fn(p, m, |_, _| rnd()),
        }
    }

    /// From order 30 on the split solve gives the interleaved solve's G(iω) to rounding.
    #[test]
    fn split_solve_agrees_with_the_interleaved_solve() {
        let mut rnd = uniform(11);
        for &(n, m, p) in &[(30, 1, 3), (45, 2, 4), (83, 3, 2)] {
            let sys = random_system(&mut rnd, n, m, p);
            let mut split = FreqResponse::new(&sys);
            assert!(split.large.is_some());
            let mut interleaved = FreqResponse::new(&sys);
            interleaved.large = None;
            for &w in &[0.0, 0.3, 2.0, 17.0] {
                let (g1, g2) = (split.eval(w).to_owned(), interleaved.eval(w).to_owned());
                let scale = (0..m)
                    .flat_map(|j| (0..p).map(move |i| (i, j)))
                    .map(|(i, j)| g2[(i, j)].norm())
                    .fold(0.0, f64::max);
                for j in 0..m {
                    for i in 0..p {
                        let diff = (g1[(i, j)] - g2[(i, j)]).norm();
                        assert!(diff <= 1e-13 * scale, "n={n} w={w}: {diff:e} against |G| = {scale:e}");
                    }
                }
            }
        }
    }

    #[test]
    fn hessenberg_matches_direct_solve() {
        let mut rnd = uniform(7);
        for &(n, m, p) in &[(1, 1, 1), (2, 2, 3), (7, 3, 2), (40, 2, 2), (90, 4, 3)] {
            let sys = random_system(&mut rnd, n, m, p);
            let mut fr = FreqResponse::new(&sys);
            for &w in &[0.0, 0.3, 2.0, 17.0] {
                let g1 = fr.eval(w).to_owned();
                let g2 = direct(&sys, w);
                let err = (&g1 - &g2).norm_l2() / g2.norm_l2();
                assert!(err < 1e-11, "n={n} w={w} err={err}");
                let s1 = sigma_max_c(g1.as_ref());
                let s2 = g2.singular_values().unwrap()[0];
                assert!((s1 - s2).abs() <= 1e-12 * s2, "{s1} vs {s2}");
            }
        }
    }
}
