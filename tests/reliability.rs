//! Reliability at the edges: every bad input a clear error, a journal always readable, honest
//! statuses and exit codes, signals that stop a run cleanly. Grouped by theme (the section
//! comments below).

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

use hinfix::campaign::FAKE_RUNNER_ENV;
use hinfix::campaign::{best_per_order, expand, Campaign, PlantMap, RunnerTag};
use hinfix::campaign::{parse_journal, read_journal, JournalError};
use hinfix::campaign::{JobFailure, JobRecord, JobStatus};
use hinfix::design::{Certificate, Design, DesignOptions, DesignOutcome, DesignStatus, Phase, PhaseStats};
use hinfix::lti::Plant;
use serde_json::Value;

mod common;

const BIN: &str = env!("CARGO_BIN_EXE_campaign");
const PLANTS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/plants");

fn scratch(tag: &str) -> PathBuf {
    common::scratch("rel", tag)
}

fn cli(args: &[&str]) -> Command {
    let mut c = Command::new(BIN);
    c.args(args).env("HINFIX_PLANTS", PLANTS);
    c
}

/// [`cli`] with the fake runner (examples/fake_campaign.rs), pausing `pause_ms` per iteration.
fn fake_cli(args: &[&str], pause_ms: &str) -> Command {
    let mut c = Command::new(common::fake_campaign_bin());
    c.args(args).env("HINFIX_PLANTS", PLANTS).env(FAKE_RUNNER_ENV, pause_ms);
    c
}

/// `campaign run F --results DIR/r --no-progress EXTRA…` with the fake runner pausing `pause_ms`.
fn fake_run(f: &Path, dir: &Path, extra: &[&str], pause_ms: &str) -> Command {
    let results = dir.join("r");
    let mut args = vec!["run", f.to_str().unwrap(), "--results", results.to_str().unwrap(), "--no-progress"];
    args.extend_from_slice(extra);
    fake_cli(&args, pause_ms)
}

/// `campaign design --plant PLANT --order ORDER EXTRA… --out OUT`.
fn design_cli(plant: &str, order: &str, out: &Path, extra: &[&str]) -> Command {
    let mut c = cli(&["design", "--plant", plant, "--order", order]);
    c.args(extra).args(["--out", out.to_str().unwrap()]);
    c
}

fn output(c: &mut Command) -> (Option<i32>, String, String) {
    let o: Output = c.output().unwrap();
    (o.status.code(), String::from_utf8_lossy(&o.stdout).into_owned(), String::from_utf8_lossy(&o.stderr).into_owned())
}

fn assert_no_panic(stderr: &str) {
    assert!(!stderr.contains("panicked") && !stderr.contains("RUST_BACKTRACE"), "{stderr}");
}

fn campaign(text: &str) -> Result<Campaign, hinfix::campaign::SpecError> {
    let text = text.replace("plant = \"HE1\"", &format!("plant = \"{PLANTS}/HE1.json\""));
    Campaign::from_toml_str(&text, Path::new("c.toml"))
}

/// A record of an HE1 job with the given outcome.
fn record(out: Result<DesignOutcome, JobFailure>) -> JobRecord {
    let c = campaign("name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [1]\n").unwrap();
    let job = &expand(&c, RunnerTag::Design)[0];
    JobRecord::from_run("t", job, false, out, 1.0, 2.0).unwrap()
}

fn outcome(status: DesignStatus, x: f64) -> DesignOutcome {
    DesignOutcome {
        status,
        controller: serde_json::from_value(
            serde_json::json!({"AK": [[-1.0]], "BK": [[0.0]], "CK": [[0.0], [0.0]], "DK": [[0.0], [0.0]]}),
        )
        .unwrap(),
        gamma: x,
        k_hinf: x,
        alpha_cl: x,
        alpha_k: Some(x),
        objective: x,
        controller_norm_active: false,
        certificate: Some(Certificate { dnorm: x, evaldist: x }),
        iterations: 1,
        evaluations: 1,
        phases: vec![PhaseStats { phase: Phase::Optimisation, iters: 1, evals: 1, cpu_s: x }],
        design_cpu_s: x,
        search: hinfix::design::SearchSummary {
            starts: 1,
            best_start: 0,
            best_start_kind: None,
            best_start_scaled: false,
            cpu_to_best_s: x,
            evals_to_best: 1,
            stop: hinfix::design::SearchStop::Stall,
        },
        plants: Vec::new(),
    }
}

// ---------------------------------------------------------------------------------------------
// 1. Journal: non-finite floats

/// Every f64 of the record (top level, options, certificate, phases) set to `x`.
fn all_floats(x: f64) -> JobRecord {
    let mut r = record(Ok(outcome(DesignStatus::NotStabilised { best_alpha: x }, x)));
    r.eps = x;
    r.cpumax = x;
    r.options.eps = x;
    r.options.cpumax = x;
    r.options.hinf_tol = x;
    r.options.normtol = x;
    r.options.evaldist = x;
    r.cpu_s = x;
    r.wall_s = x;
    r.finished_unix_s = x;
    r
}

fn same(a: f64, b: f64) -> bool {
    a == b || (a.is_nan() && b.is_nan())
}

#[test]
fn non_finite_values_in_every_numeric_field_round_trip_through_the_journal() {
    let dir = scratch("nonfinite");
    let path = dir.join("runs.jsonl");
    let (mut w, _) = hinfix::campaign::JournalWriter::open(&path).unwrap();
    for x in [f64::INFINITY, f64::NEG_INFINITY, f64::NAN, 1e300] {
        w.append(&all_floats(x)).unwrap();
    }
    let text = std::fs::read_to_string(&path).unwrap();
    // (`warm_from: null` is an absent predecessor, not a number)
    assert!(
        !text.replace("\"warm_from\":null", "").contains("null"),
        "a non-finite number was written as null: {text}"
    );
    let read = read_journal(&path).unwrap();
    assert!(read.torn.is_none());
    assert_eq!(read.records.len(), 4);
    for (r, x) in read.records.iter().zip([f64::INFINITY, f64::NEG_INFINITY, f64::NAN, 1e300]) {
        let o = r.outcome().unwrap();
        for (name, v) in [
            ("eps", r.eps),
            ("cpumax", r.cpumax),
            ("gamma", o.gamma),
            ("k_hinf", o.k_hinf),
            ("alpha_cl", o.alpha_cl),
            ("alpha_k", o.alpha_k.unwrap()),
            ("objective", o.objective),
            ("dnorm", o.certificate.as_ref().unwrap().dnorm),
            ("evaldist", o.certificate.as_ref().unwrap().evaldist),
            ("options.eps", r.options.eps),
            ("options.cpumax", r.options.cpumax),
            ("options.hinf_tol", r.options.hinf_tol),
            ("options.normtol", r.options.normtol),
            ("options.evaldist", r.options.evaldist),
            ("phases.cpu_s", o.phases[0].cpu_s),
            ("design_cpu_s", o.design_cpu_s),
            ("cpu_s", r.cpu_s),
            ("wall_s", r.wall_s),
            ("finished_unix_s", r.finished_unix_s),
        ] {
            assert!(same(v, x), "{name}: wrote {x}, read {v}");
        }
        match &r.status() {
            JobStatus::Design(DesignStatus::NotStabilised { best_alpha }) => assert!(same(*best_alpha, x)),
            s => panic!("{s:?}"),
        }
    }
}

/// Replaces every float number (not integers) of a JSON document by `with`.
fn replace_floats(v: &mut Value, with: &Value) {
    match v {
        Value::Number(n) if n.is_f64() => *v = with.clone(),
        Value::Array(a) => a.iter_mut().for_each(|x| replace_floats(x, with)),
        Value::Object(o) if !o.contains_key("AK") => o.values_mut().for_each(|x| replace_floats(x, with)),
        _ => {}
    }
}

#[test]
fn every_float_field_of_a_record_takes_the_string_form_and_null() {
    // Catches a float field added later without the one serialisation path: such a field would
    // refuse "inf" here.
    let base = serde_json::to_value(all_floats(0.5)).unwrap();
    for with in [Value::from("inf"), Value::from("-inf"), Value::from("nan"), Value::Null] {
        let mut v = base.clone();
        replace_floats(&mut v, &with);
        let r: JobRecord = serde_json::from_value(v).unwrap_or_else(|e| panic!("{with}: {e}"));
        assert!(!r.outcome().unwrap().gamma.is_finite() && !r.options.cpumax.is_finite() && !r.wall_s.is_finite());
    }
}

#[test]
fn old_journal_with_nulls_reads_and_a_corrupt_complete_last_line_is_not_deleted() {
    // A line a design with eps = 1e300 wrote: made ε‖K‖∞ = inf → objective null, dnorm null.
    let mut v = serde_json::to_value(all_floats(0.5)).unwrap();
    replace_floats(&mut v, &Value::Null);
    let line = v.to_string();
    let read = parse_journal(format!("{line}\n").as_bytes(), Path::new("runs.jsonl")).unwrap();
    assert_eq!(read.records.len(), 1);
    assert!(read.records[0].outcome().unwrap().objective.is_nan());

    let dir = scratch("corrupt-last");
    let path = dir.join("runs.jsonl");
    let good = serde_json::to_string(&all_floats(1.0)).unwrap();
    let text = format!("{good}\n{{\"schema_version\": 1, \"broken\": true}}\n");
    std::fs::write(&path, &text).unwrap();
    match hinfix::campaign::JournalWriter::open(&path) {
        Err(JournalError::Corrupt { line: 2, .. }) => {}
        other => panic!("expected a corrupt-line error for line 2, got {other:?}"),
    }
    assert_eq!(std::fs::read_to_string(&path).unwrap(), text, "the journal must not be cut");
}

// ---------------------------------------------------------------------------------------------
// 2. Bounded counts and one validation

#[test]
fn huge_counts_are_clear_errors() {
    let cases: &[(&str, &str)] = &[
        ("orders = { from = -9223372036854775808, to = 0 }", "0..=200"),
        ("orders = { from = 0, to = 9223372036854775807 }", "0..=200"),
        ("orders = [1]\nseeds = 9223372036854775807", "1..=10000"),
        ("orders = [1]\nseeds = 100000000", "1..=10000"),
        ("orders = [1]\nnrand = 100000000", "nrand"),
        ("orders = [1]\nnrand = 18446744073709551615", ""),
        ("orders = [1]\nmaxit = 1000000000000", "maxit"),
    ];
    for (problem, word) in cases {
        let text = format!("name = \"t\"\n[[problem]]\nplant = \"HE1\"\n{problem}\n");
        let e = campaign(&text).expect_err(problem);
        assert!(e.location.line >= 3, "{problem} → {e}");
        assert!(e.to_string().contains(word), "{problem} → {e}");
    }
    let e = campaign("name = \"t\"\n[defaults]\nthreads = 100000\n[[problem]]\nplant = \"HE1\"\norders = [1]\n")
        .unwrap_err();
    assert!(e.to_string().contains("1..=256"), "{e}");
    // 4 orders × 3 ε × 10 000 seeds × 3 problems > 100 000 jobs.
    let p = "[[problem]]\nplant = \"HE1\"\norders = [1, 2, 3, 4]\neps = [1e-1, 1e-2, 1e-3]\nseeds = 10000\n";
    let e =
        campaign(&format!("name = \"t\"\n{p}{}{}", p.replace("1e-1", "2e-1"), p.replace("1e-1", "3e-1"))).unwrap_err();
    assert!(e.to_string().contains("100000 jobs"), "{e}");

    for n in ["100000000", "18446744073709551615"] {
        let dir = scratch("nrand");
        let out = dir.join("K.json");
        let (code, _, err) = output(&mut design_cli("HE1", "1", &out, &["--nrand", n]));
        assert_eq!(code, Some(1), "{err}");
        assert!(err.contains("nrand") && err.contains("1..=10000"), "{err}");
        assert_no_panic(&err);
        assert!(!out.exists());
    }
}

#[test]
fn campaign_check_calls_design_validate_before_any_job() {
    let cases: &[(&str, &str, usize)] = &[
        ("orders = [9]", "exceeds the plant order n = 4", 5),
        ("orders = [1]\nhinf_tol = 1e-15", "hinf_tol", 6),
        ("orders = [1]\neps = nan", "ε must be a number from 1e-50 to 1e50, got NaN", 6),
        ("orders = [1]\ncpumax = -3.0", "cpumax", 6),
        ("orders = [1]\nnormtol = -1.0", "normtol", 6),
    ];
    for (problem, word, line) in cases {
        let text = format!("name = \"t\"\n[defaults]\n[[problem]]\nplant = \"HE1\"\n{problem}\n");
        let e = campaign(&text).expect_err(problem);
        assert!(e.message.to_string().contains(word), "{problem} → {e}");
        assert_eq!(e.location.line, *line, "{problem} → {e}");
        // the very message `design` gives for the same option
        assert!(e.message.to_string().starts_with("invalid design option"), "{e}");
    }
    let long = "x".repeat(101);
    let e = campaign(&format!("name = \"{long}\"\n[[problem]]\nplant = \"HE1\"\norders = [1]\n")).unwrap_err();
    assert!(e.message.to_string().contains("longer than 100"), "{e}");

    // and through the binary: nothing runs, exit 1, no journal.
    let dir = scratch("validate");
    let f = dir.join("c.toml");
    std::fs::write(&f, "name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [9]\n").unwrap();
    let (code, _, err) = output(&mut fake_run(&f, &dir, &[], "1"));
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("c.toml:4:10") && err.contains("order"), "{err}");
    assert!(!dir.join("r/t/runs.jsonl").exists());
}

// ---------------------------------------------------------------------------------------------
// 3. Input size

#[test]
fn dev_zero_as_any_input_is_a_clear_error() {
    if !Path::new("/dev/zero").exists() {
        return;
    }
    let dir = scratch("zero");
    let out = dir.join("K.json");
    let runs: Vec<Vec<&str>> = vec![
        vec!["plant", "/dev/zero"],
        vec!["check", "--plant", "HE1", "--controller", "/dev/zero"],
        vec!["status", "/dev/zero"],
        vec!["trace", "/dev/zero"],
        vec!["design", "--plant", "/dev/zero", "--order", "1", "--out", out.to_str().unwrap()],
    ];
    for args in runs {
        let (code, _, err) = output(&mut cli(&args));
        assert_eq!(code, Some(1), "{args:?}: {err}");
        assert!(err.contains("limit for a"), "{args:?}: {err}");
        assert!(err.contains("/dev/zero"), "{args:?}: {err}");
        assert_no_panic(&err);
    }
}

/// A stable random plant of order n (as a JSON file).
fn big_plant(dir: &Path, n: usize) -> PathBuf {
    let a: Vec<Vec<f64>> = (0..n)
        .map(|i| {
            (0..n)
                .map(|j| {
                    if i == j {
                        -1.0 - i as f64
                    } else if j == i + 1 {
                        0.1
                    } else {
                        0.0
                    }
                })
                .collect()
        })
        .collect();
    let col = |k: usize| -> Vec<Vec<f64>> { (0..n).map(|i| vec![((i + k) % 3) as f64; 1]).collect() };
    let row = |k: usize| -> Vec<Vec<f64>> { vec![(0..n).map(|i| ((i + k) % 2) as f64).collect()] };
    let doc = serde_json::json!({
        "name": "BIG", "dims": {"n": n, "m1": 1, "m2": 1, "p1": 1, "p2": 1},
        "A": a, "B1": col(0), "B2": col(1), "C1": row(0), "C2": row(1),
        "D11": [[0.0]], "D12": [[1.0]], "D21": [[1.0]], "D22": [[0.0]],
    });
    let p = dir.join("big.json");
    std::fs::write(&p, doc.to_string()).unwrap();
    p
}

#[test]
fn full_order_gamma_is_skipped_above_the_documented_n() {
    let dir = scratch("bigplant");
    let p = big_plant(&dir, hinfix::campaign::FULL_ORDER_MAX_N + 1);
    let (code, out, err) = output(&mut cli(&["plant", p.to_str().unwrap()]));
    assert_eq!(code, Some(0), "{err}");
    assert!(out.contains("skipped: n = 61 > 60"), "{out}");
}

// ---------------------------------------------------------------------------------------------
// 4. Signals

fn slow_campaign(dir: &Path) -> PathBuf {
    let f = dir.join("c.toml");
    std::fs::write(&f, "name = \"t\"\n[defaults]\nseeds = 40\n[[problem]]\nplant = \"HE1\"\norders = [1, 2]\n")
        .unwrap();
    f
}

fn spawn_slow(dir: &Path) -> std::process::Child {
    let f = slow_campaign(dir);
    fake_run(&f, dir, &["--threads", "2"], "100").stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap()
}

fn signal(child: &std::process::Child, sig: i32) {
    // SAFETY: kill(2) on our own child's pid.
    assert_eq!(unsafe { libc::kill(child.id() as i32, sig) }, 0);
}

/// Waits until the run has started jobs (its signal handlers are installed before that).
fn wait_started(dir: &Path) {
    let t = Instant::now();
    while tmp_traces(dir).is_empty() {
        assert!(t.elapsed() < Duration::from_secs(60), "the campaign did not start");
        std::thread::sleep(Duration::from_millis(50));
    }
}

fn tmp_traces(dir: &Path) -> Vec<PathBuf> {
    match std::fs::read_dir(dir.join("r/t/traces")) {
        Ok(rd) => rd.map(|e| e.unwrap().path()).filter(|p| p.to_string_lossy().ends_with(".tmp")).collect(),
        Err(_) => Vec::new(),
    }
}

#[test]
fn sigterm_and_sighup_stop_like_ctrl_c() {
    for (sig, code) in [(libc::SIGTERM, 143), (libc::SIGHUP, 129), (libc::SIGINT, 130)] {
        let dir = scratch(&format!("sig{sig}"));
        let child = spawn_slow(&dir);
        wait_started(&dir);
        std::thread::sleep(Duration::from_millis(300));
        signal(&child, sig);
        let out = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(code), "signal {sig}: {err}");
        assert!(err.contains("interrupted") && err.contains("jobs:"), "signal {sig}: no summary: {err}");
        assert!(tmp_traces(&dir).is_empty(), "signal {sig} left {:?}", tmp_traces(&dir));
        assert!(read_journal(&dir.join("r/t/runs.jsonl")).unwrap().torn.is_none());
    }
}

#[test]
fn second_ctrl_c_stops_at_once() {
    let dir = scratch("sigint2");
    let f = slow_campaign(&dir);
    // A pause of 60 s per fake iteration: after the first Ctrl-C the run waits for the jobs in
    // flight to reach their next check, then prints its summary. The second Ctrl-C must end the
    // process at once, without that summary: which of the two happened is read from stderr, so
    // the test does not depend on how fast the machine is.
    let child = fake_run(&f, &dir, &[], "60000").stdout(Stdio::null()).stderr(Stdio::piped()).spawn().unwrap();
    wait_started(&dir);
    signal(&child, libc::SIGINT);
    std::thread::sleep(Duration::from_millis(100));
    signal(&child, libc::SIGINT);
    let out = child.wait_with_output().unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(130), "{err}");
    assert!(!err.contains("rerun the same command to resume"), "the run waited for its jobs: {err}");
}

// ---------------------------------------------------------------------------------------------
// 5. Names

#[test]
fn hostile_names_reach_no_output_raw() {
    let dir = scratch("names");
    let text = std::fs::read_to_string(format!("{PLANTS}/HE1.json")).unwrap();
    let mut doc: Value = serde_json::from_str(&text).unwrap();
    let evil = "=HYPERLINK(\"http://x\")\u{1b}[2J\u{0}\nline";
    doc["name"] = Value::from(evil);
    std::fs::write(dir.join("evil.json"), doc.to_string()).unwrap();
    let f = dir.join("c.toml");
    std::fs::write(&f, "name = \"t\"\n[[problem]]\nplant = \"evil.json\"\norders = [1]\n").unwrap();
    let (code, out, err) = output(&mut fake_run(&f, &dir, &[], "1"));
    assert_eq!(code, Some(0), "{err}");
    for (what, s) in [("stdout", out.as_str()), ("stderr", err.as_str())] {
        assert!(!s.contains('\u{1b}') && !s.contains('\u{0}'), "{what}: {s:?}");
    }
    let t = dir.join("r/t");
    for file in ["best.csv", "compare.csv"] {
        let csv = std::fs::read_to_string(t.join(file)).unwrap();
        assert!(!csv.contains('\u{1b}') && !csv.contains('\u{0}'), "{file}: {csv:?}");
        let mut rd = csv::Reader::from_reader(csv.as_bytes());
        for rec in rd.records() {
            let plant = rec.unwrap()[0].to_string();
            assert!(plant.starts_with('\''), "{file}: {plant:?}");
            assert!(!plant.contains('\n'), "{file}: {plant:?}");
        }
    }
    for file in ["tables.tex", "compare.tex"] {
        let tex = std::fs::read_to_string(t.join(file)).unwrap();
        assert!(!tex.contains('\u{1b}') && !tex.contains('\u{0}') && !tex.contains("\nline"), "{file}: {tex:?}");
    }
}

// ---------------------------------------------------------------------------------------------
// 6. Exit codes and statuses

#[test]
fn design_and_check_exit_4_when_not_stabilised() {
    let dir = scratch("exit4");
    // An unstable mode (λ = 1) that u cannot reach.
    let plant = r#"{"name": "unreachable", "dims": {"n": 2, "m1": 1, "m2": 1, "p1": 1, "p2": 1},
        "A": [[1.0, 0.0], [0.0, -1.0]], "B1": [[1.0], [1.0]], "B2": [[0.0], [1.0]],
        "C1": [[1.0, 1.0]], "C2": [[1.0, 1.0]], "D11": [[0.0]], "D12": [[1.0]], "D21": [[1.0]], "D22": [[0.0]]}"#;
    let p = dir.join("u.json");
    std::fs::write(&p, plant).unwrap();
    let k = dir.join("K.json");
    let (code, out, err) =
        output(&mut design_cli(p.to_str().unwrap(), "0", &k, &["--cpumax", "2", "--stop-on-stall", "--nrand", "1"]));
    assert_eq!(code, Some(4), "{out}{err}");
    assert!(out.contains("NOT STABILISED"), "{out}");
    // a controller that does not stabilise is never written to --out as if it were a result …
    assert!(!k.exists(), "{out}");
    assert!(out.contains("no controller written: it does not stabilise"), "{out}");
    // … only on request, under a name that says what it is
    let (code, out, err) = output(&mut design_cli(
        p.to_str().unwrap(),
        "0",
        &k,
        &["--cpumax", "2", "--stop-on-stall", "--nrand", "1", "--out-unverified"],
    ));
    assert_eq!(code, Some(4), "{out}{err}");
    let unverified = dir.join("K.unverified.json");
    assert!(!k.exists() && unverified.is_file(), "{out}");
    assert!(out.contains("NOT STABILISING controller written to"), "{out}");
    let (code, out, err) =
        output(&mut cli(&["check", "--plant", p.to_str().unwrap(), "--controller", unverified.to_str().unwrap()]));
    assert_eq!(code, Some(4), "{out}{err}");
    assert!(out.contains("UNSTABLE"), "{out}");
    // a stabilising controller: exit 0
    let good = dir.join("G.json");
    let (code, _, err) = output(&mut design_cli("REA2", "0", &good, &["--cpumax", "5", "--stop-on-stall"]));
    assert_eq!(code, Some(0), "{err}");
    let (code, _, err) = output(&mut cli(&["check", "--plant", "REA2", "--controller", good.to_str().unwrap()]));
    assert_eq!(code, Some(0), "{err}");
}

#[test]
fn failed_means_one_thing_in_best_csv() {
    let plant = std::sync::Arc::new(Plant::load(format!("{PLANTS}/HE1.json")).unwrap());
    let plants: PlantMap = [(plant.fingerprint(), plant)].into_iter().collect();
    let not_stab = record(Ok(outcome(DesignStatus::NotStabilised { best_alpha: 0.5 }, f64::INFINITY)));
    // another job of the same (plant, order): records of one job id count once
    let mut failed = record(Err(JobFailure::RunnerError("boom".into())));
    failed.job_id.0 = format!("{}-other", failed.job_id.0);
    let rows = best_per_order(&[not_stab.clone(), failed.clone()], &plants);
    assert_eq!((rows[0].runs, rows[0].verified, rows[0].failed, rows[0].unverified), (2, 0, 1, 1));
    assert!(failed.failed() && !not_stab.failed());
}

#[test]
fn converged_and_stopped_are_told_apart_and_old_optimised_reads() {
    let r = record(Ok(outcome(DesignStatus::Converged, 1.0)));
    let mut v = serde_json::to_value(&r).unwrap();
    assert_eq!(v["status"]["kind"], "converged");
    v["status"]["kind"] = Value::from("optimised");
    let old: JobRecord = serde_json::from_value(v).unwrap();
    assert_eq!(old.status(), JobStatus::Design(DesignStatus::Stopped));
    let d: DesignStatus = serde_json::from_str(r#"{"kind": "optimised"}"#).unwrap();
    assert_eq!(d, DesignStatus::Stopped);

    // A real run: the status says whether the certificate was met.
    let p = Plant::load(format!("{PLANTS}/REA2.json")).unwrap();
    for maxit in [2, 1000] {
        let opts = DesignOptions {
            order: 1,
            seed: 1,
            cpumax: 20.0,
            maxit,
            spend_budget: false,
            // maxit bounds each local search only if cut searches are not resumed, and if the
            // continued search's local searches have the same limit.
            continue_at_maxit: false,
            continued_maxit: 0,
            gradient_sampling: false,
            ..Default::default()
        };
        let o = Design::for_plant(&p, &opts).run().unwrap();
        match o.status {
            DesignStatus::Converged => assert!(o.certificate.as_ref().unwrap().dnorm <= opts.normtol, "{o:?}"),
            DesignStatus::Stopped => assert!(o.certificate.as_ref().unwrap().dnorm > opts.normtol, "{o:?}"),
            DesignStatus::StabilisedOnly => {}
            s => panic!("maxit {maxit}: {s:?}"),
        }
        if maxit == 2 {
            assert_ne!(o.status, DesignStatus::Converged, "2 iterations cannot certify: {o:?}");
        }
    }
}

#[test]
fn controller_norm_term_is_flagged() {
    let p = Plant::load(format!("{PLANTS}/REA2.json")).unwrap();
    for (eps, active) in [(1e3, true), (1e-6, false)] {
        let opts =
            DesignOptions { order: 0, eps, seed: 0, cpumax: 5.0, nrand: 1, spend_budget: false, ..Default::default() };
        let o = Design::for_plant(&p, &opts).run().unwrap();
        assert!(o.gamma.is_finite(), "{o:?}");
        assert_eq!(o.controller_norm_active, active, "ε = {eps}: γ = {}, ε‖K‖∞ = {}", o.gamma, eps * o.k_hinf);
        // Within the norms' tolerance: on the ridge ‖Tzw‖∞ = ε‖K‖∞ the larger one is rounding.
        assert_eq!(o.controller_norm_active, eps * o.k_hinf >= o.gamma * (1.0 - opts.hinf_tol));
    }
    let dir = scratch("normflag");
    let k = dir.join("K.json");
    let (code, out, err) =
        output(&mut design_cli("REA2", "0", &k, &["--eps", "1e3", "--cpumax", "5", "--stop-on-stall", "--nrand", "1"]));
    assert_eq!(code, Some(0), "{err}");
    assert!(out.contains("controller-norm penalty"), "{out}");
}

// ---------------------------------------------------------------------------------------------
// 7. The reference table belongs to the program

#[test]
fn report_works_with_a_plant_folder_without_reference() {
    let dir = scratch("ownplants");
    let own = dir.join("myplants");
    std::fs::create_dir_all(&own).unwrap();
    std::fs::copy(format!("{PLANTS}/HE1.json"), own.join("HE1.json")).unwrap();
    let f = dir.join("c.toml");
    std::fs::write(&f, "name = \"t\"\n[[problem]]\nplant = \"HE1\"\norders = [1]\n").unwrap();
    let results = dir.join("r");
    let mut c = fake_cli(&["run", f.to_str().unwrap(), "--results", results.to_str().unwrap(), "--no-progress"], "1");
    c.env("HINFIX_PLANTS", &own).current_dir(&dir);
    let (code, out, err) = output(&mut c);
    assert_eq!(code, Some(0), "{err}");
    assert!(out.contains("0.1235"), "the paper's HE1 value must be in the comparison: {out}");
    let mut c = fake_cli(&["report", f.to_str().unwrap(), "--results", results.to_str().unwrap()], "1");
    c.env("HINFIX_PLANTS", &own).current_dir(&dir);
    let (code, _, err) = output(&mut c);
    assert_eq!(code, Some(0), "{err}");
}

// ---------------------------------------------------------------------------------------------
// 8. Error texts

#[test]
fn error_texts() {
    let dir = scratch("small");
    // plant and controller errors say their text once
    let (code, _, err) = output(&mut cli(&["plant", "/no/such/plant.json"]));
    assert_eq!(code, Some(1));
    assert_eq!(err.matches("No such file").count(), 1, "{err}");
    let (_, _, err) = output(&mut cli(&["check", "--plant", "HE1", "--controller", "/no/such/K.json"]));
    assert_eq!(err.matches("No such file").count(), 1, "{err}");
    // I/O errors on a campaign file have no 0:0 position
    let (code, _, err) = output(&mut cli(&["status", "/no/such/c.toml"]));
    assert_eq!(code, Some(1));
    assert!(!err.contains(":0:0") && err.contains("/no/such/c.toml: cannot read"), "{err}");
    // --out <directory> fails before the design, leaving nothing: the message is the check made
    // before any work ("--out …: is a directory; give a file name"), not the failed write after it
    let (code, _, err) = output(&mut design_cli("HE1", "1", &dir, &["--cpumax", "30"]));
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("--out ") && err.contains("is a directory; give a file name"), "the design ran first: {err}");
    assert!(!err.contains("writing "), "the design ran first: {err}");
    assert!(std::fs::read_dir(&dir).unwrap().next().is_none(), "left files behind");
    // --eps -1 is a number, and ε must be > 0
    let k = dir.join("K.json");
    let (code, _, err) = output(&mut design_cli("HE1", "1", &k, &["--eps", "-1"]));
    assert_eq!(code, Some(1), "{err}");
    assert!(err.contains("ε must be a number from 1e-50 to 1e50, got -1"), "{err}");
    // did you mean
    let (code, _, err) = output(&mut cli(&["plant", "he1"]));
    assert_eq!(code, Some(1));
    assert!(err.contains("did you mean `HE1`?"), "{err}");
    // a huge ε prints numbers in scientific notation
    let (code, out, err) = output(&mut design_cli(
        "REA2",
        "0",
        &k,
        &["--eps", "1e50", "--cpumax", "2", "--stop-on-stall", "--nrand", "1"],
    ));
    assert!(code == Some(0) || code == Some(4), "{err}");
    let longest = out.split_whitespace().map(str::len).max().unwrap_or(0);
    assert!(longest < 40, "a {longest}-character word in: {out}");
}

/// A printing command whose reader goes away (`campaign plant CM4 --json | head -c 100`) ends
/// quietly, by SIGPIPE as Unix tools do, not with a "failed printing to stdout" panic.
#[test]
fn closed_stdout_ends_printing_commands_quietly() {
    use std::os::unix::process::ExitStatusExt;
    for args in [&["plant", "CM4", "--json"][..], &["plants"][..]] {
        let mut child =
            cli(args).stdout(std::process::Stdio::piped()).stderr(std::process::Stdio::piped()).spawn().unwrap();
        drop(child.stdout.take()); // the reader closes before the command has printed
        let o = child.wait_with_output().unwrap();
        let err = String::from_utf8_lossy(&o.stderr);
        assert_no_panic(&err);
        assert!(
            o.status.code() == Some(0) || o.status.signal() == Some(libc::SIGPIPE),
            "{:?} {args:?}: {err}",
            o.status
        );
    }
}

/// `campaign design … | head -1`: a stdout closed before the summary is printed ends the
/// command with its own exit code and the controller written, not with the panic of `print!`
/// ("failed printing to stdout").
#[test]
fn a_closed_stdout_does_not_make_design_panic() {
    let dir = scratch("closed-stdout");
    let out = dir.join("K.json");
    let mut c = design_cli("HE1", "1", &out, &["--maxevals", "200"]);
    let mut child = c.stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap();
    drop(child.stdout.take()); // the reader goes away before anything is printed
    let o = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&o.stderr);
    assert_no_panic(&stderr);
    assert_eq!(o.status.code(), Some(0), "{stderr}");
    assert!(out.exists());
    let _ = std::fs::remove_dir_all(&dir);
}
