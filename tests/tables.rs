//! `tables.tex` in the paper's layout: 4 significant figures, captions and labels, † only when
//! used, a literature column only for plants with literature values; it and `compare.tex`
//! compile with pdflatex.

use std::path::Path;

use hinfix::campaign::BestRow;
use hinfix::campaign::{compare_rows, FullOrderRow, FullOrderSource};
use hinfix::campaign::{compare_tex, sig4, sig_figs, tables_tex, tables_tex_about, CampaignAbout};
use hinfix::campaign::{load_reference, ReferenceRow, PAPER_PLANT_FINGERPRINTS, REFERENCE_CSV};
use hinfix::design::ObjectiveKind;

mod common;

/// Reference values are matched by plant content, not name (`PAPER_PLANT_FINGERPRINTS`). The
/// plants these tests use are not shipped, so [`reference`] files their rows under two shipped
/// plants (their own rows dropped), and [`row`] gives PA and ZerenOzbay those plants'
/// fingerprints: the table shows our label with the paper's values of that content.
const STAND_INS: [(&str, &str); 2] = [("PA", "CM4"), ("ZerenOzbay", "HF1")];

fn fingerprint(label: &str) -> String {
    match STAND_INS.iter().find(|(l, _)| *l == label) {
        Some((_, shipped)) => {
            PAPER_PLANT_FINGERPRINTS.iter().find(|(n, _)| n == shipped).map(|(_, fp)| fp.to_string()).unwrap()
        }
        None => format!("fp-{label}"),
    }
}

fn reference() -> Vec<ReferenceRow> {
    let rows = load_reference(&Path::new(env!("CARGO_MANIFEST_DIR")).join(REFERENCE_CSV)).unwrap();
    rows.into_iter()
        .filter(|r| !STAND_INS.iter().any(|(_, shipped)| r.plant == *shipped))
        .map(|mut r| {
            if let Some((_, shipped)) = STAND_INS.iter().find(|(l, _)| r.plant == *l) {
                r.plant = shipped.to_string();
            }
            r
        })
        .collect()
}

fn row(plant: &str, order: usize, gamma: f64) -> BestRow {
    BestRow {
        gamma,
        job_id: Some("j".into()),
        eps: Some(1e-3),
        seed: Some(0),
        runs: 2,
        verified: 1,
        near_best: 1,
        failed: 1,
        ..BestRow::new(plant.into(), fingerprint(plant), order)
    }
}

#[test]
fn four_significant_figures_not_four_decimals() {
    assert_eq!(sig_figs(0.00035, 4), "0.0003500");
    assert_eq!(sig_figs(34.81, 4), "34.81");
    assert_eq!(sig_figs(1.36957, 4), "1.370");
    assert_eq!(sig_figs(9.99996, 4), "10.00");
    assert_eq!(sig_figs(12345.6, 4), "12346");
    assert_eq!(sig_figs(-0.123449, 4), "-0.1234");
    assert_eq!(sig4(1e-6), "$1.000\\times10^{-6}$");
    assert_eq!(sig4(f64::NAN), "--");
    assert_eq!(sig4(0.07362), "0.07362");
}

#[test]
fn paper_layout_with_literature_only_where_there_is_some_and_dagger_only_when_used() {
    let reference = reference();
    let best = vec![
        row("PA", 1, 0.000351),
        row("PA", 2, 0.0003498),
        row("ZerenOzbay", 3, 35.0),
        row("ZerenOzbay", 5, 34.9),
        row("My_Plant", 1, 2.5),
    ];
    let computed = |plant: &str, gamma| FullOrderRow {
        plant: plant.into(),
        n: None,
        gamma,
        source: FullOrderSource::Computed,
        controller_stable: None,
    };
    let full = vec![computed("PA", 1e-6), computed("ZerenOzbay", 34.24)];
    let tex = tables_tex(&best, &full, &reference);
    let block = |p: &str| {
        let start = tex.find(&format!("\\label{{tab:hinfix-{p}")).unwrap_or_else(|| panic!("no label for {p}:\n{tex}"));
        let end = start + tex[start..].find("\\end{table}").unwrap();
        tex[start..end].to_string()
    };
    let pa = block("PA");
    assert!(pa.contains("2 & 0.0003498 & 0.0003500 & 0.9994"), "{pa}");
    assert!(!pa.contains("literature"), "PA has no literature values:\n{pa}");
    assert!(pa.contains("full order ($n_K = 5$, stable $K$) & $1.000\\times10^{-6}$"), "{pa}");
    let zo = block("ZerenOzbay");
    assert!(zo.contains("& literature"), "{zo}");
    assert!(zo.contains("unstable $K$"), "the paper's full-order controller of ZerenOzbay is unstable:\n{zo}");
    assert!(zo.contains("10 & -- & -- & -- & 42.51 (Zeren-Ozbay 2000); 35.29 (Gumussoy-Ozbay 2005)"), "{zo}");
    let (i5, i3) = (zo.find("\n5 & ").unwrap(), zo.find("\n3 & ").unwrap());
    assert!(i5 < i3, "orders from the highest down, as in the paper");
    assert!(block("My-Plant-").contains("\\end{tabular}"), "labels keep only letters, digits and -");
    assert!(!tex.contains("tab:hinfix-My-Plant}"), "a changed name gets a hash, so My_Plant and My-Plant differ");
    assert!(tex.contains("\\caption{My\\_Plant: "), "names escaped in captions");
    assert_eq!(tex.matches("\\caption{").count(), 3);
    assert!(!tex.contains("dagger"), "no † when no value is the paper's");

    let with_paper = vec![FullOrderRow { source: FullOrderSource::Paper, ..computed("PA", 1e-6) }];
    let tex2 = tables_tex(&best[..2], &with_paper, &reference);
    assert_eq!(tex2.matches("$^\\dagger$").count(), 2, "one mark and its note:\n{tex2}");
    assert!(tex2.contains("full-order value from the paper (not computed here: $n > 60$, or the computation failed)"));
    // a value of the plant library's index: its own mark and note
    let with_index = vec![FullOrderRow { source: FullOrderSource::LibraryIndex, ..computed("PA", 1e-6) }];
    let tex3 = tables_tex(&best[..2], &with_index, &reference);
    assert_eq!(tex3.matches("$^\\ddagger$").count(), 2, "one mark and its note:\n{tex3}");
    assert!(tex3.contains("from the plant library's index (\\texttt{plants/compleib/INDEX.csv}"), "{tex3}");
    assert!(!tex3.contains("$^\\dagger$"), "{tex3}");

    // Both files compile.
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("tables.tex"), tables_tex(&best, &with_paper, &reference)).unwrap();
    std::fs::write(dir.path().join("compare.tex"), compare_tex(&compare_rows(&best, &full, &reference))).unwrap();
    common::latex_compiles(dir.path());
}

/// The paper's values (HIFOO and the literature it quotes) are of strong stabilisation: a plain
/// row of a paper plant has no paper value and no ratio, so it is never "above the paper".
#[test]
fn plain_rows_are_not_compared_with_the_paper() {
    let plain = |r: &BestRow| BestRow { objective: ObjectiveKind::Plain, gamma: r.gamma * 0.5, ..r.clone() };
    let (pa, zo) = (row("PA", 2, 0.0003498), row("ZerenOzbay", 10, 35.0));
    let rows = compare_rows(&[pa.clone(), plain(&pa), zo.clone(), plain(&zo)], &[], &reference());
    assert_eq!((rows[0].paper, rows[0].ratio > 0.99), (0.00035, true));
    assert_eq!(rows[2].literature.len(), 2, "{:?}", rows[2]);
    for plain in [&rows[1], &rows[3]] {
        assert!(plain.paper.is_nan() && plain.ratio.is_nan() && plain.literature.is_empty(), "{plain:?}");
    }
    let tex = compare_tex(&rows);
    assert!(tex.contains("PA & 2 & plain & 0.0002 & -- & -- & -- & --"), "{tex}");
}

/// A plant without a published reference gets the campaign layout: no paper columns, a caption
/// that describes the campaign, the columns a reader needs (n_K, objective, γ, ε, seed, ‖K‖∞,
/// α(A_K), CPU seconds), the full-order row as the unconstrained bound with its controller's
/// stability; both objectives on one (plant, n_K) add the side-by-side table.
#[test]
fn a_plant_of_ones_own_gets_the_campaign_layout_and_the_two_objectives_side_by_side() {
    let strong = |k: usize, g: f64| BestRow {
        k_hinf: Some(40.0),
        alpha_k: Some(-0.5),
        cpu_to_best_s: Some(12.34),
        controller_stable: Some(true),
        ..row("two_mass", k, g)
    };
    let plain = |k: usize, g: f64, stable: bool| BestRow {
        objective: ObjectiveKind::Plain,
        controller_stable: Some(stable),
        k_hinf: Some(if stable { 30.0 } else { f64::INFINITY }),
        alpha_k: Some(if stable { -0.1 } else { 0.3 }),
        ..strong(k, g)
    };
    let best = vec![strong(1, 3.0), plain(1, 2.5, false), strong(2, 2.6), plain(2, 2.6, true), strong(3, 2.55)];
    let full = vec![FullOrderRow {
        plant: "two_mass".into(),
        n: Some(4),
        gamma: 2.4,
        source: FullOrderSource::Computed,
        controller_stable: Some(false),
    }];
    let about = CampaignAbout {
        names: vec!["own".into()],
        eps: vec![1e-3, 1e-2],
        seeds: 3,
        cpumax: vec![20.0],
        jobs: 30,
        sampling_times: Default::default(),
    };
    let tex = tables_tex_about(&best, &full, &reference(), &about);
    assert!(
        !tex.contains("paper (HIFOO)")
            && !tex.contains("ours/paper")
            && !tex.contains("Gumussoy, Millstone \\& Overton (2008).}"),
        "{tex}"
    );
    assert!(
        tex.contains("\\texttt{own} (30 jobs: $\\varepsilon \\in \\{10^{-3}, 10^{-2}\\}$, 3 seeds, 20 CPU~s per job)"),
        "{tex}"
    );
    assert!(
        tex.contains(
            "$n_K$ & objective & $\\gamma$ & $\\varepsilon$ & seed & $\\|K\\|_\\infty$ & $\\alpha(A_K)$ & CPU s"
        ),
        "{tex}"
    );
    // the full-order row is a plain row; what it is, a note under the table (no multicolumn text
    // that widens the table past the page)
    assert!(tex.contains("full$^*$ & -- & 2.400 & -- & -- & -- & -- & -- \\\\\n\\midrule"), "{tex}");
    assert!(
        tex.contains(
            "\\end{tabular}\n\\par\\footnotesize $^*$ full order: the unconstrained bound $\\gamma = 2.400$ (any order, \
             $K$ may be unstable); its central $K$ at $1.01\\gamma$ is unstable."
        ),
        "{tex}"
    );
    assert!(!tex.contains("multicolumn"), "{tex}");
    assert!(tex.contains("1 & strong & 3.000 & $10^{-3}$ & 0 & 40.00 & -0.5000 & 12.3 \\\\"), "{tex}");
    assert!(tex.contains("1 & plain, $K$ unstable & 2.500 & $10^{-3}$ & 0 & $\\infty$ & 0.3000 & 12.3 \\\\"), "{tex}");
    // the side-by-side table: orders with both objectives only, ratio strong/plain
    let side = &tex[tex.find("strong-vs-plain").expect("a side-by-side table")..];
    assert!(side.contains("1 & 2.500 & unstable & 3.000 & 1.200 \\\\"), "{side}");
    assert!(side.contains("2 & 2.600 & stable & 2.600 & 1.000 \\\\"), "{side}");
    assert!(!side.contains("\n3 & "), "{side}");
    assert_eq!(hinfix::campaign::cost_rows(&best).len(), 2);
    let dir = tempfile::tempdir().unwrap();
    std::fs::write(dir.path().join("tables.tex"), &tex).unwrap();
    let compare = compare_tex(&compare_rows(&best, &full, &reference()));
    assert!(
        compare.contains("plant & $n_K$ & objective & ours") && compare.contains("two\\_mass & 1 & plain & 2.5000"),
        "{compare}"
    );
    assert!(
        !compare_tex(&compare_rows(&best[..1], &full, &reference())).contains("objective"),
        "one objective: old layout"
    );
    std::fs::write(dir.path().join("compare.tex"), compare).unwrap();
    common::latex_compiles(dir.path());
}
