//! The two-sided Householder updates X ← P X P of the PVL reduction (`square_reduced.rs`,
//! docs/ALGORITHMS.md §5.3), P = I − β v vᵀ acting on the trailing indices r..n: for a general
//! block ([`reflect_general`], the A of [A G; Q Aᵀ]) and for a skew-symmetric block stored by its
//! strict lower triangle ([`SkewLower`], G and Q).
//!
//! *General block.* P X P is formed as the left update X(r.., :) ← P X(r.., :) followed by the
//! right update X(:, r..) ← X(:, r..) P, in that order (no fused formula with the scalar vᵀXv: on
//! badly scaled X its rounding spread over the block and lost a crossing of the SLICOT fixture
//! `scaled_random_1`). But the passes are merged: each column is reflected from the
//! left and, while it is in cache, added into z = X(:, r..) v; a second pass subtracts β z vᵀ.
//! Two passes over the matrix instead of four.
//!
//! *Skew-symmetric block.* Stored by its strict lower triangle, skew-symmetry holds by
//! construction: the diagonal is exactly zero and X(i, k) = −X(k, i) is read, not kept twice.
//! That makes the skew analogue of LAPACK's `dsytd2`/`dsyr2` update exact in its one scalar: with
//! X_RR the trailing block and y = X_RR v, vᵀ X_RR v = 0 for every v, so
//! ```text
//! P X_RR P = X_RR − β v (vᵀ X_RR) − β (X_RR v) vᵀ + β² v (vᵀ X_RR v) vᵀ = X_RR + β (v yᵀ − y vᵀ)
//! ```
//! with no rounding of vᵀ X_RR v to spread over the block (on a full, not exactly skew copy the
//! same identity lost the crossing of `scaled_random_1` too). The rows r.. of the columns before r
//! are reflected from the left, X_RT ← P X_RT; the rows before r of the columns r.. are their
//! negated transpose and follow. One pass over X_RT and two over the lower triangle of X_RR,
//! against four passes over X(r.., :) and X(:, r..) in full storage.
//!
//! The loops are vectorised by `pulp` (the SIMD layer under faer): the instruction set is chosen
//! at run time (AVX2 with fused multiply–adds on x86-64 CPUs that have them), so the bits are
//! the same on one machine, not across machines with different instruction sets.

use faer::MatRef;
use pulp::{Arch, Simd, WithSimd};

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

    /// X ← P X P for P = I − β v vᵀ acting on the indices r..n (v.len() = n − r). Columns
    /// before `first_col` are taken to be zero in rows r.. (and so, by skew-symmetry, rows before
    /// it in columns r..) and are skipped. `y` is work space of length ≥ n − r.
    pub(crate) fn reflect_two_sided(&mut self, r: usize, v: &[f64], beta: f64, first_col: usize, y: &mut [f64]) {
        Arch::new().dispatch(SkewReflect { x: self, r, v, beta, first_col, y })
    }
}

/// [`SkewLower::reflect_two_sided`] for one SIMD instruction set.
struct SkewReflect<'a> {
    x: &'a mut SkewLower,
    r: usize,
    v: &'a [f64],
    beta: f64,
    first_col: usize,
    y: &'a mut [f64],
}

impl WithSimd for SkewReflect<'_> {
    type Output = ();

    /// The update of the module docs: X_RT ← P X_RT column by column, then y = X_RR v and
    /// X_RR ← X_RR + β(v yᵀ − y vᵀ) on the strict lower triangle.
    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let SkewReflect { x, r, v, beta, first_col, y } = self;
        let n = x.n;
        let len = n - r;
        for c in first_col..r {
            reflect_left(simd, &mut x.data[c * n + r..(c + 1) * n], v, beta);
        }
        // y = X_RR v = (L − Lᵀ) v, L the strict lower triangle: column k of L adds L(k+1.., k)·v_k
        // to y(k+1..) and subtracts L(k+1.., k)ᵀ v(k+1..) from y_k, in one pass over the column.
        let y = &mut y[..len];
        y.iter_mut().for_each(|t| *t = 0.0);
        for k in 0..len {
            let col = &x.data[(r + k) * n + r + k + 1..(r + k + 1) * n];
            let (head, tail) = y.split_at_mut(k + 1);
            head[k] -= axpy_dot(simd, v[k], col, &v[k + 1..], tail);
        }
        // L(i, k) += β(v_i y_k − y_i v_k), i > k.
        for k in 0..len {
            let (a, b) = (beta * y[k], -beta * v[k]);
            if a != 0.0 || b != 0.0 {
                axpy2(simd, a, &v[k + 1..], b, &y[k + 1..], &mut x.data[(r + k) * n + r + k + 1..(r + k + 1) * n]);
            }
        }
    }
}

/// X ← P X P for a general column-major n×n X (`data`), P = I − β v vᵀ on the indices r..n
/// (n = r + v.len()), by the merged passes of the module docs. Columns before `first_col` are zero
/// in rows r.. and rows before `first_row` zero in columns r..; both are skipped. `z`: work space
/// of length ≥ n.
pub(crate) fn reflect_general(
    data: &mut [f64],
    r: usize,
    v: &[f64],
    beta: f64,
    first_col: usize,
    first_row: usize,
    z: &mut [f64],
) {
    Arch::new().dispatch(GeneralReflect { data, r, v, beta, first_col, first_row, z })
}

/// [`reflect_general`] for one SIMD instruction set.
struct GeneralReflect<'a> {
    data: &'a mut [f64],
    r: usize,
    v: &'a [f64],
    beta: f64,
    first_col: usize,
    first_row: usize,
    z: &'a mut [f64],
}

impl WithSimd for GeneralReflect<'_> {
    type Output = ();

    #[inline(always)]
    fn with_simd<S: Simd>(self, simd: S) {
        let GeneralReflect { data, r, v, beta, first_col, first_row, z } = self;
        let n = r + v.len();
        let z = &mut z[first_row..n];
        z.iter_mut().for_each(|t| *t = 0.0);
        for c in first_col..n {
            let col = &mut data[c * n..(c + 1) * n];
            reflect_left(simd, &mut col[r..], v, beta);
            if c >= r {
                axpy2(simd, v[c - r], &col[first_row..], 0.0, &[], z);
            }
        }
        for c in r..n {
            let b = -beta * v[c - r];
            if b != 0.0 {
                axpy2(simd, b, z, 0.0, &[], &mut data[c * n + first_row..(c + 1) * n]);
            }
        }
    }
}

/// x ← P x for one column segment x (length v.len()): x −= β(vᵀx) v.
#[inline(always)]
fn reflect_left<S: Simd>(simd: S, x: &mut [f64], v: &[f64], beta: f64) {
    let s = beta * dot(simd, v, x);
    if s != 0.0 {
        axpy2(simd, -s, v, 0.0, &[], x);
    }
}

/// Σ xᵢyᵢ over the length of x (y at least as long).
#[inline(always)]
fn dot<S: Simd>(simd: S, x: &[f64], y: &[f64]) -> f64 {
    let (xh, xt) = S::as_simd_f64s(x);
    let (yh, yt) = S::as_simd_f64s(&y[..x.len()]);
    let mut acc = simd.splat_f64s(0.0);
    for (&a, &b) in xh.iter().zip(yh) {
        acc = simd.mul_add_f64s(a, b, acc);
    }
    let mut s = simd.reduce_sum_f64s(acc);
    for (a, b) in xt.iter().zip(yt) {
        s += a * b;
    }
    s
}

/// y += a·x and, in the same pass, returns Σ xᵢwᵢ: the two halves of a skew-symmetric
/// matrix–vector product for one stored column x (w and y at least as long as x).
#[inline(always)]
fn axpy_dot<S: Simd>(simd: S, a: f64, x: &[f64], w: &[f64], y: &mut [f64]) -> f64 {
    let len = x.len();
    let (xh, xt) = S::as_simd_f64s(x);
    let (wh, wt) = S::as_simd_f64s(&w[..len]);
    let (yh, yt) = S::as_mut_simd_f64s(&mut y[..len]);
    let va = simd.splat_f64s(a);
    let mut acc = simd.splat_f64s(0.0);
    for ((&xv, &wv), yv) in xh.iter().zip(wh).zip(yh) {
        acc = simd.mul_add_f64s(xv, wv, acc);
        *yv = simd.mul_add_f64s(va, xv, *yv);
    }
    let mut s = simd.reduce_sum_f64s(acc);
    for ((&xi, &wi), yi) in xt.iter().zip(wt).zip(yt) {
        s += xi * wi;
        *yi += a * xi;
    }
    s
}

/// y += a·x + b·w over the length of y (x, and w unless b = 0, at least as long; with b = 0, w
/// is not read and may be empty).
#[inline(always)]
fn axpy2<S: Simd>(simd: S, a: f64, x: &[f64], b: f64, w: &[f64], y: &mut [f64]) {
    let len = y.len();
    let (yh, yt) = S::as_mut_simd_f64s(y);
    let (xh, xt) = S::as_simd_f64s(&x[..len]);
    let va = simd.splat_f64s(a);
    if b == 0.0 {
        for (yv, &xv) in yh.iter_mut().zip(xh) {
            *yv = simd.mul_add_f64s(va, xv, *yv);
        }
        for (yi, &xi) in yt.iter_mut().zip(xt) {
            *yi += a * xi;
        }
        return;
    }
    let (wh, wt) = S::as_simd_f64s(&w[..len]);
    let vb = simd.splat_f64s(b);
    for ((yv, &xv), &wv) in yh.iter_mut().zip(xh).zip(wh) {
        *yv = simd.mul_add_f64s(vb, wv, simd.mul_add_f64s(va, xv, *yv));
    }
    for ((yi, &xi), &wi) in yt.iter_mut().zip(xt).zip(wt) {
        *yi += a * xi + b * wi;
    }
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

    /// A Householder vector (v₀ = 1) of length `len` and β = 2/‖v‖² from `rng`.
    fn householder_vector(rng: &mut ChaCha8Rng, len: usize) -> (Vec<f64>, f64) {
        let mut v: Vec<f64> = (0..len).map(|_| StandardNormal.sample(&mut *rng)).collect();
        if len > 0 {
            v[0] = 1.0;
        }
        let beta = 2.0 / v.iter().map(|t| t * t).sum::<f64>().max(1.0);
        (v, beta)
    }

    /// `got` against P M P formed densely: both products are backward stable, with entry-wise
    /// errors below 2n·ε·(|P||M||P|)ᵢⱼ (Higham, Accuracy and Stability, §3.5), so they differ by
    /// at most twice that.
    fn assert_matches_dense(m: &Mat<f64>, r: usize, v: &[f64], beta: f64, got: &Mat<f64>, what: &str) {
        let n = m.nrows();
        let p = Mat::from_fn(n, n, |i, j| {
            let e = if i == j { 1.0 } else { 0.0 };
            if i >= r && j >= r {
                e - beta * v[i - r] * v[j - r]
            } else {
                e
            }
        });
        let want = &p * m * &p;
        let abs = |a: &Mat<f64>| Mat::from_fn(n, n, |i, j| a[(i, j)].abs());
        let bound = &abs(&p) * &abs(m) * &abs(&p);
        for j in 0..n {
            for i in 0..n {
                let tol = 4.0 * n as f64 * f64::EPSILON * bound[(i, j)];
                assert!(
                    (got[(i, j)] - want[(i, j)]).abs() <= tol,
                    "{what} n={n} r={r}: ({i},{j}) {} vs {} (tol {tol:e})",
                    got[(i, j)],
                    want[(i, j)]
                );
            }
        }
    }

    /// Sizes, r and the first column (and row) of the cases below: the whole matrix, leading zero
    /// columns, the last step (v of length 1).
    const CASES: [(usize, usize, usize); 8] =
        [(1, 0, 0), (2, 1, 0), (7, 0, 0), (9, 3, 0), (37, 5, 0), (37, 5, 4), (40, 39, 0), (41, 12, 11)];

    /// Row and column scales spread over twelve decades.
    fn scales(n: usize) -> Vec<f64> {
        (0..n).map(|i| 10f64.powf(12.0 * i as f64 / n as f64 - 6.0)).collect()
    }

    /// The triangular update against P X P formed densely, for random badly scaled skew X.
    #[test]
    fn skew_reflect_matches_the_dense_product() {
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        for (n, r, first_col) in CASES {
            let scale = scales(n);
            let m0 = Mat::from_fn(n, n, |i, j| {
                let x: f64 = StandardNormal.sample(&mut rng);
                if j < first_col || i < first_col {
                    0.0
                } else {
                    x
                }
            });
            let m = Mat::from_fn(n, n, |i, j| scale[i] * scale[j] * (m0[(i, j)] - m0[(j, i)]));
            let mut x = SkewLower::from_lower(m.as_ref());
            assert_eq!(dense(&x), m);
            let (v, beta) = householder_vector(&mut rng, n - r);
            x.reflect_two_sided(r, &v, beta, first_col, &mut vec![0.0; n]);
            assert_matches_dense(&m, r, &v, beta, &dense(&x), "skew");
        }
    }

    /// The merged passes of [`reflect_general`] against P X P formed densely, for random badly
    /// scaled X with the zero blocks it may skip (rows r.. of the columns before `first_col`,
    /// columns r.. of the rows before `first_row`).
    #[test]
    fn general_reflect_matches_the_dense_product() {
        let mut rng = ChaCha8Rng::seed_from_u64(8);
        for (n, r, first_col) in CASES {
            for first_row in [0, first_col] {
                let scale = scales(n);
                let m = Mat::from_fn(n, n, |i, j| {
                    let x: f64 = StandardNormal.sample(&mut rng);
                    if (i >= r && j < first_col) || (i < first_row && j >= r) {
                        0.0
                    } else {
                        scale[i] * x / scale[j]
                    }
                });
                let mut data: Vec<f64> =
                    (0..n).flat_map(|j| (0..n).map(move |i| (i, j))).map(|(i, j)| m[(i, j)]).collect();
                let (v, beta) = householder_vector(&mut rng, n - r);
                reflect_general(&mut data, r, &v, beta, first_col, first_row, &mut vec![0.0; n]);
                let got = Mat::from_fn(n, n, |i, j| data[j * n + i]);
                assert_matches_dense(&m, r, &v, beta, &got, "general");
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
