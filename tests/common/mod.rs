//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::Path;
use std::process::Command;

/// The LaTeX tables of `dir` (`tables.tex`, `compare.tex`, and `library.tex` where there is one)
/// are always checked structurally ([`latex_structure`]); where `pdflatex` is installed they are
/// also compiled for real, in one document. Without `pdflatex` the structural check is all,
/// unless CI asks for the real compile: with `CI` set (as `.ci/run` sets it) a missing `pdflatex`
/// fails the test, except where `HINFIX_NO_PDFLATEX=1` says that none could be installed.
pub fn latex_compiles(dir: &Path) {
    let mut files = vec!["tables.tex", "compare.tex"];
    if dir.join("library.tex").is_file() {
        files.push("library.tex");
    }
    for f in &files {
        let tex = std::fs::read_to_string(dir.join(f)).unwrap();
        if let Err(e) = latex_structure(&tex) {
            panic!("{f}: {e}\n{tex}");
        }
    }
    let have = Command::new("pdflatex").arg("--version").output().is_ok_and(|o| o.status.success());
    if !have {
        let opted_out = std::env::var("HINFIX_NO_PDFLATEX").as_deref() == Ok("1");
        let ci = std::env::var("CI").is_ok_and(|v| !v.is_empty() && v != "0" && v != "false");
        assert!(
            opted_out || !ci,
            "CI is set but pdflatex is not on PATH: install it (texlive-latex-base, texlive-latex-recommended) or set HINFIX_NO_PDFLATEX=1"
        );
        eprintln!("note: pdflatex not found; the LaTeX tables were checked structurally only");
        return;
    }
    let inputs: String = files.iter().map(|f| format!("\\input{{{f}}}\n")).collect();
    std::fs::write(
        dir.join("wrap.tex"),
        format!(
            "\\documentclass{{article}}\n\\usepackage{{booktabs}}\n\\usepackage{{longtable}}\n\\begin{{document}}\n{inputs}\\end{{document}}\n"
        ),
    )
    .unwrap();
    let out = Command::new("pdflatex")
        .args(["-interaction=nonstopmode", "-halt-on-error", "wrap.tex"])
        .current_dir(dir)
        .output()
        .unwrap();
    assert!(out.status.success(), "pdflatex failed:\n{}", String::from_utf8_lossy(&out.stdout));
    assert!(dir.join("wrap.pdf").is_file());
}

/// What makes a table fragment fail to compile, checked without LaTeX: environments nest and
/// close (`\begin{x}` … `\end{x}`); braces balance; `#` never appears and `_`, `^` only in math
/// (both unescaped); `$` math closes on its line; every `tabular` and `longtable` has booktabs
/// rules, and each of its rows has as many cells (`\multicolumn{k}` counting k) as its column
/// specification has columns (a `longtable`'s `\caption` rows and its head and foot markers
/// `\endfirsthead`, `\endhead`, `\endfoot`, `\endlastfoot` aside). `%` starts a comment, as in
/// LaTeX.
pub fn latex_structure(tex: &str) -> Result<(), String> {
    let mut envs: Vec<(String, usize, Vec<String>)> = Vec::new(); // (name, columns, rows)
    let mut depth = 0i64;
    for (no, raw) in tex.lines().enumerate() {
        let at = |what: String| format!("line {}: {what}", no + 1);
        let line = strip_comment(raw);
        // Characters: braces, math, specials.
        let mut math = false;
        let mut chars = line.chars().peekable();
        while let Some(c) = chars.next() {
            match c {
                '\\' => {
                    chars.next(); // an escaped character or the first letter of a command
                }
                '{' => depth += 1,
                '}' => {
                    depth -= 1;
                    if depth < 0 {
                        return Err(at("unmatched }".into()));
                    }
                }
                '$' => math = !math,
                '#' => return Err(at("unescaped #".into())),
                '_' | '^' if !math => return Err(at(format!("unescaped {c} outside math"))),
                _ => {}
            }
        }
        if math {
            return Err(at("$ math not closed on its line".into()));
        }
        // Environments and table rows.
        let mut rest = line;
        while !rest.is_empty() {
            if let Some(r) = rest.strip_prefix("\\begin{") {
                let (name, r) = r.split_once('}').ok_or_else(|| at("\\begin without }".into()))?;
                let (cols, r) = if is_table(name) { column_spec(r).map_err(&at)? } else { (0, r) };
                envs.push((name.to_string(), cols, Vec::new()));
                rest = r;
            } else if let Some(r) = rest.strip_prefix("\\end{") {
                let (name, r) = r.split_once('}').ok_or_else(|| at("\\end without }".into()))?;
                let (open, cols, rows) = envs.pop().ok_or_else(|| at(format!("\\end{{{name}}} without \\begin")))?;
                if open != name {
                    return Err(at(format!("\\end{{{name}}} closes \\begin{{{open}}}")));
                }
                if is_table(name) {
                    check_tabular(cols, &rows, name == "longtable").map_err(&at)?;
                }
                rest = r;
            } else {
                let skip = rest.chars().next().map_or(1, char::len_utf8);
                let tail = &rest[skip..];
                let next =
                    tail.find("\\begin{").into_iter().chain(tail.find("\\end{")).min().map_or(rest.len(), |i| i + skip);
                if let Some((name, _, rows)) = envs.last_mut() {
                    if is_table(name) {
                        rows.push(rest[..next].to_string());
                    }
                }
                rest = &rest[next..];
            }
        }
    }
    if let Some((name, ..)) = envs.last() {
        return Err(format!("\\begin{{{name}}} never closed"));
    }
    if depth != 0 {
        return Err(format!("{depth} unclosed {{"));
    }
    Ok(())
}

/// Whether environment `name` is a table whose rows [`check_tabular`] checks.
fn is_table(name: &str) -> bool {
    name == "tabular" || name == "longtable"
}

fn strip_comment(line: &str) -> &str {
    let b = line.as_bytes();
    (0..b.len()).find(|&i| b[i] == b'%' && (i == 0 || b[i - 1] != b'\\')).map_or(line, |i| &line[..i])
}

/// The number of columns of a `{spec}` at the start of `s` (l, c, r, S, X; p/m/b{width};
/// `|` and @/!/>/<{…} take none), and the text after it. A `*{n}{…}` repeat is not supported.
fn column_spec(s: &str) -> Result<(usize, &str), String> {
    let s = s.strip_prefix('{').ok_or("tabular without a column specification")?;
    let (mut cols, mut level, mut end) = (0, 0, None);
    let b = s.as_bytes();
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'{' => level += 1,
            b'}' if level == 0 => {
                end = Some(i);
                break;
            }
            b'}' => level -= 1,
            b'*' => return Err("tabular column repeat *{n}{…} is not checked: write the columns out".into()),
            b'l' | b'c' | b'r' | b'S' | b'X' | b'p' | b'm' | b'b' if level == 0 => cols += 1,
            _ => {}
        }
        i += 1;
    }
    let end = end.ok_or("unterminated column specification")?;
    Ok((cols, &s[end + 1..]))
}

/// Every row of a tabular (text up to each `\\`) has `cols` cells; booktabs rules are present.
/// In a `longtable`, a row that is a `\caption` is no row of cells, and the head and foot
/// markers are not cells.
fn check_tabular(cols: usize, rows: &[String], longtable: bool) -> Result<(), String> {
    let body = rows.join("\n");
    if !(body.contains("\\toprule") && body.contains("\\bottomrule")) {
        return Err("tabular without booktabs \\toprule/\\bottomrule".into());
    }
    let mut skip = vec!["\\toprule", "\\midrule", "\\bottomrule"];
    if longtable {
        skip.extend(["\\endfirsthead", "\\endlastfoot", "\\endhead", "\\endfoot"]);
    }
    for row in body.split("\\\\").map(str::trim) {
        let row = skip.iter().fold(row.to_string(), |r, rule| r.replace(rule, ""));
        if row.trim().is_empty() || longtable && row.trim().starts_with("\\caption") {
            continue;
        }
        let b = row.as_bytes();
        let amps = (0..b.len()).filter(|&i| b[i] == b'&' && (i == 0 || b[i - 1] != b'\\')).count();
        let spans: usize = row
            .split("\\multicolumn{")
            .skip(1)
            .map(|m| {
                m.split('}').next().and_then(|k| k.trim().parse::<usize>().ok()).map_or(0, |k| k.saturating_sub(1))
            })
            .sum();
        if amps + 1 + spans != cols {
            return Err(format!("row `{}` has {} cells, the tabular has {cols} columns", row.trim(), amps + 1 + spans));
        }
    }
    Ok(())
}

/// σmax(C (iωI − A)⁻¹ B + D) by a dense complex LU (independent of the library's Hessenberg
/// path); σmax(D) at ω = ∞ or for a static system.
pub fn sigma_direct(sys: &hinfix::lti::StateSpace, w: f64) -> f64 {
    if !w.is_finite() || sys.order() == 0 {
        return sys.d.singular_values().unwrap().into_iter().fold(0.0, f64::max);
    }
    sigma_at(sys, faer::c64::new(0.0, w))
}

/// σmax(D + C(sI − A)⁻¹B) at a complex point s (e^{iθ} for a discrete-time system), by a dense
/// complex solve.
#[allow(dead_code)]
pub fn sigma_at(sys: &hinfix::lti::StateSpace, s: faer::c64) -> f64 {
    use faer::c64;
    use faer::linalg::solvers::Solve;
    use faer::Mat;
    let n = sys.order();
    let z =
        Mat::<c64>::from_fn(n, n, |i, j| c64::new(-sys.a[(i, j)], 0.0) + if i == j { s } else { c64::new(0.0, 0.0) });
    let b = Mat::<c64>::from_fn(n, sys.inputs(), |i, j| c64::new(sys.b[(i, j)], 0.0));
    let x = z.partial_piv_lu().solve(&b);
    let g = Mat::<c64>::from_fn(sys.outputs(), sys.inputs(), |i, j| {
        (0..n).fold(c64::new(sys.d[(i, j)], 0.0), |s, k| s + x[(k, j)] * sys.c[(i, k)])
    });
    g.singular_values().unwrap().into_iter().fold(0.0, f64::max)
}

/// The test-only `campaign` binary with the fake runner (examples/fake_campaign.rs), which
/// `cargo test` builds next to the test executables (target/<profile>/examples/). A test run
/// with a target filter (`cargo test --test NAME`) does not build examples, so the binary may be
/// missing, or older than the library it should contain: both fail here with what to run,
/// instead of testing stale code.
pub fn fake_campaign_bin() -> std::path::PathBuf {
    let exe = std::env::current_exe().unwrap();
    let deps = exe.parent().unwrap(); // target/<profile>/deps
    let name = format!("fake_campaign{}", std::env::consts::EXE_SUFFIX);
    let bin = deps.parent().unwrap().join("examples").join(name);
    let build = "build it with `cargo build --release --example fake_campaign` (a plain `cargo test --release` does)";
    let built = match std::fs::metadata(&bin).and_then(|m| m.modified()) {
        Ok(t) => t,
        Err(_) => panic!("{} is missing: {build}", bin.display()),
    };
    // The library it must contain: the newest hinfix rlib of this profile.
    let newest_lib = std::fs::read_dir(deps)
        .unwrap()
        .flatten()
        .filter(|e| {
            let n = e.file_name().to_string_lossy().into_owned();
            n.starts_with("libhinfix-") && n.ends_with(".rlib")
        })
        .filter_map(|e| e.metadata().and_then(|m| m.modified()).ok())
        .max();
    if let Some(lib) = newest_lib {
        assert!(built >= lib, "{} is older than the hinfix library: {build}", bin.display());
    }
    bin
}

/// Adds the contribution of one complex modal pair to a transfer matrix g at the point s
/// (s = iω or z = e^{iθ}): C₂(sI − [σ ω₀; −ω₀ σ])⁻¹B₂ with C₂ = columns i, i + 1 of `c_modal`
/// and B₂ = rows i, i + 1 of `b_modal`. With w = s − σ, the inverse of [w, −ω₀; ω₀, w] is
/// [w, ω₀; −ω₀, w]/(w² + ω₀²).
pub fn add_modal_pair(
    g: &mut faer::Mat<faer::c64>,
    s: faer::c64,
    (re, im): (f64, f64),
    c_modal: &faer::Mat<f64>,
    b_modal: &faer::Mat<f64>,
    i: usize,
) {
    use faer::c64;
    let z = s - re;
    let det = z * z + im * im;
    let (m00, m01, m10, m11) = (z / det, c64::new(im, 0.0) / det, c64::new(-im, 0.0) / det, z / det);
    for a in 0..g.nrows() {
        let (c0, c1) = (c_modal[(a, i)], c_modal[(a, i + 1)]);
        for b in 0..g.ncols() {
            let (b0, b1) = (b_modal[(i, b)], b_modal[(i + 1, b)]);
            g[(a, b)] += (m00 * b0 + m01 * b1) * c0 + (m10 * b0 + m11 * b1) * c1;
        }
    }
}

/// A matrix of a JSON fixture: an array of `rows` rows of `cols` numbers.
pub fn json_matrix(v: &serde_json::Value, rows: usize, cols: usize) -> faer::Mat<f64> {
    faer::Mat::from_fn(rows, cols, |i, j| v[i][j].as_f64().unwrap())
}

/// The system (A, B, C, D) of a fixture case with those four JSON matrices (shapes from A and D).
pub fn json_system(case: &serde_json::Value) -> hinfix::lti::StateSpace {
    let len = |v: &serde_json::Value| v.as_array().unwrap().len();
    let (n, p, m) = (len(&case["A"]), len(&case["D"]), len(&case["D"][0]));
    let mat = |k: &str, r, c| json_matrix(&case[k], r, c);
    hinfix::lti::StateSpace::new(mat("A", n, n), mat("B", n, m), mat("C", p, n), mat("D", p, m)).unwrap()
}

/// The largest error of central differences (step 1e-6) of `obj` at `x0` against its gradient
/// there, each relative to max(1, ‖∇f‖∞); asserts first that f(x0) and its gradient are finite
/// (`label` names the case in that message).
pub fn worst_fd_error(obj: &mut impl hinfix::optim::Objective, x0: &[f64], label: &str) -> f64 {
    let mut g = vec![0.0; x0.len()];
    let f0 = obj.eval(x0, &mut g);
    assert!(f0.is_finite() && g.iter().all(|v| v.is_finite()), "{label}: f = {f0}");
    let scale = g.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    let h = 1e-6;
    let mut scratch = vec![0.0; x0.len()];
    let mut worst = 0.0f64;
    for i in 0..x0.len() {
        let (mut xp, mut xm) = (x0.to_vec(), x0.to_vec());
        xp[i] += h;
        xm[i] -= h;
        let fd = (obj.eval(&xp, &mut scratch) - obj.eval(&xm, &mut scratch)) / (2.0 * h);
        worst = worst.max((fd - g[i]).abs() / scale);
    }
    worst
}

/// HE1 with D21 = [0.5, 1] (HE1's is 0) and D11 = D12·X·D21 (X = [0.3; −0.2]): a continuous H2
/// objective then fixes Dk = −X (D12 is invertible and D21 has rank 1 = p2, so the set of
/// feedthroughs is one point).
pub fn he1_with_feedthrough() -> hinfix::lti::Plant {
    let mut p = hinfix::lti::Plant::load(hinfix::lti::resolve_plant("HE1").unwrap()).unwrap();
    p.d21 = faer::mat![[0.5, 1.0]];
    let x = faer::mat![[0.3], [-0.2]];
    p.d11 = &p.d12 * &x * &p.d21;
    p.name = "HE1-D11".into();
    p
}

/// An empty scratch folder `hinfix-<test>-<tag>-<pid>` in the system's temporary folder (what
/// was there removed first).
pub fn scratch(test: &str, tag: &str) -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("hinfix-{test}-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A continuous-time plant named `name` of the matrices A, B1, B2, C1, C2, D11, D12, D21, D22
/// (the dimensions read off them), with no description, citation or check.
pub fn plant_of(name: &str, [a, b1, b2, c1, c2, d11, d12, d21, d22]: [faer::Mat<f64>; 9]) -> hinfix::lti::Plant {
    let (n, m1, m2, p1, p2) = (a.nrows(), b1.ncols(), b2.ncols(), c1.nrows(), c2.nrows());
    hinfix::lti::Plant {
        name: name.into(),
        description: String::new(),
        citation: String::new(),
        source: serde_json::Value::Null,
        notes: String::new(),
        check: None,
        dims: hinfix::lti::Dims { n, m1, m2, p1, p2 },
        domain: Default::default(),
        a,
        b1,
        b2,
        c1,
        c2,
        d11,
        d12,
        d21,
        d22,
    }
}

/// Writes the campaign file `dir/c.toml` with `text`; returns its path.
pub fn campaign_file(dir: &Path, text: &str) -> std::path::PathBuf {
    let file = dir.join("c.toml");
    std::fs::write(&file, text).unwrap();
    file
}
