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

/// The parts of `lti`, bottom up (docs/ARCHITECTURE.md §1): a module may import its own part
/// and the parts below it, never one above. `error` and `interrupt` are shared by all parts and
/// import none; `kernel_bench` (bench scaffolding behind the `test-support` feature) sits on top.
const LTI_PARTS: &[&str] = &["error", "interrupt", "io", "system", "kernels", "norms", "synthesis", "kernel_bench"];

/// Rank of the part holding an lti module (`kernels::spectral` → that of `kernels`).
fn lti_rank(module: &str) -> usize {
    let part = module.split("::").next().unwrap();
    match part {
        "error" | "interrupt" => 0,
        _ => LTI_PARTS
            .iter()
            .position(|p| *p == part)
            .unwrap_or_else(|| panic!("src/lti/{module}: in no part of lti; add its folder to LTI_PARTS")),
    }
}

#[test]
fn lti_parts_import_only_downwards() {
    let g = graph("lti");
    for part in &LTI_PARTS[2..] {
        assert!(g.keys().any(|m| m.split("::").next() == Some(part)), "src/lti/{part}: not found");
    }
    for (m, edges) in &g {
        for t in edges {
            // The one exception: the H∞ norm's recording hook for `benches/lti.rs --record`
            // (`norms/hinf_hooks.rs`), compiled only with the `test-support` feature.
            if m == "norms::hinf_hooks" && t == "kernel_bench" {
                continue;
            }
            assert!(
                lti_rank(t) <= lti_rank(m) || m.split("::").next() == t.split("::").next(),
                "src/lti/{m} imports lti::{t}, a part above its own (order: {LTI_PARTS:?})"
            );
        }
    }
}

#[test]
fn the_lti_part_order_is_checked() {
    assert!(lti_rank("kernels::spectral") > lti_rank("system::state_space"));
    assert!(lti_rank("io::mat_file") < lti_rank("system::plant"));
    assert!(lti_rank("norms::hinf") < lti_rank("synthesis::full_order::gamma_test"));
    assert_eq!(lti_rank("error"), lti_rank("interrupt"));
}

/// The parts of `campaign`, bottom up (docs/ARCHITECTURE.md §1), each a list of its modules (the
/// files stay side by side in src/campaign/): a module may import its own part and the parts
/// below it, never one above.
const CAMPAIGN_PARTS: &[(&str, &[&str])] = &[
    ("leaves", &["provenance", "reference", "sanitise", "trace_filter"]),
    ("model", &["model", "spec", "jobs"]),
    ("records", &["record", "journal", "claims", "shard"]),
    ("execution", &["scheduler", "trace", "progress", "run", "fake"]),
    ("reduction", &["reduce", "compare", "latex", "report", "plot", "status", "lookup", "methods", "html", "chain"]),
];

/// Rank of the part holding a campaign module (`plot::render` → that of `plot`).
fn campaign_rank(module: &str) -> usize {
    let top = module.split("::").next().unwrap();
    CAMPAIGN_PARTS
        .iter()
        .position(|(_, mods)| mods.contains(&top))
        .unwrap_or_else(|| panic!("src/campaign/{module}: in no part of campaign; add it to CAMPAIGN_PARTS"))
}

#[test]
fn campaign_parts_import_only_downwards() {
    let g = graph("campaign");
    for (_, mods) in CAMPAIGN_PARTS {
        for m in *mods {
            assert!(g.contains_key(*m), "src/campaign/{m}: listed in CAMPAIGN_PARTS but not found");
        }
    }
    for (m, edges) in &g {
        for t in edges {
            // The one exception: order chaining (campaign/chain.rs) judges a finished job's
            // controller as the report verifies it, and the scheduler asks it which controller
            // a chained job starts from. Open debt: the one-evaluation step of the architecture
            // issue moves verification below execution, and this exception goes.
            if m == "scheduler" && t == "chain" {
                continue;
            }
            assert!(
                campaign_rank(t) <= campaign_rank(m),
                "src/campaign/{m} imports campaign::{t}, a part above its own (order: {:?})",
                CAMPAIGN_PARTS.iter().map(|(p, _)| p).collect::<Vec<_>>()
            );
        }
    }
}

#[test]
fn the_campaign_part_order_is_checked() {
    assert!(campaign_rank("journal") > campaign_rank("jobs"));
    assert!(campaign_rank("report") > campaign_rank("scheduler"));
    assert!(campaign_rank("plot::render") > campaign_rank("trace"));
    assert_eq!(campaign_rank("spec"), campaign_rank("model"));
}
