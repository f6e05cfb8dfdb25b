//! γ against the controller order for one plant: our best re-verified γ per n_K (strong
//! objective; the plain objective's as a second series when the campaign ran it), the paper's
//! HIFOO values, and the full-order bound as a horizontal line labelled with its value; a log
//! axis when the values span more than a decade, with tick labels over its whole range
//! ([`log_ticks`]).

use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::Shift;
use plotters::prelude::*;

use super::render::{
    colour, draw_legend, log_ticks, msg, padded_range, spans_decades, styled_mesh, tick, DrawError, Figure, FONT_FAMILY,
};
use crate::campaign::reduction::compare::FullOrderSource;

/// Data of one γ-vs-order figure.
#[derive(Debug, Clone, PartialEq)]
pub struct GammaOrderFigure {
    /// Plant name.
    pub plant: String,
    /// (n_K, our best verified γ), finite values only: the strong objective's.
    pub ours: Vec<(usize, f64)>,
    /// (n_K, our best verified γ of the plain objective, K may be unstable); empty unless the
    /// campaign ran it.
    pub plain: Vec<(usize, f64)>,
    /// (n_K, the paper's HIFOO γ).
    pub paper: Vec<(usize, f64)>,
    /// The full-order bound γ_opt (None if unknown), and where it comes from.
    pub full_order: Option<(f64, FullOrderSource)>,
    /// Whether γ is a problem's value — the largest w_j·g_j of its plants without a bound
    /// (several plants, or another objective, weight or bound: plants.csv) — rather than one
    /// plant's ‖T_zw‖∞: the y axis says so.
    pub problem: bool,
}

impl GammaOrderFigure {
    /// Every γ shown (ours, paper, bound).
    fn values(&self) -> impl Iterator<Item = f64> + '_ {
        self.ours.iter().chain(&self.plain).chain(&self.paper).map(|p| p.1).chain(self.full_order.map(|f| f.0))
    }

    /// Whether the y axis is logarithmic.
    pub fn log_axis(&self) -> bool {
        let (lo, hi) = self.values().fold((f64::INFINITY, 0f64), |(l, h), v| (l.min(v), h.max(v)));
        spans_decades(lo, hi)
    }

    fn draw_with<DB: DrawingBackend, Y>(&self, root: &DrawingArea<DB, Shift>, y: Y) -> Result<(), DrawError>
    where
        Y: AsRangedCoord<Value = f64>,
        Y::CoordDescType: ValueFormatter<f64>,
    {
        let orders = self.ours.iter().chain(&self.plain).chain(&self.paper).map(|p| p.0);
        let (kmin, kmax) = orders.fold((usize::MAX, 0), |(l, h), k| (l.min(k), h.max(k)));
        let (kmin, kmax) = if kmin > kmax { (0, 1) } else { (kmin, kmax) };
        let x = (kmin as f64 - 0.5)..(kmax as f64 + 0.5);
        let mut chart = ChartBuilder::on(root)
            .caption(format!("{}: best γ per controller order", self.plant), (FONT_FAMILY, 26))
            .margin(16)
            .x_label_area_size(54)
            .y_label_area_size(90)
            .build_cartesian_2d(x, y)
            .map_err(msg)?;
        let mut mesh = chart.configure_mesh();
        styled_mesh(
            mesh.x_desc("controller order n_K").y_desc(if self.problem {
                "γ = max w_j·g_j over the plants without a bound"
            } else {
                "γ = ‖T_zw‖∞"
            }),
            16,
        )
        .x_labels(kmax - kmin + 3)
        .x_label_formatter(&|v| {
            if (v - v.round()).abs() < 1e-9 && *v >= 0.0 {
                format!("{}", v.round())
            } else {
                String::new()
            }
        })
        .draw()
        .map_err(msg)?;
        if let Some((g, source)) = self.full_order {
            let label = match source {
                FullOrderSource::Paper => format!("full-order bound {} (paper's value)", tick(g)),
                FullOrderSource::LibraryIndex => format!("full-order bound {} (library index)", tick(g)),
                FullOrderSource::Computed | FullOrderSource::Unavailable => {
                    format!("full-order bound γ_opt = {}", tick(g))
                }
            };
            let style = ShapeStyle::from(&colour::BOUND).stroke_width(2);
            chart
                .draw_series(DashedLineSeries::new(vec![(kmin as f64 - 0.5, g), (kmax as f64 + 0.5, g)], 10, 6, style))
                .map_err(msg)?
                .label(label)
                .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], style));
            // the value on the line itself, at its left end, just above it
            chart
                .draw_series(std::iter::once(
                    Text::new(
                        format!("γ_opt = {}", tick(g)),
                        (kmin as f64 - 0.45, g),
                        (FONT_FAMILY, 16).into_font().color(&colour::BOUND).pos(
                            plotters::style::text_anchor::Pos::new(
                                plotters::style::text_anchor::HPos::Left,
                                plotters::style::text_anchor::VPos::Bottom,
                            ),
                        ),
                    )
                    .into_dyn(),
                ))
                .map_err(msg)?;
        }
        let line = |pts: &[(usize, f64)]| -> Vec<(f64, f64)> { pts.iter().map(|&(k, g)| (k as f64, g)).collect() };
        let paper = line(&self.paper);
        if !paper.is_empty() {
            let c = colour::PAPER;
            chart.draw_series(LineSeries::new(paper.clone(), c.stroke_width(2))).map_err(msg)?;
            chart
                .draw_series(paper.iter().map(|&p| TriangleMarker::new(p, 9, c.filled())))
                .map_err(msg)?
                .label("paper (HIFOO, 2008)")
                .legend(move |(x, y)| {
                    EmptyElement::at((x + 12, y))
                        + PathElement::new(vec![(-12, 0), (12, 0)], c.stroke_width(2))
                        + TriangleMarker::new((0, 0), 7, c.filled())
                });
        }
        let plain = line(&self.plain);
        if !plain.is_empty() {
            let c = colour::CONTROLLER;
            chart.draw_series(LineSeries::new(plain.clone(), c.stroke_width(2))).map_err(msg)?;
            chart.draw_series(plain.iter().map(|&p| Rectangle::new([p, p], c.filled()))).map_err(msg)?;
            chart
                .draw_series(plain.iter().map(|&p| Cross::new(p, 7, c.stroke_width(3))))
                .map_err(msg)?
                .label("ours, plain objective (K may be unstable)")
                .legend(move |(x, y)| {
                    EmptyElement::at((x + 12, y))
                        + PathElement::new(vec![(-12, 0), (12, 0)], c.stroke_width(2))
                        + Cross::new((0, 0), 6, c.stroke_width(3))
                });
        }
        let ours = line(&self.ours);
        if !ours.is_empty() {
            let c = colour::OURS;
            chart.draw_series(LineSeries::new(ours.clone(), c.stroke_width(2))).map_err(msg)?;
            chart
                .draw_series(ours.iter().map(|&p| Circle::new(p, 6, c.filled())))
                .map_err(msg)?
                .label(if self.plain.is_empty() { "ours (best verified)" } else { "ours, strong (K stable)" })
                .legend(move |(x, y)| {
                    EmptyElement::at((x + 12, y))
                        + PathElement::new(vec![(-12, 0), (12, 0)], c.stroke_width(2))
                        + Circle::new((0, 0), 5, c.filled())
                });
        }
        draw_legend(&mut chart, SeriesLabelPosition::UpperRight)
    }
}

impl Figure for GammaOrderFigure {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), DrawError> {
        let (lo, hi) = self.values().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), v| (l.min(v), h.max(v)));
        let (lo, hi) = if lo <= hi { (lo, hi) } else { (0.0, 1.0) };
        if self.log_axis() {
            let (a, b) = padded_range(lo, hi, true);
            let ticks = log_ticks(a, b);
            if ticks.len() >= 2 {
                self.draw_with(root, (a..b).log_scale().with_key_points(ticks))
            } else {
                self.draw_with(root, (a..b).log_scale())
            }
        } else {
            let (a, b) = padded_range(lo, hi, false);
            self.draw_with(root, a..b)
        }
    }
}
