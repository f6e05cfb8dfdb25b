//! End-to-end tests of `campaign run` through the real binary: resume after `kill -9` at random
//! moments gives exactly the journal of an uninterrupted run; a torn journal line is reported,
//! ignored and cut off; a small real-design campaign writes its journal, traces and reports.
//!
//! The kill test uses the hidden fake runner (`HINFIX_FAKE_RUNNER`, see `campaign::fake`) so that
//! it takes seconds; its jobs carry their own ids, so fake records can never pass for real ones.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Duration;

use hinfix::campaign::fake::FAKE_RUNNER_ENV;
use hinfix::campaign::journal::read_journal;
use hinfix::campaign::summarise;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

const BIN: &str = env!("CARGO_BIN_EXE_campaign");

fn scratch(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("hinfix-runner-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
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
    let mut c = Command::new(BIN);
    c.arg("run").arg(file).arg("--results").arg(results).arg("--no-progress");
    c.env("HINFIX_PLANTS", concat!(env!("CARGO_MANIFEST_DIR"), "/plants"));
    if fake {
        c.env(FAKE_RUNNER_ENV, "15");
    } else {
        c.env_remove(FAKE_RUNNER_ENV);
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
        let mut child = command(&file, &killed, true).stdout(std::process::Stdio::null()).stderr(std::process::Stdio::null()).spawn().unwrap();
        std::thread::sleep(Duration::from_millis(rng.random_range(50..700)));
        child.kill().unwrap(); // SIGKILL on Unix
        child.wait().unwrap();
    }
    let partial = read_journal(&killed.join("t").join("runs.jsonl")).unwrap();
    assert!(partial.records.len() < 12, "the kills should have interrupted the campaign");
    run_to_end(&file, &killed, true);
    assert_eq!(journal(&killed), expected);
}

#[test]
fn torn_last_line_is_reported_ignored_and_cut_off() {
    let dir = scratch("torn");
    let file = campaign_file(&dir, 5.0, 1);
    let results = dir.join("r");
    run_to_end(&file, &results, true);
    let path = results.join("t").join("runs.jsonl");
    let complete = std::fs::read(&path).unwrap();
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
fn real_design_campaign_writes_journal_traces_and_reports() {
    let dir = scratch("real");
    let file = dir.join("c.toml");
    std::fs::write(&file, "name = \"t\"\n[defaults]\neps = [1e-2]\nseeds = 1\ncpumax = 5.0\n[[problem]]\nplant = \"REA2\"\norders = [1]\n").unwrap();
    let results = dir.join("r");
    let out = run_to_end(&file, &results, false);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains("REA2"), "{stdout}");
    let t = results.join("t");
    for f in ["runs.jsonl", "best.csv", "tables.tex", "compare.csv", "compare.tex"] {
        assert!(t.join(f).is_file(), "{f} missing");
    }
    let recs = read_journal(&t.join("runs.jsonl")).unwrap().records;
    assert_eq!(recs.len(), 1);
    assert!(recs[0].gamma <= 1.134 * 1.01, "γ = {}", recs[0].gamma);
    let traces: Vec<_> = std::fs::read_dir(t.join("traces")).unwrap().map(|e| e.unwrap().path()).collect();
    assert_eq!(traces.len(), 1);
    assert_eq!(traces[0].extension().unwrap(), "mcap");
    let s = summarise(&traces[0]).unwrap();
    // One message per iteration plus one for each start's initial point.
    assert!(s.iterations >= recs[0].iterations && s.iterations <= recs[0].iterations + 16, "{} vs {}", s.iterations, recs[0].iterations);

    latex_compiles(&t);

    // Bad campaign file: a clear error naming the file and the line, exit code 1, no panic.
    std::fs::write(&file, "name = \"t\"\n[defaults]\nepz = [1e-2]\n[[problem]]\nplant = \"REA2\"\norders = [1]\n").unwrap();
    let out = command(&file, &results, false).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("c.toml:3:"), "{stderr}");
}

/// The LaTeX tables are always checked structurally ([`latex_structure`]); where `pdflatex` is
/// installed they are also compiled for real. Without `pdflatex` the structural check is all,
/// unless CI asks for the real compile: with `CI` set (as `.ci/run` sets it) a missing `pdflatex`
/// fails the test, except where `HINFIX_NO_PDFLATEX=1` says that none could be installed.
fn latex_compiles(dir: &Path) {
    for f in ["tables.tex", "compare.tex"] {
        let tex = std::fs::read_to_string(dir.join(f)).unwrap();
        if let Err(e) = latex_structure(&tex) {
            panic!("{f}: {e}\n{tex}");
        }
    }
    let have = Command::new("pdflatex").arg("--version").output().is_ok_and(|o| o.status.success());
    if !have {
        let opted_out = std::env::var("HINFIX_NO_PDFLATEX").as_deref() == Ok("1");
        let ci = std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "0" && v != "false");
        assert!(
            opted_out || !ci,
            "CI is set but pdflatex is not on PATH: install it (texlive-latex-base, texlive-latex-recommended) or set HINFIX_NO_PDFLATEX=1"
        );
        eprintln!("note: pdflatex not found; the LaTeX tables were checked structurally only");
        return;
    }
    std::fs::write(
        dir.join("wrap.tex"),
        "\\documentclass{article}\n\\usepackage{booktabs}\n\\begin{document}\n\\input{tables.tex}\n\\input{compare.tex}\n\\end{document}\n",
    )
    .unwrap();
    let out = Command::new("pdflatex")
        .args(["-interaction=nonstopmode", "-halt-on-error", "wrap.tex"])
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(out.status.success(), "pdflatex failed:\n{}", String::from_utf8_lossy(&out.stdout));
    assert!(dir.join("wrap.pdf").is_file());
}

/// What makes a table fragment fail to compile, checked without LaTeX: environments nest and
/// close (`\begin{x}` … `\end{x}`); braces balance; `#` never appears and `_`, `^` only in math
/// (both unescaped); `$` math closes on its line; every `tabular` has booktabs rules, and each of
/// its rows has as many cells (`\multicolumn{k}` counting k) as its column specification has
/// columns. `%` starts a comment, as in LaTeX.
fn latex_structure(tex: &str) -> Result<(), String> {
    let mut envs: Vec<(String, usize, Vec<String>)> = Vec::new(); // (name, columns, rows)
    let mut depth = 0i64;
    for (no, raw) in tex.lines().enumerate() {
        let at = |what: String| format!("line {}: {what}", no + 1);
        let line = strip_comment(raw);
        // Characters: braces, math, specials.
        let mut math = false;
        let mut chars = line.chars().peekable();
        while let Some(c) = chars.next() {
            match c {
                '\\' => {
                    chars.next(); // an escaped character or the first letter of a command
                }
                '{' => depth += 1,
                '}' => {
                    depth -= 1;
                    if depth < 0 {
                        return Err(at("unmatched }".into()));
                    }
                }
                '$' => math = !math,
                '#' => return Err(at("unescaped #".into())),
                '_' | '^' if !math => return Err(at(format!("unescaped {c} outside math"))),
                _ => {}
            }
        }
        if math {
            return Err(at("$ math not closed on its line".into()));
        }
        // Environments and table rows.
        let mut rest = line;
        while !rest.is_empty() {
            if let Some(r) = rest.strip_prefix("\\begin{") {
                let (name, r) = r.split_once('}').ok_or_else(|| at("\\begin without }".into()))?;
                let (cols, r) = if name == "tabular" { column_spec(r).map_err(&at)? } else { (0, r) };
                envs.push((name.to_string(), cols, Vec::new()));
                rest = r;
            } else if let Some(r) = rest.strip_prefix("\\end{") {
                let (name, r) = r.split_once('}').ok_or_else(|| at("\\end without }".into()))?;
                let (open, cols, rows) = envs.pop().ok_or_else(|| at(format!("\\end{{{name}}} without \\begin")))?;
                if open != name {
                    return Err(at(format!("\\end{{{name}}} closes \\begin{{{open}}}")));
                }
                if name == "tabular" {
                    check_tabular(cols, &rows).map_err(&at)?;
                }
                rest = r;
            } else {
                let skip = rest.chars().next().map_or(1, char::len_utf8);
                let tail = &rest[skip..];
                let next = tail.find("\\begin{").into_iter().chain(tail.find("\\end{")).min().map_or(rest.len(), |i| i + skip);
                if let Some((name, _, rows)) = envs.last_mut() {
                    if name == "tabular" {
                        rows.push(rest[..next].to_string());
                    }
                }
                rest = &rest[next..];
            }
        }
    }
    if let Some((name, ..)) = envs.last() {
        return Err(format!("\\begin{{{name}}} never closed"));
    }
    if depth != 0 {
        return Err(format!("{depth} unclosed {{"));
    }
    Ok(())
}

fn strip_comment(line: &str) -> &str {
    let b = line.as_bytes();
    (0..b.len()).find(|&i| b[i] == b'%' && (i == 0 || b[i - 1] != b'\\')).map_or(line, |i| &line[..i])
}

/// The number of columns of a `{spec}` at the start of `s` (l, c, r, S, X; p/m/b{width};
/// `|` and @/!/>/<{…} take none), and the text after it. A `*{n}{…}` repeat is not supported.
fn column_spec(s: &str) -> Result<(usize, &str), String> {
    let s = s.strip_prefix('{').ok_or("tabular without a column specification")?;
    let (mut cols, mut level, mut end) = (0, 0, None);
    let b = s.as_bytes();
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'{' => level += 1,
            b'}' if level == 0 => {
                end = Some(i);
                break;
            }
            b'}' => level -= 1,
            b'*' => return Err("tabular column repeat *{n}{…} is not checked: write the columns out".into()),
            b'l' | b'c' | b'r' | b'S' | b'X' | b'p' | b'm' | b'b' if level == 0 => cols += 1,
            _ => {}
        }
        i += 1;
    }
    let end = end.ok_or("unterminated column specification")?;
    Ok((cols, &s[end + 1..]))
}

/// Every row of a tabular (text up to each `\\`) has `cols` cells; booktabs rules are present.
fn check_tabular(cols: usize, rows: &[String]) -> Result<(), String> {
    let body = rows.join("\n");
    if !(body.contains("\\toprule") && body.contains("\\bottomrule")) {
        return Err("tabular without booktabs \\toprule/\\bottomrule".into());
    }
    for row in body.split("\\\\").map(str::trim) {
        let row = ["\\toprule", "\\midrule", "\\bottomrule"].iter().fold(row.to_string(), |r, rule| r.replace(rule, ""));
        if row.trim().is_empty() {
            continue;
        }
        let b = row.as_bytes();
        let amps = (0..b.len()).filter(|&i| b[i] == b'&' && (i == 0 || b[i - 1] != b'\\')).count();
        let spans: usize = row
            .split("\\multicolumn{")
            .skip(1)
            .map(|m| m.split('}').next().and_then(|k| k.trim().parse::<usize>().ok()).map_or(0, |k| k.saturating_sub(1)))
            .sum();
        if amps + 1 + spans != cols {
            return Err(format!("row `{}` has {} cells, the tabular has {cols} columns", row.trim(), amps + 1 + spans));
        }
    }
    Ok(())
}

#[test]
fn latex_structure_catches_what_would_not_compile() {
    let ok = "% c\n\\begin{tabular}{l@{}rr}\n\\toprule\n\\multicolumn{3}{c}{A\\_1 γ} \\\\\n\\midrule\n$n_K$ & x & 50\\% \\\\\n\\bottomrule\n\\end{tabular}\n";
    assert_eq!(latex_structure(ok), Ok(()));
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
        let e = latex_structure(&bad).unwrap_err();
        assert!(e.contains(why), "{e} (wanted: {why})");
    }
}
