//! Starting points of a design run (docs/ALGORITHMS.md §8.1–§8.2).
//!
//! * No initial controller: `nrand` standard-normal vectors x ~ N(0, I) in ℝ^nvar
//!   (HIFOO `randn(nvar, nrand)`).
//! * An initial controller x_init: x_init itself plus `nrand` perturbations
//!   x_init + ξ ∘ (‖x_init‖₂ · r), ξ ~ N(0, I), with relative sizes r = logspace(−3, −1, nrand)
//!   (1e-3, 1e-2, 1e-1 for nrand = 3), nrand + 1 starts in total.
//! * Warm start from a lower order (HIFOO `xinitsetup`): pad Bk with zero rows, Ck with zero
//!   columns and Ak with zeros plus new diagonal entries d < 0. The added modes are
//!   uncontrollable and unobservable both in the closed loop and in K itself, so Tzw and K keep
//!   their transfer functions (‖Tzw‖∞ and ‖K‖∞ do not change) and the spectra only gain the
//!   eigenvalue d. Choosing d ≤ min(α(Acl), α(Ak), 0) − 1 ([`padding_diagonal`]) also leaves the
//!   stabilisation objective max(α(Acl), ε·α(Ak)) unchanged, so the warm start is never worse.
//!
//! # Deviation
//! HIFOO pads with d = −(complex stability radius of the closed loop) − 1 for the H∞ objective
//! (and d = α − 1 for the abscissa objective, d = −1 if the loop is unstable). Any d < 0 keeps the
//! H∞ objective; we use the abscissa rule for both objectives so that one padding serves both
//! phases and no extra norm computation is needed.
//!
//! All randomness comes from the run's seeded generator (ChaCha8, `DesignOptions::seed`), so the
//! same seed gives the same starts on every platform.

use faer::Mat;
use rand::RngCore;
use rand_distr::{Distribution, StandardNormal};

use crate::lti::{closed_loop, spectral_abscissa, Controller, Plant};

/// Smallest and largest relative perturbation size (log10) around an initial controller.
pub const PERTURB_LOG10_RANGE: (f64, f64) = (-3.0, -1.0);

/// Distance (in the real-part direction) of padded modes to the left of the rightmost existing
/// closed-loop / controller eigenvalue (HIFOO: `diagpad0 − 1`).
pub const PAD_MARGIN: f64 = 1.0;

/// `n` points 10^a … 10^b equally spaced in log10 (MATLAB `logspace`; n = 1 gives 10^b).
pub fn logspace(a: f64, b: f64, n: usize) -> Vec<f64> {
    match n {
        0 => Vec::new(),
        1 => vec![10f64.powf(b)],
        _ => (0..n).map(|i| 10f64.powf(a + (b - a) * i as f64 / (n - 1) as f64)).collect(),
    }
}

/// `nrand` standard-normal starting points in ℝ^nvar (one implementation, shared with the
/// optimiser's multi-start driver).
pub use crate::optim::random_starts;

/// One relative perturbation x + ξ ∘ (‖x‖ · r), ξ ~ N(0, I) (also the search's basin hops).
/// For x = 0 the perturbation is absolute, ξ·r, so that a zero point can still move.
pub fn perturb(x: &[f64], r: f64, rng: &mut dyn RngCore) -> Vec<f64> {
    let norm = x.iter().map(|v| v * v).sum::<f64>().sqrt();
    let scale = if norm > 0.0 { norm * r } else { r };
    x.iter()
        .map(|&v| {
            let xi: f64 = StandardNormal.sample(&mut *rng);
            v + xi * scale
        })
        .collect()
}

/// `nvar`-vector σ·ξ, ξ ~ N(0, I): a random start at scale σ (σ = 1: HIFOO's standard-normal
/// start, the same draws as [`random_starts`]).
pub fn scaled_random_start(nvar: usize, sigma: f64, rng: &mut dyn RngCore) -> Vec<f64> {
    let mut x = random_starts(nvar, 1, rng).remove(0);
    if sigma != 1.0 {
        x.iter_mut().for_each(|v| *v *= sigma);
    }
    x
}

/// The open-loop start of order `nk`: K = 0 (Dk = 0, Bk = 0, Ck = 0) with Ak = d·I, d from
/// [`padding_diagonal`] (the order-0 zero controller padded to `nk`). Its closed loop is the open
/// loop plus decoupled modes at d < 0, ‖K‖∞ = 0, and it uses no random numbers.
///
/// Why: on a badly scaled plant (AC10: ‖A‖ ≈ 2·10⁷, one unstable pair 0.10 ± 19.8j) a
/// standard-normal controller is far inside a destabilised region, while small gains stabilise;
/// relative perturbations of a large point never get near K = 0. From K = 0 exactly, Bk and Ck
/// stay 0 under any gradient method (Tzw and the closed-loop spectrum depend on them only through
/// the products Ck·(sI − Ak)⁻¹·Bk, whose gradients vanish when both are 0), so this start
/// optimises Dk (and Ak); the basin hops of the continued search make Bk, Ck non-zero.
pub fn open_loop_controller(plant: &Plant, nk: usize) -> Controller {
    let k0 = Controller::zeros(0, plant.dims.m2, plant.dims.p2);
    pad_controller(&k0, nk, padding_diagonal(plant, &k0)).expect("any order ≥ 0 pads an order-0 controller")
}

/// x_init followed by `nrand` relative perturbations x_init + ξ ∘ (‖x_init‖ · r_i),
/// r = logspace(−3, −1, nrand).
pub fn perturbed_starts(x_init: &[f64], nrand: usize, rng: &mut dyn RngCore) -> Vec<Vec<f64>> {
    let mut out = vec![x_init.to_vec()];
    for r in logspace(PERTURB_LOG10_RANGE.0, PERTURB_LOG10_RANGE.1, nrand) {
        out.push(perturb(x_init, r, rng));
    }
    out
}

/// The diagonal entry for padded modes: min(0, α(Acl), α(Ak)) − [`PAD_MARGIN`], ignoring
/// non-finite abscissas (an unstable or ill-posed loop gives −PAD_MARGIN, as HIFOO's
/// `diagpad0 = 0`). In discrete time 0 (modes at z = 0): their ρ − 1 = −1 is at or below that of
/// any matrix, so the stabilisation objective is unchanged there too.
pub fn padding_diagonal(plant: &Plant, k: &Controller) -> f64 {
    if plant.domain.is_discrete() {
        return 0.0;
    }
    let alpha_cl = closed_loop(plant, k).map(|cl| spectral_abscissa(cl.a.as_ref())).unwrap_or(f64::INFINITY);
    let alpha_k = spectral_abscissa(k.ak.as_ref());
    let mut base = 0.0f64;
    for a in [alpha_cl, alpha_k] {
        if a.is_finite() {
            base = base.min(a);
        }
    }
    base - PAD_MARGIN
}

/// `k` padded to order `nk ≥ k.order()` with decoupled modes at `diag` (module docs).
/// Returns `None` if `nk < k.order()`.
pub fn pad_controller(k: &Controller, nk: usize, diag: f64) -> Option<Controller> {
    let n0 = k.order();
    if nk < n0 {
        return None;
    }
    let (m, p) = (k.outputs(), k.inputs());
    let ak = Mat::from_fn(nk, nk, |i, j| {
        if i < n0 && j < n0 {
            k.ak[(i, j)]
        } else if i == j {
            diag
        } else {
            0.0
        }
    });
    let bk = Mat::from_fn(nk, p, |i, j| if i < n0 { k.bk[(i, j)] } else { 0.0 });
    let ck = Mat::from_fn(m, nk, |i, j| if j < n0 { k.ck[(i, j)] } else { 0.0 });
    Some(Controller { ak, bk, ck, dk: k.dk.clone(), domain: k.domain })
}

/// Relative size δ of the coupling given to padded modes by [`couple_padded_modes`].
pub const PADDED_COUPLING: f64 = 1e-2;

/// `k` (a controller whose modes `n0..` are padded: decoupled, B_K rows and C_K columns zero)
/// with those modes coupled: each of their B_K rows and C_K columns drawn as s·ξ, ξ ~ N(0, I),
/// s = (δ·g·max(1, |d_i|))^½, d_i the mode's diagonal entry and g the size of the order-n0
/// controller (‖D_K‖_F, else ‖B_K‖_F‖C_K‖_F / max(1, ‖A_K‖_F), else 1). Each new mode then adds
/// about δ·g to K's gain, C_K,i B_K,iᵀ/(s − d_i).
///
/// Why: a padded mode is a saddle of the design problem. Tzw and the spectra depend on its B_K
/// row and C_K column only through their product, whose gradient vanishes when both are 0, so
/// no local search from the padded controller ever uses the mode (docs/ALGORITHMS.md §8.2);
/// with the coupling it starts off the saddle, at nearly the padded controller's objective.
pub fn couple_padded_modes(k: &Controller, n0: usize, delta: f64, rng: &mut dyn RngCore) -> Controller {
    let nk = k.order();
    // ‖·‖_F of the order-n0 controller's leading blocks
    let frob = |m: &Mat<f64>, r: usize, c: usize| m.as_ref().submatrix(0, 0, r, c).norm_l2();
    let (dk, bk0, ck0, ak0) =
        (k.dk.as_ref().norm_l2(), frob(&k.bk, n0, k.inputs()), frob(&k.ck, k.outputs(), n0), frob(&k.ak, n0, n0));
    let g = if dk > 0.0 {
        dk
    } else if bk0 * ck0 > 0.0 {
        bk0 * ck0 / ak0.max(1.0)
    } else {
        1.0
    };
    let mut out = k.clone();
    for i in n0..nk {
        let s = (delta * g * k.ak[(i, i)].abs().max(1.0)).sqrt();
        for j in 0..k.inputs() {
            let xi: f64 = StandardNormal.sample(&mut *rng);
            out.bk[(i, j)] = s * xi;
        }
        for j in 0..k.outputs() {
            let xi: f64 = StandardNormal.sample(&mut *rng);
            out.ck[(j, i)] = s * xi;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    #[test]
    fn coupled_padding_keeps_the_order_below_and_couples_each_new_mode() {
        let k1 = Controller {
            ak: Mat::from_fn(1, 1, |_, _| -2.0),
            bk: Mat::from_fn(1, 2, |_, j| 1.0 + j as f64),
            ck: Mat::from_fn(2, 1, |i, _| 0.5 - i as f64),
            dk: Mat::from_fn(2, 2, |i, j| if i == j { 3.0 } else { 4.0 }),
            domain: crate::lti::TimeDomain::Continuous,
        };
        let padded = pad_controller(&k1, 3, -5.0).unwrap();
        let c = couple_padded_modes(&padded, 1, PADDED_COUPLING, &mut ChaCha8Rng::seed_from_u64(3));
        // A_K, D_K and the order-1 part untouched
        assert_eq!(c.ak, padded.ak);
        assert_eq!(c.dk, padded.dk);
        assert_eq!(c.bk.as_ref().row(0).to_owned(), k1.bk.as_ref().row(0).to_owned());
        assert_eq!(c.ck.as_ref().col(0).to_owned(), k1.ck.as_ref().col(0).to_owned());
        // each new mode's row and column drawn at s = (δ·‖D_K‖_F·|d|)^½ (‖D_K‖_F = √50)
        let s = (PADDED_COUPLING * 50f64.sqrt() * 5.0).sqrt();
        for i in 1..3 {
            let b = c.bk.as_ref().row(i).norm_l2();
            let cc = c.ck.as_ref().col(i).norm_l2();
            assert!(b > 0.0 && cc > 0.0);
            assert!(b < 5.0 * s * 2f64.sqrt() && cc < 5.0 * s * 2f64.sqrt(), "{b} {cc} {s}");
        }
        // seeded: the same draws again
        let again = couple_padded_modes(&padded, 1, PADDED_COUPLING, &mut ChaCha8Rng::seed_from_u64(3));
        assert_eq!(again.bk, c.bk);
        assert_eq!(again.ck, c.ck);
    }

    #[test]
    fn logspace_matches_matlab() {
        let l = logspace(-3.0, -1.0, 3);
        assert!((l[0] - 1e-3).abs() < 1e-18 && (l[1] - 1e-2).abs() < 1e-17 && (l[2] - 1e-1).abs() < 1e-16);
        assert_eq!(logspace(-3.0, -1.0, 1), vec![10f64.powf(-1.0)]);
        assert!(logspace(0.0, 1.0, 0).is_empty());
    }

    #[test]
    fn random_starts_are_seeded() {
        let a = random_starts(5, 3, &mut ChaCha8Rng::seed_from_u64(7));
        let b = random_starts(5, 3, &mut ChaCha8Rng::seed_from_u64(7));
        let c = random_starts(5, 3, &mut ChaCha8Rng::seed_from_u64(8));
        assert_eq!(a, b);
        assert_ne!(a, c);
        assert_eq!(a.len(), 3);
        assert!(a.iter().all(|x| x.len() == 5));
        // standard normal: a mean of many draws is near 0, the variance near 1
        let big = random_starts(10_000, 1, &mut ChaCha8Rng::seed_from_u64(1)).remove(0);
        let mean = big.iter().sum::<f64>() / big.len() as f64;
        let var = big.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / big.len() as f64;
        assert!(mean.abs() < 0.05 && (var - 1.0).abs() < 0.05, "mean {mean} var {var}");
    }

    #[test]
    fn perturbations_have_the_documented_relative_sizes() {
        let x: Vec<f64> = (0..400).map(|i| ((i as f64) * 0.1).cos()).collect();
        let norm = x.iter().map(|v| v * v).sum::<f64>().sqrt();
        let s = perturbed_starts(&x, 3, &mut ChaCha8Rng::seed_from_u64(3));
        assert_eq!(s.len(), 4);
        assert_eq!(s[0], x);
        for (i, r) in [1e-3, 1e-2, 1e-1].into_iter().enumerate() {
            let d: f64 = s[i + 1].iter().zip(&x).map(|(a, b)| (a - b).powi(2)).sum::<f64>().sqrt();
            // ‖ξ‖ ≈ sqrt(400) = 20
            let rel = d / (norm * r * 20.0);
            assert!((0.8..1.2).contains(&rel), "perturbation {i}: relative size {rel}");
        }
    }

    #[test]
    fn padding_keeps_the_old_blocks_and_adds_decoupled_modes() {
        let k = Controller {
            ak: Mat::from_fn(1, 1, |_, _| -2.0),
            bk: Mat::from_fn(1, 2, |_, j| j as f64 + 1.0),
            ck: Mat::from_fn(1, 1, |_, _| 3.0),
            dk: Mat::from_fn(1, 2, |_, j| 0.5 * j as f64),
            domain: crate::lti::TimeDomain::Continuous,
        };
        let kp = pad_controller(&k, 3, -4.0).unwrap();
        assert_eq!(kp.order(), 3);
        assert_eq!(kp.ak[(0, 0)], -2.0);
        assert_eq!((kp.ak[(1, 1)], kp.ak[(2, 2)], kp.ak[(0, 1)], kp.ak[(2, 1)]), (-4.0, -4.0, 0.0, 0.0));
        assert_eq!((kp.bk[(0, 1)], kp.bk[(2, 1)]), (2.0, 0.0));
        assert_eq!((kp.ck[(0, 0)], kp.ck[(0, 2)]), (3.0, 0.0));
        assert_eq!(kp.dk, k.dk);
        assert!(pad_controller(&kp, 2, -1.0).is_none());
        assert_eq!(pad_controller(&k, 1, -1.0).unwrap(), k);
    }
}
