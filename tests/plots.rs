//! `campaign plot`: every figure kind (γ vs order, convergence, σ-plot) rendered from a tiny real
//! campaign as PNG and SVG; the files are checked (PNG signature and IHDR size, SVG parses as XML
//! with an `<svg>` root and text), and the figures' data on synthetic input (log axis when values
//! span decades, phase boundaries and restarts found where they are).

use std::path::{Path, PathBuf};
use std::process::Command;

use hinfix::campaign::plot::{log_ticks, png_bytes, svg_text, SIZE};
use hinfix::campaign::plot::{ConvergenceFigure, GammaOrderFigure};
use hinfix::campaign::{FullOrderSource, TraceIteration};

const BIN: &str = env!("CARGO_BIN_EXE_campaign");

/// Checks a PNG: signature, IHDR width × height = [`SIZE`], and a plausible size (a blank image
/// of this size compresses to ~2 kB; a drawn figure is bigger).
fn check_png(bytes: &[u8], what: &str) {
    assert!(bytes.starts_with(b"\x89PNG\r\n\x1a\n"), "{what}: not a PNG");
    assert_eq!(&bytes[12..16], b"IHDR", "{what}");
    let w = u32::from_be_bytes(bytes[16..20].try_into().unwrap());
    let h = u32::from_be_bytes(bytes[20..24].try_into().unwrap());
    assert_eq!((w, h), SIZE, "{what}");
    assert!(bytes.len() > 10_000, "{what}: only {} bytes", bytes.len());
}

/// Checks an SVG: well-formed XML, `<svg>` root, some text and some paths.
fn check_svg(text: &str, what: &str) {
    let doc = roxmltree::Document::parse(text).unwrap_or_else(|e| panic!("{what}: SVG does not parse: {e}"));
    assert_eq!(doc.root_element().tag_name().name(), "svg", "{what}");
    assert!(doc.descendants().any(|n| n.has_tag_name("text")), "{what}: no text");
    assert!(
        doc.descendants()
            .filter(|n| n.has_tag_name("polyline") || n.has_tag_name("path") || n.has_tag_name("line"))
            .count()
            > 5,
        "{what}: no lines"
    );
}

/// `campaign <args> FILE --results DIR` with the shipped plants; it must succeed.
fn campaign(args: &[&str], file: &Path, results: &Path) -> std::process::Output {
    let out = Command::new(BIN)
        .args(args)
        .arg(file)
        .arg("--results")
        .arg(results)
        .env("HINFIX_PLANTS", concat!(env!("CARGO_MANIFEST_DIR"), "/plants"))
        .output()
        .unwrap();
    assert!(out.status.success(), "campaign {args:?}: {}", String::from_utf8_lossy(&out.stderr));
    out
}

#[test]
fn every_figure_kind_is_rendered_for_a_small_real_campaign() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("c.toml");
    std::fs::write(&file, "name = \"p\"\n[defaults]\neps = [1e-3]\nseeds = 1\ncpumax = 2.0\nnrand = 1\nspend_budget = false\n[[problem]]\nplant = \"REA2\"\norders = [1, 2]\n").unwrap();
    let results = dir.path().join("r");
    let run = |args: &[&str]| campaign(args, &file, &results);
    run(&["run", "--no-progress"]);
    let out = run(&["plot"]);
    let listed = String::from_utf8_lossy(&out.stdout).to_string();
    let plots = results.join("p").join("plots");
    let mut expected: Vec<PathBuf> = Vec::new();
    for stem in
        ["gamma-vs-order_REA2", "convergence_REA2_nK1", "convergence_REA2_nK2", "sigma_REA2_nK1", "sigma_REA2_nK2"]
    {
        for ext in ["png", "svg"] {
            expected.push(plots.join(format!("{stem}.{ext}")));
        }
    }
    for f in &expected {
        assert!(
            f.is_file(),
            "{} missing; plot printed:\n{listed}\n{}",
            f.display(),
            String::from_utf8_lossy(&out.stderr)
        );
        assert!(listed.contains(&f.display().to_string()), "{} not listed", f.display());
        let what = f.display().to_string();
        if f.extension().unwrap() == "png" {
            check_png(&std::fs::read(f).unwrap(), &what);
        } else {
            check_svg(&std::fs::read_to_string(f).unwrap(), &what);
        }
    }
    let svg = std::fs::read_to_string(plots.join("sigma_REA2_nK1.svg")).unwrap();
    assert!(svg.contains("rad/s") && svg.contains("peak"), "σ-plot labels");
    let svg = std::fs::read_to_string(plots.join("gamma-vs-order_REA2.svg")).unwrap();
    assert!(svg.contains("paper (HIFOO, 2008)") && svg.contains("full-order bound"), "γ-vs-order legend");
    let svg = std::fs::read_to_string(plots.join("convergence_REA2_nK1.svg")).unwrap();
    assert!(svg.contains("CPU time (s)"), "convergence x axis");

    // A trace with 8 bytes overwritten made the MCAP reader panic, so `campaign
    // trace` exited 101 and `campaign plot` died. Damage the order-1 trace where the reader
    // panics (found with the library, so the test keeps hitting that path).
    let traces: Vec<PathBuf> =
        std::fs::read_dir(results.join("p").join("traces")).unwrap().map(|e| e.unwrap().path()).collect();
    let title = |t: &Path| hinfix::campaign::summarise(t).unwrap().final_status;
    assert_eq!(traces.len(), 2, "{traces:?}");
    let good = std::fs::read(&traces[0]).unwrap();
    let damaged = (0..good.len())
        .map(|at| {
            let mut b = good.clone();
            b[at..(at + 8).min(good.len())].fill(0xff);
            b
        })
        .find(|b| {
            matches!(
                hinfix::campaign::summarise_bytes(b, Path::new("t")),
                Err(hinfix::campaign::TraceError::Damaged { .. })
            )
        })
        .expect("some 8-byte overwrite makes the reader panic");
    assert!(title(&traces[1]).is_some());
    std::fs::write(&traces[0], damaged).unwrap();
    let out = Command::new(BIN).arg("trace").arg(&traces[0]).output().unwrap();
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stderr));
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("damaged trace") && !stderr.contains("panicked"), "{stderr}");
    for f in &expected {
        std::fs::remove_file(f).unwrap();
    }
    let out = run(&["plot"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("skipped: convergence of") && stderr.contains("damaged trace"), "{stderr}");
    let missing: Vec<&PathBuf> = expected.iter().filter(|f| !f.is_file()).collect();
    assert_eq!(missing.len(), 2, "only the damaged trace's figure is missing: {missing:?}");
    assert!(missing.iter().all(|f| f.to_string_lossy().contains("convergence_")), "{missing:?}");
}

/// A plant file for [`plant_names_never_share_or_overflow_figure_files`]: ẋ = −x + w + u,
/// z = c x, y = x.
fn tiny_plant(dir: &Path, file: &str, name: &str, c: f64) -> PathBuf {
    let p = dir.join(file);
    let doc = serde_json::json!({
        "name": name, "dims": {"n": 1, "m1": 1, "m2": 1, "p1": 1, "p2": 1},
        "A": [[-1.0]], "B1": [[1.0]], "B2": [[1.0]], "C1": [[c]], "C2": [[1.0]],
        "D11": [[0.0]], "D12": [[0.0]], "D21": [[0.0]], "D22": [[0.0]]
    });
    std::fs::write(&p, doc.to_string()).unwrap();
    p
}

#[test]
fn plant_names_never_share_or_overflow_figure_files() {
    // Plants "X+1" and "X_1" wrote the same figure files, and a 300-character
    // name failed with "File name too long" and stopped the later figures.
    let dir = tempfile::tempdir().unwrap();
    let long = "Y".repeat(300);
    let names = ["X+1", "X_1", long.as_str()];
    let mut toml = "name = \"n\"\n[defaults]\neps = [1e-3]\nseeds = 1\ncpumax = 1.0\nnrand = 1\nspend_budget = false\n"
        .to_string();
    for (i, name) in names.iter().enumerate() {
        let p = tiny_plant(dir.path(), &format!("p{i}.json"), name, 1.0 + i as f64);
        toml += &format!("[[problem]]\nplant = {:?}\norders = [0]\n", p.to_str().unwrap());
    }
    let file = dir.path().join("c.toml");
    std::fs::write(&file, toml).unwrap();
    let results = dir.path().join("r");
    for cmd in ["run", "plot"] {
        let mut c = Command::new(BIN);
        c.arg(cmd).arg(&file).arg("--results").arg(&results);
        if cmd == "run" {
            c.arg("--no-progress");
        }
        let out = c.output().unwrap();
        assert!(out.status.success(), "{cmd}: {}", String::from_utf8_lossy(&out.stderr));
    }
    let files: Vec<String> = std::fs::read_dir(results.join("n").join("plots"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    for kind in ["gamma-vs-order_", "sigma_"] {
        let n = files.iter().filter(|f| f.starts_with(kind) && f.ends_with(".png")).count();
        assert_eq!(n, 3, "{kind}: {files:?}");
    }
    assert!(files.iter().all(|f| f.len() < 100), "{files:?}");
    assert!(files.contains(&"gamma-vs-order_X_1.png".to_string()), "{files:?}");
}

/// The trimmed texts of an SVG's `<text>` elements.
fn svg_texts(svg: &str) -> Vec<String> {
    let doc = roxmltree::Document::parse(svg).unwrap();
    doc.descendants()
        .filter(|n| n.has_tag_name("text"))
        .filter_map(|n| n.text())
        .map(|t| t.trim().to_string())
        .collect()
}

fn it(phase: &str, start: usize, iteration: usize, f: f64, t: f64) -> TraceIteration {
    TraceIteration { phase: phase.into(), start, iteration, f, elapsed_cpu_s: t }
}

#[test]
fn convergence_marks_phases_and_restarts_and_renders() {
    let mut its = vec![it("stabilisation", 0, 0, 0.5, 0.01), it("stabilisation", 0, 1, -0.1, 0.02)];
    its.extend((0..20).map(|i| it("optimisation", 0, i, 10.0 / (1.0 + i as f64), 0.03 + 0.01 * i as f64)));
    its.extend((0..20).map(|i| it("optimisation", 1, i, 8.0 / (1.0 + i as f64), 0.3 + 0.01 * i as f64)));
    its.extend((0..5).map(|i| it("gradient_sampling", 0, i, 0.39 - 0.001 * i as f64, 0.6 + 0.01 * i as f64)));
    let fig = ConvergenceFigure { title: "synthetic".into(), iterations: its };
    assert!(fig.x_is_cpu());
    // Each marker at the last message before the change (the end of a run, in every trace).
    let phases: Vec<(f64, String)> = fig.phase_markers().into_iter().map(|m| (m.x, m.label)).collect();
    assert_eq!(phases, vec![(0.02, "BFGS".to_string()), (0.3 + 0.01 * 19.0, "gradient sampling".to_string())]);
    let restarts: Vec<(f64, String)> = fig.restart_markers().into_iter().map(|m| (m.x, m.label)).collect();
    assert_eq!(restarts, vec![(0.03 + 0.01 * 19.0, "start 2".to_string())]);
    let p = Path::new("synthetic.png");
    check_png(&png_bytes(&fig, p).unwrap(), "convergence");
    let svg = svg_text(&fig, p).unwrap();
    check_svg(&svg, "convergence");

    assert!(fig.shows_stabilisation());
    let texts = svg_texts(&svg);
    assert!(texts.iter().any(|t| t == "stabilisation objective (first local search)"), "{texts:?}");

    // A warm start that already stabilises: no stabilisation panel (it would be an empty sliver).
    let mut warm = vec![it("stabilisation", 0, 0, -0.01, 0.001), it("stabilisation", 0, 1, -0.02, 0.002)];
    warm.extend((0..20).map(|i| it("optimisation", 0, i, 2.0 / (1.0 + i as f64), 0.01 + 0.01 * i as f64)));
    let warm = ConvergenceFigure { title: "warm".into(), iterations: warm };
    assert!(!warm.shows_stabilisation());
    let svg = svg_text(&warm, p).unwrap();
    check_svg(&svg, "warm-started convergence");
    let texts = svg_texts(&svg);
    assert!(!texts.iter().any(|t| t.contains("stabilisation")), "{texts:?}");
    assert!(texts.iter().any(|t| t == "local searches (thinned)"), "{texts:?}");

    // No CPU clock (the test runner's traces): drawn against the iteration count.
    let flat = ConvergenceFigure {
        title: "flat".into(),
        iterations: (0..5).map(|i| it("optimisation", 0, i, 1.0, 0.0)).collect(),
    };
    assert!(!flat.x_is_cpu());
    check_svg(&svg_text(&flat, p).unwrap(), "flat convergence");
}

#[test]
fn gamma_vs_order_uses_a_log_axis_only_when_values_span_decades() {
    let pa = GammaOrderFigure {
        plant: "PA".into(),
        ours: vec![(1, 0.000351), (2, 0.00035)],
        plain: vec![],
        paper: vec![(1, 0.00035), (2, 0.00035)],
        full_order: Some((1e-6, FullOrderSource::Computed)),
        problem: false,
    };
    assert!(pa.log_axis());
    let he1 = GammaOrderFigure {
        plant: "HE1".into(),
        ours: vec![(1, 0.124), (2, 0.11)],
        plain: vec![],
        paper: vec![(1, 0.1235)],
        full_order: Some((0.0737, FullOrderSource::Paper)),
        problem: false,
    };
    assert!(!he1.log_axis());
    let p = Path::new("g.png");
    for fig in [&pa, &he1] {
        check_png(&png_bytes(fig, p).unwrap(), &fig.plant);
        check_svg(&svg_text(fig, p).unwrap(), &fig.plant);
    }
}

/// γ from 2.5 to 40 on a log axis is labelled below 10 too (it once had the one label 10); the
/// full-order line carries its value; the plain objective's series is drawn when there is one.
#[test]
fn gamma_vs_order_labels_its_whole_range_and_the_bound() {
    let ticks = log_ticks(2.2, 45.0);
    assert!(ticks.iter().any(|&t| t < 10.0) && ticks.iter().any(|&t| t > 10.0), "{ticks:?}");
    assert!((4..=12).contains(&ticks.len()), "{ticks:?}");
    assert_eq!(log_ticks(1e-7, 2.0), vec![1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2, 1e-1, 1.0]);
    let fig = GammaOrderFigure {
        plant: "own".into(),
        ours: vec![(1, 40.0), (2, 4.0), (3, 2.6)],
        plain: vec![(1, 3.0), (2, 2.55)],
        paper: vec![],
        full_order: Some((2.5, FullOrderSource::Computed)),
        problem: false,
    };
    assert!(fig.log_axis());
    let svg = svg_text(&fig, Path::new("g.svg")).unwrap();
    check_svg(&svg, "own");
    let texts = svg_texts(&svg);
    for label in
        ["3", "5", "20", "γ_opt = 2.5", "full-order bound γ_opt = 2.5", "ours, plain objective (K may be unstable)"]
    {
        assert!(texts.iter().any(|t| t == label), "{label} missing from {texts:?}");
    }
    // a bound that is not computed here says where it is from
    let from_index = GammaOrderFigure { full_order: Some((2.5, FullOrderSource::LibraryIndex)), ..fig };
    let texts = svg_texts(&svg_text(&from_index, Path::new("g.svg")).unwrap());
    assert!(texts.iter().any(|t| t == "full-order bound 2.5 (library index)"), "{texts:?}");
}

/// A fast job's trace with thousands of local searches: the figure shows the best objective
/// so far, at most MAX_RUNS_DRAWN searches of at most MAX_POINTS_PER_RUN points, one labelled
/// boundary per phase, and its SVG stays small (one was 9.3 MB).
#[test]
fn a_trace_of_thousands_of_restarts_is_drawn_thinned_and_small() {
    use hinfix::campaign::plot::convergence::{best_so_far, decimate, thin_runs, MAX_POINTS_PER_RUN, MAX_RUNS_DRAWN};
    let mut its = Vec::new();
    let mut t = 0.0;
    for start in 0..3000 {
        for i in 0..4 {
            t += 1e-3;
            its.push(it("stabilisation", start, i, 0.5 - 0.2 * i as f64, t));
        }
        for i in 0..30 {
            t += 1e-3;
            let f = 2.0 + 1.0 / (1.0 + start as f64).sqrt() + 0.5 / (1.0 + i as f64);
            its.push(it("optimisation", start, i, f, t));
        }
        if start % 10 == 0 {
            for i in 0..5 {
                t += 1e-3;
                its.push(it("gradient_sampling", start, i, 2.0 + 1.0 / (1.0 + start as f64).sqrt(), t));
            }
        }
    }
    let fig = ConvergenceFigure { title: "many".into(), iterations: its };
    assert_eq!(fig.first_phase_markers().len(), 3, "stabilisation, BFGS and gradient sampling, once each");
    let runs = fig.runs(false);
    assert!(runs.len() > 3000);
    let shown = thin_runs(&runs);
    assert!(shown.len() <= MAX_RUNS_DRAWN && !shown.is_empty());
    let best = best_so_far(&runs);
    assert!(best.windows(2).all(|w| w[1].1 <= w[0].1 && w[1].0 >= w[0].0), "the best so far never rises");
    let low = runs.iter().flat_map(|r| r.points.iter().map(|p| p.1)).fold(f64::INFINITY, f64::min);
    assert_eq!(best.last().unwrap().1, low);
    let svg = svg_text(&fig, Path::new("c.svg")).unwrap();
    check_svg(&svg, "many restarts");
    assert!(svg.len() < 400_000, "SVG of {} bytes", svg.len());
    let polylines = svg.matches("<polyline").count();
    // (thousands before thinning: one per local search and a dotted line per restart)
    assert!(polylines <= 600, "{polylines} polylines");
    let long: Vec<(f64, f64)> = (0..5000).map(|i| (i as f64, 1.0 / (1.0 + i as f64))).collect();
    let short = decimate(&long);
    assert_eq!((short.len(), short[0], *short.last().unwrap()), (MAX_POINTS_PER_RUN, long[0], long[4999]));
    check_png(&png_bytes(&fig, Path::new("c.png")).unwrap(), "many restarts");
}

/// A plant whose performance output carries nothing (C1, D11, D12 = 0): ‖T_zw‖∞ = 0 has no place
/// on the σ-plot's log axis. The figure used to take it as the axis's lower end, and the tick
/// walk from log10(0) ran over 2³¹ decades (memory until the process died); now the peak is not
/// marked, the axis spans the controller's curve, and the figure renders.
#[test]
fn a_closed_loop_with_zero_norm_draws_its_sigma_plot() {
    use hinfix::campaign::plot::SigmaFigure;
    use hinfix::lti::{Controller, Plant};
    let plant = Plant::from_json_str(
        r#"{"name":"zeroz","dims":{"n":2,"m1":1,"m2":1,"p1":1,"p2":1},"A":[[0.5,1],[0,-1]],"B1":[[1],[0]],"B2":[[0],[1]],"C1":[[0,0]],"C2":[[1,1]],"D11":[[0]],"D12":[[0]],"D21":[[1]],"D22":[[0]]}"#,
        "zeroz.json",
    )
    .unwrap();
    let mut k = Controller::zeros(0, 1, 1);
    k.dk[(0, 0)] = -3.0; // u = -3 y: A + B2·DK·C2 = [[0.5, 1], [-3, -4]], stable
    let fig = SigmaFigure::new(&plant, &k, "zero".into()).unwrap();
    assert_eq!(fig.peak.0, 0.0);
    assert_eq!(fig.peak_point(), None);
    check_svg(&svg_text(&fig, Path::new("sigma_zero.svg")).unwrap(), "zero-norm σ-plot");
    check_png(&png_bytes(&fig, Path::new("sigma_zero.png")).unwrap(), "zero-norm σ-plot");
    for (lo, hi) in [(0.0, 1.0), (-1.0, 1.0), (1.0, f64::INFINITY), (f64::NAN, 1.0), (2.0, 1.0)] {
        assert!(log_ticks(lo, hi).is_empty(), "log_ticks({lo}, {hi})");
    }
}

/// A convergence figure is drawn only from the trace of the run that journaled the row's record:
/// another job's trace under the best job's file name (or a trace left from an earlier run of the
/// job) is skipped with the reason, and the figure an earlier plot made for the row is removed
/// (index.html would link it under this row's ε and seed).
#[test]
fn a_trace_of_another_run_is_not_drawn_as_the_rows_convergence() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("c.toml");
    std::fs::write(&file, "name = \"p\"\n[defaults]\neps = [1e-3]\nseeds = 1\ncpumax = 1.0\nnrand = 1\nspend_budget = false\n[[problem]]\nplant = \"HE1\"\norders = [1, 2]\n").unwrap();
    let results = dir.path().join("r");
    let run = |args: &[&str]| {
        let out = campaign(args, &file, &results);
        format!("{}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr))
    };
    run(&["run", "--no-progress"]);
    run(&["plot"]);
    let plots = results.join("p/plots");
    assert!(plots.join("convergence_HE1_nK2.svg").is_file());
    let best = std::fs::read_to_string(results.join("p/best.csv")).unwrap();
    let ids: Vec<String> = best.lines().skip(1).map(|l| l.split(',').nth(4).unwrap().to_string()).collect();
    assert_eq!(ids.len(), 2, "{best}");
    let traces = results.join("p/traces");
    std::fs::copy(traces.join(format!("{}.mcap", ids[0])), traces.join(format!("{}.mcap", ids[1]))).unwrap();
    let said = run(&["plot"]);
    assert!(said.contains(&format!("is the trace of job {}, not of this job", ids[0])), "{said}");
    assert!(!plots.join("convergence_HE1_nK2.svg").exists() && !plots.join("convergence_HE1_nK2.png").exists());
    assert!(plots.join("convergence_HE1_nK1.svg").is_file() && plots.join("sigma_HE1_nK2.svg").is_file());
}
