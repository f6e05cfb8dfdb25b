//! The files of `campaign compare`, as text: the per-entry CSV and LaTeX tables, the summary as
//! CSV and as text. Pure functions of the sources, the rows and the summary; `mod.rs` writes
//! them atomically.

use std::fmt::Write as _;

use super::source::Source;
use super::summary::Summary;
use super::table::{Cell, EntryRow};
use crate::campaign::leaves::sanitise::for_csv;
use crate::campaign::reduction::latex::{escape, sig4};

fn num(x: f64) -> String {
    crate::design::f64_text(x)
}

/// A γ cell of the CSV: the number, `failed` or `missing`.
fn gamma_cell(c: Cell) -> String {
    match c {
        Cell::Solved { gamma, .. } => num(gamma),
        Cell::Failed => "failed".into(),
        Cell::Missing => "missing".into(),
    }
}

/// `entries.csv`: plant, order, objective, how the plant was matched, the methods within the
/// tolerance of the row's best (`;`-separated), then per method `gamma_<L>` and `ratio_<L>` (to
/// the row's best, `inf` for a failure or a missing entry), `cpu_s_<L>` for the methods with CPU
/// times, and per pair `<A>/<B>` = γ_A / γ_B where both solved the entry (empty otherwise).
pub fn entries_csv(sources: &[Source], rows: &[EntryRow], rtol: f64) -> Result<Vec<u8>, csv::Error> {
    let mut w = csv::Writer::from_writer(Vec::new());
    let mut head: Vec<String> = ["plant", "order", "objective", "match", "best"].map(String::from).to_vec();
    for s in sources {
        head.push(format!("gamma_{}", s.label));
        head.push(format!("ratio_{}", s.label));
    }
    let cpu: Vec<usize> =
        (0..sources.len()).filter(|&i| sources[i].entries.iter().any(|e| e.cpu_s.is_some())).collect();
    for &i in &cpu {
        head.push(format!("cpu_s_{}", sources[i].label));
    }
    for (a, b) in pairs(sources.len()) {
        head.push(format!("{}/{}", sources[a].label, sources[b].label));
    }
    w.write_record(&head)?;
    for r in rows {
        let ratios = r.ratios();
        let best: Vec<&str> =
            (0..sources.len()).filter(|&i| r.is_best(i, rtol)).map(|i| sources[i].label.as_str()).collect();
        let mut rec = vec![
            for_csv(&r.plant),
            r.order.to_string(),
            r.objective.name().to_string(),
            r.matched.name().to_string(),
            best.join(";"),
        ];
        for (c, ratio) in r.cells.iter().zip(&ratios) {
            rec.push(gamma_cell(*c));
            rec.push(num(*ratio));
        }
        for &i in &cpu {
            rec.push(match r.cells[i] {
                Cell::Solved { cpu_s: Some(t), .. } => num(t),
                _ => String::new(),
            });
        }
        for (a, b) in pairs(sources.len()) {
            let (ga, gb) = (r.cells[a].gamma(), r.cells[b].gamma());
            rec.push(if ga.is_finite() && gb.is_finite() { num(ga / gb) } else { String::new() });
        }
        w.write_record(&rec)?;
    }
    w.into_inner().map_err(|e| csv::Error::from(e.into_error()))
}

/// The pairs (a, b), a < b, of `n` methods.
pub fn pairs(n: usize) -> impl Iterator<Item = (usize, usize)> {
    (0..n).flat_map(move |a| (a + 1..n).map(move |b| (a, b)))
}

/// `entries.tex`: a booktabs tabular, per entry each method's γ (4 significant figures, the
/// best within the tolerance in bold, `fail` / `--` for a failure / a missing entry), then each
/// method's ratio to the row's best ($\infty$ for a failure or a missing entry).
pub fn entries_tex(sources: &[Source], rows: &[EntryRow], rtol: f64) -> String {
    let mixed = rows.iter().any(|r| r.objective != rows[0].objective);
    let n = sources.len();
    let labels: Vec<String> = sources.iter().map(|s| escape(&s.label)).collect();
    let mut s = format!(
        "% campaign compare: γ per method, ratio to the best of the row; bold: within a relative {rtol:e} of the best\n\\begin{{tabular}}{{lr{}{}{}}}\n\\toprule\n",
        if mixed { "l" } else { "" },
        "r".repeat(n),
        "r".repeat(n)
    );
    let _ = writeln!(
        s,
        " & &{} \\multicolumn{{{n}}}{{c}}{{$\\gamma$}} & \\multicolumn{{{n}}}{{c}}{{$\\gamma/\\gamma_{{\\mathrm{{best}}}}$}} \\\\",
        if mixed { " &" } else { "" }
    );
    let _ = writeln!(
        s,
        "plant & $n_K${} & {} & {} \\\\\n\\midrule",
        if mixed { " & objective" } else { "" },
        labels.join(" & "),
        labels.join(" & ")
    );
    for r in rows {
        let gammas: Vec<String> = (0..n)
            .map(|i| match r.cells[i] {
                Cell::Solved { gamma, .. } if r.is_best(i, rtol) => format!("\\textbf{{{}}}", sig4(gamma)),
                Cell::Solved { gamma, .. } => sig4(gamma),
                Cell::Failed => "fail".into(),
                Cell::Missing => "--".into(),
            })
            .collect();
        let ratios: Vec<String> =
            r.ratios().iter().map(|&x| if x.is_finite() { format!("{x:.4}") } else { "$\\infty$".into() }).collect();
        let objective = if mixed { format!(" & {}", r.objective.name()) } else { String::new() };
        let _ = writeln!(
            s,
            "{} & {}{objective} & {} & {} \\\\",
            escape(&r.plant),
            r.order,
            gammas.join(" & "),
            ratios.join(" & ")
        );
    }
    s.push_str("\\bottomrule\n\\end{tabular}\n");
    s
}

/// `summary.csv`: one row per pair of methods: wins, ties, losses of the first against the
/// second at the tolerance, and the geometric mean of γ_a/γ_b over the entries every method
/// solved.
pub fn summary_csv(sources: &[Source], sm: &Summary) -> Result<Vec<u8>, csv::Error> {
    let mut w = csv::Writer::from_writer(Vec::new());
    w.write_record([
        "method_a",
        "method_b",
        "wins_a",
        "ties",
        "losses_a",
        "entries",
        "all_solved",
        "geomean_a_over_b",
        "rtol",
    ])?;
    for p in &sm.pairs {
        w.write_record([
            sources[p.a].label.clone(),
            sources[p.b].label.clone(),
            p.wins.to_string(),
            p.ties.to_string(),
            p.losses.to_string(),
            sm.entries.to_string(),
            sm.all_solved.to_string(),
            num(p.geomean_ratio),
            num(sm.rtol),
        ])?;
    }
    w.into_inner().map_err(|e| csv::Error::from(e.into_error()))
}

/// The summary for people (`summary.txt`, and what `campaign compare` prints): the sources, per
/// method its counts and geometric mean ratio, per pair its wins / ties / losses, then every
/// missing and every failed entry by name, and the entries matched by plant name only.
pub fn summary_text(sources: &[Source], rows: &[EntryRow], sm: &Summary) -> String {
    let mut s = String::new();
    let w = sources.iter().map(|x| x.label.len()).max().unwrap_or(0).max(6);
    for x in sources {
        let _ = writeln!(s, "{:<w$}  {}", x.label, crate::campaign::for_terminal(&x.path.display().to_string()));
    }
    let _ = writeln!(
        s,
        "{} entries, {} solved by every method; ties within a relative {:e}\n",
        sm.entries, sm.all_solved, sm.rtol
    );
    let _ = writeln!(
        s,
        "{:<w$} {:>7} {:>7} {:>8} {:>6} {:>16}",
        "method", "solved", "failed", "missing", "best", "geomean γ/best"
    );
    for (x, m) in sources.iter().zip(&sm.methods) {
        let _ = writeln!(
            s,
            "{:<w$} {:>7} {:>7} {:>8} {:>6} {:>16}",
            x.label,
            m.solved,
            m.failed,
            m.missing,
            m.best,
            format!("{:.6}", m.geomean_ratio)
        );
    }
    let _ = writeln!(
        s,
        "\n{:<w2$} {:>5} {:>5} {:>7} {:>14}",
        "pair",
        "wins",
        "ties",
        "losses",
        "geomean γa/γb",
        w2 = 2 * w + 4
    );
    for p in &sm.pairs {
        let pair = format!("{} vs {}", sources[p.a].label, sources[p.b].label);
        let _ = writeln!(
            s,
            "{pair:<w2$} {:>5} {:>5} {:>7} {:>14}",
            p.wins,
            p.ties,
            p.losses,
            format!("{:.6}", p.geomean_ratio),
            w2 = 2 * w + 4
        );
    }
    let name =
        |r: &EntryRow| format!("{} n_K={} {}", crate::campaign::for_terminal(&r.plant), r.order, r.objective.name());
    for (what, cell) in [("missing", Cell::Missing), ("failed", Cell::Failed)] {
        for (i, x) in sources.iter().enumerate() {
            let list: Vec<String> = rows.iter().filter(|r| r.cells[i] == cell).map(name).collect();
            if !list.is_empty() {
                let _ = writeln!(s, "\n{} {what} in {}: {}", list.len(), x.label, list.join(", "));
            }
        }
    }
    let by_name: Vec<String> = rows.iter().filter(|r| r.matched == super::table::Match::Name).map(name).collect();
    if !by_name.is_empty() {
        let _ = writeln!(
            s,
            "\n{} matched by plant name only (no fingerprint on one side): {}",
            by_name.len(),
            by_name.join(", ")
        );
    }
    s
}
