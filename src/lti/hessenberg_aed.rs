//! Eigenvalues (no vectors) of a larger real upper Hessenberg matrix by the QR iteration with
//! aggressive early deflation (issue 13).
//!
//! K. Braman, R. Byers, R. Mathias, "The multishift QR algorithm. Part II: Aggressive early
//! deflation", SIAM J. Matrix Anal. Appl. 23 (2002) 948–973; Kressner, *Numerical Methods for
//! General and Structured Eigenvalue Problems* (2005), §1.6. Each round of the iteration on the
//! active block H(lo..=hi, lo..=hi):
//! 1. **Deflation window**: the trailing w×w block H₂₂ (rows and columns kw..=hi) is brought to
//!    real Schur form, H₂₂ = Z·T·Zᵀ, by the double-shift iteration of `hessenberg_qr.rs` with the
//!    factor accumulated. The similarity diag(I, Z) turns the single subdiagonal entry
//!    s = H(kw, kw−1) coupling the window to the rest into the *spike* s·Zᵀe₁ (column kw−1).
//! 2. **Spike test**: from the bottom of T, a 1×1 or 2×2 block whose spike entries are below
//!    ulp·|λ| (λ: the block's eigenvalue, larger modulus; smlnum at least) is deflated: setting
//!    them to zero perturbs H by at most that much, so its eigenvalues are those of H + E with
//!    ‖E‖ ≤ ulp·‖H‖ (backward stable, as the classical subdiagonal test). The first block that
//!    fails stops the test (no reordering of T).
//! 3. If blocks deflated, the similarity is applied: T and the shortened spike replace the window,
//!    the rows lo..kw−1 above it are multiplied by Z (a matrix product), and Householder
//!    reflections bring the undeflated part (spike and leading block of T) back to Hessenberg
//!    form (Kressner §1.6.1). If none deflated, H is left unchanged.
//! 4. The undeflated window eigenvalues are the shifts: unless the window deflated many
//!    eigenvalues (then the next round deflates again first), they are applied in pairs by
//!    Francis double-shift sweeps over the active block (the bulges of Part I's multishift step,
//!    chased one after another).
//!
//! Values only, as in `hessenberg_qr.rs`: only the active block is updated. After
//! [`EXCEPTIONAL_ROUNDS`] rounds without a deflation an exceptional double shift is used; the
//! double-shift sweeps are counted against the limit of `hessenberg_qr.rs`, beyond which a
//! [`HessenbergQrError`], never a panic or an endless loop.

use faer::linalg::matmul::matmul;
use faer::{c64, Accum, MatMut, MatRef, Par};

use super::hessenberg_qr::{
    clear_below_subdiagonal, householder, iteration_limit, HessenbergQrError, Shifts, Window, EXCEPTIONAL_SHIFT_EVERY,
};

/// From this size of the matrix (and of the active block) on, [`aggressive_deflation_eigenvalues`]
/// serves; smaller active blocks are finished by the double-shift iteration.
pub(crate) const AGGRESSIVE_DEFLATION_FROM: usize = 75;
/// A round whose window deflated more than this percentage of its size skips the sweep and
/// deflates again (the "nibble" crossover of Braman, Byers & Mathias).
const NIBBLE_PERCENT: usize = 14;
/// A slab of the chained sweep takes this many times 3·(number of bulges) time steps.
const SLAB_STEPS_PER_ROW: usize = 1;
/// At least this many time steps per slab.
const MIN_SLAB_STEPS: usize = 24;
/// An exceptional double shift after this many rounds without a deflation.
const EXCEPTIONAL_ROUNDS: usize = 6;

/// The deflation window's size for an active block of `size` rows (at least 2 less than it).
fn window_size(size: usize) -> usize {
    let w = if size < 150 { 10 } else { (size / (usize::BITS - size.leading_zeros()) as usize).max(10) };
    w.min(size - 2)
}

/// Scratch space of the deflation windows, reused over the rounds.
#[derive(Default)]
struct Workspace {
    /// The window's Schur form T (w×w, column-major).
    t: Vec<f64>,
    /// Its orthogonal factor Z (w×w, column-major).
    z: Vec<f64>,
    /// T's eigenvalues, in the order of its diagonal blocks.
    eig: Vec<c64>,
    /// The spike s·Zᵀe₁ of the undeflated part.
    spike: Vec<f64>,
    /// The product of the rows above the window with Z.
    above: Vec<f64>,
    /// The shifts for the next sweeps: the undeflated eigenvalues.
    shifts: Vec<c64>,
    /// The orthogonal factor of a slab of the chained sweep.
    u: Vec<f64>,
}

/// The eigenvalues of the n×n upper Hessenberg matrix `h` (column-major; as
/// `hessenberg_qr::hessenberg_eigenvalues`, which calls this from [`AGGRESSIVE_DEFLATION_FROM`]
/// on). `h` is overwritten.
pub(crate) fn aggressive_deflation_eigenvalues(h: &mut [f64], n: usize) -> Result<Vec<c64>, HessenbergQrError> {
    assert_eq!(h.len(), n * n, "hessenberg_eigenvalues: storage does not match the size");
    let mut ev = vec![c64::new(0.0, 0.0); n];
    if n == 0 {
        return Ok(ev);
    }
    clear_below_subdiagonal(h, n);
    let ulp = f64::EPSILON;
    let smlnum = f64::MIN_POSITIVE * (n as f64 / ulp);
    let limit = iteration_limit(n);
    let mut ws = Workspace::default();
    let mut hi = n - 1;
    // Double-shift sweeps and rounds since the last deflation.
    let (mut sweeps, mut rounds) = (0usize, 0usize);
    loop {
        let mut qr = Window::values_only(h, n);
        let lo = qr.small_subdiagonal(0, hi, ulp, smlnum);
        if lo > 0 {
            qr.set(lo, lo - 1, 0.0);
        }
        let size = hi + 1 - lo;
        if size < AGGRESSIVE_DEFLATION_FROM {
            qr.converge_block(lo, hi, &mut ev, limit)
                .map_err(|e| HessenbergQrError { converged: n - 1 - hi + e.converged, ..e })?;
            if lo == 0 {
                return Ok(ev);
            }
            hi = lo - 1;
            sweeps = 0;
            rounds = 0;
            continue;
        }
        if sweeps > limit {
            return Err(HessenbergQrError { n, converged: n - 1 - hi, iterations: limit });
        }
        let w = window_size(size);
        let deflated = deflate_window(h, n, lo, hi, w, &mut ev, &mut ws);
        hi -= deflated;
        if deflated > 0 {
            sweeps = 0;
            rounds = 0;
        } else {
            rounds += 1;
        }
        if deflated * 100 > w * NIBBLE_PERCENT {
            continue;
        }
        let mut qr = Window::values_only(h, n);
        if rounds > 0 && rounds.is_multiple_of(EXCEPTIONAL_ROUNDS) || ws.shifts.len() < 2 {
            // Top and bottom exceptional shifts alternate (`Window::shifts`).
            let which = if (rounds / EXCEPTIONAL_ROUNDS).is_multiple_of(2) { 1 } else { 2 };
            let shifts = qr.shifts(lo, hi, which * EXCEPTIONAL_SHIFT_EVERY);
            let (m, v) = qr.bulge_start(lo, hi, shifts, ulp);
            qr.double_shift_step(lo, m, hi, v);
            sweeps += 1;
            continue;
        }
        let pairs = shift_pairs(&ws.shifts);
        sweeps += pairs.len();
        chained_sweep(h, n, lo, hi, &pairs, &mut ws);
    }
}

/// The shifts grouped into the pairs of double-shift steps: each complex pair (λ, λ̄) as it
/// comes, the real ones two by two in order (an odd one out is dropped).
fn shift_pairs(shifts: &[c64]) -> Vec<Shifts> {
    let mut pairs = Vec::with_capacity(shifts.len() / 2);
    let mut real: Option<f64> = None;
    let mut k = 0;
    while k < shifts.len() {
        let z = shifts[k];
        if z.im != 0.0 && k + 1 < shifts.len() {
            pairs.push(Shifts { re1: z.re, im1: z.im, re2: shifts[k + 1].re, im2: shifts[k + 1].im });
            k += 2;
            continue;
        }
        match real.take() {
            Some(r) => pairs.push(Shifts { re1: r, im1: 0.0, re2: z.re, im2: 0.0 }),
            None => real = Some(z.re),
        }
        k += 1;
    }
    pairs
}

/// One aggressive early deflation (module docs, steps 1–3) on the trailing w×w window of the
/// active block lo..=hi (w ≤ hi − lo − 1): the deflated eigenvalues into ev[hi+1−d..=hi], the
/// undeflated ones into `ws.shifts`; returns d. If the window's QR fails, nothing deflates and
/// there are no shifts.
fn deflate_window(
    h: &mut [f64],
    n: usize,
    lo: usize,
    hi: usize,
    w: usize,
    ev: &mut [c64],
    ws: &mut Workspace,
) -> usize {
    let kw = hi + 1 - w;
    let s = h[kw + (kw - 1) * n];
    ws.t.clear();
    ws.t.extend((0..w * w).map(|k| {
        let (r, c) = (k % w, k / w);
        if r <= c + 1 {
            h[(kw + r) + (kw + c) * n]
        } else {
            0.0
        }
    }));
    ws.z.clear();
    ws.z.extend((0..w * w).map(|k| if k % w == k / w { 1.0 } else { 0.0 }));
    ws.eig.clear();
    ws.eig.resize(w, c64::new(0.0, 0.0));
    ws.shifts.clear();
    if Window::schur_form(&mut ws.t, &mut ws.z, w).converge_block(0, w - 1, &mut ws.eig, iteration_limit(w)).is_err() {
        return 0;
    }
    let ns = undeflated(&ws.t, &ws.z, &ws.eig, w, s);
    ws.shifts.extend_from_slice(&ws.eig[..ns]);
    let deflated = w - ns;
    if deflated == 0 {
        return 0;
    }
    ev[kw + ns..=hi].copy_from_slice(&ws.eig[ns..]);
    ws.spike.clear();
    ws.spike.extend((0..ns).map(|j| s * ws.z[j * w]));
    restore_hessenberg(&mut ws.t, &mut ws.z, &mut ws.spike, w);
    h[kw + (kw - 1) * n] = ws.spike.first().copied().unwrap_or(0.0);
    for r in kw + 1..=hi {
        h[r + (kw - 1) * n] = 0.0;
    }
    for c in 0..w {
        h[kw + (kw + c) * n..=hi + (kw + c) * n].copy_from_slice(&ws.t[c * w..(c + 1) * w]);
    }
    if kw > lo {
        multiply_rows_above(h, n, lo, kw, w, MatRef::from_column_major_slice(&ws.z, w, w), &mut ws.above);
    }
    deflated
}

/// The spike test (module docs, step 2) on the w×w Schur form `t` with factor `z`, eigenvalues
/// `eig` and coupling entry `s`: the number of leading rows that stay undeflated.
fn undeflated(t: &[f64], z: &[f64], eig: &[c64], w: usize, s: f64) -> usize {
    let ulp = f64::EPSILON;
    let smlnum = f64::MIN_POSITIVE * (w as f64 / ulp);
    let mut ns = w;
    while ns > 0 {
        let block = if ns >= 2 && t[(ns - 1) + (ns - 2) * w] != 0.0 { 2 } else { 1 };
        let size = eig[ns - block..ns].iter().fold(0.0f64, |m, e| m.max(e.norm()));
        let spike = (ns - block..ns).fold(0.0f64, |m, j| m.max((s * z[j * w]).abs()));
        if spike > smlnum.max(ulp * size) {
            break;
        }
        ns -= block;
    }
    ns
}

/// Householder reduction of the undeflated part back to Hessenberg form (module docs, step 3):
/// with ns = `spike.len()`, the ns×(1 + ns) matrix [spike, T(0..ns, 0..ns)] is reduced column by
/// column (GVL Alg. 7.4.2); each reflection acts on rows of T (all its columns, so the block
/// coupling to the deflated part follows), on columns of T's leading block, and on columns of
/// Z. Afterwards only spike[0] is nonzero.
fn restore_hessenberg(t: &mut [f64], z: &mut [f64], spike: &mut [f64], w: usize) {
    let ns = spike.len();
    let mut u = Vec::with_capacity(ns);
    for k in 0..ns.saturating_sub(1) {
        // The column to reduce: the spike, then T's columns 0, 1, …; rows k..ns.
        u.clear();
        if k == 0 {
            u.extend_from_slice(spike);
        } else {
            u.extend_from_slice(&t[k + (k - 1) * w..ns + (k - 1) * w]);
        }
        let (beta, tau) = householder(u[0], &mut u[1..]);
        if k == 0 {
            spike.fill(0.0);
            spike[0] = beta;
        } else {
            t[k + (k - 1) * w..ns + (k - 1) * w].fill(0.0);
            t[k + (k - 1) * w] = beta;
        }
        if tau == 0.0 {
            continue;
        }
        u[0] = 1.0;
        // Rows k..ns of T, columns k.. (column k − 1 is done): P·T.
        for col in t[k * w..].chunks_exact_mut(w) {
            let x = &mut col[k..ns];
            let sum: f64 = x.iter().zip(&u).map(|(a, b)| a * b).sum::<f64>() * tau;
            x.iter_mut().zip(&u).for_each(|(a, b)| *a -= sum * b);
        }
        // Columns k..ns of T (rows 0..ns) and of Z (all rows): X·P.
        reflect_columns(t, w, k, 0..ns, &u, tau);
        reflect_columns(z, w, k, 0..w, &u, tau);
    }
}

/// X ← X·(I − τ·u·uᵀ) on the columns k..k+len(u) of the column-major `x` (leading dimension
/// ld), rows `rows`.
fn reflect_columns(x: &mut [f64], ld: usize, k: usize, rows: std::ops::Range<usize>, u: &[f64], tau: f64) {
    for r in rows {
        let sum: f64 = u.iter().enumerate().map(|(j, uj)| x[r + (k + j) * ld] * uj).sum::<f64>() * tau;
        for (j, uj) in u.iter().enumerate() {
            x[r + (k + j) * ld] -= sum * uj;
        }
    }
}

/// The double-shift sweeps of all `pairs` at once on the active block lo..=hi, as a chain of
/// bulges three rows apart (Braman, Byers & Mathias, Part I): at each time step every bulge
/// moves down one row, the lowest first. Bulge j is introduced at row lo three steps after bulge
/// j − 1; the reflections of different bulges act on disjoint index ranges and those a bulge's
/// next reflection reads are final, so the result is that of the sweeps one after another, in
/// exact arithmetic.
///
/// Delayed updates (Part I, §2.3): the time steps go in slabs of [`SLAB_STEPS_PER_ROW`]·3·nb
/// steps; a slab's reflections act on the diagonal block a..b that holds them (everything they
/// read lies there) and are accumulated into its orthogonal factor U; then the rows above
/// (H[lo..a, a..b]·U) and the columns right of it (Uᵀ·H[a..b, b..=hi]) are updated by two
/// matrix products.
fn chained_sweep(h: &mut [f64], n: usize, lo: usize, hi: usize, pairs: &[Shifts], ws: &mut Workspace) {
    let nb = pairs.len();
    if nb == 0 {
        return;
    }
    let steps = (hi - lo) + 3 * (nb - 1);
    let slab = (SLAB_STEPS_PER_ROW * 3 * nb).max(MIN_SLAB_STEPS);
    let mut t0 = 0;
    while t0 < steps {
        let t1 = (t0 + slab).min(steps);
        // Bulge j's reflection at time t is at row lo + t − 3j, for rows lo..hi − 1.
        let kmin = (lo + t0).saturating_sub(3 * (nb - 1)).max(lo);
        let kmax = (lo + t1 - 1).min(hi - 1);
        let a = if kmin == lo { lo } else { kmin - 1 };
        let b = (kmax + 4).min(hi + 1);
        let w = b - a;
        ws.u.clear();
        ws.u.extend((0..w * w).map(|k| if k % w == k / w { 1.0 } else { 0.0 }));
        let mut qr = Window::values_only(h, n);
        for t in t0..t1 {
            for (j, pair) in pairs.iter().enumerate() {
                let Some(k) = (lo + t).checked_sub(3 * j).filter(|&k| k >= lo) else { break };
                if k >= hi {
                    continue;
                }
                let first = (k == lo).then(|| qr.first_column(lo, *pair));
                if let Some(r) = qr.chase_reflector(lo, hi, k, first) {
                    qr.reflect(r, hi, k, a, b);
                    r.apply_right(&mut ws.u[(k - a) * w..(k - a + r.len) * w], w, 0..w);
                }
            }
        }
        let u = MatRef::from_column_major_slice(&ws.u, w, w);
        if b <= hi {
            let cols = hi + 1 - b;
            ws.above.clear();
            ws.above.resize(w * cols, 0.0);
            let right = MatRef::from_column_major_slice_with_stride(&h[a + b * n..], w, cols, n);
            matmul(
                MatMut::from_column_major_slice_mut(&mut ws.above, w, cols),
                Accum::Replace,
                u.transpose(),
                right,
                1.0,
                Par::Seq,
            );
            for c in 0..cols {
                h[a + (b + c) * n..b + (b + c) * n].copy_from_slice(&ws.above[c * w..(c + 1) * w]);
            }
        }
        if a > lo {
            multiply_rows_above(h, n, lo, a, w, u, &mut ws.above);
        }
        t0 = t1;
    }
}

/// H[lo..a, a..a+w] ← H[lo..a, a..a+w]·U (`scratch`: the product's storage).
fn multiply_rows_above(
    h: &mut [f64],
    n: usize,
    lo: usize,
    a: usize,
    w: usize,
    u: MatRef<'_, f64>,
    scratch: &mut Vec<f64>,
) {
    let rows = a - lo;
    scratch.clear();
    scratch.resize(rows * w, 0.0);
    let top = MatRef::from_column_major_slice_with_stride(&h[lo + a * n..], rows, w, n);
    matmul(MatMut::from_column_major_slice_mut(scratch, rows, w), Accum::Replace, top, u, 1.0, Par::Seq);
    for c in 0..w {
        h[lo + (a + c) * n..a + (a + c) * n].copy_from_slice(&scratch[c * rows..(c + 1) * rows]);
    }
}
