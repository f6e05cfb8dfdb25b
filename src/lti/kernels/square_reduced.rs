//! Eigenvalues of a real Hamiltonian matrix by Van Loan's square-reduced method.
//!
//! C. F. Van Loan, "A symplectic method for approximating all the eigenvalues of a Hamiltonian
//! matrix", Linear Algebra Appl. 61 (1984) 233–251; the reduction is the "PVL" (Paige–Van Loan)
//! form of D. Kressner, *Numerical Methods for General and Structured Eigenvalue Problems*
//! (Springer 2005), §4.2.
//!
//! H = [F G; K −Fᵀ] (G, K symmetric) has eigenvalues in pairs ±λ. Its square M = H² is
//! skew-Hamiltonian, M = [M₁₁ M₁₂; M₂₁ M₁₁ᵀ] with M₁₂, M₂₁ skew-symmetric, and an orthogonal
//! *symplectic* similarity Q (products of Householder matrices diag(P, P) and Givens rotations in
//! the (k, n+k) planes) brings it to
//! ```text
//! Qᵀ M Q = [ W  X  ]      W upper Hessenberg (n×n),
//!          [ 0  Wᵀ ]
//! ```
//! so λ(H)² = λ(W), each eigenvalue of W standing for one pair ±λ. The n×n Hessenberg QR
//! replaces the 2n×2n one of an unstructured solver: about a third of the work.
//!
//! # Accuracy
//! The method is backward stable for M, not for H: an eigenvalue μ = λ² of W carries an absolute
//! error of order ε‖H‖², so λ is accurate to ε‖H‖²/|λ| (instead of ε‖H‖). The caller must use a
//! test on μ that allows for this ([`SquaredSpectrum::abs_error`]); for the H∞ level set that
//! only turns near-axis eigenvalues into candidate crossings, which are checked by evaluating
//! σmax(G(iω)) (hinf.rs), so it can cost an evaluation but cannot lower the computed norm.
//!
//! Written by hand: no Rust crate has a structure-preserving Hamiltonian eigensolver (faer's
//! Hessenberg QR does the final n×n step).

use faer::{c64, Mat, MatRef};

use super::hessenberg_qr::{hessenberg_eigenvalues, HESSENBERG_QR_FROM};
use super::pvl_update::{reflect_general, SkewLower};
use super::spectral::eigenvalues;
use super::step_stats::{timed, Step};
use crate::numeric::dot_four_lanes;

/// The eigenvalues μ = λ² of H² (one per pair ±λ of H) and a bound on their absolute error.
pub(crate) struct SquaredSpectrum {
    pub mu: Vec<c64>,
    /// c·ε·‖H²‖_F of the balanced H ([`hamiltonian_squared_eigenvalues`]): rounding in the
    /// formation of H², the reduction and the QR. This is ε‖H‖² (module docs) only when ‖H‖² is
    /// near ‖H²‖; the balancing makes the off-diagonal blocks equal, but a large F or cancellation
    /// inside H² can still leave it below the error of small μ (docs/ALGORITHMS.md §5.3).
    pub abs_error: f64,
}

/// From this size n on, the reduction reflects A by merged passes ([`reflect_general`]) and keeps
/// G and Q by their strict lower triangles ([`SkewLower`]) (faster at large n than the
/// faer level-2 kernels on full storage used before); below it full storage and the hand-written loops, whose rounding the
/// small plants' design results (the smoke campaign's table) were obtained with.
const FAST_KERNELS_FROM: usize = 30;

/// Safety factor on ε‖M‖_F in [`SquaredSpectrum::abs_error`] (the reduction applies 3n
/// orthogonal transformations; their rounding grows like √n in practice).
const ERROR_FACTOR: f64 = 100.0;

/// λ(H)² for the real Hamiltonian H = [F G; K −Fᵀ] (G, K symmetric, all n×n) with G and K
/// given by factors ([`LowRank`]); `None` if the data are not finite or the QR fails.
///
/// H is first balanced by the symplectic similarity diag(√s·I, I/√s) (see
/// [`symplectic_balance_exponent`]), which turns G, K into G/s, s·K and leaves the eigenvalues
/// unchanged.
pub(crate) fn hamiltonian_squared_eigenvalues(
    f: MatRef<'_, f64>,
    g: LowRank<'_>,
    k: LowRank<'_>,
) -> Option<SquaredSpectrum> {
    let ([m11, m12, m21], norm) = balanced_square(f, g, k)?;
    let mu = skew_hamiltonian_eigenvalues(m11.as_ref(), m12.as_ref(), m21.as_ref())?;
    Some(SquaredSpectrum { mu, abs_error: ERROR_FACTOR * f64::EPSILON * norm.max(f64::MIN_POSITIVE) })
}

/// An off-diagonal block X = L Rᵀ of a Hamiltonian by its factors (n×r each): the H∞
/// Hamiltonian's −γBR⁻¹Bᵀ and γCᵀS⁻¹C have ranks m and p ≪ n. A dense X is L = X, R = I.
#[derive(Clone, Copy)]
pub(crate) struct LowRank<'a> {
    pub left: MatRef<'a, f64>,
    pub right: MatRef<'a, f64>,
}

/// The blocks [M₁₁, M₁₂, M₂₁] of M = H² for the balanced H (see
/// [`hamiltonian_squared_eigenvalues`]) and ‖M‖_F; `None` if not finite.
///
/// M = H² = [F² + GK, FG − GFᵀ; KF − FᵀK, (F² + GK)ᵀ], with GFᵀ = (FG)ᵀ and FᵀK = (KF)ᵀ. GK, FG
/// and KF are formed from the factors, O(n²r), so that F² is the only O(n³) product (measured:
/// four dense products were 4 % of a CM4 design run). The balancing scales G by 2⁻ᵗ and K by 2ᵗ:
/// GK is unchanged, FG and KF are scaled after the product (exact, a power of two).
fn balanced_square(f: MatRef<'_, f64>, g: LowRank<'_>, k: LowRank<'_>) -> Option<([Mat<f64>; 3], f64)> {
    timed(Step::HamiltonianSquare, || {
        let (g_norm, k_norm) = ((g.left * g.right.transpose()).norm_l2(), (k.left * k.right.transpose()).norm_l2());
        if !(g_norm.is_finite() && k_norm.is_finite()) {
            return None;
        }
        let e = symplectic_balance_exponent(g_norm, k_norm);
        let gk = g.left * ((g.right.transpose() * k.left) * k.right.transpose());
        let fg = (f * g.left) * g.right.transpose() * faer::Scale((-e).exp2());
        let kf = k.left * (k.right.transpose() * f) * faer::Scale(e.exp2());
        let m11 = f * f + gk;
        let (m12, m21) = (&fg - fg.transpose(), &kf - kf.transpose());
        let norm = (2.0 * m11.squared_norm_l2() + m12.squared_norm_l2() + m21.squared_norm_l2()).sqrt();
        norm.is_finite().then_some(([m11, m12, m21], norm))
    })
}

/// The exponent t (an integer, as f64) of the symplectic scaling s = 2ᵗ ≈ √(‖G‖/‖K‖) that makes
/// the off-diagonal blocks G/s and s·K of a Hamiltonian [F G; K −Fᵀ] equally large (0 if either
/// is zero). A power of two, so the scaling is exact in floating point.
///
/// Why: the squared method's μ = λ² are backward stable for H², with absolute errors of order
/// ε‖H‖² (Van Loan 1984). When ‖G‖ and ‖K‖ differ by orders of magnitude, H² cancels them
/// (its blocks hold the products GK, FG, KF), so ‖H‖² is far above ‖H²‖ and the small μ are
/// computed with errors far above the bound ε‖H²‖ (a converged BDT2 closed loop: ‖H‖₂² ≈ 3.4e10
/// against ‖H²‖_F ≈ 2.2e6). Balanced, ‖H‖² shrinks towards ‖H²‖ (docs/ALGORITHMS.md §5.3).
fn symplectic_balance_exponent(g_norm: f64, k_norm: f64) -> f64 {
    if !(g_norm > 0.0 && k_norm > 0.0) {
        return 0.0;
    }
    // ½(log₂‖G‖ − log₂‖K‖), each finite and ≥ −1075, so |t| ≤ ~1100: 2^±t stays representable
    // only if clamped (the blocks' entries are then too far apart for any scaling to matter).
    (0.5 * (g_norm.log2() - k_norm.log2())).round().clamp(-500.0, 500.0)
}

/// The W (n×n upper Hessenberg, column-major) of the PVL reduction of H² for the Hamiltonian
/// H = [F G; K −Fᵀ], as [`hamiltonian_squared_eigenvalues`] computes it (for the QR
/// microbenchmark, `lti::kernel_bench`); `None` if not finite.
#[cfg(feature = "test-support")]
pub(crate) fn hamiltonian_squared_w(f: MatRef<'_, f64>, g: MatRef<'_, f64>, k: MatRef<'_, f64>) -> Option<Vec<f64>> {
    let id = Mat::<f64>::identity(f.nrows(), f.nrows());
    let dense = |x| LowRank { left: x, right: id.as_ref() };
    let ([m11, m12, m21], _) = balanced_square(f, dense(g), dense(k))?;
    Some(pvl_w(m11.as_ref(), m12.as_ref(), m21.as_ref()))
}

/// The W (n×n upper Hessenberg, column-major) of the PVL reduction of [A G; Q Aᵀ], as
/// [`skew_hamiltonian_eigenvalues`] computes it (for the microbenchmarks, `lti::kernel_bench`).
#[cfg(feature = "test-support")]
pub(crate) fn pvl_w(a: MatRef<'_, f64>, g: MatRef<'_, f64>, q: MatRef<'_, f64>) -> Vec<f64> {
    skew_hamiltonian_w(a, g, q).data
}

/// The n eigenvalues of the real skew-Hamiltonian matrix W = [A G; Q Aᵀ] (G, Q skew-symmetric,
/// all n×n; W has each of them twice), by the PVL reduction and an n×n Hessenberg QR. Backward
/// stable for W: errors of order ε‖W‖. `None` if the QR fails.
pub(crate) fn skew_hamiltonian_eigenvalues(
    a: MatRef<'_, f64>,
    g: MatRef<'_, f64>,
    q: MatRef<'_, f64>,
) -> Option<Vec<c64>> {
    let mut w = skew_hamiltonian_w(a, g, q);
    timed(Step::QrW, || hessenberg_part_eigenvalues(&mut w))
}

/// The Hessenberg W of the PVL reduction of [A G; Q Aᵀ] (entries below its subdiagonal are
/// the reduction's rounding).
fn skew_hamiltonian_w(a: MatRef<'_, f64>, g: MatRef<'_, f64>, q: MatRef<'_, f64>) -> ColMajor {
    if a.nrows() < FAST_KERNELS_FROM {
        SkewHamiltonian { a: ColMajor::from(a), g: ColMajor::from(g), q: ColMajor::from(q) }.into_pvl_w()
    } else {
        SkewHamiltonian { a: ColMajor::from(a), g: SkewLower::from_lower(g), q: SkewLower::from_lower(q) }.into_pvl_w()
    }
}

/// The eigenvalues of the upper Hessenberg part of `w` (entries below the subdiagonal, the
/// reduction's rounding, are not read).
fn hessenberg_part_eigenvalues(w: &mut ColMajor) -> Option<Vec<c64>> {
    let n = w.n;
    if n >= HESSENBERG_QR_FROM {
        // W's leading block is already Hessenberg: no second reduction (a wasted O(n³) step otherwise).
        return hessenberg_eigenvalues(&mut w.data, n).ok();
    }
    let h = Mat::from_fn(n, n, |i, j| if i <= j + 1 { w.at(i, j) } else { 0.0 });
    eigenvalues(h.as_ref())
}

/// A dense column-major square matrix with direct slice access to its columns (the reduction
/// is a sequence of rank-one updates on contiguous column segments).
struct ColMajor {
    n: usize,
    data: Vec<f64>,
}

impl ColMajor {
    fn from(m: MatRef<'_, f64>) -> Self {
        let n = m.nrows();
        let mut data = vec![0.0; n * n];
        for j in 0..n {
            for i in 0..n {
                data[j * n + i] = m[(i, j)];
            }
        }
        ColMajor { n, data }
    }

    fn at(&self, i: usize, j: usize) -> f64 {
        self.data[j * self.n + i]
    }

    fn set(&mut self, i: usize, j: usize, x: f64) {
        self.data[j * self.n + i] = x;
    }

    fn col(&self, j: usize) -> &[f64] {
        &self.data[j * self.n..(j + 1) * self.n]
    }

    /// X ← P X P by hand-written loops, for small n ([`FAST_KERNELS_FROM`]): the same
    /// arithmetic as before the merged passes of [`reflect_general`], so that small plants' results (the smoke
    /// campaign's) stay bit for bit what they were.
    fn reflect_two_sided_loops(
        &mut self,
        r: usize,
        v: &[f64],
        beta: f64,
        first_col: usize,
        first_row: usize,
        w: &mut [f64],
    ) {
        let len = v.len();
        for c in first_col..self.n {
            let seg = &mut self.data[c * self.n + r..c * self.n + r + len];
            let s = beta * dot_four_lanes(v, seg);
            if s != 0.0 {
                axpy(-s, v, seg);
            }
        }
        // Right: w = X[first_row.., r..] v; X[first_row.., r..] −= β w vᵀ.
        let w = &mut w[first_row..];
        w.iter_mut().for_each(|t| *t = 0.0);
        for (k, &vk) in v.iter().enumerate() {
            axpy(vk, &self.col(r + k)[first_row..], w);
        }
        for (k, &vk) in v.iter().enumerate() {
            let n = self.n;
            axpy(-beta * vk, w, &mut self.data[(r + k) * n + first_row..(r + k + 1) * n]);
        }
    }

    /// X ← P X P for P = I − β v vᵀ acting on indices r..n (v.len() = n − r). Columns before
    /// `first_col` are zero in rows r.. and are skipped on the left; rows before `first_row` are
    /// zero in columns r.. and are skipped on the right. From n = [`FAST_KERNELS_FROM`] on by
    /// [`reflect_general`] (two merged passes; before it, four level-2 passes through
    /// faer's kernels, twice the memory traffic), below it by [`Self::reflect_two_sided_loops`].
    fn reflect_two_sided(
        &mut self,
        r: usize,
        v: &[f64],
        beta: f64,
        first_col: usize,
        first_row: usize,
        buf: &mut [f64],
    ) {
        if self.n < FAST_KERNELS_FROM {
            return self.reflect_two_sided_loops(r, v, beta, first_col, first_row, buf);
        }
        reflect_general(&mut self.data, r, v, beta, first_col, first_row, buf);
    }
}

/// Storage of the skew-symmetric blocks G and Q of a skew-Hamiltonian matrix: in full
/// ([`ColMajor`], below [`FAST_KERNELS_FROM`]) or by the strict lower triangle ([`SkewLower`]).
trait SkewBlock {
    fn at(&self, i: usize, j: usize) -> f64;
    fn set(&mut self, i: usize, j: usize, x: f64);
    /// Entries from.. of column j (from > j).
    fn col_below(&self, j: usize, from: usize) -> &[f64];
    /// X ← P X P for P = I − β v vᵀ on the indices r..n; rows and columns before `first` are
    /// zero outside the leading block and are skipped. `buf`: work space of length n.
    fn reflect(&mut self, r: usize, v: &[f64], beta: f64, first: usize, buf: &mut [f64]);
    /// M ← R M Rᵀ for the rotation R = [c s; −s c] in the (r, n+r) plane of the skew-Hamiltonian
    /// M = [A G; Q Aᵀ] with this storage of G and Q ([`rotate_by_entries`]).
    fn rotate(a: &mut ColMajor, g: &mut Self, q: &mut Self, r: usize, c: f64, s: f64)
    where
        Self: Sized;
}

impl SkewBlock for ColMajor {
    fn at(&self, i: usize, j: usize) -> f64 {
        ColMajor::at(self, i, j)
    }
    fn set(&mut self, i: usize, j: usize, x: f64) {
        ColMajor::set(self, i, j, x)
    }
    fn col_below(&self, j: usize, from: usize) -> &[f64] {
        &self.col(j)[from..]
    }
    fn reflect(&mut self, r: usize, v: &[f64], beta: f64, first: usize, buf: &mut [f64]) {
        self.reflect_two_sided(r, v, beta, first, first, buf)
    }
    fn rotate(a: &mut ColMajor, g: &mut Self, q: &mut Self, r: usize, c: f64, s: f64) {
        rotate_by_entries(a, g, q, r, c, s)
    }
}

impl SkewBlock for SkewLower {
    fn at(&self, i: usize, j: usize) -> f64 {
        SkewLower::at(self, i, j)
    }
    fn set(&mut self, i: usize, j: usize, x: f64) {
        SkewLower::set(self, i, j, x)
    }
    fn col_below(&self, j: usize, from: usize) -> &[f64] {
        SkewLower::col_below(self, j, from)
    }
    fn reflect(&mut self, r: usize, v: &[f64], beta: f64, first: usize, buf: &mut [f64]) {
        self.reflect_two_sided(r, v, beta, first, buf)
    }
    /// [`rotate_by_entries`] in one pass without work arrays (measured: its reads through `at`
    /// were ~5 % of a BDT2 design run's norms). G(k, r) = −G(r, k) and Q(k, r) = −Q(r, k) are one
    /// stored entry each, and the two formulas that set it give exactly opposite values (negation
    /// and the commutativity of a sum are exact), so each is computed once: the same bits.
    fn rotate(a: &mut ColMajor, g: &mut Self, q: &mut Self, r: usize, c: f64, s: f64) {
        let n = a.n;
        let old = [a.at(r, r), 0.0, 0.0];
        for k in (0..n).filter(|&k| k != r) {
            let (ar, ac) = (a.data[k * n + r], a.data[r * n + k]);
            let (gr, qr) = (g.at(r, k), q.at(r, k));
            let (gc, qc) = (-gr, -qr);
            a.data[k * n + r] = c * ar + s * qr;
            a.data[r * n + k] = c * ac + s * gc;
            g.set(r, k, c * gr + s * ac);
            q.set(k, r, c * qc + s * ar);
        }
        rotate_diagonal_block(a, g, q, r, c, s, old);
    }
}

/// A skew-Hamiltonian matrix [A G; Q Aᵀ] stored by its three blocks (the fourth is Aᵀ).
struct SkewHamiltonian<S> {
    a: ColMajor,
    g: S,
    q: S,
}

impl<S: SkewBlock> SkewHamiltonian<S> {
    /// [`Self::pvl_reduce`] (timed as [`Step::Pvl`]), then the block W = A of the PVL form.
    fn into_pvl_w(mut self) -> ColMajor {
        timed(Step::Pvl, || self.pvl_reduce());
        self.a
    }

    /// Reduces to PVL form in place by orthogonal symplectic similarity (Kressner 2005,
    /// Alg. 4.8): for each column j, a Householder matrix diag(P, P) annihilates Q(j+2:n, j), a
    /// Givens rotation in the (j+1, n+j+1) plane annihilates Q(j+1, j), and a second diag(P, P)
    /// annihilates A(j+2:n, j). Q(0:j+1, j) vanishes by skew-symmetry, so afterwards Q = 0 (to
    /// rounding) and A is upper Hessenberg. diag(P, P) acts on each block as X ← P X P.
    fn pvl_reduce(&mut self) {
        let n = self.a.n;
        let mut v = vec![0.0; n];
        let mut w = vec![0.0; n];
        let fast_norm = n >= FAST_KERNELS_FROM;
        for j in 0..n.saturating_sub(1) {
            let r = j + 1;
            let len = n - r;
            if let Some(beta) = householder(self.q.col_below(j, r), &mut v[..len], fast_norm) {
                self.reflect(r, &v[..len], beta, j, &mut w);
            }
            let (a, b) = (self.a.at(r, j), self.q.at(r, j));
            if b != 0.0 {
                let rho = a.hypot(b);
                self.rotate(r, a / rho, b / rho);
            }
            if let Some(beta) = householder(&self.a.col(j)[r..n], &mut v[..len], fast_norm) {
                self.reflect(r, &v[..len], beta, j, &mut w);
            }
        }
    }

    /// diag(P, P) similarity at step j (P acting on j+1..n). Q(:, 0..j) = 0 and, by
    /// skew-symmetry, Q(0..j, :) = 0, so Q's update is confined to its trailing block.
    fn reflect(&mut self, r: usize, v: &[f64], beta: f64, j: usize, w: &mut [f64]) {
        self.a.reflect_two_sided(r, v, beta, j, 0, w);
        self.g.reflect(r, v, beta, 0, w);
        self.q.reflect(r, v, beta, j, w);
    }

    /// M ← R M Rᵀ for the rotation R = [c s; −s c] in the (r, n+r) plane of the full matrix M
    /// (orthogonal and symplectic); see [`SkewBlock::rotate`].
    fn rotate(&mut self, r: usize, c: f64, s: f64) {
        S::rotate(&mut self.a, &mut self.g, &mut self.q, r, c, s)
    }
}

/// [`SkewBlock::rotate`] through `at` and `set` (full storage, below [`FAST_KERNELS_FROM`]).
/// Only rows and columns r and n+r of M change; with M[n+i, n+k] = A(k, i) they are, from the
/// old values,
/// A(r,k) ← c A(r,k) + s Q(r,k),   Q(r,k) ← −s A(r,k) + c Q(r,k),   G(r,k) ← c G(r,k) + s A(k,r),
/// A(i,r) ← c A(i,r) + s G(i,r),   G(i,r) ← −s A(i,r) + c G(i,r),   Q(i,r) ← c Q(i,r) + s A(r,i)
/// for i, k ≠ r, and the 2×2 block [A(r,r) G(r,r); Q(r,r) A(r,r)] ← R (·) Rᵀ.
fn rotate_by_entries<S: SkewBlock>(a: &mut ColMajor, g: &mut S, q: &mut S, r: usize, c: f64, s: f64) {
    let n = a.n;
    let (ar, ac): (Vec<f64>, Vec<f64>) = (0..n).map(|k| (a.at(r, k), a.at(k, r))).unzip();
    let (gr, gc): (Vec<f64>, Vec<f64>) = (0..n).map(|k| (g.at(r, k), g.at(k, r))).unzip();
    let (qr, qc): (Vec<f64>, Vec<f64>) = (0..n).map(|k| (q.at(r, k), q.at(k, r))).unzip();
    for k in (0..n).filter(|&k| k != r) {
        a.set(r, k, c * ar[k] + s * qr[k]);
        q.set(r, k, -s * ar[k] + c * qr[k]);
        g.set(r, k, c * gr[k] + s * ac[k]);
        a.set(k, r, c * ac[k] + s * gc[k]);
        g.set(k, r, -s * ac[k] + c * gc[k]);
        q.set(k, r, c * qc[k] + s * ar[k]);
    }
    rotate_diagonal_block(a, g, q, r, c, s, [ar[r], gr[r], qr[r]]);
}

/// The 2×2 block [A(r,r) G(r,r); Q(r,r) A(r,r)] ← R (·) Rᵀ of [`rotate_by_entries`], from the
/// old values `[A(r,r), G(r,r), Q(r,r)]`.
fn rotate_diagonal_block<S: SkewBlock>(
    a: &mut ColMajor,
    g: &mut S,
    q: &mut S,
    r: usize,
    c: f64,
    s: f64,
    old: [f64; 3],
) {
    let [al, g0, q0] = old;
    let (t00, t01) = (c * al + s * q0, c * g0 + s * al);
    let (t10, t11) = (-s * al + c * q0, -s * g0 + c * al);
    a.set(r, r, t00 * c + t01 * s);
    g.set(r, r, -t00 * s + t01 * c);
    q.set(r, r, t10 * c + t11 * s);
}

/// The Householder vector (v₀ = 1) and β of P = I − β v vᵀ with P x = ∓‖x‖ e₁ (LAPACK `dlarfg`
/// convention); `None` when x is already a multiple of e₁.
/// From n = [`FAST_KERNELS_FROM`] on (`fast_norm`) the tail's norm is faer's (scaled, SIMD)
/// instead of a `hypot` fold (libm's hypot was 2 % of a BDT2 design run).
fn householder(x: &[f64], v: &mut [f64], fast_norm: bool) -> Option<f64> {
    let tail = if fast_norm {
        MatRef::from_column_major_slice(&x[1..], x.len() - 1, 1).norm_l2()
    } else {
        x[1..].iter().fold(0.0f64, |s, &t| s.hypot(t))
    };
    if tail == 0.0 {
        return None;
    }
    let x0 = x[0];
    let alpha = -x0.signum() * x0.hypot(tail);
    let scale = 1.0 / (x0 - alpha);
    v[0] = 1.0;
    for (vi, &xi) in v[1..].iter_mut().zip(&x[1..]) {
        *vi = xi * scale;
    }
    Some((alpha - x0) / alpha)
}

/// y += a·x.
fn axpy(a: f64, x: &[f64], y: &mut [f64]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi += a * xi;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, StandardNormal};

    /// Blocks (F, G, K) of a random Hamiltonian [F G; K −Fᵀ] and the full matrix.
    fn random_hamiltonian(n: usize, seed: u64) -> ([Mat<f64>; 3], Mat<f64>) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut r = |_: usize, _: usize| -> f64 { StandardNormal.sample(&mut rng) };
        let f = Mat::from_fn(n, n, &mut r);
        let g0 = Mat::from_fn(n, n, &mut r);
        let k0 = Mat::from_fn(n, n, &mut r);
        let g = &g0 + g0.transpose();
        let k = &k0 + k0.transpose();
        let h = full(&f, &g, &k);
        ([f, g, k], h)
    }

    fn full(f: &Mat<f64>, g: &Mat<f64>, k: &Mat<f64>) -> Mat<f64> {
        let n = f.nrows();
        Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
            (true, true) => f[(i, j)],
            (true, false) => g[(i, j - n)],
            (false, true) => k[(i - n, j)],
            (false, false) => -f[(j - n, i - n)],
        })
    }

    /// Reduces [A G; Q Aᵀ] with G, Q stored as `S`; checks the PVL form (Q = 0 and A upper
    /// Hessenberg to rounding) and the invariants of the similarity (Frobenius norm, trace).
    fn reduce_and_check_form<S: SkewBlock>(mut s: SkewHamiltonian<S>, m: &Mat<f64>, what: &str) -> ColMajor {
        let n = s.a.n;
        let scale = m.norm_l2();
        let trace: f64 = (0..n).map(|i| m[(i, i)]).sum();
        s.pvl_reduce();
        let mut off = 0.0f64;
        for j in 0..n {
            for i in 0..n {
                off = off.max(s.q.at(i, j).abs());
                if i > j + 1 {
                    off = off.max(s.a.at(i, j).abs());
                }
            }
        }
        assert!(off <= 1e-13 * scale, "{what} n={n}: residual {off:e} vs ‖M‖ {scale:e}");
        // Similarity: the Frobenius norm of [A G; 0 Aᵀ] equals that of M, trace(A) that of M₁₁.
        let g2: f64 = (0..n).flat_map(|j| (0..n).map(move |i| (i, j))).map(|(i, j)| s.g.at(i, j).powi(2)).sum();
        let fro = (2.0 * s.a.data.iter().map(|x| x * x).sum::<f64>() + g2).sqrt();
        assert!((fro - scale).abs() <= 1e-12 * scale, "{what} n={n}: ‖·‖_F {fro} vs {scale}");
        let t: f64 = (0..n).map(|i| s.a.at(i, i)).sum();
        assert!((t - trace).abs() <= 1e-12 * scale, "{what} n={n}: trace {t} vs {trace}");
        s.a
    }

    #[test]
    fn pvl_form_is_reached_and_similar() {
        for (n, seed) in [(1usize, 1u64), (2, 2), (5, 3), (17, 4), (40, 5), (64, 6)] {
            let (_, h) = random_hamiltonian(n, seed);
            let m = &h * &h;
            let block = |i0: usize, j0: usize| m.as_ref().submatrix(i0, j0, n, n);
            let full = SkewHamiltonian {
                a: ColMajor::from(block(0, 0)),
                g: ColMajor::from(block(0, n)),
                q: ColMajor::from(block(n, 0)),
            };
            reduce_and_check_form(full, &m, "full");
            let tri = SkewHamiltonian {
                a: ColMajor::from(block(0, 0)),
                g: SkewLower::from_lower(block(0, n)),
                q: SkewLower::from_lower(block(n, 0)),
            };
            reduce_and_check_form(tri, &m, "triangular");
        }
    }

    /// A random skew-Hamiltonian [A G; Q Aᵀ] (G, Q skew) after the symplectic diagonal
    /// similarity diag(D, D⁻¹), D = diag(10^(−s/2) … 10^(s/2)): G → DGD, Q → D⁻¹QD⁻¹, A → DAD⁻¹,
    /// same eigenvalues, entries spread over 2s decades.
    fn random_skew_hamiltonian(n: usize, seed: u64, s: f64) -> [Mat<f64>; 3] {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut r = |_: usize, _: usize| -> f64 { StandardNormal.sample(&mut rng) };
        let a = Mat::from_fn(n, n, &mut r);
        let (g0, q0) = (Mat::from_fn(n, n, &mut r), Mat::from_fn(n, n, &mut r));
        let d: Vec<f64> = (0..n).map(|i| 10f64.powf(s * (i as f64 / (n - 1) as f64 - 0.5))).collect();
        [
            Mat::from_fn(n, n, |i, j| d[i] * a[(i, j)] / d[j]),
            Mat::from_fn(n, n, |i, j| d[i] * (g0[(i, j)] - g0[(j, i)]) * d[j]),
            Mat::from_fn(n, n, |i, j| (q0[(i, j)] - q0[(j, i)]) / (d[i] * d[j])),
        ]
    }

    /// The triangular storage of G, Q (used from n = FAST_KERNELS_FROM on) against the full one
    /// and the unstructured solver of the 2n×2n matrix, on random and badly scaled
    /// skew-Hamiltonian matrices: the same PVL form and, eigenvalue for eigenvalue, an error
    /// against the truth (the unscaled matrix's spectrum) within the full storage's.
    #[test]
    fn triangular_storage_matches_full_storage() {
        for (n, seed) in [(30usize, 31u64), (47, 32), (80, 33)] {
            let unscaled = random_skew_hamiltonian(n, seed, 0.0);
            let [a, g, q] = &unscaled;
            let w = Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
                (true, true) => a[(i, j)],
                (true, false) => g[(i, j - n)],
                (false, true) => q[(i - n, j)],
                (false, false) => a[(j - n, i - n)],
            });
            let truth = eigenvalues(w.as_ref()).unwrap();
            for s in [0.0, 4.0, 8.0] {
                let [a, g, q] = random_skew_hamiltonian(n, seed, s);
                let norm = (2.0 * a.squared_norm_l2() + g.squared_norm_l2() + q.squared_norm_l2()).sqrt();
                let m = Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
                    (true, true) => a[(i, j)],
                    (true, false) => g[(i, j - n)],
                    (false, true) => q[(i - n, j)],
                    (false, false) => a[(j - n, i - n)],
                });
                let full = SkewHamiltonian {
                    a: ColMajor::from(a.as_ref()),
                    g: ColMajor::from(g.as_ref()),
                    q: ColMajor::from(q.as_ref()),
                };
                let mut w_full = reduce_and_check_form(full, &m, "full");
                let tri = SkewHamiltonian {
                    a: ColMajor::from(a.as_ref()),
                    g: SkewLower::from_lower(g.as_ref()),
                    q: SkewLower::from_lower(q.as_ref()),
                };
                let mut w_tri = reduce_and_check_form(tri, &m, "triangular");
                let err = |w: &mut ColMajor| -> f64 {
                    let mu = hessenberg_part_eigenvalues(w).unwrap();
                    assert_eq!(mu.len(), n);
                    mu.iter()
                        .map(|x| truth.iter().map(|t| (t - x).norm()).fold(f64::INFINITY, f64::min))
                        .fold(0.0, f64::max)
                };
                let (e_full, e_tri) = (err(&mut w_full), err(&mut w_tri));
                assert!(
                    e_tri <= 10.0 * e_full + ERROR_FACTOR * f64::EPSILON * norm,
                    "n={n} s={s}: triangular storage off by {e_tri:e}, full by {e_full:e} (ε‖W‖ = {:e})",
                    f64::EPSILON * norm
                );
                eprintln!(
                    "n={n} s={s}: max error triangular {e_tri:e}, full {e_full:e}, ε‖W‖_F {:e}",
                    f64::EPSILON * norm
                );
            }
        }
    }

    /// [`hamiltonian_squared_eigenvalues`] for dense G and K (factors G·I and K·I).
    fn dense_squared_eigenvalues(
        f: MatRef<'_, f64>,
        g: MatRef<'_, f64>,
        k: MatRef<'_, f64>,
    ) -> Option<SquaredSpectrum> {
        let id = Mat::<f64>::identity(f.nrows(), f.nrows());
        hamiltonian_squared_eigenvalues(
            f,
            LowRank { left: g, right: id.as_ref() },
            LowRank { left: k, right: id.as_ref() },
        )
    }

    /// Low-rank G = G_L G_Rᵀ and K = K_L K_Rᵀ (the H∞ Hamiltonian's form) give the eigenvalues
    /// of the dense blocks to rounding.
    #[test]
    fn low_rank_blocks_give_the_dense_eigenvalues() {
        let mut rng = ChaCha8Rng::seed_from_u64(31);
        let mut r = |rows: usize, cols: usize| {
            Mat::<f64>::from_fn(rows, cols, |_, _| {
                let z: f64 = StandardNormal.sample(&mut rng);
                z
            })
        };
        for (n, rank) in [(30usize, 1usize), (45, 3)] {
            let f = r(n, n);
            let (gl, kl) = (r(n, rank), r(n, rank));
            let (wg, wk) = (r(rank, rank), r(rank, rank));
            // Symmetric G = G_L W G_Lᵀ and K = K_L W K_Lᵀ (W symmetric).
            let (wg, wk) = (&wg + wg.transpose(), &wk + wk.transpose());
            let (gr, kr) = (&gl * &wg, &kl * &wk);
            let (g, k) = (&gl * gr.transpose(), &kl * kr.transpose());
            let dense = dense_squared_eigenvalues(f.as_ref(), g.as_ref(), k.as_ref()).unwrap();
            let low = hamiltonian_squared_eigenvalues(
                f.as_ref(),
                LowRank { left: gl.as_ref(), right: gr.as_ref() },
                LowRank { left: kl.as_ref(), right: kr.as_ref() },
            )
            .unwrap();
            for mu in &low.mu {
                let off = dense.mu.iter().map(|d| (d - mu).norm()).fold(f64::INFINITY, f64::min);
                assert!(off <= 10.0 * dense.abs_error, "n = {n}: μ = {mu} off by {off:e}");
            }
        }
    }

    #[test]
    fn squared_eigenvalues_match_the_unstructured_solver() {
        for (n, seed) in [(1usize, 11u64), (3, 12), (8, 13), (30, 14)] {
            let ([f, g, k], h) = random_hamiltonian(n, seed);
            let full = eigenvalues(h.as_ref()).unwrap();
            let sq = dense_squared_eigenvalues(f.as_ref(), g.as_ref(), k.as_ref()).unwrap();
            assert_eq!(sq.mu.len(), n);
            // Every μ is the square of some eigenvalue of H, within the stated error (×10 for
            // the unstructured solver's own rounding).
            for mu in &sq.mu {
                let best = full.iter().map(|l| (l * l - mu).norm()).fold(f64::INFINITY, f64::min);
                assert!(
                    best <= 10.0 * sq.abs_error.max(1e-14),
                    "n={n}: μ = {mu}, off by {best:e} (bound {:e})",
                    sq.abs_error
                );
            }
        }
    }

    /// H = [F s·G; K/s −Fᵀ] has the eigenvalues of [F G; K −Fᵀ] for any s > 0. Unbalanced
    /// (s = 1e6), its unscaled square would carry errors ε‖H‖² ≈ 1e-4, far above the bound
    /// 100·ε·‖H²‖_F; balanced, every μ stays within the bound of the balanced matrix.
    #[test]
    fn an_unbalanced_hamiltonian_keeps_its_accuracy() {
        let n = 40;
        let ([f, g, k], h) = random_hamiltonian(n, 21);
        let truth = eigenvalues(h.as_ref()).unwrap();
        let balanced = dense_squared_eigenvalues(f.as_ref(), g.as_ref(), k.as_ref()).unwrap();
        for s in [1e6, 1e-6, 3.3e5] {
            let (gs, ks) = (&g * faer::Scale(s), &k * faer::Scale(1.0 / s));
            assert_eq!(symplectic_balance_exponent(gs.norm_l2(), ks.norm_l2()), (s.log2()).round(), "s = {s}");
            let sq = dense_squared_eigenvalues(f.as_ref(), gs.as_ref(), ks.as_ref()).unwrap();
            assert!(sq.abs_error <= 2.0 * balanced.abs_error, "s = {s}: bound {:e}", sq.abs_error);
            for mu in &sq.mu {
                let off = truth.iter().map(|l| (l * l - mu).norm()).fold(f64::INFINITY, f64::min);
                assert!(off <= 10.0 * sq.abs_error, "s = {s}: μ = {mu} off by {off:e} (bound {:e})", sq.abs_error);
            }
        }
        assert_eq!(symplectic_balance_exponent(0.0, 1.0), 0.0);
        assert_eq!(symplectic_balance_exponent(1.0, 0.0), 0.0);
    }

    #[test]
    fn purely_imaginary_pairs_give_negative_real_squares() {
        // H = [0 I; −diag(ω²) 0]: eigenvalues ±iωₖ, so μ = −ωₖ² exactly.
        let n = 4;
        let omegas = [0.5, 1.0, 3.0, 10.0];
        let f = Mat::<f64>::zeros(n, n);
        let g = Mat::<f64>::identity(n, n);
        let k = Mat::from_fn(n, n, |i, j| if i == j { -omegas[i] * omegas[i] } else { 0.0 });
        let sq = dense_squared_eigenvalues(f.as_ref(), g.as_ref(), k.as_ref()).unwrap();
        let mut got: Vec<f64> = sq.mu.iter().map(|m| m.re).collect();
        got.sort_by(f64::total_cmp);
        let mut want: Vec<f64> = omegas.iter().map(|w| -w * w).collect();
        want.sort_by(f64::total_cmp);
        for (g, w) in got.iter().zip(&want) {
            assert!((g - w).abs() <= 1e-12 * 100.0, "{got:?} vs {want:?}");
        }
        assert!(sq.mu.iter().all(|m| m.im.abs() <= sq.abs_error));
    }

    /// The blocks [A, G, Q] of a skew-Hamiltonian matrix.
    type Blocks = [Mat<f64>; 3];

    /// The dense 2n×2n matrix [A G; Q Aᵀ].
    fn dense_skew_hamiltonian([a, g, q]: &Blocks) -> Mat<f64> {
        let n = a.nrows();
        Mat::from_fn(2 * n, 2 * n, |i, j| match (i < n, j < n) {
            (true, true) => a[(i, j)],
            (true, false) => g[(i, j - n)],
            (false, true) => q[(i - n, j)],
            (false, false) => a[(j - n, i - n)],
        })
    }

    /// The eigenvalues of W from the reduction used from n = FAST_KERNELS_FROM on (triangular
    /// storage), each taken twice, against faer's of the dense 2n×2n matrix, matched one to one
    /// (nearest first) within 10⁻⁸‖M‖_F: random matrices, badly scaled ones (entries over 8 and
    /// 16 decades; compared with the spectrum of the unscaled matrix they are similar to), and
    /// ones that make the reduction skip transformations: Q = 0 (no P₁, no rotation), Q nonzero
    /// only next to its diagonal (no P₁, a rotation per step), A tridiagonal with Q = 0 (nothing).
    #[test]
    fn reduction_keeps_the_spectrum_each_eigenvalue_twice() {
        for (n, seed) in [(30usize, 51u64), (64, 52)] {
            let [a, g, q] = random_skew_hamiltonian(n, seed + 100, 0.0);
            let zero = Mat::<f64>::zeros(n, n);
            let near = Mat::from_fn(n, n, |i, j| match i.cmp(&j) {
                _ if i.abs_diff(j) != 1 => 0.0,
                std::cmp::Ordering::Greater => q[(i, j)],
                _ => -q[(j, i)],
            });
            // Symmetric tridiagonal: Hessenberg with well-conditioned eigenvalues (the Hessenberg
            // part of a random matrix has eigenvalues too ill-conditioned for a dense reference).
            let hess = Mat::from_fn(n, n, |i, j| if i.abs_diff(j) <= 1 { a[(i, j)] + a[(j, i)] } else { 0.0 });
            let mut cases: Vec<(Blocks, Blocks)> = [0.0, 4.0, 8.0]
                .iter()
                .map(|&s| (random_skew_hamiltonian(n, seed, 0.0), random_skew_hamiltonian(n, seed, s)))
                .collect();
            for blocks in [[a.clone(), g.clone(), zero.clone()], [a.clone(), g.clone(), near], [hess, g.clone(), zero]]
            {
                cases.push((blocks.clone(), blocks));
            }
            for (k, (unscaled, blocks)) in cases.iter().enumerate() {
                let truth = eigenvalues(dense_skew_hamiltonian(unscaled).as_ref()).unwrap();
                let m = dense_skew_hamiltonian(blocks);
                let [a, g, q] = blocks;
                let tri = SkewHamiltonian {
                    a: ColMajor::from(a.as_ref()),
                    g: SkewLower::from_lower(g.as_ref()),
                    q: SkewLower::from_lower(q.as_ref()),
                };
                let mut w = reduce_and_check_form(tri, &m, "triangular");
                let mu = hessenberg_part_eigenvalues(&mut w).unwrap();
                let mut left = truth.clone();
                for x in mu.iter().chain(&mu) {
                    let (at, d) = left.iter().map(|t| (t - x).norm()).enumerate().fold((0, f64::INFINITY), |b, c| {
                        if c.1 < b.1 {
                            c
                        } else {
                            b
                        }
                    });
                    assert!(d <= 1e-8 * m.norm_l2(), "n={n} case {k}: μ = {x} off by {d:e}");
                    left.swap_remove(at);
                }
            }
        }
    }
}
