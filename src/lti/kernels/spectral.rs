//! Spectral abscissa α(M) = max Re λ(M), spectral radius ρ(M) = max |λ(M)| and their gradients
//! (docs/ALGORITHMS.md §4, §10.1).
//!
//! For a simple eigenvalue λ with right eigenvector v (M v = λ v) and left eigenvector u
//! (uᴴ M = λ uᴴ), first-order perturbation theory gives dλ = uᴴ dM v / (uᴴ v), hence
//!
//! ```text
//! ∇α(M) = Re( ū vᵀ ) / (uᴴ v)      (a real matrix; ⟨G, dM⟩ = Σ G_ij dM_ij)
//! ```
//!
//! and, for the eigenvalue λ of largest modulus (d|λ| = Re(λ̄ dλ)/|λ|),
//!
//! ```text
//! ∇ρ(M) = Re( (λ̄/|λ|) ū vᵀ ) / (uᴴ v)
//! ```
//!
//! (Burke, Henrion, Lewis & Overton, "HIFOO — a MATLAB package for fixed-order controller design
//! and H∞ optimization", IFAC ROCOND 2006.) Left and right eigenvectors come from one call to faer's
//! `evd_real` (LAPACK `dgeev`-style packing).
//!
//! * **Complex pairs.** Both members of a conjugate pair give the same real gradient; we always
//!   use the member with Im λ > 0.
//! * **Ties** between distinct eigenvalues with equal real part: the first one is used (α is not
//!   differentiable there; any member of the subdifferential is acceptable to BFGS / gradient
//!   sampling, as in HIFOO).
//! * **Nearly defective eigenvalues.** Then uᴴv → 0 and the true gradient blows up (α is not
//!   Lipschitz at a defective eigenvalue). HIFOO perturbs V until V⁻¹ is finite; we instead keep
//!   the direction and bound the magnitude: |uᴴv| is replaced by
//!   max(|uᴴv|, [`MIN_EIGVEC_COSINE`]·‖u‖‖v‖) with the phase of uᴴv kept, so the gradient is
//!   always finite (‖∇α‖ ≤ 1/MIN_EIGVEC_COSINE) and points the right way.
//! * **NaN / Inf** entries, or an eigensolver failure: α = +∞ (treated as unstable); so is ρ.
//! * The same rules hold for ρ (pairs: the member with Im λ > 0; ties in |λ|, e.g. λ and −λ: the
//!   first; the same regularised uᴴv).

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::evd::{self, ComputeEigenvectors};
use faer::{c64, Mat, MatRef, Par};

use super::freq_response::hessenberg_qr_eigenvalues;
use super::hessenberg_qr::HESSENBERG_QR_FROM;

/// Lower bound on the cosine |uᴴv|/(‖u‖‖v‖) between left and right eigenvectors used in the
/// gradient (the reciprocal of the largest eigenvalue condition number we trust); ≈ 1000 ε.
pub const MIN_EIGVEC_COSINE: f64 = 1e-13;

/// α(A) = max Re λ(A): −∞ for a 0×0 matrix, +∞ if A has non-finite entries or the eigensolver fails.
pub fn spectral_abscissa(a: MatRef<'_, f64>) -> f64 {
    if a.nrows() == 0 {
        return f64::NEG_INFINITY;
    }
    match eigenvalues(a) {
        Some(ev) => abscissa_of(&ev),
        None => f64::INFINITY,
    }
}

/// Whether a system with spectral abscissa `spectral_abscissa` (= α(A), from
/// [`spectral_abscissa`]) is (asymptotically) stable: α < 0, **strictly**.
///
/// The one stability test of the crate. Strict, because α = 0 puts a pole on the imaginary axis:
/// the system is then not asymptotically stable and its H∞ norm is infinite (or undefined), so a
/// controller at α = 0 is no stabilising controller. A NaN abscissa (a failed computation) is
/// not stable. No margin is added: this is the optimiser's test (its objective must not move);
/// verification and reports use [`is_stable_with_margin`] (docs/ALGORITHMS.md §3.1, §5).
/// −∞ (an empty matrix, e.g. Ak of an order-0 controller) counts as stable.
pub fn is_stable(spectral_abscissa: f64) -> bool {
    spectral_abscissa < 0.0
}

/// Relative stability margin of verification and reporting: 1e-12 (about 4 500 ulps of 1).
///
/// The optimiser decides with [`is_stable`] (α < 0, so its objective and its controllers are
/// what they always were); whatever verifies or reports a controller decides with
/// [`is_stable_with_margin`]: α < −[`stability_margin`]. A computed abscissa carries a rounding
/// error of about ε_mach·‖A‖ (more for non-normal matrices), so α = −4.4e-16 on a matrix of norm
/// 1 is not evidence of stability: the closed loop may have a pole on the imaginary axis. The
/// margin is far below any damping a design aims at (a stable Ak near the axis costs ε‖K‖∞ ~
/// 1/|α|), so no real result is refused by it.
pub const STABILITY_MARGIN_RTOL: f64 = 1e-12;

/// The stability margin of a system matrix `a`: [`STABILITY_MARGIN_RTOL`] · max(1, ‖B‖_F) with B
/// the balanced `a` where balancing pays
/// (`kernels::balance::balanced_for_eigenvalues`: the same eigenvalues,
/// computed with a rounding error of about ε_mach·‖B‖ by [`verified_spectral_abscissa`]), else
/// `a` itself. The Frobenius norm
/// bounds the 2-norm and costs one pass. For a well-scaled matrix B = A; for a badly scaled one
/// (COMPleib's EB6: ‖A‖_F = 1.3e8 but ‖B‖_F ≈ 1e4) ‖A‖_F would be a margin far above the
/// eigenvalues' real error, and would throw away stabilising controllers of a lightly damped
/// plant.
pub fn stability_margin(a: MatRef<'_, f64>) -> f64 {
    let norm = super::balance::balanced_for_eigenvalues(a).map_or_else(|| a.norm_l2(), |b| b.norm_l2());
    STABILITY_MARGIN_RTOL * norm.max(1.0)
}

/// α(A) as verification and reports compute it: [`spectral_abscissa`] of the balanced A where
/// balancing pays, whose eigenvalues are A's, with a rounding error of the scale of
/// [`stability_margin`] (the optimiser uses [`spectral_abscissa`] of A itself; the two are bit for
/// bit the same wherever balancing does not pay, which is every well-scaled matrix).
pub fn verified_spectral_abscissa(a: MatRef<'_, f64>) -> f64 {
    super::balance::balanced_for_eigenvalues(a).map_or_else(|| spectral_abscissa(a), |b| spectral_abscissa(b.as_ref()))
}

/// ρ(A) as verification computes it: [`spectral_radius`] of the balanced A (as
/// [`verified_spectral_abscissa`]).
pub fn verified_spectral_radius(a: MatRef<'_, f64>) -> f64 {
    super::balance::balanced_for_eigenvalues(a).map_or_else(|| spectral_radius(a), |b| spectral_radius(b.as_ref()))
}

/// Whether a system of state matrix `a` with spectral abscissa `alpha` is stable with the
/// verification margin: α < −[`stability_margin`]`(a)`. NaN is not stable; −∞ (an empty matrix)
/// is.
pub fn is_stable_with_margin(alpha: f64, a: MatRef<'_, f64>) -> bool {
    alpha < -stability_margin(a)
}

/// ρ(A) = max |λ(A)|, the spectral radius (the discrete-time counterpart of
/// [`spectral_abscissa`]): 0 for a 0×0 matrix (no dynamics), +∞ if A has non-finite entries or
/// the eigensolver fails. Same eigenvalues as [`spectral_abscissa`].
pub fn spectral_radius(a: MatRef<'_, f64>) -> f64 {
    match eigenvalues(a) {
        Some(ev) => radius_of(&ev),
        None => f64::INFINITY,
    }
}

/// Whether a discrete-time system with spectral radius `rho` (= ρ(A), from [`spectral_radius`])
/// is (asymptotically) stable: ρ < 1, **strictly** (a pole on the unit circle makes the H∞ norm
/// infinite). NaN is not stable; 0 (an empty matrix) is. The optimiser's test, as
/// [`is_stable`] is in continuous time.
pub fn is_schur_stable(rho: f64) -> bool {
    rho < 1.0
}

/// Whether a discrete-time system of state matrix `a` with spectral radius `rho` is stable with
/// the verification margin: ρ < 1 − [`stability_margin`]`(a)` (the eigenvalues' rounding error
/// is absolute, of order ε‖A‖, as in [`is_stable_with_margin`]). NaN is not stable.
pub fn is_schur_stable_with_margin(rho: f64, a: MatRef<'_, f64>) -> bool {
    rho < 1.0 - stability_margin(a)
}

/// Eigenvalues of a real square matrix; `None` on non-finite input or failure. From n =
/// [`HESSENBERG_QR_FROM`] on by a Hessenberg reduction and our Francis QR (`hessenberg_qr.rs`,
/// faster than faer's `evd_real` and exactly the poles the H∞ norm uses), below it by faer.
pub(crate) fn eigenvalues(a: MatRef<'_, f64>) -> Option<Vec<c64>> {
    let n = a.nrows();
    if n == 0 {
        return Some(Vec::new());
    }
    if !crate::numeric::all_finite(a) {
        return None;
    }
    if n >= HESSENBERG_QR_FROM {
        return hessenberg_qr_eigenvalues(a);
    }
    let mut wr = faer::diag::Diag::<f64>::zeros(n);
    let mut wi = faer::diag::Diag::<f64>::zeros(n);
    let par = Par::Seq;
    let mut mem = MemBuffer::new(evd::evd_scratch::<f64>(
        n,
        ComputeEigenvectors::No,
        ComputeEigenvectors::No,
        par,
        Default::default(),
    ));
    evd::evd_real(a, wr.as_mut(), wi.as_mut(), None, None, par, MemStack::new(&mut mem), Default::default()).ok()?;
    Some((0..n).map(|i| c64::new(wr[i], wi[i])).collect())
}

/// max Re λ over a spectrum; +∞ if any eigenvalue is not finite.
pub(crate) fn abscissa_of(ev: &[c64]) -> f64 {
    let mut alpha = f64::NEG_INFINITY;
    for l in ev {
        if !(l.re.is_finite() && l.im.is_finite()) {
            return f64::INFINITY;
        }
        alpha = alpha.max(l.re);
    }
    alpha
}

/// max |λ| over a spectrum (0 for an empty one); +∞ if any eigenvalue is not finite.
pub(crate) fn radius_of(ev: &[c64]) -> f64 {
    let mut rho = 0.0f64;
    for l in ev {
        if !(l.re.is_finite() && l.im.is_finite()) {
            return f64::INFINITY;
        }
        rho = rho.max(l.re.hypot(l.im));
    }
    rho
}

/// An extreme eigenvalue (the rightmost, or one of largest modulus) with its left and right
/// eigenvectors.
#[derive(Debug, Clone)]
pub(crate) struct ExtremeEigen {
    /// The eigenvalue λ (the member with Im λ ≥ 0 of a conjugate pair).
    pub lambda: c64,
    /// Left eigenvector u (uᴴ A = λ uᴴ).
    pub u: Vec<c64>,
    /// Right eigenvector v scaled by 1/(uᴴv) (regularised, see the module docs), so that
    /// ∇α = Re(ū vᵀ); for the spectral radius ([`largest_modulus_eigen`]) further by λ̄/|λ|, so
    /// that ∇ρ = Re(ū vᵀ).
    pub v_scaled: Vec<c64>,
}

/// Rightmost eigen-triple of A (n ≥ 1); `None` for non-finite input or eigensolver failure.
pub(crate) fn rightmost_eigen(a: MatRef<'_, f64>) -> Option<ExtremeEigen> {
    extreme_eigen(a, |re, _| re)
}

/// Eigen-triple of A (n ≥ 1) of largest modulus |λ| = ρ(A), with `v_scaled` also multiplied by
/// the phase λ̄/|λ| (1 for λ = 0), so that ∇ρ = Re(ū vᵀ) (module docs); `None` for non-finite
/// input or eigensolver failure.
pub(crate) fn largest_modulus_eigen(a: MatRef<'_, f64>) -> Option<ExtremeEigen> {
    let mut e = extreme_eigen(a, f64::hypot)?;
    let r = e.lambda.norm();
    if r > 0.0 {
        let phase = e.lambda.conj() * (1.0 / r);
        e.v_scaled.iter_mut().for_each(|z| *z *= phase);
    }
    Some(e)
}

/// The eigen-triple of A (n ≥ 1) maximising `key(Re λ, Im λ)` (the first on ties; `key` must
/// give both members of a conjugate pair the same value), right eigenvector scaled by 1/(uᴴv);
/// `None` for non-finite input or eigensolver failure.
fn extreme_eigen(a: MatRef<'_, f64>, key: impl Fn(f64, f64) -> f64) -> Option<ExtremeEigen> {
    let n = a.nrows();
    if n == 0 || !crate::numeric::all_finite(a) {
        return None;
    }
    let par = Par::Seq;
    let mut wr = faer::diag::Diag::<f64>::zeros(n);
    let mut wi = faer::diag::Diag::<f64>::zeros(n);
    let mut vl = Mat::<f64>::zeros(n, n);
    let mut vr = Mat::<f64>::zeros(n, n);
    let mut mem = MemBuffer::new(evd::evd_scratch::<f64>(
        n,
        ComputeEigenvectors::Yes,
        ComputeEigenvectors::Yes,
        par,
        Default::default(),
    ));
    evd::evd_real(
        a,
        wr.as_mut(),
        wi.as_mut(),
        Some(vl.as_mut()),
        Some(vr.as_mut()),
        par,
        MemStack::new(&mut mem),
        Default::default(),
    )
    .ok()?;
    let mut k = 0;
    for i in 0..n {
        if !(wr[i].is_finite() && wi[i].is_finite()) {
            return None;
        }
        if key(wr[i], wi[i]) > key(wr[k], wi[k]) {
            k = i;
        }
    }
    // dgeev packing: a pair occupies columns (j, j+1) with wi[j] > 0, v = vr[:,j] + i vr[:,j+1].
    let (u, v): (Vec<c64>, Vec<c64>) = if wi[k] == 0.0 {
        ((0..n).map(|i| c64::new(vl[(i, k)], 0.0)).collect(), (0..n).map(|i| c64::new(vr[(i, k)], 0.0)).collect())
    } else {
        let j = if wi[k] > 0.0 { k } else { k - 1 };
        (
            (0..n).map(|i| c64::new(vl[(i, j)], vl[(i, j + 1)])).collect(),
            (0..n).map(|i| c64::new(vr[(i, j)], vr[(i, j + 1)])).collect(),
        )
    };
    let s = u.iter().zip(&v).fold(c64::new(0.0, 0.0), |acc, (ui, vi)| acc + ui.conj() * vi);
    let norm = |x: &[c64]| x.iter().map(|z| z.norm_sqr()).sum::<f64>().sqrt();
    let floor = MIN_EIGVEC_COSINE * norm(&u) * norm(&v);
    let s = if s.norm() >= floor {
        s
    } else if s.norm() > 0.0 {
        s * (floor / s.norm())
    } else {
        c64::new(floor, 0.0)
    };
    if !(s.norm() > 0.0) || !s.re.is_finite() {
        return None;
    }
    // ∇α = Re(ū vᵀ / s): fold 1/s into v.
    let sinv = s.inv();
    let v_scaled = v.into_iter().map(|z| z * sinv).collect();
    Some(ExtremeEigen { lambda: c64::new(wr[k], wi[k].abs()), u, v_scaled })
}

/// ∇α(A) as a dense real matrix Re(ū vᵀ)/(uᴴv); `None` where α is +∞.
pub fn spectral_abscissa_grad(a: MatRef<'_, f64>) -> Option<(f64, Mat<f64>)> {
    let e = rightmost_eigen(a)?;
    Some((e.lambda.re, e.real_gradient()))
}

impl ExtremeEigen {
    /// The real matrix Re(ū vᵀ) (with `v_scaled` for v): ∇α or ∇ρ.
    pub(crate) fn real_gradient(&self) -> Mat<f64> {
        let n = self.u.len();
        Mat::from_fn(n, n, |i, j| (self.u[i].conj() * self.v_scaled[j]).re)
    }
}

/// ∇ρ(A) as a dense real matrix Re((λ̄/|λ|) ū vᵀ)/(uᴴv) for the eigenvalue λ of largest modulus
/// (module docs); `None` where ρ is +∞ or A is 0×0. At ρ = 0 (A nilpotent) ρ is not
/// differentiable and the phase λ̄/|λ| is taken as 1.
pub fn spectral_radius_grad(a: MatRef<'_, f64>) -> Option<(f64, Mat<f64>)> {
    let e = largest_modulus_eigen(a)?;
    Some((e.lambda.norm(), e.real_gradient()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn verified_abscissa_of_a_badly_scaled_matrix_is_accurate() {
        // A = T·M·T⁻¹: the same eigenvalues as M, entries up to 1e12
        let (m, a) = crate::lti::kernels::balance::tests::badly_scaled_3x3();
        let alpha_m = spectral_abscissa(m.as_ref());
        assert!((verified_spectral_abscissa(a.as_ref()) - alpha_m).abs() < 1e-13);
        assert!(stability_margin(a.as_ref()) < 1e-10, "{}", stability_margin(a.as_ref()));
        // a well-scaled matrix: the optimiser's abscissa, bit for bit
        assert_eq!(verified_spectral_abscissa(m.as_ref()).to_bits(), alpha_m.to_bits());
    }

    #[test]
    fn the_verification_margin_scales_with_the_matrix() {
        // Α = −4.4e-16 was called stable.
        let one = faer::Mat::from_fn(2, 2, |i, j| if i == j { -1.0 } else { 0.0 });
        assert!(!is_stable_with_margin(-4.4e-16, one.as_ref()));
        assert!(is_stable_with_margin(-1e-11, one.as_ref()));
        assert!(!is_stable_with_margin(f64::NAN, one.as_ref()));
        let big = faer::Mat::from_fn(1, 1, |_, _| -1e6);
        assert_eq!(stability_margin(big.as_ref()), 1e-6);
        assert!(!is_stable_with_margin(-1e-7, big.as_ref()));
        let empty = faer::Mat::<f64>::zeros(0, 0);
        assert!(is_stable_with_margin(f64::NEG_INFINITY, empty.as_ref()));
        // the optimiser's test is unchanged
        assert!(is_stable(-4.4e-16));
    }

    #[test]
    fn empty_and_nan() {
        assert_eq!(spectral_abscissa(Mat::<f64>::zeros(0, 0).as_ref()), f64::NEG_INFINITY);
        let mut a = Mat::<f64>::identity(3, 3);
        a[(1, 2)] = f64::NAN;
        assert_eq!(spectral_abscissa(a.as_ref()), f64::INFINITY);
        a[(1, 2)] = f64::INFINITY;
        assert_eq!(spectral_abscissa(a.as_ref()), f64::INFINITY);
    }

    #[test]
    fn complex_pair_gradient_matches_fd() {
        // rotation-like block with a real eigenvalue further left
        let a = Mat::from_fn(3, 3, |i, j| [[-0.5, 2.0, 0.3], [-1.5, -0.4, 0.1], [0.2, 0.7, -3.0]][i][j]);
        let (alpha, g) = spectral_abscissa_grad(a.as_ref()).unwrap();
        assert!((alpha - spectral_abscissa(a.as_ref())).abs() < 1e-14);
        let h = 1e-6;
        for i in 0..3 {
            for j in 0..3 {
                let mut ap = a.clone();
                ap[(i, j)] += h;
                let mut am = a.clone();
                am[(i, j)] -= h;
                let fd = (spectral_abscissa(ap.as_ref()) - spectral_abscissa(am.as_ref())) / (2.0 * h);
                assert!((fd - g[(i, j)]).abs() < 1e-7, "({i},{j}) fd {fd} vs {}", g[(i, j)]);
            }
        }
    }

    #[test]
    fn defective_gradient_is_finite() {
        // Jordan block: uᴴv = 0 exactly in exact arithmetic.
        let a = Mat::from_fn(3, 3, |i, j| {
            if i == j {
                -1.0
            } else if j == i + 1 {
                1.0
            } else {
                0.0
            }
        });
        let (alpha, g) = spectral_abscissa_grad(a.as_ref()).unwrap();
        assert!((alpha + 1.0).abs() < 1e-4);
        assert!((0..3).all(|i| (0..3).all(|j| g[(i, j)].is_finite())));
    }

    /// A dense 3×3 from rows.
    fn m3(rows: [[f64; 3]; 3]) -> Mat<f64> {
        Mat::from_fn(3, 3, |i, j| rows[i][j])
    }

    /// Central differences of `f` against the gradient `g`, entry by entry.
    fn assert_fd(a: &Mat<f64>, g: &Mat<f64>, f: impl Fn(MatRef<'_, f64>) -> f64, tol: f64) {
        let h = 1e-6;
        for i in 0..a.nrows() {
            for j in 0..a.ncols() {
                let (mut ap, mut am) = (a.clone(), a.clone());
                ap[(i, j)] += h;
                am[(i, j)] -= h;
                let fd = (f(ap.as_ref()) - f(am.as_ref())) / (2.0 * h);
                assert!((fd - g[(i, j)]).abs() < tol, "({i},{j}) fd {fd} vs {}", g[(i, j)]);
            }
        }
    }

    /// Diagonal A: ρ = max |aᵢᵢ| and ∇ρ = sign(aₖₖ) eₖeₖᵀ, a negative dominant eigenvalue included.
    #[test]
    fn radius_of_a_diagonal_matrix() {
        let a = m3([[0.3, 0.0, 0.0], [0.0, -0.8, 0.0], [0.0, 0.0, 0.5]]);
        assert_eq!(spectral_radius(a.as_ref()), 0.8);
        let (rho, g) = spectral_radius_grad(a.as_ref()).unwrap();
        assert_eq!(rho, 0.8);
        for i in 0..3 {
            for j in 0..3 {
                let want = if (i, j) == (1, 1) { -1.0 } else { 0.0 };
                assert!((g[(i, j)] - want).abs() < 1e-14, "({i},{j}) {}", g[(i, j)]);
            }
        }
        assert!(is_schur_stable(rho) && !is_schur_stable(1.0) && !is_schur_stable(f64::NAN));
        assert!(is_schur_stable_with_margin(rho, a.as_ref()));
        assert!(!is_schur_stable_with_margin(1.0 - 1e-15, a.as_ref()));
    }

    /// For a 2×2 block with a complex pair, |λ|² = det A, so ρ = √det A and ∇ρ = (ρ/2)·A⁻ᵀ; for
    /// A = r·R(φ), a scaled rotation, ∇ρ = R(φ)/2. Also a non-normal block, and the block embedded
    /// beside a smaller real eigenvalue.
    #[test]
    fn radius_gradient_of_rotation_blocks() {
        let (r, phi) = (0.9f64, 2.3f64);
        let (c, s) = (phi.cos(), phi.sin());
        let rot = m3([[r * c, -r * s, 0.0], [r * s, r * c, 0.0], [0.0, 0.0, -0.4]]);
        let (rho, g) = spectral_radius_grad(rot.as_ref()).unwrap();
        assert!((rho - r).abs() < 1e-15);
        let want = [[c / 2.0, -s / 2.0, 0.0], [s / 2.0, c / 2.0, 0.0], [0.0, 0.0, 0.0]];
        for i in 0..3 {
            for j in 0..3 {
                assert!((g[(i, j)] - want[i][j]).abs() < 1e-14, "({i},{j}) {} vs {}", g[(i, j)], want[i][j]);
            }
        }
        // Non-normal 2×2 with a complex pair: det = 0.52, trace² − 4 det < 0.
        let a = Mat::from_fn(2, 2, |i, j| [[0.2, 3.0], [-0.16, 0.4]][i][j]);
        let det = 0.2 * 0.4 + 3.0 * 0.16;
        let (rho, g) = spectral_radius_grad(a.as_ref()).unwrap();
        assert!((rho - f64::sqrt(det)).abs() < 1e-14);
        // (ρ/2)·A⁻ᵀ = (ρ/2)/det · [[a11, −a10], [−a01, a00]]
        let want = [[0.4, 0.16], [-3.0, 0.2]];
        for i in 0..2 {
            for j in 0..2 {
                let w = rho / 2.0 / det * want[i][j];
                assert!((g[(i, j)] - w).abs() < 1e-13, "({i},{j}) {} vs {w}", g[(i, j)]);
            }
        }
    }

    /// ∇ρ against central differences: a dominant complex pair, a dominant negative real
    /// eigenvalue; and the empty, NaN and nilpotent cases.
    #[test]
    fn radius_gradient_matches_fd() {
        let pair = m3([[0.5, 0.6, 0.3], [-0.5, 0.4, 0.1], [0.2, 0.1, -0.3]]);
        let real = m3([[-0.9, 0.2, 0.3], [0.1, 0.4, 0.1], [0.2, -0.3, 0.1]]);
        for a in [pair, real] {
            let (rho, g) = spectral_radius_grad(a.as_ref()).unwrap();
            assert!((rho - spectral_radius(a.as_ref())).abs() < 1e-14);
            assert_fd(&a, &g, spectral_radius, 1e-7);
        }
        assert_eq!(spectral_radius(Mat::<f64>::zeros(0, 0).as_ref()), 0.0);
        assert!(spectral_radius_grad(Mat::<f64>::zeros(0, 0).as_ref()).is_none());
        let mut a = Mat::<f64>::identity(2, 2);
        a[(0, 1)] = f64::NAN;
        assert_eq!(spectral_radius(a.as_ref()), f64::INFINITY);
        assert!(spectral_radius_grad(a.as_ref()).is_none());
        let nil = Mat::from_fn(2, 2, |i, j| if (i, j) == (0, 1) { 1.0 } else { 0.0 });
        let (rho, g) = spectral_radius_grad(nil.as_ref()).unwrap();
        assert_eq!(rho, 0.0);
        assert!((0..2).all(|i| (0..2).all(|j| g[(i, j)].is_finite())));
    }
}
