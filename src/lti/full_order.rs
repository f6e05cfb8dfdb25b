//! The optimal full-order H∞ level γ_opt of a generalised plant (the "full" row of the paper's
//! tables), by γ-iteration on the two Riccati equations.
//!
//! # The γ-test (Glover–Doyle 1988; Doyle–Glover–Khargonekar–Francis 1989; the general-D form as
//! in Zhou–Doyle–Glover 1996, ch. 17, and SLICOT SB10PD/SB10QD)
//!
//! With `B = [B1 B2]`, `C = [C1; C2]`, `D1• = [D11 D12]`, `D•1 = [D11; D21]` and
//!
//! ```text
//! R  = D1•ᵀ D1• − diag(γ² I_m1, 0),          R̃ = D•1 D•1ᵀ − diag(γ² I_p1, 0),
//! X:  (A − B R⁻¹ D1•ᵀ C1)ᵀ X + X (A − B R⁻¹ D1•ᵀ C1) − X B R⁻¹ Bᵀ X + C1ᵀ (I − D1• R⁻¹ D1•ᵀ) C1 = 0,
//! Y:  (A − B1 D•1ᵀ R̃⁻¹ C) Y + Y (…)ᵀ − Y Cᵀ R̃⁻¹ C Y + B1 (I − D•1ᵀ R̃⁻¹ D•1) B1ᵀ = 0,
//! ```
//!
//! a stabilising controller with ‖T_zw‖∞ < γ exists iff (i) γ > max(σ̄(D12⊥ᵀ D11), σ̄(D11 D21⊥ᵀ))
//! (the part of D11 no controller can touch), (ii) the X Hamiltonian has no imaginary-axis
//! eigenvalues and its stabilising solution X ⪰ 0, (iii) the same for Y ⪰ 0, (iv) ρ(XY) < γ².
//! This "R-form" needs no explicit normalisation of D12, D21: it is invariant under the usual
//! scalings u → T u, z → U z, y → S y, w → V w that bring D12ᵀD12 = I and D21D21ᵀ = I, so the
//! standing assumption is only that D12 has full column rank and D21 full row rank (plus the
//! imaginary-axis rank conditions). D11 ≠ 0 is handled directly (no loop shifting needed). D22
//! does not affect γ_opt (it is removed by a loop transformation of the controller) and is ignored.
//! Each Riccati equation is solved by [`super::riccati::solve_care`] (matrix sign function, with
//! finiteness, residual and stabilising checks); any failure there means "γ infeasible".
//!
//! Feasibility is monotone in γ, so γ_opt is found by bracketing (factors of 10) and geometric
//! bisection down to the relative width [`GAMMA_RTOL`]; the reported `gamma` is the feasible end.
//!
//! # Singular problems: regularisation
//!
//! Several benchmark plants have D12 without full column rank or D21 without full row rank (HE1,
//! REA2, HF1, AC10, BDT2: D21 = 0; CM4: D21 is 2×1). As is usual in the field (e.g. the
//! regularisation used with `hinfsyn`, and the perturbation argument of Stoorvogel 1992 showing
//! γ_opt(δ) ↓ γ_opt as δ ↓ 0), the singular side is augmented with δ-weighted channels:
//!
//! * D21 rank-deficient: new disturbances w_x (state noise) and v (sensor noise),
//!   `B1 → [B1, δI_n, 0]`, `D21 → [D21, 0, δI_p2]`, `D11 → [D11, 0, 0]`;
//! * D12 rank-deficient: new outputs δ x and δ u,
//!   `C1 → [C1; δI_n; 0]`, `D12 → [D12; 0; δI_m2]`, `D11 → [D11; 0; 0]`.
//!
//! The state channels also restore the imaginary-axis rank conditions (BDT2 has integrators not
//! reached by B1). Augmenting w and z can only increase ‖T_zw‖ for every controller, so γ(δ) is an
//! upper bound of the singular infimum and decreases to it as δ → 0. δ is absolute (in the plant's
//! units). It is decreased through [`REGULARISATION_DELTAS`] (10⁻⁵ … 10⁻⁸) until γ(δ) is flat to
//! [`FLAT_RTOL`], or until the numerics stop being trustworthy (γ(δ) would increase as δ
//! decreases, which is impossible in exact arithmetic: the Hamiltonians carry 1/δ² terms), and
//! the value at the smallest trusted δ is reported, with the whole sequence, in
//! [`FullOrderGamma::regularisation_history`]. Very slowly converging plants (BDT2) are reported as such.

use std::fmt;

use faer::{Mat, MatRef, Side};

use super::plant::Plant;
use super::riccati::solve_care;
use crate::numeric::all_finite;

/// Relative width of the final γ bracket.
pub const GAMMA_RTOL: f64 = 1e-8;
/// Relative singular-value threshold for the numerical rank of D12 and D21.
pub const RANK_TOL: f64 = 1e-10;
/// Regularisation levels tried in order (absolute), for plants with singular D12 or D21.
pub const REGULARISATION_DELTAS: [f64; 4] = [1e-5, 1e-6, 1e-7, 1e-8];
/// Stop decreasing δ once γ changes relatively by less than this.
pub const FLAT_RTOL: f64 = 1e-6;
/// X ⪰ 0 test: λmin(X) ≥ −(PSD_RTOL·max|λ(X)| + PSD_ATOL).
pub const PSD_RTOL: f64 = 1e-8;
/// Absolute part of the X ⪰ 0 / Y ⪰ 0 test (accepts rounding noise around X = 0).
pub const PSD_ATOL: f64 = 1e-12;
/// Largest γ tried when searching a feasible level.
pub const GAMMA_MAX: f64 = 1e12;
/// Relative to the first trial, the smallest γ tried before declaring γ_opt = 0.
const GAMMA_MIN_REL: f64 = 1e-12;

/// Which condition of the γ-test fails just below γ_opt.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Binding {
    /// γ_opt equals the D11 bound (condition (i)).
    Feedthrough,
    /// The X (state-feedback) Riccati equation has no stabilising X ⪰ 0.
    StateFeedback,
    /// The Y (output-injection / filter) Riccati equation has no stabilising Y ⪰ 0.
    Filter,
    /// The coupling condition ρ(XY) < γ².
    Coupling,
    /// γ_opt = 0 (every tried level was feasible).
    None,
}

impl Binding {
    /// Short human-readable text.
    pub fn text(self) -> &'static str {
        match self {
            Binding::Feedthrough => "D11 bound",
            Binding::StateFeedback => "X Riccati (state feedback)",
            Binding::Filter => "Y Riccati (filter)",
            Binding::Coupling => "coupling rho(XY) = gamma^2",
            Binding::None => "none",
        }
    }
}

/// The full-order optimal H∞ level and how it was obtained.
#[derive(Debug, Clone, serde::Serialize)]
pub struct FullOrderGamma {
    /// γ_opt (feasible end of the final bracket; at the reported δ for singular plants).
    pub gamma: f64,
    /// Infeasible end of the final bracket (γ_opt ∈ (gamma_lower, gamma]).
    pub gamma_lower: f64,
    /// The regularisation δ at which `gamma` was evaluated; `None` for a regular plant.
    pub regularisation: Option<f64>,
    /// Numerical rank of D12 (m2 = full column rank).
    pub d12_rank: usize,
    /// Numerical rank of D21 (p2 = full row rank).
    pub d21_rank: usize,
    /// D12 was regularised (z augmented with δ x, δ u).
    pub d12_regularised: bool,
    /// D21 was regularised (w augmented with δ state noise, δ sensor noise).
    pub d21_regularised: bool,
    /// γ(δ) for every δ evaluated, in order (empty for a regular plant).
    pub regularisation_history: Vec<(f64, f64)>,
    /// Whether γ(δ) was flat to [`FLAT_RTOL`] at the reported δ (true for a regular plant).
    pub regularisation_converged: bool,
    /// The condition that fails just below γ_opt.
    pub binding: Binding,
    /// The D11 lower bound (condition (i)).
    pub feedthrough_bound: f64,
    /// Number of γ-tests (pairs of Riccati solves) performed in total.
    pub gamma_tests: usize,
    /// Remarks (e.g. why δ was not decreased further).
    pub notes: Vec<String>,
}

impl FullOrderGamma {
    /// A one-paragraph description for `campaign plant NAME`.
    pub fn describe(&self) -> String {
        self.to_string()
    }
}

impl fmt::Display for FullOrderGamma {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "full-order gamma_opt = {:.7} (bracket ({:.7}, {:.7}], {} gamma-tests; binding: {})",
            self.gamma,
            self.gamma_lower,
            self.gamma,
            self.gamma_tests,
            self.binding.text()
        )?;
        if let Some(delta) = self.regularisation {
            let mut what = Vec::new();
            if self.d21_regularised {
                what.push(format!("D21 rank {} (w augmented with delta*I state and sensor noise)", self.d21_rank));
            }
            if self.d12_regularised {
                what.push(format!("D12 rank {} (z augmented with delta*x, delta*u)", self.d12_rank));
            }
            write!(f, "\n  singular plant: {}; regularised, reported at delta = {delta:.0e}", what.join("; "))?;
            let hist: Vec<String> =
                self.regularisation_history.iter().map(|(e, g)| format!("{e:.0e}: {g:.7}")).collect();
            write!(
                f,
                "\n  gamma(delta): {}{}",
                hist.join(", "),
                if self.regularisation_converged {
                    " (flat)"
                } else {
                    " (not flat: an upper bound of the delta -> 0 limit)"
                }
            )?;
        }
        for n in &self.notes {
            write!(f, "\n  note: {n}")?;
        }
        Ok(())
    }
}

/// Why γ_opt could not be computed.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum FullOrderError {
    /// Plant data with NaN or infinity.
    #[error("plant has non-finite entries")]
    NonFinite,
    /// The plant has no control input or no measurement.
    #[error("plant has m2 = {m2} control inputs and p2 = {p2} measurements; both must be positive")]
    NoControl {
        /// Control inputs.
        m2: usize,
        /// Measurements.
        p2: usize,
    },
    /// No γ up to [`GAMMA_MAX`] passes the test (e.g. (A, B2) not stabilisable, (C2, A) not
    /// detectable, or the rank conditions fail on the imaginary axis).
    #[error("no feasible gamma up to {gamma_max:e} (last failure: {last})")]
    NoFeasibleGamma {
        /// Largest γ tried.
        gamma_max: f64,
        /// The last failure seen.
        last: String,
    },
    /// A rank or eigenvalue computation failed.
    #[error("linear algebra failure: {0}")]
    LinearAlgebra(&'static str),
}

/// How singular problems are regularised.
#[derive(Debug, Clone, PartialEq)]
pub enum Regularisation {
    /// Decrease δ through [`REGULARISATION_DELTAS`] until flat or no longer trustworthy (default).
    Auto,
    /// One fixed δ (used if D12 or D21 is rank-deficient).
    Fixed(f64),
}

/// Options of [`full_order_gamma_with`].
#[derive(Debug, Clone, PartialEq)]
pub struct FullOrderOptions {
    /// Relative width of the final bracket.
    pub rtol: f64,
    /// Regularisation policy.
    pub regularisation: Regularisation,
}

impl Default for FullOrderOptions {
    fn default() -> Self {
        FullOrderOptions { rtol: GAMMA_RTOL, regularisation: Regularisation::Auto }
    }
}

/// γ_opt of the plant with default options (see the module docs).
pub fn full_order_gamma(plant: &Plant) -> Result<FullOrderGamma, FullOrderError> {
    full_order_gamma_with(plant, &FullOrderOptions::default())
}

/// γ_opt of the plant with explicit options.
pub fn full_order_gamma_with(plant: &Plant, opts: &FullOrderOptions) -> Result<FullOrderGamma, FullOrderError> {
    let d = plant.dims;
    if d.m2 == 0 || d.p2 == 0 {
        return Err(FullOrderError::NoControl { m2: d.m2, p2: d.p2 });
    }
    for m in [&plant.a, &plant.b1, &plant.b2, &plant.c1, &plant.c2, &plant.d11, &plant.d12, &plant.d21] {
        if !all_finite(m.as_ref()) {
            return Err(FullOrderError::NonFinite);
        }
    }
    let d12_rank = numerical_rank(plant.d12.as_ref())?;
    let d21_rank = numerical_rank(plant.d21.as_ref())?;
    let d12_reg = d12_rank < d.m2;
    let d21_reg = d21_rank < d.p2;
    let mut tests = 0usize;
    let mut notes = Vec::new();

    if !d12_reg && !d21_reg {
        let prob = Problem::new(plant, 0.0, false, false)?;
        let b = prob.gamma_opt(opts.rtol, None, &mut tests)?;
        return Ok(FullOrderGamma {
            gamma: b.hi,
            gamma_lower: b.lo,
            regularisation: None,
            d12_rank,
            d21_rank,
            d12_regularised: false,
            d21_regularised: false,
            regularisation_history: Vec::new(),
            regularisation_converged: true,
            binding: b.binding,
            feedthrough_bound: prob.gamma_d,
            gamma_tests: tests,
            notes,
        });
    }

    let delta_list: Vec<f64> = match opts.regularisation {
        Regularisation::Auto => REGULARISATION_DELTAS.to_vec(),
        Regularisation::Fixed(e) => vec![e],
    };
    let mut history: Vec<(f64, f64)> = Vec::new();
    let mut best: Option<(f64, Bracket, f64)> = None; // (delta, bracket, gamma_d)
    let mut converged = false;
    for &delta in &delta_list {
        let prob = Problem::new(plant, delta, d12_reg, d21_reg)?;
        let warm = best.as_ref().map(|(_, b, _)| b.hi);
        if let Some(prev) = warm {
            // γ(δ) is non-increasing as δ decreases: the previous γ must still be feasible.
            tests += 1;
            if let Err(why) = prob.test(prev) {
                notes.push(format!(
                    "delta = {delta:.0e} not used: the previous gamma {prev:.7} tested infeasible there ({}), \
                     i.e. the 1/delta^2-scaled Riccati equations are no longer numerically reliable",
                    why.1
                ));
                break;
            }
        }
        let b = match prob.gamma_opt(opts.rtol, warm, &mut tests) {
            Ok(b) => b,
            Err(e) if best.is_some() => {
                notes.push(format!("delta = {delta:.0e} not used: {e}"));
                break;
            }
            Err(e) => return Err(e),
        };
        history.push((delta, b.hi));
        let prev = best.as_ref().map(|(_, pb, _)| pb.hi);
        best = Some((delta, b, prob.gamma_d));
        if let Some(p) = prev {
            if (p - history.last().expect("pushed").1).abs() <= FLAT_RTOL * p {
                converged = true;
                break;
            }
        }
    }
    let (delta, b, gamma_d) = best.expect("the first delta either succeeds or returns an error");
    if matches!(opts.regularisation, Regularisation::Fixed(_)) {
        converged = false;
        notes.push("fixed delta requested: no delta -> 0 convergence check".into());
    }
    Ok(FullOrderGamma {
        gamma: b.hi,
        gamma_lower: b.lo,
        regularisation: Some(delta),
        d12_rank,
        d21_rank,
        d12_regularised: d12_reg,
        d21_regularised: d21_reg,
        regularisation_history: history,
        regularisation_converged: converged,
        binding: b.binding,
        feedthrough_bound: gamma_d,
        gamma_tests: tests,
        notes,
    })
}

/// A γ bracket: `lo` infeasible (or the D11 bound / 0), `hi` feasible.
#[derive(Debug, Clone)]
struct Bracket {
    lo: f64,
    hi: f64,
    binding: Binding,
}

/// The (possibly regularised) plant with the γ-independent products precomputed.
struct Problem {
    n: usize,
    m1: usize,
    p1: usize,
    a: Mat<f64>,
    b: Mat<f64>,
    c: Mat<f64>,
    /// D1•ᵀ D1• ((m1+m2)²), D1•ᵀ C1, C1ᵀ C1.
    d1t_d1: Mat<f64>,
    d1t_c1: Mat<f64>,
    c1t_c1: Mat<f64>,
    /// D•1 D•1ᵀ ((p1+p2)²), D•1 B1ᵀ, B1 B1ᵀ.
    dd1_dd1t: Mat<f64>,
    dd1_b1t: Mat<f64>,
    b1_b1t: Mat<f64>,
    /// Condition (i) bound.
    gamma_d: f64,
}

impl Problem {
    fn new(plant: &Plant, delta: f64, reg12: bool, reg21: bool) -> Result<Problem, FullOrderError> {
        let (n, m2, p2) = (plant.dims.n, plant.dims.m2, plant.dims.p2);
        let (mut b1, mut c1) = (plant.b1.clone(), plant.c1.clone());
        let (mut d11, mut d12, mut d21) = (plant.d11.clone(), plant.d12.clone(), plant.d21.clone());
        if reg12 {
            let p1 = c1.nrows();
            c1 = Mat::from_fn(p1 + n + m2, n, |i, j| {
                if i < p1 {
                    c1[(i, j)]
                } else if i - p1 == j {
                    delta
                } else {
                    0.0
                }
            });
            d12 = Mat::from_fn(p1 + n + m2, m2, |i, j| {
                if i < p1 {
                    d12[(i, j)]
                } else if i >= p1 + n && i - p1 - n == j {
                    delta
                } else {
                    0.0
                }
            });
            d11 = Mat::from_fn(p1 + n + m2, d11.ncols(), |i, j| if i < p1 { d11[(i, j)] } else { 0.0 });
        }
        if reg21 {
            let m1 = b1.ncols();
            b1 = Mat::from_fn(n, m1 + n + p2, |i, j| {
                if j < m1 {
                    b1[(i, j)]
                } else if j - m1 == i {
                    delta
                } else {
                    0.0
                }
            });
            d21 = Mat::from_fn(p2, m1 + n + p2, |i, j| {
                if j < m1 {
                    d21[(i, j)]
                } else if j >= m1 + n && j - m1 - n == i {
                    delta
                } else {
                    0.0
                }
            });
            d11 = Mat::from_fn(d11.nrows(), m1 + n + p2, |i, j| if j < m1 { d11[(i, j)] } else { 0.0 });
        }
        let (p1, m1) = (c1.nrows(), b1.ncols());
        let b = concat_cols(b1.as_ref(), plant.b2.as_ref());
        let c = concat_rows(c1.as_ref(), plant.c2.as_ref());
        let d1 = concat_cols(d11.as_ref(), d12.as_ref());
        let dd1 = concat_rows(d11.as_ref(), d21.as_ref());
        let gamma_d = feedthrough_bound(d11.as_ref(), d12.as_ref(), d21.as_ref())?;
        Ok(Problem {
            n,
            m1,
            p1,
            a: plant.a.clone(),
            d1t_d1: d1.transpose() * &d1,
            d1t_c1: d1.transpose() * &c1,
            c1t_c1: c1.transpose() * &c1,
            dd1_dd1t: &dd1 * dd1.transpose(),
            dd1_b1t: &dd1 * b1.transpose(),
            b1_b1t: &b1 * b1.transpose(),
            b,
            c,
            gamma_d,
        })
    }

    /// The γ-test: Ok(ρ(XY)/γ²) if γ is feasible, Err((binding, reason)) otherwise.
    fn test(&self, gamma: f64) -> Result<f64, (Binding, String)> {
        let n = self.n;
        let g2 = gamma * gamma;
        if gamma <= self.gamma_d {
            return Err((Binding::Feedthrough, format!("gamma {gamma} <= D11 bound {}", self.gamma_d)));
        }
        // X: R = D1ᵀD1 − diag(γ²I, 0); M = R⁻¹ [D1ᵀC1, Bᵀ].
        let mut r = self.d1t_d1.clone();
        for i in 0..self.m1 {
            r[(i, i)] -= g2;
        }
        let rhs = concat_cols(self.d1t_c1.as_ref(), self.b.transpose());
        let m = solve(r.as_ref(), rhs.as_ref()).ok_or((Binding::StateFeedback, "R singular".to_string()))?;
        let (r_dc, r_bt) = (m.subcols(0, n), m.subcols(n, n));
        let ax = &self.a - &self.b * r_dc;
        let gx = &self.b * r_bt;
        let qx = &self.c1t_c1 - self.d1t_c1.transpose() * r_dc;
        let x = solve_care(ax.as_ref(), gx.as_ref(), qx.as_ref())
            .map_err(|e| (Binding::StateFeedback, format!("X: {e}")))?
            .x;
        let (xl, xv) = sym_eig(x.as_ref()).ok_or((Binding::StateFeedback, "eig(X) failed".to_string()))?;
        psd_check(&xl).map_err(|s| (Binding::StateFeedback, format!("X: {s}")))?;

        // Y: R̃ = D•1D•1ᵀ − diag(γ²I, 0); N = R̃⁻¹ [D•1B1ᵀ, C].
        let mut rt = self.dd1_dd1t.clone();
        for i in 0..self.p1 {
            rt[(i, i)] -= g2;
        }
        let rhs = concat_cols(self.dd1_b1t.as_ref(), self.c.as_ref());
        let nn = solve(rt.as_ref(), rhs.as_ref()).ok_or((Binding::Filter, "R~ singular".to_string()))?;
        let (rt_db, rt_c) = (nn.subcols(0, n), nn.subcols(n, n));
        // CARE in transposed form: A_yᵀ Y + Y A_y − Y G_y Y + Q_y with A_y = (A − B1 D•1ᵀ R̃⁻¹ C)ᵀ.
        let ay = self.a.transpose() - self.c.transpose() * rt_db;
        let gy = self.c.transpose() * rt_c;
        let qy = &self.b1_b1t - self.dd1_b1t.transpose() * rt_db;
        let y = solve_care(ay.as_ref(), gy.as_ref(), qy.as_ref()).map_err(|e| (Binding::Filter, format!("Y: {e}")))?.x;
        let (yl, _) = sym_eig(y.as_ref()).ok_or((Binding::Filter, "eig(Y) failed".to_string()))?;
        psd_check(&yl).map_err(|s| (Binding::Filter, format!("Y: {s}")))?;

        // ρ(XY) = λmax(X^{1/2} Y X^{1/2}).
        let sq = Mat::from_fn(n, n, |i, j| xv[(i, j)] * xl[j].max(0.0).sqrt());
        let xh = &sq * xv.transpose();
        let mm = &xh * &y * &xh;
        let (ml, _) = sym_eig(mm.as_ref()).ok_or((Binding::Coupling, "eig(X^1/2 Y X^1/2) failed".to_string()))?;
        let rho = ml.last().copied().unwrap_or(0.0);
        if rho < g2 {
            Ok(rho / g2)
        } else {
            Err((Binding::Coupling, format!("rho(XY)/gamma^2 = {:.6}", rho / g2)))
        }
    }

    /// Bracket and bisect. `warm`: a γ known feasible (previous δ), searched downwards from.
    fn gamma_opt(&self, rtol: f64, warm: Option<f64>, tests: &mut usize) -> Result<Bracket, FullOrderError> {
        let floor = self.gamma_d;
        let mut lo_binding = Binding::Feedthrough;
        let (mut lo, mut hi);
        match warm {
            Some(w) => {
                // Step down from w by growing relative amounts until infeasible.
                hi = w;
                let mut delta = 1e-5;
                loop {
                    let g = (hi * (1.0 - delta)).max(floor);
                    if g <= floor {
                        lo = floor;
                        break;
                    }
                    *tests += 1;
                    match self.test(g) {
                        Ok(_) => {
                            hi = g;
                            delta = (delta * 10.0).min(0.9);
                        }
                        Err((bnd, _)) => {
                            lo = g;
                            lo_binding = bnd;
                            break;
                        }
                    }
                }
            }
            None => {
                let start = if floor > 0.0 { 2.0 * floor } else { 1.0 };
                *tests += 1;
                match self.test(start) {
                    Ok(_) => {
                        hi = start;
                        loop {
                            let g = hi / 10.0;
                            if g <= floor {
                                lo = floor;
                                break;
                            }
                            if g < GAMMA_MIN_REL * start {
                                return Ok(Bracket { lo: 0.0, hi, binding: Binding::None });
                            }
                            *tests += 1;
                            match self.test(g) {
                                Ok(_) => hi = g,
                                Err((bnd, _)) => {
                                    lo = g;
                                    lo_binding = bnd;
                                    break;
                                }
                            }
                        }
                    }
                    Err((bnd, why)) => {
                        lo = start;
                        lo_binding = bnd;
                        let mut last = why;
                        loop {
                            let g = lo * 10.0;
                            if g > GAMMA_MAX {
                                return Err(FullOrderError::NoFeasibleGamma { gamma_max: GAMMA_MAX, last });
                            }
                            *tests += 1;
                            match self.test(g) {
                                Ok(_) => {
                                    hi = g;
                                    break;
                                }
                                Err((bnd, why)) => {
                                    lo = g;
                                    lo_binding = bnd;
                                    last = why;
                                }
                            }
                        }
                    }
                }
            }
        }
        while hi - lo > rtol * hi {
            let mid = if lo > 0.0 { (lo * hi).sqrt() } else { 0.5 * hi };
            *tests += 1;
            match self.test(mid) {
                Ok(_) => hi = mid,
                Err((bnd, _)) => {
                    lo = mid;
                    lo_binding = bnd;
                }
            }
        }
        Ok(Bracket { lo, hi, binding: lo_binding })
    }
}

/// max(σ̄(D12⊥ᵀ D11), σ̄(D11 D21⊥ᵀ)) via the projectors onto the complements of range(D12) and of
/// the row space of D21.
fn feedthrough_bound(d11: MatRef<'_, f64>, d12: MatRef<'_, f64>, d21: MatRef<'_, f64>) -> Result<f64, FullOrderError> {
    if d11.nrows() == 0 || d11.ncols() == 0 || d11.norm_max() == 0.0 {
        return Ok(0.0);
    }
    let p12 = complement_projector(d12)?; // p1 × p1
    let p21 = complement_projector(d21.transpose())?; // m1 × m1
    let a = sigma_max((&p12 * d11).as_ref())?;
    let b = sigma_max((d11 * &p21).as_ref())?;
    Ok(a.max(b))
}

/// I − U_r U_rᵀ, U_r an orthonormal basis of range(M).
fn complement_projector(m: MatRef<'_, f64>) -> Result<Mat<f64>, FullOrderError> {
    let r = m.nrows();
    let mut p = Mat::<f64>::identity(r, r);
    if m.ncols() == 0 || m.norm_max() == 0.0 {
        return Ok(p);
    }
    let svd = m.thin_svd().map_err(|_| FullOrderError::LinearAlgebra("SVD"))?;
    let s = svd.S().column_vector();
    let smax = (0..s.nrows()).map(|i| s[i]).fold(0.0, f64::max);
    let u = svd.U();
    for k in 0..s.nrows() {
        if s[k] > RANK_TOL * smax {
            for i in 0..r {
                for j in 0..r {
                    p[(i, j)] -= u[(i, k)] * u[(j, k)];
                }
            }
        }
    }
    Ok(p)
}

fn numerical_rank(m: MatRef<'_, f64>) -> Result<usize, FullOrderError> {
    if m.nrows() == 0 || m.ncols() == 0 {
        return Ok(0);
    }
    let s = m.singular_values().map_err(|_| FullOrderError::LinearAlgebra("singular values"))?;
    let smax = s.iter().copied().fold(0.0, f64::max);
    Ok(s.iter().filter(|&&v| v > RANK_TOL * smax && v > 0.0).count())
}

fn sigma_max(m: MatRef<'_, f64>) -> Result<f64, FullOrderError> {
    if m.nrows() == 0 || m.ncols() == 0 {
        return Ok(0.0);
    }
    let s = m.singular_values().map_err(|_| FullOrderError::LinearAlgebra("singular values"))?;
    Ok(s.iter().copied().fold(0.0, f64::max))
}

/// Ascending eigenvalues and eigenvectors of the symmetric part of m.
fn sym_eig(m: MatRef<'_, f64>) -> Option<(Vec<f64>, Mat<f64>)> {
    let n = m.nrows();
    let s = Mat::from_fn(n, n, |i, j| 0.5 * (m[(i, j)] + m[(j, i)]));
    let e = s.self_adjoint_eigen(Side::Lower).ok()?;
    let d = e.S().column_vector();
    let vals: Vec<f64> = (0..n).map(|i| d[i]).collect();
    if vals.iter().any(|v| !v.is_finite()) {
        return None;
    }
    Some((vals, e.U().to_owned()))
}

fn psd_check(eigs: &[f64]) -> Result<(), String> {
    let max_abs = eigs.iter().fold(0.0f64, |a, &v| a.max(v.abs()));
    let lmin = eigs.first().copied().unwrap_or(0.0);
    if lmin >= -(PSD_RTOL * max_abs + PSD_ATOL) {
        Ok(())
    } else {
        Err(format!("not positive semidefinite (lambda_min = {lmin:.3e}, max |lambda| = {max_abs:.3e})"))
    }
}

/// Solves R Z = B by LU; None if the result is not finite.
fn solve(r: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Option<Mat<f64>> {
    use faer::linalg::solvers::Solve;
    let z = r.partial_piv_lu().solve(b);
    all_finite(z.as_ref()).then_some(z)
}

fn concat_cols(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    let ca = a.ncols();
    Mat::from_fn(a.nrows(), ca + b.ncols(), |i, j| if j < ca { a[(i, j)] } else { b[(i, j - ca)] })
}

fn concat_rows(a: MatRef<'_, f64>, b: MatRef<'_, f64>) -> Mat<f64> {
    let ra = a.nrows();
    Mat::from_fn(ra + b.nrows(), a.ncols(), |i, j| if i < ra { a[(i, j)] } else { b[(i - ra, j)] })
}
