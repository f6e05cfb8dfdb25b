//! The architecture's import rules (docs/ARCHITECTURE.md §1), checked on the source text: the
//! modules of each layer folder form no import cycle, and the layers import only downwards.
//!
//! An edge a → b is any `super::b` or `crate::<layer>::b` path in file a outside its
//! `#[cfg(test)]` part (comments and doc comments ignored); a folder's `mod.rs` only re-exports
//! and is left out. A cycle is a strongly connected component of more than one module.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Module name (relative to the layer folder, `::`-separated) → source text without tests and
/// comments.
fn modules(layer: &str) -> BTreeMap<String, String> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("src").join(layer);
    let mut out = BTreeMap::new();
    let mut stack = vec![root.clone()];
    while let Some(dir) = stack.pop() {
        for e in std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
            let path: PathBuf = e.unwrap().path();
            if path.is_dir() {
                stack.push(path);
                continue;
            }
            if path.extension().is_none_or(|x| x != "rs") {
                continue;
            }
            let rel = path.strip_prefix(&root).unwrap().with_extension("");
            let mut parts: Vec<String> = rel.iter().map(|p| p.to_string_lossy().into_owned()).collect();
            if parts.last().is_some_and(|p| p == "mod") {
                parts.pop();
            }
            if parts.is_empty() {
                continue; // the layer's mod.rs: re-exports only
            }
            let text = std::fs::read_to_string(&path).unwrap();
            let code = text.split("#[cfg(test)]").next().unwrap_or("");
            let code: String = code.lines().map(|l| l.split("//").next().unwrap_or("")).collect::<Vec<_>>().join("\n");
            out.insert(parts.join("::"), code);
        }
    }
    out
}

/// Identifiers following each occurrence of `prefix` (`super::` → `report`, …).
fn paths_after<'a>(code: &'a str, prefix: &str) -> Vec<&'a str> {
    code.match_indices(prefix)
        .filter(|(i, _)| *i == 0 || !code.as_bytes()[i - 1].is_ascii_alphanumeric() && code.as_bytes()[i - 1] != b'_')
        .map(|(i, _)| {
            let rest = &code[i + prefix.len()..];
            let end = rest.find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':')).unwrap_or(rest.len());
            rest[..end].trim_end_matches(':')
        })
        .collect()
}

/// The import graph of one layer folder.
fn graph(layer: &str) -> BTreeMap<String, BTreeSet<String>> {
    let mods = modules(layer);
    let resolve = |cand: &str| -> Option<String> {
        // the longest module path that `cand` starts with (`plot::render::Figure` → `plot::render`)
        let parts: Vec<&str> = cand.split("::").collect();
        (1..=parts.len()).rev().map(|k| parts[..k].join("::")).find(|m| mods.contains_key(m))
    };
    let mut g = BTreeMap::new();
    for (m, code) in &mods {
        let parent: Vec<&str> = m.split("::").collect();
        let parent = parent[..parent.len() - 1].join("::");
        let mut edges = BTreeSet::new();
        for p in paths_after(code, "super::") {
            let full = if parent.is_empty() { p.to_string() } else { format!("{parent}::{p}") };
            if let Some(t) = resolve(&full).or_else(|| resolve(p)) {
                edges.insert(t);
            }
        }
        for p in paths_after(code, &format!("crate::{layer}::")) {
            if let Some(t) = resolve(p) {
                edges.insert(t);
            }
        }
        edges.remove(m);
        // a submodule naming its own parent folder (`super::PlotError` in plot/render.rs) is not
        // an edge between siblings
        edges.retain(|t| !m.starts_with(&format!("{t}::")));
        g.insert(m.clone(), edges);
    }
    g
}

/// Strongly connected components with more than one module (Tarjan).
fn cycles(g: &BTreeMap<String, BTreeSet<String>>) -> Vec<Vec<String>> {
    struct T<'a> {
        g: &'a BTreeMap<String, BTreeSet<String>>,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        on: BTreeSet<&'a str>,
        out: Vec<Vec<String>>,
    }
    impl<'a> T<'a> {
        fn visit(&mut self, v: &'a str) {
            let i = self.index.len();
            self.index.insert(v, i);
            self.low.insert(v, i);
            self.stack.push(v);
            self.on.insert(v);
            for w in &self.g[v] {
                let w = w.as_str();
                if !self.index.contains_key(w) {
                    self.visit(w);
                    let l = self.low[v].min(self.low[w]);
                    self.low.insert(v, l);
                } else if self.on.contains(w) {
                    let l = self.low[v].min(self.index[w]);
                    self.low.insert(v, l);
                }
            }
            if self.low[v] == self.index[v] {
                let mut comp = Vec::new();
                while let Some(w) = self.stack.pop() {
                    self.on.remove(w);
                    comp.push(w.to_string());
                    if w == v {
                        break;
                    }
                }
                if comp.len() > 1 {
                    comp.sort();
                    self.out.push(comp);
                }
            }
        }
    }
    let mut t =
        T { g, index: BTreeMap::new(), low: BTreeMap::new(), stack: Vec::new(), on: BTreeSet::new(), out: Vec::new() };
    for v in g.keys() {
        if !t.index.contains_key(v.as_str()) {
            t.visit(v);
        }
    }
    t.out
}

#[test]
fn no_import_cycles_inside_a_layer() {
    for layer in ["campaign", "design", "lti", "optim"] {
        let g = graph(layer);
        assert!(g.len() > 3, "{layer}: found only {} modules; is the source tree where it should be?", g.len());
        assert_eq!(cycles(&g), Vec::<Vec<String>>::new(), "import cycles in src/{layer}: {g:#?}");
    }
}

#[test]
fn the_cycle_finder_finds_cycles() {
    let g: BTreeMap<String, BTreeSet<String>> = [("a", &["b"][..]), ("b", &["c"]), ("c", &["a"]), ("d", &["a"])]
        .into_iter()
        .map(|(k, v)| (k.to_string(), v.iter().map(|s| s.to_string()).collect()))
        .collect();
    assert_eq!(cycles(&g), vec![vec!["a".to_string(), "b".into(), "c".into()]]);
    assert_eq!(paths_after("use super::jobs::{Job};\nx = my_super::y", "super::"), vec!["jobs"]);
}

#[test]
fn layers_import_only_downwards() {
    // docs/ARCHITECTURE.md §1: optim and lti are independent; design uses both; campaign uses
    // design (and through it lti/optim); nothing below imports what is above it.
    let forbidden: &[(&str, &[&str])] = &[
        ("optim", &["lti", "design", "campaign"]),
        ("lti", &["optim", "design", "campaign"]),
        ("design", &["campaign"]),
    ];
    for (layer, above) in forbidden {
        for (m, code) in modules(layer) {
            for a in *above {
                let hits = paths_after(&code, &format!("crate::{a}"));
                assert!(hits.is_empty(), "src/{layer}/{m} imports crate::{a}, a layer it must not depend on");
            }
        }
    }
}

/// Rank of the part holding `module` among `parts` (bottom up) of `layer`: that of its folder
/// (`kernels::spectral` → `kernels`); the modules `shared` by all parts rank lowest.
fn part_rank(layer: &str, parts: &[&str], shared: &[&str], module: &str) -> usize {
    let part = module.split("::").next().unwrap();
    if shared.contains(&part) {
        return 0;
    }
    parts
        .iter()
        .position(|p| *p == part)
        .unwrap_or_else(|| panic!("src/{layer}/{module}: in no part of {layer}; add its folder to the parts"))
}

/// Every module of `layer` imports only its own part and those below it (`parts`, bottom up;
/// `shared` modules below all), but for the edges `exceptions` (each still in use); every part
/// is found.
fn assert_parts_import_only_downwards(layer: &str, parts: &[&str], shared: &[&str], exceptions: &[(&str, &str)]) {
    let g = graph(layer);
    for part in parts.iter().filter(|p| !shared.contains(p)) {
        assert!(g.keys().any(|m| m.split("::").next() == Some(part)), "src/{layer}/{part}: not found");
    }
    for (m, t) in exceptions {
        let used = g.get(*m).is_some_and(|edges| edges.contains(*t));
        assert!(used, "src/{layer}/{m} no longer imports {layer}::{t}: remove the exception");
    }
    let rank = |m: &str| part_rank(layer, parts, shared, m);
    for (m, edges) in &g {
        for t in edges {
            if exceptions.contains(&(m.as_str(), t.as_str())) {
                continue;
            }
            assert!(
                rank(t) <= rank(m) || m.split("::").next() == t.split("::").next(),
                "src/{layer}/{m} imports {layer}::{t}, a part above its own (order: {parts:?})"
            );
        }
    }
}

/// The parts of `lti`, bottom up (docs/ARCHITECTURE.md §1): a module may import its own part
/// and the parts below it, never one above. `error` and `interrupt` are shared by all parts and
/// import none; `kernel_bench` (bench scaffolding behind the `test-support` feature) sits on top.
const LTI_PARTS: &[&str] = &["error", "interrupt", "io", "system", "kernels", "norms", "synthesis", "kernel_bench"];

/// The modules of `lti` shared by all its parts.
const LTI_SHARED: &[&str] = &["error", "interrupt"];

fn lti_rank(module: &str) -> usize {
    part_rank("lti", LTI_PARTS, LTI_SHARED, module)
}

#[test]
fn lti_parts_import_only_downwards() {
    // The one exception: the H∞ norm's recording hook for `benches/lti.rs --record`
    // (`norms/hinf_hooks.rs`), compiled only with the `test-support` feature.
    assert_parts_import_only_downwards("lti", LTI_PARTS, LTI_SHARED, &[("norms::hinf_hooks", "kernel_bench")]);
}

#[test]
fn the_lti_part_order_is_checked() {
    assert!(lti_rank("kernels::spectral") > lti_rank("system::state_space"));
    assert!(lti_rank("io::mat_file") < lti_rank("system::plant"));
    assert!(lti_rank("norms::hinf") < lti_rank("synthesis::full_order::gamma_test"));
    assert_eq!(lti_rank("error"), lti_rank("interrupt"));
}

/// The parts of `campaign`, bottom up (docs/ARCHITECTURE.md §1), one folder each: a module may
/// import its own part and the parts below it, never one above.
const CAMPAIGN_PARTS: &[&str] = &["leaves", "model", "records", "execution", "reduction"];

fn campaign_rank(module: &str) -> usize {
    part_rank("campaign", CAMPAIGN_PARTS, &[], module)
}

#[test]
fn campaign_parts_import_only_downwards() {
    assert_parts_import_only_downwards("campaign", CAMPAIGN_PARTS, &[], &[]);
}

#[test]
fn the_campaign_part_order_is_checked() {
    assert!(campaign_rank("records::journal") > campaign_rank("model::jobs"));
    assert!(campaign_rank("reduction::report") > campaign_rank("execution::scheduler"));
    assert!(campaign_rank("reduction::plot::render") > campaign_rank("execution::trace"));
    assert!(campaign_rank("reduction::export::best_csv") > campaign_rank("execution::chain"));
    assert_eq!(campaign_rank("model::spec"), campaign_rank("model::campaign"));
}
