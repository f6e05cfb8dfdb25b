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

impl ObjectiveKind {
    /// The name used in campaign files and journals (`"strong"`, `"plain"`).
    pub fn name(self) -> &'static str {
        match self {
            ObjectiveKind::Strong => "strong",
            ObjectiveKind::Plain => "plain",
        }
    }
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

/// Default of [`DesignOptions::bfgs_restart`]: 300 iterations. Against no restart, at 6 CPU s per
/// job on 35 COMPleib entries (3 seeds each) it lowered the geometric mean of the best γ to 0.95
/// (10 entries lower by more than 0.1 %, 3 higher); NN13 n_K = 2 reached γ ≤ 10.50 in 6 to 9 of
/// 10 seeds against 1 (docs/ALGORITHMS.md §7.1).
pub const DEFAULT_BFGS_RESTART: usize = 300;

/// A name that is no [`VariableScaling`] mode (the name given).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("expected \"off\", \"alternate\" or \"always\" (or a boolean), found {0:?}")]
pub struct UnknownVariableScaling(pub String);

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
    pub fn parse(s: &str) -> Result<Self, UnknownVariableScaling> {
        match s {
            "off" | "false" => Ok(VariableScaling::Off),
            "alternate" => Ok(VariableScaling::Alternate),
            "always" | "true" => Ok(VariableScaling::Always),
            other => Err(UnknownVariableScaling(other.to_string())),
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

/// Checks nothing: an option every value of its type is fine for (a seed, a switch).
fn any_value<T>(_: &T) -> Result<(), String> {
    Ok(())
}

/// The check of an optional count limit (`maxevals`, `max_starts`): absent, or at least 1.
fn optional_limit(v: &Option<usize>) -> Result<(), String> {
    require(*v != Some(0), || "must be at least 1 (omit it for no limit)".into())
}

/// The check of an iteration count (`continued_maxit`, `bfgs_restart`, `gradsamp_maxit`): at most
/// [`MAX_ITERATIONS`]; `zero` says what 0 means, where it means something else than 0 iterations.
fn iterations_at_most_max(v: usize, zero: Option<&str>) -> Result<(), String> {
    require(v <= MAX_ITERATIONS, || {
        let zero = zero.map_or(String::new(), |z| format!(" (0: {z})"));
        format!("must be at most {MAX_ITERATIONS}{zero}, got {v}")
    })
}

/// `Ok` when `ok`, else the message.
fn require(ok: bool, problem: impl FnOnce() -> String) -> Result<(), String> {
    if ok {
        Ok(())
    } else {
        Err(problem())
    }
}

/// The first entry of `v` that is not finite and above `min`.
fn first_not_above(v: &[f64], min: f64) -> Option<f64> {
    v.iter().copied().find(|x| !(x.is_finite() && *x > min))
}

/// The value type of a design option as the option table sees it: how its default is written in
/// campaigns/FORMAT.md, and what a campaign file gives for it (a number for `maxevals:
/// Option<usize>`, which then means `Some`).
pub trait OptionValue: Sized {
    /// What a campaign file's key holds.
    type Setting: Clone;
    /// The option's value for a setting read from a campaign file.
    fn from_setting(s: Self::Setting) -> Self;
    /// The value as the option table in campaigns/FORMAT.md writes it.
    fn show(&self) -> String;
}

/// A float for people: `1e-3` rather than `0.001` below 10⁻², plain otherwise (`60`, `0.03`).
fn show_f64(x: f64) -> String {
    if x != 0.0 && x.abs() < 1e-2 {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

macro_rules! identity_option_value {
    ($($t:ty => |$v:ident| $show:expr;)*) => {$(
        impl OptionValue for $t {
            type Setting = $t;
            fn from_setting(s: $t) -> $t {
                s
            }
            fn show(&self) -> String {
                let $v = self;
                $show
            }
        }
    )*};
}

identity_option_value! {
    f64 => |x| show_f64(*x);
    usize => |n| n.to_string();
    u64 => |n| n.to_string();
    bool => |b| b.to_string();
    Vec<f64> => |v| format!("[{}]", v.iter().map(|x| show_f64(*x)).collect::<Vec<_>>().join(", "));
    ObjectiveKind => |k| format!("\"{}\"", k.name());
    VariableScaling => |m| format!("\"{}\"", m.name());
}

impl OptionValue for Option<usize> {
    type Setting = usize;
    fn from_setting(s: usize) -> Self {
        Some(s)
    }
    fn show(&self) -> String {
        match self {
            Some(n) => n.to_string(),
            None => "no limit".into(),
        }
    }
}

/// One row of the option table: what [`DesignOptions::table`] says of an option.
#[derive(Debug, Clone, PartialEq)]
pub struct OptionRow {
    /// The `DesignOptions` field (and the job-id document's key).
    pub name: &'static str,
    /// Its key in a campaign file (`""`: none; `orders`, `eps`, `seeds` are lists of jobs).
    pub key: &'static str,
    /// Its flag of `campaign design` (`""`: none; a switch names the non-default side).
    pub flag: &'static str,
    /// The default, as campaigns/FORMAT.md writes it.
    pub default: String,
    /// The accepted values, as checked by [`crate::design::validate`].
    pub accepts: String,
    /// One line on what it does.
    pub doc: &'static str,
}

/// **The option table**: every design option once — its field (type, serde form, rustdoc), its
/// default, its campaign-file key, its `campaign design` flag, the values it accepts (text and
/// check) and one line of documentation. Everything else comes from here (docs/ARCHITECTURE.md
/// §4): the [`DesignOptions`] struct and its `Default`, the per-option checks of
/// [`crate::design::validate`], the campaign keys layered in `campaign/spec.rs` (`key layered`:
/// the key is the field's name and `[defaults]` / `[[problem]]` set it), the defaults of the
/// command line (`cli/design.rs` reads [`DesignOptions::default`]) and the option table of
/// campaigns/FORMAT.md (a test keeps it equal to [`DesignOptions::table`]).
///
/// The fields' order and serde attributes are the journal's and the job id's serialised form:
/// never reorder, rename or change a skip rule (every job id would change).
///
/// Invoked with a callback macro and its arguments: `design_option_table!(callback { args })`
/// expands to `callback! { { args } entry; entry; … }`, one entry per option:
/// `#[attrs] field: Type = default, key layered|"key", flag "--flag", accepts text, check fn,
/// doc "line";`.
macro_rules! design_option_table {
    ($callback:ident { $($args:tt)* }) => {
        $callback! { { $($args)* }
            /// Controller order nk ≥ 0.
            order: usize = 1,
                key "orders", flag "--order",
                accepts "0..=n, the plant's order (checked against the plant)",
                check any_value,
                doc "controller order n_K";
            /// Weight ε of the controller's own term (strong stabilisation only), ε > 0.
            #[serde(with = "serde_f64_or_string")]
            eps: f64 = 1e-3,
                key "eps", flag "--eps",
                accepts "from 1e-50 to 1e50",
                // the range of a plant's weight (`MIN_WEIGHT`, `MAX_WEIGHT`): ε = 1e308 made
                // ε·α(Ak) overflow, and the run returned Ak = −5e307 with a garbage closed loop
                check |v: &f64| require((super::MIN_WEIGHT..=super::MAX_WEIGHT).contains(v), || {
                    format!("ε must be a number from 1e-50 to 1e50, got {}", crate::numeric::readable(*v))
                }),
                doc "weight ε of ‖K‖∞ in max(‖Tzw‖∞, ε‖K‖∞) and of α(A_K)";
            /// Seed of the run's random number generator.
            seed: u64 = 0,
                key "seeds", flag "--seed",
                accepts "any",
                check any_value,
                doc "seed of the job's random numbers";
            /// Budget of the whole run in **CPU seconds** (both phases and gradient sampling): thread CPU
            /// time, not wall-clock time. A run stopped by it is not reproducible bit for bit (it depends
            /// on the machine's speed).
            #[serde(with = "serde_f64_or_string")]
            cpumax: f64 = 60.0,
                key layered, flag "--cpumax",
                accepts "> 0, may be inf",
                check |v: &f64| require(*v > 0.0, || {
                    format!("must be > 0 CPU seconds (may be infinite), got {v}")
                }),
                doc "CPU seconds per job (thread CPU time; a run it ends is not reproducible bit for bit)";
            /// Evaluation budget of the whole run (objective evaluations, both phases and gradient
            /// sampling); `None`: no limit. Deterministic: the same job stops at the same evaluation on
            /// any machine and under any load.
            #[serde(default, skip_serializing_if = "Option::is_none")]
            maxevals: Option<usize> = None,
                key layered, flag "--maxevals",
                accepts "≥ 1",
                check optional_limit,
                doc "objective evaluations per job (deterministic)";
            /// Number of random starting points (HIFOO `nrand`, default 3), or of perturbations of an
            /// initial controller. These starts are always made (unless a budget ends the run first).
            nrand: usize = 3,
                key layered, flag "--nrand",
                accepts format!("1..={}", $crate::design::MAX_NRAND),
                check |v: &usize| require((1..=$crate::design::MAX_NRAND).contains(v), || {
                    format!("must be in 1..={}, got {v}", $crate::design::MAX_NRAND)
                }),
                doc "HIFOO's first random starts (or perturbations of the initial controller)";
            /// Stall rule of the continued search (the `design::search` module docs, "When it stops"): after the first
            /// starts, new local searches are started until `stall_starts` consecutive ones have not
            /// improved the best objective by a relative `stall_rtol` (or a budget ends the run; with
            /// `spend_budget`, the rule ends only runs that no budget bounds).
            /// 0 = HIFOO 3.5's search: only the first starts. (Missing in a serialised record: 0, the
            /// behaviour before this option existed.)
            #[serde(default)]
            stall_starts: usize = $crate::design::DEFAULT_STALL_STARTS,
                key layered, flag "--stall-starts",
                accepts "≥ 0 (0: the first starts only)",
                check any_value,
                doc "stall rule: stop after this many local searches in a row without improvement";
            /// Relative improvement of the best objective that resets the stall count (see
            /// `stall_starts`).
            #[serde(with = "serde_f64_or_string")]
            stall_rtol: f64 = 1e-6,
                key layered, flag "--stall-rtol",
                accepts "finite, ≥ 0; > 0 when no budget bounds the search",
                check |v: &f64| require(v.is_finite() && *v >= 0.0, || {
                    format!("must be finite and >= 0, got {v}")
                }),
                doc "relative improvement of the best objective that resets the stall count";
            /// Stall rule in CPU time: the continued search also stops (under the same conditions as
            /// the stall rule of `stall_starts`) once `stall_cpu` CPU seconds have passed since the
            /// best objective last improved by `stall_rtol` (or since the run began), so that a slow
            /// plant, whose local searches take many seconds each, stops as soon as a fast one. 0 (the
            /// default): off. (Missing in a serialised record: 0, the behaviour before this option
            /// existed; not written when 0, so job ids without it do not change.)
            #[serde(default, with = "serde_f64_or_string", skip_serializing_if = "is_zero_f64")]
            stall_cpu: f64 = 0.0,
                key layered, flag "--stall-cpu",
                accepts "finite, ≥ 0 (0: off)",
                check |v: &f64| require(v.is_finite() && *v >= 0.0, || {
                    format!("must be finite and >= 0 CPU seconds (0: off), got {v}")
                }),
                doc "stall rule in CPU time: stop after this many CPU seconds without improvement (0: off)";
            /// Spend the budget: when a budget bounds the run (`cpumax` finite, `maxevals` or
            /// `max_starts` set), the stall rule does not end it once a stable point is known; the
            /// continued search goes on until the budget ends it. The stall rule still ends runs without
            /// any budget. false: the stall rule ends bounded runs too. (Missing in a serialised record:
            /// false, the behaviour before this option existed; not written when false.)
            #[serde(default, skip_serializing_if = "is_false")]
            spend_budget: bool = true,
                key layered, flag "--stop-on-stall",
                accepts "true, false",
                check any_value,
                doc "a bounded job searches until its budget ends it (false: the stall rule ends it too)";
            /// Resume a cut local search: when the f_h local search that produced the best point ended
            /// on `maxit` (not at a minimiser), the next continued start is that point itself, with a
            /// fresh BFGS (the first starts are unchanged). (Missing in a serialised record: false, the
            /// behaviour before this option existed; not written when false.)
            #[serde(default, skip_serializing_if = "is_false")]
            continue_at_maxit: bool = true,
                key layered, flag "--no-continue-at-maxit",
                accepts "true, false",
                check any_value,
                doc "resume the best point's local search when maxit cut it";
            /// BFGS iteration limit of the continued search's f_h local searches (HIFOO's first starts
            /// and every stabilisation keep `maxit`); 0: `maxit`. Local searches on many variables are
            /// cut by HIFOO's 1000 iterations (Enns n_K = 8, 81 variables); on small plants they end at
            /// a minimiser long before either limit, so the option changes nothing there. (Missing in a
            /// serialised record: 0, the behaviour before this option existed; not written when 0.)
            #[serde(default, skip_serializing_if = "is_zero")]
            continued_maxit: usize = $crate::design::DEFAULT_CONTINUED_MAXIT,
                key layered, flag "--continued-maxit",
                accepts format!("0..={} (0: maxit)", $crate::design::MAX_ITERATIONS),
                check |v: &usize| iterations_at_most_max(*v, Some("maxit")),
                doc "BFGS iterations per local search of the continued search (HIFOO's first starts keep maxit)";
            /// Restart period of every BFGS run (`optim::BfgsOptions::restart_every`): after every
            /// `bfgs_restart` iterations the inverse-Hessian approximation is set back to the
            /// identity and the run goes on from its point (docs/ALGORITHMS.md §7.1); 0: never, as
            /// HIFOO. (Missing in a serialised record: 0, the behaviour before this option existed;
            /// not written when 0.)
            #[serde(default, skip_serializing_if = "is_zero")]
            bfgs_restart: usize = $crate::design::DEFAULT_BFGS_RESTART,
                key layered, flag "--bfgs-restart",
                accepts format!("0..={} (0: never)", $crate::design::MAX_ITERATIONS),
                check |v: &usize| iterations_at_most_max(*v, Some("never")),
                doc "BFGS restarts its inverse Hessian at the identity every this many iterations (0: never)";
            /// Give the unused part of the gradient-sampling reserve back to the search: gradient
            /// sampling runs on the incumbent where HIFOO's search runs it (after the `nrand` first
            /// starts; the incumbent is then HIFOO's result) and whenever the search's share of a budget
            /// is spent; the reserve becomes twice what it took (at most the first 10 %), and gradient
            /// sampling runs again at the end only if the incumbent changed. false: 10 % of each budget
            /// is kept, and gradient sampling runs once, at the end.
            /// (Missing in a serialised record: false, the behaviour before this option existed; not
            /// written when false.)
            #[serde(default, skip_serializing_if = "is_false")]
            return_gs_reserve: bool = true,
                key layered, flag "--keep-gs-reserve",
                accepts "true, false",
                check any_value,
                doc "give what gradient sampling did not need of its 10 % back to the search";
            /// Refine near-misses: an f_h local search of the continued search that ends uncertified
            /// (dnorm > `normtol`) at most a relative `refine_rtol` above the incumbent gets gradient
            /// sampling from its end point (with `gradient_sampling`), so that its basin is judged by a
            /// refined value, as the incumbent's is (the `design::search` module docs). 0 (the default): none. (Missing
            /// in a serialised record: 0, the behaviour before this option existed; not written when 0.)
            #[serde(default, with = "serde_f64_or_string", skip_serializing_if = "is_zero_f64")]
            refine_rtol: f64 = $crate::design::DEFAULT_REFINE_RTOL,
                key layered, flag "--refine-rtol",
                accepts "finite, ≥ 0 (0: none)",
                check |v: &f64| require(v.is_finite() && *v >= 0.0, || {
                    format!("must be finite and >= 0 (0: none), got {v}")
                }),
                doc "gradient sampling on uncertified local searches at most this relative amount above the best point";
            /// Largest number of local searches (first starts included); `None`: no limit.
            #[serde(default, skip_serializing_if = "Option::is_none")]
            max_starts: Option<usize> = None,
                key layered, flag "--max-starts",
                accepts "≥ 1",
                check optional_limit,
                doc "local searches per job, first starts included (deterministic)";
            /// Relative sizes r of the basin-hopping perturbations x* + ξ ∘ (‖x*‖·r), ξ ~ N(0, I), of the
            /// best point x* (the same form as the perturbations of an initial controller). The
            /// continued search cycles through one perturbation per size, then one fresh random start.
            /// Empty: random starts only. (Missing in a serialised record: empty.)
            #[serde(default, with = "serde_vec_f64_or_string")]
            hop_scales: Vec<f64> = $crate::design::DEFAULT_HOP_SCALES.to_vec(),
                key layered, flag "--hop-scales",
                accepts "each finite, > 0 ([]: random restarts only)",
                check |v: &Vec<f64>| match first_not_above(v, 0.0) {
                    Some(bad) => Err(format!("every scale must be finite and > 0, got {bad}")),
                    None => Ok(()),
                },
                doc "basin-hopping perturbation sizes, relative to the best point";
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
            random_scales: Vec<f64> = $crate::design::DEFAULT_RANDOM_SCALES.to_vec(),
                key layered, flag "--random-scales",
                accepts "at least one; each finite, > 0",
                check |v: &Vec<f64>| {
                    if v.is_empty() {
                        return Err("must have at least one scale (e.g. [1] for standard-normal starts only)".into());
                    }
                    match first_not_above(v, 0.0) {
                        Some(bad) => Err(format!("every scale must be finite and > 0, got {bad}")),
                        None => Ok(()),
                    }
                },
                doc "scales σ of the continued search's random starts σ·N(0, I), used in turn";
            /// Make the open-loop start K = 0 (`design::starts::open_loop_controller`) one more first
            /// start, after the `nrand` starts and before the central-controller starts. (Missing in a
            /// serialised record: false; not written when false.)
            #[serde(default, skip_serializing_if = "is_false")]
            open_loop_start: bool = true,
                key layered, flag "--no-open-loop-start",
                accepts "true, false",
                check any_value,
                doc "one more first start: K = 0 (Bk, Ck, Dk = 0, Ak stable diagonal)";
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
            variable_scaling: $crate::design::VariableScaling = $crate::design::VariableScaling::Alternate,
                key layered, flag "--variable-scaling",
                accepts "\"off\", \"alternate\", \"always\" (false, true: off, always)",
                check any_value,
                doc "which local searches run in variables scaled by the plant's channel sizes";
            /// Levels γ = f·γ_opt (factors f > 1 of the full-order optimum) of the reduced-order
            /// central-controller starts: for each f, the full-order H∞ central controller at that level,
            /// reduced to `order` by balanced truncation, is one more first start, made after the `nrand`
            /// starts (`design::central_start`). Empty: none. (Missing in a serialised record: empty.)
            /// Not written when empty, so a record of a build without central starts reads and rewrites
            /// identically (and keeps its job id).
            #[serde(default, with = "serde_vec_f64_or_string", skip_serializing_if = "Vec::is_empty")]
            central_gammas: Vec<f64> = $crate::design::DEFAULT_CENTRAL_GAMMAS.to_vec(),
                key layered, flag "--central-gammas",
                accepts "each finite, > 1 ([]: none)",
                check |v: &Vec<f64>| match first_not_above(v, 1.0) {
                    Some(bad) => Err(format!("every factor of gamma_opt must be finite and > 1, got {bad}")),
                    None => Ok(()),
                },
                doc "reduced-order central-controller starts at f·γ_opt";
            /// Strong stabilisation or plain H∞.
            objective: $crate::design::ObjectiveKind = $crate::design::ObjectiveKind::Strong,
                key layered, flag "--no-strong",
                accepts "\"strong\", \"plain\"",
                check any_value,
                doc "\"strong\": max(‖Tzw‖∞, ε‖K‖∞), K stable; \"plain\": ‖Tzw‖∞ only";
            /// Relative tolerance of the H∞ norm computation.
            #[serde(with = "serde_f64_or_string")]
            hinf_tol: f64 = $crate::lti::DEFAULT_HINF_TOL,
                key layered, flag "",
                accepts format!("in [{:e}, 1)", $crate::lti::MIN_HINF_TOL),
                check |v: &f64| {
                    let min = $crate::lti::MIN_HINF_TOL;
                    require(v.is_finite() && *v >= min && *v < 1.0, || {
                        format!("must be in [{min:e}, 1), got {v}")
                    })
                },
                doc "relative tolerance of the H∞ norm";
            /// BFGS iteration limit per start and phase (HIFOO `maxit`, 1000).
            maxit: usize = 1000,
                key layered, flag "",
                accepts format!("1..={}", $crate::design::MAX_ITERATIONS),
                check |v: &usize| require((1..=$crate::design::MAX_ITERATIONS).contains(v), || {
                    format!("must be in 1..={}, got {v}", $crate::design::MAX_ITERATIONS)
                }),
                doc "BFGS iterations per start and phase";
            /// Stop BFGS when the certificate dnorm ≤ normtol (HIFOO passes 1e-3); each gradient
            /// is taken in the unit of the term that set f at its point (ε for the controller's
            /// term of the strong objective, docs/ALGORITHMS.md §7.3).
            #[serde(with = "serde_f64_or_string")]
            normtol: f64 = 1e-3,
                key layered, flag "",
                accepts "finite, ≥ 0",
                check |v: &f64| require(v.is_finite() && *v >= 0.0, || {
                    format!("must be finite and >= 0, got {v}")
                }),
                doc "certificate tolerance (dnorm ≤ normtol stops)";
            /// Gradient-bundle radius (HIFOO passes 1e-3).
            #[serde(with = "serde_f64_or_string")]
            evaldist: f64 = 1e-3,
                key layered, flag "",
                accepts "finite, ≥ 0",
                check |v: &f64| require(v.is_finite() && *v >= 0.0, || {
                    format!("must be finite and >= 0, got {v}")
                }),
                doc "radius of the gradient bundle";
            /// Run gradient sampling after BFGS (HIFOO `fast = 0`).
            gradient_sampling: bool = true,
                key layered, flag "",
                accepts "true, false",
                check any_value,
                doc "gradient sampling after BFGS from the best point";
            /// Iteration limit of each gradient-sampling run (HIFOO caps HANSO 2.0's gradient sampling
            /// at 100 iterations per radius, 3 radii; each iteration costs 2·nvar evaluations).
            gradsamp_maxit: usize = 300,
                key "", flag "",
                accepts format!("0..={}", $crate::design::MAX_ITERATIONS),
                check |v: &usize| iterations_at_most_max(*v, None),
                doc "iterations of each gradient-sampling run (HIFOO's 3 radii × 100)";
        }
    };
}
pub(crate) use design_option_table;

/// The campaign key of an option table entry: its field name for `key layered`.
macro_rules! option_key {
    (layered, $field:ident) => {
        stringify!($field)
    };
    ($key:literal, $field:ident) => {
        $key
    };
}

/// The option table's callback that defines [`DesignOptions`], its `Default`, its per-option
/// checks and [`DesignOptions::table`].
macro_rules! define_design_options {
    ({} $(
        $(#[$attr:meta])*
        $field:ident : $ty:ty = $default:expr,
            key $key:tt, flag $flag:literal,
            accepts $accepts:expr,
            check $check:expr,
            doc $doc:literal;
    )*) => {
        /// Options of a design ([`crate::design::Design`]). Defaults follow HIFOO 3.5 (docs/ALGORITHMS.md §8),
        /// except that the search goes on after HIFOO's starts (`stall_starts`, `hop_scales`).
        /// Defined by the option table (`design_option_table!`, [`DesignOptions::table`]).
        #[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
        #[serde(default, deny_unknown_fields)]
        pub struct DesignOptions {
            $(
                $(#[$attr])*
                pub $field: $ty,
            )*
        }

        impl Default for DesignOptions {
            fn default() -> Self {
                DesignOptions { $($field: $default,)* }
            }
        }

        impl DesignOptions {
            /// Every option's own check, in the table's order: the first option whose value is
            /// not accepted, and why. Checks across options and against the plant are
            /// [`crate::design::validate`]'s.
            pub(crate) fn check_each(&self) -> Result<(), (&'static str, String)> {
                $(
                    let check: fn(&$ty) -> Result<(), String> = $check;
                    check(&self.$field).map_err(|problem| (stringify!($field), problem))?;
                )*
                Ok(())
            }

            /// The option table: every option in field order with its campaign key, flag,
            /// default, accepted values and one line on what it does (campaigns/FORMAT.md
            /// prints it).
            pub fn table() -> Vec<OptionRow> {
                let d = DesignOptions::default();
                vec![$(
                    OptionRow {
                        name: stringify!($field),
                        key: option_key!($key, $field),
                        flag: $flag,
                        default: OptionValue::show(&d.$field),
                        accepts: ($accepts).to_string(),
                        doc: $doc,
                    },
                )*]
            }
        }
    };
}

design_option_table!(define_design_options {});

/// [`DesignOptions::table`] as the Markdown table of campaigns/FORMAT.md.
pub fn options_markdown() -> String {
    let cell = |s: &str| if s.is_empty() { "—".to_string() } else { format!("`{s}`") };
    let mut out = String::from("| option | campaign key | `campaign design` | default | accepted | what |\n");
    out += "|---|---|---|---|---|---|\n";
    for r in DesignOptions::table() {
        out += &format!(
            "| `{}` | {} | {} | `{}` | {} | {} |\n",
            r.name,
            cell(r.key),
            cell(r.flag),
            r.default,
            r.accepts,
            r.doc
        );
    }
    out
}

impl DesignOptions {
    /// The options of a JSON object that names some options (the others at their defaults,
    /// [`DesignOptions::default`]), as a program driving the design from outside gives them (the
    /// Python package). Not plain deserialisation: a *record* lacking a field reads it as the
    /// behaviour before the field existed (e.g. `stall_starts` 0, no hops), which is right for an
    /// old journal line and wrong for a caller who left the option out to get the default.
    /// An unknown name is an error, as in a campaign file.
    pub fn from_json_over_defaults(given: serde_json::Map<String, serde_json::Value>) -> serde_json::Result<Self> {
        let mut all = match serde_json::to_value(DesignOptions::default())? {
            serde_json::Value::Object(m) => m,
            _ => serde_json::Map::new(),
        };
        all.extend(given);
        serde_json::from_value(serde_json::Value::Object(all))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Options left out of the object are the defaults, not a record's "missing field" values
    /// (stall_starts 0, no hops, no open-loop or central starts); given ones are taken as given.
    #[test]
    fn options_over_the_defaults() {
        let none = DesignOptions::from_json_over_defaults(serde_json::Map::new()).unwrap();
        assert_eq!(none, DesignOptions::default());
        let record = serde_json::from_str::<DesignOptions>("{}").unwrap();
        assert_ne!(record.stall_starts, none.stall_starts, "the test must show the difference");
        let given = serde_json::json!({"order": 2, "stall_starts": 5, "hop_scales": []});
        let serde_json::Value::Object(given) = given else { unreachable!() };
        let o = DesignOptions::from_json_over_defaults(given).unwrap();
        let want = DesignOptions { order: 2, stall_starts: 5, hop_scales: vec![], ..DesignOptions::default() };
        assert_eq!(o, want);
        let serde_json::Value::Object(bad) = serde_json::json!({"stall_start": 5}) else { unreachable!() };
        assert!(DesignOptions::from_json_over_defaults(bad).unwrap_err().to_string().contains("stall_start"));
    }

    /// The job ids of the results already journaled are hashes of this form: it must not change.
    /// The options of a journaled job of campaigns/strong-stab.toml (results/strong-stab), as
    /// 5d54f9e wrote them.
    #[test]
    fn the_serialised_form_is_unchanged() {
        let o = DesignOptions {
            eps: 0.01,
            cpumax: 300.0,
            stall_starts: 10,
            stall_rtol: 1e-4,
            spend_budget: false,
            bfgs_restart: 0, // an option its build did not have: 0, its behaviour then
            ..DesignOptions::default()
        };
        let want = r#"{"order":1,"eps":0.01,"seed":0,"cpumax":300.0,"nrand":3,"stall_starts":10,"stall_rtol":0.0001,"continue_at_maxit":true,"continued_maxit":3000,"return_gs_reserve":true,"hop_scales":[0.01,0.1,1.0],"random_scales":[1.0,0.1,0.01],"open_loop_start":true,"variable_scaling":"alternate","central_gammas":[1.1,2.0],"objective":"strong","hinf_tol":1e-10,"maxit":1000,"normtol":0.001,"evaldist":0.001,"gradient_sampling":true,"gradsamp_maxit":300}"#;
        assert_eq!(serde_json::to_string(&o).unwrap(), want);
        let back: DesignOptions = serde_json::from_str(want).unwrap();
        assert_eq!(back, o);
    }

    /// Every default passes its own check, and every option is in the table once.
    #[test]
    fn the_table_is_consistent() {
        assert_eq!(DesignOptions::default().check_each(), Ok(()));
        let t = DesignOptions::table();
        let json = serde_json::to_value(DesignOptions {
            maxevals: Some(1),
            max_starts: Some(1),
            refine_rtol: 0.1,
            stall_cpu: 1.0,
            ..Default::default()
        })
        .unwrap();
        let fields: Vec<&str> = json.as_object().unwrap().keys().map(|k| k.as_str()).collect();
        let mut names: Vec<&str> = t.iter().map(|r| r.name).collect();
        names.sort_unstable();
        assert_eq!(names, fields, "the table lists every serialised field once");
        for r in &t {
            assert!(!r.doc.is_empty() && !r.accepts.is_empty(), "{r:?}");
        }
    }

    /// campaigns/FORMAT.md's option table is [`options_markdown`], so that its defaults, keys,
    /// flags and ranges are the code's.
    #[test]
    fn format_md_has_the_option_table() {
        let doc = std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/campaigns/FORMAT.md")).unwrap();
        let want = options_markdown();
        assert!(
            doc.contains(&want),
            "campaigns/FORMAT.md should hold the option table of DesignOptions::table(), exactly:\n\n{want}"
        );
    }

    #[test]
    fn a_bad_value_is_named_with_the_old_message() {
        let bad = DesignOptions { nrand: 0, ..Default::default() };
        assert_eq!(bad.check_each(), Err(("nrand", format!("must be in 1..={MAX_NRAND}, got 0"))));
        let bad = DesignOptions { random_scales: vec![], ..Default::default() };
        assert_eq!(bad.check_each().unwrap_err().0, "random_scales");
        let bad = DesignOptions { central_gammas: vec![1.1, 1.0], ..Default::default() };
        assert_eq!(
            bad.check_each(),
            Err(("central_gammas", "every factor of gamma_opt must be finite and > 1, got 1".to_string()))
        );
    }
}
