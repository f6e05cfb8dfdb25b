//! A real skew-symmetric matrix X = −Xᵀ stored by its strict lower triangle, and the two-sided
//! Householder update X ← P X P it undergoes in the PVL reduction of `square_reduced.rs`
//! (docs/ALGORITHMS.md §5.3).
//!
//! Stored this way, skew-symmetry holds by construction: the diagonal is exactly zero and
//! X(i, k) = −X(k, i) is read, not kept twice. That makes the skew analogue of LAPACK's
//! `dsytd2`/`dsyr2` update exact in its one scalar: for P = I − β v vᵀ on the trailing indices
//! r..n and y = X_RR v (X_RR the trailing block), vᵀ X_RR v = 0 for every v, so
//! ```text
//! P X_RR P = X_RR − β v (vᵀ X_RR) − β (X_RR v) vᵀ + β² v (vᵀ X_RR v) vᵀ = X_RR + β (v yᵀ − y vᵀ)
//! ```
//! with no rounding of vᵀ X_RR v to spread over the block (on a full, not exactly skew copy the
//! same identity lost a crossing on the badly scaled SLICOT fixture `scaled_random_1`: issue 13).
//! The rows r.. of the columns before r are reflected from the left, X_RT ← P X_RT; the rows
//! before r of the columns r.. are their negated transpose and follow. The work per reflection is
//! one pass over X_RT and two over the strict lower triangle of X_RR, against four passes over
//! X(r.., :) and X(:, r..) for a full matrix.
//!
//! The loops are written for the compiler to vectorise (four partial sums in the reductions); on
//! x86-64 CPUs with AVX2 (detected at run time) the same code is compiled for 256-bit registers.
//! No fused multiply–adds: both builds give the same bits.

use faer::MatRef;

/// A square skew-symmetric matrix, column-major, of which only the strict lower triangle is
/// stored (the diagonal and the upper triangle of `data` stay zero and are never read).
pub(crate) struct SkewLower {
    n: usize,
    data: Vec<f64>,
}

impl SkewLower {
    /// The skew-symmetric matrix with the strict lower triangle of `m` (square); the rest of `m`
    /// is not read, so an exactly skew `m` is represented exactly.
    pub(crate) fn from_lower(m: MatRef<'_, f64>) -> Self {
        let n = m.nrows();
        let mut data = vec![0.0; n * n];
        for j in 0..n {
            for i in j + 1..n {
                data[j * n + i] = m[(i, j)];
            }
        }
        SkewLower { n, data }
    }

    /// X(i, j).
    pub(crate) fn at(&self, i: usize, j: usize) -> f64 {
        match i.cmp(&j) {
            std::cmp::Ordering::Greater => self.data[j * self.n + i],
            std::cmp::Ordering::Less => -self.data[i * self.n + j],
            std::cmp::Ordering::Equal => 0.0,
        }
    }

    /// X(i, j) ← x, and with it X(j, i) ← −x; a diagonal entry stays zero (x is ignored).
    pub(crate) fn set(&mut self, i: usize, j: usize, x: f64) {
        match i.cmp(&j) {
            std::cmp::Ordering::Greater => self.data[j * self.n + i] = x,
            std::cmp::Ordering::Less => self.data[i * self.n + j] = -x,
            std::cmp::Ordering::Equal => {}
        }
    }

    /// X(from.., j) for from > j (stored entries of column j).
    pub(crate) fn col_below(&self, j: usize, from: usize) -> &[f64] {
        &self.data[j * self.n + from..(j + 1) * self.n]
    }

    /// X ← P X P for P = I − β v vᵀ acting on the indices r..n (v.len() = n − r), r ≥ 1 or 0.
    /// Columns before `first_col` are taken to be zero in rows r.. (and so, by skew-symmetry,
    /// rows before it in columns r..) and are skipped. `y` is work space of length ≥ n − r.
    pub(crate) fn reflect_two_sided(&mut self, r: usize, v: &[f64], beta: f64, first_col: usize, y: &mut [f64]) {
        #[cfg(target_arch = "x86_64")]
        {
            if std::is_x86_feature_detected!("avx2") {
                // SAFETY: `reflect_avx2` only requires AVX2, which the CPU was just found to have.
                unsafe { self.reflect_avx2(r, v, beta, first_col, y) };
                return;
            }
        }
        self.reflect_any(r, v, beta, first_col, y);
    }

    /// [`Self::reflect_any`] compiled for AVX2 (no FMA: the same bits as the baseline build).
    #[cfg(target_arch = "x86_64")]
    #[target_feature(enable = "avx2")]
    fn reflect_avx2(&mut self, r: usize, v: &[f64], beta: f64, first_col: usize, y: &mut [f64]) {
        self.reflect_any(r, v, beta, first_col, y)
    }

    /// The update of the module docs: X_RT ← P X_RT column by column, then y = X_RR v and
    /// X_RR ← X_RR + β(v yᵀ − y vᵀ) on the strict lower triangle.
    #[inline(always)]
    fn reflect_any(&mut self, r: usize, v: &[f64], beta: f64, first_col: usize, y: &mut [f64]) {
        let n = self.n;
        let len = n - r;
        for c in first_col..r {
            let seg = &mut self.data[c * n + r..(c + 1) * n];
            let s = beta * dot4(v, seg);
            if s != 0.0 {
                for (x, &vi) in seg.iter_mut().zip(v) {
                    *x -= s * vi;
                }
            }
        }
        // y = X_RR v = (L − Lᵀ) v, L the strict lower triangle: column k of L adds L(k+1.., k)·v_k
        // to y(k+1..) and subtracts L(k+1.., k)ᵀ v(k+1..) from y_k, in one pass over the column.
        let y = &mut y[..len];
        y.iter_mut().for_each(|t| *t = 0.0);
        for k in 0..len {
            let col = &self.data[(r + k) * n + r + k + 1..(r + k + 1) * n];
            let (head, tail) = y.split_at_mut(k + 1);
            head[k] -= axpy_dot(v[k], col, &v[k + 1..], tail);
        }
        // L(i, k) += β(v_i y_k − y_i v_k), i > k.
        for k in 0..len {
            let (a, b) = (beta * y[k], beta * v[k]);
            if a == 0.0 && b == 0.0 {
                continue;
            }
            let col = &mut self.data[(r + k) * n + r + k + 1..(r + k + 1) * n];
            for ((x, &vi), &yi) in col.iter_mut().zip(&v[k + 1..]).zip(&y[k + 1..]) {
                *x += vi * a - yi * b;
            }
        }
    }
}

/// Σ xᵢyᵢ with four partial sums, the remainder added last (as `numeric::dot_four_lanes`, inlined
/// here so that it is compiled for the caller's target features).
#[inline(always)]
fn dot4(x: &[f64], y: &[f64]) -> f64 {
    let mut acc = [0.0f64; 4];
    let (xc, yc) = (x.chunks_exact(4), y.chunks_exact(4));
    let (xr, yr) = (xc.remainder(), yc.remainder());
    for (a, b) in xc.zip(yc) {
        for l in 0..4 {
            acc[l] += a[l] * b[l];
        }
    }
    let mut s = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    for (a, b) in xr.iter().zip(yr) {
        s += a * b;
    }
    s
}

/// y += a·x and, in the same pass, returns Σ xᵢwᵢ (four partial sums, as [`dot4`]): the two
/// halves of a skew-symmetric matrix–vector product for one stored column x.
#[inline(always)]
fn axpy_dot(a: f64, x: &[f64], w: &[f64], y: &mut [f64]) -> f64 {
    let mut acc = [0.0f64; 4];
    let q = x.len() / 4 * 4;
    for ((xc, wc), yc) in x[..q].chunks_exact(4).zip(w[..q].chunks_exact(4)).zip(y[..q].chunks_exact_mut(4)) {
        for l in 0..4 {
            yc[l] += a * xc[l];
            acc[l] += xc[l] * wc[l];
        }
    }
    let mut s = (acc[0] + acc[1]) + (acc[2] + acc[3]);
    for i in q..x.len() {
        y[i] += a * x[i];
        s += x[i] * w[i];
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::Mat;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, StandardNormal};

    fn dense(x: &SkewLower) -> Mat<f64> {
        Mat::from_fn(x.n, x.n, |i, j| x.at(i, j))
    }

    /// The triangular update against P X P formed densely, for a random skew X with entries
    /// spread over twelve decades, on the whole matrix (first_col 0) and with leading zero columns.
    #[test]
    fn reflect_matches_the_dense_product() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for (n, r, first_col) in
            [(1usize, 0usize, 0usize), (2, 1, 0), (7, 0, 0), (9, 3, 0), (37, 5, 0), (37, 5, 4), (40, 39, 0)]
        {
            let mut g = |_: usize, _: usize| -> f64 { StandardNormal.sample(&mut rng) };
            let scale: Vec<f64> = (0..n).map(|i| 10f64.powf(12.0 * i as f64 / n as f64 - 6.0)).collect();
            let m0 = Mat::from_fn(n, n, |i, j| if j < first_col || i < first_col { 0.0 } else { g(i, j) });
            let m = Mat::from_fn(n, n, |i, j| scale[i] * scale[j] * (m0[(i, j)] - m0[(j, i)]));
            let mut x = SkewLower::from_lower(m.as_ref());
            assert_eq!(dense(&x), m);
            let len = n - r;
            let mut v: Vec<f64> = (0..len).map(|i| g(i, 0)).collect();
            if len > 0 {
                v[0] = 1.0;
            }
            let beta = 2.0 / v.iter().map(|t| t * t).sum::<f64>().max(1.0);
            let p = Mat::from_fn(n, n, |i, j| {
                let e = if i == j { 1.0 } else { 0.0 };
                if i >= r && j >= r {
                    e - beta * v[i - r] * v[j - r]
                } else {
                    e
                }
            });
            let want = &p * &m * &p;
            let mut y = vec![0.0; n];
            x.reflect_two_sided(r, &v, beta, first_col, &mut y);
            let got = dense(&x);
            // Both products are backward stable: entry-wise errors below 2n·ε·(|P||M||P|)ᵢⱼ
            // (Higham, Accuracy and Stability, §3.5), so they differ by at most twice that.
            let abs = |a: &Mat<f64>| Mat::from_fn(n, n, |i, j| a[(i, j)].abs());
            let bound = &abs(&p) * &abs(&m) * &abs(&p);
            for j in 0..n {
                for i in 0..n {
                    let tol = 4.0 * n as f64 * f64::EPSILON * bound[(i, j)];
                    assert!(
                        (got[(i, j)] - want[(i, j)]).abs() <= tol,
                        "n={n} r={r}: ({i},{j}) {} vs {} (tol {tol:e})",
                        got[(i, j)],
                        want[(i, j)]
                    );
                }
            }
        }
    }

    #[test]
    fn entries_keep_skew_symmetry() {
        let mut x = SkewLower::from_lower(Mat::<f64>::zeros(3, 3).as_ref());
        x.set(0, 2, 1.5);
        x.set(1, 1, 7.0);
        assert_eq!((x.at(0, 2), x.at(2, 0), x.at(1, 1)), (1.5, -1.5, 0.0));
        assert_eq!(x.col_below(0, 1), &[0.0, -1.5]);
    }
}
