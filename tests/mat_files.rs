//! MATLAB .mat interchange: plants and controllers read from files written by an independent
//! writer (scipy.io.savemat, `tests/fixtures/mat/generate.py`; the tests need no Python), our own
//! writer read back, the same plant as .mat and JSON giving bit-identical designs, errors that
//! name the file and the variable, and the command line (`design --out K.mat`, `check
//! --controller K.mat`, `export`).

use std::path::{Path, PathBuf};
use std::process::Command;

use hinfix::design::{Design, DesignOptions};
use hinfix::lti::{controller_to_mat, plant_to_mat, read_mat_vars};
use hinfix::lti::{Controller, Plant};

const BIN: &str = env!("CARGO_BIN_EXE_campaign");

fn fixture(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/mat").join(name)
}

fn he1_json() -> Plant {
    Plant::load(Path::new(env!("CARGO_MANIFEST_DIR")).join("plants/HE1.json")).unwrap()
}

fn same_bits(a: &Plant, b: &Plant) {
    assert_eq!(a.dims, b.dims);
    for (x, y) in a.matrices().iter().zip(b.matrices()) {
        for j in 0..x.ncols() {
            for i in 0..x.nrows() {
                assert_eq!(x[(i, j)].to_bits(), y[(i, j)].to_bits(), "entry ({i}, {j})");
            }
        }
    }
    assert_eq!(a.fingerprint(), b.fingerprint());
}

#[test]
fn scipy_plant_files_equal_the_json_plant_bit_for_bit() {
    let json = he1_json();
    let mat = Plant::load(fixture("HE1.mat")).unwrap();
    assert_eq!(mat.name, "HE1", "the `name` char variable names the plant");
    same_bits(&json, &mat);
    let compressed = Plant::load(fixture("HE1_compressed.mat")).unwrap();
    assert_eq!(compressed.name, "HE1_compressed", "without `name`, the file stem names the plant");
    same_bits(&json, &compressed);
}

#[test]
fn same_plant_as_mat_and_json_gives_bit_identical_designs() {
    let json = he1_json();
    let mat = Plant::load(fixture("HE1.mat")).unwrap();
    // Short deterministic runs (iteration limits and the stall rule, not the CPU budget, end them).
    let opts = DesignOptions {
        order: 1,
        seed: 3,
        nrand: 1,
        maxit: 40,
        cpumax: 60.0,
        spend_budget: false,
        gradient_sampling: false,
        ..Default::default()
    };
    let a = Design::for_plant(&json, &opts).run().unwrap();
    let b = Design::for_plant(&mat, &opts).run().unwrap();
    assert_eq!(a.controller, b.controller);
    assert_eq!(a.gamma.to_bits(), b.gamma.to_bits());
    assert_eq!((a.iterations, a.evaluations), (b.iterations, b.evaluations));
}

#[test]
fn empty_blocks_are_zero_blocks_and_dims_are_inferred() {
    let p = Plant::load(fixture("empty_blocks.mat")).unwrap();
    assert_eq!((p.dims.n, p.dims.m1, p.dims.m2, p.dims.p1, p.dims.p2), (2, 1, 1, 0, 1));
    assert_eq!((p.d11.nrows(), p.d11.ncols()), (0, 1));
    assert_eq!((p.d22.nrows(), p.d22.ncols()), (1, 1));
    assert_eq!(p.d22[(0, 0)], 0.0);
    assert_eq!(p.d21[(0, 0)], 0.125);
    assert_eq!(p.a[(0, 1)], 2.0);
}

#[test]
fn scipy_controller_files_equal_their_json_twins() {
    for name in ["K2", "K0"] {
        let m = Controller::load(fixture(&format!("{name}.mat"))).unwrap();
        let j = Controller::load(fixture(&format!("{name}.json"))).unwrap();
        assert_eq!(m, j, "{name}");
    }
    assert_eq!(Controller::load(fixture("K0.mat")).unwrap().order(), 0);
}

#[test]
fn our_writer_reads_back_bit_for_bit() {
    let dir = tempfile::tempdir().unwrap();
    let k = Controller::load(fixture("K2.json")).unwrap();
    let path = dir.path().join("k.mat");
    k.save(&path).unwrap();
    assert_eq!(Controller::load(&path).unwrap(), k);
    assert_eq!(std::fs::read(&path).unwrap(), controller_to_mat(&k));
    let k0 = Controller::load(fixture("K0.json")).unwrap();
    k0.save(&path).unwrap();
    assert_eq!(Controller::load(&path).unwrap(), k0);
    let vars = read_mat_vars(&controller_to_mat(&k0)).unwrap();
    assert_eq!((vars["BK"].rows, vars["BK"].cols), (0, 2), "a static gain's BK keeps its 0×p shape");

    let p = he1_json();
    let pm = dir.path().join("HE1.mat");
    std::fs::write(&pm, plant_to_mat(&p)).unwrap();
    same_bits(&p, &Plant::load(&pm).unwrap());
}

#[test]
fn bad_files_name_the_file_and_the_variable() {
    let e = Plant::load(fixture("bad_missing_D22.mat")).unwrap_err().to_string();
    assert!(e.contains("bad_missing_D22.mat") && e.contains("matrix `D22` is missing"), "{e}");
    let e = Plant::load(fixture("bad_complex_A.mat")).unwrap_err().to_string();
    assert!(e.contains("variable `A` is complex"), "{e}");
    let e = Plant::load(fixture("bad_nan.mat")).unwrap_err().to_string();
    assert!(e.contains("matrix `B2` entry (2, 1) is not finite"), "{e}");
    // A JSON plant file renamed .mat, and a controller .mat given as a plant.
    let dir = tempfile::tempdir().unwrap();
    let fake = dir.path().join("plant.mat");
    std::fs::copy(Path::new(env!("CARGO_MANIFEST_DIR")).join("plants/HE1.json"), &fake).unwrap();
    let e = Plant::load(&fake).unwrap_err().to_string();
    assert!(e.contains("plant.mat") && e.contains("not a readable MATLAB level-5 .mat file"), "{e}");
    let e = Plant::load(fixture("K2.mat")).unwrap_err().to_string();
    assert!(e.contains("matrix `A` is missing"), "{e}");
    // Shapes are checked as for JSON: a controller whose BK has the wrong height.
    let k = Controller::load(fixture("K2.json")).unwrap();
    let bad = hinfix::lti::write_mat(
        &[("AK", k.ak.as_ref()), ("BK", k.ck.as_ref()), ("CK", k.ck.as_ref()), ("DK", k.dk.as_ref())],
        "bad",
    );
    let kp = dir.path().join("k.mat");
    std::fs::write(&kp, bad).unwrap();
    let e = Controller::load(&kp).unwrap_err().to_string();
    assert!(e.contains("k.mat") && e.contains("`BK`"), "{e}");
}

fn cli(args: &[&str]) -> std::process::Output {
    let out = Command::new(BIN)
        .args(args)
        .env("HINFIX_PLANTS", concat!(env!("CARGO_MANIFEST_DIR"), "/plants"))
        .output()
        .unwrap();
    assert!(out.status.success(), "campaign {args:?} failed: {}", String::from_utf8_lossy(&out.stderr));
    out
}

#[test]
fn command_line_designs_into_mat_checks_plots_and_exports_it() {
    let dir = tempfile::tempdir().unwrap();
    let k = dir.path().join("K.mat");
    let plant = fixture("HE1.mat");
    let (k_s, plant_s) = (k.to_str().unwrap(), plant.to_str().unwrap());
    cli(&[
        "design",
        "--plant",
        plant_s,
        "--order",
        "1",
        "--cpumax",
        "2",
        "--nrand",
        "1",
        "--stop-on-stall",
        "--out",
        k_s,
    ]);
    let kk = Controller::load(&k).unwrap();
    assert_eq!((kk.order(), kk.outputs(), kk.inputs()), (1, 2, 1));
    let svg = dir.path().join("sigma.svg");
    let png = dir.path().join("sigma.png");
    let out = cli(&["check", "--plant", "HE1", "--controller", k_s, "--json", "--plot", svg.to_str().unwrap()]);
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["closed_loop_stable"], serde_json::json!(true));
    roxmltree::Document::parse(&std::fs::read_to_string(&svg).unwrap()).unwrap();
    cli(&["check", "--plant", plant_s, "--controller", k_s, "--plot", png.to_str().unwrap()]);
    assert!(std::fs::read(&png).unwrap().starts_with(b"\x89PNG\r\n\x1a\n"));

    let m = String::from_utf8(cli(&["export", "--controller", k_s, "--to", "matlab"]).stdout).unwrap();
    assert!(m.contains("K = ss(AK, BK, CK, DK);") && m.contains("u = K y") && m.contains("lft(P, K)"), "{m}");
    let p = String::from_utf8(cli(&["export", "--controller", k_s, "--to", "python"]).stdout).unwrap();
    assert!(p.contains("K = control.ss(AK, BK, CK, DK)") && p.contains("import control"), "{p}");
    // The printed DK reads back to the controller's exact value.
    let dk_line = m.lines().find(|l| l.starts_with("DK = [")).unwrap();
    let first: f64 =
        dk_line.trim_start_matches("DK = [").split([',', ';', ']']).next().unwrap().trim().parse().unwrap();
    assert_eq!(first.to_bits(), kk.dk[(0, 0)].to_bits());
}

#[test]
fn a_campaign_may_name_a_mat_plant_and_gets_the_same_job_ids() {
    use hinfix::campaign::{expand, Campaign, RunnerTag};
    let dir = tempfile::tempdir().unwrap();
    let ids = |plant: &Path| {
        let f = dir.path().join("c.toml");
        std::fs::write(
            &f,
            format!(
                "name = \"m\"\n[defaults]\nseeds = 2\n[[problem]]\nplant = \"{}\"\norders = [1, 2]\n",
                plant.display()
            ),
        )
        .unwrap();
        let c = Campaign::load(&f).unwrap_or_else(|e| panic!("{e}"));
        expand(&c, RunnerTag::Design).into_iter().map(|j| j.id.0).collect::<Vec<_>>()
    };
    let from_mat = ids(&fixture("HE1.mat"));
    assert_eq!(from_mat.len(), 4);
    assert_eq!(from_mat, ids(&Path::new(env!("CARGO_MANIFEST_DIR")).join("plants/HE1.json")));
}

/// A cut, padded-out or doubly-defined MAT-file is an error that says so: `matfile` stopped at a
/// damaged element and returned the variables before it (a truncated plant read as "matrix `D22`
/// is missing", trailing garbage was accepted), and of two variables of one name it kept the
/// last (a second `A` silently replaced the plant's).
#[test]
fn truncated_damaged_and_repeated_variables_are_named() {
    let p = he1_json();
    let good = plant_to_mat(&p);
    assert!(read_mat_vars(&good).is_ok());
    let cut = &good[..good.len() - 4];
    let e = read_mat_vars(cut).unwrap_err().to_string();
    assert!(e.contains("truncated or damaged file: the element at byte") && e.contains("remain"), "{e}");
    let mut trailing = good.clone();
    trailing.extend_from_slice(&[14, 0, 0, 0, 0xe8, 3, 0, 0, 1, 2, 3, 4, 5, 6, 7, 8]); // miMATRIX of 1000 bytes, 8 given
    let e = read_mat_vars(&trailing).unwrap_err().to_string();
    assert!(e.contains("claims 1000 bytes, 8 remain"), "{e}");
    let mut stray = good.clone();
    stray.extend_from_slice(&[0, 0, 0]);
    let e = read_mat_vars(&stray).unwrap_err().to_string();
    assert!(e.contains("3 stray bytes after the last element"), "{e}");
    let minus = faer::Mat::<f64>::from_fn(4, 4, |i, j| if i == j { -5.0 } else { 0.0 });
    let mut vars: Vec<(&str, faer::MatRef<'_, f64>)> =
        ["A", "B1", "B2", "C1", "C2", "D11", "D12", "D21", "D22"].into_iter().zip(p.matrices()).collect();
    vars.push(("A", minus.as_ref()));
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("dup.mat");
    std::fs::write(&path, hinfix::lti::write_mat(&vars, "dup")).unwrap();
    let e = Plant::load(&path).unwrap_err().to_string();
    assert!(e.contains("dup.mat") && e.contains("variable `A` appears twice"), "{e}");
}
