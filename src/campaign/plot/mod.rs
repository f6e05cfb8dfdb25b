//! Figures of a campaign (`campaign plot`): `<results>/<name>/plots/`, each figure as PNG and SVG.
//!
//! * `gamma-vs-order_<plant>` — [`GammaOrderFigure`]: our best verified γ per n_K, the paper's HIFOO
//!   values and the full-order bound;
//! * `convergence_<plant>_nK<k>` — [`ConvergenceFigure`]: the objective of the best job of each
//!   (plant, order) against CPU time from its MCAP trace, phases and restarts marked;
//! * `sigma_<plant>_nK<k>` — [`SigmaFigure`]: σmax of T_zw(iω) and of K(iω) for the best controller of
//!   each (plant, order), peak marked.
//!
//! Like the report files, the figures are pure functions of the journal, the traces, the plants
//! and the reference table. Drawing is `plotters` with a bundled font (`render.rs`), so nothing
//! outside Rust crates is needed.

pub(crate) mod convergence;
pub(crate) mod gamma_order;
pub(crate) mod render;
pub(crate) mod sigma;

use std::path::{Path, PathBuf};

use super::compare::full_order_rows;
use super::record::JobRecord;
use super::reduce::{best_per_order, BestRow, PlantMap};
use super::reference::{RefMethod, ReferenceRow};
use super::report::ReportError;
use super::trace::{read_iterations, TraceError};
use crate::lti::{Controller, Plant};

pub use convergence::ConvergenceFigure;
pub use gamma_order::GammaOrderFigure;
pub use render::{png_bytes, svg_text, write_by_extension, write_png_and_svg, Figure, SIZE};
pub use sigma::SigmaFigure;

/// Errors making a figure, naming the file.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PlotError {
    /// Drawing or encoding failed.
    #[error("{}: drawing failed: {message}", path.display())]
    Draw {
        /// The figure's file.
        path: PathBuf,
        /// plotters' or the encoder's message.
        message: String,
    },
    /// The requested file type is not one we write.
    #[error("{}: the figure's file name must end in .png or .svg", path.display())]
    Format {
        /// The file.
        path: PathBuf,
    },
    /// Writing the file failed.
    #[error(transparent)]
    Write(#[from] ReportError),
    /// A trace could not be read.
    #[error(transparent)]
    Trace(#[from] TraceError),
    /// A controller could not be evaluated on its plant.
    #[error("{what}: {message}")]
    System {
        /// Which figure.
        what: String,
        /// What went wrong.
        message: String,
    },
}

/// What `campaign plot` wrote, and what it skipped with the reason.
#[derive(Debug, Default)]
pub struct PlotSummary {
    /// Files written.
    pub files: Vec<PathBuf>,
    /// Figures not drawn (e.g. no trace of the best job), one line each.
    pub skipped: Vec<String>,
}

/// A plant name as a file-name part: letters, digits, `-`, `_`, `.`; anything else becomes `_`.
pub fn file_part(name: &str) -> String {
    name.chars().map(|c| if c.is_ascii_alphanumeric() || "-_.".contains(c) { c } else { '_' }).collect()
}

/// The γ-vs-order figure of each plant in `best`.
pub fn gamma_order_figures(best: &[BestRow], plants: &PlantMap, reference: &[ReferenceRow]) -> Vec<GammaOrderFigure> {
    let full = full_order_rows(best, plants, reference);
    let mut names: Vec<&str> = best.iter().map(|r| r.plant.as_str()).collect();
    names.dedup();
    names
        .into_iter()
        .map(|p| {
            let ours =
                best.iter().filter(|r| r.plant == p && r.gamma.is_finite()).map(|r| (r.order, r.gamma)).collect();
            let mut paper: Vec<(usize, f64)> = reference
                .iter()
                .filter(|r| r.plant == p && r.method == RefMethod::Hifoo)
                .map(|r| (r.order, r.gamma))
                .collect();
            paper.sort_by_key(|x| x.0);
            let full_order = full.iter().find(|f| f.plant == p && f.gamma.is_finite()).map(|f| (f.gamma, f.from_paper));
            GammaOrderFigure { plant: p.to_string(), ours, paper, full_order }
        })
        .collect()
}

/// Writes every figure of a campaign into `<campaign_dir>/plots/`. Traces are read from
/// `<campaign_dir>/traces/`; a best job without a trace (or a failed trace read) is skipped with
/// its reason in the summary, not an error.
pub fn write_plots(
    campaign_dir: &Path,
    records: &[JobRecord],
    plants: &PlantMap,
    reference: &[ReferenceRow],
) -> Result<PlotSummary, PlotError> {
    let dir = campaign_dir.join("plots");
    std::fs::create_dir_all(&dir).map_err(|source| ReportError::Io { path: dir.clone(), source })?;
    let best = best_per_order(records, plants);
    let mut out = PlotSummary::default();
    for fig in gamma_order_figures(&best, plants, reference) {
        out.files.extend(write_png_and_svg(&fig, &dir.join(format!("gamma-vs-order_{}", file_part(&fig.plant))))?);
    }
    for row in &best {
        let tag = format!("{}_nK{}", file_part(&row.plant), row.order);
        let Some(job) = row.job_id.as_deref() else {
            out.skipped.push(format!("{} n_K = {}: no verified controller", row.plant, row.order));
            continue;
        };
        let title = format!(
            "{}, n_K = {} (ε = {}, seed {})",
            row.plant,
            row.order,
            row.eps.unwrap_or(f64::NAN),
            row.seed.unwrap_or(0)
        );
        let trace = campaign_dir.join("traces").join(format!("{job}.mcap"));
        if trace.is_file() {
            match read_iterations(&trace) {
                Ok(iterations) if !iterations.is_empty() => {
                    let fig = ConvergenceFigure { title: format!("convergence: {title}"), iterations };
                    out.files.extend(write_png_and_svg(&fig, &dir.join(format!("convergence_{tag}")))?);
                }
                Ok(_) => out.skipped.push(format!("{}: no iterations in the trace", trace.display())),
                Err(e) => out.skipped.push(format!("convergence of {tag}: {e}")),
            }
        } else {
            out.skipped.push(format!("convergence of {tag}: no trace {}", trace.display()));
        }
        let (Some(plant), Some(rec)) = (plants.get(&row.plant_fingerprint), records.iter().find(|r| r.job_id.0 == job))
        else {
            continue;
        };
        let Some(k) = rec.controller() else { continue };
        let fig = sigma_figure(plant, k, format!("σ-plot: {title}"))?;
        out.files.extend(write_png_and_svg(&fig, &dir.join(format!("sigma_{tag}")))?);
    }
    Ok(out)
}

/// The σ-plot of `k` on `plant`.
pub fn sigma_figure(plant: &Plant, k: &Controller, title: String) -> Result<SigmaFigure, PlotError> {
    SigmaFigure::new(plant, k, title.clone()).map_err(|e| PlotError::System { what: title, message: e.to_string() })
}
