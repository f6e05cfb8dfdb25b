//! σ-plot of one controller on its plant: σmax(T_zw(iω)) and σmax(K(iω)) against ω (rad/s),
//! log-log (in discrete time σmax at z = e^{iωTs}, ω up to the Nyquist frequency π/Ts), with the H∞ peak of T_zw marked (the level-set value and frequency from
//! `lti::hinf_norm`, not the grid's maximum).
//!
//! The frequency band runs from a decade below the slowest to a decade above the fastest
//! closed-loop or controller mode (|λ|, zero modes ignored), widened to contain the peak
//! (`lti::frequency_band`); each curve is `lti::sigma_curve`'s adaptive grid (200 log-spaced
//! points, refined where σmax bends or peaks, at most 3000), so the curves are smooth at their
//! peaks and the SVG stays small; the peak frequency itself is on the closed loop's grid.

use plotters::coord::Shift;
use plotters::prelude::*;

use super::render::{colour, draw_legend, log_ticks, msg, tick, DrawError, Figure, FONT_FAMILY};
use crate::lti::{
    closed_loop, frequency_band, hinf_norm_in, sigma_curve, Controller, HinfParams, LtiError, Plant, StateSpace,
};

/// Data of one σ-plot.
#[derive(Debug, Clone, PartialEq)]
pub struct SigmaFigure {
    /// Title.
    pub title: String,
    /// (ω, σmax(T_zw(iω))).
    pub closed_loop: Vec<(f64, f64)>,
    /// (ω, σmax(K(iω))).
    pub controller: Vec<(f64, f64)>,
    /// ‖T_zw‖∞ and the frequency where it is attained (may be 0 or +∞).
    pub peak: (f64, f64),
    /// The sampling time of a discrete-time plant (the curves are then at z = e^{iωTs}, up to
    /// the Nyquist frequency); `None` in continuous time.
    pub ts: Option<f64>,
}

impl SigmaFigure {
    /// Computes the curves of `k` on `plant`. Errors if the closed loop cannot be formed; an
    /// unstable closed loop is drawn all the same (its peak is then +∞ and not marked).
    pub fn new(plant: &Plant, k: &Controller, title: String) -> Result<Self, LtiError> {
        let cl = closed_loop(plant, k)?;
        let ks = StateSpace::new(k.ak.clone(), k.bk.clone(), k.ck.clone(), k.dk.clone())?;
        let domain = plant.domain;
        let h = hinf_norm_in(domain, &cl, &HinfParams::default()).expect("no stop hook is set");
        let peak_freq = domain.to_rad_per_s(h.peak_freq);
        let peak = [peak_freq];
        let band = frequency_band(domain, &[&cl, &ks], &peak);
        let closed_loop = sigma_curve(domain, &cl, band, &peak);
        let controller = sigma_curve(domain, &ks, band, &[]);
        Ok(SigmaFigure { title, closed_loop, controller, peak: (h.value, peak_freq), ts: domain.ts() })
    }

    fn positive(v: &[(f64, f64)]) -> impl Iterator<Item = (f64, f64)> + '_ {
        v.iter().copied().filter(|p| p.1 > 0.0 && p.1.is_finite())
    }

    /// Where the peak is drawn: its frequency, moved to the grid's nearer end when it is 0 or
    /// +∞; `None` when there is nothing to mark (no finite positive peak — a zero ‖T_zw‖∞ has no
    /// place on the log axis —, no grid, or a grid whose ends are not an interval of positive
    /// frequencies).
    pub fn peak_point(&self) -> Option<(f64, f64)> {
        let (g, w) = self.peak;
        if !(g > 0.0 && g.is_finite()) || w.is_nan() {
            return None;
        }
        let (w0, w1) = (self.closed_loop.first()?.0, self.closed_loop.last()?.0);
        // not `clamp`: it panics on NaN or reversed bounds
        let grid = w0 > 0.0 && w0 <= w1 && w1.is_finite();
        grid.then(|| (w.max(w0).min(w1), g))
    }
}

/// The points of a log-log curve worth drawing: a point is kept when it moves at least about a
/// pixel (1/800 of the axes' log spans) from the last one kept, and so is every local maximum and
/// the last point. The adaptive grid is denser than the pixels where the curve is steep, and a
/// thick line through sub-pixel segments draws hairy edges.
fn for_screen(points: impl Iterator<Item = (f64, f64)>, x: (f64, f64), y: (f64, f64)) -> Vec<(f64, f64)> {
    let pts: Vec<(f64, f64)> = points.collect();
    let (dx, dy) = ((x.1 / x.0).ln() / 800.0, (y.1 / y.0).ln() / 800.0);
    let mut out: Vec<(f64, f64)> = Vec::with_capacity(pts.len());
    for (i, &p) in pts.iter().enumerate() {
        let peak = i > 0 && i + 1 < pts.len() && p.1 >= pts[i - 1].1 && p.1 >= pts[i + 1].1;
        let far = out.last().is_none_or(|&(x0, y0)| (p.0 / x0).ln().abs() >= dx || (p.1 / y0).ln().abs() >= dy);
        if far || peak || i + 1 == pts.len() {
            out.push(p);
        }
    }
    out
}

/// The σ axis's ticks: [`log_ticks`], or its two ends when the range is too narrow for any.
fn y_ticks(lo: f64, hi: f64) -> Vec<f64> {
    let t = log_ticks(lo, hi);
    if t.len() >= 2 {
        t
    } else {
        vec![lo, hi]
    }
}

impl Figure for SigmaFigure {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), DrawError> {
        let ys = Self::positive(&self.closed_loop)
            .chain(Self::positive(&self.controller))
            .map(|p| p.1)
            .chain(self.peak_point().map(|p| p.1));
        let (lo, hi) = ys.fold((f64::INFINITY, 0f64), |(l, h), v| (l.min(v), h.max(v)));
        let (lo, hi) = if lo <= hi { (lo / 2.0, hi * 2.0) } else { (0.1, 10.0) };
        let (w0, w1) = match (self.closed_loop.first(), self.closed_loop.last()) {
            (Some(a), Some(b)) if a.0 < b.0 => (a.0, b.0),
            _ => (0.1, 10.0),
        };
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, (FONT_FAMILY, 24))
            .margin(16)
            .x_label_area_size(54)
            .y_label_area_size(90)
            .build_cartesian_2d((w0..w1).log_scale(), (lo..hi).log_scale().with_key_points(y_ticks(lo, hi)))
            .map_err(msg)?;
        chart
            .configure_mesh()
            .x_desc(match self.ts {
                None => "frequency ω (rad/s)".to_string(),
                Some(ts) => format!(
                    "frequency ω (rad/s), up to the Nyquist frequency π/Ts (Ts = {} s)",
                    crate::numeric::readable(ts)
                ),
            })
            .y_desc("largest singular value σ_max")
            .x_label_formatter(&|v| tick(*v))
            .y_label_formatter(&|v| tick(*v))
            .label_style((FONT_FAMILY, 15))
            .axis_desc_style((FONT_FAMILY, 17))
            .draw()
            .map_err(msg)?;
        let at = if self.ts.is_some() { "e^(iωTs)" } else { "iω" };
        let curves = [
            (&self.closed_loop, colour::OURS, format!("σ_max(T_zw({at})), closed loop")),
            (&self.controller, colour::CONTROLLER, format!("σ_max(K({at})), controller")),
        ];
        for (curve, colour, label) in curves {
            let style = colour.stroke_width(2);
            chart
                .draw_series(LineSeries::new(for_screen(Self::positive(curve), (w0, w1), (lo, hi)), style))
                .map_err(msg)?
                .label(label)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], style));
        }
        if let Some(p) = self.peak_point() {
            let (g, w) = self.peak;
            let at = if w.is_infinite() {
                "ω → ∞".to_string()
            } else if w == 0.0 {
                "ω = 0".to_string()
            } else {
                format!("ω = {} rad/s", tick(w))
            };
            let text = format!("peak ‖T_zw‖∞ = {} at {at}", tick(g));
            chart
                .draw_series(std::iter::once(Circle::new(p, 7, colour::PAPER.filled())))
                .map_err(msg)?
                .label(text)
                .legend(|(x, y)| Circle::new((x + 12, y), 6, colour::PAPER.filled()));
        }
        draw_legend(&mut chart, SeriesLabelPosition::LowerLeft)
    }
}
