//! Property-based fuzzing of every reader of outside input:
//! the plant and controller JSON readers, the campaign-file reader (single-plant problems, and
//! `[[problem]]` tables of several plants with objectives, weights, bounds and a structure), the
//! journal reader, the MCAP trace reader (mutations of a real trace), the MAT-file reader
//! (mutations of real plant files, plain and compressed), the controller-structure readers (JSON
//! and .mat), and `design::validate`. The property is always the same: any input gives `Ok` or a clear `Err`,
//! never a panic (proptest turns a panic into a failing case and shrinks it).
//!
//! Inputs are partly free (arbitrary JSON, TOML-ish text, bytes) and partly mutations of valid
//! files (one field replaced by an arbitrary value, bytes flipped, the text cut short), so that
//! the deep paths (shapes, dims, option ranges, record fields) are reached too.
//!
//! `cargo test --release --test fuzz_readers` runs a fast subset ([`FAST_CASES`] per target). The
//! full run, `cargo test --release --test fuzz_readers -- --ignored --nocapture`, runs
//! [`FULL_CASES`] (100 000) inputs per target and prints the counts; `HINFIX_FUZZ_CASES=N` sets
//! another count per target for the full run.

use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::OnceLock;

use hinfix::campaign::parse_journal;
use hinfix::campaign::JobRecord;
use hinfix::campaign::{expand, Campaign, RunnerTag};
use hinfix::campaign::{summarise_bytes, TraceError, TraceWriter};
use hinfix::design::{
    validate, ControllerShape, DesignOptions, DesignOutcome, DesignStatus, ObjectiveKind, Phase, PhaseStats, Structure,
};
use hinfix::lti::{read_mat_vars, Controller, Plant};
use proptest::prelude::*;
use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};
use serde_json::{json, Value};

/// Cases per target in `cargo test`.
const FAST_CASES: u32 = 300;
/// Cases per target in the ignored full run, unless `HINFIX_FUZZ_CASES` says otherwise.
const FULL_CASES: u32 = 100_000;

fn manifest(p: &str) -> String {
    format!("{}/{p}", env!("CARGO_MANIFEST_DIR"))
}

fn he1_text() -> &'static str {
    static T: OnceLock<String> = OnceLock::new();
    T.get_or_init(|| std::fs::read_to_string(manifest("plants/HE1.json")).unwrap())
}

fn he1() -> &'static Plant {
    static P: OnceLock<Plant> = OnceLock::new();
    P.get_or_init(|| Plant::from_json_str(he1_text(), "HE1.json").unwrap())
}

const CONTROLLER: &str =
    r#"{"AK": [[-1.0, 0.5], [0.0, -2.0]], "BK": [[1.0], [0.5]], "CK": [[1.0, 0.0], [0.0, 1.0]], "DK": [[0.1], [0.2]]}"#;

/// A valid journal line (a converged HE1 job with every field filled in).
fn record_line() -> &'static str {
    static L: OnceLock<String> = OnceLock::new();
    L.get_or_init(|| {
        let c = Campaign::from_toml_str(
            &format!("name = \"f\"\n[[problem]]\nplant = \"{}\"\norders = [2]\n", manifest("plants/HE1.json")),
            Path::new("f.toml"),
        )
        .unwrap();
        let job = &expand(&c, RunnerTag::Design)[0];
        let out = DesignOutcome {
            status: DesignStatus::Converged,
            controller: serde_json::from_str(CONTROLLER).unwrap(),
            gamma: 0.2,
            k_hinf: 3.0,
            alpha_cl: -0.1,
            alpha_k: Some(-1.0),
            objective: 0.2,
            controller_norm_active: false,
            certificate: Some(hinfix::design::Certificate { dnorm: 1e-4, evaldist: 1e-3 }),
            iterations: 10,
            evaluations: 20,
            phases: vec![PhaseStats { phase: Phase::Optimisation, iters: 10, evals: 20, cpu_s: 0.5 }],
            design_cpu_s: 0.5,
            search: hinfix::design::SearchSummary {
                starts: 3,
                best_start: 1,
                best_start_kind: Some(hinfix::design::StartKind::Central),
                best_start_scaled: false,
                cpu_to_best_s: 0.25,
                evals_to_best: 12,
                stop: hinfix::design::SearchStop::Stall,
            },
            plants: Vec::new(),
        };
        let r = JobRecord::from_run("f", job, false, Ok(out), 1.0, 1.5).unwrap();
        serde_json::to_string(&r).unwrap()
    })
}

/// Keys that the readers look for, so that generated objects hit real fields.
const KEYS: &[&str] = &[
    "name",
    "dims",
    "n",
    "m1",
    "m2",
    "p1",
    "p2",
    "A",
    "B1",
    "B2",
    "C1",
    "C2",
    "D11",
    "D12",
    "D21",
    "D22",
    "Ts",
    "source",
    "citation",
    "order",
    "AK",
    "BK",
    "CK",
    "DK",
    "status",
    "kind",
    "gamma",
    "eps",
    "options",
    "controller",
    "schema_version",
    "certificate",
    "phases",
];

fn arb_key() -> impl Strategy<Value = String> {
    prop_oneof![3 => proptest::sample::select(KEYS).prop_map(str::to_string), 1 => ".{0,6}"]
}

fn arb_number() -> impl Strategy<Value = Value> {
    prop_oneof![
        any::<f64>().prop_map(|x| json!(x)),
        any::<i64>().prop_map(|x| json!(x)),
        any::<u64>().prop_map(|x| json!(x)),
        (-3i64..10).prop_map(|x| json!(x)),
        Just(json!(1e308)),
        Just(json!(-0.0)),
    ]
}

fn arb_json() -> impl Strategy<Value = Value> {
    let leaf = prop_oneof![
        Just(Value::Null),
        any::<bool>().prop_map(Value::Bool),
        arb_number(),
        prop_oneof![Just("inf".to_string()), Just("nan".to_string()), ".{0,12}"].prop_map(Value::String),
    ];
    leaf.prop_recursive(4, 48, 6, |inner| {
        prop_oneof![
            prop::collection::vec(inner.clone(), 0..6).prop_map(Value::Array),
            prop::collection::vec((arb_key(), inner), 0..6).prop_map(|kv| Value::Object(kv.into_iter().collect())),
        ]
    })
}

/// Replaces the value at a random path (object keys and array indices, by position) of `doc`;
/// the path stops early at a leaf or an empty container, whose value is replaced.
fn replace_at(doc: &mut Value, path: &[usize], new: Value) {
    let Some((&i, rest)) = path.split_first() else {
        *doc = new;
        return;
    };
    match doc {
        Value::Object(o) if !o.is_empty() => {
            let k = o.keys().nth(i % o.len()).unwrap().clone();
            replace_at(o.get_mut(&k).unwrap(), rest, new);
        }
        Value::Array(a) if !a.is_empty() => {
            let n = a.len();
            replace_at(&mut a[i % n], rest, new);
        }
        _ => *doc = new,
    }
}

/// Text mutations: cut, flip a byte, insert, delete.
#[derive(Debug, Clone)]
enum Edit {
    Cut(usize),
    Set(usize, u8),
    Insert(usize, Vec<u8>),
    Delete(usize, usize),
}

fn arb_edits() -> impl Strategy<Value = Vec<Edit>> {
    let edit = prop_oneof![
        any::<usize>().prop_map(Edit::Cut),
        (any::<usize>(), any::<u8>()).prop_map(|(i, b)| Edit::Set(i, b)),
        (any::<usize>(), prop::collection::vec(any::<u8>(), 1..8)).prop_map(|(i, b)| Edit::Insert(i, b)),
        (any::<usize>(), 1usize..16).prop_map(|(i, n)| Edit::Delete(i, n)),
    ];
    prop::collection::vec(edit, 1..4)
}

fn apply(text: &str, edits: &[Edit]) -> Vec<u8> {
    apply_bytes(text.as_bytes(), edits)
}

fn apply_bytes(bytes: &[u8], edits: &[Edit]) -> Vec<u8> {
    let mut b = bytes.to_vec();
    for e in edits {
        let n = b.len().max(1);
        match e {
            Edit::Cut(i) => b.truncate(i % n),
            Edit::Set(i, x) => {
                if !b.is_empty() {
                    let k = i % b.len();
                    b[k] = *x;
                }
            }
            Edit::Insert(i, x) => {
                let k = i % (b.len() + 1);
                b.splice(k..k, x.iter().copied());
            }
            Edit::Delete(i, len) => {
                if !b.is_empty() {
                    let k = i % b.len();
                    let end = (k + len).min(b.len());
                    b.drain(k..end);
                }
            }
        }
    }
    b
}

/// A document: free JSON, a valid document with one value replaced, or a valid text edited.
fn arb_doc(valid: &'static str) -> impl Strategy<Value = String> {
    let base: Value = serde_json::from_str(valid).unwrap();
    prop_oneof![
        1 => arb_json().prop_map(|v| v.to_string()),
        2 => (prop::collection::vec(any::<usize>(), 1..5), arb_json()).prop_map(move |(path, v)| {
            let mut d = base.clone();
            replace_at(&mut d, &path, v);
            d.to_string()
        }),
        2 => arb_edits().prop_map(move |e| String::from_utf8_lossy(&apply(valid, &e)).into_owned()),
    ]
}

/// The fast subset uses a fixed seed (the same inputs in every `cargo test`); the full run a
/// fresh one each time, to explore further.
fn runner(cases: u32) -> TestRunner {
    let config = Config { cases, failure_persistence: None, max_shrink_iters: 2000, ..Config::default() };
    if cases <= FAST_CASES {
        TestRunner::new_with_rng(config, TestRng::deterministic_rng(RngAlgorithm::ChaCha))
    } else {
        TestRunner::new(config)
    }
}

/// Inputs tried by one target, and how many of them the reader accepted (`Ok`): a share of
/// accepted inputs shows that the mutations reach past the first checks.
#[derive(Debug, Clone, Copy)]
struct Counts {
    tried: usize,
    accepted: usize,
}

/// Runs one target; `f` says whether the input was accepted.
fn fuzz<S: Strategy>(name: &str, cases: u32, strategy: S, f: impl Fn(S::Value) -> bool) -> Counts
where
    S::Value: std::fmt::Debug,
{
    let tried = AtomicUsize::new(0);
    let accepted = AtomicUsize::new(0);
    let result = runner(cases).run(&strategy, |input| {
        tried.fetch_add(1, Ordering::Relaxed);
        if f(input) {
            accepted.fetch_add(1, Ordering::Relaxed);
        }
        Ok(())
    });
    if let Err(e) = result {
        panic!("{name}: {e}");
    }
    Counts { tried: tried.into_inner(), accepted: accepted.into_inner() }
}

fn plant_target(cases: u32) -> Counts {
    fuzz("plant reader", cases, arb_doc(he1_text()), |text| Plant::from_json_str(&text, "fuzz.json").is_ok())
}

fn controller_target(cases: u32) -> Counts {
    fuzz("controller reader", cases, arb_doc(CONTROLLER), |text| match Controller::from_json_str(&text, "k.json") {
        Ok(k) => {
            let _ = k.check_fits(he1());
            true
        }
        Err(_) => false,
    })
}

/// Campaign text: a template whose values are generated (so counts, ranges and option values
/// reach the checks), or a valid file edited byte-wise.
fn arb_campaign() -> impl Strategy<Value = String> {
    // Mostly valid values (HE1 has n = 4), so that whole files get through, and every kind of
    // invalid one.
    let int = prop_oneof![
        6 => (1i64..4).prop_map(|x| x.to_string()),
        1 => any::<i64>().prop_map(|x| x.to_string()),
        1 => (-2i64..12).prop_map(|x| x.to_string()),
        1 => Just("9223372036854775807".to_string()),
    ];
    let float = prop_oneof![
        8 => (1e-6f64..1.0).prop_map(|x| format!("{x:?}")),
        1 => any::<f64>().prop_map(|x| format!("{x:?}")),
        1 => Just("inf".to_string()),
        1 => Just("nan".to_string()),
        1 => Just("-1.0".to_string()),
        1 => Just("1e300".to_string()),
        1 => Just("1e-20".to_string()),
    ];
    let orders = prop_oneof![
        int.clone(),
        prop::collection::vec(int.clone(), 0..4).prop_map(|v| format!("[{}]", v.join(", "))),
        (int.clone(), int.clone()).prop_map(|(a, b)| format!("{{ from = {a}, to = {b} }}")),
    ];
    let seeds =
        prop_oneof![int.clone(), prop::collection::vec(int.clone(), 0..4).prop_map(|v| format!("[{}]", v.join(", ")))];
    let eps = prop_oneof![
        float.clone(),
        prop::collection::vec(float.clone(), 0..3).prop_map(|v| format!("[{}]", v.join(", ")))
    ];
    let name = prop_oneof![6 => Just("\"ok\"".to_string()), 1 => ".{0,8}".prop_map(|s| format!("{s:?}")), 1 => Just(format!("\"{}\"", "x".repeat(300)))];
    let option = prop_oneof![
        float.clone().prop_map(|v| format!("cpumax = {v}")),
        float.clone().prop_map(|v| format!("hinf_tol = {v}")),
        float.clone().prop_map(|v| format!("normtol = {v}")),
        float.clone().prop_map(|v| format!("evaldist = {v}")),
        int.clone().prop_map(|v| format!("nrand = {v}")),
        int.clone().prop_map(|v| format!("maxit = {v}")),
        Just("objective = \"plain\"".to_string()),
        Just("warm_start = true".to_string()),
    ];
    let template = (name, orders, seeds, eps, int.clone(), prop::collection::vec(option, 0..3)).prop_map(
        |(name, orders, seeds, eps, threads, opts)| {
            format!(
                "name = {name}\n[defaults]\nthreads = {threads}\n[[problem]]\nplant = \"HE1\"\norders = {orders}\nseeds = {seeds}\neps = {eps}\n{}\n",
                opts.join("\n")
            )
        },
    );
    const GOOD: &str = "name = \"g\"\n[defaults]\neps = [1e-2, 1e-3]\nseeds = 2\ncpumax = 5.0\n[[problem]]\nplant = \"HE1\"\norders = { from = 1, to = 3 }\nwarm_start = true\n";
    prop_oneof![3 => template, 1 => arb_edits().prop_map(|e| String::from_utf8_lossy(&apply(GOOD, &e)).into_owned())]
}

fn campaign_target(cases: u32) -> Counts {
    // Bare plant names resolve in the project's plant library.
    std::env::set_var(hinfix::lti::PLANTS_ENV, manifest("plants"));
    fuzz("campaign reader", cases, arb_campaign(), |text| {
        Campaign::from_toml_str(&text, Path::new("fuzz.toml")).is_ok()
    })
}

fn journal_target(cases: u32) -> Counts {
    let line = record_line();
    let base: Value = serde_json::from_str(line).unwrap();
    let mutated_line = (prop::collection::vec(any::<usize>(), 1..4), arb_json()).prop_map(move |(path, v)| {
        let mut d = base.clone();
        replace_at(&mut d, &path, v);
        d.to_string()
    });
    let journal = prop_oneof![
        prop::collection::vec(any::<u8>(), 0..256),
        (mutated_line, any::<bool>())
            .prop_map(move |(l, nl)| format!("{line}\n{l}{}", if nl { "\n" } else { "" }).into_bytes()),
        arb_edits().prop_map(move |e| apply(&format!("{line}\n{line}\n"), &e)),
    ];
    fuzz("journal reader", cases, journal, |bytes| {
        match parse_journal(&bytes, Path::new("runs.jsonl")) {
            Ok(read) => {
                // What was read can be written again and read back.
                for r in read.records {
                    let again = serde_json::to_string(&r).unwrap();
                    serde_json::from_str::<JobRecord>(&again).unwrap();
                }
                true
            }
            Err(_) => false,
        }
    })
}

/// The bytes of a real trace: a [`TraceWriter`] file of 30 iterations in two phases and the
/// final record of [`record_line`].
fn trace_bytes() -> &'static [u8] {
    static T: OnceLock<Vec<u8>> = OnceLock::new();
    T.get_or_init(|| {
        let dir = tempfile::tempdir().unwrap();
        let mut w = TraceWriter::create(dir.path(), "job", hinfix::design::ObserverMode::Always).unwrap();
        for i in 0..30 {
            let x = i as f64;
            let it = hinfix::optim::Iteration {
                solver: hinfix::optim::SolverKind::Bfgs,
                start: i / 20,
                iter: i % 20,
                f: 1.0 / (1.0 + x),
                dnorm: 1e-3,
                step: 1.0,
                evals: 2 * i,
                cpu_s: x / 10.0,
            };
            w.record_iter(&hinfix::design::DesignIterRecord {
                phase: if i < 10 { Phase::Stabilisation } else { Phase::Optimisation },
                it,
                gamma: if i < 10 { f64::INFINITY } else { 2.0 - x / 100.0 },
                k_hinf: f64::NAN,
                alpha_cl: -x,
                alpha_k: f64::NAN,
                improved: true,
            })
            .unwrap();
        }
        let record: JobRecord = serde_json::from_str(record_line()).unwrap();
        std::fs::read(w.complete(&record).unwrap()).unwrap()
    })
}

/// Byte-level mutations of `valid`: the text edits of [`arb_edits`], or 1–16 bytes overwritten
/// at a random place with random bytes or with one repeated byte (lengths, offsets and counts
/// in binary formats are what such overwrites hit).
fn arb_bytes(valid: &'static [u8]) -> impl Strategy<Value = Vec<u8>> {
    let overwrite =
        (
            any::<usize>(),
            prop_oneof![
                prop::collection::vec(any::<u8>(), 1..16),
                (any::<u8>(), 1usize..16).prop_map(|(b, n)| vec![b; n]),
            ],
        )
            .prop_map(move |(at, with)| {
                let mut b = valid.to_vec();
                let k = at % b.len();
                for (i, x) in with.into_iter().enumerate() {
                    if let Some(slot) = b.get_mut(k + i) {
                        *slot = x;
                    }
                }
                b
            });
    prop_oneof![
        2 => overwrite,
        1 => arb_edits().prop_map(move |e| apply_bytes(valid, &e)),
    ]
}

fn trace_target(cases: u32) -> Counts {
    fuzz("trace reader", cases, arb_bytes(trace_bytes()), |bytes| {
        summarise_bytes(&bytes, Path::new("fuzz.mcap")).is_ok()
    })
}

fn mat_bytes(name: &str) -> &'static [u8] {
    static FILES: OnceLock<std::collections::BTreeMap<String, Vec<u8>>> = OnceLock::new();
    let files = FILES.get_or_init(|| {
        ["HE1.mat", "HE1_compressed.mat", "K2.mat"]
            .into_iter()
            .map(|f| (f.to_string(), std::fs::read(manifest(&format!("tests/fixtures/mat/{f}"))).unwrap()))
            .collect()
    });
    &files[name]
}

fn mat_target(cases: u32) -> Counts {
    let files = prop_oneof![
        arb_bytes(mat_bytes("HE1.mat")),
        arb_bytes(mat_bytes("HE1_compressed.mat")),
        arb_bytes(mat_bytes("K2.mat"))
    ];
    fuzz("MAT-file reader", cases, files, |bytes| {
        let vars = read_mat_vars(&bytes).is_ok();
        let plant = Plant::from_mat_bytes(&bytes, Path::new("fuzz.mat")).is_ok();
        vars || plant
    })
}

/// A structure for HE1 at order 1 (nk = 1, m = 2, p = 1): AK free, BK fixed, CK and DK mixed.
const STRUCTURE: &str = r#"{"AK": [[null]], "BK": [[0.5]], "CK": [[null], [1.0]], "DK": [[null], [-0.0]]}"#;

fn he1_order1() -> ControllerShape {
    ControllerShape::for_plant(he1(), 1)
}

/// A structure read is one whose fixed entries every projected controller keeps.
fn structure_accepted(s: Result<Structure, hinfix::design::StructureError>) -> bool {
    match s {
        Ok(s) => {
            let k = s.project(&Controller::zeros(1, 2, 1));
            assert!(s.violation(&k).is_none(), "a projected controller keeps the fixed entries");
            true
        }
        Err(e) => {
            assert!(!e.to_string().is_empty());
            false
        }
    }
}

fn structure_json_target(cases: u32) -> Counts {
    fuzz("structure JSON", cases, arb_doc(STRUCTURE), |text| {
        structure_accepted(Structure::from_json(&text, "s.json", he1_order1()))
    })
}

/// [`STRUCTURE`] as a MAT-file (NaN = free).
fn structure_mat() -> &'static [u8] {
    static B: OnceLock<Vec<u8>> = OnceLock::new();
    B.get_or_init(|| {
        let m = |r: usize, c: usize, v: &[f64]| faer::Mat::from_fn(r, c, |i, j| v[i + j * r]);
        let (ak, bk, ck, dk) =
            (m(1, 1, &[f64::NAN]), m(1, 1, &[0.5]), m(2, 1, &[f64::NAN, 1.0]), m(2, 1, &[f64::NAN, -0.0]));
        hinfix::lti::write_mat(
            &[("AK", ak.as_ref()), ("BK", bk.as_ref()), ("CK", ck.as_ref()), ("DK", dk.as_ref())],
            "s",
        )
    })
}

fn structure_mat_target(cases: u32) -> Counts {
    fuzz("structure .mat", cases, arb_bytes(structure_mat()), |bytes| {
        structure_accepted(Structure::from_mat_bytes(&bytes, "s.mat", he1_order1()))
    })
}

/// Campaign text with `[[problem]]` tables of several plants: plant lists, objectives, weights,
/// bounds, names and a structure drawn from mostly valid and every kind of invalid value.
fn arb_multi_campaign() -> impl Strategy<Value = String> {
    let plant = prop_oneof![
        4 => Just("\"HE1\"".to_string()),
        4 => (1..=3).prop_map(|i| format!("{:?}", manifest(&format!("examples/multi-model/HE1_op{i}.json")))),
        1 => Just(format!("{:?}", manifest("examples/discrete/HE1_Ts0.1.json"))),
        1 => Just("\"AC8\"".to_string()),
        1 => ".{0,6}".prop_map(|s| format!("{s:?}")),
    ];
    let plants = prop::collection::vec(plant, 0..4).prop_map(|v| format!("[{}]", v.join(", ")));
    let objective = prop_oneof![
        4 => proptest::sample::select(vec!["\"hinf\"", "\"h2\"", "\"abscissa\"", "\"radius\""]).prop_map(str::to_string),
        1 => Just("\"H2\"".to_string()),
        1 => Just("3".to_string()),
    ];
    let number = prop_oneof![
        6 => (1e-3f64..10.0).prop_map(|x| format!("{x:?}")),
        1 => any::<f64>().prop_map(|x| format!("{x:?}")),
        1 => prop_oneof![Just("1e308"), Just("-1.0"), Just("0"), Just("nan"), Just("inf"), Just("1e-320")].prop_map(str::to_string),
    ];
    let bound = prop_oneof![2 => Just("\"none\"".to_string()), 2 => number.clone(), 1 => Just("\"nope\"".to_string())];
    fn per_plant(one: impl Strategy<Value = String> + Clone) -> impl Strategy<Value = String> {
        prop_oneof![
            one.clone(),
            prop::collection::vec(one, 0..4).prop_map(|v| format!("[{}]", v.join(", "))),
            Just("{ a = 1 }".to_string()),
        ]
    }
    let structure = prop_oneof![
        3 => Just(None),
        1 => Just(Some(format!("{:?}", manifest("tests/fixtures/structure-fuzz-does-not-exist.json")))),
        1 => Just(Some("\"/dev/zero\"".to_string())),
    ];
    let optional = |s: BoxedStrategy<String>| prop::option::weighted(0.7, s);
    (
        plants,
        optional(per_plant(objective).boxed()),
        optional(per_plant(number).boxed()),
        optional(per_plant(bound).boxed()),
        prop::option::weighted(0.7, "[a-z]{1,6}"),
        structure,
        prop_oneof![Just("[0]"), Just("[1]"), Just("{ from = 0, to = 2 }"), Just("[9]")],
        any::<bool>(),
    )
        .prop_map(|(plants, objectives, weights, bounds, name, structure, orders, warm)| {
            let mut s = format!(
                "name = \"m\"\n[defaults]\nmaxevals = 100\n[[problem]]\nplants = {plants}\norders = {orders}\n"
            );
            for (key, v) in
                [("objectives", objectives), ("weights", weights), ("bounds", bounds), ("structure", structure)]
            {
                if let Some(v) = v {
                    s += &format!("{key} = {v}\n");
                }
            }
            if let Some(n) = name {
                s += &format!("name = \"{n}\"\n");
            }
            if warm {
                s += "warm_start = true\n";
            }
            s
        })
}

fn multi_campaign_target(cases: u32) -> Counts {
    std::env::set_var(hinfix::lti::PLANTS_ENV, manifest("plants"));
    fuzz("several-plant problems", cases, arb_multi_campaign(), |text| {
        match Campaign::from_toml_str(&text, Path::new("fuzz.toml")) {
            Ok(c) => {
                let _ = expand(&c, RunnerTag::Design);
                true
            }
            Err(e) => {
                let m = e.to_string();
                assert!(!m.contains("untagged") && !m.contains("usize"), "serde jargon: {m}");
                false
            }
        }
    })
}

#[allow(clippy::needless_update)]
fn validate_target(cases: u32) -> Counts {
    // Mostly valid values, so that every check is reached, and every kind of invalid one.
    let size = prop_oneof![4 => 1usize..4, 1 => Just(0usize), 1 => any::<usize>()];
    let float = prop_oneof![
        6 => 1e-12f64..1.0,
        1 => any::<f64>(),
        1 => prop_oneof![Just(f64::INFINITY), Just(f64::NAN), Just(0.0), Just(-1.0), Just(1e-15), Just(1e308)],
    ];
    let opts = (
        (size.clone(), float.clone(), any::<u64>(), float.clone(), size.clone()),
        (any::<bool>(), float.clone(), size.clone(), float.clone(), float.clone(), any::<bool>(), size.clone()),
    )
        .prop_map(|((order, eps, seed, cpumax, nrand), (plain, hinf_tol, maxit, normtol, evaldist, gs, gsm))| {
            DesignOptions {
                order,
                eps,
                seed,
                cpumax,
                nrand,
                objective: if plain { ObjectiveKind::Plain } else { ObjectiveKind::Strong },
                hinf_tol,
                maxit,
                normtol,
                evaldist,
                gradient_sampling: gs,
                gradsamp_maxit: gsm,
                // (options that other issues add keep their defaults)
                ..DesignOptions::default()
            }
        });
    let init = prop::option::weighted(
        0.3,
        (0usize..4, 0usize..3, 0usize..3, float.clone()).prop_map(|(nk, m, p, x)| {
            let mut k = Controller::zeros(nk, m, p);
            if m > 0 && p > 0 {
                k.dk[(0, 0)] = x;
            }
            k
        }),
    );
    fuzz("design::validate", cases, (opts, init), |(o, k)| validate(he1(), &o, k.as_ref()).is_ok())
}

fn all(cases: u32) -> Vec<(&'static str, Counts)> {
    vec![
        ("plant reader", plant_target(cases)),
        ("controller reader", controller_target(cases)),
        ("campaign reader", campaign_target(cases)),
        ("journal reader", journal_target(cases)),
        ("trace reader", trace_target(cases)),
        ("MAT-file reader", mat_target(cases)),
        ("design::validate", validate_target(cases)),
        ("structure JSON", structure_json_target(cases)),
        ("structure .mat", structure_mat_target(cases)),
        ("several-plant problems", multi_campaign_target(cases)),
    ]
}

#[test]
fn trace_with_eight_bytes_overwritten_anywhere_is_an_error_not_a_panic() {
    // A real trace with 8 bytes overwritten made the mcap reader panic (slice
    // index out of range), and `campaign trace` exit 101. Every offset, three fillers.
    let good = trace_bytes();
    assert!(summarise_bytes(good, Path::new("t.mcap")).unwrap().iterations > 0);
    let mut damaged = 0;
    for filler in [0x00u8, 0xff, 0x7f] {
        for at in 0..good.len() {
            let mut b = good.to_vec();
            for slot in b.iter_mut().skip(at).take(8) {
                *slot = filler;
            }
            if let Err(TraceError::Damaged { message, .. }) = summarise_bytes(&b, Path::new("t.mcap")) {
                assert!(!message.is_empty());
                damaged += 1;
            }
        }
    }
    // the reader's panic is reached (and caught) at some offsets
    assert!(damaged > 0);
}

#[test]
fn readers_never_panic_fast_subset() {
    for (name, c) in all(FAST_CASES) {
        assert!(c.tried as u32 >= FAST_CASES, "{name}: {c:?}");
        // Some inputs must get through, or the mutations only test the first check.
        assert!(c.accepted > 0 && c.accepted < c.tried, "{name}: {c:?}");
    }
}

#[test]
#[ignore = "minutes in release: cargo test --release --test fuzz_readers -- --ignored --nocapture"]
fn readers_never_panic_full() {
    let t = std::time::Instant::now();
    let cases = std::env::var("HINFIX_FUZZ_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(FULL_CASES);
    let counts = all(cases);
    let total: usize = counts.iter().map(|c| c.1.tried).sum();
    for (name, c) in &counts {
        eprintln!(
            "fuzz {name:<20} {:>7} inputs ({:>6} accepted, {:>6} clear errors), 0 panics",
            c.tried,
            c.accepted,
            c.tried - c.accepted
        );
    }
    eprintln!("fuzz total {total} inputs, 0 panics, {:.1} s", t.elapsed().as_secs_f64());
    assert!(counts.iter().all(|c| c.1.tried as u32 >= cases), "{counts:?}");
}
