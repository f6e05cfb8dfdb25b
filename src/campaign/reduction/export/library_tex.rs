//! `library.tex`: the whole campaign in one `longtable`, the table a paper prints for a library of
//! plants (needs `\usepackage{longtable}` and `\usepackage{booktabs}`). Per plant (sorted by
//! name, letter case ignored and digits compared as numbers: AC2 before AC10) its order n, its
//! full-order bound (marked where it is not computed here, `latex::full_order_mark`) and, for each
//! controller order the campaign ran, the best re-verified γ to 4 significant figures — one row
//! per objective the campaign ran (plain, then strong; a plant's rows kept on one page), since a
//! column per order and objective made the table of orders 0–3 some 160 pt wider than an
//! article's text. `$^{\mathrm{u}}$` marks a best plain controller that is unstable; `n.s.` (not
//! stabilised) an entry whose jobs ran but gave no re-verified controller, `--` one no job ran.
//! A full-order value above the plant's best fixed-order γ is marked `$^{*}$`: it cannot be the
//! infimum over full-order controllers (every fixed-order controller is one), so it is the value
//! of a regularised problem (singular D12 or D21: AC1, AC12, AC18 and NN10 of COMPleib) or an
//! approximation, and the caption says so. The caption states the campaign (ε, seeds, budgets) and
//! every mark used; the header repeats on each page. Written whenever the campaign has a best row.

use std::collections::BTreeSet;
use std::fmt::Write as _;

use super::{Exporter, ReportData};
use crate::campaign::reduction::compare::FullOrderSource;
use crate::campaign::reduction::latex::{about_text, escape, full_order_mark, full_order_note, sig4};
use crate::design::ObjectiveKind;
use crate::lti::NORM_TIE_RTOL;

/// `library.tex`.
pub struct LibraryTex;

impl Exporter for LibraryTex {
    fn file(&self) -> &'static str {
        "library.tex"
    }

    fn export(&self, data: &ReportData) -> Result<Option<Vec<u8>>, csv::Error> {
        Ok(library_tex(data).map(String::into_bytes))
    }
}

/// The mark of a plain entry whose best controller is unstable.
const UNSTABLE_MARK: &str = "$^{\\mathrm{u}}$";

/// The mark of a full-order value above the plant's best fixed-order γ (module docs).
const ABOVE_FIXED_ORDER_MARK: &str = "$^{*}$";

/// A sort key of a plant name: letter case folded, each run of digits a number (so `AC2` comes
/// before `AC10`); a run of digits sorts before text.
fn natural_key(name: &str) -> Vec<(bool, usize, String)> {
    let mut key: Vec<(bool, usize, String)> = Vec::new();
    for c in name.chars().flat_map(char::to_lowercase) {
        let digit = c.is_ascii_digit();
        match key.last_mut() {
            Some((text, _, run)) if *text != digit => run.push(c),
            _ => key.push((!digit, 0, c.to_string())),
        }
    }
    for (text, len, run) in &mut key {
        if !*text {
            // a number: compared by its length without leading zeros, then by its digits
            *run = run.trim_start_matches('0').to_string();
            *len = run.len();
        }
    }
    key
}

/// `library.tex` of `data`; `None` without best rows.
fn library_tex(data: &ReportData) -> Option<String> {
    if data.best.is_empty() {
        return None;
    }
    // the entries the campaign ran: (plant fingerprint, n_K, objective)
    let ran: BTreeSet<(&str, usize, &str)> =
        data.records.iter().map(|r| (r.plant_fingerprint.as_str(), r.order, r.options.objective.name())).collect();
    let orders: BTreeSet<usize> = ran.iter().map(|e| e.1).collect();
    let objectives: Vec<ObjectiveKind> = [ObjectiveKind::Plain, ObjectiveKind::Strong]
        .into_iter()
        .filter(|o| ran.iter().any(|e| e.2 == o.name()))
        .collect();
    let mut plants: Vec<(&str, &str)> =
        data.best.iter().map(|b| (b.plant.as_str(), b.plant_fingerprint.as_str())).collect();
    plants.sort_by_cached_key(|&(name, fp)| (natural_key(name), name, fp));
    plants.dedup();

    let both = objectives.len() > 1;
    let columns = 3 + usize::from(both) + orders.len();
    // the objective column needs no head: its cells say `plain` and `strong`
    let mut head = String::from(if both { "plant & $n$ & full order &" } else { "plant & $n$ & full order" });
    for k in &orders {
        let _ = write!(head, " & $n_K = {k}$");
    }

    let mut rows = String::new();
    let mut any_above = false;
    for (i, (name, fp)) in plants.into_iter().enumerate() {
        let full = data.full.iter().find(|f| f.plant == name);
        let n = full.and_then(|f| f.n).map_or("--".to_string(), |n| n.to_string());
        let lowest = data
            .best
            .iter()
            .filter(|b| b.plant_fingerprint == fp && b.job_id.is_some())
            .map(|b| b.gamma)
            .fold(f64::INFINITY, f64::min);
        let full_order = full.map_or("--".to_string(), |f| {
            let above = f.gamma > lowest * (1.0 + NORM_TIE_RTOL);
            any_above |= above;
            let mark = if above { ABOVE_FIXED_ORDER_MARK } else { "" };
            format!("{}{}{mark}", sig4(f.gamma), full_order_mark(f.source))
        });
        if both && i > 0 {
            rows.push_str("\\addlinespace\n");
        }
        for (j, &o) in objectives.iter().enumerate() {
            if j == 0 {
                let _ = write!(rows, "{} & {n} & {full_order}", escape(name));
            } else {
                rows.push_str(" & &");
            }
            if both {
                let _ = write!(rows, " & {}", o.name());
            }
            for &k in &orders {
                let best = data
                    .best
                    .iter()
                    .find(|b| b.plant_fingerprint == fp && b.order == k && b.objective == o && b.job_id.is_some());
                let cell = match best {
                    Some(b) if b.controller_stable == Some(false) => format!("{}{UNSTABLE_MARK}", sig4(b.gamma)),
                    Some(b) => sig4(b.gamma),
                    None if ran.contains(&(fp, k, o.name())) => "n.s.".into(),
                    None => "--".into(),
                };
                let _ = write!(rows, " & {cell}");
            }
            // a plant's rows stay on one page
            rows.push_str(if j + 1 < objectives.len() { " \\\\*\n" } else { " \\\\\n" });
        }
    }

    let objective_text: Vec<String> = objectives
        .iter()
        .map(|o| match o {
            ObjectiveKind::Plain => format!("plain: $K$ may be unstable ({UNSTABLE_MARK}: the best $K$ is unstable)"),
            ObjectiveKind::Strong => "strong: $K$ stable".into(),
        })
        .collect();
    let mut notes: Vec<String> = [FullOrderSource::Paper, FullOrderSource::LibraryIndex]
        .into_iter()
        .filter(|s| data.full.iter().any(|f| f.source == *s))
        .filter_map(full_order_note)
        .collect();
    if any_above {
        notes.push(format!("{ABOVE_FIXED_ORDER_MARK} above a fixed-order $\\gamma$ of the plant, so not the infimum over full-order controllers: the value of a regularised problem (singular $D_{{12}}$ or $D_{{21}}$) or an approximation."));
    }
    let caption = format!(
        "Best closed-loop $H_\\infty$ norm $\\gamma$ of a re-verified controller per plant and controller order $n_K$ found by {}; {}. $n$: the plant's order; full order: the optimal $\\gamma$ of a full-order controller (any order, $K$ may be unstable), computed here unless marked. n.s.\\ (not stabilised): jobs ran, but none gave a re-verified controller; --: no job ran.{}",
        about_text(&data.about),
        objective_text.join("; "),
        notes.iter().map(|n| format!(" {n}")).collect::<String>()
    );
    let mut s = format!(
        "% hinfix: best γ per plant and controller order (re-verified), one longtable;\n% needs \\usepackage{{longtable}} and \\usepackage{{booktabs}}\n\\begingroup\n\\footnotesize\n\\setlength{{\\tabcolsep}}{{3pt}}\n\\begin{{longtable}}{{lrr{}{}}}\n",
        if both { "l" } else { "" },
        "r".repeat(orders.len())
    );
    let _ = write!(
        s,
        "\\caption{{{caption}}}\\label{{tab:hinfix-library}} \\\\\n\\toprule\n{head} \\\\\n\\midrule\n\\endfirsthead\n\\caption[]{{(continued)}} \\\\\n\\toprule\n{head} \\\\\n\\midrule\n\\endhead\n\\midrule\n\\multicolumn{{{columns}}}{{r}}{{continued on the next page}} \\\\\n\\endfoot\n\\bottomrule\n\\endlastfoot\n{rows}\\end{{longtable}}\n\\endgroup\n"
    );
    Some(s)
}

#[cfg(test)]
mod tests {
    use super::super::snapshots::with_fixture;
    use super::*;

    /// An entry whose jobs gave no verified controller is "n.s.", one never run "--"; a
    /// full-order value from the library index is marked ‡ and the caption says what that is.
    #[test]
    fn entries_without_a_controller_and_index_values_are_marked() {
        let tex = with_fixture(|mut data| {
            let plain = data.best.iter_mut().find(|b| b.objective == ObjectiveKind::Plain).unwrap();
            (plain.gamma, plain.job_id, plain.controller_stable) = (f64::NAN, None, None);
            data.full[0].source = FullOrderSource::LibraryIndex;
            library_tex(&data).unwrap()
        });
        let rows = "\nHE1 & 4 & 0.07362$^\\ddagger$ & plain & n.s. \\\\*\n & & & strong & 0.1270 \\\\\n\\addlinespace\nHE1-twice & -- & -- & plain & -- \\\\*\n & & & strong & 0.1245 \\\\\n";
        assert!(tex.contains(rows), "{tex}");
        assert!(tex.contains("$^\\ddagger$ full-order value from the plant library's index"), "{tex}");
        assert!(!tex.contains("dagger$ full-order value from the paper"), "{tex}");
        assert!(with_fixture(|mut data| {
            data.best.clear();
            library_tex(&data)
        })
        .is_none());
    }

    /// A full-order value above the plant's best fixed-order γ is marked and explained; one at or
    /// below it is not.
    #[test]
    fn a_full_order_value_above_a_fixed_order_one_is_marked() {
        let tex = with_fixture(|mut data| {
            data.full[0].gamma = 1.0; // HE1's best rows: 0.1155 (plain), 0.1270 (strong)
            library_tex(&data).unwrap()
        });
        assert!(tex.contains("\nHE1 & 4 & 1.000$^{*}$ & plain"), "{tex}");
        assert!(tex.contains("$^{*}$ above a fixed-order $\\gamma$ of the plant, so not the infimum"), "{tex}");
        let tex = with_fixture(|data| library_tex(&data).unwrap());
        assert!(!tex.contains("$^{*}$"), "{tex}");
    }

    #[test]
    fn plants_sort_by_name_with_numbers_as_numbers() {
        let mut names = vec!["AC10", "ac2", "AC1", "CM1_IS", "AC02x", "Enns", "CM1", "AC2"];
        names.sort_by_cached_key(|n| (natural_key(n), *n));
        assert_eq!(names, ["AC1", "AC2", "ac2", "AC02x", "AC10", "CM1", "CM1_IS", "Enns"]);
    }
}
