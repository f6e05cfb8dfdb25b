//! Several `campaign run` processes on one results folder, `--shard K/N`, and reports merged
//! from several journals — through the command line with the fast fake runner
//! (examples/fake_campaign.rs, see `campaign::fake`).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::Duration;

use hinfix::campaign::summarise;
use hinfix::campaign::JobRecord;
use hinfix::campaign::FAKE_RUNNER_ENV;
use hinfix::campaign::{journals_in, read_journal};

mod common;

fn scratch(tag: &str) -> PathBuf {
    common::scratch("shared", tag)
}

/// HE1 at orders 1–2 warm-started and REA2 at order 1, 2 ε, `seeds` seeds: 6·seeds jobs.
fn campaign_file(dir: &Path, seeds: usize) -> PathBuf {
    let f = dir.join("c.toml");
    std::fs::write(
        &f,
        format!(
            "name = \"t\"\n[defaults]\neps = [1e-2, 1e-3]\nseeds = {seeds}\ncpumax = 5.0\n\n\
             [[problem]]\nplant = \"HE1\"\norders = [1, 2]\nwarm_start = true\n\n\
             [[problem]]\nplant = \"REA2\"\norders = [1]\n"
        ),
    )
    .unwrap();
    f
}

fn command(sub: &str, file: &Path, results: &Path, pause_ms: u64) -> Command {
    let mut c = Command::new(common::fake_campaign_bin());
    c.arg(sub).arg(file).arg("--results").arg(results);
    if sub == "run" {
        c.arg("--no-progress");
    }
    c.env("HINFIX_PLANTS", concat!(env!("CARGO_MANIFEST_DIR"), "/plants"));
    c.env(FAKE_RUNNER_ENV, pause_ms.to_string());
    c
}

fn ok(out: Output) -> Output {
    assert!(
        out.status.success(),
        "failed: {}\n{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// Every record of every journal of `<results>/t`, with the journal it came from.
fn all_records(results: &Path) -> Vec<(PathBuf, JobRecord)> {
    let mut out = Vec::new();
    for j in journals_in(&results.join("t")).unwrap() {
        let read = read_journal(&j).unwrap();
        assert!(read.torn.is_none(), "{}: torn tail left", j.display());
        out.extend(read.records.into_iter().map(|r| (j.clone(), r)));
    }
    out
}

/// job id → record without timing/provenance; panics if a job is journaled twice.
fn once(records: &[(PathBuf, JobRecord)]) -> BTreeMap<String, serde_json::Value> {
    let mut m = BTreeMap::new();
    for (path, r) in records {
        assert!(
            m.insert(r.job_id.0.clone(), r.comparable()).is_none(),
            "job {} journaled twice (again in {})",
            r.job_id.0,
            path.display()
        );
    }
    m
}

#[test]
fn concurrent_runs_on_one_folder_with_a_kill_then_resume_run_every_job_once() {
    let dir = scratch("concurrent");
    let file = campaign_file(&dir, 4); // 24 jobs of 10 × 30 ms
    let whole = dir.join("whole");
    ok(command("run", &file, &whole, 30).output().unwrap());
    let expected = once(&all_records(&whole));
    assert_eq!(expected.len(), 24);

    let shared = dir.join("shared");
    let mut procs: Vec<Child> = (0..3)
        .map(|_| {
            command("run", &file, &shared, 30)
                .arg("--threads")
                .arg("2")
                .stdout(Stdio::null())
                .stderr(Stdio::piped())
                .spawn()
                .unwrap()
        })
        .collect();
    std::thread::sleep(Duration::from_millis(700));
    let mut victim = procs.remove(1);
    victim.kill().unwrap(); // SIGKILL
    victim.wait().unwrap();
    for p in procs {
        ok(p.wait_with_output().unwrap());
    }
    // The resume picks up whatever the killed process held; nothing runs twice.
    let out = ok(command("run", &file, &shared, 30).output().unwrap());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("24 jobs"), "{stderr}");

    let records = all_records(&shared);
    let writers: BTreeSet<&PathBuf> = records.iter().map(|(p, _)| p).collect();
    assert!(writers.len() >= 2, "the processes should have shared the work: {writers:?}");
    // Same results as one uninterrupted process (warm starts crossed processes).
    assert_eq!(once(&records), expected);
    for (_, r) in &records {
        let p = r.provenance.as_ref().expect("every new record has provenance");
        assert_eq!(p.hinfix_version, env!("CARGO_PKG_VERSION"));
    }

    // Every trace is complete and readable; no tmp file is left behind.
    let traces = shared.join("t").join("traces");
    let names: BTreeSet<String> =
        std::fs::read_dir(&traces).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().to_string()).collect();
    assert!(names.iter().all(|n| n.ends_with(".mcap")), "leftovers: {names:?}");
    for id in expected.keys() {
        let s = summarise(&traces.join(format!("{id}.mcap"))).unwrap();
        assert_eq!(s.final_status.as_deref(), Some("converged"), "{id}");
        assert_eq!(s.iterations, 10, "{id}");
    }
    // No claim is left held; the killed process's claims were released by its death.
    let status = ok(command("status", &file, &shared, 30).output().unwrap());
    let text = String::from_utf8_lossy(&status.stdout);
    let total = text.lines().find(|l| l.starts_with("total")).unwrap().split_whitespace().collect::<Vec<_>>();
    assert_eq!(total[1..], ["24", "24", "0", "0", "0"], "{text}");
}

#[test]
fn shards_in_separate_folders_merge_into_the_whole_campaign() {
    let dir = scratch("shards");
    let file = campaign_file(&dir, 2); // 12 jobs, 4 HE1 chains of 2 and 4 REA2 jobs
    let whole = dir.join("whole");
    ok(command("run", &file, &whole, 1).output().unwrap());
    let expected = once(&all_records(&whole));

    let roots: Vec<PathBuf> = (1..=3).map(|k| dir.join(format!("r{k}"))).collect();
    let mut union = Vec::new();
    for (k, root) in roots.iter().enumerate() {
        let out = ok(command("run", &file, root, 1).arg("--shard").arg(format!("{}/3", k + 1)).output().unwrap());
        assert!(String::from_utf8_lossy(&out.stderr).contains(&format!("shard {}/3", k + 1)));
        let recs = all_records(root);
        assert!(!recs.is_empty() && recs.len() < 12, "shard {}: {} jobs", k + 1, recs.len());
        for (_, r) in &recs {
            if let Some(p) = &r.warm_from {
                assert!(recs.iter().any(|(_, q)| &q.job_id == p), "chain split across shards");
                assert!(r.warm_started, "warm start inside the shard");
            }
        }
        union.extend(recs);
    }
    // disjoint, and the union is the whole campaign with the same results
    assert_eq!(once(&union), expected);

    // status and report over the three folders: the first by --results, the others by --journal
    // (a folder, and a single journal file).
    let extra = |c: &mut Command| {
        c.arg("--journal").arg(roots[1].join("t")).arg("--journal").arg(roots[2].join("t").join("runs.jsonl"));
    };
    let mut c = command("status", &file, &roots[0], 1);
    extra(&mut c);
    let text = String::from_utf8_lossy(&ok(c.output().unwrap()).stdout).to_string();
    assert!(text.contains("3 journal(s)"), "{text}");
    assert!(
        text.lines().any(|l| l.split_whitespace().collect::<Vec<_>>() == ["total", "12", "12", "0", "0", "0"]),
        "{text}"
    );
    let mut c = command("report", &file, &roots[0], 1);
    extra(&mut c);
    ok(c.output().unwrap());
    let best = std::fs::read_to_string(roots[0].join("t").join("best.csv")).unwrap();
    assert!(best.lines().next().unwrap().contains("plant_fingerprint"), "{best}");

    // the same journal given twice is read once; a copy of it gives every job two records,
    // which is tolerated and reported
    let mut c = command("status", &file, &roots[0], 1);
    c.arg("--journal").arg(roots[0].join("t").join("runs.jsonl"));
    let text = String::from_utf8_lossy(&ok(c.output().unwrap()).stdout).to_string();
    assert!(text.contains("1 journal(s)") && !text.contains("more than one record"), "{text}");
    let copy = dir.join("copy.jsonl");
    std::fs::copy(roots[0].join("t").join("runs.jsonl"), &copy).unwrap();
    let mut c = command("status", &file, &roots[0], 1);
    c.arg("--journal").arg(&copy);
    let text = String::from_utf8_lossy(&ok(c.output().unwrap()).stdout).to_string();
    assert!(text.contains("more than one record"), "{text}");
    let mut c = command("report", &file, &roots[0], 1);
    c.arg("--journal").arg(&copy);
    let out = ok(c.output().unwrap());
    assert!(String::from_utf8_lossy(&out.stderr).contains("more than one record"));

    let out = command("run", &file, &roots[0], 1).arg("--shard").arg("4/3").output().unwrap();
    assert_eq!(out.status.code(), Some(2), "clap rejects a bad --shard");
    assert!(String::from_utf8_lossy(&out.stderr).contains("K must be between 1 and N"));
}

#[test]
fn shards_sharing_one_folder_run_each_job_once() {
    let dir = scratch("shards-shared");
    let file = campaign_file(&dir, 2);
    let shared = dir.join("r");
    let procs: Vec<Child> = (1..=3)
        .map(|k| {
            command("run", &file, &shared, 5)
                .arg("--shard")
                .arg(format!("{k}/3"))
                .stdout(Stdio::null())
                .stderr(Stdio::piped())
                .spawn()
                .unwrap()
        })
        .collect();
    for p in procs {
        ok(p.wait_with_output().unwrap());
    }
    assert_eq!(once(&all_records(&shared)).len(), 12);
}
