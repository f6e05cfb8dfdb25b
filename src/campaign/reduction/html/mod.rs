//! The HTML report of a results folder, `<dir>/report/index.html`, written by `campaign report`
//! beside the tables: one self-contained static page (its style and script inline, no network)
//! with the campaign's summary, the best-γ table (sortable by clicking a column head, filterable;
//! a few lines of vanilla JS, [`SCRIPT`]), each entry linking to its convergence and σ figures
//! where `campaign plot` made them (relative links into `../plots/`), the γ-vs-order figures
//! inline (loaded lazily, so hundreds of plants stay usable) and the provenance of the jobs.
//!
//! The page is a pure function of the best rows, the comparison rows, the journal records and
//! which figure files exist: no clock, so the same folder gives the same page.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

use super::compare::{CampaignAbout, CompareRow};
use super::plot::file_part;
use super::reduce::BestRow;
use crate::campaign::records::record::JobRecord;
use crate::design::ObjectiveKind;

/// The page's script: sorting and filtering of the table, the render time, and with `#selftest`
/// in the URL a check that every linked figure loads (the CI browser test reads its result).
pub const SCRIPT: &str = include_str!("report.js");

/// The page's style.
pub const STYLE: &str = include_str!("report.css");

/// `s` escaped for HTML text and attribute values.
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&#39;"),
            c if c.is_control() => {}
            c => out.push(c),
        }
    }
    out
}

/// A number for the table: 6 significant figures, `–` when not finite.
fn num(x: f64) -> String {
    if x.is_finite() && x != 0.0 && !(1e-4..1e6).contains(&x.abs()) {
        format!("{x:.5e}")
    } else if x.is_finite() {
        super::latex::sig_figs(x, 6)
    } else {
        "–".into()
    }
}

/// A sort key attribute: the number, or a large value for "none" so that it sorts last.
fn key(x: f64) -> String {
    if x.is_finite() {
        format!("{x:e}")
    } else {
        "1e308".into()
    }
}

/// The relative link `../plots/<stem>.svg` (or `.png`) when `campaign plot` made that figure.
fn figure(dir: &Path, stem: &str) -> Option<String> {
    ["svg", "png"]
        .iter()
        .map(|ext| format!("{stem}.{ext}"))
        .find(|f| dir.join("plots").join(f).is_file())
        .map(|f| format!("../plots/{f}"))
}

/// The page of the results folder `dir` (figures are looked up in `dir/plots/`).
pub fn report_html(dir: &Path, best: &[BestRow], compare: &[CompareRow], records: &[JobRecord]) -> String {
    let about = CampaignAbout::of(records);
    let title = format!("hinfix campaign {}", about.names.join(", "));
    let mut s = String::new();
    let _ = write!(
        s,
        "<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n<title>{}</title>\n<style>\n{STYLE}</style>\n</head>\n<body>\n<h1>{}</h1>\n",
        escape(&title),
        escape(&title)
    );
    summary(&mut s, best, records, &about);
    table(&mut s, dir, best, compare);
    gamma_figures(&mut s, dir, best);
    provenance(&mut s, records);
    let _ = write!(s, "<script>\n{SCRIPT}</script>\n</body>\n</html>\n");
    s
}

fn summary(s: &mut String, best: &[BestRow], records: &[JobRecord], about: &CampaignAbout) {
    let mut cpu: BTreeMap<&str, f64> = BTreeMap::new();
    for r in records {
        cpu.entry(r.job_id.0.as_str()).or_insert(r.cpu_s);
    }
    let cpu_h: f64 = cpu.values().sum::<f64>() / 3600.0;
    let mut plants: Vec<&str> = best.iter().map(|b| b.plant.as_str()).collect();
    plants.dedup();
    let verified = best.iter().filter(|b| b.job_id.is_some()).count();
    let failed: usize = best.iter().map(|b| b.failed).sum();
    let list = |v: &[f64]| v.iter().map(|x| format!("{x}")).collect::<Vec<_>>().join(", ");
    let _ = write!(
        s,
        "<section id=\"summary\">\n<h2>Summary</h2>\n<ul>\n<li>{} jobs journaled, {:.2} CPU hours; {} failed</li>\n<li>{} plants, {} entries (plant, n<sub>K</sub>, objective), {} with a verified controller</li>\n<li>ε: {}; {} seeds; CPU budget per job: {} s</li>\n</ul>\n<p>Every γ is recomputed from the returned controller (best.csv). Tables: <a href=\"../best.csv\">best.csv</a>, <a href=\"../compare.csv\">compare.csv</a>, <a href=\"../tables.tex\">tables.tex</a>.</p>\n</section>\n",
        about.jobs,
        cpu_h,
        failed,
        plants.len(),
        best.len(),
        verified,
        list(&about.eps),
        about.seeds,
        list(&about.cpumax)
    );
}

fn table(s: &mut String, dir: &Path, best: &[BestRow], compare: &[CompareRow]) {
    let mixed = best.iter().any(|b| b.objective != ObjectiveKind::Strong);
    s.push_str("<section id=\"best\">\n<h2>Best γ per entry</h2>\n<p><input id=\"filter\" type=\"search\" placeholder=\"filter rows (plant, n_K, …)\"> <span id=\"shown\"></span>; click a column head to sort.</p>\n<table id=\"best-table\">\n<thead><tr>");
    let heads: &[&str] = &[
        "plant",
        "n<sub>K</sub>",
        "objective",
        "γ",
        "paper",
        "γ / paper",
        "verified / runs",
        "near best",
        "ε",
        "seed",
        "CPU to best (s)",
        "figures",
    ];
    for h in heads {
        let _ = write!(s, "<th>{h}</th>");
    }
    s.push_str("</tr></thead>\n<tbody>\n");
    for b in best {
        let c = compare.iter().find(|c| c.plant == b.plant && c.order == b.order && c.objective == b.objective);
        let (paper, ratio) = c.map_or((f64::NAN, f64::NAN), |c| (c.paper, c.ratio));
        let plain = b.objective == ObjectiveKind::Plain;
        let tag = format!("{}_nK{}{}", file_part(&b.plant), b.order, if plain { "_plain" } else { "" });
        let links: Vec<String> = [("convergence", "convergence"), ("σ-plot", "sigma")]
            .iter()
            .filter_map(|(name, prefix)| {
                figure(dir, &format!("{prefix}_{tag}"))
                    .map(|f| format!("<a href=\"{}\" data-fig>{name}</a>", escape(&f)))
            })
            .collect();
        let objective = match (b.objective, b.controller_stable) {
            (ObjectiveKind::Plain, Some(false)) => "plain (K unstable)",
            (o, _) => o.name(),
        };
        let _ = writeln!(
            s,
            "<tr><td>{}</td><td data-v=\"{}\">{}</td><td>{}</td><td data-v=\"{}\">{}</td><td data-v=\"{}\">{}</td><td data-v=\"{}\">{}</td><td data-v=\"{}\">{} / {}</td><td data-v=\"{}\">{}</td><td data-v=\"{}\">{}</td><td data-v=\"{}\">{}</td><td data-v=\"{}\">{}</td><td>{}</td></tr>",
            escape(&b.plant),
            b.order,
            b.order,
            objective,
            key(b.gamma),
            num(b.gamma),
            key(paper),
            num(paper),
            key(ratio),
            num(ratio),
            b.verified,
            b.verified,
            b.runs,
            b.near_best,
            b.near_best,
            key(b.eps.unwrap_or(f64::NAN)),
            b.eps.map_or("–".into(), |e| format!("{e}")),
            b.seed.map_or(u64::MAX, |x| x),
            b.seed.map_or("–".into(), |x| x.to_string()),
            key(b.cpu_to_best_s.unwrap_or(f64::NAN)),
            num(b.cpu_to_best_s.unwrap_or(f64::NAN)),
            if links.is_empty() { "–".into() } else { links.join(" ") }
        );
    }
    s.push_str("</tbody>\n</table>\n");
    if mixed {
        s.push_str("<p>Rows of the plain objective ask nothing of the controller's stability.</p>\n");
    }
    s.push_str("</section>\n");
}

fn gamma_figures(s: &mut String, dir: &Path, best: &[BestRow]) {
    let mut plants: Vec<&str> = best.iter().map(|b| b.plant.as_str()).collect();
    plants.dedup();
    s.push_str("<section id=\"figures\">\n<h2>γ against the controller order</h2>\n");
    let mut missing = 0;
    for p in plants {
        match figure(dir, &format!("gamma-vs-order_{}", file_part(p))) {
            Some(f) => {
                let _ = writeln!(
                    s,
                    "<figure><a href=\"{f}\"><img src=\"{f}\" alt=\"γ against n_K for {p}\" loading=\"lazy\" width=\"480\" height=\"320\"></a><figcaption>{p}</figcaption></figure>",
                    f = escape(&f),
                    p = escape(p)
                );
            }
            None => missing += 1,
        }
    }
    if missing > 0 {
        let _ = writeln!(s, "<p>{missing} plant(s) without figures: <code>campaign plot</code> draws them.</p>");
    }
    s.push_str("</section>\n");
}

fn provenance(s: &mut String, records: &[JobRecord]) {
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    for r in records {
        let line = match &r.provenance {
            Some(p) => format!(
                "hinfix {} (commit {}), host {}, {} worker thread(s), {}",
                p.hinfix_version,
                p.git_commit.as_deref().unwrap_or("unknown"),
                p.host,
                p.threads,
                p.cpu_model
            ),
            None => "no provenance (journal of an older build)".to_string(),
        };
        *seen.entry(line).or_default() += 1;
    }
    s.push_str("<section id=\"provenance\">\n<h2>Provenance</h2>\n<ul>\n");
    for (line, n) in &seen {
        let _ = writeln!(s, "<li>{n} record(s): {}</li>", escape(line));
    }
    s.push_str("</ul>\n</section>\n");
}
