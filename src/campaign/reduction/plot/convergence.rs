//! Convergence of one job from its MCAP trace, drawn for a reader: the best objective so far
//! against CPU seconds (a thick step curve), behind it a thinned sample of the local searches (at
//! most [`MAX_RUNS_DRAWN`], those that set a new best first, each of at most
//! [`MAX_POINTS_PER_RUN`] points: a fast job makes thousands, which drew a grey wall and a 9.3 MB
//! SVG), a triangle where a restart set a new best, and a dashed line at the first entry into
//! each later phase (BFGS, gradient sampling) with its label placed clear of the others.
//!
//! The stabilisation phase minimises max(α(A_cl), ε·α(A_K)), which ends below zero, while the
//! later phases minimise max(‖T_zw‖∞, ε‖K‖∞) > 0: the first local search's stabilisation is drawn
//! in a lower panel of its own (the upper one logarithmic when the objective spans more than a
//! decade), when there is something to show: a search whose first start already stabilises (a
//! warm start from a stabilising controller, as every continued job of a campaign has) has no
//! lower panel. A trace whose CPU clock never advanced (the test runner's) is drawn against the
//! iteration count.

use plotters::coord::ranged1d::{AsRangedCoord, ValueFormatter};
use plotters::coord::Shift;
use plotters::prelude::*;

use super::render::{
    colour, draw_legend, msg, padded_range, spans_decades, styled_mesh, tick, DrawError, Figure, FONT_FAMILY,
};
use crate::campaign::execution::trace::TraceIteration;

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

    /// The first entry into each phase (the first of [`Self::phase_markers`] with each label):
    /// the boundaries the figure draws and labels.
    pub fn first_phase_markers(&self) -> Vec<Marker> {
        let mut seen: Vec<String> = Vec::new();
        self.phase_markers()
            .into_iter()
            .filter(|m| {
                let new = !seen.contains(&m.label);
                if new {
                    seen.push(m.label.clone());
                }
                new
            })
            .collect()
    }

    /// The local searches of the panel's phases (`stab`: the stabilisation phase, else the
    /// others), one per (phase, start) run of finite points, with whether each set a new best.
    pub fn runs(&self, stab: bool) -> Vec<Run> {
        let mut runs: Vec<Run> = Vec::new();
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
                runs.push(Run { points: Vec::new(), restart, improved: false });
            }
            runs.last_mut().expect("pushed above").points.push((self.x_of(i), it.f));
            prev = Some(i);
        }
        let mut best = f64::INFINITY;
        for r in &mut runs {
            let low = r.points.iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
            if low < best * (1.0 - 1e-9) || (best.is_infinite() && low.is_finite()) {
                r.improved = true;
                best = low;
            }
        }
        runs
    }

    /// Whether the figure has the stabilisation panel: the first local search's stabilisation
    /// starts at a point that does not stabilise (objective ≥ 0). From a stabilising start the
    /// phase is a few messages below zero in a millisecond, an empty-looking panel.
    pub fn shows_stabilisation(&self) -> bool {
        self.panel_runs(true).first().and_then(|r| r.points.first()).is_some_and(|p| p.1 >= 0.0)
    }

    /// x range of a panel: the whole run for the objective; for the stabilisation panel only
    /// its own iterations (it usually takes a small fraction of the run and would be a sliver).
    fn x_range(&self, stab: bool) -> (f64, f64) {
        let hi = if stab {
            // the first local search's stabilisation: the later ones are slivers spread over
            // the whole run
            self.panel_runs(true).iter().flat_map(|r| r.points.iter().map(|p| p.0)).fold(0f64, f64::max)
        } else {
            (0..self.iterations.len()).map(|i| self.x_of(i)).filter(|x| x.is_finite()).fold(0f64, f64::max)
        };
        (0.0, if hi > 0.0 { hi * 1.02 } else { 1.0 })
    }

    /// The runs a panel draws from: every local search of the objective's phases, or the first
    /// local search's stabilisation.
    fn panel_runs(&self, stab: bool) -> Vec<Run> {
        let mut runs = self.runs(stab);
        if stab {
            runs.truncate(1);
        }
        runs
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
            (true, true) => "CPU time (s), stabilisation phase of the first local search",
            (false, _) => "iteration (no CPU time in the trace)",
        };
        let y_desc = if stab { "max(α(A_cl), ε·α(A_K))" } else { "objective max(‖T_zw‖∞, ε‖K‖∞)" };
        styled_mesh(chart.configure_mesh().x_desc(x_desc).y_desc(y_desc), 15).draw().map_err(msg)?;
        let (ylo, yhi) = {
            let r = chart.plotting_area().get_y_range();
            (r.start, r.end)
        };
        // Phase boundaries: a multi-start search changes phase at every start (thousands of
        // dashed lines made a grey wall), so only the first entry into each phase is drawn, and
        // its label goes to the first of three rows where it clears the labels before it.
        let px_per_x = f64::from(area.dim_in_pixel().0.saturating_sub(110).max(1)) / (x1 - x0).max(f64::MIN_POSITIVE);
        let mut rows: [Option<f64>; 3] = [None; 3];
        let row_height = (yhi - ylo) * 0.07;
        let markers = if stab { Vec::new() } else { self.first_phase_markers() };
        for m in markers.into_iter().filter(|m| m.x <= x1 && m.label != STABILISATION) {
            let style = ShapeStyle::from(&colour::MARK).stroke_width(2);
            chart.draw_series(DashedLineSeries::new(vec![(m.x, ylo), (m.x, yhi)], 8, 5, style)).map_err(msg)?;
            let width = (m.label.chars().count() as f64 + 2.0) * 8.5 / px_per_x;
            let Some(row) = (0..rows.len()).find(|&r| rows[r].is_none_or(|end| m.x > end)) else { continue };
            rows[row] = Some(m.x + width);
            let y = if self_is_log(ylo, yhi) {
                // rows spaced evenly on a log axis
                yhi * (ylo / yhi).powf(0.07 * row as f64)
            } else {
                yhi - row_height * row as f64
            };
            chart
                .draw_series(std::iter::once(Text::new(
                    format!(" {}", m.label),
                    (m.x, y),
                    (FONT_FAMILY, 15).into_font().color(&colour::MARK),
                )))
                .map_err(msg)?;
        }
        if stab {
            chart.draw_series(LineSeries::new(vec![(x0, 0.0), (x1, 0.0)], &BLACK.mix(0.4))).map_err(msg)?;
        }
        // The local searches, thinned: those that set a new best and an even sample of the
        // others, at most MAX_RUNS_DRAWN, each with at most MAX_POINTS_PER_RUN points, drawn
        // faintly behind the best-so-far curve.
        let runs = self.panel_runs(stab);
        let line_colour = if stab { colour::PAPER } else { colour::OURS };
        let faint = line_colour.mix(0.35).stroke_width(1);
        let shown = thin_runs(&runs);
        for (n, &i) in shown.iter().enumerate() {
            let s = chart.draw_series(LineSeries::new(decimate(&runs[i].points), faint)).map_err(msg)?;
            if n == 0 {
                let label =
                    if stab { "stabilisation objective (first local search)" } else { "local searches (thinned)" };
                s.label(label).legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], faint));
            }
        }
        if !stab {
            let best = best_so_far(&runs);
            if let Some(&(_, last)) = best.last() {
                let style = colour::OURS.stroke_width(3);
                chart
                    .draw_series(LineSeries::new(best.clone(), style))
                    .map_err(msg)?
                    .label(format!("best objective so far (final {})", tick(last)))
                    .legend(move |(x, y)| PathElement::new(vec![(x, y), (x + 24, y)], style));
            }
            // a triangle where a restart (a new local search) set a new best
            let improving: Vec<(f64, f64)> =
                runs.iter().filter(|r| r.restart && r.improved).filter_map(|r| r.best_point()).collect();
            if !improving.is_empty() {
                chart
                    .draw_series(improving.iter().map(|&p| TriangleMarker::new(p, 8, colour::MARK.filled())))
                    .map_err(msg)?
                    .label("new best from a restart")
                    .legend(|(x, y)| TriangleMarker::new((x + 12, y), 7, colour::MARK.filled()));
            }
        }
        draw_legend(&mut chart, SeriesLabelPosition::UpperRight)
    }

    fn panel_auto<DB: DrawingBackend>(
        &self,
        area: &DrawingArea<DB, Shift>,
        stab: bool,
        caption: Option<&str>,
    ) -> Result<(), DrawError> {
        let ys: Vec<f64> = self.panel_runs(stab).iter().flat_map(|r| r.points.iter().map(|p| p.1)).collect();
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

/// Largest number of local searches drawn in a panel ([`thin_runs`]).
pub const MAX_RUNS_DRAWN: usize = 40;
/// Largest number of points drawn of one local search ([`decimate`]).
pub const MAX_POINTS_PER_RUN: usize = 150;

/// One local search of one phase as the trace has it: its (x, f) points.
#[derive(Debug, Clone, PartialEq)]
pub struct Run {
    /// (x, objective) in trace order.
    pub points: Vec<(f64, f64)>,
    /// Whether it follows another local search of the same phase (a restart).
    pub restart: bool,
    /// Whether it lowered the best objective of the panel so far.
    pub improved: bool,
}

impl Run {
    /// Its lowest point.
    fn best_point(&self) -> Option<(f64, f64)> {
        self.points.iter().copied().min_by(|a, b| a.1.total_cmp(&b.1))
    }
}

/// Which runs to draw: every run that set a new best, then an even sample of the rest, at most
/// [`MAX_RUNS_DRAWN`] in all (the improving ones first when they alone are more), in run order.
pub fn thin_runs(runs: &[Run]) -> Vec<usize> {
    let improving: Vec<usize> = (0..runs.len()).filter(|&i| runs[i].improved).collect();
    let mut keep: Vec<usize> = if improving.len() >= MAX_RUNS_DRAWN {
        let step = improving.len() as f64 / MAX_RUNS_DRAWN as f64;
        (0..MAX_RUNS_DRAWN).map(|k| improving[(k as f64 * step) as usize]).collect()
    } else {
        let others: Vec<usize> = (0..runs.len()).filter(|&i| !runs[i].improved).collect();
        let room = MAX_RUNS_DRAWN - improving.len();
        let step = (others.len() as f64 / room.max(1) as f64).max(1.0);
        let sample = (0..room).map(|k| (k as f64 * step) as usize).take_while(|&j| j < others.len()).map(|j| others[j]);
        improving.iter().copied().chain(sample).collect()
    };
    keep.sort_unstable();
    keep.dedup();
    keep
}

/// At most [`MAX_POINTS_PER_RUN`] of `points`, evenly spaced, the first and the last kept.
pub fn decimate(points: &[(f64, f64)]) -> Vec<(f64, f64)> {
    if points.len() <= MAX_POINTS_PER_RUN {
        return points.to_vec();
    }
    let step = (points.len() - 1) as f64 / (MAX_POINTS_PER_RUN - 1) as f64;
    (0..MAX_POINTS_PER_RUN).map(|k| points[((k as f64 * step).round() as usize).min(points.len() - 1)]).collect()
}

/// The best objective so far as a step curve over the runs' points in time order: a point where
/// it drops (a horizontal then a vertical segment) and one at the end.
pub fn best_so_far(runs: &[Run]) -> Vec<(f64, f64)> {
    let mut pts: Vec<(f64, f64)> = runs.iter().flat_map(|r| r.points.iter().copied()).collect();
    pts.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut out: Vec<(f64, f64)> = Vec::new();
    let mut best = f64::INFINITY;
    for &(x, f) in &pts {
        if f < best {
            if out.last().is_some() {
                out.push((x, best));
            }
            best = f;
            out.push((x, f));
        }
    }
    if let (Some(&(x, _)), true) = (pts.last(), best.is_finite()) {
        out.push((x, best));
    }
    out
}

/// Whether a y range belongs to a log axis (the panel draws the objective on one when it spans
/// decades).
fn self_is_log(ylo: f64, yhi: f64) -> bool {
    spans_decades(ylo, yhi)
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
        // Beside the objective, the stabilisation panel only when it has something to show.
        let stab_panel = if has_opt { self.shows_stabilisation() } else { has_stab };
        match (stab_panel, has_opt) {
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
