//! Files of older builds stay readable (tests/fixtures/compat/README.md): a journal line and the
//! messages of a trace written at commit 2980e60, before ‖Tzw‖∞ / ‖K‖∞ were named `gamma` /
//! `k_hinf` everywhere (the trace's iteration messages said `hinf_cl` / `hinf_k`), and a journal
//! of commit 8ee3691, the last schema-1 build, with one job of each status.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use hinfix::campaign::{iter_message, summarise, ITER_TOPIC, RESULT_TOPIC};
use hinfix::campaign::{read_journal, JobRecord, JobStatus, JournalWriter, SCHEMA_VERSION};
use hinfix::design::{f64_from_json, DesignIterRecord, Phase, SearchStop};
use hinfix::lti::Controller;
use hinfix::optim::{Iteration, SolverKind};
use serde_json::Value;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/compat").join(name)
}

/// Keys of a designed job's outcome in a journal line (a failed job's line of schema 2 has only
/// its `status`).
const OUTCOME_KEYS: &[&str] = &[
    "controller",
    "gamma",
    "k_hinf",
    "alpha_cl",
    "alpha_k",
    "objective",
    "controller_norm_active",
    "certificate",
    "iterations",
    "evaluations",
    "phases",
    "design_cpu_s",
    "search",
];

/// `got` equals `want`, key by key (the message names the first key that differs).
fn assert_same_object(got: &Value, want: &Value, what: &str) {
    let (g, w) = (got.as_object().unwrap(), want.as_object().unwrap());
    for (k, v) in w {
        assert_eq!(g.get(k), Some(v), "{what}: key {k}");
    }
    for k in g.keys() {
        assert!(w.contains_key(k), "{what}: extra key {k}");
    }
}

/// `record` written again, as JSON.
fn rewritten(record: &JobRecord) -> Value {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("runs.jsonl");
    let (mut w, _) = JournalWriter::open(&out).unwrap();
    w.append(record).unwrap();
    drop(w);
    serde_json::from_str(std::fs::read_to_string(&out).unwrap().trim_end()).unwrap()
}

/// What a schema-1 line becomes when written again: the same object with `schema_version` 2,
/// the per-phase counters under their current names, and for a failed job without the outcome
/// keys (schema 1 wrote NaN, null and zeros there).
fn as_schema_2(old: &Value) -> Value {
    let mut v = old.clone();
    let o = v.as_object_mut().unwrap();
    o.insert("schema_version".into(), Value::from(SCHEMA_VERSION));
    if old["status"]["kind"] == "failed" {
        for k in OUTCOME_KEYS {
            o.remove(*k);
        }
    }
    // the per-phase counters are written with the outcome's key names (`iterations`,
    // `evaluations`, `design_cpu_s`); older lines said `iters`, `evals`, `cpu_s`
    if let Some(Value::Array(phases)) = o.get_mut("phases") {
        for p in phases.iter_mut().filter_map(Value::as_object_mut) {
            for (old, new) in [("iters", "iterations"), ("evals", "evaluations"), ("cpu_s", "design_cpu_s")] {
                if let Some(x) = p.remove(old) {
                    p.insert(new.into(), x);
                }
            }
        }
    }
    v
}

/// The old journal line reads, its figures and controller are there, and writing the record
/// again gives the same JSON but for the schema version (a designed job's line did not change).
#[test]
fn journal_line_of_2980e60_reads_and_rewrites_identically() {
    let path = fixture("journal-2980e60.jsonl");
    let text = std::fs::read_to_string(&path).unwrap();
    let want: Value = serde_json::from_str(&text).unwrap();
    let read = read_journal(&path).unwrap();
    assert!(read.torn.is_none());
    assert_eq!(read.records.len(), 1);
    let r = &read.records[0];
    let o = r.outcome().unwrap();
    assert_eq!(o.gamma, want["gamma"].as_f64().unwrap());
    assert_eq!(o.k_hinf, want["k_hinf"].as_f64().unwrap());
    assert!(o.gamma > 0.12 && o.gamma < 0.13, "HE1 n_K = 1: γ ≈ 0.1245, got {}", o.gamma);
    let k = r.controller().unwrap();
    assert_eq!((k.order(), k.outputs(), k.inputs()), (1, 2, 1));
    assert_eq!(want["schema_version"], 1);
    assert_same_object(&rewritten(r), &as_schema_2(&want), "2980e60");
}

/// The journal of commit 8ee3691 (schema 1; tests/fixtures/compat/README.md): the smoke
/// campaign and one job of each further status, a failed one included. Every line reads to the
/// values it holds, and writes back as schema 2.
#[test]
fn journal_of_8ee3691_reads_every_status_to_the_same_values() {
    let path = fixture("journal-8ee3691.jsonl");
    let text = std::fs::read_to_string(&path).unwrap();
    let read = read_journal(&path).unwrap();
    assert!(read.torn.is_none());
    assert_eq!(read.records.len(), 28);
    let mut kinds = BTreeMap::new();
    for (line, r) in text.lines().zip(&read.records) {
        let want: Value = serde_json::from_str(line).unwrap();
        assert_eq!(want["schema_version"], 1);
        let kind = want["status"]["kind"].as_str().unwrap();
        *kinds.entry(kind.to_string()).or_insert(0) += 1;
        assert_eq!(r.status().kind(), kind);
        assert_eq!(r.job_id.0, want["job_id"].as_str().unwrap());
        match r.outcome() {
            None => {
                assert_eq!(kind, "failed");
                assert!(r.failed() && r.controller().is_none());
                let JobStatus::Failed { error, .. } = r.status() else { panic!("{line}") };
                assert_eq!(error, want["status"]["error"].as_str().unwrap());
            }
            Some(o) => {
                for (got, key) in
                    [(o.gamma, "gamma"), (o.k_hinf, "k_hinf"), (o.alpha_cl, "alpha_cl"), (o.objective, "objective")]
                {
                    assert_eq!(got.to_bits(), f64_from_json(&want[key]).to_bits(), "{key}: {line}");
                }
                assert_eq!(o.iterations as u64, want["iterations"].as_u64().unwrap());
                assert_eq!(o.evaluations as u64, want["evaluations"].as_u64().unwrap());
                assert_eq!(o.design_cpu_s, want["design_cpu_s"].as_f64().unwrap());
                assert_eq!(o.certificate.is_some(), !want["certificate"].is_null());
                assert_eq!(o.controller, Controller::from_json_value(&want["controller"]).unwrap());
                assert_eq!(serde_json::to_value(&o.search).unwrap(), want["search"]);
            }
        }
        let again = rewritten(r);
        assert_same_object(&again, &as_schema_2(&want), line);
        if kind == "failed" {
            assert!(OUTCOME_KEYS.iter().all(|k| again.get(*k).is_none()), "{again}");
        }
        // the schema-2 line reads back to the same record
        let back: JobRecord = serde_json::from_value(again.clone()).unwrap();
        assert_eq!(back.status(), r.status());
        assert_same_object(&rewritten(&back), &again, line);
    }
    let got: Vec<(&str, i32)> = kinds.iter().map(|(k, n)| (k.as_str(), *n)).collect();
    assert_eq!(got, [("budget_exhausted", 2), ("converged", 18), ("failed", 1), ("not_stabilised", 1), ("stopped", 6)]);
}

/// `campaign report` on the 8ee3691 journal writes the tables that build wrote (best.csv and
/// compare.csv, stored next to the journal; γ to 2e-10, see [`assert_same_table`]): reading the
/// old format changes no result. The
/// campaigns are the ones that build ran, with its search options pinned (later builds changed
/// the defaults, and so the job ids).
#[test]
fn report_on_the_journal_of_8ee3691_gives_its_tables() {
    let journal = fixture("journal-8ee3691.jsonl");
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    for (campaign, name) in [(fixture("smoke-8ee3691.toml"), "smoke"), (fixture("kinds.toml"), "kinds")] {
        let results = tempfile::tempdir().unwrap();
        let out = std::process::Command::new(env!("CARGO_BIN_EXE_campaign"))
            .arg("report")
            .arg(&campaign)
            .arg("--results")
            .arg(results.path())
            .arg("--journal")
            .arg(&journal)
            .env("HINFIX_PLANTS", root.join("plants"))
            .output()
            .unwrap();
        assert!(out.status.success(), "{name}: {}", String::from_utf8_lossy(&out.stderr));
        for table in ["best", "compare"] {
            let got = std::fs::read_to_string(results.path().join(name).join(format!("{table}.csv"))).unwrap();
            let want = std::fs::read_to_string(fixture(&format!("{table}-{name}-8ee3691.csv"))).unwrap();
            assert_same_table(&got, &want, &format!("{name}: {table}.csv"));
        }
    }
}

/// The tables are equal cell by cell, numbers to 2e-10 relative (twice the norm's tolerance): `report` re-verifies each
/// controller, recomputing γ with the current H∞ norm, and a change of that norm's rounding
/// (e.g. a different level-set path) may move the last digits; nothing else may differ. Columns
/// are matched by their header: a column added since (best.csv's `k_hinf`, `near_best`, …) is
/// allowed, none of the old ones may go or change.
fn assert_same_table(got: &str, want: &str, what: &str) {
    let (g, w): (Vec<&str>, Vec<&str>) = (got.lines().collect(), want.lines().collect());
    assert_eq!(g.len(), w.len(), "{what}: rows\n{got}\n{want}");
    let (gh, wh): (Vec<&str>, Vec<&str>) = (g[0].split(',').collect(), w[0].split(',').collect());
    let cols: Vec<usize> = wh
        .iter()
        .map(|c| gh.iter().position(|h| h == c).unwrap_or_else(|| panic!("{what}: column {c} is gone from {}", g[0])))
        .collect();
    for (gl, wl) in g.iter().zip(&w).skip(1) {
        let (gc, wc): (Vec<&str>, Vec<&str>) = (gl.split(',').collect(), wl.split(',').collect());
        assert_eq!((gc.len(), wc.len()), (gh.len(), wh.len()), "{what}: {gl} / {wl}");
        for (&i, b) in cols.iter().zip(&wc) {
            let a = gc[i];
            if a == *b {
                continue;
            }
            let (x, y): (f64, f64) = (a.parse().unwrap_or(f64::NAN), b.parse().unwrap_or(f64::NAN));
            // no number: an empty cell of older builds, "nan" since non-finite numbers are
            // written one way
            if x.is_nan() && y.is_nan() && [a, *b].iter().all(|c| c.is_empty() || *c == "nan") {
                continue;
            }
            // within the norm's own tolerance (1e-10 relative): another refinement path may
            // stop at another attained value below the peak
            assert!((x - y).abs() <= 2e-10 * x.abs().max(y.abs()), "{what}: {a} vs {b} in\n{gl}\n{wl}");
        }
    }
}

/// A designed job's line from before the search summary existed (06018b1) reads, its search
/// marked as not recorded.
#[test]
fn a_line_without_search_summary_reads_as_not_recorded() {
    let text = std::fs::read_to_string(fixture("journal-2980e60.jsonl")).unwrap();
    let mut v: Value = serde_json::from_str(&text).unwrap();
    v.as_object_mut().unwrap().remove("search");
    let r: JobRecord = serde_json::from_value(v).unwrap();
    let o = r.outcome().unwrap();
    assert_eq!(o.search.stop, SearchStop::NotRecorded);
    assert!(o.gamma > 0.12 && o.gamma < 0.13);
}

/// Writes `messages` (topic, JSON bytes) into a new MCAP file, the way the trace writer does.
fn write_mcap(path: &Path, messages: &[(&str, &[u8])]) {
    let file = std::io::BufWriter::new(std::fs::File::create(path).unwrap());
    let mut w = mcap::WriteOptions::new().compression(None).profile("").create(file).unwrap();
    let meta = BTreeMap::new();
    let s_iter = w.add_schema("hinfix.Iteration", "jsonschema", b"{}").unwrap();
    let s_res = w.add_schema("hinfix.JobRecord", "jsonschema", b"{}").unwrap();
    let c_iter = w.add_channel(s_iter, ITER_TOPIC, "json", &meta).unwrap();
    let c_res = w.add_channel(s_res, RESULT_TOPIC, "json", &meta).unwrap();
    for (seq, (topic, data)) in messages.iter().enumerate() {
        let channel_id = if *topic == ITER_TOPIC { c_iter } else { c_res };
        let t = seq as u64;
        let header = mcap::records::MessageHeader { channel_id, sequence: seq as u32, log_time: t, publish_time: t };
        w.write_to_known_channel(&header, data).unwrap();
    }
    w.finish().unwrap();
}

/// `campaign trace` on a trace whose iteration messages carry the old keys still finds the best
/// ‖Tzw‖∞, and new messages carry the new keys only.
#[test]
fn trace_messages_of_2980e60_summarise() {
    let text = std::fs::read_to_string(fixture("trace-2980e60.jsonl")).unwrap();
    let mut messages = Vec::new();
    let mut best_old = f64::NAN;
    let mut final_gamma = f64::NAN;
    for line in text.lines() {
        let (kind, json) = line.split_once(' ').unwrap();
        let v: Value = serde_json::from_str(json).unwrap();
        match kind {
            "iter" => {
                assert!(v.get("gamma").is_none() && v.get("hinf_cl").is_some(), "fixture has the old keys");
                let h = f64_from_json(&v["hinf_cl"]);
                if h.is_finite() && (best_old.is_nan() || h < best_old) {
                    best_old = h;
                }
                messages.push((ITER_TOPIC, json.as_bytes()));
            }
            "result" => {
                final_gamma = v["gamma"].as_f64().unwrap();
                messages.push((RESULT_TOPIC, json.as_bytes()));
            }
            other => panic!("unknown topic tag {other}"),
        }
    }
    assert!(best_old.is_finite() && best_old < 0.13);

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("old.mcap");
    write_mcap(&path, &messages);
    let s = summarise(&path).unwrap();
    assert_eq!(s.messages, messages.len() - 1);
    assert_eq!(s.best_gamma, best_old);
    assert_eq!(s.final_gamma, Some(final_gamma));
    assert_eq!(s.final_status.as_deref(), Some("converged"));

    let it =
        Iteration { solver: SolverKind::Bfgs, start: 0, iter: 1, f: 2.0, dnorm: 0.1, step: 1.0, evals: 1, cpu_s: 0.0 };
    let rec = DesignIterRecord {
        phase: Phase::Optimisation,
        it,
        gamma: 2.0,
        k_hinf: 3.0,
        alpha_cl: -1.0,
        alpha_k: -1.0,
        improved: true,
    };
    let m = iter_message(&rec);
    assert_eq!((m["gamma"].as_f64(), m["k_hinf"].as_f64()), (Some(2.0), Some(3.0)));
    assert!(m.get("hinf_cl").is_none() && m.get("hinf_k").is_none());
}
