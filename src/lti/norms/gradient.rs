//! The four quantities of the design objectives with their exact gradients with respect to the
//! controller (Ak, Bk, Ck, Dk): α(Acl), α(Ak), ‖Tzw‖∞ and ‖K‖∞ (docs/ALGORITHMS.md §3.2, §6).
//!
//! Written by hand because no crate offers H∞ norms or their gradients.
//! Method as in HIFOO (Burke, Henrion, Lewis & Overton 2006; Gumussoy, Millstone & Overton 2008):
//!
//! * α: ∇_A α = Re(ū vᵀ)/(uᴴv) from the rightmost eigen-triple (`spectral.rs`).
//! * ‖·‖∞ at its peak ω with Z = iωI − A and the leading singular pair G(iω) v = σ u:
//!   with a = Z⁻ᴴ Cᵀ u and b = Z⁻¹ B v,
//!   ```text
//!   G_A = Re(ā bᵀ),  G_B = Re(ā vᵀ),  G_C = Re(ū bᵀ),  G_D = Re(ū vᵀ)
//!   ```
//!   (docs/ALGORITHMS.md §6.1, in vector form; at ω = ∞ only G_D survives). One complex LU of Z gives both b and a;
//!   from order 30 on the norm's Hessenberg form Z = Q(iωI − H)Qᵀ does, in O(n²)
//!   (`FreqResponse::transfer_vectors`).
//! * Chain rule through the closed loop, D22 ≠ 0 included: `closed_loop.rs`
//!   ([`ClosedLoop::chain_rule`]). For the controller's own quantities the matrix gradients are the
//!   gradient (no chain rule).
//!
//! The norm is non-smooth where σmax is multiple or the peak is not unique; then one element of the
//! Clarke subdifferential is returned (any singular pair), as HIFOO does.
//!
//! Cost sharing: one eigenvalue computation of Acl serves both the stability test and the norm's
//! test frequencies; the gradient re-uses the norm's peak (no second norm computation).

use faer::linalg::solvers::Solve;
use faer::{c64, Mat, MatRef};

use super::hinf::{hinf_norm_parts, HinfNorm, HinfParams, NormParts};
use crate::lti::error::LtiError;
use crate::lti::kernels::freq_response::FreqResponse;
use crate::lti::kernels::hessenberg_qr::HESSENBERG_QR_FROM;
use crate::lti::kernels::spectral::{largest_modulus_eigen, rightmost_eigen, ExtremeEigen};
use crate::lti::kernels::step_stats::{for_order, timed, Step};
use crate::lti::system::closed_loop::ClosedLoop;
use crate::lti::system::controller::Controller;
use crate::lti::system::plant::Plant;
use crate::lti::system::state_space::StateSpace;

/// Gradient with respect to (Ak, Bk, Ck, Dk), same shapes as the controller.
pub type ControllerGradient = Controller;

/// α(Acl) and its gradient. α is finite for unstable loops; +∞ with a NaN gradient if the
/// eigensolver fails or the loop has non-finite entries. Err(IllPosed) for an ill-posed loop.
pub fn closed_loop_abscissa_grad(plant: &Plant, k: &Controller) -> Result<(f64, ControllerGradient), LtiError> {
    closed_loop_eigen_grad(plant, k, &ABSCISSA)
}

/// ρ(Acl) and its gradient, for a discrete-time plant with a discrete-time controller (the same
/// closed loop as in continuous time, docs/ALGORITHMS.md §10.1); as
/// [`closed_loop_abscissa_grad`] otherwise.
pub fn closed_loop_radius_grad(plant: &Plant, k: &Controller) -> Result<(f64, ControllerGradient), LtiError> {
    closed_loop_eigen_grad(plant, k, &RADIUS)
}

/// α(Ak) and its gradient (only the Ak block is nonzero); nk = 0: (−∞, zeros).
pub fn controller_abscissa_grad(k: &Controller) -> (f64, ControllerGradient) {
    controller_eigen_grad(k, &ABSCISSA)
}

/// ρ(Ak) and its gradient (only the Ak block is nonzero); nk = 0: (0, zeros) (a static
/// controller has no dynamics). The strong-stabilisation constraint of a discrete-time design is
/// ρ(Ak) < 1.
pub fn controller_radius_grad(k: &Controller) -> (f64, ControllerGradient) {
    controller_eigen_grad(k, &RADIUS)
}

/// An eigenvalue function of a state matrix (α or ρ): how its eigen-triple is found, its value
/// from the eigenvalue, its value for a 0×0 matrix.
struct EigenFunction {
    triple: fn(MatRef<'_, f64>) -> Option<ExtremeEigen>,
    value: fn(c64) -> f64,
    empty: f64,
}

const ABSCISSA: EigenFunction = EigenFunction { triple: rightmost_eigen, value: |l| l.re, empty: f64::NEG_INFINITY };
const RADIUS: EigenFunction = EigenFunction { triple: largest_modulus_eigen, value: |l| l.norm(), empty: 0.0 };

/// `f`(Acl) and its gradient through the closed loop's chain rule.
fn closed_loop_eigen_grad(
    plant: &Plant,
    k: &Controller,
    f: &EigenFunction,
) -> Result<(f64, ControllerGradient), LtiError> {
    let cl = ClosedLoop::new(plant, k)?;
    Ok(match (f.triple)(cl.sys.a.as_ref()) {
        Some(e) => ((f.value)(e.lambda), cl.chain_rule(&e.u, &e.v_scaled, None)),
        None => (f64::INFINITY, nan_like(k)),
    })
}

/// `f`(Ak) and its gradient (only the Ak block is nonzero).
fn controller_eigen_grad(k: &Controller, f: &EigenFunction) -> (f64, ControllerGradient) {
    let nk = k.order();
    if nk == 0 {
        return (f.empty, Controller::zeros(0, k.outputs(), k.inputs()));
    }
    match (f.triple)(k.ak.as_ref()) {
        Some(e) => {
            let mut g = Controller::zeros(nk, k.outputs(), k.inputs());
            g.ak = e.real_gradient();
            ((f.value)(e.lambda), g)
        }
        None => (f64::INFINITY, nan_like(k)),
    }
}

/// ‖Tzw‖∞ on the imaginary axis (+∞ if the loop is unstable, with a NaN gradient) and its
/// gradient ([`closed_loop_hinf_grad`](crate::lti::closed_loop_hinf_grad) takes the plant's
/// domain into account), computed as
/// `params` ask ([`HinfParams`]: tolerance, peak hints of a nearby controller, a stop hook —
/// `Err(LtiError::Interrupted)` once it fires —, a level at which to stop early — a value at or
/// above `params.enough` is then an attained σmax(Tzw(iω)), a lower bound of the norm, returned
/// with a NaN gradient —, and a [`ResponseSlot`](crate::lti::ResponseSlot) whose evaluator of this very closed loop is
/// reused). `Err(IllPosed)` for an ill-posed loop.
pub(crate) fn closed_loop_hinf_grad_continuous(
    plant: &Plant,
    k: &Controller,
    params: &HinfParams<'_>,
) -> Result<(HinfNorm, ControllerGradient), LtiError> {
    let cl = ClosedLoop::new(plant, k)?;
    Ok(closed_loop_grad_from(&cl, k, hinf_with_vectors(&cl.sys, params)?))
}

/// The norm and gradient of the closed loop `cl` of `k` from the norm and the vectors at its peak
/// (`None`: unstable).
pub(crate) fn closed_loop_grad_from(
    cl: &ClosedLoop<'_>,
    k: &Controller,
    peak: Option<(HinfNorm, Option<PeakVectors>)>,
) -> (HinfNorm, ControllerGradient) {
    grad_at_peak(k, peak, |pv| cl.chain_rule(&pv.a, &pv.b, Some((&pv.u, &pv.v))))
}

/// The norm and the gradient `chain` makes of the vectors at its peak; NaN gradients without
/// vectors (a value at or above `params.enough`), +∞ for `None` (unstable).
pub(crate) fn grad_at_peak(
    k: &Controller,
    peak: Option<(HinfNorm, Option<PeakVectors>)>,
    chain: impl FnOnce(&PeakVectors) -> Controller,
) -> (HinfNorm, ControllerGradient) {
    match peak {
        Some((norm, Some(pv))) => (norm, chain(&pv)),
        Some((norm, None)) => (norm, nan_like(k)),
        None => (HinfNorm::UNSTABLE, nan_like(k)),
    }
}

/// ‖K‖∞ of the controller itself on the imaginary axis (+∞ if Ak is not Hurwitz; σmax(Dk) for
/// nk = 0) and its gradient; [`controller_hinf_grad`](crate::lti::controller_hinf_grad) takes
/// the controller's domain into account.
pub(crate) fn controller_hinf_grad_continuous(k: &Controller, tol: f64) -> (HinfNorm, ControllerGradient) {
    controller_grad_from(k, hinf_with_vectors(&controller_system(k), &HinfParams::new(tol)))
}

/// The controller (Ak, Bk, Ck, Dk) as a system.
pub(crate) fn controller_system(k: &Controller) -> StateSpace {
    StateSpace { a: k.ak.clone(), b: k.bk.clone(), c: k.ck.clone(), d: k.dk.clone() }
}

/// ‖K‖∞ and its gradient from the norm of `k` and the vectors at its peak.
pub(crate) fn controller_grad_from(
    k: &Controller,
    peak: Result<Option<(HinfNorm, Option<PeakVectors>)>, LtiError>,
) -> (HinfNorm, ControllerGradient) {
    let Ok(Some((norm, Some(pv)))) = peak else {
        return (HinfNorm::UNSTABLE, nan_like(k));
    };
    let [ak, bk, ck, dk] = matrix_gradients(&pv);
    (norm, Controller::continuous(ak, bk, ck, dk))
}

/// The gradients of σmax at the peak with respect to (A, B, C, D) of the system itself:
/// Re(ā bᵀ), Re(ā vᵀ), Re(ū bᵀ), Re(ū vᵀ) (module docs).
pub(crate) fn matrix_gradients(pv: &PeakVectors) -> [Mat<f64>; 4] {
    let outer = |x: &[c64], y: &[c64]| Mat::from_fn(x.len(), y.len(), |i, j| (x[i].conj() * y[j]).re);
    [outer(&pv.a, &pv.b), outer(&pv.a, &pv.v), outer(&pv.u, &pv.b), outer(&pv.u, &pv.v)]
}

/// Vectors of the H∞ gradient at the peak (module docs).
pub(crate) struct PeakVectors {
    /// Left singular vector u (p).
    pub u: Vec<c64>,
    /// Right singular vector v (m).
    pub v: Vec<c64>,
    /// a = Z⁻ᴴ Cᵀ u (n); zero at ω = ∞.
    pub a: Vec<c64>,
    /// b = Z⁻¹ B v (n); zero at ω = ∞.
    pub b: Vec<c64>,
    /// σmax(G) at the point (0 if G is empty).
    pub sigma: f64,
}

/// Norm and gradient vectors; `Ok(None)` if unstable (or not finite); `Err` once `params.stop`
/// fires. A value at or above `params.enough` comes without vectors (it may be a lower bound of
/// the norm). The vectors are computed in the norm's working coordinates (`hinf::Working`,
/// x = D·x_b) and returned in `sys`'s: u and v are the same, a = D⁻¹a_b and b = D·b_b (with
/// Z_b = D⁻¹ZD, C_b = CD and B_b = D⁻¹B, Z_b⁻ᴴC_bᵀu = D·Z⁻ᴴCᵀu and Z_b⁻¹B_b v = D⁻¹·Z⁻¹Bv).
pub(crate) fn hinf_with_vectors(
    sys: &StateSpace,
    params: &HinfParams<'_>,
) -> Result<Option<(HinfNorm, Option<PeakVectors>)>, LtiError> {
    let NormParts { norm, response: fr, working, .. } = hinf_norm_parts(sys, params)?;
    if !norm.value.is_finite() {
        return Ok(None);
    }
    if norm.value >= params.enough {
        return Ok(Some((norm, None)));
    }
    params.stop.poll()?;
    let w = norm.peak_freq;
    let ws = working.sys.as_ref();
    let vectors = || match fr {
        Some(mut fr) if ws.order() >= HESSENBERG_QR_FROM && w.is_finite() && ws.inputs().min(ws.outputs()) > 0 => {
            peak_vectors_hessenberg(&mut fr, w)
        }
        _ => peak_vectors(ws, w),
    };
    let pv = for_order(sys.order(), || timed(Step::Gradient, vectors));
    Ok(pv.map(|pv| (norm, Some(in_coordinates_of_sys(pv, working.scaling.as_deref())))))
}

/// The vectors `pv` of the working coordinates with diagonal `d` in those of the system itself
/// ([`hinf_with_vectors`]); unchanged without a `d`.
fn in_coordinates_of_sys(mut pv: PeakVectors, d: Option<&[f64]>) -> PeakVectors {
    if let Some(d) = d {
        pv.a.iter_mut().zip(d).for_each(|(a, &di)| *a /= di);
        pv.b.iter_mut().zip(d).for_each(|(b, &di)| *b *= di);
    }
    pv
}

/// u, v, a, b at the finite frequency w (module docs) through the Hessenberg form of `fr`
/// (`FreqResponse::transfer_vectors`: O(n²) where [`peak_vectors`]' dense LU is O(n³)); `None`
/// if the SVD fails or iωI − A is singular. From order [`HESSENBERG_QR_FROM`] on (measured: the
/// dense LU was 2–3 % of a BDT2 or CM4 design run).
fn peak_vectors_hessenberg(fr: &mut FreqResponse, w: f64) -> Option<PeakVectors> {
    let (u, v, sigma) = leading_singular_pair(fr.eval(w))?;
    let (a, b) = fr.transfer_vectors(w, &u, &v)?;
    finite_vectors(PeakVectors { u, v, a, b, sigma })
}

/// The leading singular triple (u, v, σmax) of G (p×m, both nonzero): G v = σmax u; `None` if
/// the SVD fails.
fn leading_singular_pair(g: MatRef<'_, c64>) -> Option<(Vec<c64>, Vec<c64>, f64)> {
    let svd = g.thin_svd().ok()?;
    let s = svd.S();
    let k = (0..s.dim()).fold(0, |b, i| if s[i].re > s[b].re { i } else { b });
    let u = (0..g.nrows()).map(|i| svd.U()[(i, k)]).collect();
    let v = (0..g.ncols()).map(|j| svd.V()[(j, k)]).collect();
    Some((u, v, s[k].re))
}

/// `pv` if all its entries are finite.
fn finite_vectors(pv: PeakVectors) -> Option<PeakVectors> {
    let PeakVectors { u, v, a, b, .. } = &pv;
    let finite = a.iter().chain(b).chain(u).chain(v).all(|z| z.re.is_finite() && z.im.is_finite());
    finite.then_some(pv)
}

/// u, v, a, b at frequency w (module docs); `None` if an SVD fails.
pub(crate) fn peak_vectors(sys: &StateSpace, w: f64) -> Option<PeakVectors> {
    peak_vectors_at(sys, w.is_finite().then_some(c64::new(0.0, w)))
}

/// u, v, a, b with Z = zI − A at the point z of the complex plane (`None`: z = ∞), for the
/// continuous (z = iω) and the discrete (z = e^{iθ}) norm alike; `None` if an SVD fails.
pub(crate) fn peak_vectors_at(sys: &StateSpace, z: Option<c64>) -> Option<PeakVectors> {
    let (n, m, p) = (sys.order(), sys.inputs(), sys.outputs());
    let cz = |x: f64| c64::new(x, 0.0);
    let zero = c64::new(0.0, 0.0);
    // (On the imaginary axis the diagonal is −a + iω exactly as it always was: no 0 − a.)
    let entry = |z: c64, i: usize, j: usize| {
        let a = sys.a[(i, j)];
        if i != j {
            c64::new(-a, 0.0)
        } else if z.re == 0.0 {
            c64::new(-a, z.im)
        } else {
            c64::new(z.re - a, z.im)
        }
    };
    let (g, lu_x) = match z.filter(|_| n > 0) {
        Some(z) => {
            let zm = Mat::<c64>::from_fn(n, n, |i, j| entry(z, i, j));
            let lu = zm.partial_piv_lu();
            let x = lu.solve(Mat::<c64>::from_fn(n, m, |i, j| cz(sys.b[(i, j)]))); // Z⁻¹B
            let g =
                Mat::<c64>::from_fn(p, m, |i, j| (0..n).fold(cz(sys.d[(i, j)]), |s, k| s + x[(k, j)] * sys.c[(i, k)]));
            (g, Some((lu, x)))
        }
        None => (Mat::<c64>::from_fn(p, m, |i, j| cz(sys.d[(i, j)])), None),
    };
    if p == 0 || m == 0 {
        return Some(PeakVectors {
            u: vec![zero; p],
            v: vec![zero; m],
            a: vec![zero; n],
            b: vec![zero; n],
            sigma: 0.0,
        });
    }
    let (u, v, sigma) = leading_singular_pair(g.as_ref())?;
    let (a, b) = match lu_x {
        Some((lu, x)) => {
            let b: Vec<c64> = (0..n).map(|i| (0..m).fold(zero, |s, j| s + x[(i, j)] * v[j])).collect();
            let ctu = Mat::<c64>::from_fn(n, 1, |i, _| (0..p).fold(zero, |s, r| s + u[r] * sys.c[(r, i)]));
            let a = lu.solve_adjoint(ctu);
            ((0..n).map(|i| a[(i, 0)]).collect(), b)
        }
        None => (vec![zero; n], vec![zero; n]),
    };
    finite_vectors(PeakVectors { u, v, a, b, sigma })
}

pub(crate) fn nan_like(k: &Controller) -> Controller {
    let f = |m: &Mat<f64>| Mat::from_fn(m.nrows(), m.ncols(), |_, _| f64::NAN);
    Controller::continuous(f(&k.ak), f(&k.bk), f(&k.ck), f(&k.dk))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The matrix gradients Re(x̄ yᵀ) for the pairs (a, b), (a, v), (u, b), (u, v): invariant
    /// under the phase of the singular pair, unlike the vectors.
    fn outer_products(pv: &PeakVectors) -> Vec<f64> {
        let outer = |x: &[c64], y: &[c64]| -> Vec<f64> {
            x.iter().flat_map(|xi| y.iter().map(move |yj| (xi.conj() * yj).re)).collect()
        };
        [outer(&pv.a, &pv.b), outer(&pv.a, &pv.v), outer(&pv.u, &pv.b), outer(&pv.u, &pv.v)].concat()
    }

    /// The Hessenberg route gives the dense LU's gradient to rounding, with square and
    /// non-square G, at frequencies near and far from the poles.
    #[test]
    fn hessenberg_vectors_match_the_dense_solve() {
        let mut seed = 5u64;
        let mut rnd = move || {
            seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
            ((seed >> 11) as f64 / (1u64 << 53) as f64) - 0.5
        };
        for &(n, m, p) in &[(30usize, 1usize, 3usize), (47, 2, 2), (90, 3, 1)] {
            let sys = StateSpace {
                a: Mat::from_fn(n, n, |i, j| rnd() + if i == j { -0.5 * (1 + i % 7) as f64 } else { 0.0 }),
                b: Mat::from_fn(n, m, |_, _| rnd()),
                c: Mat::from_fn(p, n, |_, _| rnd()),
                d: Mat::from_fn(p, m, |_, _| rnd()),
            };
            let mut fr = FreqResponse::new(&sys);
            for w in [0.0, 0.4, 3.0, 25.0] {
                let dense = outer_products(&peak_vectors(&sys, w).unwrap());
                let ours = outer_products(&peak_vectors_hessenberg(&mut fr, w).unwrap());
                let scale = dense.iter().fold(0.0f64, |s, x| s.max(x.abs()));
                let err = dense.iter().zip(&ours).fold(0.0f64, |s, (x, y)| s.max((x - y).abs()));
                assert!(err <= 1e-11 * scale, "n={n} m={m} p={p} ω={w}: {err:e} against {scale:e}");
            }
        }
    }

    /// The gradient of a badly scaled realisation, computed in the norm's balanced coordinates
    /// and carried back ([`in_coordinates_of_sys`]), is the well-scaled realisation's gradient
    /// under the change of coordinates: with A_s = T⁻¹AT, B_s = T⁻¹B, C_s = CT (T = diag(t),
    /// spreading 12 decades), G_As = (t_i/t_j)·G_A, G_Bs = t_i·G_B (row i), G_Cs = G_C/t_j
    /// (column j), G_Ds = G_D. Without the carrying back these are off by the balancing's D.
    #[test]
    fn gradient_of_a_badly_scaled_realisation_is_carried_back_from_balanced_coordinates() {
        let mut compared = 0;
        for (case, (sys, scaled, t)) in super::super::hinf::badly_scaled_pairs(21, false).into_iter().enumerate() {
            assert!(super::super::hinf::Working::of(&scaled).scaling.is_some(), "case {case}: not balanced");
            let at_peak = |s: &StateSpace| {
                let (norm, pv) = hinf_with_vectors(s, &HinfParams::default()).unwrap().unwrap();
                (norm.peak_freq, matrix_gradients(&pv.unwrap()))
            };
            let (w, [ga, gb, gc, gd]) = at_peak(&sys);
            let (ws, [sa, sb, sc, sd]) = at_peak(&scaled);
            // another peak of nearly the same height may win in the other realisation (a kink)
            if !w.is_finite() || (ws / w - 1.0).abs() > 1e-6 {
                continue;
            }
            compared += 1;
            let check = |got: &Mat<f64>, want: &dyn Fn(usize, usize) -> f64, what: &str| {
                let scale = (0..got.nrows())
                    .flat_map(|i| (0..got.ncols()).map(move |j| (i, j)))
                    .fold(0.0f64, |s, (i, j)| s.max(want(i, j).abs()));
                for i in 0..got.nrows() {
                    for j in 0..got.ncols() {
                        let (g, x) = (got[(i, j)], want(i, j));
                        assert!(
                            (g - x).abs() <= 1e-5 * x.abs() + 1e-9 * scale,
                            "case {case}, {what}[{i},{j}]: {g:e} against {x:e}"
                        );
                    }
                }
            };
            check(&sa, &|i, j| ga[(i, j)] * t[i] / t[j], "A");
            check(&sb, &|i, j| gb[(i, j)] * t[i], "B");
            check(&sc, &|i, j| gc[(i, j)] / t[j], "C");
            check(&sd, &|i, j| gd[(i, j)], "D");
        }
        assert!(compared >= 15, "only {compared} cases compared");
    }
}
