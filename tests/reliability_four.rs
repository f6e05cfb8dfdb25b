//! Reliability of the newer surfaces (several plants, the H2,
//! abscissa and radius objectives, structures, discrete time), one regression test per class of
//! what a hostile user found: (1) panics, (2) false claims and wrong numbers, (3) silent losses,
//! (4) unclear errors. Each test feeds a class of inputs, not the one reported input.

use std::path::{Path, PathBuf};
use std::process::Command;

use hinfix::design::{ControllerShape, Structure};
use hinfix::lti::{read_mat_vars, write_mat, Controller, TimeDomain};
use serde_json::{json, Value};

const BIN: &str = env!("CARGO_BIN_EXE_campaign");
const PLANTS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/plants");

mod common;

fn scratch(tag: &str) -> PathBuf {
    common::scratch("rel4", tag)
}

/// Runs the CLI: (exit code, stdout, stderr), and no panic whatever the input.
fn cli(args: &[&str]) -> (i32, String, String) {
    let o = Command::new(BIN).args(args).env("HINFIX_PLANTS", PLANTS).output().unwrap();
    let (out, err) = (String::from_utf8_lossy(&o.stdout).into_owned(), String::from_utf8_lossy(&o.stderr).into_owned());
    assert!(!err.contains("panicked") && !err.contains("RUST_BACKTRACE"), "{args:?} panicked:\n{err}");
    (o.status.code().unwrap_or(-1), out, err)
}

fn p(path: &Path) -> &str {
    path.to_str().unwrap()
}

/// A lightly damped discrete 2-state plant (poles 0.9·e^{±i}) with sampling time `ts`: its H∞
/// peak is at θ = 1 rad/sample, i.e. ω ≈ 1/Ts rad/s; and the zero static gain for it.
fn resonant(dir: &Path, ts: f64) -> (PathBuf, PathBuf) {
    let (r, t) = (0.9f64, 1.0f64);
    let plant = json!({
        "name": format!("res{ts:e}"), "Ts": ts,
        "A": [[r * t.cos(), -r * t.sin()], [r * t.sin(), r * t.cos()]],
        "B1": [[1.0], [0.0]], "B2": [[0.0], [1.0]], "C1": [[1.0, 0.0]], "C2": [[0.0, 1.0]],
        "D11": [[0.0]], "D12": [[0.0]], "D21": [[0.0]], "D22": [[0.0]]
    });
    let k = json!({"AK": [], "BK": [], "CK": [], "DK": [[0.0]], "Ts": ts});
    let (pp, kp) = (dir.join(format!("res{ts:e}.json")), dir.join(format!("k{ts:e}.json")));
    std::fs::write(&pp, plant.to_string()).unwrap();
    std::fs::write(&kp, k.to_string()).unwrap();
    (pp, kp)
}

// ---------------------------------------------------------------- class 1: no panic ----------

/// Sampling times at and beyond every extreme: the ones out of range are clear errors in every
/// command that reads a plant or a controller (Ts = 5e-324 once panicked the σ-plot in a
/// `clamp` with NaN bounds), the extremes accepted draw and print finite frequencies.
#[test]
fn extreme_sampling_times_never_panic_and_are_refused_or_right() {
    let dir = scratch("ts");
    for ts in [5e-324, 1e-320, 1e-300, 1e-200, 1e-51, 1e51, 1e200, 1e300, f64::MAX] {
        let (plant, k) = resonant(&dir, ts);
        let svg = dir.join("x.svg");
        for args in [
            vec!["check", "--plant", p(&plant), "--controller", p(&k), "--plot", p(&svg)],
            vec!["check", "--plant", p(&plant), "--controller", p(&k), "--json"],
            vec!["plant", p(&plant)],
            vec!["export", "--controller", p(&k), "--to", "python"],
            vec!["design", "--plant", p(&plant), "--order", "0", "--maxevals", "50", "--out", p(&dir.join("o.json"))],
        ] {
            let (code, _, err) = cli(&args);
            assert_eq!(code, 1, "Ts = {ts:e}: {args:?}\n{err}");
            assert!(err.contains("`Ts`") && err.contains("1e-50 to 1e50"), "Ts = {ts:e}: {err}");
            assert!(err.len() < 400, "a short message: {err}");
        }
    }
    for ts in [1e-50, 1e-3, 1.0, 1e50] {
        let (plant, k) = resonant(&dir, ts);
        let svg = dir.join(format!("ok{ts:e}.svg"));
        let (code, out, err) = cli(&["check", "--plant", p(&plant), "--controller", p(&k), "--plot", p(&svg)]);
        assert_eq!(code, 0, "{err}");
        assert!(std::fs::read_to_string(&svg).unwrap().contains("<svg"));
        // Ts and the peak frequency printed with an exponent, not hundreds of digits
        assert!(out.lines().all(|l| l.chars().count() < 200), "{out}");
        let (_, json_out, _) = cli(&["check", "--plant", p(&plant), "--controller", p(&k), "--json"]);
        let v: Value = serde_json::from_str(&json_out).unwrap();
        let w = v["closed_loop_peak_freq"].as_f64().unwrap();
        // the peak is at θ = 1.0028 rad/sample
        assert!((w * ts - 1.002845).abs() < 1e-4, "Ts = {ts:e}: peak at ω = {w}");
    }
}

// ------------------------------------------------- class 2: false claims, wrong numbers ------

/// A design exits 0 only with a controller that `check` verifies: over the objectives a strong
/// design can end on the stability boundary with (the abscissa, which the ε‖K‖∞ term pushes to
/// 0), the exit code, the status and `check` agree; `--maxevals` is named as the budget that
/// stopped; an infeasible bound ends `bound_violated`, exit 5, with `bound_met: false` in the
/// JSON of that plant.
#[test]
fn a_design_claims_only_what_its_controller_shows() {
    let dir = scratch("claims");
    for (objective, evals) in [("abscissa", "3000"), ("radius", "2000"), ("hinf", "1500")] {
        let out = dir.join(format!("{objective}.json"));
        let (code, text, err) = cli(&[
            "design",
            "--plant",
            "HE1",
            "--order",
            "1",
            "--objective",
            objective,
            "--maxevals",
            evals,
            "--json",
            "--out",
            p(&out),
        ]);
        let v: Value = serde_json::from_str(&text).unwrap_or_else(|e| panic!("{e}: {text}\n{err}"));
        let kind = v["status"]["kind"].as_str().unwrap().to_string();
        if code == 0 {
            let (c, _, e) = cli(&["check", "--plant", "HE1", "--controller", p(&out), "--json"]);
            assert_eq!(c, 0, "{objective}: design exited 0 ({kind}) but check says\n{e}");
            let k: Value =
                serde_json::from_str(&cli(&["check", "--plant", "HE1", "--controller", p(&out), "--json"]).1).unwrap();
            assert_eq!(k["controller_stable"], json!(true), "{objective}: {kind}");
        } else {
            assert_eq!(code, 4, "{objective}: {err}");
            assert_eq!(kind, "not_stabilised", "{objective}");
        }
    }
    // the budget a stop names
    let (_, text, _) =
        cli(&["design", "--plant", "HE1", "--order", "1", "--maxevals", "30", "--out", p(&dir.join("m.json"))]);
    assert!(!text.contains("CPU budget"), "{text}");
    if text.contains("exhausted") {
        assert!(text.contains("evaluation budget (--maxevals) exhausted"), "{text}");
    }
    // an infeasible bound (α(A_cl) ≤ −100) is not "converged"
    let (code, text, err) = cli(&[
        "design",
        "--plant",
        "HE1",
        "--plant",
        "HE1",
        "--objective",
        "hinf",
        "--objective",
        "abscissa",
        "--bound",
        "none",
        "--bound",
        "-100",
        "--order",
        "1",
        "--maxevals",
        "1500",
        "--json",
        "--out",
        p(&dir.join("b.json")),
    ]);
    assert_eq!(code, 5, "{text}\n{err}");
    let v: Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["status"]["kind"], json!("bound_violated"));
    assert_eq!(v["plants"][0]["bound_met"], Value::Null);
    assert_eq!(v["plants"][1]["bound_met"], json!(false));
}

/// Weights and bounds that would overflow the objective are refused before the search, in both
/// the CLI and a campaign file; a python export keeps −0.0.
#[test]
fn overflowing_weights_are_refused_and_negative_zero_survives_export() {
    let dir = scratch("weights");
    for (flag, value) in [("--weight", "1e308"), ("--weight", "1e-320"), ("--bound", "1e308"), ("--bound", "-1e300")] {
        let (code, _, err) =
            cli(&["design", "--plant", "HE1", "--order", "0", flag, value, "--out", p(&dir.join("w.json"))]);
        assert_eq!(code, 1, "{flag} {value}");
        assert!(err.contains("1e50") && err.contains(&value.replace('+', "")), "{err}");
    }
    let toml = dir.join("w.toml");
    std::fs::write(&toml, "name = \"w\"\n[[problem]]\nplant = \"HE1\"\nweights = 1e308\nname = \"x\"\norders = [0]\n")
        .unwrap();
    let (code, _, err) = cli(&["status", p(&toml), "--results", p(&dir)]);
    assert_eq!(code, 1);
    assert!(err.contains("weight 1e308") && err.contains(":4:"), "{err}");
    let k = dir.join("k.json");
    std::fs::write(&k, r#"{"AK": [], "BK": [], "CK": [], "DK": [[-0.0, 2.0]]}"#).unwrap();
    let (_, py, _) = cli(&["export", "--controller", p(&k), "--to", "python"]);
    assert!(py.contains("np.array([[-0.0, 2.0]])"), "{py}");
}

// ------------------------------------------------------------ class 3: silent losses --------

/// The level-5 bytes of `write_mat(vars)` with the array class of variable number `which`
/// changed to `class` (1 cell, 2 struct, 4 char, 5 sparse, 12 int32): what MATLAB writes for
/// such variables starts the same way, and the reader must refuse them by their class instead of
/// skipping them.
fn with_class(vars: &[(&str, faer::MatRef<'_, f64>)], which: usize, class: u8) -> Vec<u8> {
    let mut b = write_mat(vars, "test");
    let mut pos = 128;
    for _ in 0..which {
        let len = u32::from_le_bytes(b[pos + 4..pos + 8].try_into().unwrap()) as usize;
        pos += 8 + len.div_ceil(8) * 8;
    }
    b[pos + 16] = class; // miMATRIX tag (8) + array-flags tag (8), then the class byte
    b
}

/// Variables of a class the reader does not read (char, cell, struct, sparse, and int32 stored
/// as doubles) in a structure, controller or plant MAT-file, `Ts` included, are errors naming the
/// variable and its class; a duplicate key in a structure (or plant, or controller) JSON is an
/// error naming the key.
#[test]
fn unread_mat_variables_and_duplicate_keys_are_errors() {
    let one = faer::Mat::<f64>::from_fn(1, 1, |_, _| f64::NAN);
    let dk = faer::Mat::<f64>::from_fn(2, 1, |_, _| 0.5);
    let ts = faer::Mat::<f64>::from_fn(1, 1, |_, _| 0.1);
    let shape = ControllerShape { nk: 1, m: 2, p: 1, domain: TimeDomain::Continuous };
    for (class, words) in [(1, "cell"), (2, "struct"), (4, "char"), (5, "sparse"), (12, "int32")] {
        // a structure's AK
        let bytes = with_class(&[("AK", one.as_ref()), ("DK", dk.as_ref())], 0, class);
        let e = Structure::from_mat_bytes(&bytes, "s.mat", shape).unwrap_err().to_string();
        assert!(e.contains("`AK`") && e.contains(words), "{e}");
        // a controller's Ts
        let k = [("AK", one.as_ref()), ("BK", one.as_ref()), ("CK", dk.as_ref()), ("DK", dk.as_ref())];
        let mut vars = k.to_vec();
        vars.push(("Ts", ts.as_ref()));
        let e = read_mat_vars(&with_class(&vars, 4, class)).unwrap_err().to_string();
        assert!(e.contains("`Ts`") && e.contains(words), "{e}");
    }
    // duplicate keys
    let shape0 = ControllerShape { nk: 0, m: 2, p: 1, domain: TimeDomain::Continuous };
    let e = Structure::from_json(r#"{"DK": [[null], [null]], "DK": [[1.0], [2.0]]}"#, "s.json", shape0)
        .unwrap_err()
        .to_string();
    assert!(e.contains("\"DK\"") && e.contains("twice"), "{e}");
    let e = Controller::from_json_str(r#"{"AK": [], "BK": [], "CK": [], "DK": [[1.0]], "DK": [[2.0]]}"#, "k.json")
        .unwrap_err()
        .to_string();
    assert!(e.contains("\"DK\"") && e.contains("twice"), "{e}");
}

/// `campaign plot` of problems of several plants and of a non-H∞ objective draws their figures:
/// γ against order with points, and a σ-plot of the best controller on each plant.
#[test]
fn campaign_plot_draws_several_plant_and_non_hinf_problems() {
    let dir = scratch("plot");
    for op in 1..=2 {
        std::fs::copy(
            Path::new(env!("CARGO_MANIFEST_DIR")).join(format!("examples/multi-model/HE1_op{op}.json")),
            dir.join(format!("HE1_op{op}.json")),
        )
        .unwrap();
    }
    let toml = dir.join("mm.toml");
    std::fs::write(
        &toml,
        "name = \"mm\"\n[defaults]\nseeds = 1\nmaxevals = 400\nnrand = 1\n\
         [[problem]]\nplants = [\"HE1_op1.json\", \"HE1_op2.json\"]\nname = \"two\"\norders = [1]\n\
         [[problem]]\nplant = \"HE1_op2.json\"\nobjectives = \"h2\"\norders = [1]\n",
    )
    .unwrap();
    let res = dir.join("res");
    let (code, _, err) = cli(&["run", p(&toml), "--results", p(&res), "--no-progress"]);
    assert_eq!(code, 0, "{err}");
    let (code, out, err) = cli(&["plot", p(&toml), "--results", p(&res)]);
    assert_eq!(code, 0, "{err}");
    for f in ["sigma_two_nK1_HE1_op1.svg", "sigma_two_nK1_HE1_op2.svg", "sigma_HE1_op2_nK1_HE1_op2.svg"] {
        assert!(out.contains(f), "{f} not drawn:\n{out}\n{err}");
        let svg = std::fs::read_to_string(res.join("mm/plots").join(f)).unwrap();
        assert!(svg.matches("<polyline").count() >= 2, "{f}: no curves");
    }
    let gamma = std::fs::read_to_string(res.join("mm/plots/gamma-vs-order_two.svg")).unwrap();
    assert!(gamma.contains("<circle") || gamma.contains("<polyline"), "γ-vs-order of a multi-plant problem is empty");
}

// ------------------------------------------------------------ class 4: unclear errors -------

/// Structure files are read as plant files are: a UTF-8 byte-order mark is accepted, the size is
/// capped (`/dev/zero`), and a structure whose fixed A_K is unstable is refused at once under the
/// strong objective, naming the structure; campaign-file type errors are in words, not Rust's.
#[test]
fn structure_files_and_campaign_errors_speak_plainly() {
    let dir = scratch("words");
    let bom = dir.join("bom.json");
    std::fs::write(&bom, b"\xef\xbb\xbf{\"DK\": [[null], [0.5]]}").unwrap();
    let s = Structure::load(&bom, ControllerShape { nk: 0, m: 2, p: 1, domain: TimeDomain::Continuous }).unwrap();
    assert_eq!(s.nfree(), 1);
    let (code, _, err) =
        cli(&["design", "--plant", "HE1", "--order", "0", "--structure", "/dev/zero", "--out", p(&dir.join("k.json"))]);
    assert_eq!(code, 1);
    assert!(err.contains("limit for a structure file"), "{err}");
    let unstable = dir.join("ak.json");
    std::fs::write(&unstable, r#"{"AK": [[0.5]]}"#).unwrap();
    let started = std::time::Instant::now();
    let (code, _, err) = cli(&[
        "design",
        "--plant",
        "HE1",
        "--order",
        "1",
        "--structure",
        p(&unstable),
        "--cpumax",
        "30",
        "--out",
        p(&dir.join("k.json")),
    ]);
    assert_eq!(code, 1, "{err}");
    assert!(err.contains("structure") && err.contains("AK") && err.contains("not stable"), "{err}");
    assert!(started.elapsed().as_secs() < 20, "refused only after the 30-s budget");
    // serde's type names never reach a campaign author
    for (key, value) in [
        ("weights", "{ a = 1 }"),
        ("bounds", "[true]"),
        ("objectives", "3"),
        ("maxevals", "-1"),
        ("maxevals", "1.5"),
        ("nrand", "\"x\""),
    ] {
        let toml = dir.join("c.toml");
        std::fs::write(
            &toml,
            format!(
                "name = \"c\"\n[[problem]]\nplants = [\"HE1\", \"HE1\"]\nname = \"x\"\norders = [0]\n{key} = {value}\n"
            ),
        )
        .unwrap();
        let (code, _, err) = cli(&["status", p(&toml), "--results", p(&dir)]);
        assert_eq!(code, 1, "{key} = {value}");
        for jargon in ["untagged", "PerPlant", "usize", "u64", "i64", "f64", "BoundValue", "enum"] {
            assert!(!err.contains(jargon), "{key} = {value}: {err}");
        }
        assert!(err.contains(":6:"), "{key} = {value}: the position of the key: {err}");
    }
}
