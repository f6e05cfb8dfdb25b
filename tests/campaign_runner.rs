//! End-to-end tests of `campaign run` through the real binary: resume after `kill -9` at random
//! moments gives exactly the journal of an uninterrupted run; a torn journal line is reported,
//! ignored and cut off; a small real-design campaign writes its journal, traces and reports;
//! its sparse traces are a fraction of the full ones and still summarise and plot.
//!
//! The kill test uses the fake runner (examples/fake_campaign.rs, see `campaign::fake`) so that
//! it takes seconds; its jobs carry their own ids, so fake records can never pass for real ones.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Duration;

use hinfix::campaign::read_journal;
use hinfix::campaign::FAKE_RUNNER_ENV;
use hinfix::campaign::{read_iterations, summarise, TraceIteration};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

mod common;
use common::latex_compiles;

const BIN: &str = env!("CARGO_BIN_EXE_campaign");

fn scratch(tag: &str) -> PathBuf {
    common::scratch("runner", tag)
}

/// A campaign file in `dir`: HE1 at orders 1–2 warm-started, 2 ε, `seeds` seeds.
fn campaign_file(dir: &Path, cpumax: f64, seeds: usize) -> PathBuf {
    let f = dir.join("c.toml");
    std::fs::write(
        &f,
        format!(
            "name = \"t\"\n[defaults]\neps = [1e-2, 1e-3]\nseeds = {seeds}\ncpumax = {cpumax}\n\n\
             [[problem]]\nplant = \"HE1\"\norders = [1, 2]\nwarm_start = true\n"
        ),
    )
    .unwrap();
    f
}

fn command(file: &Path, results: &Path, fake: bool) -> Command {
    let mut c = if fake { Command::new(common::fake_campaign_bin()) } else { Command::new(BIN) };
    c.arg("run").arg(file).arg("--results").arg(results).arg("--no-progress");
    c.env("HINFIX_PLANTS", concat!(env!("CARGO_MANIFEST_DIR"), "/plants"));
    if fake {
        c.env(FAKE_RUNNER_ENV, "15");
    }
    c
}

fn run_to_end(file: &Path, results: &Path, fake: bool) -> Output {
    let out = command(file, results, fake).output().unwrap();
    assert!(out.status.success(), "campaign run failed: {}", String::from_utf8_lossy(&out.stderr));
    out
}

/// job id → record without timing fields.
fn journal(results: &Path) -> BTreeMap<String, serde_json::Value> {
    let read = read_journal(&results.join("t").join("runs.jsonl")).unwrap();
    assert!(read.torn.is_none());
    let mut m = BTreeMap::new();
    for r in read.records {
        assert!(m.insert(r.job_id.0.clone(), r.comparable()).is_none(), "job {} journaled twice", r.job_id.0);
    }
    m
}

#[test]
fn kill_minus_nine_at_random_moments_then_resume_equals_an_uninterrupted_run() {
    let dir = scratch("kill");
    let file = campaign_file(&dir, 5.0, 3);
    let whole = dir.join("whole");
    run_to_end(&file, &whole, true);
    let expected = journal(&whole);
    assert_eq!(expected.len(), 12);

    let killed = dir.join("killed");
    let mut rng = ChaCha8Rng::seed_from_u64(2026);
    for _ in 0..5 {
        let mut child = command(&file, &killed, true)
            .stdout(std::process::Stdio::null())
            .stderr(std::process::Stdio::null())
            .spawn()
            .unwrap();
        std::thread::sleep(Duration::from_millis(rng.random_range(50..700)));
        child.kill().unwrap(); // SIGKILL on Unix
        child.wait().unwrap();
    }
    let partial = read_journal(&killed.join("t").join("runs.jsonl")).unwrap();
    assert!(partial.records.len() < 12, "the kills should have interrupted the campaign");
    run_to_end(&file, &killed, true);
    assert_eq!(journal(&killed), expected);
}

/// A one-seed fake campaign run to its end in a scratch folder `tag`: the campaign file, the
/// results folder, the journal's path and its bytes.
fn finished_fake_campaign(tag: &str) -> (PathBuf, PathBuf, PathBuf, Vec<u8>) {
    let dir = scratch(tag);
    let file = campaign_file(&dir, 5.0, 1);
    let results = dir.join("r");
    run_to_end(&file, &results, true);
    let path = results.join("t").join("runs.jsonl");
    let complete = std::fs::read(&path).unwrap();
    (file, results, path, complete)
}

#[test]
fn torn_last_line_is_reported_ignored_and_cut_off() {
    let (file, results, path, complete) = finished_fake_campaign("torn");
    let lines: Vec<&[u8]> = complete.split_inclusive(|&b| b == b'\n').collect();
    // Drop the last record and leave half of it, as a kill in mid-write would.
    let last = lines[lines.len() - 1];
    let mut torn: Vec<u8> = lines[..lines.len() - 1].concat();
    torn.extend_from_slice(&last[..last.len() / 2]);
    std::fs::write(&path, &torn).unwrap();
    assert!(read_journal(&path).unwrap().torn.is_some());

    let out = run_to_end(&file, &results, true);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("torn"), "{stderr}");
    let read = read_journal(&path).unwrap();
    assert!(read.torn.is_none());
    assert_eq!(read.records.len(), lines.len());
}

#[test]
fn whole_last_record_without_newline_is_kept_not_cut() {
    // A valid last record lacking only its newline was taken for torn and cut.
    let (file, results, path, complete) = finished_fake_campaign("nonl");
    let n = complete.iter().filter(|&&b| b == b'\n').count();
    std::fs::write(&path, &complete[..complete.len() - 1]).unwrap();
    let read = read_journal(&path).unwrap();
    assert!(read.torn.is_none() && read.unterminated);
    assert_eq!(read.records.len(), n);

    let out = run_to_end(&file, &results, true);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!stderr.contains("torn"), "{stderr}");
    // nothing ran again: the file is the original, newline restored
    assert_eq!(std::fs::read(&path).unwrap(), complete);
}

#[test]
fn real_design_campaign_writes_journal_traces_and_reports() {
    let dir = scratch("real");
    let file = dir.join("c.toml");
    // Every iteration in the trace (the file's key; the default is sparse).
    std::fs::write(&file, "name = \"t\"\n[defaults]\neps = [1e-2]\nseeds = 1\ncpumax = 5.0\nmaxevals = 3000\ntrace = \"full\"\n[[problem]]\nplant = \"REA2\"\norders = [1]\n").unwrap();
    let results = dir.join("r");
    let out = run_to_end(&file, &results, false);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("REA2"), "{stdout}");
    let t = results.join("t");
    for f in ["runs.jsonl", "best.csv", "tables.tex", "compare.csv", "compare.tex", "library.tex"] {
        assert!(t.join(f).is_file(), "{f} missing");
    }
    let recs = read_journal(&t.join("runs.jsonl")).unwrap().records;
    assert_eq!(recs.len(), 1);
    let designed = recs[0].outcome().expect("the job was designed");
    assert!(designed.gamma <= 1.134 * 1.01, "γ = {}", designed.gamma);
    let traces: Vec<_> = std::fs::read_dir(t.join("traces")).unwrap().map(|e| e.unwrap().path()).collect();
    assert_eq!(traces.len(), 1);
    assert_eq!(traces[0].extension().unwrap(), "mcap");
    let s = summarise(&traces[0]).unwrap();
    // The trace counts steps as the journal does (they once differed: 3 313 against 3 306); the starting
    // points of every local search (f_s and f_h) and of the final gradient sampling are extra
    // messages.
    let search = designed.search.clone();
    let slack = 2 * search.starts + 4;
    assert_eq!(s.iterations, designed.iterations);
    assert!(
        s.messages > s.iterations && s.messages <= designed.iterations + slack,
        "{} vs {}",
        s.messages,
        designed.iterations
    );
    assert_eq!(s.search.as_ref(), Some(&search));
    assert!(search.starts >= 3 && search.best_start < search.starts, "{search:?}");

    latex_compiles(&t);

    // `export` takes the results folder and an entry (plant and order, or a job id prefix), and
    // prints MATLAB by default: the same controller either way.
    let export = |args: &[&str]| {
        let out = Command::new(BIN).arg("export").arg("--results").arg(&t).args(args).output().unwrap();
        assert!(out.status.success(), "{args:?}: {}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8(out.stdout).unwrap()
    };
    let by_entry = export(&["--plant", "REA2", "--order", "1"]);
    assert!(by_entry.contains("K = ss(AK, BK, CK, DK)") && by_entry.contains(&recs[0].job_id.0), "{by_entry}");
    assert_eq!(export(&["--job", &recs[0].job_id.0[..12]]), by_entry);
    assert!(export(&["--job", &recs[0].job_id.0, "--to", "python"]).contains("control.ss("));
    let out =
        Command::new(BIN).args(["export", "--results"]).arg(&t).args(["--plant", "REA2", "--order", "2"]).output();
    let stderr = String::from_utf8_lossy(&out.as_ref().unwrap().stderr).to_string();
    assert!(stderr.contains("no row for plant REA2, n_K = 2"), "{stderr}");

    // MCAP log times are Unix epoch times (ns) of the run, not times since the job started.
    let mut times = Vec::new();
    let bytes = std::fs::read(&traces[0]).unwrap();
    for m in mcap::MessageStream::new(&bytes).unwrap() {
        times.push(m.unwrap().log_time);
    }
    let finished = recs[0].finished_unix_s * 1e9;
    assert!(!times.is_empty());
    assert!(times.iter().all(|&t| (t as f64) <= finished + 1e9 && (t as f64) >= finished - 600e9), "{times:?}");

    // Bad campaign file: a clear error naming the file and the line, exit code 1, no panic.
    std::fs::write(&file, "name = \"t\"\n[defaults]\nepz = [1e-2]\n[[problem]]\nplant = \"REA2\"\norders = [1]\n")
        .unwrap();
    let out = command(&file, &results, false).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("c.toml:3:"), "{stderr}");
}

/// The one trace of a results folder.
fn only_trace(results: &Path) -> PathBuf {
    let traces: Vec<_> =
        std::fs::read_dir(results.join("t").join("traces")).unwrap().map(|e| e.unwrap().path()).collect();
    assert_eq!(traces.len(), 1, "{traces:?}");
    traces[0].clone()
}

/// One real design (evaluation budget: the same iterations every time) traced at each level
/// through `--trace`: the same journal and job id; the sparse trace is a small fraction of the
/// full one and summarises to the same steps, phases, best ‖Tzw‖∞ and result; `campaign trace`
/// and the convergence figure work on it; with `off` there is no trace and `campaign plot` skips
/// the convergence figure without an error.
#[test]
fn sparse_trace_is_small_and_still_summarises_and_plots() {
    let dir = scratch("levels");
    let file = dir.join("c.toml");
    std::fs::write(&file, "name = \"t\"\n[defaults]\neps = [1e-2]\nseeds = 1\ncpumax = 30.0\nmaxevals = 4000\n[[problem]]\nplant = \"HE1\"\norders = [1]\n").unwrap();
    let run = |level: Option<&str>| {
        let results = dir.join(level.unwrap_or("default"));
        let mut c = command(&file, &results, false);
        if let Some(l) = level {
            c.arg("--trace").arg(l);
        }
        let out = c.output().unwrap();
        assert!(out.status.success(), "{level:?}: {}", String::from_utf8_lossy(&out.stderr));
        results
    };
    let (sparse, full, off) = (run(None), run(Some("full")), run(Some("off")));
    assert_eq!(journal(&sparse), journal(&full));
    assert_eq!(journal(&off), journal(&full));

    let (ts, tf) = (only_trace(&sparse), only_trace(&full));
    assert_eq!(ts.file_name(), tf.file_name(), "same job id");
    let (bs, bf) = (std::fs::metadata(&ts).unwrap().len(), std::fs::metadata(&tf).unwrap().len());
    assert!(bs * 5 < bf, "sparse {bs} B, full {bf} B");
    let (s, f) = (summarise(&ts).unwrap(), summarise(&tf).unwrap());
    assert!(s.messages * 5 < f.messages, "{} of {} messages", s.messages, f.messages);
    assert_eq!((s.offered, f.offered), (f.messages, f.messages));
    let designed = read_journal(&sparse.join("t").join("runs.jsonl")).unwrap().records[0].outcome().unwrap().clone();
    assert_eq!((s.iterations, f.iterations), (designed.iterations, designed.iterations));
    assert_eq!((s.first_f.to_bits(), s.last_f.to_bits()), (f.first_f.to_bits(), f.last_f.to_bits()));
    assert_eq!(s.best_gamma.to_bits(), f.best_gamma.to_bits());
    assert_eq!(s.evaluations, f.evaluations);
    let phases = |t: &hinfix::campaign::TraceSummary| -> Vec<(String, u64, u64)> {
        t.phases.iter().map(|(n, p)| (n.clone(), p.first_f.to_bits(), p.last_f.to_bits())).collect()
    };
    assert_eq!(phases(&s), phases(&f));
    let search =
        |t: &hinfix::campaign::TraceSummary| t.search.clone().map(|s| (s.starts, s.best_start, s.evals_to_best));
    assert_eq!((&s.final_status, s.final_gamma, search(&s)), (&f.final_status, f.final_gamma, search(&f)));

    // The best objective of every phase kind, and the last point of every local search (so
    // every run boundary), are in the sparse trace; of the first points, those of the job and of
    // every phase's first run.
    let (is, it) = (read_iterations(&ts).unwrap(), read_iterations(&tf).unwrap());
    let best = |v: &[TraceIteration], stab: bool| {
        v.iter().filter(|i| (i.phase == "stabilisation") == stab).map(|i| i.f).fold(f64::INFINITY, f64::min)
    };
    for stab in [true, false] {
        assert_eq!(best(&is, stab).to_bits(), best(&it, stab).to_bits());
    }
    let key = |i: &TraceIteration| (i.phase.clone(), i.start, i.iteration);
    let lasts = |v: &[TraceIteration]| -> Vec<(String, usize, usize)> {
        let mut e: Vec<_> = v
            .windows(2)
            .filter(|w| w[0].phase != w[1].phase || w[0].start != w[1].start || w[1].iteration <= w[0].iteration)
            .map(|w| key(&w[0]))
            .collect();
        e.extend(v.last().map(key));
        e
    };
    assert!(lasts(&it).len() >= 4);
    assert_eq!(lasts(&is), lasts(&it));
    let phase_firsts = |v: &[TraceIteration]| -> Vec<(String, usize, usize)> {
        let mut firsts: Vec<(String, usize, usize)> = Vec::new();
        for i in v {
            if !firsts.iter().any(|f| f.0 == i.phase) {
                firsts.push(key(i));
            }
        }
        firsts
    };
    assert_eq!(phase_firsts(&is), phase_firsts(&it));
    let starting_points = |v: &[TraceIteration]| v.iter().filter(|i| i.iteration == 0).count();
    assert!(starting_points(&is) < starting_points(&it), "the other runs' first messages are left out");

    // `campaign trace` and `campaign plot` on the sparse trace; no trace at level off.
    let out = Command::new(BIN).arg("trace").arg(&ts).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success() && text.contains("kept (sparse)") && text.contains("final: "), "{text}");
    let plot = |results: &Path| {
        let mut c = Command::new(BIN);
        c.arg("plot").arg(&file).arg("--results").arg(results);
        c.env("HINFIX_PLANTS", concat!(env!("CARGO_MANIFEST_DIR"), "/plants"));
        let out = c.output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        (results.join("t").join("plots"), String::from_utf8_lossy(&out.stderr).to_string())
    };
    let (plots, _) = plot(&sparse);
    assert!(plots.join("convergence_HE1_nK1.svg").is_file() && plots.join("convergence_HE1_nK1.png").is_file());
    assert!(!off.join("t").join("traces").exists());
    let (plots, stderr) = plot(&off);
    assert!(!plots.join("convergence_HE1_nK1.svg").exists());
    assert!(plots.join("sigma_HE1_nK1.svg").is_file());
    assert!(stderr.contains("skipped: convergence of HE1_nK1: no trace"), "{stderr}");
}

/// Under an evaluation budget (CPU budget not binding) a real-design campaign journals the same
/// records, controllers included, bit for bit, at one worker thread and at two.
#[test]
fn maxevals_campaign_is_identical_at_one_and_two_threads() {
    let dir = scratch("threads");
    let text = "name = \"t\"\n[defaults]\neps = [1e-2, 1e-3]\nseeds = 1\ncpumax = 1000.0\nmaxevals = 1200\n\
                [[problem]]\nplant = \"REA2\"\norders = [1, 2]\n";
    let file = common::campaign_file(&dir, text);
    let mut journals = Vec::new();
    for threads in ["1", "2"] {
        let results = dir.join(format!("r{threads}"));
        let out = command(&file, &results, false).arg("--threads").arg(threads).output().unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        journals.push(journal(&results));
    }
    assert_eq!(journals[0].len(), 4);
    for r in journals[0].values() {
        assert_eq!(r["search"]["stop"], "maxevals", "{r}");
    }
    assert_eq!(journals[0], journals[1]);
}

#[test]
fn latex_structure_catches_what_would_not_compile() {
    let ok = "% c\n\\begin{tabular}{l@{}rr}\n\\toprule\n\\multicolumn{3}{c}{A\\_1 γ} \\\\\n\\midrule\n$n_K$ & x & 50\\% \\\\\n\\bottomrule\n\\end{tabular}\n";
    assert_eq!(common::latex_structure(ok), Ok(()));
    for (bad, why) in [
        (ok.replace("A\\_1", "A_1"), "outside math"),
        (ok.replace("& x &", "& x & y &"), "has 4 cells"),
        (ok.replace("\\end{tabular}", "\\end{table}"), "closes"),
        (ok.replace("{c}{A", "{c}A"), "unmatched }"),
        (ok.replace("\\bottomrule", ""), "booktabs"),
        (ok.replace("$n_K$", "$n_K"), "math not closed"),
        (ok.replace("\\end{tabular}\n", ""), "never closed"),
        (ok.replace("x &", "\\# #1 &"), "unescaped #"),
    ] {
        let e = common::latex_structure(&bad).unwrap_err();
        assert!(e.contains(why), "{e} (wanted: {why})");
    }
    // a longtable: its caption rows and head and foot markers are no rows of cells
    let long = "\\begin{longtable}{lr}\n\\caption{A, B}\\label{t} \\\\\n\\toprule\na & b \\\\\n\\midrule\n\\endfirsthead\n\\caption[]{(continued)} \\\\\n\\toprule\na & b \\\\\n\\endhead\n\\multicolumn{2}{r}{more} \\\\\n\\endfoot\n\\bottomrule\n\\endlastfoot\nx & 1 \\\\\n\\end{longtable}\n";
    assert_eq!(common::latex_structure(long), Ok(()));
    let e = common::latex_structure(&long.replace("x & 1", "x & 1 & 2")).unwrap_err();
    assert!(e.contains("has 3 cells, the tabular has 2 columns"), "{e}");
}
