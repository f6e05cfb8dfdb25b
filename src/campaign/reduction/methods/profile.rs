//! Performance profiles (Dolan & Moré, Math. Program. 91, 2002): for each method s,
//! ρ_s(τ) = (number of entries on which s's ratio to the best is ≤ τ) / (number of entries),
//! drawn against a log-scaled τ ≥ 1, one step line per method. A failure or a missing entry has
//! ratio +∞: it never counts, so ρ_s(τ) stays below 1 when s failed somewhere.

use plotters::coord::Shift;
use plotters::prelude::*;

use crate::campaign::reduction::plot::render::{log_ticks, msg, styled_mesh, DrawError, Figure, FONT_FAMILY};

/// One performance-profile figure.
#[derive(Debug, Clone, PartialEq)]
pub struct ProfileFigure {
    /// Title.
    pub title: String,
    /// What the ratios are of (the τ axis' description).
    pub x_desc: String,
    /// Per method: its label and its ratio on every entry (+∞ for a failure).
    pub methods: Vec<(String, Vec<f64>)>,
}

/// ρ(τ) of one method's ratios: the fraction of them that are ≤ τ (0 for no entries).
pub fn rho(ratios: &[f64], tau: f64) -> f64 {
    if ratios.is_empty() {
        return 0.0;
    }
    ratios.iter().filter(|&&r| r <= tau).count() as f64 / ratios.len() as f64
}

/// The step function ρ as the corners of its graph on [1, `tau_max`]: (1, ρ(1)), then at each
/// finite ratio t in (1, tau_max] the points (t, ρ(t⁻)) and (t, ρ(t)), then (tau_max, ρ(tau_max)).
pub fn steps(ratios: &[f64], tau_max: f64) -> Vec<(f64, f64)> {
    let mut ts: Vec<f64> = ratios.iter().copied().filter(|&r| r.is_finite() && r > 1.0 && r <= tau_max).collect();
    ts.sort_by(f64::total_cmp);
    ts.dedup();
    let mut pts = vec![(1.0, rho(ratios, 1.0))];
    for t in ts {
        let before = pts.last().map_or(0.0, |p| p.1);
        pts.push((t, before));
        pts.push((t, rho(ratios, t)));
    }
    pts.push((tau_max, rho(ratios, tau_max)));
    pts
}

impl ProfileFigure {
    /// The right end of the τ axis: a little beyond the largest finite ratio, at least 2.
    pub fn tau_max(&self) -> f64 {
        let worst = self.methods.iter().flat_map(|m| m.1.iter()).copied().filter(|r| r.is_finite()).fold(1.0, f64::max);
        (worst * 1.25).max(2.0)
    }
}

/// Ticks of the τ axis [1, `tau_max`]: [`log_ticks`], or within less than a decade (where
/// that gives only 1 and 2) 1, 1.05, 1.1, 1.2, 1.5, 2, 3, 5, 7 as far as they go.
pub fn tau_ticks(tau_max: f64) -> Vec<f64> {
    let ticks = log_ticks(1.0, tau_max);
    if ticks.len() >= 4 {
        return ticks;
    }
    [1.0, 1.05, 1.1, 1.2, 1.5, 2.0, 3.0, 5.0, 7.0, 10.0].into_iter().filter(|&t| t <= tau_max).collect()
}

/// Line colours (Okabe–Ito), then dash patterns, so that the lines stay apart in grey too.
const COLOURS: [RGBColor; 7] = [
    RGBColor(0, 114, 178),
    RGBColor(213, 94, 0),
    RGBColor(0, 158, 115),
    RGBColor(204, 121, 167),
    RGBColor(86, 180, 233),
    RGBColor(230, 159, 0),
    RGBColor(0, 0, 0),
];

impl Figure for ProfileFigure {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), DrawError> {
        let tau_max = self.tau_max();
        let ticks = tau_ticks(tau_max);
        let mut chart = ChartBuilder::on(root)
            .caption(&self.title, (FONT_FAMILY, 30))
            .margin(18)
            .x_label_area_size(64)
            .y_label_area_size(84)
            .build_cartesian_2d((1.0..tau_max).log_scale().with_key_points(ticks), 0.0..1.04)
            .map_err(msg)?;
        styled_mesh(chart.configure_mesh().x_desc(&self.x_desc).y_desc("fraction of entries ρ(τ)"), 22)
            .draw()
            .map_err(msg)?;
        for (i, (label, ratios)) in self.methods.iter().enumerate() {
            let c = COLOURS[i % COLOURS.len()];
            let style = ShapeStyle::from(&c).stroke_width(4);
            let pts = steps(ratios, tau_max);
            let dashed = i % 2 == 1;
            let legend = move |(x, y): (i32, i32)| PathElement::new(vec![(x, y), (x + 30, y)], style);
            if dashed {
                chart.draw_series(DashedLineSeries::new(pts, 14, 8, style)).map_err(msg)?.label(label).legend(legend);
            } else {
                chart.draw_series(LineSeries::new(pts, style)).map_err(msg)?.label(label).legend(legend);
            }
        }
        chart
            .configure_series_labels()
            .position(SeriesLabelPosition::LowerRight)
            .background_style(WHITE.mix(0.9))
            .border_style(BLACK)
            .label_font((FONT_FAMILY, 22))
            .draw()
            .map_err(msg)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rho_counts_the_ratios_within_tau() {
        let r = [1.0, 1.5, 3.0, f64::INFINITY];
        assert_eq!(rho(&r, 1.0), 0.25);
        assert_eq!(rho(&r, 1.5), 0.5);
        assert_eq!(rho(&r, 2.9), 0.5);
        assert_eq!(rho(&r, 1e300), 0.75);
        assert_eq!(rho(&[], 2.0), 0.0);
    }

    #[test]
    fn steps_are_the_corners_of_rho() {
        let r = [1.0, 1.5, 1.5, 3.0, f64::INFINITY];
        let s = steps(&r, 4.0);
        assert_eq!(s, vec![(1.0, 0.2), (1.5, 0.2), (1.5, 0.6), (3.0, 0.6), (3.0, 0.8), (4.0, 0.8)]);
        // every corner agrees with ρ at a point just to its right
        for w in s.windows(2) {
            if w[0].0 < w[1].0 {
                assert_eq!(rho(&r, (w[0].0 + w[1].0) / 2.0), w[0].1);
            }
        }
    }

    #[test]
    fn short_tau_axes_get_intermediate_ticks() {
        assert_eq!(tau_ticks(2.4), vec![1.0, 1.05, 1.1, 1.2, 1.5, 2.0]);
        assert_eq!(tau_ticks(1000.0), log_ticks(1.0, 1000.0));
    }

    #[test]
    fn the_figure_draws_with_failures_and_ties() {
        let fig = ProfileFigure {
            title: "t".into(),
            x_desc: "τ".into(),
            methods: vec![("a".into(), vec![1.0, 1.0]), ("b".into(), vec![1.0, f64::INFINITY])],
        };
        assert_eq!(fig.tau_max(), 2.0);
        let svg = crate::campaign::reduction::plot::svg_text(&fig, std::path::Path::new("p.svg")).unwrap();
        assert!(svg.contains("\na\n</text>") && svg.contains("\nb\n</text>"), "legend labels missing");
    }
}
