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
/// `best.csv`). A job journaled several times gives its first record.
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
        1 => Ok(found.swap_remove(0)),
        n => Err(LookupError::Ambiguous(format!("{n} jobs of {} start with {id}: give more of the id", dir.display()))),
    }
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
}
