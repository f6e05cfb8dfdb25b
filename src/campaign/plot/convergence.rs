//! Convergence of one job from its MCAP trace: the objective against CPU seconds, phase
//! boundaries (stabilisation → BFGS → gradient sampling) as dashed vertical lines and restarts
//! (a new starting point) as dotted ones with a triangle on the curve.
//!
//! The stabilisation phase minimises max(α(A_cl), ε·α(A_K)), which ends below zero, while the
//! later phases minimise max(‖T_zw‖∞, ε‖K‖∞) > 0: the two are drawn in two panels sharing the
//! time axis (the upper one logarithmic when the objective spans more than a decade). A trace
//! whose CPU clock never advanced (the test runner's) is drawn against the iteration count.

use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::Shift;
use plotters::prelude::*;

use super::render::{colour, draw_legend, msg, padded_range, spans_decades, tick, DrawError, Figure, FONT_FAMILY};
use crate::campaign::trace::TraceIteration;

/// Name of the stabilisation phase in traces.
const STABILISATION: &str = "stabilisation";

/// Data of one convergence figure.
#[derive(Debug, Clone, PartialEq)]
pub struct ConvergenceFigure {
    /// Title (plant, order, job).
    pub title: String,
    /// The trace's iterations.
    pub iterations: Vec<TraceIteration>,
}

/// One vertical marker: x, what it marks.
#[derive(Debug, Clone, PartialEq)]
pub struct Marker {
    /// Position on the x axis.
    pub x: f64,
    /// Label (new phase name, or `start k`).
    pub label: String,
}

impl ConvergenceFigure {
    /// Whether the x axis is CPU time (else the iteration count).
    pub fn x_is_cpu(&self) -> bool {
        self.iterations.iter().any(|it| it.elapsed_cpu_s.is_finite() && it.elapsed_cpu_s > 0.0)
    }

    fn x_of(&self, i: usize) -> f64 {
        if self.x_is_cpu() {
            self.iterations[i].elapsed_cpu_s
        } else {
            i as f64
        }
    }

    /// (x, f) of the finite points of the phases matching `stab`.
    fn points(&self, stab: bool) -> Vec<(f64, f64, &str)> {
        (0..self.iterations.len())
            .filter(|&i| (self.iterations[i].phase == STABILISATION) == stab && self.iterations[i].f.is_finite())
            .map(|i| (self.x_of(i), self.iterations[i].f, self.iterations[i].phase.as_str()))
            .collect()
    }

    /// Phase boundaries: where the phase changes, drawn at the last message before the change.
    /// That message ends a run, which every trace level keeps; the new run's first message may
    /// not be in a sparse trace (its first kept one can come much later).
    pub fn phase_markers(&self) -> Vec<Marker> {
        let it = &self.iterations;
        (1..it.len())
            .filter(|&i| it[i].phase != it[i - 1].phase)
            .map(|i| Marker { x: self.x_of(i - 1), label: phase_label(&it[i].phase).to_string() })
            .collect()
    }

    /// Restarts: where the start index changes within a phase, drawn like
    /// [`Self::phase_markers`] at the last message before the change.
    pub fn restart_markers(&self) -> Vec<Marker> {
        let it = &self.iterations;
        (1..it.len())
            .filter(|&i| it[i].phase == it[i - 1].phase && it[i].start != it[i - 1].start)
            .map(|i| Marker { x: self.x_of(i - 1), label: format!("start {}", it[i].start + 1) })
            .collect()
    }

    /// x range of a panel: the whole run for the objective; for the stabilisation panel only
    /// its own iterations (it usually takes a small fraction of the run and would be a sliver).
    fn x_range(&self, stab: bool) -> (f64, f64) {
        let n = self.iterations.len();
        let xs = (0..n).filter(|&i| !stab || self.iterations[i].phase == STABILISATION).map(|i| self.x_of(i));
        let hi = xs.filter(|x| x.is_finite()).fold(0f64, f64::max);
        (0.0, if hi > 0.0 { hi * 1.02 } else { 1.0 })
    }

    fn panel<DB: DrawingBackend, Y>(
        &self,
        area: &DrawingArea<DB, Shift>,
        stab: bool,
        caption: Option<&str>,
        y: Y,
    ) -> Result<(), DrawError>
    where
        Y: AsRangedCoord<Value = f64>,
        Y::CoordDescType: ValueFormatter<f64>,
    {
        let (x0, x1) = self.x_range(stab);
        let mut b = ChartBuilder::on(area);
        b.margin(14).x_label_area_size(50).y_label_area_size(90);
        if let Some(c) = caption {
            b.caption(c, (FONT_FAMILY, 24));
        }
        let mut chart = b.build_cartesian_2d(x0..x1, y).map_err(msg)?;
        let x_desc = match (self.x_is_cpu(), stab) {
            (true, false) => "CPU time (s)",
            (true, true) => "CPU time (s), stabilisation phase only",
            (false, _) => "iteration (no CPU time in the trace)",
        };
        let y_desc = if stab { "max(α(A_cl), ε·α(A_K))" } else { "objective max(‖T_zw‖∞, ε‖K‖∞)" };
        chart
            .configure_mesh()
            .x_desc(x_desc)
            .y_desc(y_desc)
            .y_label_formatter(&|v| tick(*v))
            .x_label_formatter(&|v| tick(*v))
            .max_light_lines(2)
            .label_style((FONT_FAMILY, 15))
            .axis_desc_style((FONT_FAMILY, 17))
            .draw()
            .map_err(msg)?;
        let (ylo, yhi) = {
            let r = chart.plotting_area().get_y_range();
            (r.start, r.end)
        };
        // A multi-start search changes phase at every start: label a boundary only where its
        // text does not run into the previous label (the dashed line is always drawn).
        let min_gap = 0.12 * (x1 - x0);
        let mut last_label: Option<f64> = None;
        for m in self.phase_markers().into_iter().filter(|m| m.x <= x1) {
            let style = ShapeStyle::from(&colour::MARK).stroke_width(2);
            chart.draw_series(DashedLineSeries::new(vec![(m.x, ylo), (m.x, yhi)], 8, 5, style)).map_err(msg)?;
            if last_label.is_some_and(|x| m.x - x < min_gap) {
                continue;
            }
            last_label = Some(m.x);
            chart
                .draw_series(std::iter::once(Text::new(
                    format!(" {}", m.label),
                    (m.x, yhi),
                    (FONT_FAMILY, 15).into_font().color(&colour::MARK),
                )))
                .map_err(msg)?;
        }
        for m in self.restart_markers().into_iter().filter(|m| m.x <= x1) {
            chart
                .draw_series(DashedLineSeries::new(
                    vec![(m.x, ylo), (m.x, yhi)],
                    2,
                    4,
                    ShapeStyle::from(&colour::MARK.mix(0.6)),
                ))
                .map_err(msg)?;
        }
        if stab {
            chart.draw_series(LineSeries::new(vec![(x0, 0.0), (x1, 0.0)], &BLACK.mix(0.4))).map_err(msg)?;
        }
        // One line per (phase, start) run, so that restarts are not joined to their predecessor.
        let pts = self.points(stab);
        let mut runs: Vec<(bool, Vec<(f64, f64)>)> = Vec::new();
        let mut prev: Option<usize> = None;
        for i in 0..self.iterations.len() {
            let it = &self.iterations[i];
            if (it.phase == STABILISATION) != stab || !it.f.is_finite() {
                continue;
            }
            let key_changed =
                prev.is_none_or(|p| self.iterations[p].phase != it.phase || self.iterations[p].start != it.start);
            if key_changed {
                let restart = prev.is_some_and(|p| self.iterations[p].phase == it.phase);
                runs.push((restart, Vec::new()));
            }
            runs.last_mut().expect("pushed above").1.push((self.x_of(i), it.f));
            prev = Some(i);
        }
        let line_colour = if stab { colour::PAPER } else { colour::OURS };
        for (n, (restart, run)) in runs.iter().enumerate() {
            let s = chart.draw_series(LineSeries::new(run.clone(), line_colour.stroke_width(2))).map_err(msg)?;
            if n == 0 {
                let label = if stab { "stabilisation objective" } else { "objective (BFGS, gradient sampling)" };
                s.label(label)
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], line_colour.stroke_width(2)));
            }
            // restart marker at the first point of a new start within the same phase
            if *restart {
                let p = run[0];
                chart.draw_series(std::iter::once(TriangleMarker::new(p, 8, colour::MARK.filled()))).map_err(msg)?;
            }
        }
        if !stab {
            if let Some(best) = pts.iter().map(|p| p.1).fold(None, |b: Option<f64>, v| Some(b.map_or(v, |b| b.min(v))))
            {
                let style = ShapeStyle::from(&colour::BOUND).stroke_width(1);
                chart
                    .draw_series(DashedLineSeries::new(vec![(x0, best), (x1, best)], 6, 6, style))
                    .map_err(msg)?
                    .label(format!("best objective {}", tick(best)))
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], style));
            }
            chart
                .draw_series(std::iter::empty::<TriangleMarker<(f64, f64), i32>>())
                .map_err(msg)?
                .label("restart (new starting point)")
                .legend(|(x, y)| TriangleMarker::new((x + 12, y), 7, colour::MARK.filled()));
        }
        draw_legend(&mut chart, SeriesLabelPosition::UpperRight)
    }

    fn panel_auto<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        stab: bool,
        caption: Option<&str>,
    ) -> Result<(), DrawError> {
        let ys: Vec<f64> = self.points(stab).iter().map(|p| p.1).collect();
        let (lo, hi) = ys.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), &v| (l.min(v), h.max(v)));
        let (lo, hi) = if lo <= hi { (lo, hi) } else { (0.0, 1.0) };
        if !stab && spans_decades(lo, hi) {
            let (a, b) = padded_range(lo, hi, true);
            self.panel(area, stab, caption, (a..b).log_scale())
        } else {
            let (lo, hi) = if stab { (lo.min(0.0), hi.max(0.0)) } else { (lo, hi) };
            let (a, b) = padded_range(lo, hi, false);
            self.panel(area, stab, caption, a..b)
        }
    }
}

/// A phase's name for a reader.
fn phase_label(phase: &str) -> &str {
    match phase {
        "stabilisation" => "stabilisation",
        "optimisation" => "BFGS",
        "gradient_sampling" => "gradient sampling",
        other => other,
    }
}

impl Figure for ConvergenceFigure {
    fn draw<DB: DrawingBackend>(&self, root: &DrawingArea<DB, Shift>) -> Result<(), DrawError> {
        let has_stab = self.iterations.iter().any(|it| it.phase == STABILISATION && it.f.is_finite());
        let has_opt = self.iterations.iter().any(|it| it.phase != STABILISATION && it.f.is_finite());
        match (has_stab, has_opt) {
            (true, true) => {
                let (upper, lower) = root.split_vertically((root.dim_in_pixel().1 as f64 * 0.68) as u32);
                self.panel_auto(&upper, false, Some(&self.title))?;
                self.panel_auto(&lower, true, None)
            }
            (true, false) => self.panel_auto(root, true, Some(&self.title)),
            _ => self.panel_auto(root, false, Some(&self.title)),
        }
    }
}
