//! σmax(G(iω)) along the frequency axis: the band worth looking at, an adaptive curve (dense
//! where the curve bends or peaks, so a plot is smooth at its peaks with few points elsewhere)
//! and every frequency where σmax comes within a relative tolerance of the H∞ norm (an optimal
//! controller often equalises several peaks: ω = 0, a resonance and ω → ∞ at once).
//!
//! Frequencies are in rad/s in both time domains. A discrete-time system's axis is the unit
//! circle, z = e^{iωTs} for ω ∈ [0, π/Ts] (the Nyquist frequency ends it); σmax(G(e^{iθ})) is
//! evaluated as σmax(Gc(iν)) of its bilinear image at the image frequency ν of θ = ωTs
//! (`kernels/bilinear.rs`: the two are equal, docs/ALGORITHMS.md §10.2), which keeps the
//! Hessenberg evaluator of the continuous case.

use faer::c64;

use super::domain::hinf_norm_in;
use super::hinf::{balanced_coordinates, hinf_norm_parts, HinfNorm, HinfParams, NormParts};
use crate::lti::interrupt::Interrupted;
use crate::lti::kernels::bilinear::Cayley;
use crate::lti::kernels::freq_response::FreqResponse;
use crate::lti::kernels::spectral::eigenvalues;
use crate::lti::{StateSpace, TimeDomain};

/// σmax of a system along its domain's frequency axis, at ω in rad/s.
struct AxisResponse {
    fr: FreqResponse,
    /// Discrete time: the sampling time and the bilinear map the evaluator is of.
    discrete: Option<(f64, Cayley)>,
}

impl AxisResponse {
    /// The evaluator of `sys` in `domain`; in discrete time `None` when the system has no
    /// bilinear image (poles at both z = 1 and z = −1) or non-finite data.
    fn new(domain: TimeDomain, sys: &StateSpace) -> Option<Self> {
        match domain {
            TimeDomain::Continuous => Some(AxisResponse { fr: FreqResponse::new(sys), discrete: None }),
            TimeDomain::Discrete { ts } => {
                let cayley = Cayley::new(sys).filter(|_| sys.is_finite())?;
                Some(AxisResponse { fr: FreqResponse::new(&cayley.sys), discrete: Some((ts, cayley)) })
            }
        }
    }

    /// The continuous-time evaluator `fr` (one already made for a norm).
    fn continuous(fr: FreqResponse) -> Self {
        AxisResponse { fr, discrete: None }
    }

    fn sigma_max(&mut self, w: f64) -> f64 {
        match &self.discrete {
            None => self.fr.sigma_max(w),
            Some((ts, cayley)) => {
                let nu = cayley.continuous_freq((w * ts).min(std::f64::consts::PI));
                self.fr.sigma_max(nu)
            }
        }
    }
}

/// The two ends of the domain's frequency axis in rad/s: 0 and +∞, or 0 and the Nyquist
/// frequency π/Ts.
fn axis_ends(domain: TimeDomain) -> [f64; 2] {
    [0.0, domain.nyquist().unwrap_or(f64::INFINITY)]
}

/// Relative tolerance within which two computed norms count as the same value: peaks of σmax
/// within it of ‖G‖∞ are all reported as peaks ([`near_peak_frequencies`]), ε‖K‖∞ within it of
/// ‖Tzw‖∞ makes the controller-norm term active (`design`), and replicates within it of the best
/// γ count as reaching it (`campaign`). 0.1 %: what a person reading 4 significant figures sees
/// as one number.
pub const NORM_TIE_RTOL: f64 = 1e-3;

/// Points of the first, uniform (in log ω) pass of [`sigma_curve`].
pub const SIGMA_BASE_POINTS: usize = 200;
/// Largest number of points [`sigma_curve`] returns.
pub const SIGMA_MAX_POINTS: usize = 3000;
/// Largest relative change of σmax between neighbouring points [`sigma_curve`] leaves unrefined.
pub const SIGMA_STEP_RTOL: f64 = 0.02;

/// The frequency band (rad/s) of the systems' dynamics: from a decade below the slowest to a
/// decade above the fastest mode (|λ| of the nonzero eigenvalues of each A; in discrete time
/// the mode's |ln λ|/Ts), widened to hold every finite positive frequency of `extra`; whole
/// decades; (0.1, 10) with no modes. In discrete time the band ends at the Nyquist frequency
/// π/Ts and starts at least three decades below it.
pub fn frequency_band(domain: TimeDomain, systems: &[&StateSpace], extra: &[f64]) -> (f64, f64) {
    let modes: Vec<c64> = systems.iter().flat_map(|s| eigenvalues(s.a.as_ref()).unwrap_or_default()).collect();
    band_of_modes(domain, &modes, extra)
}

/// [`frequency_band`] of systems whose modes (eigenvalues of the A matrices) are known.
fn band_of_modes(domain: TimeDomain, modes: &[c64], extra: &[f64]) -> (f64, f64) {
    let mode_freq = |l: c64| match domain {
        TimeDomain::Continuous => l.norm(),
        TimeDomain::Discrete { ts } => c64::new(l.norm().ln(), l.arg()).norm() / ts,
    };
    let mags = modes
        .iter()
        .copied()
        .map(mode_freq)
        .filter(|m| *m > 0.0 && m.is_finite())
        .chain(extra.iter().copied().filter(|w| *w > 0.0 && w.is_finite()));
    let (lo, hi) = mags.fold((f64::INFINITY, 0f64), |(l, h), m| (l.min(m), h.max(m)));
    let (lo, hi) = if lo <= hi { (lo, hi) } else { (1.0, 1.0) };
    let band = (10f64.powf((lo / 10.0).log10().floor()), 10f64.powf((hi * 10.0).log10().ceil()));
    let band = match domain.nyquist() {
        None => band,
        Some(nyquist) => (band.0.min(nyquist * 1e-3), nyquist),
    };
    // A log-spaced grid needs finite positive ends: modes near 0 or beyond 1e300 rad/s (a
    // controller's huge entries) must not make an end 0 or +∞ (the grid, and a plot's axis,
    // would be NaN).
    let (lo, hi) = (band.0.clamp(BAND_LIMITS.0, BAND_LIMITS.1), band.1.clamp(BAND_LIMITS.0, BAND_LIMITS.1));
    if lo < hi {
        (lo, hi)
    } else {
        (lo.min(hi / 10.0).max(BAND_LIMITS.0), hi.max(lo * 10.0).min(BAND_LIMITS.1))
    }
}

/// `n` ≥ 2 frequencies spaced uniformly in log ω from `band.0` to `band.1`.
fn log_grid(band: (f64, f64), n: usize) -> impl Iterator<Item = f64> {
    let (l0, l1) = (band.0.log10(), band.1.log10());
    (0..n).map(move |i| 10f64.powf(l0 + (l1 - l0) * i as f64 / (n - 1) as f64))
}

/// The widest band [`frequency_band`] returns (rad/s): wide enough for every plant (entries and
/// sampling times within 1e-50..1e50), narrow enough that its log-spaced grid is finite.
const BAND_LIMITS: (f64, f64) = (1e-300, 1e300);

/// (ω, σmax(G(iω))) on `band`, ascending in ω: [`SIGMA_BASE_POINTS`] log-spaced points, then
/// midpoints (in log ω) inserted next to every point where σmax changes by more than
/// [`SIGMA_STEP_RTOL`] to a neighbour or has a local maximum, until no interval needs it or
/// [`SIGMA_MAX_POINTS`] are reached. `extra` frequencies inside the band (a peak) are added.
/// In discrete time σmax(G(e^{iωTs})); empty if the system has no bilinear image (module docs).
pub fn sigma_curve(domain: TimeDomain, sys: &StateSpace, band: (f64, f64), extra: &[f64]) -> Vec<(f64, f64)> {
    let Some(mut fr) = AxisResponse::new(domain, sys) else { return Vec::new() };
    let mut pts: Vec<(f64, f64)> = log_grid(band, SIGMA_BASE_POINTS)
        .chain(extra.iter().copied().filter(|w| *w > band.0 && *w < band.1))
        .map(|w| (w, fr.sigma_max(w)))
        .collect();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    let rel = |a: f64, b: f64| (a - b).abs() / a.abs().max(b.abs()).max(f64::MIN_POSITIVE);
    for _ in 0..12 {
        let k = pts.len();
        let mut split = vec![false; k.saturating_sub(1)];
        for i in 0..k.saturating_sub(1) {
            if rel(pts[i].1, pts[i + 1].1) > SIGMA_STEP_RTOL {
                split[i] = true;
            }
        }
        for i in 1..k.saturating_sub(1) {
            if pts[i].1 > pts[i - 1].1 && pts[i].1 > pts[i + 1].1 {
                split[i - 1] = true;
                split[i] = true;
            }
        }
        // intervals too narrow to split (a jump, not a bend) are left alone
        for (i, s) in split.iter_mut().enumerate() {
            *s &= pts[i + 1].0 / pts[i].0 > 1.0 + 1e-9;
        }
        let wanted = split.iter().filter(|s| **s).count();
        if wanted == 0 || k + wanted > SIGMA_MAX_POINTS {
            break;
        }
        let mut next = Vec::with_capacity(k + wanted);
        for i in 0..k {
            next.push(pts[i]);
            if i + 1 < k && split[i] {
                let w = (pts[i].0 * pts[i + 1].0).sqrt();
                next.push((w, fr.sigma_max(w)));
            }
        }
        pts = next;
    }
    pts
}

/// Every frequency (rad/s) where σmax(G(iω)) is within a relative `rtol` of `norm.value` (‖G‖∞
/// of a stable `sys`, with `norm.peak_freq` in rad/s), ascending: ω = 0 and ω = +∞ (σmax(D))
/// — in discrete time the Nyquist frequency — when they qualify, and each local maximum of the
/// [`sigma_curve`] on the system's [`frequency_band`], refined by golden-section search in log
/// ω; `norm.peak_freq` is always one of them. Empty for an unstable system and for G ≡ 0.
pub fn near_peak_frequencies(domain: TimeDomain, sys: &StateSpace, norm: &HinfNorm, rtol: f64) -> Vec<f64> {
    let peak = norm.value;
    // no peak of an infinite norm, nor of T ≡ 0 (every frequency would be "within rtol" of 0)
    if !(peak.is_finite() && peak > 0.0) {
        return Vec::new();
    }
    let level = peak * (1.0 - rtol);
    let Some(mut fr) = AxisResponse::new(domain, sys) else { return vec![norm.peak_freq] };
    let mut found: Vec<f64> = Vec::new();
    for w in axis_ends(domain) {
        if fr.sigma_max(w) >= level {
            found.push(w);
        }
    }
    let extra = [norm.peak_freq];
    let curve = sigma_curve(domain, sys, frequency_band(domain, &[sys], &extra), &extra);
    for i in 1..curve.len().saturating_sub(1) {
        if curve[i].1 >= curve[i - 1].1 && curve[i].1 >= curve[i + 1].1 {
            let (w, s) = golden_max(&mut fr, curve[i - 1].0, curve[i + 1].0);
            if s.max(curve[i].1) >= level {
                found.push(if s >= curve[i].1 { w } else { curve[i].0 });
            }
        }
    }
    if !norm.peak_freq.is_nan() {
        found.push(norm.peak_freq);
    }
    found.sort_by(f64::total_cmp);
    // one frequency per peak: neighbours within 1 % (or both near 0) are the same peak
    let mut out: Vec<f64> = Vec::new();
    for w in found {
        match out.last() {
            Some(&last) if w == last || (w.is_finite() && (w - last).abs() <= 1e-2 * w.max(last)) => {
                // keep the reported peak frequency when it is one of the two
                if w == norm.peak_freq {
                    *out.last_mut().expect("non-empty") = w;
                }
            }
            _ => out.push(w),
        }
    }
    out
}

/// The maximum of σmax on [a, b] (0 < a < b) by golden-section search in log ω.
fn golden_max(fr: &mut AxisResponse, a: f64, b: f64) -> (f64, f64) {
    let g = (5f64.sqrt() - 1.0) / 2.0;
    let (mut lo, mut hi) = (a.ln(), b.ln());
    let mut x1 = hi - g * (hi - lo);
    let mut x2 = lo + g * (hi - lo);
    let (mut f1, mut f2) = (fr.sigma_max(x1.exp()), fr.sigma_max(x2.exp()));
    for _ in 0..60 {
        if hi - lo < 1e-10 {
            break;
        }
        if f1 >= f2 {
            hi = x2;
            (x2, f2) = (x1, f1);
            x1 = hi - g * (hi - lo);
            f1 = fr.sigma_max(x1.exp());
        } else {
            lo = x1;
            (x1, f1) = (x2, f2);
            x2 = lo + g * (hi - lo);
            f2 = fr.sigma_max(x2.exp());
        }
    }
    if f1 >= f2 {
        (x1.exp(), f1)
    } else {
        (x2.exp(), f2)
    }
}

/// Points of the log-spaced grid on which [`hinf_norm_checked`] checks a norm.
pub const NORM_CHECK_POINTS: usize = 200;
/// A grid value above the norm by more than this (relative) is a missed peak.
pub const NORM_CHECK_RTOL: f64 = 1e-8;

/// ‖sys‖∞ in `domain` (`hinf_norm_in`, peak frequency in its units), checked against σmax at
/// ω = 0 and on `NORM_CHECK_POINTS` log-spaced frequencies of the [`frequency_band`], evaluated
/// in balanced state coordinates wherever balancing moves A (the same transfer function exactly;
/// D⁻¹AD with D a diagonal of powers of two). If a grid value is above the norm by more than
/// `NORM_CHECK_RTOL`, the norm missed that peak or under-read it, and it is computed again in
/// those coordinates from that frequency (a hint, whose peak is climbed); the larger of that
/// and the grid's value is returned. Every value is an attained σmax, so the check can only
/// raise a norm. What verification and reports use (`design::evaluate`); the optimiser's
/// norms do without it (a second evaluator per norm).
///
/// Why, two failures of COMPleib's AC12 under plain designs, whose ‖Tzw‖∞ ≈ 1e-7 is tiny
/// against the loop's data (‖C_cl‖ = 1e3, ‖A_cl‖ = 5.8e3):
/// * order 3, γ = 1.147e-7: the Hamiltonian of the level-set test has blocks of size ‖C‖²/γ,
///   its eigenvalues near the crossings are lost, and the norm came out 9.42e-8, a value attained
///   at a mode frequency, 18 % low (SLICOT's AB13DD: 1.1428e-7; σmax in 40-digit arithmetic and
///   in double precision at the peak, 5.742 rad/s: 1.14703e-7);
/// * orders 1 and 2, peak at ω = 0: σmax itself, from the Hessenberg form of the unbalanced A,
///   came out 3.4e-4 and 1.5e-3 low (1.08474e-7 against 1.08512e-7 in 40-digit arithmetic).
///   The Hessenberg reduction mixes rows of sizes 1e-2 to 1e3; in balanced coordinates (‖A‖_F
///   63 against 5.8e3) the same evaluator is within 1.3e-6.
///
/// Both in `tests/hinf_regression.rs`. A third, a discrete loop of HE1 sampled at Ts = 1e-7
/// (modes from 6e-9 to 1.1 after the bilinear transform), whose design summary said
/// ‖Tzw‖∞ = 0.152088 where σmax reaches 0.154795 at 0.836 rad/s, is why the design's reported γ
/// is this norm too (`hinf_norm_checked_with`).
pub fn hinf_norm_checked(domain: TimeDomain, sys: &StateSpace) -> HinfNorm {
    hinf_norm_checked_with(domain, sys, &HinfParams::default()).expect("no stop hook is set")
}

/// [`hinf_norm_checked`] with `params`' tolerance and stop hook (its hints, `enough` and
/// `reuse` are not used): `Err(Interrupted)` only if the stop hook fired.
pub fn hinf_norm_checked_with(
    domain: TimeDomain,
    sys: &StateSpace,
    params: &HinfParams<'_>,
) -> Result<HinfNorm, Interrupted> {
    let params = HinfParams { tol: params.tol, stop: params.stop, ..HinfParams::default() };
    // In continuous time the norm's poles give the band, and its evaluator serves the grid
    // where the coordinates agree.
    let (h, parts) = match domain {
        TimeDomain::Continuous => {
            let p = hinf_norm_parts(sys, &params)?;
            (p.norm, Some(p))
        }
        _ => (hinf_norm_in(domain, sys, &params)?, None),
    };
    if !h.value.is_finite() || sys.order() == 0 {
        return Ok(h);
    }
    let balanced = balanced_coordinates(sys);
    let checked = balanced.as_ref().unwrap_or(sys);
    // The norm's evaluator is of its working coordinates (`hinf::Working`): the balanced ones
    // where balancing pays, which are the grid's; else `sys`, the grid's only if balancing
    // leaves A as it is.
    let (band, kept) = match parts {
        Some(NormParts { poles: Some(poles), response, working, .. }) => {
            let shared = working.scaling.is_some() || balanced.is_none();
            (band_of_modes(domain, &poles, &[]), response.filter(|_| shared))
        }
        _ => (frequency_band(domain, &[sys], &[]), None),
    };
    let Some(mut fr) = kept.map(AxisResponse::continuous).or_else(|| AxisResponse::new(domain, checked)) else {
        return Ok(h);
    };
    let (mut s_top, mut w_top) = (f64::NEG_INFINITY, f64::NAN);
    for w in std::iter::once(0.0).chain(log_grid(band, NORM_CHECK_POINTS)) {
        let s = fr.sigma_max(w);
        if s > s_top {
            (s_top, w_top) = (s, w);
        }
    }
    if !(s_top > h.value * (1.0 + NORM_CHECK_RTOL)) {
        return Ok(h);
    }
    // the grid's frequency in the norm's units (rad/sample in discrete time)
    let hint = match domain {
        TimeDomain::Continuous => w_top,
        TimeDomain::Discrete { ts } => (w_top * ts).min(std::f64::consts::PI),
    };
    let again = hinf_norm_in(domain, checked, &HinfParams { hints: &[hint], ..params })?;
    Ok(if again.value >= s_top { again } else { HinfNorm { value: s_top, peak_freq: hint } })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::lti::{hinf_norm, HinfParams};
    use faer::Mat;

    fn ss(a: Mat<f64>, b: Mat<f64>, c: Mat<f64>, d: Mat<f64>) -> StateSpace {
        StateSpace::new(a, b, c, d).unwrap()
    }

    /// G(s) = 1 + 2ζωn s/(s² + 2ζωn s + ωn²)·k with a resonance: the band holds ωn, the curve is
    /// refined around the peak (its points closer there than the uniform pass) and the peak is
    /// found at ωn, |G(iωn)| = 1 + k.
    #[test]
    fn the_curve_is_dense_at_a_resonance_and_its_peak_is_found() {
        let (wn, z, k) = (3.0, 0.01, 1.0);
        let a = Mat::from_fn(2, 2, |i, j| [[0.0, 1.0], [-wn * wn, -2.0 * z * wn]][i][j]);
        let b = Mat::from_fn(2, 1, |i, _| [0.0, 1.0][i]);
        let c = Mat::from_fn(1, 2, |_, j| [0.0, 2.0 * z * wn * k][j]);
        let d = Mat::from_fn(1, 1, |_, _| 1.0);
        let g = ss(a, b, c, d);
        let band = frequency_band(TimeDomain::Continuous, &[&g], &[]);
        assert_eq!(band, (0.1, 100.0));
        let curve = sigma_curve(TimeDomain::Continuous, &g, band, &[]);
        assert!(curve.len() > SIGMA_BASE_POINTS && curve.len() <= SIGMA_MAX_POINTS);
        assert!(curve.windows(2).all(|w| w[0].0 < w[1].0));
        let step = |w0: f64| {
            let i = curve.iter().position(|p| p.0 >= w0).unwrap();
            curve[i + 1].0 / curve[i].0
        };
        let uniform = (1000f64).powf(1.0 / (SIGMA_BASE_POINTS - 1) as f64);
        assert!(step(wn) < 1.0 + (uniform - 1.0) / 4.0, "not refined at the peak: {}", step(wn));
        let h = hinf_norm(&g, &HinfParams::default()).unwrap();
        assert!((h.value - (1.0 + k)).abs() < 1e-6, "{h:?}");
        let peaks = near_peak_frequencies(TimeDomain::Continuous, &g, &h, NORM_TIE_RTOL);
        assert_eq!(peaks.len(), 1, "{peaks:?}");
        assert!((peaks[0] - wn).abs() < 1e-3 * wn, "{peaks:?}");
    }

    /// σmax equal to the norm at ω = 0, at a resonance and as ω → ∞, lower in between: the
    /// diagonal system diag(1 − x(s), x(s)) with the band-pass x = 2ζωn s/(s² + 2ζωn s + ωn²),
    /// whose value on the imaginary axis runs on the circle |x − ½| = ½ from 0 (ω = 0) through
    /// 1 (ω = ωn) back to 0 (ω → ∞): σmax = max(|1 − x|, |x|) is 1 at the three and below 1
    /// elsewhere.
    #[test]
    fn every_frequency_at_the_peak_is_reported() {
        let (wn, z) = (0.72, 0.05);
        let t = 2.0 * z * wn;
        let a = Mat::from_fn(4, 4, |i, j| match (i, j) {
            (0, 1) | (2, 3) => 1.0,
            (1, 0) | (3, 2) => -wn * wn,
            (1, 1) | (3, 3) => -t,
            _ => 0.0,
        });
        let b = Mat::from_fn(4, 2, |i, j| if (i, j) == (1, 0) || (i, j) == (3, 1) { 1.0 } else { 0.0 });
        let c = Mat::from_fn(2, 4, |i, j| match (i, j) {
            (0, 1) => -t,
            (1, 3) => t,
            _ => 0.0,
        });
        let d = Mat::from_fn(2, 2, |i, j| if (i, j) == (0, 0) { 1.0 } else { 0.0 });
        let g = ss(a, b, c, d);
        let h = hinf_norm(&g, &HinfParams::default()).unwrap();
        assert!((h.value - 1.0).abs() < 1e-6, "{h:?}");
        let peaks = near_peak_frequencies(TimeDomain::Continuous, &g, &h, NORM_TIE_RTOL);
        assert_eq!(peaks.len(), 3, "{peaks:?}");
        assert_eq!(peaks[0], 0.0);
        assert!((peaks[1] - wn).abs() < 1e-3, "{peaks:?}");
        assert!(peaks[2].is_infinite());
        // a tighter tolerance than the ends' distance keeps them: they are exactly 1
        assert_eq!(near_peak_frequencies(TimeDomain::Continuous, &g, &h, 1e-9).len(), 3);
        // G ≡ 0 has no peak (every frequency is "within rtol" of 0)
        let zero = ss(
            Mat::from_fn(2, 2, |i, j| if i == j { -1.0 } else { 0.0 }),
            Mat::zeros(2, 1),
            Mat::zeros(1, 2),
            Mat::zeros(1, 1),
        );
        let h0 = hinf_norm(&zero, &HinfParams::default()).unwrap();
        assert_eq!(h0.value, 0.0);
        assert!(near_peak_frequencies(TimeDomain::Continuous, &zero, &h0, NORM_TIE_RTOL).is_empty());
    }
}
