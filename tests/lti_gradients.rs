//! Central finite-difference checks of every gradient (α_cl, α_K, ‖Tzw‖∞, ‖K‖∞) at seeded random
//! points, with D22 = 0 and D22 ≠ 0, nk = 0 and nk > 0; the same in discrete time (ρ_cl, ρ_K and
//! the norms on the unit circle); plus the ill-posed loop.

use faer::Mat;
use hinfix::lti::{
    closed_loop, closed_loop_abscissa_grad, closed_loop_hinf_grad, closed_loop_hinf_grad_discrete,
    closed_loop_radius_grad, controller_abscissa_grad, controller_hinf_grad, controller_hinf_grad_discrete,
    controller_radius_grad, hinf_norm, hinf_norm_discrete, hinf_norm_grad_discrete, spectral_abscissa, spectral_radius,
    Controller, Dims, HinfParams, LtiError, Plant, StateSpace,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

/// H∞ tolerance for the finite differences (tight, so that the norm is smooth to FD accuracy).
const FD_HINF_TOL: f64 = 1e-13;
/// Central-difference step.
const H: f64 = 1e-6;
/// Accepted |fd − g| relative to max(1, ‖g‖∞).
const FD_REL: f64 = 2e-5;

fn randn(rng: &mut ChaCha8Rng, r: usize, c: usize, scale: f64) -> Mat<f64> {
    Mat::from_fn(r, c, |_, _| scale * rng.sample::<f64, _>(StandardNormal))
}

fn random_plant(rng: &mut ChaCha8Rng, n: usize, m1: usize, m2: usize, p1: usize, p2: usize, d22: bool) -> Plant {
    let a = randn(rng, n, n, 1.0) - Mat::<f64>::identity(n, n) * faer::Scale(2.0 + (n as f64).sqrt());
    Plant {
        name: "random".into(),
        description: String::new(),
        citation: String::new(),
        source: serde_json::Value::Null,
        notes: String::new(),
        check: None,
        dims: Dims { n, m1, m2, p1, p2 },
        domain: Default::default(),
        a,
        b1: randn(rng, n, m1, 1.0),
        b2: randn(rng, n, m2, 1.0),
        c1: randn(rng, p1, n, 1.0),
        c2: randn(rng, p2, n, 1.0),
        d11: randn(rng, p1, m1, 0.3),
        d12: randn(rng, p1, m2, 0.5),
        d21: randn(rng, p2, m1, 0.5),
        d22: if d22 { randn(rng, p2, m2, 0.4) } else { Mat::zeros(p2, m2) },
    }
}

fn random_controller(rng: &mut ChaCha8Rng, nk: usize, m: usize, p: usize) -> Controller {
    Controller {
        ak: randn(rng, nk, nk, 0.7) - Mat::<f64>::identity(nk, nk) * faer::Scale(1.5),
        bk: randn(rng, nk, p, 0.3),
        ck: randn(rng, m, nk, 0.3),
        dk: randn(rng, m, p, 0.3),
        domain: Default::default(),
    }
}

/// The four blocks as one list of (block, i, j) to perturb.
fn entries(k: &Controller) -> Vec<(usize, usize, usize)> {
    let mut v = Vec::new();
    for (b, m) in [&k.ak, &k.bk, &k.ck, &k.dk].into_iter().enumerate() {
        for i in 0..m.nrows() {
            for j in 0..m.ncols() {
                v.push((b, i, j));
            }
        }
    }
    v
}

fn block_mut(k: &mut Controller, b: usize) -> &mut Mat<f64> {
    match b {
        0 => &mut k.ak,
        1 => &mut k.bk,
        2 => &mut k.ck,
        _ => &mut k.dk,
    }
}

fn block(k: &Controller, b: usize) -> &Mat<f64> {
    [&k.ak, &k.bk, &k.ck, &k.dk][b]
}

/// Compares an analytic gradient with central differences of `f`.
fn check_fd(label: &str, k: &Controller, g: &Controller, mut f: impl FnMut(&Controller) -> f64) {
    let gmax = entries(k).iter().map(|&(b, i, j)| block(g, b)[(i, j)].abs()).fold(1.0, f64::max);
    for (b, i, j) in entries(k) {
        let mut kp = k.clone();
        block_mut(&mut kp, b)[(i, j)] += H;
        let mut km = k.clone();
        block_mut(&mut km, b)[(i, j)] -= H;
        let fd = (f(&kp) - f(&km)) / (2.0 * H);
        let an = block(g, b)[(i, j)];
        assert!(
            (fd - an).abs() <= FD_REL * gmax,
            "{label}: block {b} entry ({i},{j}): finite difference {fd} vs gradient {an} (scale {gmax})"
        );
    }
}

#[test]
fn gradients_match_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(20240611);
    let mut checked_hinf = 0;
    for case in 0..12 {
        let d22 = case % 2 == 1;
        let nk = [0, 1, 2, 3][case / 3 % 4];
        let (n, m1, m2, p1, p2) = [(4, 2, 1, 2, 1), (5, 2, 2, 3, 2), (6, 1, 2, 2, 3)][case % 3];
        let plant = random_plant(&mut rng, n, m1, m2, p1, p2, d22);
        let k = random_controller(&mut rng, nk, m2, p2);
        let label = format!("case {case} (n={n}, nk={nk}, D22≠0: {d22})");

        // α(Acl)
        let (alpha, g) = closed_loop_abscissa_grad(&plant, &k).unwrap();
        check_fd(&format!("{label} α_cl"), &k, &g, |kk| {
            spectral_abscissa(closed_loop(&plant, kk).unwrap().a.as_ref())
        });
        // ‖Tzw‖∞ (only where the loop is stable)
        if alpha < 0.0 {
            let (h, g) = closed_loop_hinf_grad(&plant, &k, &HinfParams::new(FD_HINF_TOL)).unwrap();
            assert!(h.value.is_finite());
            check_fd(&format!("{label} ‖Tzw‖∞ (peak ω = {})", h.peak_freq), &k, &g, |kk| {
                hinf_norm(&closed_loop(&plant, kk).unwrap(), &HinfParams::new(FD_HINF_TOL)).unwrap().value
            });
            checked_hinf += 1;
        } else {
            let (h, g) = closed_loop_hinf_grad(&plant, &k, &HinfParams::new(FD_HINF_TOL)).unwrap();
            assert_eq!(h.value, f64::INFINITY);
            assert!(g.dk[(0, 0)].is_nan());
        }
        // α(Ak)
        let (ak_alpha, g) = controller_abscissa_grad(&k);
        if nk == 0 {
            assert_eq!(ak_alpha, f64::NEG_INFINITY);
        } else {
            check_fd(&format!("{label} α_K"), &k, &g, |kk| spectral_abscissa(kk.ak.as_ref()));
        }
        // ‖K‖∞ (σmax(Dk) for nk = 0)
        let (hk, g) = controller_hinf_grad(&k, FD_HINF_TOL);
        assert!(hk.value.is_finite());
        check_fd(&format!("{label} ‖K‖∞"), &k, &g, |kk| controller_hinf_grad(kk, FD_HINF_TOL).0.value);
    }
    assert!(checked_hinf >= 6, "too few stable random loops ({checked_hinf})");
}

/// `a` scaled to spectral radius `rho`, times `sign` (−1 puts the dominant poles of the Hurwitz
/// matrices above, mostly real negative, near z = +ρ instead of z = −ρ).
fn schur(a: &Mat<f64>, rho: f64, sign: f64) -> Mat<f64> {
    a * faer::Scale(sign * rho / spectral_radius(a.as_ref()))
}

/// Discrete time: ρ(Acl), ρ(Ak), ‖Tzw‖∞ and ‖K‖∞ on the unit circle against central differences,
/// dominant poles near z = −1 and near z = +1 (both sides of the bilinear transform's choice);
/// the system-matrix gradient of `hinf_norm_grad_discrete` is the controller's own.
#[test]
fn discrete_time_gradients_match_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(20261205);
    let params = HinfParams::new(FD_HINF_TOL);
    let mut checked_hinf = 0;
    for case in 0..12 {
        let d22 = case % 2 == 1;
        let sign = if case % 4 < 2 { 1.0 } else { -1.0 };
        let nk = [0, 1, 2, 3][case / 3 % 4];
        let (n, m1, m2, p1, p2) = [(4, 2, 1, 2, 1), (5, 2, 2, 3, 2), (6, 1, 2, 2, 3)][case % 3];
        let mut plant = random_plant(&mut rng, n, m1, m2, p1, p2, d22);
        plant.a = schur(&plant.a, 0.5, sign);
        let mut k = random_controller(&mut rng, nk, m2, p2);
        if nk > 0 {
            k.ak = schur(&k.ak, 0.7, -sign);
        }
        let label = format!("discrete case {case} (n={n}, nk={nk}, D22≠0: {d22}, sign {sign})");

        let (rho, g) = closed_loop_radius_grad(&plant, &k).unwrap();
        check_fd(&format!("{label} ρ_cl"), &k, &g, |kk| spectral_radius(closed_loop(&plant, kk).unwrap().a.as_ref()));
        let (h, g) = closed_loop_hinf_grad_discrete(&plant, &k, &params).unwrap();
        if rho < 1.0 {
            assert!(h.value.is_finite() && (0.0..=std::f64::consts::PI).contains(&h.peak_freq), "{label}: {h:?}");
            check_fd(&format!("{label} ‖Tzw‖∞ (peak θ = {})", h.peak_freq), &k, &g, |kk| {
                hinf_norm_discrete(&closed_loop(&plant, kk).unwrap(), &params).unwrap().value
            });
            checked_hinf += 1;
        } else {
            assert_eq!(h.value, f64::INFINITY, "{label}");
            assert!(g.dk[(0, 0)].is_nan());
        }
        let (rho_k, g) = controller_radius_grad(&k);
        if nk == 0 {
            assert_eq!(rho_k, 0.0);
        } else {
            assert!((rho_k - 0.7).abs() < 1e-12, "{label}: ρ(Ak) = {rho_k}");
            check_fd(&format!("{label} ρ_K"), &k, &g, |kk| spectral_radius(kk.ak.as_ref()));
        }
        let (hk, g) = controller_hinf_grad_discrete(&k, FD_HINF_TOL);
        assert!(hk.value.is_finite());
        check_fd(&format!("{label} ‖K‖∞"), &k, &g, |kk| controller_hinf_grad_discrete(kk, FD_HINF_TOL).0.value);
        let ks = StateSpace { a: k.ak.clone(), b: k.bk.clone(), c: k.ck.clone(), d: k.dk.clone() };
        let (hs, gs) = hinf_norm_grad_discrete(&ks, &params).unwrap();
        assert_eq!(hs, hk, "{label}");
        assert_eq!((gs.a, gs.b, gs.c, gs.d), (g.ak, g.bk, g.ck, g.dk), "{label}");
    }
    assert!(checked_hinf >= 6, "too few stable random discrete loops ({checked_hinf})");
}

/// From closed-loop order 30 on, the H∞ gradient's vectors come from the norm's Hessenberg form
/// (`FreqResponse::transfer_vectors`) instead of a dense LU: the same finite-difference check, at
/// orders 34 and 51 with D22 = 0 and D22 ≠ 0.
#[test]
fn large_order_hinf_gradient_matches_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(20261203);
    let mut checked = 0;
    for case in 0..4 {
        let (n, nk) = [(33, 1), (49, 2)][case % 2];
        let d22 = case >= 2;
        let plant = random_plant(&mut rng, n, 2, 2, 3, 2, d22);
        let k = random_controller(&mut rng, nk, 2, 2);
        let (h, g) = closed_loop_hinf_grad(&plant, &k, &HinfParams::new(FD_HINF_TOL)).unwrap();
        if !h.value.is_finite() {
            continue;
        }
        let label = format!("case {case} (n={n}, nk={nk}, D22≠0: {d22}) ‖Tzw‖∞ (peak ω = {})", h.peak_freq);
        check_fd(&label, &k, &g, |kk| {
            hinf_norm(&closed_loop(&plant, kk).unwrap(), &HinfParams::new(FD_HINF_TOL)).unwrap().value
        });
        checked += 1;
    }
    assert!(checked >= 3, "too few stable random loops ({checked})");
}

#[test]
fn ill_posed_loop_is_an_error() {
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let mut plant = random_plant(&mut rng, 3, 1, 1, 1, 1, true);
    plant.d22[(0, 0)] = 2.0;
    let mut k = random_controller(&mut rng, 1, 1, 1);
    k.dk[(0, 0)] = 0.5; // 1 − Dk·D22 = 0
    assert!(matches!(closed_loop(&plant, &k), Err(LtiError::IllPosed { .. })));
    assert!(matches!(closed_loop_hinf_grad(&plant, &k, &HinfParams::new(1e-10)), Err(LtiError::IllPosed { .. })));
    assert!(matches!(closed_loop_abscissa_grad(&plant, &k), Err(LtiError::IllPosed { .. })));
    k.dk[(0, 0)] = f64::NAN;
    assert!(matches!(closed_loop(&plant, &k), Err(LtiError::IllPosed { .. })));
}

#[test]
fn shape_mismatch_is_an_error() {
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let plant = random_plant(&mut rng, 3, 1, 2, 1, 1, false);
    let k = random_controller(&mut rng, 1, 1, 1);
    assert!(matches!(closed_loop(&plant, &k), Err(LtiError::Shape { .. })));
}

#[test]
fn d22_closed_loop_matches_interconnection() {
    // Check the D22 ≠ 0 loop against a direct solve of the loop equations at one frequency-free
    // level: for random states/inputs, (ẋ, ẋk, z) from the formula equals solving u = K y.
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let plant = random_plant(&mut rng, 4, 2, 2, 2, 3, true);
    let k = random_controller(&mut rng, 2, 2, 3);
    let cl = closed_loop(&plant, &k).unwrap();
    let x = randn(&mut rng, 4, 1, 1.0);
    let xk = randn(&mut rng, 2, 1, 1.0);
    let w = randn(&mut rng, 2, 1, 1.0);
    // u = Ck xk + Dk (C2 x + D21 w + D22 u)  →  (I − Dk D22) u = Ck xk + Dk C2 x + Dk D21 w
    use faer::linalg::solvers::Solve;
    let f = Mat::<f64>::identity(2, 2) - &k.dk * &plant.d22;
    let u = f.partial_piv_lu().solve(&k.ck * &xk + &k.dk * &plant.c2 * &x + &k.dk * &plant.d21 * &w);
    let y = &plant.c2 * &x + &plant.d21 * &w + &plant.d22 * &u;
    let xdot = &plant.a * &x + &plant.b1 * &w + &plant.b2 * &u;
    let xkdot = &k.ak * &xk + &k.bk * &y;
    let z = &plant.c1 * &x + &plant.d11 * &w + &plant.d12 * &u;
    let mut s = Mat::<f64>::zeros(6, 1);
    s.as_mut().submatrix_mut(0, 0, 4, 1).copy_from(&x);
    s.as_mut().submatrix_mut(4, 0, 2, 1).copy_from(&xk);
    let dcl = &cl.a * &s + &cl.b * &w;
    let zcl = &cl.c * &s + &cl.d * &w;
    let mut want = Mat::<f64>::zeros(6, 1);
    want.as_mut().submatrix_mut(0, 0, 4, 1).copy_from(&xdot);
    want.as_mut().submatrix_mut(4, 0, 2, 1).copy_from(&xkdot);
    assert!((&dcl - &want).norm_l2() <= 1e-12 * want.norm_l2());
    assert!((&zcl - &z).norm_l2() <= 1e-12 * z.norm_l2());
}
