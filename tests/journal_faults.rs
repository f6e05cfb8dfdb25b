//! Faults of the results folder during `campaign run`. Traces that cannot be written (a full
//! disk) fail the run (exit 1, saying so) though the results are journaled. The journal (or the whole results folder) removed or replaced while
//! `campaign run` appends to it. The run must notice before its next append, stop with an error
//! (non-zero exit) naming what happened, and lose no finished record: everything the journal
//! held and the record that found it gone are in a rescued journal of the folder, which a resume
//! reads.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::{Child, Stdio};
use std::time::{Duration, Instant};

use hinfix::campaign::{journals_in, read_journal, FAKE_RUNNER_ENV};

mod common;

const PLANTS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/plants");

/// Fake jobs of 10 × 30 ms each, two at a time: a record arrives about every 150 ms.
fn spawn_run(dir: &Path) -> Child {
    let f = dir.join("c.toml");
    std::fs::write(&f, "name = \"t\"\n[defaults]\nseeds = 30\n[[problem]]\nplant = \"HE1\"\norders = [1]\n").unwrap();
    std::process::Command::new(common::fake_campaign_bin())
        .args(["run", f.to_str().unwrap(), "--results", dir.join("r").to_str().unwrap(), "--no-progress"])
        .args(["--threads", "2"])
        .env("HINFIX_PLANTS", PLANTS)
        .env(FAKE_RUNNER_ENV, "30")
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap()
}

fn ids_in(path: &Path) -> BTreeSet<String> {
    read_journal(path).unwrap().records.into_iter().map(|r| r.job_id.0).collect()
}

/// Waits until the journal holds at least `n` records and returns their ids.
fn wait_records(journal: &Path, n: usize) -> BTreeSet<String> {
    let t = Instant::now();
    loop {
        let ids = ids_in(journal);
        if ids.len() >= n {
            return ids;
        }
        assert!(t.elapsed() < Duration::from_secs(60), "the run journaled only {} records", ids.len());
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Every record id in the journals of `folder` (the folder as it is after the run).
fn remaining(folder: &Path) -> BTreeSet<String> {
    journals_in(folder).unwrap().iter().flat_map(|j| ids_in(j)).collect()
}

fn scratch(tag: &str) -> PathBuf {
    common::scratch("jfault", tag)
}

/// Runs the campaign, applies `fault` to its folder after 3 records, and checks the run's end.
fn fault_during_run(tag: &str, what: &str, fault: impl FnOnce(&Path)) {
    let dir = scratch(tag);
    let folder = dir.join("r").join("t");
    let journal = folder.join("runs.jsonl");
    let child = spawn_run(&dir);
    let before = wait_records(&journal, 3);
    fault(&folder);
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{tag}: the run exited 0 after its journal was {what}: {stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(stderr.contains(&format!("runs.jsonl: the journal was {what}")), "{tag}: {stderr}");
    // No internal names (the cancel reason was printed as `CallbackError`)
    assert!(!stderr.contains("CallbackError"), "{stderr}");
    assert!(stderr.contains("runs.rescued-") && stderr.contains("which a resume reads"), "{tag}: {stderr}");
    let after = remaining(&folder);
    assert!(before.is_subset(&after), "{tag}: finished records lost: {:?}", before.difference(&after));
    assert!(after.len() > before.len(), "{tag}: the record that found the journal gone was lost");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn journal_deleted_during_a_run_stops_it_and_loses_nothing() {
    fault_during_run("deleted", "deleted", |folder| std::fs::remove_file(folder.join("runs.jsonl")).unwrap());
}

#[test]
fn journal_replaced_during_a_run_stops_it_and_loses_nothing() {
    fault_during_run("replaced", "replaced by another file", |folder| {
        let other = folder.join("other");
        std::fs::write(&other, b"").unwrap();
        std::fs::rename(&other, folder.join("runs.jsonl")).unwrap();
    });
}

#[test]
fn results_folder_deleted_during_a_run_stops_it_and_loses_nothing() {
    fault_during_run("folder", "deleted", |folder| {
        // a trace file being created meanwhile can make one attempt fail with "not empty"
        for _ in 0..20 {
            match std::fs::remove_dir_all(folder) {
                Ok(()) => return,
                Err(e) if e.kind() == std::io::ErrorKind::NotFound => return,
                Err(_) => std::thread::sleep(Duration::from_millis(1)),
            }
        }
        panic!("could not remove {}", folder.display());
    });
}

#[test]
fn traces_that_cannot_be_written_fail_the_run_and_say_so() {
    // A full disk while writing traces exited 0 and the traces were lost. A
    // file where the traces folder should be fails every trace the same way.
    let dir = scratch("traces");
    let folder = dir.join("r").join("t");
    std::fs::create_dir_all(&folder).unwrap();
    std::fs::write(folder.join("traces"), b"not a folder").unwrap();
    let f = dir.join("c.toml");
    std::fs::write(&f, "name = \"t\"\n[defaults]\nseeds = 2\n[[problem]]\nplant = \"HE1\"\norders = [1]\n").unwrap();
    let out = std::process::Command::new(common::fake_campaign_bin())
        .args(["run", f.to_str().unwrap(), "--results", dir.join("r").to_str().unwrap(), "--no-progress"])
        .env("HINFIX_PLANTS", PLANTS)
        .env(FAKE_RUNNER_ENV, "1")
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("warning(s) above") && stderr.contains("traces"), "{stderr}");
    assert_eq!(ids_in(&folder.join("runs.jsonl")).len(), 2, "the results are journaled");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A journal line that carries a job's id but not its ε (hand-edited or damaged) is not counted
/// under the ε it claims: `report` warns, naming the job and the field, and leaves it out (the
/// row once showed an ε the campaign never ran).
#[test]
fn a_record_that_disagrees_with_its_job_is_named_and_not_counted() {
    let dir = scratch("disagree");
    let file = dir.join("c.toml");
    std::fs::write(
        &file,
        "name = \"d\"\n[defaults]\neps = [1e-3]\nseeds = 2\nmaxevals = 300\nnrand = 1\n[[problem]]\nplant = \"HE1\"\norders = [1]\n",
    )
    .unwrap();
    let results = dir.join("r");
    let cmd = |args: &[&str]| {
        std::process::Command::new(env!("CARGO_BIN_EXE_campaign"))
            .args(args)
            .arg(&file)
            .arg("--results")
            .arg(&results)
            .env("HINFIX_PLANTS", PLANTS)
            .output()
            .unwrap()
    };
    assert!(cmd(&["run", "--no-progress", "--trace", "off"]).status.success());
    let journal = results.join("d/runs.jsonl");
    let text = std::fs::read_to_string(&journal).unwrap();
    let (first, rest) = text.split_once('\n').unwrap();
    let mut v: serde_json::Value = serde_json::from_str(first).unwrap();
    v["eps"] = serde_json::json!(0.5);
    std::fs::write(&journal, format!("{v}\n{rest}")).unwrap();
    let out = cmd(&["report"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    let id = v["job_id"].as_str().unwrap();
    assert!(
        err.contains(&format!("a record of job {}: eps 0.5 in the record, 0.001 in the campaign", &id[..8])),
        "{err}"
    );
    let best = std::fs::read_to_string(results.join("d/best.csv")).unwrap();
    assert!(!best.contains(",0.5,"), "{best}");
    // one job counted (the other's record is left out): `runs` is 1
    let head: Vec<&str> = best.lines().next().unwrap().split(',').collect();
    let row: Vec<&str> = best.lines().nth(1).unwrap().split(',').collect();
    let runs = head.iter().position(|h| *h == "runs").unwrap();
    assert_eq!(row[runs], "1", "{best}");
}

/// A journal saved by an editor that put a UTF-8 byte-order mark at its start reads as without
/// it (its first line was "corrupt: expected value at line 1 column 1").
#[test]
fn a_byte_order_mark_at_the_start_of_a_journal_is_read_past() {
    let fixture = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/fixtures/report/runs.jsonl");
    let text = std::fs::read(fixture).unwrap();
    let plain = hinfix::campaign::parse_journal(&text, Path::new("runs.jsonl")).unwrap();
    let with_bom = [b"\xEF\xBB\xBF".as_slice(), &text].concat();
    let read = hinfix::campaign::parse_journal(&with_bom, Path::new("runs.jsonl")).unwrap();
    assert!(!plain.records.is_empty());
    assert_eq!(read.records.len(), plain.records.len());
    assert_eq!(read.records[0].job_id, plain.records[0].job_id);
    assert!(read.torn.is_none());
}

/// A journal's name on a folder (or anything but a regular file) is an error naming it: it was
/// skipped without a word, and `run` re-ran the jobs it should have held.
#[test]
fn a_journal_name_on_a_folder_is_named() {
    let dir = std::env::temp_dir().join(format!("hinfix-journal-folder-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(dir.join("runs.2.jsonl")).unwrap();
    std::fs::write(dir.join("runs.jsonl"), b"").unwrap();
    let e = journals_in(&dir).unwrap_err().to_string();
    assert!(e.contains("runs.2.jsonl") && e.contains("is not a regular file"), "{e}");
    std::fs::remove_dir_all(dir.join("runs.2.jsonl")).unwrap();
    assert_eq!(journals_in(&dir).unwrap(), vec![dir.join("runs.jsonl")]);
    let _ = std::fs::remove_dir_all(&dir);
}
