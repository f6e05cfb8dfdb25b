//! Headless-browser helpers for the HTML report (`campaign report` → `report/index.html`): find
//! the browser, dump a page's DOM after its scripts ran, read its self-test, and write a synthetic
//! campaign folder of any size. Shared by `tests/html_report.rs` and the page-render benchmark
//! `benches/report_page.rs` (which includes this file by path).
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::Command;

use hinfix::campaign::{write_html_report, BestRow};
use hinfix::design::ObjectiveKind;

/// The browser, or None (after a note) when there is none outside CI.
pub fn browser() -> Option<PathBuf> {
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
pub fn dump_dom(browser: &Path, page: &Path, selftest: bool) -> String {
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
pub fn selftest(dom: &str) -> std::collections::BTreeMap<String, String> {
    let mark = "<pre id=\"selftest\">rows=";
    let start = dom.find(mark).unwrap_or_else(|| panic!("no self-test result in the DOM")) + mark.len() - "rows=".len();
    let line = &dom[start..dom[start..].find('<').map_or(dom.len(), |e| start + e)];
    line.split_whitespace().filter_map(|w| w.split_once('=')).map(|(k, v)| (k.into(), v.into())).collect()
}

/// A synthetic campaign folder of `plants` × `orders` entries with a tiny figure per link.
pub fn synthetic(dir: &Path, plants: usize, orders: usize) -> (Vec<BestRow>, PathBuf) {
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

/// The render time the page reports (its `data-render-ms` attribute), in milliseconds.
pub fn render_ms(dom: &str) -> f64 {
    dom.split("data-render-ms=\"")
        .nth(1)
        .and_then(|s| s.split('"').next())
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no render time in the DOM"))
}
