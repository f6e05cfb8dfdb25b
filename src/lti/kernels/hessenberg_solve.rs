//! The solve (iωI − H) X = B̃ of the frequency response (`freq_response.rs`) for large orders,
//! with real and imaginary parts in separate arrays.
//!
//! The method is that of `FreqResponse::eval` (Gaussian elimination with adjacent-row partial
//! pivoting on the upper Hessenberg iωI − H, then back substitution; backward stable); only the
//! layout differs, for speed at large orders: a row update r₁ ← r₁ − l·r₀ on split real and imaginary parts is
//! independent per entry, and the compiler vectorises it where interleaved complex numbers kept it
//! scalar. The elimination has the interleaved solve's operations in its order; the back
//! substitution's sums run over four partial sums (`numeric::complex_dot_four_lanes`) so that they vectorise too,
//! which changes their rounding: the two solves agree to rounding, not bit for bit (the
//! interleaved one serves below order `HESSENBERG_QR_FROM`, this one from it on, so no system sees
//! both). On x86-64 CPUs with AVX2 (detected at run time) the same code is compiled for 256-bit
//! registers; without fused multiply–adds every lane rounds as the scalar code does, and the order
//! of every sum is fixed by the code, so both builds give the same bits.

use faer::c64;

use crate::numeric::complex_dot_four_lanes;

/// Work arrays and the result of [`ShiftedHessenbergSolve::solve`].
pub(crate) struct ShiftedHessenbergSolve {
    n: usize,
    m: usize,
    /// Re and Im of iωI − H during the elimination, row-major n×n.
    tr: Vec<f64>,
    ti: Vec<f64>,
    /// Re and Im of X, column-major n×m.
    xr: Vec<f64>,
    xi: Vec<f64>,
}

impl ShiftedHessenbergSolve {
    /// Buffers for order `n` and `m` right-hand sides.
    pub(crate) fn new(n: usize, m: usize) -> Self {
        ShiftedHessenbergSolve {
            n,
            m,
            tr: vec![0.0; n * n],
            ti: vec![0.0; n * n],
            xr: vec![0.0; n * m],
            xi: vec![0.0; n * m],
        }
    }

    /// Solves (iωI − H) X = B for H upper Hessenberg (row-major n×n; entries below the
    /// subdiagonal are not read) and B row-major n×m; returns Re X and Im X, column-major n×m.
    /// Entries are +∞ where iωI − H is exactly singular (as in `FreqResponse::eval`).
    pub(crate) fn solve(&mut self, h: &[f64], b: &[f64], w: f64) -> (&[f64], &[f64]) {
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx2") {
                // SAFETY: `solve_avx2` only requires AVX2, which the CPU was just found to have.
                unsafe { self.solve_avx2(h, b, w) };
                return (&self.xr, &self.xi);
            }
        }
        self.solve_any(h, b, w);
        (&self.xr, &self.xi)
    }

    /// [`Self::solve_any`] compiled for AVX2 (no FMA: the same bits as the baseline build).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn solve_avx2(&mut self, h: &[f64], b: &[f64], w: f64) {
        self.solve_any(h, b, w)
    }

    #[inline(always)]
    fn solve_any(&mut self, h: &[f64], b: &[f64], w: f64) {
        let (n, m) = (self.n, self.m);
        let (tr, ti, xr, xi) = (&mut self.tr, &mut self.ti, &mut self.xr, &mut self.xi);
        for i in 0..n {
            let lo = i.saturating_sub(1);
            for j in lo..n {
                tr[i * n + j] = -h[i * n + j];
                ti[i * n + j] = 0.0;
            }
            ti[i * n + i] = w;
        }
        for c in 0..m {
            for k in 0..n {
                xr[c * n + k] = b[k * m + c];
                xi[c * n + k] = 0.0;
            }
        }
        // Elimination with adjacent-row pivoting: after step k rows k+1.. are Hessenberg again.
        for k in 0..n.saturating_sub(1) {
            let (r0, r1) = (k * n, (k + 1) * n);
            let a = c64::new(tr[r0 + k], ti[r0 + k]);
            let s = c64::new(tr[r1 + k], ti[r1 + k]);
            if s.norm_sqr() > a.norm_sqr() {
                for t in [&mut *tr, &mut *ti] {
                    let (top, bottom) = t.split_at_mut(r1);
                    top[r0 + k..r0 + n].swap_with_slice(&mut bottom[k..n]);
                }
                for c in 0..m {
                    xr.swap(c * n + k, c * n + k + 1);
                    xi.swap(c * n + k, c * n + k + 1);
                }
            }
            let piv = c64::new(tr[r0 + k], ti[r0 + k]);
            if piv == c64::new(0.0, 0.0) {
                continue; // singular; caught in the back substitution
            }
            let l = c64::new(tr[r1 + k], ti[r1 + k]) / piv;
            if l == c64::new(0.0, 0.0) {
                continue;
            }
            tr[r1 + k] = 0.0;
            ti[r1 + k] = 0.0;
            let (tr0, tr1) = tr.split_at_mut(r1);
            let (ti0, ti1) = ti.split_at_mut(r1);
            let (lr, li) = (l.re, l.im);
            for (((y_re, y_im), &x_re), &x_im) in tr1[k + 1..n]
                .iter_mut()
                .zip(ti1[k + 1..n].iter_mut())
                .zip(&tr0[r0 + k + 1..r0 + n])
                .zip(&ti0[r0 + k + 1..r0 + n])
            {
                *y_re -= lr * x_re - li * x_im;
                *y_im -= lr * x_im + li * x_re;
            }
            for c in 0..m {
                let (x_re, x_im) = (xr[c * n + k], xi[c * n + k]);
                xr[c * n + k + 1] -= lr * x_re - li * x_im;
                xi[c * n + k + 1] -= lr * x_im + li * x_re;
            }
        }
        // Back substitution, row k: x_k = (y_k − Σ_{j>k} u_kj x_j) / u_kk. The sum runs over four
        // interleaved partial sums (lanes j ≡ k+1+l mod 4, added pairwise at the end) so that it
        // vectorises: the row of U and the column of X are both contiguous. The order of the
        // additions is fixed by the code, not by the CPU, so every build gives the same bits.
        for k in (0..n).rev() {
            let row = k * n;
            let piv = c64::new(tr[row + k], ti[row + k]);
            let (ur, ui) = (&tr[row + k + 1..row + n], &ti[row + k + 1..row + n]);
            for c in 0..m {
                let col = c * n;
                let (head_r, tail_r) = xr[col..col + n].split_at_mut(k + 1);
                let (head_i, tail_i) = xi[col..col + n].split_at_mut(k + 1);
                let (dr, di) = complex_dot_four_lanes(ur, ui, tail_r, tail_i);
                let (sr, si) = (head_r[k] - dr, head_i[k] - di);
                let x = if piv == c64::new(0.0, 0.0) { c64::new(f64::INFINITY, 0.0) } else { c64::new(sr, si) / piv };
                head_r[k] = x.re;
                head_i[k] = x.im;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn random(len: usize, seed: &mut u64) -> Vec<f64> {
        (0..len)
            .map(|_| {
                *seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
                ((*seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
            })
            .collect()
    }

    /// Small residual ‖(iωI − H)X − B‖ (backward stability), and the dispatched (AVX2 where
    /// available) and the baseline builds give the same bits.
    #[test]
    fn solves_with_small_residual_and_the_same_bits_on_every_build() {
        let mut seed = 3u64;
        for &(n, m) in &[(30usize, 1usize), (31, 2), (77, 3)] {
            let mut h = random(n * n, &mut seed);
            for i in 0..n {
                for j in 0..i.saturating_sub(1) {
                    h[i * n + j] = 0.0;
                }
            }
            let b = random(n * m, &mut seed);
            for &w in &[0.0, 0.37, 5.0] {
                let mut fast = ShiftedHessenbergSolve::new(n, m);
                let (xr, xi) = fast.solve(&h, &b, w);
                let (xr, xi) = (xr.to_vec(), xi.to_vec());
                let mut plain = ShiftedHessenbergSolve::new(n, m);
                plain.solve_any(&h, &b, w);
                assert_eq!((&xr, &xi), (&plain.xr, &plain.xi), "n={n} m={m} w={w}");
                let x_norm = xr.iter().chain(&xi).map(|v| v * v).sum::<f64>().sqrt();
                for c in 0..m {
                    for i in 0..n {
                        // Row i of (iωI − H)X − B, column c.
                        let (mut re, mut im) = (-b[i * m + c], 0.0);
                        for j in i.saturating_sub(1)..n {
                            let (a_re, a_im) = (-h[i * n + j], if i == j { w } else { 0.0 });
                            re += a_re * xr[c * n + j] - a_im * xi[c * n + j];
                            im += a_re * xi[c * n + j] + a_im * xr[c * n + j];
                        }
                        let r = re.hypot(im);
                        assert!(r <= 1e-12 * (1.0 + x_norm * n as f64), "n={n} w={w}: residual {r:e}");
                    }
                }
            }
        }
    }
}
