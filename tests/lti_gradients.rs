//! Central finite-difference checks of every gradient (α_cl, α_K, ‖Tzw‖∞, ‖K‖∞) at seeded random
//! points, with D22 = 0 and D22 ≠ 0, nk = 0 and nk > 0; the same in discrete time (ρ_cl, ρ_K and
//! the norms on the unit circle); the H2 norm (continuous and discrete, of a system and of the
//! loop) and 1/r_C(Acl); plus the ill-posed loop.

use faer::Mat;
use hinfix::lti::{
    closed_loop, closed_loop_abscissa_grad, closed_loop_h2_grad, closed_loop_h2_grad_discrete, closed_loop_hinf_grad,
    closed_loop_hinf_grad_discrete, closed_loop_inverse_stability_radius_grad, closed_loop_radius_grad,
    controller_abscissa_grad, controller_hinf_grad, controller_hinf_grad_discrete, controller_radius_grad,
    h2_feedthrough_parameterisation, h2_norm, h2_norm_discrete, h2_norm_grad, h2_norm_grad_discrete, hinf_norm,
    hinf_norm_discrete, hinf_norm_grad_discrete, inverse_stability_radius, spectral_abscissa, spectral_radius,
    Controller, HinfParams, LtiError, Plant, StateSpace,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

mod common;

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
    let mats = [
        a,
        randn(rng, n, m1, 1.0),
        randn(rng, n, m2, 1.0),
        randn(rng, p1, n, 1.0),
        randn(rng, p2, n, 1.0),
        randn(rng, p1, m1, 0.3),
        randn(rng, p1, m2, 0.5),
        randn(rng, p2, m1, 0.5),
        if d22 { randn(rng, p2, m2, 0.4) } else { Mat::zeros(p2, m2) },
    ];
    common::plant_of("random", mats)
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

/// Compares an analytic gradient with central differences of `f`; returns the largest
/// |fd − g| / max(1, ‖g‖∞).
fn check_fd(label: &str, k: &Controller, g: &Controller, mut f: impl FnMut(&Controller) -> f64) -> f64 {
    let gmax = entries(k).iter().map(|&(b, i, j)| block(g, b)[(i, j)].abs()).fold(1.0, f64::max);
    let mut worst = 0.0f64;
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
        worst = worst.max((fd - an).abs() / gmax);
    }
    worst
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

/// The continuous H2 norm of strictly proper loops (D22 = 0: D11 = D12·X·D21, D12 of deficient
/// rank where m2 > 1, and Dk on the affine set of `h2_feedthrough_parameterisation`; D22 ≠ 0:
/// D11 = 0, D21 = 0), its chain rule checked
/// on all of (Ak, Bk, Ck, Dk) against the strictly proper part's norm and along the affine set
/// against the loop's own value; 1/r_C(Acl); and the discrete H2 norm of the same plants with A
/// and Ak scaled into the unit disc (any feedthrough).
#[test]
fn h2_and_stability_radius_gradients_match_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(20261207);
    let params = HinfParams::new(FD_HINF_TOL);
    let (mut checked_h2, mut checked_affine, mut checked_radius) = (0, 0, 0);
    let mut worst = [0.0f64; 4]; // ‖Tzw‖₂, along z, 1/r_C, discrete ‖Tzw‖₂
    for case in 0..12 {
        let d22 = case % 2 == 1;
        let nk = [0, 1, 2, 3][case / 3 % 4];
        let (n, m1, m2, p1, p2) = [(4, 2, 1, 2, 1), (5, 2, 2, 3, 2), (6, 1, 2, 2, 3)][case % 3];
        let mut plant = random_plant(&mut rng, n, m1, m2, p1, p2, d22);
        let mut k = random_controller(&mut rng, nk, m2, p2);
        let label = format!("case {case} (n={n}, nk={nk}, D22≠0: {d22})");
        let affine = if d22 {
            plant.d11 = Mat::zeros(p1, m1);
            plant.d21 = Mat::zeros(p2, m1);
            None
        } else {
            if m2 > 1 {
                plant.d12.col_mut(m2 - 1).fill(0.0); // rank D12 < m2: free parameters
            }
            plant.d11 = &plant.d12 * randn(&mut rng, m2, p2, 1.0) * &plant.d21;
            let aff = h2_feedthrough_parameterisation(&plant).unwrap();
            let z: Vec<f64> = (0..aff.dim()).map(|_| 0.3 * rng.sample::<f64, _>(StandardNormal)).collect();
            k.dk = aff.dk(&z).unwrap();
            Some((aff, z))
        };
        let strictly_proper = |kk: &Controller| {
            let cl = closed_loop(&plant, kk).unwrap();
            h2_norm(&StateSpace { d: Mat::zeros(cl.d.nrows(), cl.d.ncols()), ..cl })
        };
        let (h2, g) = closed_loop_h2_grad(&plant, &k).unwrap();
        if spectral_abscissa(closed_loop(&plant, &k).unwrap().a.as_ref()) < 0.0 {
            assert!(h2.is_finite() && (h2 - strictly_proper(&k)).abs() <= 1e-14 * h2, "{label}: ‖Tzw‖₂ {h2}");
            worst[0] = worst[0].max(check_fd(&format!("{label} ‖Tzw‖₂"), &k, &g, strictly_proper));
            checked_h2 += 1;
            // Along the affine set the loop's own value (its feedthrough test included) is finite,
            // and ∂f/∂zᵢ = ⟨Eᵢ, ∂f/∂Dk⟩.
            if let Some((aff, z)) = affine.filter(|(aff, _)| aff.dim() > 0) {
                let dz = aff.components(g.dk.as_ref()).unwrap();
                for (i, &dzi) in dz.iter().enumerate() {
                    let at = |t: f64| {
                        let mut zz = z.clone();
                        zz[i] += t;
                        let kk = Controller { dk: aff.dk(&zz).unwrap(), ..k.clone() };
                        closed_loop_h2_grad(&plant, &kk).unwrap().0
                    };
                    let fd = (at(H) - at(-H)) / (2.0 * H);
                    assert!((fd - dzi).abs() <= FD_REL * dzi.abs().max(1.0), "{label}: ∂/∂z{i}: {fd} vs {dzi}");
                    worst[1] = worst[1].max((fd - dzi).abs() / dzi.abs().max(1.0));
                }
                checked_affine += 1;
            }
        } else {
            assert_eq!(h2, f64::INFINITY, "{label}");
            assert!(g.dk[(0, 0)].is_nan());
        }
        let (r, g) = closed_loop_inverse_stability_radius_grad(&plant, &k, &params).unwrap();
        if r.value.is_finite() {
            let err = check_fd(&format!("{label} 1/r_C (peak ω = {})", r.peak_freq), &k, &g, |kk| {
                inverse_stability_radius(closed_loop(&plant, kk).unwrap().a.as_ref(), &params).unwrap().value
            });
            worst[2] = worst[2].max(err);
            checked_radius += 1;
        }

        let sign = if case % 4 < 2 { 1.0 } else { -1.0 };
        plant.a = schur(&plant.a, 0.5, sign);
        if nk > 0 {
            k.ak = schur(&k.ak, 0.7, -sign);
        }
        let (h2, g) = closed_loop_h2_grad_discrete(&plant, &k).unwrap();
        if spectral_radius(closed_loop(&plant, &k).unwrap().a.as_ref()) < 1.0 {
            let err = check_fd(&format!("{label} discrete ‖Tzw‖₂ = {h2}"), &k, &g, |kk| {
                h2_norm_discrete(&closed_loop(&plant, kk).unwrap())
            });
            worst[3] = worst[3].max(err);
        } else {
            assert_eq!(h2, f64::INFINITY, "{label}");
        }
    }
    eprintln!(
        "checked {checked_h2} H2 loops ({checked_affine} along z), {checked_radius} 1/r_C: worst |fd − g|/max(1, ‖g‖∞) \
         ‖Tzw‖₂ {:.1e}, along z {:.1e}, 1/r_C {:.1e}, discrete ‖Tzw‖₂ {:.1e}",
        worst[0], worst[1], worst[2], worst[3]
    );
    assert!(checked_h2 >= 6 && checked_radius >= 6, "too few stable random loops ({checked_h2}, {checked_radius})");
    assert!(checked_affine >= 2, "too few loops with free feedthrough parameters ({checked_affine})");
}

/// The H2 norm's gradient with respect to a system's own (A, B, C, D), continuous (D = 0, whose
/// block is zero: the norm is +∞ off it) and discrete, through the controller-shaped check.
#[test]
fn system_h2_gradients_match_finite_differences() {
    let mut rng = ChaCha8Rng::seed_from_u64(20261208);
    let as_controller = |s: StateSpace| Controller::continuous(s.a, s.b, s.c, s.d);
    let as_system = |k: &Controller| StateSpace { a: k.ak.clone(), b: k.bk.clone(), c: k.ck.clone(), d: k.dk.clone() };
    for (n, m, p) in [(1, 1, 1), (3, 2, 1), (6, 2, 3), (12, 1, 2)] {
        let plant = random_plant(&mut rng, n, m, 0, p, 0, false);
        let sys = StateSpace { a: plant.a.clone(), b: plant.b1.clone(), c: plant.c1.clone(), d: Mat::zeros(p, m) };
        let (h2, g) = h2_norm_grad(&sys);
        assert!(h2.is_finite() && h2 == h2_norm(&sys));
        let strictly_proper = |kk: &Controller| h2_norm(&StateSpace { d: Mat::zeros(p, m), ..as_system(kk) });
        let err = check_fd(&format!("n={n} ‖G‖₂"), &as_controller(sys.clone()), &as_controller(g), strictly_proper);
        let dsys = StateSpace { a: schur(&sys.a, 0.8, -1.0), d: randn(&mut rng, p, m, 1.0), ..sys };
        let (h2, g) = h2_norm_grad_discrete(&dsys);
        assert!(h2.is_finite() && h2 == h2_norm_discrete(&dsys));
        let derr =
            check_fd(&format!("n={n} discrete ‖G‖₂"), &as_controller(dsys.clone()), &as_controller(g), |kk| {
                h2_norm_discrete(&as_system(kk))
            });
        eprintln!("n={n}: worst |fd − g|/max(1, ‖g‖∞) ‖G‖₂ {err:.1e}, discrete {derr:.1e}");
    }
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
    // a plant of two controls against a controller of one output
    let mut rng = ChaCha8Rng::seed_from_u64(4);
    let (plant, k) = (random_plant(&mut rng, 3, 1, 2, 1, 1, false), random_controller(&mut rng, 1, 1, 1));
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
