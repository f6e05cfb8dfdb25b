//! The continuous/discrete choice of every numerical computation is made inside `lti`
//! (`lti/norms/domain.rs`, docs/ARCHITECTURE.md §1): outside `src/lti`, `TimeDomain::` is named
//! only where a domain is read from input or a number is formatted for output. This test counts
//! the uses of `TimeDomain::` in every source file outside `src/lti` (the crate's `src/` and the
//! Python package's `python/src/`; comments and the `#[cfg(test)] mod tests` of a file are not
//! counted) and compares them with [`ALLOWED`]: a new numerical match on the domain fails here —
//! write it as a function of `lti` instead.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The files outside `src/lti` that may name `TimeDomain::`, how many times, and why (input or
/// formatting only).
const ALLOWED: &[(&str, usize, &str)] = &[
    (
        "src/campaign/reduction/latex.rs",
        1,
        "formatting: a table cell shows ρ = s + 1 of a discrete-time plant's measure",
    ),
    ("src/cli/check.rs", 2, "formatting: the JSON keys of `check` (abscissas, or Ts and spectral radii)"),
    ("src/cli/plants.rs", 2, "formatting: the name of the plant's stability quantity in `plants`"),
    ("python/src/norms.rs", 1, "input: the domain of `hinfnorm` from its `dt` argument"),
    ("python/src/plant.rs", 1, "input: the domain of a plant from its `dt` argument"),
];

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else { return };
    for e in entries.flatten() {
        let p = e.path();
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

/// Uses of `TimeDomain::` in `text`, outside comments and the file's test module.
fn uses(text: &str) -> usize {
    let code = match text.find("#[cfg(test)]\nmod tests") {
        Some(i) => &text[..i],
        None => text,
    };
    code.lines().map(|l| l.split("//").next().unwrap_or("").matches("TimeDomain::").count()).sum()
}

#[test]
fn time_domain_is_matched_only_inside_lti_for_numerics() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files = Vec::new();
    rust_files(&root.join("src"), &mut files);
    rust_files(&root.join("python/src"), &mut files);
    let mut found = BTreeMap::new();
    for f in &files {
        let rel = f.strip_prefix(root).expect("under the crate").to_string_lossy().replace('\\', "/");
        if rel.starts_with("src/lti/") {
            continue;
        }
        let n = uses(&std::fs::read_to_string(f).expect("readable source"));
        if n > 0 {
            found.insert(rel, n);
        }
    }
    let allowed: BTreeMap<String, usize> = ALLOWED.iter().map(|(f, n, _)| (f.to_string(), *n)).collect();
    assert_eq!(
        found, allowed,
        "uses of `TimeDomain::` outside src/lti (left) against the allow-list of input and formatting places \
         (right): put a numerical choice by time domain into lti (lti/norms/domain.rs)"
    );
}

#[test]
fn the_count_skips_comments_and_tests() {
    let text = "let d = TimeDomain::Continuous; // TimeDomain::Discrete\n// TimeDomain::x\n#[cfg(test)]\nmod tests {\n    TimeDomain::Continuous\n}\n";
    assert_eq!(uses(text), 1);
}
