//! Structured controllers (design::structure, docs/ALGORITHMS.md §1.1): fixed entries stay bit for
//! bit, the structured objective's gradient is that of the free entries, bad structure files are
//! named errors, and a design without a structure (or with every entry free) is exactly the
//! unstructured one.

mod common;

use std::cell::RefCell;
use std::path::PathBuf;
use std::rc::Rc;

use hinfix::design::{
    controller_to_x, ComponentCache, ControllerShape, Design, DesignObjective, DesignOptions, DesignOutcome,
    ObjectivePhase, Structure,
};
use hinfix::lti::{resolve_plant, Controller, Plant};
use hinfix::optim::Objective;

fn plant(name: &str) -> Plant {
    Plant::load(resolve_plant(name).unwrap()).unwrap()
}

fn opts(order: usize, seed: u64) -> DesignOptions {
    DesignOptions { order, seed, cpumax: 30.0, maxevals: Some(1500), ..Default::default() }
}

fn design(p: &Plant, o: &DesignOptions, s: Option<&Structure>) -> DesignOutcome {
    Design::for_plant(p, o).structure(s).run().unwrap()
}

/// Every fixed entry of `k` is bit for bit the structure's value.
fn assert_fixed_kept(s: &Structure, k: &Controller) {
    let x = controller_to_x(k);
    for (i, e) in s.entries().iter().enumerate() {
        if let Some(v) = e {
            assert_eq!(x[i].to_bits(), v.to_bits(), "entry {i} of x: {} instead of {v}", x[i]);
        }
    }
    assert_eq!(s.violation(k), None);
}

fn bits(k: &Controller) -> Vec<u64> {
    controller_to_x(k).iter().map(|v| v.to_bits()).collect()
}

fn temp_file(name: &str, text: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("hinfix-structure-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// A static gain (order 0) on AC8 with zeros and one non-zero fixed value in Dk.
#[test]
fn a_static_gain_keeps_its_fixed_entries() {
    let p = plant("AC8");
    let shape = ControllerShape::for_plant(&p, 0);
    let (m, q) = (shape.m, shape.p);
    assert!(q >= 3, "AC8 has {q} measurements");
    // Dk(1, j): free for even j, 0.0 for odd j; Dk(i > 1, ·) free; Dk(1, 1) fixed at 0.125.
    let row = |i: usize| {
        (0..q)
            .map(|j| match (i, j) {
                (0, 0) => "0.125".to_string(),
                (0, j) if j % 2 == 1 => "0.0".to_string(),
                _ => "null".to_string(),
            })
            .collect::<Vec<_>>()
            .join(", ")
    };
    let rows: Vec<String> = (0..m).map(|i| format!("[{}]", row(i))).collect();
    let path = temp_file("ac8-static.json", &format!(r#"{{"DK": [{}]}}"#, rows.join(", ")));
    let s = Structure::load(&path, shape).unwrap();
    assert!(s.nfree() < shape.nvar() && s.nfree() > 0);
    let o = design(&p, &opts(0, 1), Some(&s));
    assert_fixed_kept(&s, &o.controller);
    assert!(o.gamma.is_finite() || o.gamma == f64::INFINITY);
}

/// An order-2 PID-like mask on HE1: Ak fixed diagonal (a slow pole for the integral action, a
/// derivative filter pole), Bk free, Ck's off-diagonal pattern fixed at 0, Dk free.
#[test]
fn an_order_two_pid_like_mask_keeps_its_fixed_entries() {
    let p = plant("HE1");
    let shape = ControllerShape::for_plant(&p, 2);
    let (m, q) = (shape.m, shape.p);
    let free_row = |n: usize| format!("[{}]", vec!["null"; n].join(", "));
    let ck: Vec<String> = (0..m).map(|i| if i == 0 { "[null, 0.0]".into() } else { "[0.0, null]".into() }).collect();
    let text = format!(
        r#"{{"AK": [[-0.01, 0.0], [0.0, -10.0]], "BK": [{b}, {b}], "CK": [{ck}], "DK": [{d}]}}"#,
        b = free_row(q),
        ck = ck.join(", "),
        d = (0..m).map(|_| free_row(q)).collect::<Vec<_>>().join(", ")
    );
    let path = temp_file("he1-pid.json", &text);
    let s = Structure::load(&path, shape).unwrap();
    let o = design(&p, &opts(2, 2), Some(&s));
    assert_fixed_kept(&s, &o.controller);
    assert!(o.gamma.is_finite(), "HE1 with a PID-like structure: {:?}, γ = {}", o.status, o.gamma);
}

/// A block-diagonal (decentralised) order-2 mask on HE1 (m2 = 2 controls): controller state i
/// sees only measurement i-ish and drives only control i.
#[test]
fn a_block_diagonal_mask_keeps_its_fixed_entries() {
    let p = plant("HE1");
    let shape = ControllerShape::for_plant(&p, 2);
    let entries: Vec<Option<f64>> = {
        let mut e = vec![None; shape.nvar()];
        let (nk, m, q) = (shape.nk, shape.m, shape.p);
        // Ak off-diagonal
        e[1] = Some(0.0);
        e[2] = Some(0.0);
        // Ck (m × nk, column-major at nk² + nk·q): Ck(i, j) = 0 for i ≠ j
        let ck0 = nk * nk + nk * q;
        for j in 0..nk {
            for i in 0..m {
                if i != j {
                    e[ck0 + i + j * m] = Some(0.0);
                }
            }
        }
        e
    };
    let s = Structure::from_entries(shape, entries).unwrap();
    let o = design(&p, &opts(2, 1), Some(&s));
    assert_fixed_kept(&s, &o.controller);
    assert_eq!(o.controller.ak[(0, 1)].to_bits(), 0.0f64.to_bits());
}

/// The gradient of both objectives on the free entries of a structured order-1 controller on
/// HE1 agrees with central differences.
#[test]
fn the_structured_gradient_matches_finite_differences() {
    let p = plant("HE1");
    let shape = ControllerShape::for_plant(&p, 1);
    let mut entries = vec![None; shape.nvar()];
    entries[0] = Some(-2.0); // Ak fixed
    let last = shape.nvar() - 1;
    entries[last] = Some(0.0); // the last Dk entry fixed at 0
    let s = Rc::new(Structure::from_entries(shape, entries).unwrap());
    // a stabilising strongly stable point: the HE1 order-1 design projected onto the structure
    let o = Design::for_plant(&p, &opts(1, 1)).run().unwrap();
    let x_full = controller_to_x(&s.project(&o.controller));
    let x0 = s.restrict(&x_full);
    for (phase, strong, eps) in [
        (ObjectivePhase::Stabilisation, true, 1e-2),
        (ObjectivePhase::Performance, false, 0.0),
        (ObjectivePhase::Performance, true, 1e-3),
    ] {
        let cache = Rc::new(RefCell::new(ComponentCache::default()));
        let mut obj =
            DesignObjective::new(&p, shape, phase, strong, eps, 1e-12, cache).with_structure(Some(Rc::clone(&s)));
        assert_eq!(obj.nvar(), s.nfree());
        let worst = common::worst_fd_error(&mut obj, &x0, &format!("{phase:?}"));
        assert!(worst < 1e-5, "{phase:?} strong={strong}: worst relative error {worst:.2e}");
    }
}

/// Bad files: the error names the file and the block (and the entry where there is one).
#[test]
fn bad_structure_files_are_named_errors() {
    let shape = ControllerShape::for_plant(&plant("HE1"), 1); // Ak 1×1, Bk 1×1, Ck 2×1, Dk 2×1
    let cases = [
        ("wrong-shape.json", r#"{"DK": [[null, null]]}"#, vec!["block DK", "must be 2×1", "found 1 rows"]),
        ("wrong-row.json", r#"{"CK": [[null, 1.0], [null]]}"#, vec!["block CK", "row 1 has 2 entries"]),
        ("string.json", r#"{"BK": [["free"]]}"#, vec!["block BK", "entry (1, 1)", "\"free\""]),
        ("unknown.json", r#"{"AK": [[null]], "EK": [[1.0]]}"#, vec!["unknown key \"EK\""]),
        ("not-json.json", r#"{"AK": [[null]"#, vec!["not valid JSON"]),
    ];
    for (name, text, needles) in cases {
        let path = temp_file(name, text);
        let msg = Structure::load(&path, shape).unwrap_err().to_string();
        assert!(msg.contains(&path.display().to_string()), "{name}: {msg}");
        for n in needles {
            assert!(msg.contains(n), "{name}: {msg:?} lacks {n:?}");
        }
    }
    let missing = std::env::temp_dir().join("hinfix-structure-no-such-file.json");
    let msg = Structure::load(&missing, shape).unwrap_err().to_string();
    assert!(msg.contains("hinfix-structure-no-such-file.json"), "{msg}");
    // a structure of another order is refused by the run, not silently used
    let p = plant("HE1");
    let s2 = Structure::all_free(ControllerShape::for_plant(&p, 2));
    let err = Design::for_plant(&p, &opts(1, 1)).structure(Some(&s2)).run();
    assert!(err.unwrap_err().to_string().contains("structure"));
}

/// Without a structure, and with every entry free, the design is bit for bit `run`'s (same seed,
/// evaluation budget).
#[test]
fn no_structure_and_all_free_are_the_unstructured_design() {
    for (name, order) in [("HE1", 1), ("REA2", 2), ("AC8", 0)] {
        let p = plant(name);
        let o = opts(order, 3);
        let reference = Design::for_plant(&p, &o).run().unwrap();
        let none = design(&p, &o, None);
        let free = design(&p, &o, Some(&Structure::all_free(ControllerShape::for_plant(&p, order))));
        for (label, out) in [("no structure", &none), ("all free", &free)] {
            assert_eq!(bits(&out.controller), bits(&reference.controller), "{name} order {order}: {label}");
            assert_eq!(out.gamma.to_bits(), reference.gamma.to_bits(), "{name} order {order}: {label}");
            assert_eq!(out.evaluations, reference.evaluations, "{name} order {order}: {label}");
        }
    }
}

/// The worked examples of docs/ALGORITHMS.md §1.1 parse with the shapes they are written for.
#[test]
fn the_documented_examples_parse() {
    use hinfix::lti::TimeDomain;
    let shape = |nk, m, p| ControllerShape { nk, m, p, domain: TimeDomain::Continuous };
    let pid = r#"{"AK": [[0.0, 0.0], [0.0, -10.0]], "BK": [[1.0], [1.0]], "CK": [[null, null]], "DK": [[null]]}"#;
    let dec = r#"{"AK": [[null, 0.0], [0.0, null]], "BK": [[null, 0.0], [0.0, null]],
       "CK": [[null, 0.0], [0.0, null]], "DK": [[null, 0.0], [0.0, null]]}"#;
    let stat = r#"{"DK": [[null, 0.0, null], [0.0, null, 0.0]]}"#;
    let docs = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/ALGORITHMS.md")).unwrap();
    for (text, sh, nfree) in [(pid, shape(2, 1, 1), 3), (dec, shape(2, 2, 2), 8), (stat, shape(0, 2, 3), 3)] {
        assert!(docs.contains(text.lines().next().unwrap().trim()), "not in the docs: {text}");
        assert_eq!(Structure::from_json(text, "doc", sh).unwrap().nfree(), nfree, "{text}");
    }
}

/// `campaign design --structure`: a JSON and a .mat structure give controller files whose fixed
/// entries are their values; a bad file is an error naming the file and the block.
#[test]
fn the_cli_designs_with_a_structure_file() {
    use hinfix::lti::write_mat;
    let bin = env!("CARGO_BIN_EXE_campaign");
    let p = plant("HE1"); // m2 = 2, p2 = 1
    let shape = ControllerShape::for_plant(&p, 0);
    let json = temp_file("cli.json", r#"{"DK": [[null], [0.0]]}"#);
    let dk = faer::Mat::from_fn(2, 1, |i, _| if i == 0 { f64::NAN } else { 0.0 });
    let mat = temp_file("cli.mat", "");
    std::fs::write(&mat, write_mat(&[("DK", dk.as_ref())], "structure")).unwrap();
    for s_path in [&json, &mat] {
        let out = s_path.with_extension("K.json");
        let run = std::process::Command::new(bin)
            .args(["design", "--plant", "HE1", "--order", "0", "--maxevals", "300", "--structure"])
            .arg(s_path)
            .arg("--out")
            .arg(&out)
            .output()
            .unwrap();
        assert!(run.status.success(), "{}", String::from_utf8_lossy(&run.stderr));
        let k = Controller::load(&out).unwrap();
        let s = Structure::load(s_path, shape).unwrap();
        assert_fixed_kept(&s, &k);
    }
    let bad = temp_file("cli-bad.json", r#"{"DK": [[null, 1.0], [0.0]]}"#);
    let run = std::process::Command::new(bin)
        .args(["design", "--plant", "HE1", "--order", "0", "--maxevals", "300", "--structure"])
        .arg(&bad)
        .args(["--out", "/tmp/hinfix-structure-never-written.json"])
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(!run.status.success() && err.contains("cli-bad.json") && err.contains("block DK"), "{err}");
}

/// A structure that fixes all of DK at a matrix for which the loop is ill posed (I − DK·D22
/// singular) is refused before the search: every controller of it is, and the whole budget ran
/// before the design said it could not form a closed loop.
#[test]
fn a_fixed_dk_that_makes_every_loop_ill_posed_is_refused_at_once() {
    let text = std::fs::read_to_string(resolve_plant("HE1").unwrap()).unwrap();
    let mut v: serde_json::Value = serde_json::from_str(&text).unwrap();
    v["D22"] = serde_json::json!([[1.0, 0.0]]);
    let p = Plant::from_json_str(&v.to_string(), "he1_d22.json").unwrap();
    let shape = ControllerShape::for_plant(&p, 0);
    let path = temp_file("dk_singular.json", r#"{"DK": [[1.0], [0.0]]}"#);
    let s = Structure::load(&path, shape).unwrap();
    let e = Design::for_plant(&p, &opts(0, 0)).structure(Some(&s)).run().unwrap_err().to_string();
    assert!(e.contains("fixes every entry of DK") && e.contains("ill posed") && e.contains("HE1"), "{e}");
    // a DK that leaves the loop well posed designs as before
    let fine = temp_file("dk_fine.json", r#"{"DK": [[0.5], [0.0]]}"#);
    let s = Structure::load(&fine, shape).unwrap();
    assert!(Design::for_plant(&p, &opts(0, 0)).structure(Some(&s)).run().is_ok());
}
