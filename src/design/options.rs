//! Options of one design run (they enter the campaign's job-id hash, so they are serde).

use serde::{Deserialize, Serialize};

use super::float_serde::{serde_f64_or_string, serde_vec_f64_or_string};

/// Largest accepted number of random starts `nrand` (each start is a BFGS run of its own).
pub const MAX_NRAND: usize = 10_000;
/// Largest accepted iteration limit `maxit` and `gradsamp_maxit` (the CPU budget stops a run
/// long before; the bound only turns a typo into an error).
pub const MAX_ITERATIONS: usize = 100_000_000;

/// Which problem to solve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum ObjectiveKind {
    /// Strong stabilisation: minimise max(‖Tzw‖∞, ε‖K‖∞) subject to a stable closed loop and a
    /// stable controller (Gumussoy–Millstone–Overton 2008).
    #[default]
    Strong,
    /// Plain fixed-order H∞: minimise ‖Tzw‖∞ with a stable closed loop, K unrestricted.
    Plain,
}

/// Default of [`DesignOptions::stall_starts`].
pub const DEFAULT_STALL_STARTS: usize = 60;

/// Default of [`DesignOptions::hop_scales`].
pub const DEFAULT_HOP_SCALES: [f64; 3] = [1e-2, 1e-1, 1.0];

/// Default of [`DesignOptions::random_scales`].
pub const DEFAULT_RANDOM_SCALES: [f64; 3] = [1.0, 1e-1, 1e-2];

/// [`DesignOptions::random_scales`] of a record that does not have the field (builds before it
/// existed): standard-normal random starts only.
fn unit_random_scale() -> Vec<f64> {
    vec![1.0]
}

fn is_unit_random_scale(v: &[f64]) -> bool {
    v == [1.0]
}

fn is_false(b: &bool) -> bool {
    !*b
}

fn is_zero(n: &usize) -> bool {
    *n == 0
}

fn is_zero_f64(x: &f64) -> bool {
    *x == 0.0
}

/// Default of [`DesignOptions::refine_rtol`]: off. 0.03 lowered HE1 n_K = 3 (ε = 1e-3, 60 CPU s)
/// from 0.09268 to 0.0906–0.0910 at seed 1 but not at seeds 2 and 3 (0.09275, 0.09274 against
/// 0.09271, 0.08964 without), and was mixed on random plants (docs/ALGORITHMS.md §8.3).
pub const DEFAULT_REFINE_RTOL: f64 = 0.0;

/// Default of [`DesignOptions::continued_maxit`].
pub const DEFAULT_CONTINUED_MAXIT: usize = 3000;

/// Which coordinates the local searches of a run use (docs/ALGORITHMS.md §8.6): the controller's
/// parameters x, or the plant-scaled variables x̃ with x = d ∘ x̃ (`design::scaling`). A plant
/// whose channels are alike has d = 1: every mode is then the unscaled search, bit for bit.
///
/// Serialised as `"alternate"`, `true` (always) and, when off, not at all: builds before the mode
/// had the boolean `variable_scaling` (false: off, true: always), so their records and campaign
/// files read unchanged and keep their job ids. A campaign file or record may give either form.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum VariableScaling {
    /// Every local search in x (HIFOO's search). The value of a record without the field.
    #[default]
    Off,
    /// Both: HIFOO's first starts in x, then the continued search's hop cycles (the hops and
    /// random start of a cycle drawn in its coordinates) in the coordinates that found the
    /// incumbent, except one in [`crate::design::ALTERNATE_PERIOD`] = 4 (the first included) in the
    /// others. The default of [`DesignOptions`].
    Alternate,
    /// Every local search in x̃ (the boolean `true` of older builds).
    Always,
}

impl VariableScaling {
    /// The name used in campaign files, `--variable-scaling` and messages.
    pub fn name(self) -> &'static str {
        match self {
            VariableScaling::Off => "off",
            VariableScaling::Alternate => "alternate",
            VariableScaling::Always => "always",
        }
    }

    /// Reads a name ("off", "alternate", "always"; also "false" / "true").
    pub fn parse(s: &str) -> Result<Self, String> {
        match s {
            "off" | "false" => Ok(VariableScaling::Off),
            "alternate" => Ok(VariableScaling::Alternate),
            "always" | "true" => Ok(VariableScaling::Always),
            other => Err(format!("expected \"off\", \"alternate\" or \"always\" (or a boolean), found {other:?}")),
        }
    }

    fn is_off(&self) -> bool {
        *self == VariableScaling::Off
    }
}

impl Serialize for VariableScaling {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        match self {
            VariableScaling::Off => s.serialize_bool(false),
            VariableScaling::Always => s.serialize_bool(true),
            VariableScaling::Alternate => s.serialize_str(self.name()),
        }
    }
}

impl<'de> Deserialize<'de> for VariableScaling {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct Visitor;
        impl serde::de::Visitor<'_> for Visitor {
            type Value = VariableScaling;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("\"off\", \"alternate\", \"always\" or a boolean (false: off, true: always)")
            }
            fn visit_bool<E: serde::de::Error>(self, b: bool) -> Result<VariableScaling, E> {
                Ok(if b { VariableScaling::Always } else { VariableScaling::Off })
            }
            fn visit_str<E: serde::de::Error>(self, s: &str) -> Result<VariableScaling, E> {
                VariableScaling::parse(s).map_err(E::custom)
            }
        }
        d.deserialize_any(Visitor)
    }
}

/// Default of [`DesignOptions::central_gammas`].
pub const DEFAULT_CENTRAL_GAMMAS: [f64; 2] = [1.1, 2.0];

/// Options of [`crate::design::run`]. Defaults follow HIFOO 3.5 (docs/ALGORITHMS.md §8), except that
/// the search goes on after HIFOO's starts (`stall_starts`, `hop_scales`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DesignOptions {
    /// Controller order nk ≥ 0.
    pub order: usize,
    /// Weight ε of the controller's own term (strong stabilisation only), ε > 0.
    #[serde(with = "serde_f64_or_string")]
    pub eps: f64,
    /// Seed of the run's random number generator.
    pub seed: u64,
    /// Budget of the whole run in **CPU seconds** (both phases and gradient sampling): thread CPU
    /// time, not wall-clock time. A run stopped by it is not reproducible bit for bit (it depends
    /// on the machine's speed).
    #[serde(with = "serde_f64_or_string")]
    pub cpumax: f64,
    /// Evaluation budget of the whole run (objective evaluations, both phases and gradient
    /// sampling); `None`: no limit. Deterministic: the same job stops at the same evaluation on
    /// any machine and under any load.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub maxevals: Option<usize>,
    /// Number of random starting points (HIFOO `nrand`, default 3), or of perturbations of an
    /// initial controller. These starts are always made (unless a budget ends the run first).
    pub nrand: usize,
    /// Stall rule of the continued search (the `design::search` module docs, "When it stops"): after the first
    /// starts, new local searches are started until `stall_starts` consecutive ones have not
    /// improved the best objective by a relative `stall_rtol` (or a budget ends the run; with
    /// `spend_budget`, the rule ends only runs that no budget bounds).
    /// 0 = HIFOO 3.5's search: only the first starts. (Missing in a serialised record: 0, the
    /// behaviour before this option existed.)
    #[serde(default)]
    pub stall_starts: usize,
    /// Relative improvement of the best objective that resets the stall count (see
    /// `stall_starts`).
    #[serde(with = "serde_f64_or_string")]
    pub stall_rtol: f64,
    /// Spend the budget: when a budget bounds the run (`cpumax` finite, `maxevals` or
    /// `max_starts` set), the stall rule does not end it once a stable point is known; the
    /// continued search goes on until the budget ends it. The stall rule still ends runs without
    /// any budget. false: the stall rule ends bounded runs too. (Missing in a serialised record:
    /// false, the behaviour before this option existed; not written when false.)
    #[serde(default, skip_serializing_if = "is_false")]
    pub spend_budget: bool,
    /// Resume a cut local search: when the f_h local search that produced the best point ended
    /// on `maxit` (not at a minimiser), the next continued start is that point itself, with a
    /// fresh BFGS (the first starts are unchanged). (Missing in a serialised record: false, the
    /// behaviour before this option existed; not written when false.)
    #[serde(default, skip_serializing_if = "is_false")]
    pub continue_at_maxit: bool,
    /// BFGS iteration limit of the continued search's f_h local searches (HIFOO's first starts
    /// and every stabilisation keep `maxit`); 0: `maxit`. Local searches on many variables are
    /// cut by HIFOO's 1000 iterations (Enns n_K = 8, 81 variables); on small plants they end at
    /// a minimiser long before either limit, so the option changes nothing there. (Missing in a
    /// serialised record: 0, the behaviour before this option existed; not written when 0.)
    #[serde(default, skip_serializing_if = "is_zero")]
    pub continued_maxit: usize,
    /// Give the unused part of the gradient-sampling reserve back to the search: gradient
    /// sampling runs on the incumbent where HIFOO's search runs it (after the `nrand` first
    /// starts; the incumbent is then HIFOO's result) and whenever the search's share of a budget
    /// is spent; the reserve becomes twice what it took (at most the first 10 %), and gradient
    /// sampling runs again at the end only if the incumbent changed. false: 10 % of each budget
    /// is kept, and gradient sampling runs once, at the end.
    /// (Missing in a serialised record: false, the behaviour before this option existed; not
    /// written when false.)
    #[serde(default, skip_serializing_if = "is_false")]
    pub return_gs_reserve: bool,
    /// Refine near-misses: an f_h local search of the continued search that ends uncertified
    /// (dnorm > `normtol`) at most a relative `refine_rtol` above the incumbent gets gradient
    /// sampling from its end point (with `gradient_sampling`), so that its basin is judged by a
    /// refined value, as the incumbent's is (the `design::search` module docs). 0 (the default): none. (Missing
    /// in a serialised record: 0, the behaviour before this option existed; not written when 0.)
    #[serde(default, with = "serde_f64_or_string", skip_serializing_if = "is_zero_f64")]
    pub refine_rtol: f64,
    /// Largest number of local searches (first starts included); `None`: no limit.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub max_starts: Option<usize>,
    /// Relative sizes r of the basin-hopping perturbations x* + ξ ∘ (‖x*‖·r), ξ ~ N(0, I), of the
    /// best point x* (the same form as the perturbations of an initial controller). The
    /// continued search cycles through one perturbation per size, then one fresh random start.
    /// Empty: random starts only. (Missing in a serialised record: empty.)
    #[serde(default, with = "serde_vec_f64_or_string")]
    pub hop_scales: Vec<f64>,
    /// Scales σ of the continued search's fresh random starts σ·ξ, ξ ~ N(0, I): the c-th fresh
    /// random start uses σ = `random_scales[c mod len]` (HIFOO's first `nrand` starts are always
    /// standard normal). Small scales reach controllers with small gains, which badly scaled
    /// plants need to be stabilised. (Missing in a serialised record: `[1]`, the behaviour before
    /// this option existed; not written when `[1]`.)
    #[serde(
        default = "unit_random_scale",
        with = "serde_vec_f64_or_string",
        skip_serializing_if = "is_unit_random_scale"
    )]
    pub random_scales: Vec<f64>,
    /// Make the open-loop start K = 0 (`design::starts::open_loop_controller`) one more first
    /// start, after the `nrand` starts and before the central-controller starts. (Missing in a
    /// serialised record: false; not written when false.)
    #[serde(default, skip_serializing_if = "is_false")]
    pub open_loop_start: bool,
    /// Coordinates of the local searches ([`VariableScaling`]): `Off`, x only; `Alternate` (the
    /// default), HIFOO's first starts and the open-loop start in x, each central start in x and
    /// then in x̃ (on a scaled plant), then the continued search's hop cycles in the
    /// coordinates that found the incumbent, except one in four (the first included) in the
    /// others — x or the plant-scaled variables x̃ (x = d ∘ x̃, `design::scaling`: the control
    /// and measurement channels scaled to comparable sizes, powers of two); `Always`, x̃ only. A
    /// plant whose channels are alike (within 2¹⁰: HE1, REA2, AC8, Enns, every SISO plant) gets
    /// d = 1, and every mode is the unscaled search bit for bit. AC10 n_K = 1 needs x̃ (γ ≈ 17.6
    /// unscaled, 10.05 always scaled at 300 CPU s), BDT2 n_K = 1 does better in x (0.581 against
    /// 0.897); the incumbent is kept in x, so alternating keeps what each finds (AC10 10.46,
    /// BDT2 0.5815 with `Alternate`). (Missing in a
    /// serialised record: off. The booleans of older builds read as off / always.)
    #[serde(default, skip_serializing_if = "VariableScaling::is_off")]
    pub variable_scaling: VariableScaling,
    /// Levels γ = f·γ_opt (factors f > 1 of the full-order optimum) of the reduced-order
    /// central-controller starts: for each f, the full-order H∞ central controller at that level,
    /// reduced to `order` by balanced truncation, is one more first start, made after the `nrand`
    /// starts (`design::central_start`). Empty: none. (Missing in a serialised record: empty.)
    /// Not written when empty, so a record of a build without central starts reads and rewrites
    /// identically (and keeps its job id).
    #[serde(default, with = "serde_vec_f64_or_string", skip_serializing_if = "Vec::is_empty")]
    pub central_gammas: Vec<f64>,
    /// Strong stabilisation or plain H∞.
    pub objective: ObjectiveKind,
    /// Relative tolerance of the H∞ norm computation.
    #[serde(with = "serde_f64_or_string")]
    pub hinf_tol: f64,
    /// BFGS iteration limit per start and phase (HIFOO `maxit`, 1000).
    pub maxit: usize,
    /// Stop BFGS when the certificate dnorm ≤ normtol (HIFOO passes 1e-3).
    #[serde(with = "serde_f64_or_string")]
    pub normtol: f64,
    /// Gradient-bundle radius (HIFOO passes 1e-3).
    #[serde(with = "serde_f64_or_string")]
    pub evaldist: f64,
    /// Run gradient sampling after BFGS (HIFOO `fast = 0`).
    pub gradient_sampling: bool,
    /// Iteration limit of each gradient-sampling run (HIFOO caps HANSO 2.0's gradient sampling
    /// at 100 iterations per radius, 3 radii; each iteration costs 2·nvar evaluations).
    pub gradsamp_maxit: usize,
}

impl Default for DesignOptions {
    fn default() -> Self {
        DesignOptions {
            order: 1,
            eps: 1e-3,
            seed: 0,
            cpumax: 60.0,
            maxevals: None,
            nrand: 3,
            stall_starts: DEFAULT_STALL_STARTS,
            stall_rtol: 1e-6,
            spend_budget: true,
            continue_at_maxit: true,
            continued_maxit: DEFAULT_CONTINUED_MAXIT,
            return_gs_reserve: true,
            refine_rtol: DEFAULT_REFINE_RTOL,
            max_starts: None,
            hop_scales: DEFAULT_HOP_SCALES.to_vec(),
            random_scales: DEFAULT_RANDOM_SCALES.to_vec(),
            open_loop_start: true,
            variable_scaling: VariableScaling::Alternate,
            central_gammas: DEFAULT_CENTRAL_GAMMAS.to_vec(),
            objective: ObjectiveKind::Strong,
            hinf_tol: crate::lti::DEFAULT_HINF_TOL,
            maxit: 1000,
            normtol: 1e-3,
            evaldist: 1e-3,
            gradient_sampling: true,
            gradsamp_maxit: 300,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::DesignOptions;

    /// campaigns/FORMAT.md lists the defaults in prose; they must be the code's defaults.
    #[test]
    fn format_md_states_the_defaults() {
        let doc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/campaigns/FORMAT.md")).unwrap();
        let doc = doc.split_whitespace().collect::<Vec<_>>().join(" ");
        let d = DesignOptions::default();
        for want in [
            format!("ε {:e},", d.eps),
            format!("seed {},", d.seed),
            format!("cpumax {} CPU seconds,", d.cpumax),
            format!("nrand {},", d.nrand),
            format!("stall_starts {},", d.stall_starts),
            format!("stall_rtol {:e},", d.stall_rtol),
            format!("spend_budget {},", d.spend_budget),
            format!("continue_at_maxit {},", d.continue_at_maxit),
            format!("continued_maxit {},", d.continued_maxit),
            format!("return_gs_reserve {},", d.return_gs_reserve),
            format!("refine_rtol {},", d.refine_rtol),
            format!("maxit {},", d.maxit),
            format!("normtol {:e},", d.normtol),
            format!("evaldist {:e},", d.evaldist),
            format!("hinf_tol {:e},", d.hinf_tol),
        ] {
            assert!(doc.contains(&want), "campaigns/FORMAT.md's list of defaults should say `{want}`");
        }
    }
}
