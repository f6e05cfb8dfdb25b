//! Files of older builds stay readable (tests/fixtures/compat/README.md): a journal line and the
//! messages of a trace written at commit 2980e60, before ‖Tzw‖∞ / ‖K‖∞ were named `gamma` /
//! `k_hinf` everywhere (the trace's iteration messages said `hinf_cl` / `hinf_k`).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use hinfix::campaign::{iter_message, summarise, ITER_TOPIC, RESULT_TOPIC};
use hinfix::campaign::{read_journal, JournalWriter};
use hinfix::design::{f64_from_json, DesignIterRecord, Phase};
use hinfix::lti::Controller;
use serde_json::Value;

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/compat").join(name)
}

/// The old journal line reads, its figures and controller are there, and writing the record
/// again gives the same JSON (the journal format did not change with the typed controller).
#[test]
fn journal_line_of_2980e60_reads_and_rewrites_identically() {
    let path = fixture("journal-2980e60.jsonl");
    let text = std::fs::read_to_string(&path).unwrap();
    let want: Value = serde_json::from_str(&text).unwrap();
    let read = read_journal(&path).unwrap();
    assert!(read.torn.is_none());
    assert_eq!(read.records.len(), 1);
    let r = &read.records[0];
    assert_eq!(r.gamma, want["gamma"].as_f64().unwrap());
    assert_eq!(r.k_hinf, want["k_hinf"].as_f64().unwrap());
    assert!(r.gamma > 0.12 && r.gamma < 0.13, "HE1 n_K = 1: γ ≈ 0.1245, got {}", r.gamma);
    let k = Controller::from_json_value(r.controller.as_ref().unwrap()).unwrap();
    assert_eq!((k.order(), k.outputs(), k.inputs()), (1, 2, 1));

    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("runs.jsonl");
    let (mut w, _) = JournalWriter::open(&out).unwrap();
    w.append(r).unwrap();
    drop(w);
    let got: Value = serde_json::from_str(std::fs::read_to_string(&out).unwrap().trim_end()).unwrap();
    assert_eq!(got, want);
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

    let rec = DesignIterRecord {
        phase: Phase::Optimisation,
        start: 0,
        iter: 1,
        f: 2.0,
        gamma: 2.0,
        k_hinf: 3.0,
        alpha_cl: -1.0,
        alpha_k: -1.0,
        dnorm: 0.1,
        step: 1.0,
        evals: 1,
        cpu_s: 0.0,
    };
    let m = iter_message(&rec);
    assert_eq!((m["gamma"].as_f64(), m["k_hinf"].as_f64()), (Some(2.0), Some(3.0)));
    assert!(m.get("hinf_cl").is_none() && m.get("hinf_k").is_none());
}
