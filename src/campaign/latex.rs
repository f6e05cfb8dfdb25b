//! LaTeX (booktabs) rendering of the campaign tables: `tables.tex` (the paper's layout: per
//! plant, n_K and γ, full-order row first) and `compare.tex`.

use std::fmt::Write as _;

use super::report::{CompareRow, FullOrderRow};
use super::reduce::BestRow;

/// Escapes LaTeX specials (`\ & % $ # _ { } ~ ^`) and drops control characters (a newline or
/// NUL in a name must not end a table row or break the file).
pub fn escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            c if c.is_control() => {}
            '\\' => out.push_str("\\textbackslash{}"),
            '&' | '%' | '$' | '#' | '_' | '{' | '}' => {
                out.push('\\');
                out.push(c);
            }
            '~' => out.push_str("\\textasciitilde{}"),
            '^' => out.push_str("\\textasciicircum{}"),
            _ => out.push(c),
        }
    }
    out
}

/// γ to 4 decimals, `--` when not finite.
pub fn num(x: f64) -> String {
    if x.is_finite() { format!("{x:.4}") } else { "--".into() }
}

/// `tables.tex`: one booktabs tabular per plant; the full-order row first ("full", with a dagger
/// when the value is the paper's rather than computed here).
pub fn tables_tex(best: &[BestRow], full: &[FullOrderRow]) -> String {
    let mut s = String::from("% hinfix: best γ per controller order (re-verified); booktabs\n");
    let mut plants: Vec<&str> = best.iter().map(|r| r.plant.as_str()).collect();
    plants.dedup();
    for p in plants {
        let _ = writeln!(s, "\\begin{{tabular}}{{rr}}\n\\toprule\n\\multicolumn{{2}}{{c}}{{{}}} \\\\\n\\midrule\n$n_K$ & $\\gamma$ \\\\\n\\midrule", escape(p));
        if let Some(f) = full.iter().find(|f| f.plant == p) {
            let mark = if f.from_paper { "$^\\dagger$" } else { "" };
            let _ = writeln!(s, "full{mark} & {} \\\\", num(f.gamma));
        }
        for r in best.iter().filter(|r| r.plant == p) {
            let _ = writeln!(s, "{} & {} \\\\", r.order, num(r.gamma));
        }
        s.push_str("\\bottomrule\n\\end{tabular}\n\n");
    }
    s.push_str("% $^\\dagger$ full-order value from the paper (not recomputed: n > 60)\n");
    s
}

/// `compare.tex`: ours vs the paper per plant and order.
pub fn compare_tex(rows: &[CompareRow]) -> String {
    let mut s = String::from("% hinfix vs Gumussoy, Millstone & Overton (2008)\n\\begin{tabular}{lrrrlrr}\n\\toprule\nplant & $n_K$ & ours & paper & literature & full order & ours/paper \\\\\n\\midrule\n");
    for r in rows {
        let lit = r.literature.iter().map(|(src, g)| format!("{} {}", escape(src), num(*g))).collect::<Vec<_>>().join("; ");
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
