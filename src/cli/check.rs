//! `campaign check --plant NAME|PATH --controller K.json|K.mat [--json] [--plot OUT.svg|png]`:
//! closed-loop and controller spectral abscissas, ‖Tzw‖∞ with its peak frequency, ‖K‖∞, and both
//! stability decisions; `--plot` also draws the σ-plot.
//!
//! For a discrete-time plant (and controller: the two must have the same `Ts`) stability is
//! ρ < 1, the norm is on the unit circle and frequencies are in rad/s up to the Nyquist
//! frequency π/Ts; the JSON then has `Ts` and `closed_loop_spectral_radius`,
//! `controller_spectral_radius` in place of the two abscissas.
//!
//! JSON keys: `closed_loop_spectral_abscissa`, `controller_spectral_abscissa` (null for nk = 0),
//! `gamma` (‖Tzw‖∞) and `k_hinf` (‖K‖∞) — the names of the journal, the traces and
//! [`crate::design::DesignOutcome`] (docs/ARCHITECTURE.md §5; builds before that wrote the SLICOT
//! oracle's `closed_loop_hinf` / `controller_hinf`) — `closed_loop_peak_freq` (where ‖Tzw‖∞
//! peaks), `closed_loop_peak_freqs` (every frequency where σmax(Tzw(iω)) is within
//! `lti::NORM_TIE_RTOL`, 0.1 %, of ‖Tzw‖∞: ω = 0 and "inf" included; an optimal controller often
//! equalises several peaks), `closed_loop_stable`, `controller_stable`; non-finite numbers are written
//! as the strings "inf" / "-inf" / "nan" (as `design::float_serde`), a frequency that does not
//! exist (unstable loop) as null.
//!
//! Exit codes: 0 when the closed loop is stable, 4 ([`super::EXIT_NOT_STABILISED`]) when it is
//! not (the report is printed either way), 1 on an error.
use std::path::PathBuf;
use std::process::ExitCode;

use crate::design::{evaluate_plant, loop_details};
use crate::lti::{Controller, Plant, TimeDomain, NORM_TIE_RTOL};
use anyhow::Context;
use serde_json::{json, Value};

/// Arguments of `campaign check`.
#[derive(clap::Args, Debug)]
pub struct CheckArgs {
    /// Plant name (from plants/) or path to a plant file (JSON or MATLAB .mat). Repeat it to
    /// check one controller on several plants (a multi-model design): each plant is reported.
    #[arg(long, required = true)]
    pub plant: Vec<String>,
    /// Controller file: JSON {AK, BK, CK, DK} or MATLAB .mat with the variables AK BK CK DK.
    #[arg(long)]
    pub controller: PathBuf,
    /// Print machine-readable JSON.
    #[arg(long)]
    pub json: bool,
    /// Also draw the σ-plot (σmax of Tzw(iω) and K(iω) vs ω, peak marked) to this .png or .svg file
    /// (one plant only).
    #[arg(long, value_name = "OUT.svg|OUT.png")]
    pub plot: Option<PathBuf>,
}

/// Everything `check` reports.
#[derive(Debug, Clone)]
struct CheckReport {
    domain: TimeDomain,
    /// Stability measures (`lti::stability_measure`): α, or ρ − 1 in discrete time.
    alpha_cl: f64,
    alpha_k: Option<f64>,
    gamma: f64,
    peak_freq: f64,
    /// Every frequency where σmax is within `NORM_TIE_RTOL` of the peak (ascending; empty if
    /// the loop is unstable).
    peak_freqs: Vec<f64>,
    k_hinf: f64,
    /// ‖Tzw‖₂ (+∞ for an unstable loop, or a continuous loop whose feedthrough is not zero).
    h2: f64,
    /// 1/r_C(A_cl), the reciprocal of the complex stability radius (continuous time; None in
    /// discrete time).
    inverse_radius: Option<f64>,
    /// Stability margins (`lti::verified_stability`) of A_cl and Ak: stable means α below minus it
    /// (NaN for Ak of order 0).
    margin_cl: f64,
    margin_k: f64,
}

impl CheckReport {
    fn closed_loop_stable(&self) -> bool {
        self.alpha_cl < -self.margin_cl
    }
    fn controller_stable(&self) -> bool {
        self.alpha_k.is_none_or(|a| a < -self.margin_k)
    }
}

pub fn run(a: CheckArgs) -> anyhow::Result<ExitCode> {
    let plants = a
        .plant
        .iter()
        .map(|name| Ok(Plant::load(crate::lti::resolve_plant(name)?)?))
        .collect::<anyhow::Result<Vec<Plant>>>()?;
    if plants.len() > 1 && a.plot.is_some() {
        anyhow::bail!("--plot draws one plant's σ-plot: give one --plant with it");
    }
    let k = Controller::load(&a.controller)?;
    for plant in &plants {
        k.check_fits(plant)
            .with_context(|| format!("controller {} on plant {}", a.controller.display(), plant.name))?;
    }
    let reports = plants
        .iter()
        .map(|p| {
            evaluate(p, &k)
                .with_context(|| format!("checking the controller {} on the plant {}", a.controller.display(), p.name))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let all_stable = reports.iter().all(CheckReport::closed_loop_stable);
    let exit = if all_stable { ExitCode::SUCCESS } else { ExitCode::from(super::EXIT_NOT_STABILISED) };
    if let [plant] = plants.as_slice() {
        report_one(&a, plant, &k, &reports[0])?;
        return Ok(exit);
    }
    if a.json {
        let each: Vec<Value> = plants
            .iter()
            .zip(&reports)
            .map(|(p, r)| {
                let mut v = to_json(r);
                v.as_object_mut().expect("an object").insert("plant".into(), json!(p.name));
                v
            })
            .collect();
        let v = json!({
            "plants": each,
            "closed_loop_stable": all_stable,
            "controller_stable": reports[0].controller_stable(),
        });
        println!("{}", serde_json::to_string_pretty(&v)?);
    } else {
        for (i, (p, r)) in plants.iter().zip(&reports).enumerate() {
            print!("[{} of {}] {}", i + 1, plants.len(), human(p, &k, r));
        }
        let unstable: Vec<&str> = plants
            .iter()
            .zip(&reports)
            .filter(|(_, r)| !r.closed_loop_stable())
            .map(|(p, _)| p.name.as_str())
            .collect();
        match unstable.as_slice() {
            [] => println!("every closed loop ({} plants) is stable", plants.len()),
            u => println!("UNSTABLE closed loop with {}", crate::campaign::for_terminal(&u.join(", "))),
        }
    }
    Ok(exit)
}

/// The report of one plant, as `check` has always printed it.
fn report_one(a: &CheckArgs, plant: &Plant, k: &Controller, r: &CheckReport) -> anyhow::Result<()> {
    if let Some(out) = &a.plot {
        let title = format!("σ-plot: {}, controller {} (order {})", plant.name, a.controller.display(), k.order());
        let fig = crate::campaign::plot::sigma_figure(plant, k, title)?;
        crate::campaign::plot::write_by_extension(&fig, out)?;
        eprintln!("σ-plot written to {}", out.display());
    }
    if a.json {
        println!("{}", serde_json::to_string_pretty(&to_json(r))?);
    } else {
        print!("{}", human(plant, k, r));
    }
    Ok(())
}

fn evaluate(plant: &Plant, k: &Controller) -> anyhow::Result<CheckReport> {
    let e = evaluate_plant(plant, k);
    let l = e.plants[0].closed_loop.as_ref().map_err(Clone::clone).context("forming the closed loop")?;
    let details = loop_details(plant, k, &l.hinf).context("forming the closed loop")?;
    let r = CheckReport {
        h2: details.h2,
        inverse_radius: details.inverse_radius,
        domain: plant.domain,
        alpha_cl: l.stability.measure,
        alpha_k: e.controller.stability.map(|s| s.measure),
        gamma: l.hinf.value,
        peak_freq: l.hinf.peak_freq,
        peak_freqs: details.peak_freqs,
        k_hinf: e.controller.hinf,
        margin_cl: l.stability.margin,
        margin_k: e.controller.stability.map_or(f64::NAN, |s| s.margin),
    };
    // A stable system has a finite norm: NaN or ∞ here is a computation out of f64's range (a
    // controller with huge entries; plants are bounded on load), never a result to print.
    for (what, value, stable) in
        [("‖Tzw‖∞", r.gamma, r.closed_loop_stable()), ("‖K‖∞", r.k_hinf, r.controller_stable())]
    {
        if stable && !value.is_finite() {
            anyhow::bail!(
                "{what} of a stable system came out {value}: the plant's and the controller's numbers are out of \
                 the range the norm can be computed in (see the magnitude limits in campaigns/FORMAT.md)"
            );
        }
    }
    Ok(r)
}

use crate::design::f64_to_json as num;

fn to_json(r: &CheckReport) -> Value {
    let mut v = json!({
        "gamma": num(r.gamma),
        "closed_loop_peak_freq": if r.peak_freq.is_nan() { Value::Null } else { num(r.peak_freq) },
        "closed_loop_peak_freqs": r.peak_freqs.iter().map(|&w| num(w)).collect::<Vec<_>>(),
        "k_hinf": num(r.k_hinf),
        "h2": num(r.h2),
        "closed_loop_stable": r.closed_loop_stable(),
        "controller_stable": r.controller_stable(),
        "closed_loop_stability_margin": num(r.margin_cl),
        "controller_stability_margin": r.alpha_k.map(|_| num(r.margin_k)),
    });
    let o = v.as_object_mut().expect("an object");
    match r.domain {
        TimeDomain::Continuous => {
            o.insert("closed_loop_spectral_abscissa".into(), num(r.alpha_cl));
            o.insert("controller_spectral_abscissa".into(), r.alpha_k.map(num).into());
            o.insert("inverse_stability_radius".into(), r.inverse_radius.map(num).into());
        }
        TimeDomain::Discrete { ts } => {
            o.insert("Ts".into(), num(ts));
            let rho = |s: f64| num(r.domain.stability_quantity(s).1);
            o.insert("closed_loop_spectral_radius".into(), rho(r.alpha_cl));
            o.insert("controller_spectral_radius".into(), r.alpha_k.map(rho).into());
        }
    }
    v
}

fn human(plant: &Plant, k: &Controller, r: &CheckReport) -> String {
    let yes_no = |b: bool| if b { "stable" } else { "UNSTABLE" };
    let freq = peak_text(r);
    let mut s = format!(
        "plant {} (n = {}), controller of order {}\n",
        crate::campaign::for_terminal(&plant.name),
        plant.dims.n,
        k.order()
    );
    // α, or ρ in discrete time (stable means ρ < 1 − margin)
    let quantity = |m: f64| r.domain.stability_quantity(m);
    let (name, alpha_cl) = quantity(r.alpha_cl);
    let bound = if r.domain.is_discrete() { "ρ < 1 − " } else { "α < −" };
    if r.domain.is_discrete() {
        s += &format!("{}, frequencies in rad/s up to the Nyquist frequency\n", r.domain);
    }
    s += &format!(
        "closed loop: {name}(A_cl) = {:+.6e}   {} (stable means {bound}{:.6e})\n",
        alpha_cl,
        yes_no(r.closed_loop_stable()),
        r.margin_cl
    );
    s += &format!("             ‖Tzw‖∞  = {}   at {}\n", super::fmt_num(r.gamma, 10), freq);
    s += &format!("             ‖Tzw‖₂  = {}\n", super::fmt_num(r.h2, 10));
    if let Some(ir) = r.inverse_radius {
        s += &format!(
            "             1/r_C   = {}   (complex stability radius r_C = {})\n",
            super::fmt_num(ir, 10),
            super::fmt_num(1.0 / ir, 10)
        );
    }
    match r.alpha_k {
        Some(a) => {
            s += &format!(
                "controller:  {name}(Ak)    = {:+.6e}   {} (stable means {bound}{:.6e})\n",
                quantity(a).1,
                yes_no(r.controller_stable()),
                r.margin_k
            )
        }
        None => s += "controller:  static gain (order 0), trivially stable\n",
    }
    s += &format!("             ‖K‖∞    = {}\n", super::fmt_num(r.k_hinf, 10));
    s
}

/// "ω = 0.720000 rad/s", or with several peaks within `NORM_TIE_RTOL` of the norm
/// "ω = 0, 0.720000 and ∞ rad/s (σmax within 0.1 % of the peak at each)".
fn peak_text(r: &CheckReport) -> String {
    let one = |w: f64| {
        if w.is_infinite() {
            "∞".to_string()
        } else if w == 0.0 {
            "0".to_string()
        } else {
            super::fmt_num(w, 6)
        }
    };
    match r.peak_freqs.as_slice() {
        _ if r.peak_freq.is_nan() => "—".to_string(),
        _ if r.gamma == 0.0 => "— (σmax(Tzw) = 0 at every frequency)".to_string(),
        [] | [_] if r.peak_freq.is_infinite() => "ω → ∞".to_string(),
        [] | [_] => format!("ω = {} rad/s", one(r.peak_freq)),
        [init @ .., last] => format!(
            "ω = {} and {} rad/s (σmax within {} % of the peak at each)",
            init.iter().map(|&w| one(w)).collect::<Vec<_>>().join(", "),
            one(*last),
            NORM_TIE_RTOL * 100.0
        ),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Several peaks at the norm are all named, ω = 0 and ∞ included.
    #[test]
    fn every_peak_is_named() {
        let mut r = CheckReport {
            domain: TimeDomain::Continuous,
            alpha_cl: -1.0,
            alpha_k: None,
            gamma: 2.0,
            peak_freq: 0.0,
            peak_freqs: vec![0.0, 0.72, f64::INFINITY],
            k_hinf: 1.0,
            h2: 1.0,
            inverse_radius: Some(1.0),
            margin_cl: 1e-12,
            margin_k: 1e-12,
        };
        assert_eq!(peak_text(&r), "ω = 0, 0.720000 and ∞ rad/s (σmax within 0.1 % of the peak at each)");
        assert_eq!(to_json(&r)["closed_loop_peak_freqs"], json!([0.0, 0.72, "inf"]));
        r.peak_freqs = vec![0.72];
        r.peak_freq = 0.72;
        assert_eq!(peak_text(&r), "ω = 0.720000 rad/s");
        // T_zw ≡ 0: no peak to name (every frequency was listed, about 200 of them)
        r.gamma = 0.0;
        r.peak_freqs = vec![];
        assert_eq!(peak_text(&r), "— (σmax(Tzw) = 0 at every frequency)");
    }

    #[test]
    fn json_keys_and_infinities() {
        let r = CheckReport {
            domain: TimeDomain::Continuous,
            alpha_cl: 0.3,
            alpha_k: None,
            gamma: f64::INFINITY,
            peak_freq: f64::NAN,
            peak_freqs: vec![],
            k_hinf: 1.5,
            h2: f64::INFINITY,
            inverse_radius: None,
            margin_cl: 1e-12,
            margin_k: 1e-12,
        };
        let v = to_json(&r);
        assert_eq!(v["gamma"], json!("inf"));
        assert_eq!(v["k_hinf"], json!(1.5));
        assert_eq!(v["closed_loop_peak_freq"], Value::Null);
        assert_eq!(v["controller_spectral_abscissa"], Value::Null);
        assert_eq!(v["closed_loop_stable"], json!(false));
        assert_eq!(v["controller_stable"], json!(true));
        assert!(!serde_json::to_string(&v).unwrap().contains("Infinity"));
        let r = CheckReport {
            domain: TimeDomain::Continuous,
            alpha_cl: -0.3,
            alpha_k: Some(-1.0),
            gamma: 2.0,
            peak_freq: f64::INFINITY,
            peak_freqs: vec![f64::INFINITY],
            k_hinf: 1.5,
            h2: f64::INFINITY,
            inverse_radius: None,
            margin_cl: 1e-12,
            margin_k: 1e-12,
        };
        assert_eq!(to_json(&r)["closed_loop_peak_freq"], json!("inf"));
    }
}
