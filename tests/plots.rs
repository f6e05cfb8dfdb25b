//! `campaign plot`: every figure kind (γ vs order, convergence, σ-plot) rendered from a tiny real
//! campaign as PNG and SVG; the files are checked (PNG signature and IHDR size, SVG parses as XML
//! with an `<svg>` root and text), and the figures' data on synthetic input (log axis when values
//! span decades, phase boundaries and restarts found where they are).

use std::path::{Path, PathBuf};
use std::process::Command;

use hinfix::campaign::plot::{png_bytes, svg_text, SIZE};
use hinfix::campaign::plot::{ConvergenceFigure, GammaOrderFigure};
use hinfix::campaign::TraceIteration;

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

#[test]
fn every_figure_kind_is_rendered_for_a_small_real_campaign() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("c.toml");
    std::fs::write(&file, "name = \"p\"\n[defaults]\neps = [1e-3]\nseeds = 1\ncpumax = 2.0\nnrand = 1\nspend_budget = false\n[[problem]]\nplant = \"REA2\"\norders = [1, 2]\n").unwrap();
    let results = dir.path().join("r");
    let run = |args: &[&str]| {
        let out = Command::new(BIN)
            .args(args)
            .arg(&file)
            .arg("--results")
            .arg(&results)
            .env("HINFIX_PLANTS", concat!(env!("CARGO_MANIFEST_DIR"), "/plants"))
            .output()
            .unwrap();
        assert!(out.status.success(), "campaign {args:?}: {}", String::from_utf8_lossy(&out.stderr));
        out
    };
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
    check_svg(&svg_text(&fig, p).unwrap(), "convergence");

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
        paper: vec![(1, 0.00035), (2, 0.00035)],
        full_order: Some((1e-6, false)),
    };
    assert!(pa.log_axis());
    let he1 = GammaOrderFigure {
        plant: "HE1".into(),
        ours: vec![(1, 0.124), (2, 0.11)],
        paper: vec![(1, 0.1235)],
        full_order: Some((0.0737, false)),
    };
    assert!(!he1.log_axis());
    let p = Path::new("g.png");
    for fig in [&pa, &he1] {
        check_png(&png_bytes(fig, p).unwrap(), &fig.plant);
        check_svg(&svg_text(fig, p).unwrap(), &fig.plant);
    }
}
