//! The bilinear (Cayley) transform of a discrete-time system into a continuous-time one with the
//! same frequency response on the boundary (docs/ALGORITHMS.md §10.2): the discrete H∞ norm is
//! the continuous norm of the image.
//!
//! The Möbius map z = (1 + s)/(1 − s) sends the imaginary axis s = iω onto the unit circle
//! z = e^{iθ}, θ = 2·atan ω (ω = 0 ↦ z = 1, ω = ±∞ ↦ z = −1), and the open left half-plane onto
//! the open unit disc. With W = (A + I)⁻¹ (A has no eigenvalue −1 when ρ(A) < 1),
//!
//! ```text
//! Gc(s) = G((1+s)/(1−s)) = Cc (sI − Ac)⁻¹ Bc + Dc,
//! Ac = (A − I) W = I − 2W,   Bc = √2 W B,   Cc = √2 C W,   Dc = D − C W B,
//! ```
//!
//! (in the scalar case both sides are cb(1 − s)/((1 + a)s + 1 − a) + d), so σmax(Gc(iω)) = σmax(G(e^{iθ})) for every ω, and Ac is Hurwitz iff ρ(A) < 1.
//!
//! *Accuracy.* The transform costs one LU of A + I. Its rounding is a perturbation of A of
//! relative size about ε·κ(A + I): harmless unless A has an eigenvalue near z = −1 (a pole of Gc
//! near s = ∞, a lightly damped mode at θ ≈ π). The other real Möbius map of the disc onto the
//! half-plane, z = −(1 + s)/(1 − s) (the transform of G(−z), i.e. of (−A, B, −C, D), with θ ↦
//! π − θ), is singular at z = +1 instead; [`Cayley::new`] takes whichever of A + I and I − A has
//! the smaller ‖inverse‖_F. Only a system with poles near both z = −1 and z = +1 (distance δ)
//! loses a factor ~1/δ; the norm's value is re-evaluated on the original data at the peak
//! (`norms/discrete.rs`).

use faer::linalg::solvers::{DenseSolveCore, Solve};
use faer::{Mat, Scale};

use crate::lti::system::state_space::StateSpace;

/// A discrete-time system's continuous-time image under z = ±(1 + s)/(1 − s).
#[derive(Debug, Clone)]
pub(crate) struct Cayley {
    /// The continuous-time image (Ac, Bc, Cc, Dc).
    pub sys: StateSpace,
    /// Whether the map is z = −(1 + s)/(1 − s) (the image of G(−z); used when A has an
    /// eigenvalue nearer to −1 than to +1, in the sense of ‖(A ± I)⁻¹‖).
    pub flipped: bool,
}

impl Cayley {
    /// The image of the discrete-time `sys` (finite data); `None` if neither A + I nor I − A
    /// has a finite inverse.
    pub(crate) fn new(sys: &StateSpace) -> Option<Cayley> {
        let n = sys.order();
        let inverse = |sign: f64| {
            let m = Mat::from_fn(n, n, |i, j| sign * sys.a[(i, j)] + if i == j { 1.0 } else { 0.0 });
            let lu = m.partial_piv_lu();
            let w = lu.inverse();
            let size = w.norm_l2();
            size.is_finite().then_some((size, lu, w))
        };
        let (flipped, (_, lu, w)) = match (inverse(1.0), inverse(-1.0)) {
            (Some(plus), Some(minus)) if minus.0 < plus.0 => (true, minus),
            (Some(plus), _) => (false, plus),
            (None, Some(minus)) => (true, minus),
            (None, None) => return None,
        };
        // The flipped system is (−A, B, −C, D): its C is sign·C.
        let sign = if flipped { -1.0 } else { 1.0 };
        let c = &sys.c * Scale(sign);
        let x = lu.solve(&sys.b); // W B
        let ct_w = lu.solve_transpose(c.transpose()); // (C W)ᵀ
        let r2 = std::f64::consts::SQRT_2;
        let image = StateSpace {
            a: Mat::from_fn(n, n, |i, j| if i == j { 1.0 } else { 0.0 } - 2.0 * w[(i, j)]),
            b: &x * Scale(r2),
            c: ct_w.transpose() * Scale(r2),
            d: &sys.d - &c * &x,
        };
        image.is_finite().then_some(Cayley { sys: image, flipped })
    }

    /// The continuous frequency ω ≥ 0 of the image at which it takes the value G(e^{iθ}) has
    /// (θ in rad/sample, folded into [0, π]); +∞ for the map's singular point.
    pub(crate) fn continuous_freq(&self, theta: f64) -> f64 {
        let t = fold(theta);
        let t = if self.flipped { std::f64::consts::PI - t } else { t };
        if t >= std::f64::consts::PI {
            f64::INFINITY
        } else {
            (0.5 * t).tan()
        }
    }

    /// The discrete frequency θ ∈ [0, π] (rad/sample) of the image's frequency ω ≥ 0 (+∞
    /// included): 2·atan ω, or π − 2·atan ω for the flipped map. Exact at the ends.
    pub(crate) fn discrete_freq(&self, w: f64) -> f64 {
        let t = 2.0 * w.abs().atan();
        if self.flipped {
            std::f64::consts::PI - t
        } else {
            t
        }
    }
}

/// The discrete-time system whose image under the map of `flipped` (as [`Cayley::new`] chose it)
/// is the continuous-time `image`: the inverse transform. With V = (I − Ac)⁻¹,
///
/// ```text
/// A = 2V − I,   B = √2 V Bc,   C = √2 Cc V,   D = Dc + Cc V Bc,
/// ```
///
/// (solve the forward formulas for A, B, C, D: W = (A + I)⁻¹ = (I − Ac)/2), then, for the flipped
/// map, (−A, B, −C, D). `None` if I − Ac is singular (a pole of the image at s = 1, which is the
/// map's singular point) or the result is not finite.
pub(crate) fn from_continuous(image: &StateSpace, flipped: bool) -> Option<StateSpace> {
    let n = image.order();
    let m = Mat::from_fn(n, n, |i, j| if i == j { 1.0 } else { 0.0 } - image.a[(i, j)]);
    let lu = m.partial_piv_lu();
    let v = lu.inverse();
    let sign = if flipped { -1.0 } else { 1.0 };
    let r2 = std::f64::consts::SQRT_2;
    let vb = &v * &image.b;
    let sys = StateSpace {
        a: Mat::from_fn(n, n, |i, j| sign * (2.0 * v[(i, j)] - if i == j { 1.0 } else { 0.0 })),
        b: &vb * Scale(r2),
        c: &image.c * &v * Scale(sign * r2),
        d: &image.d + &image.c * &vb,
    };
    sys.is_finite().then_some(sys)
}

/// θ folded into [0, π] (G is real: G(e^{−iθ}) is the conjugate of G(e^{iθ})); NaN stays NaN.
pub(crate) fn fold(theta: f64) -> f64 {
    let two_pi = 2.0 * std::f64::consts::PI;
    let t = theta.rem_euclid(two_pi);
    if t > std::f64::consts::PI {
        two_pi - t
    } else {
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::c64;

    /// G(z) of a real system at a complex point, by a dense solve.
    fn eval(sys: &StateSpace, z: c64) -> Mat<c64> {
        let n = sys.order();
        let cz = |m: &Mat<f64>| Mat::from_fn(m.nrows(), m.ncols(), |i, j| c64::new(m[(i, j)], 0.0));
        let zi = Mat::from_fn(n, n, |i, j| if i == j { z } else { c64::new(0.0, 0.0) }) - cz(&sys.a);
        let x = zi.partial_piv_lu().solve(cz(&sys.b));
        cz(&sys.c) * x + cz(&sys.d)
    }

    fn system(a: [[f64; 3]; 3]) -> StateSpace {
        StateSpace {
            a: Mat::from_fn(3, 3, |i, j| a[i][j]),
            b: Mat::from_fn(3, 2, |i, j| ((i + 2 * j) as f64).cos()),
            c: Mat::from_fn(2, 3, |i, j| ((3 * i + j) as f64 + 0.5).sin()),
            d: Mat::from_fn(2, 2, |i, j| 0.1 * (i as f64) - 0.2 * (j as f64)),
        }
    }

    /// A system with a pole near z = −1 (the map is flipped for it) and one with a pole near
    /// z = +1 (not flipped), each with whether the map is flipped.
    fn one_on_each_side() -> [(StateSpace, bool); 2] {
        [
            (system([[-0.95, 0.2, 0.0], [0.0, 0.3, 0.1], [0.1, 0.0, 0.5]]), true),
            (system([[0.95, 0.2, 0.0], [0.0, -0.3, 0.1], [0.1, 0.0, 0.5]]), false),
        ]
    }

    /// Gc(iω) = G(e^{iθ}) entry by entry (up to conjugation, which the flipped map introduces) at
    /// θ = 0, π and in between, for a system on each side of the choice; Ac is Hurwitz.
    #[test]
    fn the_image_has_the_same_response_on_the_boundary() {
        for (sys, flipped) in one_on_each_side() {
            let cay = Cayley::new(&sys).unwrap();
            assert_eq!(cay.flipped, flipped);
            assert!(crate::lti::kernels::spectral::spectral_abscissa(cay.sys.a.as_ref()) < 0.0);
            for theta in [0.0, 0.3, 1.7, 3.0, std::f64::consts::PI] {
                let w = cay.continuous_freq(theta);
                assert!((cay.discrete_freq(w) - theta).abs() <= 1e-15 * (1.0 + theta), "θ {theta} ω {w}");
                let gd = eval(&sys, c64::new(theta.cos(), theta.sin()));
                let gc = if w.is_finite() {
                    eval(&cay.sys, c64::new(0.0, w))
                } else {
                    Mat::from_fn(2, 2, |i, j| c64::new(cay.sys.d[(i, j)], 0.0))
                };
                for i in 0..2 {
                    for j in 0..2 {
                        let (x, y) = (gd[(i, j)], gc[(i, j)]);
                        let y = if flipped { y.conj() } else { y };
                        assert!((x - y).norm() <= 1e-13 * (1.0 + x.norm()), "θ {theta}: {x:?} vs {y:?}");
                    }
                }
            }
        }
    }

    /// The inverse map takes the image back to the system, on both branches of the map.
    #[test]
    fn the_inverse_map_takes_the_image_back() {
        for (sys, flipped) in one_on_each_side() {
            let c = Cayley::new(&sys).unwrap();
            assert_eq!(c.flipped, flipped);
            let back = from_continuous(&c.sys, c.flipped).unwrap();
            for (x, y) in [(&back.a, &sys.a), (&back.b, &sys.b), (&back.c, &sys.c), (&back.d, &sys.d)] {
                let err = (x - y).norm_l2() / y.norm_l2().max(1.0);
                assert!(err < 1e-13, "flipped = {flipped}: {err:e}");
            }
        }
        // a pole of the image at s = 1 (the map's singular point) has no preimage
        let mut s1 = system([[0.0; 3]; 3]);
        s1.a = Mat::from_fn(3, 3, |i, j| if i == j { 1.0 } else { 0.0 });
        assert!(from_continuous(&s1, false).is_none());
    }

    #[test]
    fn folding_and_the_singular_point() {
        let pi = std::f64::consts::PI;
        assert_eq!(fold(-0.5), 0.5);
        assert!((fold(2.0 * pi - 0.5) - 0.5).abs() < 1e-15);
        assert_eq!(fold(pi), pi);
        assert!(fold(f64::NAN).is_nan());
        let sys = system([[0.1, 0.0, 0.0], [0.0, 0.2, 0.0], [0.0, 0.0, 0.3]]);
        let cay = Cayley::new(&sys).unwrap();
        assert!(!cay.flipped);
        assert_eq!(cay.continuous_freq(pi), f64::INFINITY);
        assert_eq!(cay.discrete_freq(f64::INFINITY), pi);
        assert_eq!(cay.discrete_freq(0.0), 0.0);
    }
}
