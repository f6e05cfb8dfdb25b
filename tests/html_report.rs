//! The HTML report of a results folder (`campaign report` → `report/index.html`, module
//! `campaign::html`): the committed page of results/strong-stab is what the library makes of
//! the committed best.csv, compare.csv and journal, and in a real browser (headless Chromium, as
//! `.ci/run` installs it) it shows 57 table rows and every linked figure loads; a removed figure
//! is reported broken; a synthetic 1 000-entry page renders in under 2 s.
//!
//! Without a browser the browser tests are skipped with a note, except under `CI=true`, where a
//! missing browser is a failure. `HINFIX_BROWSER` names the browser's executable.

use std::path::{Path, PathBuf};
use std::process::Command;

use hinfix::campaign::{read_journal, report_html, write_html_report, BestRow, CompareRow};
use hinfix::design::ObjectiveKind;

fn repo(p: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(p)
}

/// The browser, or None (after a note) when there is none outside CI.
fn browser() -> Option<PathBuf> {
    let names: Vec<String> = match std::env::var("HINFIX_BROWSER") {
        Ok(b) => vec![b],
        Err(_) => ["chromium", "chromium-browser", "google-chrome", "google-chrome-stable"].map(String::from).to_vec(),
    };
    let path = std::env::var_os("PATH").unwrap_or_default();
    for n in &names {
        let candidates: Vec<PathBuf> = if n.contains('/') {
            vec![PathBuf::from(n)]
        } else {
            std::env::split_paths(&path).map(|d| d.join(n)).collect()
        };
        if let Some(p) = candidates.into_iter().find(|p| p.is_file()) {
            return Some(p);
        }
    }
    assert!(
        std::env::var("CI").as_deref() != Ok("true"),
        "CI=true but no headless browser found ({names:?}): .ci/run installs Debian's chromium"
    );
    eprintln!("note: no browser found ({names:?}; set HINFIX_BROWSER): the HTML report's browser test is skipped");
    None
}

/// The DOM of `page` after its scripts ran, from headless Chromium (as root too: no sandbox).
/// With `selftest`, the page checks its figures and the virtual clock lets their loads finish.
fn dump_dom(browser: &Path, page: &Path, selftest: bool) -> String {
    let profile = tempfile::tempdir().unwrap();
    let mut c = Command::new(browser);
    c.args(["--headless", "--no-sandbox", "--disable-gpu", "--no-first-run", "--timeout=60000"])
        .arg(format!("--user-data-dir={}", profile.path().display()));
    if selftest {
        c.arg("--virtual-time-budget=30000");
    }
    let url = format!("file://{}{}", page.canonicalize().unwrap().display(), if selftest { "#selftest" } else { "" });
    let out = c.arg("--dump-dom").arg(url).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8(out.stdout).unwrap()
}

/// The self-test's `key=value` words.
fn selftest(dom: &str) -> std::collections::BTreeMap<String, String> {
    let mark = "<pre id=\"selftest\">rows=";
    let start = dom.find(mark).unwrap_or_else(|| panic!("no self-test result in the DOM")) + mark.len() - "rows=".len();
    let line = &dom[start..dom[start..].find('<').map_or(dom.len(), |e| start + e)];
    line.split_whitespace().filter_map(|w| w.split_once('=')).map(|(k, v)| (k.into(), v.into())).collect()
}

/// The rows of a compare.csv file (the paper and ratio columns the page shows).
fn compare_rows(path: &Path) -> Vec<CompareRow> {
    let mut r = csv::Reader::from_path(path).unwrap();
    r.records()
        .map(|rec| {
            let rec = rec.unwrap();
            let f = |i: usize| rec[i].parse::<f64>().unwrap();
            CompareRow {
                plant: rec[0].into(),
                order: rec[1].parse().unwrap(),
                objective: if &rec[7] == "plain" { ObjectiveKind::Plain } else { ObjectiveKind::Strong },
                ours: f(2),
                paper: f(3),
                literature: Vec::new(),
                full_order: f(5),
                ratio: f(6),
            }
        })
        .collect()
}

fn best_rows(path: &Path) -> Vec<BestRow> {
    csv::Reader::from_path(path).unwrap().deserialize().map(Result::unwrap).collect()
}

#[test]
fn the_committed_strong_stab_page_is_current() {
    let dir = repo("results/strong-stab");
    let records = read_journal(&dir.join("runs.jsonl")).unwrap().records;
    let page = report_html(&dir, &best_rows(&dir.join("best.csv")), &compare_rows(&dir.join("compare.csv")), &records);
    let committed = std::fs::read_to_string(dir.join("report/index.html")).unwrap();
    assert!(page == committed, "results/strong-stab/report/index.html is not what `campaign report` writes now");
    assert_eq!(page.matches("<tr><td>").count(), 57);
}

#[test]
fn the_strong_stab_page_in_a_browser_has_57_rows_and_no_broken_link() {
    let Some(b) = browser() else { return };
    let page = repo("results/strong-stab/report/index.html");
    let html = std::fs::read_to_string(&page).unwrap();
    let links = html.matches(" data-fig>").count() + html.matches("<img src=").count();
    let t = selftest(&dump_dom(&b, &page, true));
    assert_eq!(t["rows"], "57", "{t:?}");
    assert_eq!(t["links"], links.to_string(), "{t:?}");
    assert_eq!(t["broken"], "0", "{t:?}");
    assert_eq!(t["ok"], links.to_string(), "{t:?}");
}

/// A synthetic campaign folder of `plants` × `orders` entries with a tiny figure per link.
fn synthetic(dir: &Path, plants: usize, orders: usize) -> (Vec<BestRow>, PathBuf) {
    let plots = dir.join("plots");
    std::fs::create_dir_all(&plots).unwrap();
    let svg = "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"48\" height=\"32\"><rect width=\"48\" height=\"32\" fill=\"#07b\"/></svg>\n";
    let mut best = Vec::new();
    for p in 0..plants {
        let name = format!("P{p:04}");
        std::fs::write(plots.join(format!("gamma-vs-order_{name}.svg")), svg).unwrap();
        for k in 0..orders {
            for kind in ["convergence", "sigma"] {
                std::fs::write(plots.join(format!("{kind}_{name}_nK{k}.svg")), svg).unwrap();
            }
            best.push(BestRow {
                plant: name.clone(),
                plant_fingerprint: format!("{p:064x}"),
                order: k,
                gamma: 1.0 + (p * 7 + k * 3) as f64 % 11.0,
                job_id: Some(format!("{:064x}", p * 100 + k)),
                eps: Some(1e-3),
                seed: Some(k as u64),
                k_hinf: Some(1.0),
                alpha_k: Some(-1.0),
                cpu_to_best_s: Some(k as f64),
                chain_cpu_to_best_s: Some(k as f64),
                runs: 10,
                verified: 10,
                near_best: 3,
                failed: 0,
                unverified: 0,
                objective: ObjectiveKind::Strong,
                controller_stable: Some(true),
                plants: Vec::new(),
            });
        }
    }
    let page = write_html_report(dir, &best, &[], &[]).unwrap();
    (best, page)
}

#[test]
fn a_removed_figure_is_a_broken_link() {
    let Some(b) = browser() else { return };
    let dir = tempfile::tempdir().unwrap();
    let (_, page) = synthetic(dir.path(), 2, 2);
    std::fs::remove_file(dir.path().join("plots/sigma_P0001_nK1.svg")).unwrap();
    let t = selftest(&dump_dom(&b, &page, true));
    assert_eq!((t["rows"].as_str(), t["links"].as_str(), t["broken"].as_str()), ("4", "10", "1"), "{t:?}");
    assert!(t["first_broken"].ends_with("sigma_P0001_nK1.svg"), "{t:?}");
}

#[test]
fn a_1000_entry_page_renders_in_under_2_s() {
    let Some(b) = browser() else { return };
    let dir = tempfile::tempdir().unwrap();
    let (best, page) = synthetic(dir.path(), 200, 5);
    assert_eq!(best.len(), 1000);
    let started = std::time::Instant::now();
    let dom = dump_dom(&b, &page, false);
    let wall = started.elapsed().as_secs_f64();
    let ms: f64 = dom
        .split("data-render-ms=\"")
        .nth(1)
        .and_then(|s| s.split('"').next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no render time in the DOM"));
    eprintln!("1000-entry page: rendered in {ms} ms (browser process {wall:.2} s)");
    assert_eq!(dom.matches("<tr><td>").count(), 1000);
    assert!(ms < 2000.0, "the 1000-entry page took {ms} ms to render");
}
