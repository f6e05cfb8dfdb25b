//! The shipped plant library loads, and malformed plant files are rejected with errors that name
//! the file, the field and what is wrong.

use hinfix::lti::{MatrixJsonError, Plant, PlantErrorKind};
use serde_json::{json, Value};

fn plants_dir() -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("plants")
}

#[test]
fn every_shipped_plant_loads_with_the_papers_order() {
    // (name, n) as the paper's Tables VII and VIII state them.
    let expected =
        [("AC8", 9), ("HE1", 4), ("REA2", 4), ("AC10", 55), ("BDT2", 82), ("HF1", 130), ("CM4", 240), ("Enns", 8)];
    for (name, n) in expected {
        let p = Plant::load(plants_dir().join(format!("{name}.json"))).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(p.name, name);
        assert_eq!(p.dims.n, n, "{name}");
        assert!(!p.citation.is_empty(), "{name} has no citation");
        assert!(p.check.is_some(), "{name} has no check block");
    }
    // the top folder holds the paper's plants; the COMPleib collection is tests/compleib.rs's
    let mut shipped: Vec<String> =
        hinfix::lti::library_plants().unwrap().into_iter().filter(|p| p.collection.is_none()).map(|p| p.name).collect();
    shipped.sort();
    let mut names: Vec<String> = expected.iter().map(|(n, _)| n.to_string()).collect();
    names.sort();
    assert_eq!(shipped, names);
}

/// A small valid plant document (n = 2, m1 = m2 = p1 = p2 = 1).
fn good() -> Value {
    json!({
        "name": "T", "source": "test",
        "dims": {"n": 2, "m1": 1, "m2": 1, "p1": 1, "p2": 1},
        "A": [[-1.0, 0.0], [0.0, -2.0]], "B1": [[1.0], [0.0]], "B2": [[0.0], [1.0]],
        "C1": [[1.0, 0.0]], "C2": [[0.0, 1.0]],
        "D11": [[0.0]], "D12": [[1.0]], "D21": [[1.0]], "D22": [[0.0]]
    })
}

fn with(edit: impl FnOnce(&mut serde_json::Map<String, Value>)) -> String {
    let mut v = good();
    edit(v.as_object_mut().unwrap());
    v.to_string()
}

#[test]
fn a_valid_file_loads() {
    let p = Plant::from_json_str(&good().to_string(), "t.json").unwrap();
    assert_eq!(p.dims.n, 2);
    assert!(p.d22_is_zero());
}

/// As a .mat file, a JSON plant may leave out `name` (the file's stem names it) and `dims`
/// (inferred from the blocks; an empty `[]` block is a zero block): the same plant, same
/// fingerprint.
#[test]
fn name_and_dims_may_be_left_out() {
    let full = Plant::from_json_str(&good().to_string(), "t.json").unwrap();
    let bare = with(|o| {
        o.remove("name");
        o.remove("dims");
    });
    let p = Plant::from_json_str(&bare, "dir/two_mass.json").unwrap();
    assert_eq!(p.name, "two_mass");
    assert_eq!(p.dims, full.dims);
    assert_eq!(p.fingerprint(), full.fingerprint());
    // an empty block stands for zeros when the dims are inferred
    let bare_d22 = with(|o| {
        o.remove("dims");
        o["D22"] = json!([]);
    });
    let q = Plant::from_json_str(&bare_d22, "t.json").unwrap();
    assert_eq!(q.fingerprint(), full.fingerprint());
    // with dims given, an empty block of a non-empty shape is still an error
    let with_dims = with(|o| {
        o["D22"] = json!([]);
    });
    assert!(Plant::from_json_str(&with_dims, "t.json").is_err());
}

/// What a bad plant file is expected to give: (what is wrong, the file's text, the error kind,
/// a phrase of the message).
type BadCase = (&'static str, String, fn(&PlantErrorKind) -> bool, &'static str);

/// Each case's text is refused with its own error kind and a message naming the file and `msg`.
fn assert_each_refused(cases: Vec<BadCase>) {
    for (what, text, check, msg) in cases {
        let e = Plant::from_json_str(&text, "bad/plant.json").expect_err(what);
        assert!(check(&e.kind), "{what}: unexpected error kind {:?}", e.kind);
        let shown = e.to_string();
        assert!(shown.starts_with("plant file bad/plant.json: "), "{what}: {shown}");
        assert!(shown.contains(msg), "{what}: `{shown}` should mention `{msg}`");
    }
}

/// Whether `k` is a non-number at entry (1, 2) of `matrix`.
fn not_a_number_at_1_2(k: &PlantErrorKind, matrix: &str) -> bool {
    matches!(k, PlantErrorKind::Matrix { matrix: m, problem: MatrixJsonError::NotNumber { row: 1, col: 2, .. }, .. } if *m == matrix)
}

#[test]
fn bad_plant_files_each_get_their_own_error() {
    let cases: Vec<BadCase> = vec![
        (
            "malformed JSON",
            "{\"name\": \"T\", ".to_string(),
            |k| matches!(k, PlantErrorKind::Json { line: 1, .. }),
            "invalid JSON at line 1",
        ),
        ("not an object", "[1, 2]".to_string(), |k| matches!(k, PlantErrorKind::NotObject), "top level"),
        (
            "negative dimension",
            with(|o| {
                o["dims"]["m1"] = json!(-1);
            }),
            |k| matches!(k, PlantErrorKind::BadField { field, .. } if field == "dims.m1"),
            "dims.m1",
        ),
        (
            "unknown dims key",
            with(|o| {
                o["dims"]["q"] = json!(1);
            }),
            |k| matches!(k, PlantErrorKind::BadField { field, .. } if field == "dims.q"),
            "unknown key",
        ),
        (
            "order disagrees with dims",
            with(|o| {
                o.insert("order".into(), json!(3));
            }),
            |k| matches!(k, PlantErrorKind::BadField { field, .. } if field == "order"),
            "dims.n is 2",
        ),
        (
            "name not a string",
            with(|o| {
                o["name"] = json!(7);
            }),
            |k| matches!(k, PlantErrorKind::BadField { field, .. } if field == "name"),
            "non-empty string",
        ),
    ];
    assert_each_refused(cases);
}

#[test]
fn bad_matrices_each_get_their_own_error() {
    let cases: Vec<BadCase> = vec![
        (
            "missing matrix",
            with(|o| {
                o.remove("C2");
            }),
            |k| matches!(k, PlantErrorKind::Matrix { matrix: "C2", problem: MatrixJsonError::Missing, .. }),
            "`C2` is missing",
        ),
        (
            "wrong row count",
            with(|o| {
                o["A"] = json!([[-1.0, 0.0]]);
            }),
            |k| {
                matches!(
                    k,
                    PlantErrorKind::Matrix {
                        matrix: "A",
                        problem: MatrixJsonError::RowCount { expected: 2, got: 1 },
                        ..
                    }
                )
            },
            "expected 2×2",
        ),
        (
            "ragged row",
            with(|o| {
                o["B1"] = json!([[1.0], [0.0, 3.0]]);
            }),
            |k| {
                matches!(
                    k,
                    PlantErrorKind::Matrix { matrix: "B1", problem: MatrixJsonError::RowLength { row: 2, .. }, .. }
                )
            },
            "row 2",
        ),
        (
            "NaN as a string",
            with(|o| {
                o["A"] = json!([[-1.0, "NaN"], [0.0, -2.0]]);
            }),
            |k| not_a_number_at_1_2(k, "A"),
            "entry (1, 2)",
        ),
        (
            "null entry",
            with(|o| {
                o["C1"] = json!([[1.0, null]]);
            }),
            |k| not_a_number_at_1_2(k, "C1"),
            "not a number",
        ),
        (
            "wrong D22 shape",
            with(|o| {
                o["D22"] = json!([[0.0, 0.0]]);
            }),
            |k| matches!(k, PlantErrorKind::Matrix { matrix: "D22", problem: MatrixJsonError::RowLength { .. }, .. }),
            "p2×m2",
        ),
        (
            "matrix not an array",
            with(|o| {
                o["D11"] = json!(0.0);
            }),
            |k| matches!(k, PlantErrorKind::Matrix { matrix: "D11", problem: MatrixJsonError::NotArray { .. }, .. }),
            "array of rows",
        ),
    ];
    assert_each_refused(cases);
}

#[test]
fn overflowing_number_is_rejected_not_panicked() {
    // 1e999 is not a finite f64; serde_json refuses it as a number.
    let text = with(|_| {}).replace("-2.0", "1e999");
    let e = Plant::from_json_str(&text, "p.json").unwrap_err();
    assert!(matches!(e.kind, PlantErrorKind::Json { .. }), "{e}");
}

#[test]
fn unreadable_file_is_an_io_error_naming_it() {
    let e = Plant::load("no/such/plant.json").unwrap_err();
    assert!(matches!(e.kind, PlantErrorKind::Io(_)));
    assert!(e.to_string().contains("no/such/plant.json"));
}

#[test]
fn unknown_name_lists_the_library() {
    let e = hinfix::lti::resolve_plant("NoSuchPlant").unwrap_err();
    let s = e.to_string();
    // about 150 names: the count and where to see them, not the whole list
    assert!(s.contains("NoSuchPlant") && s.contains("plants, listed by `campaign plants`"), "{s}");
    let s = hinfix::lti::resolve_plant("cdp").unwrap_err().to_string();
    assert!(s.contains("did you mean `CDP`?"), "{s}");
    assert!(hinfix::lti::resolve_plant("HE1").unwrap().ends_with("plants/HE1.json"));
    assert!(hinfix::lti::resolve_plant("CDP").unwrap().ends_with("plants/compleib/CDP.json.gz"));
}

#[test]
fn a_plant_listed_as_missing_is_named_so() {
    // CM6 (no public data) and HF2D1 (left out for size) are in plants/compleib/MISSING.md,
    // ZerenOzbay (a paper problem without data) in plants/MISSING.md.
    for (name, list) in
        [("CM6", "compleib/MISSING.md"), ("HF2D1", "compleib/MISSING.md"), ("ZerenOzbay", "plants/MISSING.md")]
    {
        let s = hinfix::lti::resolve_plant(name).unwrap_err().to_string();
        assert!(s.contains(&format!("`{name}` is listed in")) && s.contains(list), "{s}");
    }
    // a name only inside another word of a list is not listed: CM6_I, HF2D
    for name in ["CM6_I", "HF2D", "NoSuchPlant"] {
        let s = hinfix::lti::resolve_plant(name).unwrap_err().to_string();
        assert!(!s.contains("is listed in"), "{s}");
    }
}

#[test]
fn unknown_top_level_key_is_rejected_by_name() {
    // A misspelt matrix (`d12`) or a key this version does not know was ignored.
    for key in ["d12", "ts", "dt", "comment"] {
        let text = with(|o| {
            o.insert(key.into(), json!(1));
        });
        let e = Plant::from_json_str(&text, "p.json").unwrap_err();
        assert!(matches!(&e.kind, PlantErrorKind::UnknownKey { key: k } if k == key), "{key}: {e}");
        assert!(e.to_string().contains(&format!("unknown key `{key}`")), "{e}");
    }
    // the optional provenance keys stay accepted
    let text = with(|o| {
        o.insert("notes".into(), json!("n"));
        o.insert("check".into(), json!({"gamma": 1.0}));
        o.insert("order".into(), json!(2));
        o.insert("description".into(), json!("d"));
        o.insert("Ts".into(), json!(0.5));
    });
    Plant::from_json_str(&text, "p.json").unwrap();
}

#[test]
fn each_shipped_plant_has_its_fingerprint_in_the_reference_table() {
    // The paper's values are matched by content fingerprint, not by name.
    let table = hinfix::campaign::PAPER_PLANT_FINGERPRINTS;
    let shipped: Vec<String> =
        hinfix::lti::library_plants().unwrap().into_iter().filter(|p| p.collection.is_none()).map(|p| p.name).collect();
    assert_eq!(table.len(), shipped.len());
    for name in shipped {
        let p = Plant::load(plants_dir().join(format!("{name}.json"))).unwrap();
        let entry = table.iter().find(|(n, _)| *n == name).unwrap_or_else(|| panic!("{name} has no entry"));
        assert_eq!(entry.1, p.fingerprint(), "{name}: the table's fingerprint is not the shipped file's");
        assert_eq!(hinfix::campaign::paper_plant_name(&p.fingerprint()), Some(name.as_str()));
    }
}

#[test]
fn a_changed_plant_named_like_a_paper_plant_is_not_compared_with_the_paper() {
    use hinfix::campaign::{compare_rows, load_default_reference, BestRow};
    let he1 = Plant::load(plants_dir().join("HE1.json")).unwrap();
    let mut changed = he1.clone();
    changed.a[(0, 0)] += 1e-3;
    let reference = load_default_reference().unwrap();
    let row =
        |p: &Plant| BestRow { gamma: 0.2, runs: 1, verified: 1, ..BestRow::new("HE1".into(), p.fingerprint(), 1) };
    let rows = compare_rows(&[row(&he1), row(&changed)], &[], &reference);
    assert_eq!(rows[0].paper, 0.1235, "the shipped HE1 is compared with the paper's");
    assert!(rows[1].paper.is_nan() && rows[1].literature.is_empty(), "{:?}", rows[1]);
    // and a renamed copy of the shipped plant still is
    let mut renamed = row(&he1);
    renamed.plant = "MyHelicopter".into();
    assert_eq!(compare_rows(&[renamed], &[], &reference)[0].paper, 0.1235);
}

/// `Plant::from_matrices` (the Python binding's entry) gives the plant of the file, bit for bit,
/// and refuses what the file reader refuses, naming the matrix.
#[test]
fn a_plant_from_its_matrices_is_the_plant_of_its_file() {
    for name in ["HE1", "AC8"] {
        let p = Plant::load(plants_dir().join(format!("{name}.json"))).unwrap();
        let q = Plant::from_matrices(name, p.matrices()).unwrap();
        assert_eq!(q.dims, p.dims);
        assert_eq!(q.fingerprint(), p.fingerprint(), "{name}");
    }
    let p = Plant::from_json_str(&good().to_string(), "t.json").unwrap();
    let mut m: Vec<faer::Mat<f64>> = p.matrices().iter().map(|m| m.to_owned()).collect();
    m[5][(0, 0)] = f64::NAN;
    let refs: [faer::MatRef<'_, f64>; 9] = std::array::from_fn(|i| m[i].as_ref());
    let err = Plant::from_matrices("T", refs).unwrap_err();
    assert!(matches!(err, PlantErrorKind::Matrix { matrix: "D11", problem: MatrixJsonError::NotFinite { .. }, .. }));
    m[5][(0, 0)] = 0.0;
    m[6] = faer::Mat::zeros(2, 1); // D12 with 2 rows where C1 has 1
    let refs: [faer::MatRef<'_, f64>; 9] = std::array::from_fn(|i| m[i].as_ref());
    let err = Plant::from_matrices("T", refs).unwrap_err();
    assert!(err.to_string().contains("D12"), "{err}");
}

/// A plant library folder that is not there (HINFIX_PLANTS pointing nowhere) is named in the
/// error, not listed as a library of no plants ("known: ").
#[test]
fn a_library_folder_that_is_not_there_is_named() {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_campaign"))
        .args(["plant", "HE1"])
        .env("HINFIX_PLANTS", "/nonexistent/hinfix-plants")
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.contains("the library folder /nonexistent/hinfix-plants is not a folder (from HINFIX_PLANTS)"),
        "{err}"
    );
}
