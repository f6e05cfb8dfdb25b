//! The parity interlacing property on the command line: `design` with the strong objective on a
//! plant no stable controller stabilises fails at once naming the zeros and poles (exit 4, no
//! file written), the plain objective still designs, a campaign's strong jobs on it fail fast
//! with the same message; every shipped plant passes the check (the paper found stable
//! controllers for all of them).
use std::process::Command;
use std::time::Instant;

use hinfix::lti::{library_plants, parity_interlacing, Plant};

const BIN: &str = env!("CARGO_BIN_EXE_campaign");
const PLANTS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/plants");

/// P22 = (s − 1)/((s − 2)(s + 1)) in controllable canonical form (A = [[0, 1], [2, 1]]: s² − s − 2;
/// C2 = [−1, 1]: s − 1), with w entering both states and z = (x, u).
const NOT_STRONGLY_STABILISABLE: &str = r#"{"name": "pip", "dims": {"n": 2, "m1": 1, "m2": 1, "p1": 3, "p2": 1},
    "A": [[0, 1], [2, 1]], "B1": [[1], [1]], "B2": [[0], [1]],
    "C1": [[1, 0], [0, 1], [0, 0]], "C2": [[-1, 1]],
    "D11": [[0], [0], [0]], "D12": [[0], [0], [1]], "D21": [[1]], "D22": [[0]]}"#;

#[test]
fn every_shipped_plant_is_strongly_stabilisable() {
    // the paper's plants (the top folder); COMPleib's collection has plants that are not
    for entry in library_plants().unwrap().into_iter().filter(|p| p.collection.is_none()) {
        let name = entry.name;
        let p = Plant::load(format!("{PLANTS}/{name}.json")).unwrap();
        if let Some(pip) = parity_interlacing(&p) {
            assert!(pip.holds(), "{name}: {:?}", pip.violation);
        }
    }
}

#[test]
fn design_refuses_at_once_and_a_campaign_fails_fast() {
    let dir = tempfile::tempdir().unwrap();
    let plant = dir.path().join("pip.json");
    std::fs::write(&plant, NOT_STRONGLY_STABILISABLE).unwrap();
    let k = dir.path().join("K.json");
    let started = Instant::now();
    let out = Command::new(BIN)
        .args(["design", "--order", "1", "--cpumax", "600", "--plant"])
        .arg(&plant)
        .arg("--out")
        .arg(&k)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    assert_eq!(out.status.code(), Some(4), "{stderr}");
    assert!(
        stderr.contains("parity interlacing") && stderr.contains("s = 1 and s = ∞") && stderr.contains("(s = 2)"),
        "{stderr}"
    );
    assert!(!k.exists());
    // not the 600-s budget (a generous bound: the check is one eigenvalue problem and one QZ)
    assert!(started.elapsed().as_secs() < 60);

    // the plain objective designs (an unstable controller is allowed and may be needed)
    let out = Command::new(BIN)
        .args(["design", "--order", "1", "--maxevals", "3000", "--no-strong", "--plant"])
        .arg(&plant)
        .arg("--out")
        .arg(&k)
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(k.is_file());

    // a campaign: its strong jobs fail fast with the same message, the plain ones run
    let file = dir.path().join("c.toml");
    std::fs::write(
        &file,
        "name = \"pip\"\n[defaults]\neps = [1e-2]\nseeds = 1\ncpumax = 600.0\nmaxevals = 3000\ntrace = \"off\"\n\
         [[problem]]\nplant = \"pip.json\"\norders = [1]\nobjective = \"strong\"\n\
         [[problem]]\nplant = \"pip.json\"\norders = [1]\nobjective = \"plain\"\n",
    )
    .unwrap();
    let results = dir.path().join("r");
    let out =
        Command::new(BIN).arg("run").arg(&file).arg("--results").arg(&results).arg("--no-progress").output().unwrap();
    assert_eq!(out.status.code(), Some(3), "{}", String::from_utf8_lossy(&out.stderr));
    let journal = std::fs::read_to_string(results.join("pip").join("runs.jsonl")).unwrap();
    let lines: Vec<serde_json::Value> = journal.lines().map(|l| serde_json::from_str(l).unwrap()).collect();
    assert_eq!(lines.len(), 2);
    let failed: Vec<&serde_json::Value> = lines.iter().filter(|l| l["status"]["kind"] == "failed").collect();
    assert_eq!(failed.len(), 1, "{journal}");
    assert_eq!(failed[0]["options"]["objective"], "strong");
    let msg = failed[0]["status"]["error"].as_str().unwrap();
    assert!(msg.contains("parity interlacing") && msg.contains("s = 1 and s = ∞"), "{msg}");
    assert!(failed[0]["cpu_s"].as_f64().unwrap() < 5.0, "{}", failed[0]);
}
