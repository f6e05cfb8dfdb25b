//! Finding one job's record in a results folder (`<results>/<name>/`): by job id (or a unique
//! prefix of one), or as the best job of a (plant, order[, objective]) entry of its `best.csv`.
//! `campaign export --results DIR --plant P --order K` and `--job ID` use it.

use std::path::{Path, PathBuf};

use super::reduce::BestRow;
use crate::campaign::records::journal::{journals_in, read_journal, JournalError};
use crate::campaign::records::record::JobRecord;

/// Which job of a results folder.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Entry {
    /// A job id, or a prefix of one that names a single job.
    Job(String),
    /// The best job of a `best.csv` row: plant label, n_K and the objective (`strong` or
    /// `plain`); without one, the strong row when the campaign ran both (the design's default
    /// objective), else the only row.
    Best {
        /// Plant as `best.csv` names it.
        plant: String,
        /// Controller order.
        order: usize,
        /// `strong` or `plain`; `None` when the row is unique without it.
        objective: Option<String>,
    },
}

/// Why no record was found.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum LookupError {
    /// A journal could not be read.
    #[error(transparent)]
    Journal(#[from] JournalError),
    /// `best.csv` could not be read.
    #[error("{}: {message} (run `campaign report` on the campaign first)", path.display())]
    Best {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        message: String,
    },
    /// No row or record matches.
    #[error("{0}")]
    NotFound(String),
    /// Several match.
    #[error("{0}")]
    Ambiguous(String),
}

/// The record of `entry` in the results folder `dir` (the folder holding `runs*.jsonl` and
/// `best.csv`). A job journaled several times (a job run twice, journals merged) gives the
/// record `campaign report` counts (`one_record` below).
pub fn find_record(dir: &Path, entry: &Entry) -> Result<JobRecord, LookupError> {
    let id = match entry {
        Entry::Job(id) => id.clone(),
        Entry::Best { plant, order, objective } => best_job_id(dir, plant, *order, objective.as_deref())?,
    };
    let mut found: Vec<JobRecord> = Vec::new();
    for j in journals_in(dir)? {
        found.extend(read_journal(&j)?.records.into_iter().filter(|r| r.job_id.0.starts_with(&id)));
    }
    let mut ids: Vec<&str> = found.iter().map(|r| r.job_id.0.as_str()).collect();
    ids.sort_unstable();
    ids.dedup();
    match ids.len() {
        0 => Err(LookupError::NotFound(format!("no job {id} in the journals of {}", dir.display()))),
        1 => one_record(found, dir),
        n => Err(LookupError::Ambiguous(format!("{n} jobs of {} start with {id}: give more of the id", dir.display()))),
    }
}

/// The one record of a job among its `records` (one job id, at least one record): the only one,
/// or where they hold different controllers, the one `campaign report` counts — the smallest γ
/// re-verified on the plant (`reduce::verify`, the first of equals), the plant taken from the
/// library by the record's name and checked by its fingerprint. The first record was taken once:
/// a hand-made or damaged duplicate put first was exported although the report, and best.csv,
/// had counted the other, verified one. Where the plant is not in the library (a plant file, a
/// problem of several plants), different controllers are an error that says so.
fn one_record(mut records: Vec<JobRecord>, dir: &Path) -> Result<JobRecord, LookupError> {
    let controllers: Vec<_> = records.iter().filter_map(JobRecord::controller).collect();
    if records.len() == 1 || controllers.windows(2).all(|w| w[0] == w[1]) {
        let first_with = records.iter().position(|r| r.controller().is_some()).unwrap_or(0);
        return Ok(records.swap_remove(first_with));
    }
    let r0 = &records[0];
    let plant = crate::lti::resolve_plant(&r0.plant)
        .ok()
        .and_then(|path| crate::lti::Plant::load(path).ok())
        .filter(|p| p.fingerprint() == r0.plant_fingerprint);
    let Some(plant) = plant else {
        return Err(LookupError::Ambiguous(format!(
            "job {} has {} records with different controllers in the journals of {}, and its plant {} is not in the \
             plant library to verify them: keep the one you want in the journal",
            r0.job_id.0,
            records.len(),
            dir.display(),
            r0.plant
        )));
    };
    let gammas: Vec<f64> =
        records.iter().map(|r| super::reduce::verify(r, &plant).gamma().unwrap_or(f64::INFINITY)).collect();
    let best = (0..records.len()).fold(0, |b, i| if gammas[i] < gammas[b] { i } else { b });
    Ok(records.swap_remove(best))
}

fn best_job_id(dir: &Path, plant: &str, order: usize, objective: Option<&str>) -> Result<String, LookupError> {
    let path = dir.join("best.csv");
    let err = |message: String| LookupError::Best { path: path.clone(), message };
    let mut reader = csv::Reader::from_path(&path).map_err(|e| err(e.to_string()))?;
    let rows: Vec<BestRow> = reader.deserialize().collect::<Result<_, _>>().map_err(|e| err(e.to_string()))?;
    let mut matching: Vec<&BestRow> = rows
        .iter()
        .filter(|r| r.plant == plant && r.order == order)
        .filter(|r| objective.is_none_or(|o| r.objective.name() == o))
        .collect();
    if objective.is_none() && matching.len() > 1 {
        matching.retain(|r| r.objective == crate::design::ObjectiveKind::Strong);
    }
    let what = format!("plant {plant}, n_K = {order}{}", objective.map(|o| format!(", {o}")).unwrap_or_default());
    match matching.as_slice() {
        [] => {
            let known: Vec<String> = rows.iter().map(|r| format!("{} n_K={}", r.plant, r.order)).collect();
            Err(LookupError::NotFound(format!("{}: no row for {what} (rows: {})", path.display(), known.join(", "))))
        }
        [row] => row
            .job_id
            .clone()
            .ok_or_else(|| LookupError::NotFound(format!("{}: {what} has no verified job", path.display()))),
        _ => Err(LookupError::Ambiguous(format!("{}: {what} has several rows", path.display()))),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::design::ObjectiveKind;

    /// A (plant, order) with rows of both objectives: the strong one unless --objective says
    /// plain; an order without a row names the rows there are.
    #[test]
    fn an_entry_picks_its_row_by_objective() {
        let dir = tempfile::tempdir().unwrap();
        let row = |objective, id: &str| BestRow {
            job_id: Some(id.into()),
            objective,
            ..BestRow::new("P".into(), "fp".into(), 2)
        };
        let mut w = csv::Writer::from_path(dir.path().join("best.csv")).unwrap();
        w.serialize(row(ObjectiveKind::Strong, "s1")).unwrap();
        w.serialize(row(ObjectiveKind::Plain, "p1")).unwrap();
        w.flush().unwrap();
        assert_eq!(best_job_id(dir.path(), "P", 2, None).unwrap(), "s1");
        assert_eq!(best_job_id(dir.path(), "P", 2, Some("plain")).unwrap(), "p1");
        let e = best_job_id(dir.path(), "P", 3, None).unwrap_err().to_string();
        assert!(e.contains("no row for plant P, n_K = 3") && e.contains("P n_K=2"), "{e}");
        assert!(matches!(find_record(dir.path(), &Entry::Job("nope".into())), Err(LookupError::NotFound(_))));
    }

    /// A job journaled twice with different controllers gives the record the report counts (the
    /// verified one), not the first: here an unstable copy (AK = 5) comes first.
    #[test]
    fn a_job_recorded_twice_gives_its_verified_record() {
        let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/report/runs.jsonl");
        let line = std::fs::read_to_string(fixture).unwrap().lines().next().unwrap().to_string();
        let mut bad: serde_json::Value = serde_json::from_str(&line).unwrap();
        assert_eq!(bad["plant"], "HE1");
        let nk = bad["controller"]["AK"].as_array().unwrap().len();
        bad["controller"]["AK"] = serde_json::json!((0..nk)
            .map(|i| (0..nk).map(|j| if i == j { 5.0 } else { 0.0 }).collect::<Vec<_>>())
            .collect::<Vec<_>>());
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("runs.jsonl"), format!("{bad}\n{line}\n")).unwrap();
        let id = bad["job_id"].as_str().unwrap().to_string();
        let got = find_record(dir.path(), &Entry::Job(id[..8].to_string())).unwrap();
        let want: JobRecord = serde_json::from_str(&line).unwrap();
        assert_eq!(got.controller(), want.controller());
        // the same controller twice: simply that record
        std::fs::write(dir.path().join("runs.jsonl"), format!("{line}\n{line}\n")).unwrap();
        assert_eq!(find_record(dir.path(), &Entry::Job(id)).unwrap().controller(), want.controller());
    }
}
