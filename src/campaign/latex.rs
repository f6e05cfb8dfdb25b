//! LaTeX (booktabs) rendering of the campaign tables: `tables.tex` (the paper's layout: per
//! plant, the full-order bound, then per n_K ours, the paper's and the ratio) and `compare.tex`.

use std::fmt::Write as _;

use super::compare::{CompareRow, FullOrderRow, FULL_ORDER_MAX_N};
use super::reduce::BestRow;
use super::reference::{RefMethod, ReferenceRow};

/// Escapes LaTeX specials and drops control characters: [`super::sanitise::for_latex`], which
/// every LaTeX table uses (kept under this name too).
pub use super::sanitise::for_latex as escape;

/// γ to 4 decimals, `--` when not finite.
pub fn num(x: f64) -> String {
    if x.is_finite() {
        format!("{x:.4}")
    } else {
        "--".into()
    }
}

/// `x` rounded to `n` significant figures, in fixed notation (`0.0003500`, `34.81`, `1.000`):
/// trailing zeros are kept, since they are significant.
pub fn sig_figs(x: f64, n: usize) -> String {
    if !x.is_finite() || x == 0.0 || n == 0 {
        return format!("{x}");
    }
    // Round in scientific form first, so that 9.9996 → 1.000e1 gives "10.00", not "10.000".
    let sci = format!("{:.*e}", n - 1, x);
    let exp: i32 = sci.rsplit('e').next().and_then(|e| e.parse().ok()).unwrap_or(0);
    let decimals = (n as i32 - 1 - exp).max(0) as usize;
    format!("{x:.decimals$}")
}

/// γ with 4 significant figures for LaTeX, `--` when not finite; values below 10⁻⁴ or from 10⁶
/// up in scientific form (`$1.000\times10^{-6}$`).
pub fn sig4(x: f64) -> String {
    if !x.is_finite() {
        return "--".into();
    }
    let a = x.abs();
    if x == 0.0 || (1e-4..1e6).contains(&a) {
        return sig_figs(x, 4);
    }
    let sci = format!("{x:.3e}");
    let (mant, exp) = sci.split_once('e').unwrap_or((&sci, "0"));
    format!("${mant}\\times10^{{{exp}}}$")
}

/// A LaTeX `\label` key part: ASCII letters and digits kept, everything else `-`, with a short
/// hash when that changed the name (`sanitise::as_key`), so two plants never share a label.
fn label_key(name: &str) -> String {
    super::sanitise::as_key(name, |c| c.is_ascii_alphanumeric(), '-', 64)
}

/// `tables.tex`, in the layout of the paper's tables: one `table` per plant with a caption and a
/// `\label{tab:hinfix-<plant>}`; first the full-order bound (computed here, or the paper's value
/// marked †, with whether the paper's full-order controller is stable), then per n_K from the
/// highest down: our best re-verified γ, the paper's HIFOO γ and ours/paper. Plants for which the
/// reference table has values from earlier literature get a literature column (their orders
/// appear as rows of their own when we have no result there). 4 significant figures throughout.
pub fn tables_tex(best: &[BestRow], full: &[FullOrderRow], reference: &[ReferenceRow]) -> String {
    let mut s = String::from("% hinfix: best γ per controller order (re-verified) in the layout of\n% Gumussoy, Millstone & Overton (2008); needs \\usepackage{booktabs}\n");
    let mut plants: Vec<(&str, &str)> = best.iter().map(|r| (r.plant.as_str(), r.plant_fingerprint.as_str())).collect();
    plants.dedup();
    for (p, fp) in plants {
        let refs = |m: RefMethod| reference.iter().filter(move |r| r.is_for(fp) && r.method == m);
        let literature: Vec<&ReferenceRow> = refs(RefMethod::Literature).collect();
        let has_lit = !literature.is_empty();
        let paper_at =
            |k: usize| refs(RefMethod::Hifoo).filter(|r| r.order == k).map(|r| r.gamma).fold(f64::NAN, f64::min);
        let lit_at = |k: usize| {
            let cells: Vec<String> = literature
                .iter()
                .filter(|r| r.order == k)
                .map(|r| format!("{} ({})", sig4(r.gamma), escape(&r.source)))
                .collect();
            if cells.is_empty() {
                "--".to_string()
            } else {
                cells.join("; ")
            }
        };
        let f = full.iter().find(|f| f.plant == p);
        let dagger = f.is_some_and(|f| f.from_paper);
        let paper_full = refs(RefMethod::FullOrder).next();
        let _ = writeln!(s, "\\begin{{table}}[!htbp]\n\\centering");
        let _ = writeln!(
            s,
            "\\caption{{{}: closed-loop $H_\\infty$ norm $\\gamma$ of the best re-verified stable controller of each order $n_K$ (hinfix), against the HIFOO results of Gumussoy, Millstone \\& Overton (2008).}}",
            escape(p)
        );
        let _ = writeln!(s, "\\label{{tab:hinfix-{}}}", label_key(p));
        let (cols, head) = if has_lit { ("lrrrl", " & literature") } else { ("lrrr", "") };
        let _ = writeln!(
            s,
            "\\begin{{tabular}}{{{cols}}}\n\\toprule\n$n_K$ & ours & paper (HIFOO) & ours/paper{head} \\\\\n\\midrule"
        );
        if let Some(f) = f {
            let stab = match paper_full {
                Some(r) if r.controller_stable => ", stable $K$",
                Some(_) => ", unstable $K$",
                None => "",
            };
            let order = paper_full.map(|r| format!(" ($n_K = {}${stab})", r.order)).unwrap_or_default();
            let mark = if dagger { "$^\\dagger$" } else { "" };
            let pf = paper_full.map_or(f64::NAN, |r| r.gamma);
            let _ = write!(s, "full order{order} & {}{mark} & {} & {}", sig4(f.gamma), sig4(pf), sig4(f.gamma / pf));
            if has_lit {
                s.push_str(" & --");
            }
            s.push_str(" \\\\\n\\midrule\n");
        }
        let mut orders: Vec<usize> = best.iter().filter(|r| r.plant == p).map(|r| r.order).collect();
        orders.extend(literature.iter().map(|r| r.order));
        orders.sort_unstable_by(|a, b| b.cmp(a));
        orders.dedup();
        for k in orders {
            let ours = best.iter().find(|r| r.plant == p && r.order == k).map_or(f64::NAN, |r| r.gamma);
            let paper = paper_at(k);
            let _ = write!(s, "{k} & {} & {} & {}", sig4(ours), sig4(paper), sig4(ours / paper));
            if has_lit {
                let _ = write!(s, " & {}", lit_at(k));
            }
            s.push_str(" \\\\\n");
        }
        s.push_str("\\bottomrule\n\\end{tabular}\n");
        if dagger {
            let _ = writeln!(
                s,
                "\\par\\footnotesize $^\\dagger$ full-order value from the paper (not recomputed here: $n > {FULL_ORDER_MAX_N}$)."
            );
        }
        s.push_str("\\end{table}\n\n");
    }
    s
}

/// `compare.tex`: ours vs the paper per plant and order.
pub fn compare_tex(rows: &[CompareRow]) -> String {
    let mut s = String::from("% hinfix vs Gumussoy, Millstone & Overton (2008)\n\\begin{tabular}{lrrrlrr}\n\\toprule\nplant & $n_K$ & ours & paper & literature & full order & ours/paper \\\\\n\\midrule\n");
    for r in rows {
        let lit =
            r.literature.iter().map(|(src, g)| format!("{} {}", escape(src), num(*g))).collect::<Vec<_>>().join("; ");
        let _ = writeln!(
            s,
            "{} & {} & {} & {} & {} & {} & {} \\\\",
            escape(&r.plant),
            r.order,
            num(r.ours),
            num(r.paper),
            if lit.is_empty() { "--".into() } else { lit },
            num(r.full_order),
            num(r.ratio)
        );
    }
    s.push_str("\\bottomrule\n\\end{tabular}\n");
    s
}
