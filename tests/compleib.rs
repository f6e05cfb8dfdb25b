//! The COMPleib collection of the plant library (`plants/compleib/`): every file loads (plain or
//! gzip-compressed JSON), agrees with its `INDEX.csv` row (dimensions, open-loop spectral
//! abscissa) and with its documented fingerprint (`FINGERPRINTS.csv`), and every name is found by
//! the library lookup that campaigns and commands use.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use hinfix::lti::{self, Plant};

fn compleib_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("plants/compleib")
}

/// Rows of a CSV file with a header, as maps from column to field.
fn read_csv(path: &Path) -> Vec<BTreeMap<String, String>> {
    let mut r = csv::Reader::from_path(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let header = r.headers().unwrap().clone();
    r.records().map(|rec| header.iter().zip(rec.unwrap().iter()).map(|(h, v)| (h.into(), v.into())).collect()).collect()
}

#[test]
fn every_plant_matches_its_index_row_and_fingerprint() {
    let index = read_csv(&compleib_dir().join("INDEX.csv"));
    let prints: BTreeMap<String, (String, String)> = read_csv(&compleib_dir().join("FINGERPRINTS.csv"))
        .into_iter()
        .map(|r| (r["name"].clone(), (r["file"].clone(), r["fingerprint"].clone())))
        .collect();
    assert!(index.len() >= 100, "{} plants", index.len());
    assert_eq!(index.len(), prints.len(), "INDEX.csv and FINGERPRINTS.csv list the same plants");
    for row in &index {
        let name = &row["name"];
        let (file, fingerprint) = prints.get(name).unwrap_or_else(|| panic!("{name}: not in FINGERPRINTS.csv"));
        let path = compleib_dir().join(file);
        // the lookup by name finds the same file
        assert_eq!(lti::resolve_plant(name).unwrap().canonicalize().unwrap(), path.canonicalize().unwrap(), "{name}");
        let p = Plant::load(&path).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(&p.name, name);
        let d = p.dims;
        let dims: Vec<usize> = ["n", "m1", "m2", "p1", "p2"].iter().map(|k| row[*k].parse().unwrap()).collect();
        assert_eq!(vec![d.n, d.m1, d.m2, d.p1, d.p2], dims, "{name}: dims");
        // the index gives α to 10 significant digits; a defective rightmost eigenvalue is only
        // determined to about (ε‖A‖)^(1/k) by any eigensolver, k its largest Jordan block
        let alpha: f64 = row["open_loop_alpha"].parse().unwrap();
        let ours = lti::stability_measure(p.domain, p.a.as_ref());
        let tol = match DEFECTIVE.iter().find(|(n, _)| n == name) {
            Some((_, k)) => 4.0 * (f64::EPSILON * frobenius(&p)).powf(1.0 / *k as f64),
            None => 1e-8 * alpha.abs().max(1.0),
        };
        assert!((ours - alpha).abs() <= tol, "{name}: α {ours} against the index's {alpha}");
        assert_eq!(&p.fingerprint(), fingerprint, "{name}: fingerprint");
        // large plants are stored compressed, small ones as plain JSON
        assert_eq!(file.ends_with(".json.gz"), d.n > 60, "{name}: {file}");
        assert!(d22_zero(&p), "{name}: COMPleib has no D22");
    }
}

/// Plants whose rightmost eigenvalue is defective, with its largest Jordan block: NN11's A has
/// λ = −1 of algebraic multiplicity 6 and geometric multiplicity 2 (rank of (A + I)^k is 14, 12,
/// 10, 10 for k = 1…4: two blocks of size 3).
const DEFECTIVE: [(&str, usize); 1] = [("NN11", 3)];

fn frobenius(p: &Plant) -> f64 {
    let a = p.a.as_ref();
    (0..a.nrows()).flat_map(|i| (0..a.ncols()).map(move |j| a[(i, j)] * a[(i, j)])).sum::<f64>().sqrt()
}

fn d22_zero(p: &Plant) -> bool {
    p.d22_is_zero()
}

#[test]
fn the_library_lists_every_compleib_plant_once_and_no_other_file() {
    let listed = lti::library_plants().unwrap();
    let compleib: BTreeSet<String> =
        listed.iter().filter(|p| p.collection.as_deref() == Some("compleib")).map(|p| p.name.clone()).collect();
    let index: BTreeSet<String> =
        read_csv(&compleib_dir().join("INDEX.csv")).into_iter().map(|r| r["name"].clone()).collect();
    assert_eq!(compleib, index);
    // no name twice in the whole library (the top folder holds AC8, HE1, …, Enns)
    let mut names: Vec<&str> = listed.iter().map(|p| p.name.as_str()).collect();
    let total = names.len();
    names.sort();
    names.dedup();
    assert_eq!(names.len(), total, "a plant name is in two library folders");
    assert!(total >= 150, "{total}");
    // what is listed as missing is not here
    let missing = std::fs::read_to_string(compleib_dir().join("MISSING.md")).unwrap();
    for absent in ["CM6", "CM6_IS", "HF2D1", "HF2D_CD3", "HF2D_IS4"] {
        assert!(missing.contains(absent), "{absent}");
        assert!(!names.contains(&absent), "{absent} is listed as missing but ships");
    }
}

#[test]
fn a_damaged_or_endless_gzip_plant_is_a_clear_error() {
    let dir = tempfile::tempdir().unwrap();
    let bad = dir.path().join("bad.json.gz");
    std::fs::write(&bad, b"not gzip at all").unwrap();
    let e = Plant::load(&bad).unwrap_err().to_string();
    assert!(e.contains("bad.json.gz") && e.contains("gzip"), "{e}");
    // a good gzip of something that is not a plant: the JSON error, naming the file
    let text = dir.path().join("text.json.gz");
    let mut enc = libflate::gzip::Encoder::new(Vec::new()).unwrap();
    std::io::Write::write_all(&mut enc, b"{\"name\": \"x\"}").unwrap();
    std::fs::write(&text, enc.finish().into_result().unwrap()).unwrap();
    let e = Plant::load(&text).unwrap_err().to_string();
    assert!(e.contains("text.json.gz") && e.contains("dims"), "{e}");
}

#[test]
fn a_stabilising_controller_of_a_badly_scaled_plant_verifies() {
    // EB6: ‖A‖_F = 1.3e8 while |λ| ≤ 6 400 and the modes are damped to 1e-7. Its order-1
    // controller (tests/fixtures/compleib/EB6_order1.json, from `campaign design --plant EB6
    // --order 1`) gives α(A_cl) ≈ −4.0e-5: a margin of 1e-12·‖A_cl‖_F (above 1e-4) threw it
    // away; the margin of the balanced closed loop keeps it, and the abscissa computed on the
    // balanced matrix is the same as on A_cl to far better than that.
    use hinfix::campaign::{verify_controller, Verdict};
    use hinfix::design::ObjectiveKind;
    let plant = Plant::load(lti::resolve_plant("EB6").unwrap()).unwrap();
    let fixture = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/compleib/EB6_order1.json");
    let k = lti::Controller::load(fixture).unwrap();
    let cl = lti::closed_loop(&plant, &k).unwrap();
    assert!(1e-12 * cl.a.norm_l2() > 4.0e-5, "the unbalanced margin would refuse it");
    let margin = lti::stability_margin(cl.a.as_ref());
    assert!(margin < 1e-6, "{margin}");
    let alpha = lti::verified_stability_measure(plant.domain, cl.a.as_ref());
    assert!((alpha + 4.007e-5).abs() < 1e-8, "{alpha}");
    match verify_controller(&k, 1, ObjectiveKind::Strong, &plant) {
        Verdict::Verified { gamma, .. } => assert!((gamma - 1.905236).abs() < 1e-5, "{gamma}"),
        other => panic!("{other:?}"),
    }
    // the open loop, damped to 1e-7, is stable with the balanced margin
    let a = plant.a.as_ref();
    assert!(lti::is_stable_with_margin(lti::verified_stability_measure(plant.domain, a), a));
}
