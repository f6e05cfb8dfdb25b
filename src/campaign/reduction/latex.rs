//! LaTeX (booktabs) rendering of the campaign tables: `tables.tex` (the paper's layout: per
//! plant, the full-order bound, then per n_K ours, the paper's and the ratio) and `compare.tex`.

use crate::lti::TimeDomain;
use std::fmt::Write as _;

use super::compare::{
    cost_rows, CampaignAbout, CompareRow, CostRow, FullOrderRow, FullOrderSource, FULL_ORDER_CENTRAL_LEVEL,
    FULL_ORDER_MAX_N,
};
use super::reduce::BestRow;
use crate::campaign::leaves::reference::{RefMethod, ReferenceRow};
use crate::design::ObjectiveKind;

/// Escapes LaTeX specials and drops control characters: [`crate::campaign::leaves::sanitise::for_latex`], which
/// every LaTeX table uses (kept under this name too).
pub use crate::campaign::leaves::sanitise::for_latex as escape;

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

/// The mark of a full-order value not computed here: † the paper's, ‡ the plant library's index
/// (`FullOrderSource`); none for a computed one.
pub(crate) fn full_order_mark(source: FullOrderSource) -> &'static str {
    match source {
        FullOrderSource::Paper => "$^\\dagger$",
        FullOrderSource::LibraryIndex => "$^\\ddagger$",
        FullOrderSource::Computed | FullOrderSource::Unavailable => "",
    }
}

/// What the mark of [`full_order_mark`] says, as a sentence for under a table or a caption;
/// `None` for an unmarked value.
pub(crate) fn full_order_note(source: FullOrderSource) -> Option<String> {
    let why = format!("not computed here: $n > {FULL_ORDER_MAX_N}$, or the computation failed");
    match source {
        FullOrderSource::Paper => Some(format!("$^\\dagger$ full-order value from the paper ({why}).")),
        FullOrderSource::LibraryIndex => Some(format!(
            "$^\\ddagger$ full-order value from the plant library's index (\\texttt{{plants/compleib/INDEX.csv}}; {why}): for a singular plant (regularised) or where SLICOT's SB10AD controller gave it, an upper bound of the full-order infimum, for some plants an approximate one."
        )),
        FullOrderSource::Computed | FullOrderSource::Unavailable => None,
    }
}

/// A LaTeX `\label` key part: ASCII letters and digits kept, everything else `-`, with a short
/// hash when that changed the name (`sanitise::as_key`), so two plants never share a label.
fn label_key(name: &str) -> String {
    crate::campaign::leaves::sanitise::as_key(name, |c| c.is_ascii_alphanumeric(), '-', 64)
}

/// The opening of a table float: `\begin{table}`, its caption, its label `tab:hinfix-<label>`,
/// and a booktabs `tabular` of columns `cols` with the header row `head`.
fn table_start(caption: &str, label: &str, cols: &str, head: &str) -> String {
    format!(
        "\\begin{{table}}[!htbp]\n\\centering\n\\caption{{{caption}}}\n\\label{{tab:hinfix-{label}}}\n\\begin{{tabular}}{{{cols}}}\n\\toprule\n{head} \\\\\n\\midrule\n"
    )
}

/// `rows` by order, highest first (a stable sort: rows of one order keep their order).
fn highest_order_first<'a, R>(rows: &[&'a R], order: impl Fn(&R) -> usize) -> Vec<&'a R> {
    let mut sorted = rows.to_vec();
    sorted.sort_by_key(|r| std::cmp::Reverse(order(*r)));
    sorted
}

/// `tables.tex`, in the layout of the paper's tables: one `table` per plant with a caption and a
/// `\label{tab:hinfix-<plant>}`; first the full-order bound (computed here, or the paper's value
/// marked † — ‡ for the plant library's —, with whether the paper's full-order controller is
/// stable), then per n_K from the highest down: our best re-verified γ, the paper's HIFOO γ and
/// ours/paper. Plants for which the reference table has values from earlier literature get a
/// literature column (their orders appear as rows of their own when we have no result there).
/// 4 significant figures throughout.
///
/// A plant without a published reference (no row of `reference` is its), or one the campaign ran
/// only with the plain objective, gets the campaign layout instead ([`campaign_table`]); a plant
/// with best rows of both objectives at some n_K also gets the side-by-side table of the two
/// ([`cost_table`]). The same as [`tables_tex_about`] with nothing known of the campaign.
pub fn tables_tex(best: &[BestRow], full: &[FullOrderRow], reference: &[ReferenceRow]) -> String {
    tables_tex_about(best, full, reference, &CampaignAbout::default())
}

/// [`tables_tex`], with the campaign's facts for the captions of the campaign layout.
pub fn tables_tex_about(
    best: &[BestRow],
    full: &[FullOrderRow],
    reference: &[ReferenceRow],
    about: &CampaignAbout,
) -> String {
    let mut s = String::from("% hinfix: best γ per controller order (re-verified) in the layout of\n% Gumussoy, Millstone & Overton (2008); needs \\usepackage{booktabs}\n");
    let mut plants: Vec<(&str, &str)> = best.iter().map(|r| (r.plant.as_str(), r.plant_fingerprint.as_str())).collect();
    plants.dedup();
    let costs = cost_rows(best);
    for (p, fp) in plants {
        let strong: Vec<BestRow> =
            best.iter().filter(|r| r.plant == p && r.objective == ObjectiveKind::Strong).cloned().collect();
        let f = full.iter().find(|f| f.plant == p);
        if !reference.iter().any(|r| r.is_for(fp)) || strong.is_empty() {
            let rows: Vec<&BestRow> = best.iter().filter(|r| r.plant == p).collect();
            s.push_str(&campaign_table(p, fp, &rows, f, about));
        } else {
            s.push_str(&paper_table(p, fp, &strong, f, reference));
        }
        let cost: Vec<&CostRow> = costs.iter().filter(|c| c.plant == p).collect();
        if !cost.is_empty() {
            s.push_str(&cost_table(p, &cost));
        }
        let several: Vec<&BestRow> = best.iter().filter(|r| r.plant == p && !r.plants.is_empty()).collect();
        if !several.is_empty() {
            s.push_str(&plants_table(p, &several));
        }
    }
    s
}

/// The plants of a problem of several plants (`rows`: its best rows with their plants' values):
/// per n_K (highest first) and design objective, each plant's objective, weight, bound, value
/// g_j and closed-loop stability measure for the row's best controller
/// (`tab:hinfix-<problem>-plants`).
pub fn plants_table(p: &str, rows: &[&BestRow]) -> String {
    let caption = format!(
        "{}: one controller for several plants. Per order $n_K$ and objective, each plant's objective $g_j$ (hinf: $\\|T_{{zw}}\\|_\\infty$, h2: $\\|T_{{zw}}\\|_2$, abscissa: $\\alpha(A_{{cl}})$, radius: $1/r_C$), weight $w_j$, bound $b_j$, value $g_j$ recomputed from the best re-verified controller, and its closed loop's stability measure; $\\gamma$ is the largest $w_j g_j$ of the plants without a bound.",
        escape(p)
    );
    let head = "$n_K$ & objective & plant & $g_j$ & $w_j$ & $b_j$ & value & stability";
    let mut s = table_start(&caption, &format!("{}-plants", label_key(p)), "rllllrrr", head);
    for r in highest_order_first(rows, |r| r.order) {
        for v in &r.plants {
            let bound = v.bound.map_or_else(|| "--".to_string(), sig4);
            let _ = writeln!(
                s,
                "{} & {} & {} & {} & {} & {bound} & {} & {} \\\\",
                r.order,
                r.objective.name(),
                escape(&v.plant),
                v.objective.name(),
                sig4(v.weight),
                sig4(v.value),
                sig4(v.alpha_cl)
            );
        }
    }
    s.push_str("\\bottomrule\n\\end{tabular}\n\\end{table}\n\n");
    s
}

/// One plant's table in the paper's layout (`best`: its strong rows).
fn paper_table(p: &str, fp: &str, best: &[BestRow], f: Option<&FullOrderRow>, reference: &[ReferenceRow]) -> String {
    let mut s = String::new();
    {
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
        let note = f.and_then(|f| full_order_note(f.source));
        let paper_full = refs(RefMethod::FullOrder).next();
        let caption = format!(
            "{}: closed-loop $H_\\infty$ norm $\\gamma$ of the best re-verified stable controller of each order $n_K$ (hinfix), against the HIFOO results of Gumussoy, Millstone \\& Overton (2008).",
            escape(p)
        );
        let (cols, head) = if has_lit { ("lrrrl", " & literature") } else { ("lrrr", "") };
        let head = format!("$n_K$ & ours & paper (HIFOO) & ours/paper{head}");
        s.push_str(&table_start(&caption, &label_key(p), cols, &head));
        if let Some(f) = f {
            let stab = match paper_full {
                Some(r) if r.controller_stable => ", stable $K$",
                Some(_) => ", unstable $K$",
                None => "",
            };
            let order = paper_full.map(|r| format!(" ($n_K = {}${stab})", r.order)).unwrap_or_default();
            let mark = full_order_mark(f.source);
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
        if let Some(note) = note {
            let _ = writeln!(s, "\\par\\footnotesize {note}");
        }
        s.push_str("\\end{table}\n\n");
    }
    s
}

/// ε in math mode: `10^{-3}` for a power of ten, else 4 significant figures.
fn eps_math(x: f64) -> String {
    let e = x.log10().round();
    if x > 0.0 && (10f64.powf(e) - x).abs() <= 1e-12 * x {
        format!("10^{{{}}}", e as i64)
    } else {
        sig4(x).trim_matches('$').to_string()
    }
}

/// ε for a table cell: [`eps_math`] in `$…$`.
fn eps_tex(x: f64) -> String {
    format!("${}$", eps_math(x))
}

/// A number that may be +∞ (‖K‖∞ of an unstable controller): `$\infty$`, else [`sig4`].
fn sig4_inf(x: f64) -> String {
    if x == f64::INFINITY {
        "$\\infty$".into()
    } else {
        sig4(x)
    }
}

/// The caption's account of the campaign: "the campaign `name` (N jobs: ε ∈ {…}, S seeds,
/// C CPU s per job)".
pub(crate) fn about_text(about: &CampaignAbout) -> String {
    if about.names.is_empty() {
        return "the campaign".into();
    }
    let names: Vec<String> = about.names.iter().map(|n| format!("\\texttt{{{}}}", escape(n))).collect();
    let eps: Vec<String> = about.eps.iter().map(|&e| eps_math(e)).collect();
    let cpu: Vec<String> =
        about.cpumax.iter().map(|&c| if c.is_finite() { format!("{c}") } else { "unbounded".into() }).collect();
    format!(
        "the campaign {} ({} jobs: $\\varepsilon \\in \\{{{}\\}}$, {} seed{}, {} CPU~s per job)",
        names.join(", "),
        about.jobs,
        eps.join(", "),
        about.seeds,
        if about.seeds == 1 { "" } else { "s" },
        cpu.join(" or ")
    )
}

/// One plant's table in the campaign layout, for a plant without a published reference: per n_K
/// (highest first) and objective the best re-verified controller's γ, its job's ε and seed,
/// ‖K‖∞, α(A_K), the CPU seconds its job took to reach it and the objective; first the full-order
/// row, the unconstrained bound, with whether its central controller is stable. A discrete-time
/// plant (its fingerprint `fp` in `about.sampling_times`) gets ρ(A_K) for α(A_K) and its sampling
/// time in the caption.
pub fn campaign_table(p: &str, fp: &str, rows: &[&BestRow], f: Option<&FullOrderRow>, about: &CampaignAbout) -> String {
    let ts = about.sampling_times.get(fp).copied();
    let (radius, domain) = match ts {
        None => ("spectral abscissa $\\alpha(A_K)$", String::new()),
        Some(ts) => {
            ("spectral radius $\\rho(A_K)$", format!(" (discrete time, $T_s = {}$~s)", crate::numeric::readable(ts)))
        }
    };
    // A problem's γ (several plants, or another objective, weight or bound) is not one plant's
    // ‖Tzw‖∞: its plants' table follows this one.
    let measure = if rows.iter().any(|r| !r.plants.is_empty()) {
        format!(
            "value $\\gamma$ of the problem (the largest $w_j g_j$ of its plants without a bound: Table~\\ref{{tab:hinfix-{}-plants}})",
            label_key(p)
        )
    } else {
        "closed-loop $H_\\infty$ norm $\\gamma$".to_string()
    };
    let caption = format!(
        "{}{domain}: {measure} of the best re-verified controller of each order $n_K$ found by {}; $\\varepsilon$ and seed of the job that found it, its $\\|K\\|_\\infty$ and {radius}, and the CPU seconds that job took to reach it. Objective strong: $K$ stable; plain: $K$ may be unstable.",
        escape(p),
        about_text(about)
    );
    let column = if ts.is_some() { "$\\rho(A_K)$" } else { "$\\alpha(A_K)$" };
    let head = format!("$n_K$ & objective & $\\gamma$ & $\\varepsilon$ & seed & $\\|K\\|_\\infty$ & {column} & CPU s");
    let mut s = table_start(&caption, &label_key(p), "rlrrrrrr", &head);
    // The full-order row holds only its number; what it is goes in a note under the table (a
    // multicolumn row with the text made the table 116–132 pt wider than the page).
    if let Some(f) = f {
        let _ = writeln!(
            s,
            "full$^*$ & -- & {}{} & -- & -- & -- & -- & -- \\\\\n\\midrule",
            sig4(f.gamma),
            full_order_mark(f.source)
        );
    }
    let mut sorted: Vec<&&BestRow> = rows.iter().collect();
    sorted.sort_by(|a, b| b.order.cmp(&a.order).then(a.objective.name().cmp(b.objective.name()).reverse()));
    for r in sorted {
        let objective = match (r.objective, r.controller_stable) {
            (ObjectiveKind::Plain, Some(false)) => "plain, $K$ unstable".to_string(),
            (o, _) => o.name().to_string(),
        };
        let opt = |x: Option<f64>| x.map_or("--".to_string(), sig4_inf);
        let _ = writeln!(
            s,
            "{} & {objective} & {} & {} & {} & {} & {} & {} \\\\",
            r.order,
            sig4(r.gamma),
            r.eps.map_or("--".into(), eps_tex),
            r.seed.map_or("--".into(), |x| x.to_string()),
            opt(r.k_hinf),
            // ρ(A_K) of a strongly stable controller is often within 1e-4 of 1: six decimals
            r.alpha_k.map_or("--".to_string(), |a| match ts {
                Some(ts) => format!("{:.6}", TimeDomain::Discrete { ts }.stability_quantity(a).1),
                None => sig4_inf(a),
            }),
            r.cpu_to_best_s.map_or("--".into(), |t| format!("{t:.1}"))
        );
    }
    s.push_str("\\bottomrule\n\\end{tabular}\n");
    if let Some(f) = f {
        let k = match f.controller_stable {
            Some(true) => format!("; its central $K$ at ${FULL_ORDER_CENTRAL_LEVEL}\\gamma$ is stable"),
            Some(false) => format!("; its central $K$ at ${FULL_ORDER_CENTRAL_LEVEL}\\gamma$ is unstable"),
            None => String::new(),
        };
        let _ = writeln!(
            s,
            "\\par\\footnotesize $^*$ full order: the unconstrained bound $\\gamma = {}$ (any order, $K$ may be unstable){k}.",
            sig4(f.gamma)
        );
        if let Some(note) = full_order_note(f.source) {
            let _ = writeln!(s, "\\par {note}");
        }
    }
    s.push_str("\\end{table}\n\n");
    s
}

/// The side-by-side table of the two objectives for one plant: per n_K, γ of the plain
/// objective and whether its controller is stable, γ of the strong one and their ratio (the
/// comparison of the paper's tables).
pub fn cost_table(p: &str, rows: &[&CostRow]) -> String {
    let rows = highest_order_first(rows, |r| r.order);
    let caption = format!(
        "{}: the cost of strong stabilisation. Per order $n_K$, the best re-verified $\\gamma$ without a stability requirement on $K$ (plain) and whether that $K$ is stable, the best with a stable $K$ (strong), and their ratio.",
        escape(p)
    );
    let head = "$n_K$ & $\\gamma$ plain & $K$ & $\\gamma$ strong & strong/plain";
    let mut s = table_start(&caption, &format!("{}-strong-vs-plain", label_key(p)), "rrlrr", head);
    for r in rows {
        let k = match r.plain_controller_stable {
            Some(true) => "stable",
            Some(false) => "unstable",
            None => "--",
        };
        let _ = writeln!(
            s,
            "{} & {} & {k} & {} & {} \\\\",
            r.order,
            sig4(r.gamma_plain),
            sig4(r.gamma_strong),
            sig4(r.ratio)
        );
    }
    s.push_str("\\bottomrule\n\\end{tabular}\n\\end{table}\n\n");
    s
}

/// `compare.tex`: ours vs the paper per plant and order; with an `objective` column after
/// n_K only when the rows have both objectives (a campaign of one objective keeps its layout).
pub fn compare_tex(rows: &[CompareRow]) -> String {
    let mixed = rows.iter().any(|r| r.objective != rows[0].objective);
    let (cols, head) = if mixed { ("lrlrrlrr", " & objective") } else { ("lrrrlrr", "") };
    let mut s = format!("% hinfix vs Gumussoy, Millstone & Overton (2008)\n\\begin{{tabular}}{{{cols}}}\n\\toprule\nplant & $n_K${head} & ours & paper & literature & full order & ours/paper \\\\\n\\midrule\n");
    for r in rows {
        let lit =
            r.literature.iter().map(|(src, g)| format!("{} {}", escape(src), num(*g))).collect::<Vec<_>>().join("; ");
        let objective = if mixed { format!(" & {}", r.objective.name()) } else { String::new() };
        let _ = writeln!(
            s,
            "{} & {}{objective} & {} & {} & {} & {} & {} \\\\",
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
