//! Figures of a campaign (`campaign plot`): `<results>/<name>/plots/`, each figure as PNG and SVG.
//!
//! * `gamma-vs-order_<plant>` — [`GammaOrderFigure`]: our best verified γ per n_K, the paper's HIFOO
//!   values and the full-order bound;
//! * `convergence_<plant>_nK<k>` — [`ConvergenceFigure`]: the best objective so far of the best
//!   job of each (plant, order) against CPU time from its MCAP trace, a thinned sample of its
//!   local searches behind it (`_plain` appended for the plain objective's best job);
//! * `sigma_<plant>_nK<k>` — [`SigmaFigure`]: σmax of T_zw(iω) and of K(iω) for the best controller of
//!   each (plant, order), peak marked; for a problem of several plants (or another objective)
//!   one per plant, `sigma_<problem>_nK<k>_<plant>`.
//!
//! Like the report files, the figures are pure functions of the journal, the traces, the plants,
//! the reference table and the plant library's index. Drawing is `plotters` with a bundled font
//! (`render.rs`), so nothing outside Rust crates is needed.

pub mod convergence;
pub(crate) mod gamma_order;
pub(crate) mod render;
pub(crate) mod sigma;

use std::path::{Path, PathBuf};

use super::compare::full_order_rows;
use super::reduce::{best_per_problem, verify, verify_problem, BestRow, PlantMap, ProblemMap, Verdict};
use super::report::ReportError;
use crate::campaign::execution::trace::{read_run, TraceError, TraceIteration};
use crate::campaign::leaves::library_index::LibraryIndex;
use crate::campaign::leaves::reference::{RefMethod, ReferenceRow};
use crate::campaign::records::record::JobRecord;
use crate::design::ObjectiveKind;
use crate::lti::{Controller, LtiError, Plant};

pub use convergence::ConvergenceFigure;
pub use gamma_order::GammaOrderFigure;
pub use render::{log_ticks, png_bytes, svg_text, write_by_extension, write_png_and_svg, DrawError, Figure, SIZE};
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
        /// plotters' or the encoder's error.
        message: DrawError,
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
    #[error("{what}: {source}")]
    System {
        /// Which figure.
        what: String,
        /// What went wrong.
        source: LtiError,
    },
}

/// What `campaign plot` wrote, what it skipped with the reason, and what failed.
#[derive(Debug, Default)]
pub struct PlotSummary {
    /// Files written.
    pub files: Vec<PathBuf>,
    /// Figures not drawn for want of data (no trace of the best job, a damaged trace), one
    /// line each.
    pub skipped: Vec<String>,
    /// Figures that could not be drawn or written (the error), one line each. The other figures
    /// are still made; `campaign plot` exits non-zero when this is not empty.
    pub failed: Vec<String>,
}

/// Longest plant-name part of a figure's file name, in bytes (a file name must stay well below
/// the usual 255-byte limit with its prefix, order and extension).
pub const MAX_FILE_PART: usize = 64;

/// A plant name as a file-name part: letters, digits, `-`, `_`, `.` are kept and anything else
/// becomes `_`; when that changed the name, or it is longer than [`MAX_FILE_PART`], a short hash
/// is appended (`sanitise::as_key`), so different names never share figure files (`X+1`
/// and `X_1` once did) and every name fits.
pub fn file_part(name: &str) -> String {
    crate::campaign::leaves::sanitise::as_key(
        name,
        |c| c.is_ascii_alphanumeric() || "-_.".contains(c),
        '_',
        MAX_FILE_PART,
    )
}

/// [`file_part`] of `name` among the plant names `all` of one campaign: when another name's part
/// differs from this one's in letter case only ("Case" and "case"), both get the name's short
/// hash appended, so their figures do not overwrite each other on a case-insensitive file system
/// (macOS, Windows). Names without such a twin keep their part.
pub fn file_part_among(name: &str, all: &[&str]) -> String {
    let part = file_part(name);
    let twin = all.iter().any(|o| *o != name && file_part(o).eq_ignore_ascii_case(&part));
    if !twin {
        return part;
    }
    use sha2::Digest;
    let hash: String = sha2::Sha256::digest(name.as_bytes())[..4].iter().map(|b| format!("{b:02x}")).collect();
    format!("{}-{hash}", &part[..part.len().min(MAX_FILE_PART - 9)])
}

/// The file part of a problem's plant `j` among its plant names `all`: [`file_part_among`], with
/// the plant's 1-based position appended when another plant of the problem has the same name
/// (two plant files may carry one `name`; each plant's σ-plot keeps its own file).
fn problem_plant_part(j: usize, all: &[&str]) -> String {
    let part = file_part_among(all[j], all);
    if all.iter().filter(|n| **n == all[j]).count() > 1 {
        format!("{part}-{}", j + 1)
    } else {
        part
    }
}

/// The γ-vs-order figure of each plant in `best` (the full-order bound as the report has it:
/// computed, else `reference`'s, else `library`'s).
pub fn gamma_order_figures(
    best: &[BestRow],
    plants: &PlantMap,
    reference: &[ReferenceRow],
    library: &LibraryIndex,
) -> Vec<GammaOrderFigure> {
    let full = full_order_rows(best, plants, reference, library);
    let mut names: Vec<(&str, &str)> = best.iter().map(|r| (r.plant.as_str(), r.plant_fingerprint.as_str())).collect();
    names.dedup();
    names
        .into_iter()
        .map(|(p, fp)| {
            let series = |o: ObjectiveKind| -> Vec<(usize, f64)> {
                best.iter()
                    .filter(|r| r.plant == p && r.objective == o && r.gamma.is_finite())
                    .map(|r| (r.order, r.gamma))
                    .collect()
            };
            let (ours, plain) = (series(ObjectiveKind::Strong), series(ObjectiveKind::Plain));
            let mut paper: Vec<(usize, f64)> = reference
                .iter()
                .filter(|r| r.is_for(fp) && r.method == RefMethod::Hifoo)
                .map(|r| (r.order, r.gamma))
                .collect();
            paper.sort_by_key(|x| x.0);
            // A problem's γ is not one plant's ‖Tzw‖∞: no full-order H∞ bound beside it.
            let problem = best.iter().any(|r| r.plant == p && !r.plants.is_empty());
            let full_order =
                full.iter().find(|f| f.plant == p && f.gamma.is_finite() && !problem).map(|f| (f.gamma, f.source));
            GammaOrderFigure { plant: p.to_string(), ours, plain, paper, full_order, problem }
        })
        .collect()
}

/// Writes every figure of a campaign into `<campaign_dir>/plots/`. Traces are read from
/// `<campaign_dir>/traces/`; a best job without a trace (or with a trace that cannot be read) is
/// skipped with its reason in the summary, and a figure that cannot be drawn or written is in
/// its `failed` list: neither stops the other figures. Only a plots folder that cannot be made
/// is an error. `problems` are the campaign's problems of several plants or another objective
/// (`campaign::problem_map`): their rows are verified as `campaign report` verifies them, and
/// the σ-plot of their best controller is drawn on each of their plants
/// (`sigma_<problem>_nK<k>_<plant>`; the figure of a plant whose objective is not H∞ still shows
/// σmax of its closed loop, its title naming the objective).
pub fn write_plots(
    campaign_dir: &Path,
    records: &[JobRecord],
    plants: &PlantMap,
    problems: &ProblemMap,
    reference: &[ReferenceRow],
    library: &LibraryIndex,
) -> Result<PlotSummary, PlotError> {
    let dir = campaign_dir.join("plots");
    crate::fs_atomic::create_dir_all(&dir).map_err(|source| ReportError::Io { path: dir.clone(), source })?;
    let best = best_per_problem(records, plants, problems);
    let names: Vec<&str> = best.iter().map(|r| r.plant.as_str()).collect();
    let part = |name: &str| file_part_among(name, &names);
    let mut out = PlotSummary::default();
    let keep = |made: Result<Vec<PathBuf>, PlotError>, out: &mut PlotSummary| match made {
        Ok(files) => out.files.extend(files),
        Err(e) => out.failed.push(e.to_string()),
    };
    for fig in gamma_order_figures(&best, plants, reference, library) {
        keep(write_png_and_svg(&fig, &dir.join(format!("gamma-vs-order_{}", part(&fig.plant)))), &mut out);
    }
    for row in &best {
        // a plain row's figures are told apart by the objective (a strong row keeps its old name)
        let plain = row.objective == ObjectiveKind::Plain;
        let tag = format!("{}_nK{}{}", part(&row.plant), row.order, if plain { "_plain" } else { "" });
        let Some(job) = row.job_id.as_deref() else {
            out.skipped.push(format!("{} n_K = {}: no verified controller", row.plant, row.order));
            continue;
        };
        let title = format!(
            "{}, n_K = {}{} (ε = {}, seed {})",
            row.plant,
            row.order,
            if plain { ", plain" } else { "" },
            row.eps.unwrap_or(f64::NAN),
            row.seed.unwrap_or(0)
        );
        let fp = &row.plant_fingerprint;
        // The job's record that re-verified best (the one the row reports), not merely the
        // first record of the job id: a duplicate may carry another controller.
        let verdict = |r: &JobRecord| match (problems.get(fp), plants.get(fp)) {
            (Some(p), _) => Some(verify_problem(r, p)),
            (None, Some(plant)) => Some(verify(r, plant)),
            (None, None) => None,
        };
        let verified = records.iter().filter(|r| r.job_id.0 == job).filter_map(|r| match verdict(r)? {
            Verdict::Verified { gamma, .. } => Some((gamma, r)),
            Verdict::Rejected(_) => None,
        });
        let Some((_, rec)) = verified.min_by(|a, b| a.0.total_cmp(&b.0)) else {
            out.skipped.push(format!("σ-plot of {tag}: no re-verified controller of job {job}"));
            continue;
        };
        let trace = campaign_dir.join("traces").join(format!("{job}.mcap"));
        let convergence = dir.join(format!("convergence_{tag}"));
        match convergence_of(&trace, rec) {
            Ok(iterations) => {
                let fig = ConvergenceFigure { title: format!("convergence: {title}"), iterations };
                keep(write_png_and_svg(&fig, &convergence), &mut out);
            }
            Err(why) => {
                // a figure left by an earlier plot of another best job must not stay beside
                // this row (index.html links it under this row's ε and seed)
                for ext in ["png", "svg"] {
                    let _ = std::fs::remove_file(convergence.with_extension(ext));
                }
                out.skipped.push(format!("convergence of {tag}: {why}"));
            }
        }
        let Some(k) = rec.controller() else { continue };
        match problems.get(fp) {
            None => {
                let Some(plant) = plants.get(fp) else { continue };
                let made = sigma_figure(plant, k, format!("σ-plot: {title}"))
                    .and_then(|fig| write_png_and_svg(&fig, &dir.join(format!("sigma_{tag}"))));
                keep(made, &mut out);
            }
            Some(problem) => {
                let names: Vec<&str> = problem.terms.iter().map(|t| t.plant.name.as_str()).collect();
                for (j, t) in problem.terms.iter().enumerate() {
                    let what = format!(
                        "σ-plot: {title}, plant {} of {}: {} (objective {})",
                        j + 1,
                        names.len(),
                        t.plant.name,
                        t.objective.name()
                    );
                    let file = format!("sigma_{tag}_{}", problem_plant_part(j, &names));
                    let made = sigma_figure(&t.plant, k, what).and_then(|fig| write_png_and_svg(&fig, &dir.join(file)));
                    keep(made, &mut out);
                }
            }
        }
    }
    Ok(out)
}

/// The iterations of the trace `path` of the run that journaled `rec`, or why there is no
/// convergence figure: no trace, no iterations, or a trace of another run — its result message
/// names another job, or a γ other than the record's (a job rerun journals a new record, and
/// a trace of an earlier run of the job keeps its file name: drawn, it showed another run's
/// search under this record's ε and seed).
fn convergence_of(path: &Path, rec: &JobRecord) -> Result<Vec<TraceIteration>, String> {
    if !path.is_file() {
        return Err(format!("no trace {}", path.display()));
    }
    let (iterations, result) = read_run(path).map_err(|e| e.to_string())?;
    let journaled = rec.outcome().map(|o| o.gamma);
    match result {
        Some(r) if r.job_id != rec.job_id.0 => {
            return Err(format!("{} is the trace of job {}, not of this job", path.display(), r.job_id));
        }
        Some(r) if journaled.is_some_and(|g| !(g == r.gamma || (g.is_nan() && r.gamma.is_nan()))) => {
            return Err(format!(
                "{} is of another run of the job (it ended at γ = {}, the journal's record at {})",
                path.display(),
                r.gamma,
                journaled.unwrap_or(f64::NAN)
            ));
        }
        _ => {}
    }
    if iterations.is_empty() {
        return Err(format!("{}: no iterations in the trace", path.display()));
    }
    Ok(iterations)
}

/// The σ-plot of `k` on `plant`.
pub fn sigma_figure(plant: &Plant, k: &Controller, title: String) -> Result<SigmaFigure, PlotError> {
    SigmaFigure::new(plant, k, title.clone()).map_err(|e| PlotError::System { what: title, source: e })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn file_parts_are_unique_and_bounded() {
        assert_eq!(file_part("HE1"), "HE1");
        assert_eq!(file_part("X_1"), "X_1");
        let changed = file_part("X+1");
        assert!(changed.starts_with("X_1-") && changed.len() == 12, "{changed}");
        assert_ne!(file_part("X+1"), file_part("X*1"));
        let long = file_part(&"Y".repeat(300));
        assert_eq!(long.len(), MAX_FILE_PART);
        assert_ne!(long, file_part(&"Y".repeat(301)));
        assert!(file_part("ü/..").chars().all(|c| c.is_ascii_alphanumeric() || "-_.".contains(c)));
        // names differing in case only get distinct parts on a case-insensitive file system
        let all = ["Case", "case", "HE1"];
        let (a, b) = (file_part_among("Case", &all), file_part_among("case", &all));
        assert!(!a.eq_ignore_ascii_case(&b), "{a} {b}");
        assert_eq!(file_part_among("HE1", &all), "HE1");
        assert_eq!(file_part_among("Case", &["Case", "HE1"]), "Case");
        // a problem's plants of one name are told apart by their positions
        let same = ["HEX", "HE1", "HEX"];
        let parts: Vec<String> = (0..3).map(|j| problem_plant_part(j, &same)).collect();
        assert_eq!(parts, ["HEX-1", "HE1", "HEX-3"]);
    }
}
