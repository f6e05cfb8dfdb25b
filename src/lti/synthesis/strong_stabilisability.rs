//! Whether any *stable* controller can stabilise a plant: the parity interlacing property (PIP)
//! of Youla, Bongiorno & Lu, "Single-loop feedback-stabilization of linear multivariable dynamical
//! plants", Automatica 10 (1974) 159–173 (docs/ALGORITHMS.md §11).
//!
//! P22 (the transfer matrix from u to y) is strongly stabilisable — stabilisable by a stable
//! controller — if and only if between every pair of real blocking zeros of P22 in the closed
//! right half-plane, s = +∞ included, there is an even number of real poles of P22 (counted with
//! multiplicity). A blocking zero is an s where every entry of P22(s) vanishes; +∞ is one when
//! P22 is strictly proper (D22 = 0). For a SISO P22 the blocking zeros are its zeros.
//!
//! How it is computed here: the poles are the eigenvalues of A (the realisation is assumed
//! stabilisable and detectable from u and y, as any design needs; then the closed-RHP poles of P22
//! are exactly A's closed-RHP eigenvalues). The finite zeros of an entry
//! g_ij = c_i(sI − A)⁻¹b_j + d_ij are the finite generalised eigenvalues λ of its Rosenbrock pencil (M, E) = ([[A, b_j],
//! [c_i, d_ij]], diag(I, 0)); they are computed as λ = σ + 1/μ from the eigenvalues μ of
//! (M − σE)⁻¹E for a real shift σ left of the origin (the crate's eigenvalue kernel: faer's QZ took
//! seconds on BDT2's 83 × 83 pencils), and a real closed-RHP candidate is kept only if g_ij(λ)
//! vanishes there to [`PIP_RTOL`] relative to its terms (the infinite eigenvalues, μ = 0, compute as
//! a small cluster whose images are no zeros and fail that test). The blocking zeros are the
//! candidates of the first entry that is not identically zero at which every other such entry
//! vanishes too, less any that coincide with an eigenvalue of A (a cancelled mode of one entry's
//! realisation, not a zero of P22). Every way a zero can be missed here (a test failed by rounding)
//! can only hide a violation, never report a false one: leaving a zero out merges two intervals,
//! and two even counts sum to an even count. Plants with more than [`PIP_MAX_N`] states are not
//! checked.

use std::fmt;

use faer::linalg::solvers::Solve;
use faer::{c64, Mat, MatRef};

use crate::lti::kernels::spectral::eigenvalues;
use crate::lti::Plant;

/// Largest plant order checked (one eigenvalue problem of order n + 1, and a linear solve of
/// order n per entry of P22 and candidate zero).
pub const PIP_MAX_N: usize = 300;

/// Relative tolerance of the PIP check: an eigenvalue λ counts as real when |Im λ| ≤ it ·
/// max(1, |λ|) (a double real pole computes as a pair split by about √ε_mach), in the closed
/// right half-plane when Re λ ≥ −it · max(1, ‖A‖), and two zeros (or a zero and a pole) as one
/// when they differ by at most it · max(1, |z|).
pub const PIP_RTOL: f64 = 1e-6;

/// The real closed-RHP poles and blocking zeros of P22 and whether the parity interlacing
/// property holds.
#[derive(Debug, Clone, PartialEq)]
pub struct ParityInterlacing {
    /// Real blocking zeros of P22 with s ≥ 0, ascending, +∞ last when P22 is strictly proper.
    pub zeros: Vec<f64>,
    /// Real poles of P22 with s ≥ 0, ascending, repeated by multiplicity.
    pub poles: Vec<f64>,
    /// The first pair of consecutive zeros with an odd number of poles between them, if any.
    pub violation: Option<PipViolation>,
}

/// A pair of real closed-RHP blocking zeros of P22 with an odd number of real poles between
/// them: no stable controller stabilises the plant.
#[derive(Debug, Clone, PartialEq)]
pub struct PipViolation {
    /// The smaller zero.
    pub zero_lo: f64,
    /// The larger zero (+∞ when P22 is strictly proper).
    pub zero_hi: f64,
    /// The real poles between them (an odd number).
    pub poles: Vec<f64>,
}

/// A number of the message: `∞`, else 6 significant digits.
fn show(x: f64) -> String {
    if x.is_infinite() {
        "∞".into()
    } else {
        let s = format!("{x:.6}");
        let s = s.trim_end_matches('0').trim_end_matches('.');
        if s == "-0" {
            "0".into()
        } else {
            s.to_string()
        }
    }
}

impl fmt::Display for PipViolation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let poles: Vec<String> = self.poles.iter().map(|&p| show(p)).collect();
        write!(
            f,
            "no stable controller can stabilise this plant: P22 (u → y) fails the parity interlacing property \
             (Youla, Bongiorno & Lu 1974): between its real unstable blocking zeros s = {} and s = {} lie {} real \
             unstable pole{} (s = {}), an odd number; design with the plain objective (objective = \"plain\", \
             --no-strong) for a controller that is allowed to be unstable",
            show(self.zero_lo),
            show(self.zero_hi),
            self.poles.len(),
            if self.poles.len() == 1 { "" } else { "s" },
            poles.join(", ")
        )
    }
}

impl std::error::Error for PipViolation {}

impl ParityInterlacing {
    /// Whether the property holds (P22 is strongly stabilisable).
    pub fn holds(&self) -> bool {
        self.violation.is_none()
    }
}

/// The parity interlacing property of `plant`'s P22 (see the module docs); `None` when the
/// plant has more than [`PIP_MAX_N`] states or an eigenvalue computation fails (not decided).
pub fn parity_interlacing(plant: &Plant) -> Option<ParityInterlacing> {
    let n = plant.dims.n;
    if n > PIP_MAX_N {
        return None;
    }
    let a = plant.a.as_ref();
    let scale = a.norm_l2().max(1.0);
    let spectrum = eigenvalues(a)?;
    let is_real = |l: &c64| l.im.abs() <= PIP_RTOL * l.norm().max(1.0);
    let closed_rhp = |re: f64| re >= -PIP_RTOL * scale;
    let mut poles: Vec<f64> =
        spectrum.iter().filter(|l| is_real(l) && closed_rhp(l.re)).map(|l| l.re.max(0.0)).collect();
    poles.sort_by(f64::total_cmp);
    if poles.is_empty() {
        // no real unstable pole: nothing can lie between two zeros
        return Some(ParityInterlacing { zeros: Vec::new(), poles, violation: None });
    }
    let entries: Vec<Entry<'_>> = (0..plant.dims.p2)
        .flat_map(|i| (0..plant.dims.m2).map(move |j| Entry::of(plant, i, j)))
        .filter(|&g| !identically_zero(g, scale))
        .collect();
    let Some(&first) = entries.first() else {
        // P22 ≡ 0: no blocking-zero structure to check
        return Some(ParityInterlacing { zeros: Vec::new(), poles, violation: None });
    };
    let vanishes = |s: f64| entries.iter().all(|&g| if s.is_infinite() { g.d == 0.0 } else { entry_vanishes_at(g, s) });
    let mut candidates = entry_real_zeros(first, scale)?;
    candidates.retain(|&s| closed_rhp(s));
    candidates.push(f64::INFINITY);
    let common: Vec<f64> = candidates.into_iter().filter(|&s| vanishes(s)).collect();
    let mut zeros = common;
    // a zero at an eigenvalue of A is a cancelled mode of an entry's realisation
    zeros.retain(|&s| s.is_infinite() || !spectrum.iter().any(|l| is_real(l) && same(s, l.re)));
    zeros = zeros.into_iter().map(|s| s.max(0.0)).collect();
    zeros.sort_by(f64::total_cmp);
    zeros.dedup_by(|x, y| same(*x, *y));
    let violation = zeros.windows(2).find_map(|w| {
        let between: Vec<f64> = poles.iter().copied().filter(|&p| p > w[0] && p < w[1]).collect();
        (between.len() % 2 == 1).then(|| PipViolation { zero_lo: w[0], zero_hi: w[1], poles: between })
    });
    Some(ParityInterlacing { zeros, poles, violation })
}

/// One entry g(s) = c(sI − A)⁻¹b + d of P22.
#[derive(Clone, Copy)]
struct Entry<'a> {
    a: MatRef<'a, f64>,
    b: faer::ColRef<'a, f64>,
    c: faer::RowRef<'a, f64>,
    d: f64,
}

impl<'a> Entry<'a> {
    /// Entry (i, j) of `plant`'s P22.
    fn of(plant: &'a Plant, i: usize, j: usize) -> Self {
        Entry { a: plant.a.as_ref(), b: plant.b2.col(j), c: plant.c2.row(i), d: plant.d22[(i, j)] }
    }
}

/// Two zeros (or a zero and a pole) within [`PIP_RTOL`] of each other; +∞ only matches +∞.
fn same(s: f64, t: f64) -> bool {
    if s.is_infinite() || t.is_infinite() {
        return s == t;
    }
    (s - t).abs() <= PIP_RTOL * s.abs().max(t.abs()).max(1.0)
}

/// Whether c(sI − A)⁻¹b + d ≡ 0: d = 0 and every Markov parameter c Aᵏ b (k < n) is zero to
/// rounding (computed on A/‖A‖, so nothing overflows).
fn identically_zero(g: Entry<'_>, scale: f64) -> bool {
    let Entry { a, b, c, d } = g;
    if d != 0.0 {
        return false;
    }
    let tol = 1e-12 * b.norm_l2() * c.norm_l2();
    let mut v: Mat<f64> = Mat::from_fn(b.nrows(), 1, |i, _| b[i]);
    for _ in 0..a.nrows() {
        let h: f64 = (0..v.nrows()).map(|k| c[k] * v[(k, 0)]).sum();
        if h.abs() > tol {
            return false;
        }
        v = (a * &v) * (1.0 / scale);
    }
    true
}

/// Candidates for the real finite zeros of c(sI − A)⁻¹b + d: the real λ = σ + 1/μ of the
/// eigenvalues μ of (M − σE)⁻¹E (the module docs), with the shift σ = −0.73·max(1, ‖A‖) (or a
/// second one should M − σE be singular there); `None` if no shift works or the eigenvalues fail.
fn entry_real_zeros(g: Entry<'_>, scale: f64) -> Option<Vec<f64>> {
    let Entry { a, b, c, d } = g;
    let n = a.nrows();
    let e = Mat::from_fn(n + 1, n + 1, |i, j| if i == j && i < n { 1.0 } else { 0.0 });
    for sigma in [-0.73 * scale, -1.61 * scale] {
        let shifted = Mat::from_fn(n + 1, n + 1, |i, j| match (i < n, j < n) {
            (true, true) => a[(i, j)] - if i == j { sigma } else { 0.0 },
            (true, false) => b[i],
            (false, true) => c[j],
            (false, false) => d,
        });
        let x = shifted.partial_piv_lu().solve(&e);
        if !crate::numeric::all_finite(x.as_ref()) {
            continue;
        }
        let mu = eigenvalues(x.as_ref())?;
        let out = mu
            .iter()
            .filter(|m| m.norm() > 0.0)
            .map(|m| {
                let l = c64::new(1.0, 0.0) / *m;
                c64::new(l.re + sigma, l.im)
            })
            .filter(|l| l.re.is_finite() && l.norm() < 1e8 * scale && l.im.abs() <= PIP_RTOL * l.norm().max(1.0))
            .map(|l| l.re)
            .collect();
        return Some(out);
    }
    None
}

/// Whether g(s) = c(sI − A)⁻¹b + d vanishes at the real s: |g(s)| ≤ [`PIP_RTOL`]·(‖c‖‖x‖ + |d|)
/// with x = (sI − A)⁻¹b (the size of what cancels); false where sI − A is singular (a pole, not a
/// zero).
fn entry_vanishes_at(g: Entry<'_>, s: f64) -> bool {
    let Entry { a, b, c, d } = g;
    let n = a.nrows();
    let z = Mat::from_fn(n, n, |i, j| if i == j { s } else { 0.0 } - a[(i, j)]);
    let x = z.partial_piv_lu().solve(Mat::from_fn(n, 1, |i, _| b[i]));
    if !crate::numeric::all_finite(x.as_ref()) {
        return false;
    }
    let g = d + (0..n).map(|k| c[k] * x[(k, 0)]).sum::<f64>();
    g.abs() <= PIP_RTOL * (c.norm_l2() * x.norm_l2() + d.abs())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A SISO plant y = P u (w, z one channel each, not used) with P = num/den realised in
    /// controllable canonical form; `num` has lower degree than `den` or equal degree.
    fn siso(num: &[f64], den: &[f64]) -> Plant {
        // den monic: s^n + a1 s^(n-1) + … + an; num: b0 s^n + … (padded to length n + 1)
        let n = den.len() - 1;
        let mut b = vec![0.0; n + 1 - num.len()];
        b.extend_from_slice(num);
        let d = b[0];
        // strictly proper part: num − d·den
        let c: Vec<f64> = (1..=n).map(|k| b[k] - d * den[k]).collect();
        let row = |v: Vec<f64>| format!("[{}]", v.iter().map(|x| format!("{x:e}")).collect::<Vec<_>>().join(","));
        let a: Vec<String> = (0..n)
            .map(|i| {
                row((0..n)
                    .map(|j| {
                        if i + 1 < n {
                            if j == i + 1 {
                                1.0
                            } else {
                                0.0
                            }
                        } else {
                            -den[n - j]
                        }
                    })
                    .collect())
            })
            .collect();
        let bcol: Vec<String> = (0..n).map(|i| row(vec![if i + 1 == n { 1.0 } else { 0.0 }])).collect();
        // c in canonical form: coefficients of s^0 … s^(n-1)
        let crow = row((0..n).map(|j| c[n - 1 - j]).collect());
        let zero_col: Vec<String> = (0..n).map(|_| "[0]".to_string()).collect();
        let text = format!(
            r#"{{"name":"P","dims":{{"n":{n},"m1":1,"m2":1,"p1":1,"p2":1}},
            "A":[{}],"B1":[{}],"B2":[{}],"C1":[{}],"C2":[{crow}],
            "D11":[[0]],"D12":[[1]],"D21":[[1]],"D22":[[{d:e}]]}}"#,
            a.join(","),
            zero_col.join(","),
            bcol.join(","),
            row(vec![0.0; n]),
        );
        Plant::from_json_str(&text, "p.json").unwrap()
    }

    /// (s − 1)/((s − 2)(s + 1)): zeros 1 and ∞ in the closed RHP, one pole (2) between them.
    #[test]
    fn a_textbook_plant_that_no_stable_controller_stabilises() {
        let p = siso(&[1.0, -1.0], &[1.0, -1.0, -2.0]);
        let pip = parity_interlacing(&p).unwrap();
        assert_eq!(pip.poles.len(), 1);
        assert!((pip.poles[0] - 2.0).abs() < 1e-9, "{pip:?}");
        assert_eq!(pip.zeros.len(), 2, "{pip:?}");
        assert!((pip.zeros[0] - 1.0).abs() < 1e-9 && pip.zeros[1].is_infinite(), "{pip:?}");
        let v = pip.violation.clone().expect("PIP fails");
        assert_eq!((v.zero_hi, v.poles.len()), (f64::INFINITY, 1));
        let msg = v.to_string();
        assert!(msg.contains("s = 1 and s = ∞") && msg.contains("(s = 2)"), "{msg}");
    }

    /// (s − 1)/((s + 1)(s − 2)(s − 3)): two poles (2, 3) between the zeros 1 and ∞.
    #[test]
    fn a_textbook_plant_that_a_stable_controller_stabilises() {
        let p = siso(&[1.0, -1.0], &[1.0, -4.0, 1.0, 6.0]);
        let pip = parity_interlacing(&p).unwrap();
        assert_eq!(pip.poles.len(), 2, "{pip:?}");
        assert!((pip.poles[0] - 2.0).abs() < 1e-8 && (pip.poles[1] - 3.0).abs() < 1e-8);
        assert_eq!(pip.zeros.len(), 2);
        assert!(pip.holds());
    }

    /// A pole between the zeros 0 and ∞ fails (s/(s − 1)·1/(s + 2)); a biproper plant has no zero
    /// at ∞ and (s − 1)(s − 3)/((s − 2)(s + 5)) fails on the finite pair 1, 3; a double pole
    /// between two zeros is even; an unstable pole left of every zero is outside every pair.
    #[test]
    fn zeros_at_the_origin_finite_pairs_multiplicity_and_poles_outside() {
        // s/((s − 1)(s + 2)) = s/(s² + s − 2)
        let pip = parity_interlacing(&siso(&[1.0, 0.0], &[1.0, 1.0, -2.0])).unwrap();
        let v = pip.violation.expect("0 < 1 < ∞");
        assert_eq!(v.zero_lo, 0.0);
        // (s − 1)(s − 3)/((s − 2)(s + 5)) = (s² − 4s + 3)/(s² + 3s − 10)
        let pip = parity_interlacing(&siso(&[1.0, -4.0, 3.0], &[1.0, 3.0, -10.0])).unwrap();
        assert_eq!(pip.zeros.len(), 2, "{pip:?}");
        let v = pip.violation.expect("1 < 2 < 3");
        assert!((v.zero_lo - 1.0).abs() < 1e-9 && (v.zero_hi - 3.0).abs() < 1e-9, "{v:?}");
        // (s − 1)/((s − 2)²(s + 1)) = (s − 1)/(s³ − 3s² + 0s + 4)
        let pip = parity_interlacing(&siso(&[1.0, -1.0], &[1.0, -3.0, 0.0, 4.0])).unwrap();
        assert_eq!(pip.poles.len(), 2, "{pip:?}");
        assert!(pip.holds(), "{pip:?}");
        // (s − 3)/((s − 1)(s + 1)): the pole 1 lies below the first zero 3: holds
        let pip = parity_interlacing(&siso(&[1.0, -3.0], &[1.0, 0.0, -1.0])).unwrap();
        assert!(pip.holds(), "{pip:?}");
    }

    /// MIMO: the blocking zeros are the zeros common to every entry. diag((s − 1)/((s − 2)(s + 1)),
    /// 1/(s + 3)) has no finite blocking zero (the second entry does not vanish at 1): only ∞,
    /// and one zero makes no pair; with the second entry (s − 1)/(s + 3)² … the zero 1 is common.
    #[test]
    fn mimo_plants_use_blocking_zeros() {
        // states: x1, x2 for entry (1,1) in canonical form, x3 for entry (2,2)
        let mk = |c3: f64, a_extra: &str, c_extra: &str| {
            let text = format!(
                r#"{{"name":"M","dims":{{"n":{n},"m1":1,"m2":2,"p1":1,"p2":2}},
                "A":[[0,1,0{z}],[2,1,0{z}],[0,0,-3{z}]{a_extra}],
                "B1":[{b1}],"B2":[[0,0],[1,0],[0,1]{b2x}],"C1":[[0,0,0{z}]],
                "C2":[[-1,1,0{z}],[0,0,{c3}{c_extra}]],
                "D11":[[0]],"D12":[[0,0]],"D21":[[0],[0]],"D22":[[0,0],[0,0]]}}"#,
                n = if a_extra.is_empty() { 3 } else { 4 },
                z = if a_extra.is_empty() { "" } else { ",0" },
                b1 = if a_extra.is_empty() { "[0],[0],[0]" } else { "[0],[0],[0],[0]" },
                b2x = if a_extra.is_empty() { "" } else { ",[0,0]" },
            );
            Plant::from_json_str(&text, "m.json").unwrap()
        };
        // entry (1,1): A = [[0,1],[2,1]] → s² − s − 2 = (s − 2)(s + 1), C = [−1, 1] → s − 1
        let pip = parity_interlacing(&mk(1.0, "", "")).unwrap();
        assert_eq!(pip.zeros, vec![f64::INFINITY], "{pip:?}");
        assert!(pip.holds());
        // entry (2,2): (s − 1)/(s + 3)², states x3, x4 (x4' = −3 x4 + x3·0 …): realised as
        // x3' = −3x3 + u2, x4' = x3 − 3x4, y2 = −4 x3 + x4 … gives (−4(s + 3) + 1)/(s + 3)²; we
        // want s − 1 = (s + 3) − 4: y2 = x3·1 … use y2 = c3 x3 + x4 with c3 = 1 and x4' = −4x3 − 3x4?
        // Simpler: y2 = c3 x3 + x4, x4' = −3 x4 + k x3 gives (c3(s + 3) + k)/(s + 3)²; c3 = 1,
        // k = −4 → (s − 1)/(s + 3)².
        let pip = parity_interlacing(&mk(1.0, ",[0,0,-4,-3]", ",1")).unwrap();
        assert_eq!(pip.zeros.len(), 2, "{pip:?}");
        assert!((pip.zeros[0] - 1.0).abs() < 1e-8, "{pip:?}");
        assert!(pip.violation.is_some(), "{pip:?}");
    }
}
