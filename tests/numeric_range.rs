//! Numbers at the edges of what can be computed. A closed loop is stable only with a margin
//! (α < −1e-12 · max(1, ‖A_cl‖_F)). Numbers out of the
//! range the norm can be computed in are a clear error with
//! a non-zero exit, never a NaN or ∞ result called success. Plant entries are bounded on load
//! (at most `MAX_PLANT_MAGNITUDE`; a non-zero matrix needs an entry of `MIN_PLANT_MAGNITUDE` or
//! more; the error names the file and the matrix); a
//! controller's huge entries make `check` fail instead of printing a NaN norm.

use std::process::Command;

use hinfix::lti::{MatrixJsonError, Plant, PlantErrorKind, MAX_PLANT_MAGNITUDE, MIN_PLANT_MAGNITUDE};
use serde_json::Value;

const BIN: &str = env!("CARGO_BIN_EXE_campaign");
const MATRICES: [&str; 9] = ["A", "B1", "B2", "C1", "C2", "D11", "D12", "D21", "D22"];

fn he1() -> Value {
    serde_json::from_str(&std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/plants/HE1.json")).unwrap())
        .unwrap()
}

/// HE1 with `f` applied to every entry of the matrices `which`.
fn edited(which: &[&str], f: impl Fn(f64) -> f64) -> Value {
    let mut d = he1();
    for m in which {
        for row in d[*m].as_array_mut().unwrap() {
            for x in row.as_array_mut().unwrap() {
                *x = serde_json::json!(f(x.as_f64().unwrap()));
            }
        }
    }
    d
}

#[test]
fn plants_out_of_the_computable_range_are_refused_on_load_naming_the_matrix() {
    let cases = [
        (edited(&["D11"], |_| 1e200), "D11"),
        (edited(&MATRICES, |x| x * 1e150), "A"),
        (edited(&MATRICES, |x| x * 1e60), "A"),
        (edited(&MATRICES, |x| x * 1e-300), "A"),
        (edited(&["B1"], |x| x * 1e-60), "B1"),
    ];
    for (doc, matrix) in cases {
        let e = Plant::from_json_str(&doc.to_string(), "scaled.json").unwrap_err();
        let PlantErrorKind::Matrix {
            matrix: m,
            problem: MatrixJsonError::Magnitude { .. } | MatrixJsonError::Negligible { .. },
            ..
        } = &e.kind
        else {
            panic!("{e}")
        };
        assert_eq!(*m, matrix);
        let s = e.to_string();
        assert!(s.starts_with("plant file scaled.json: matrix `"), "{s}");
    }
    // the bounds themselves and zeros are accepted
    let ok = edited(&["D11"], |_| MAX_PLANT_MAGNITUDE);
    Plant::from_json_str(&ok.to_string(), "ok.json").unwrap();
    let ok = edited(&["D22"], |_| -MIN_PLANT_MAGNITUDE);
    Plant::from_json_str(&ok.to_string(), "ok.json").unwrap();
    // a single tiny entry next to ordinary ones (CM4 has 1e-70 in A) is fine
    let mut ok = he1();
    ok["A"][0][0] = serde_json::json!(1e-300);
    Plant::from_json_str(&ok.to_string(), "ok.json").unwrap();
}

#[test]
fn design_and_check_never_call_a_nan_result_success() {
    let dir = tempfile::tempdir().unwrap();
    let plant = dir.path().join("d11.json");
    std::fs::write(&plant, edited(&["D11"], |_| 1e200).to_string()).unwrap();
    let out = Command::new(BIN)
        .args(["design", "--order", "0", "--cpumax", "1", "--plant"])
        .arg(&plant)
        .arg("--out")
        .arg(dir.path().join("K.json"))
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.contains("d11.json") && stderr.contains("`D11`"), "{stderr}");
    assert!(!dir.path().join("K.json").exists());

    // A stabilising static gain with huge entries: its ‖K‖∞ is out of range.
    let k = dir.path().join("K.json");
    std::fs::write(&k, r#"{"AK": [], "BK": [], "CK": [[], []], "DK": [[1e200], [1e200]]}"#).unwrap();
    let out = Command::new(BIN)
        .args(["check", "--plant", concat!(env!("CARGO_MANIFEST_DIR"), "/plants/HE1.json"), "--controller"])
        .arg(&k)
        .output()
        .unwrap();
    let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    assert_eq!(out.status.code(), Some(1), "{stdout}{stderr}");
    assert!(!stdout.contains("NaN") && !stdout.contains("= inf"), "{stdout}");
    assert!(stderr.contains("out of the range"), "{stderr}");
}

#[test]
fn check_calls_a_loop_within_the_margin_unstable() {
    // Α = −4.4e-16 was called stable.
    let dir = tempfile::tempdir().unwrap();
    let plant = dir.path().join("edge.json");
    let doc = serde_json::json!({
        "name": "edge", "dims": {"n": 1, "m1": 1, "m2": 1, "p1": 1, "p2": 1},
        "A": [[-4.4e-16]], "B1": [[1.0]], "B2": [[1.0]], "C1": [[1.0]], "C2": [[1.0]],
        "D11": [[0.0]], "D12": [[0.0]], "D21": [[0.0]], "D22": [[0.0]]
    });
    std::fs::write(&plant, doc.to_string()).unwrap();
    let k = dir.path().join("K0.json");
    std::fs::write(&k, r#"{"AK": [], "BK": [], "CK": [[]], "DK": [[0.0]]}"#).unwrap();
    let out = Command::new(BIN).args(["check", "--plant"]).arg(&plant).arg("--controller").arg(&k).output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(out.status.code(), Some(4), "{stdout}{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains("UNSTABLE (stable means α < −1.000000e-12)"), "{stdout}");
}
