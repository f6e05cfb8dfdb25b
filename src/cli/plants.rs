//! `campaign plants` (the library, one line each) and `campaign plant NAME` (one in detail).
use std::process::ExitCode;

use crate::campaign::{for_terminal as term, load_default_reference, RefMethod, FULL_ORDER_MAX_N};
use crate::lti::{self, Plant};
use anyhow::Context;
use serde_json::{json, Value};

/// Arguments of `campaign plants`.
#[derive(clap::Args, Debug)]
pub struct PlantsArgs {
    /// Print JSON (an array of objects) instead of a table.
    #[arg(long)]
    pub json: bool,
}

/// Arguments of `campaign plant`.
#[derive(clap::Args, Debug)]
pub struct PlantArgs {
    /// Plant name (from the plant library, e.g. HE1) or path to a plant JSON file.
    pub name: String,
    /// Print JSON for machines: the plant file's content plus the computed figures.
    #[arg(long)]
    pub json: bool,
}

/// One plant's summary line.
struct Summary {
    name: String,
    /// The library folder it comes from (`compleib`), `None` for the top folder or a path.
    collection: Option<String>,
    plant: Plant,
    /// α, or ρ − 1 in discrete time.
    alpha: f64,
    /// Whether the plant is stable with the verification margin.
    stable: bool,
}

impl Summary {
    fn new(plant: Plant) -> Self {
        let verified = lti::verified_stability(plant.domain, plant.a.as_ref());
        let (alpha, stable) = (verified.measure, verified.is_stable());
        Summary { name: plant.name.clone(), collection: None, plant, alpha, stable }
    }
    fn stable(&self) -> bool {
        self.stable
    }
    fn json(&self) -> Value {
        let d = self.plant.dims;
        let mut v = json!({
            "name": self.name, "n": d.n, "m1": d.m1, "m2": d.m2, "p1": d.p1, "p2": d.p2,
            "open_loop_stable": self.stable(),
            "source": self.plant.citation,
            "collection": self.collection,
            "fingerprint": self.plant.fingerprint(),
        });
        self.insert_stability(v.as_object_mut().expect("an object"));
        v
    }
    /// `open_loop_spectral_abscissa`, or in discrete time `Ts` and `open_loop_spectral_radius`.
    fn insert_stability(&self, o: &mut serde_json::Map<String, Value>) {
        match self.plant.domain.ts() {
            None => o.insert("open_loop_spectral_abscissa".into(), crate::design::f64_to_json(self.alpha)),
            Some(ts) => {
                o.insert("Ts".into(), crate::design::f64_to_json(ts));
                let rho = self.plant.domain.stability_quantity(self.alpha).1;
                o.insert("open_loop_spectral_radius".into(), crate::design::f64_to_json(rho))
            }
        };
    }
}

/// `campaign plants`.
pub fn list(a: PlantsArgs) -> anyhow::Result<ExitCode> {
    let dir = lti::plants_dir();
    let entries = lti::library_plants().with_context(|| format!("reading the plant library {}", dir.display()))?;
    let mut rows = Vec::new();
    for entry in entries {
        let mut summary = Summary::new(Plant::load(&entry.path)?);
        // listed under the name it is asked for, which is the file's
        summary.name = entry.name;
        summary.collection = entry.collection;
        rows.push(summary);
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&rows.iter().map(Summary::json).collect::<Vec<_>>())?);
        return Ok(ExitCode::SUCCESS);
    }
    let width = rows.iter().map(|r| r.name.chars().count()).max().unwrap_or(0).max(8);
    println!(
        "{:<width$} {:>4} {:>4} {:>3} {:>3} {:>3}  {:<10} {:<9} source",
        "plant", "n", "m1", "m2", "p1", "p2", "open loop", "folder"
    );
    for r in &rows {
        let d = r.plant.dims;
        let stab = if r.stable() { "stable" } else { "unstable" };
        println!(
            "{:<width$} {:>4} {:>4} {:>3} {:>3} {:>3}  {:<10} {:<9} {}",
            term(&r.name),
            d.n,
            d.m1,
            d.m2,
            d.p1,
            d.p2,
            stab,
            r.collection.as_deref().unwrap_or("."),
            term(&short(&r.plant.citation, 70))
        );
    }
    println!("\n{} plants in {} and its folders", rows.len(), dir.display());
    let missing: Vec<String> = std::iter::once(dir.join("MISSING.md"))
        .chain(rows.iter().filter_map(|r| r.collection.as_ref()).map(|c| dir.join(c).join("MISSING.md")))
        .filter(|p| p.is_file())
        .map(|p| p.display().to_string())
        .collect::<std::collections::BTreeSet<_>>()
        .into_iter()
        .collect();
    if !missing.is_empty() {
        println!("plants listed as missing (no public data, or left out for size): {}", missing.join(", "));
    }
    Ok(ExitCode::SUCCESS)
}

/// `campaign plant NAME`.
pub fn show(a: PlantArgs) -> anyhow::Result<ExitCode> {
    let path = lti::resolve_plant(&a.name)?;
    let s = Summary::new(Plant::load(&path)?);
    let paper_full = load_default_reference()
        .ok()
        .and_then(|rows| {
            let fp = s.plant.fingerprint();
            rows.into_iter().find(|r| r.is_for(&fp) && r.method == RefMethod::FullOrder)
        })
        .map(|r| r.gamma);
    // Above FULL_ORDER_MAX_N the full-order γ takes minutes (and cannot be interrupted): skipped.
    let full = if s.plant.dims.n <= FULL_ORDER_MAX_N {
        lti::full_order_gamma(&s.plant).map_err(|e| e.to_string())
    } else {
        Err(format!("skipped: n = {} > {FULL_ORDER_MAX_N} (the limit for computing it here)", s.plant.dims.n))
    };
    if a.json {
        let mut doc = s.plant.to_json();
        let o = doc.as_object_mut().expect("plant JSON is an object");
        o.insert("file".into(), path.display().to_string().into());
        o.insert("open_loop_stable".into(), s.stable().into());
        s.insert_stability(o);
        o.insert("d22_zero".into(), s.plant.d22_is_zero().into());
        o.insert(
            "full_order_gamma".into(),
            match &full {
                Ok(f) => json!({
                    "gamma": crate::design::f64_to_json(f.gamma),
                    "regularisation": f.regularisation.map(crate::design::f64_to_json),
                    "method": f.describe()
                }),
                Err(e) => json!({"error": e}),
            },
        );
        o.insert("paper_full_order_gamma".into(), paper_full.into());
        println!("{}", serde_json::to_string_pretty(&doc)?);
        return Ok(ExitCode::SUCCESS);
    }
    let p = &s.plant;
    let d = p.dims;
    println!("{} — {}", term(&p.name), term(&p.description));
    println!("  file:        {}", term(&path.display().to_string()));
    println!("  source:      {}", term(&p.citation));
    println!("  sizes:       n = {}, w: m1 = {}, u: m2 = {}, z: p1 = {}, y: p2 = {}", d.n, d.m1, d.m2, d.p1, d.p2);
    let (what, value) = match p.domain {
        lti::TimeDomain::Continuous => ("spectral abscissa", s.alpha),
        lti::TimeDomain::Discrete { .. } => ("spectral radius", p.domain.stability_quantity(s.alpha).1),
    };
    if p.domain.is_discrete() {
        println!("  time:        {}", p.domain);
    }
    println!("  open loop:   {} ({what} {})", if s.stable() { "stable" } else { "unstable" }, super::fmt_num(value, 6));
    println!("  D22:         {}", if p.d22_is_zero() { "zero" } else { "non-zero" });
    match &full {
        Ok(f) => println!("  full-order optimal γ: {:.6} ({})", f.gamma, f.describe()),
        Err(e) => println!("  full-order optimal γ: not computed: {e}"),
    }
    if let Some(g) = paper_full {
        println!("  paper's full-order γ: {}", super::fmt_num(g, 6));
    }
    if let Some(check) = &p.check {
        println!("  file's check block:   {check}");
    }
    if !p.notes.is_empty() {
        println!("  notes:       {}", term(&p.notes));
    }
    Ok(ExitCode::SUCCESS)
}

fn short(s: &str, max: usize) -> String {
    if s.chars().count() <= max {
        s.to_string()
    } else {
        format!("{}…", s.chars().take(max - 1).collect::<String>())
    }
}
