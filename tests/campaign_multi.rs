//! Campaign problems of several plants (`plants`, `objectives`, `weights`, `bounds`, `name`) and
//! with a controller structure (`structure`), campaigns/FORMAT.md "Several plants": the file
//! parses to jobs that carry the problem; each bad value is an error at its key; the ids of
//! single-plant campaigns are those of the builds before; a real two-plant run journals each
//! plant's value, which an independent recomputation confirms, and reports them in plants.csv and tables.tex.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::process::Command;

use hinfix::campaign::{expand, read_journal, Campaign, RunnerTag, SpecError};
use hinfix::design::{plant_values, PlantObjective};

mod common;

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

fn scratch(tag: &str) -> PathBuf {
    common::scratch("multi", tag)
}

/// A campaign in the example folder (so that `HE1_op*.json` resolve) with this problem body.
fn parse(problem: &str) -> Result<Campaign, SpecError> {
    let text = format!("name = \"t\"\n[defaults]\ncpumax = 5.0\n[[problem]]\n{problem}");
    Campaign::from_toml_str(&text, &Path::new(ROOT).join("examples/multi-model/t.toml"))
}

fn err(problem: &str) -> SpecError {
    parse(problem).expect_err("expected an error")
}

const THREE: &str = "plants = [\"HE1_op1.json\", \"HE1_op2.json\", \"HE1_op3.json\"]\n";

#[test]
fn plants_parse_to_jobs_that_carry_the_problem() {
    let c = parse(&format!(
        "{THREE}objectives = [\"hinf\", \"h2\", \"abscissa\"]\nweights = [1, 2.0, 0.5]\nbounds = [\"none\", 3.0, \"none\"]\n\
         orders = [1, 2]\nwarm_start = true\n"
    ))
    .unwrap();
    let p = &c.problems[0];
    assert_eq!(p.name, "HE1_op1+HE1_op2+HE1_op3", "the default name");
    let multi = p.multi.as_ref().expect("a problem of several plants");
    let got: Vec<_> = multi.terms.iter().map(|t| (t.plant.name.as_str(), t.objective, t.weight, t.bound)).collect();
    assert_eq!(
        got,
        [
            ("HE1_op1", PlantObjective::Hinf, 1.0, None),
            ("HE1_op2", PlantObjective::H2, 2.0, Some(3.0)),
            ("HE1_op3", PlantObjective::Abscissa, 0.5, None)
        ]
    );
    let jobs = expand(&c, RunnerTag::Design);
    assert_eq!(jobs.len(), 2);
    for j in &jobs {
        assert_eq!(j.plant_name, p.name);
        assert_eq!(j.plant_fingerprint, p.fingerprint);
        assert_ne!(j.plant_fingerprint, p.plant.fingerprint(), "a problem has a fingerprint of its own");
        assert_eq!(j.multi.as_ref().unwrap().terms.len(), 3);
        assert!(j.structure.is_none());
    }
    assert_eq!(jobs[1].warm_from.as_ref(), Some(&jobs[0].id), "warm starts chain the orders");
    // one value for every plant, and a name
    let c = parse(&format!("{THREE}name = \"HE1-3op\"\nobjectives = \"hinf\"\nweights = 1\norders = [1]\n")).unwrap();
    assert_eq!(c.problems[0].name, "HE1-3op");
    assert!(c.problems[0].multi.as_ref().unwrap().terms.iter().all(|t| t.objective == PlantObjective::Hinf));
    // `plant` with the default objective, weight and bound is today's problem
    let c = parse("plant = \"HE1_op2.json\"\norders = [1]\nobjectives = \"hinf\"\n").unwrap();
    assert!(c.problems[0].multi.is_none());
    assert_eq!(c.problems[0].fingerprint, c.problems[0].plant.fingerprint());
}

#[test]
fn bad_values_are_errors_at_their_key() {
    let cases: &[(&str, usize, &str)] = &[
        ("plant = \"HE1_op1.json\"\nplants = [\"HE1_op2.json\"]\norders = [1]\n", 6, "not both"),
        ("orders = [1]\n", 5, "needs plant"),
        ("plants = []\norders = [1]\n", 5, "at least one plant"),
        (&format!("{THREE}objectives = \"hinfinity\"\norders = [1]\n"), 6, "unknown objective"),
        (
            &format!("{THREE}objectives = [\"hinf\", \"h2\"]\norders = [1]\n"),
            6,
            "objectives lists 2 values for 3 plants",
        ),
        (&format!("{THREE}weights = [1.0, 1.0, 1.0, 1.0]\norders = [1]\n"), 6, "weights lists 4"),
        (
            &format!("{THREE}weights = [1.0, 0.0, 1.0]\norders = [1]\n"),
            6,
            "weight 0 must be a number from 1e-50 to 1e50",
        ),
        (&format!("{THREE}weights = -1\norders = [1]\n"), 6, "weights: plant 1"),
        (&format!("{THREE}bounds = [\"none\", inf, 1.0]\norders = [1]\n"), 6, "bound inf must be a finite number from"),
        (&format!("{THREE}bounds = \"loose\"\norders = [1]\n"), 6, "\"loose\" is not a number or \"none\""),
        (&format!("{THREE}name = \"\"\norders = [1]\n"), 6, "name must be non-empty"),
        ("plant = \"HE1_op1.json\"\nname = \"x\"\norders = [1]\n", 6, "name must be non-empty, and is for"),
        (&format!("{THREE}structure = \"nope.json\"\norders = [1]\n"), 6, "structure file"),
        (&format!("{THREE}orders = [9]\n"), 6, "order"),
        ("plants = [\"HE1_op1.json\", \"../../plants/REA2.json\"]\norders = [1]\n", 5, "plants: plant 2 (REA2)"),
        // one problem under two names (strong and plain): the report's rows could keep one
        (
            &format!("{THREE}name = \"s\"\norders = [1]\n[[problem]]\n{THREE}name = \"p\"\nobjective = \"plain\"\norders = [1]\n"),
            9,
            "is the problem at line 5 under another name (\"p\", there \"s\")",
        ),
    ];
    for (body, line, word) in cases {
        let e = err(body);
        assert_eq!(e.location.line, *line, "{body}\n→ {e}");
        assert!(e.to_string().contains(word), "{body}\n→ {e}");
        assert!(e.to_string().starts_with(&format!("{ROOT}/examples/multi-model/t.toml:{line}:")), "{e}");
    }
}

#[test]
fn a_structure_loads_for_every_order_and_enters_the_ids() {
    let dir = scratch("structure");
    // HE1 has 2 controls and 1 measurement: Dk is 2×1; AK, BK, CK left out are free
    std::fs::write(dir.join("dk.json"), r#"{"DK": [[null], [0.0]]}"#).unwrap();
    std::fs::write(dir.join("ak1.json"), r#"{"AK": [[null]]}"#).unwrap();
    let he1 = format!("{ROOT}/plants/HE1.json");
    let file = dir.join("c.toml");
    let load = |problem: &str| {
        Campaign::from_toml_str(&format!("name = \"t\"\n[[problem]]\nplant = \"{he1}\"\n{problem}"), &file)
    };
    let plain = load("orders = [1, 2]\n").unwrap();
    let structured = load("structure = \"dk.json\"\norders = [1, 2]\n").unwrap();
    let p = &structured.problems[0];
    let s = p.structure.as_ref().unwrap();
    assert_eq!(s.per_order.keys().copied().collect::<Vec<_>>(), [1, 2]);
    assert!(p.multi.is_none());
    let ids = |c: &Campaign| expand(c, RunnerTag::Design).into_iter().map(|j| j.id).collect::<BTreeSet<_>>();
    assert!(ids(&plain).is_disjoint(&ids(&structured)), "a structure makes other jobs");
    assert!(expand(&structured, RunnerTag::Design).iter().all(|j| j.structure.is_some()));
    let e = load("structure = \"ak1.json\"\norders = [1, 2]\n").unwrap_err();
    assert_eq!(e.location.line, 4, "{e}");
    assert!(e.to_string().contains("ak1.json") && e.to_string().contains("order 2"), "{e}");
}

/// The committed strong-stab journal's ids (results/strong-stab) are jobs of the campaign, and
/// the smoke campaign's first job keeps the id it had before problems of several plants (with
/// `bfgs_restart = 0`, the search of that build: a new default makes new ids, campaigns/FORMAT.md).
#[test]
fn single_plant_ids_are_unchanged() {
    let smoke = Path::new(ROOT).join("campaigns/smoke.toml");
    let text = std::fs::read_to_string(&smoke).unwrap().replacen("[defaults]\n", "[defaults]\nbfgs_restart = 0\n", 1);
    let c = Campaign::from_toml_str(&text, &smoke).unwrap();
    let jobs = expand(&c, RunnerTag::Design);
    assert_eq!(jobs[0].id.0, "5a2a5e20881c547a3dd986b6c3fe174905f396e5be9718e4d6c9a72c6d245468", "{}", jobs[0].label());
    let c = Campaign::load(&Path::new(ROOT).join("campaigns/strong-stab.toml")).unwrap();
    let journal = read_journal(&Path::new(ROOT).join("results/strong-stab/runs.jsonl")).unwrap();
    let ids: BTreeSet<_> = expand(&c, RunnerTag::Design).into_iter().map(|j| j.id).collect();
    // the journal holds the campaign's first 1609 jobs (the rest not run yet): each one a job of
    // today's expansion, so that a resume skips it
    let unknown = journal.records.iter().filter(|r| !ids.contains(&r.job_id)).count();
    assert!(journal.records.len() >= 1609, "{}", journal.records.len());
    assert_eq!(
        unknown,
        0,
        "{unknown} of {} journaled strong-stab jobs are not in the expansion",
        journal.records.len()
    );
}

/// Each plant's journaled value, of a real two-plant run (HE1 and HE1 at another operating
/// point, bounded by maxevals), is what `design::plant_values` recomputes from the journaled
/// controller; the report lists both in plants.csv.
#[test]
fn a_two_plant_run_journals_each_plants_value() {
    let dir = scratch("run");
    let text = format!(
        "name = \"two\"\n[defaults]\nseeds = 1\ncpumax = 60.0\nmaxevals = 2000\n[[problem]]\n\
         plants = [\"{ROOT}/plants/HE1.json\", \"{ROOT}/examples/multi-model/HE1_op3.json\"]\n\
         weights = [1.0, 2.0]\norders = [1]\n"
    );
    let file = common::campaign_file(&dir, &text);
    let out = Command::new(env!("CARGO_BIN_EXE_campaign"))
        .args(["run", file.to_str().unwrap(), "--results", dir.to_str().unwrap(), "--no-progress", "--trace", "off"])
        .output()
        .unwrap();
    assert!(out.status.success(), "campaign run failed: {}", String::from_utf8_lossy(&out.stderr));
    let journal = read_journal(&dir.join("two/runs.jsonl")).unwrap();
    assert_eq!(journal.records.len(), 1);
    let r = &journal.records[0];
    assert_eq!(r.plant, "HE1+HE1_op3");
    let outcome = r.outcome().expect("designed");
    assert_eq!(outcome.plants.len(), 2);
    // the line as JSON has them, and reads back to the same record
    let line = serde_json::to_value(r).unwrap();
    assert_eq!(line["plants"].as_array().map(Vec::len), Some(2));
    let back: hinfix::campaign::JobRecord = serde_json::from_value(line.clone()).unwrap();
    assert_eq!(serde_json::to_value(&back).unwrap(), line);
    let c = Campaign::load(&file).unwrap();
    let problem = c.problems[0].multi.as_ref().unwrap();
    let again = plant_values(problem, &outcome.controller, r.options.hinf_tol);
    for (j, v) in again.iter().zip(&outcome.plants) {
        assert_eq!((j.plant.as_str(), j.weight), (v.plant.as_str(), v.weight));
        assert!((j.value - v.value).abs() <= 1e-9 * v.value.abs(), "{j:?} vs {v:?}");
        assert!(v.alpha_cl < 0.0, "{v:?}");
    }
    assert_eq!(outcome.plants[1].weight, 2.0);
    let gamma = hinfix::design::problem_gamma(&again);
    assert!((outcome.gamma - gamma).abs() <= 1e-9 * gamma, "{} vs {gamma}", outcome.gamma);
    // the report: one best.csv row, two plants.csv rows
    let plants_csv = std::fs::read_to_string(dir.join("two/plants.csv")).unwrap();
    let lines: Vec<&str> = plants_csv.lines().collect();
    assert_eq!(lines.len(), 3, "{plants_csv}");
    assert!(
        lines[0].starts_with("problem,order,objective,job_id,plant,plant_objective,weight,bound,value"),
        "{plants_csv}"
    );
    assert!(lines[1].starts_with("HE1+HE1_op3,1,strong,") && lines[1].contains(",HE1,hinf,1,none,"), "{plants_csv}");
    // no bound: `bound_met` is none (the journal's null), not true
    assert_eq!(lines[1].split(',').nth(10), Some("none"), "{plants_csv}");
    let tex = std::fs::read_to_string(dir.join("two/tables.tex")).unwrap();
    assert!(
        tex.contains("one controller for several plants") && tex.contains("1 & strong & HE1\\_op3 & hinf & 2.000 &"),
        "{tex}"
    );
    // γ is the problem's largest weighted value, not an H∞ norm: the caption says so, and
    // points to the plants' table
    assert!(tex.contains("value $\\gamma$ of the problem") && tex.contains("\\ref{tab:hinfix-HE1-HE1-op3-"), "{tex}");
    assert!(!tex.contains("closed-loop $H_\\infty$ norm $\\gamma$"), "{tex}");
    common::latex_structure(&tex).unwrap();
    let best = std::fs::read_to_string(dir.join("two/best.csv")).unwrap();
    assert!(best.lines().nth(1).is_some_and(|l| l.starts_with("HE1+HE1_op3,")), "{best}");
}
