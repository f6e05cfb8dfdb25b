//! Command-line interface (clap) of the `campaign` binary, whose `main` is [`main`]. Each
//! subcommand lives in its own file; errors become `anyhow` only here, at the edge, and map to
//! documented exit codes. It sits on top of every layer and nothing in the library uses it; it is
//! in the library (not in src/main.rs) so that the machinery tests' binary with the fake runner
//! (examples/fake_campaign.rs, `main_with`, with the `test-support` feature) is the same command
//! line.
//!
//! Exit codes: 0 success, 1 error, 2 usage error (clap), 3 some campaign jobs failed,
//! 4 not stabilised (`design` found no (strongly) stabilising controller; `check`: the closed
//! loop is unstable), 130 interrupted by Ctrl-C (SIGINT), 143 by SIGTERM, 129 by SIGHUP.

use std::process::ExitCode;

use clap::{Parser, Subcommand};

#[cfg(feature = "test-support")]
use crate::campaign::FakeRunner;
use crate::campaign::JobRunner;

mod campaign;
mod check;
mod compare;
mod design;
mod export;
mod plants;
mod signals;

/// hinfix: fixed-order H∞ controller design with strong stabilisation (HIFOO method) and a
/// benchmark-campaign runner.
#[derive(Parser, Debug)]
#[command(name = "campaign", version, about, long_about = None)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[cfg(test)]
impl Cli {
    /// The arguments of a `design` command line.
    fn design_args(&self) -> Option<&design::DesignArgs> {
        match &self.command {
            Command::Design(a) => Some(a),
            _ => None,
        }
    }
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Run a campaign file (plants × orders × ε × seeds), resuming where it stopped.
    Run(campaign::RunArgs),
    /// Report done/remaining jobs of a campaign file.
    Status(campaign::StatusArgs),
    /// Reduce a campaign's journal(s) to best.csv, tables.tex and compare.csv/.tex.
    Report(campaign::ReportArgs),
    /// Summarise one MCAP trace file.
    Trace(campaign::TraceArgs),
    /// Draw a campaign's figures (γ vs order, convergence, σ-plots) as PNG and SVG.
    Plot(campaign::PlotArgs),
    /// Compare methods (results folders, CSV files of published values) entry by entry: tables,
    /// wins/ties/losses, performance profiles.
    Compare(compare::CompareArgs),
    /// Print a controller as MATLAB or python-control code (sign convention u = K y).
    Export(export::ExportArgs),
    /// List the benchmark plants shipped in plants/.
    Plants(plants::PlantsArgs),
    /// Show one plant in detail.
    Plant(plants::PlantArgs),
    /// Check a controller on a plant: stability, ‖Tzw‖∞ and peak frequency, ‖K‖∞.
    Check(check::CheckArgs),
    /// Design one fixed-order controller (strong stabilisation by default).
    Design(Box<design::DesignArgs>),
}

/// Exit code of a run in which some jobs failed.
pub const EXIT_JOBS_FAILED: u8 = 3;
/// Exit code after an interrupt.
pub const EXIT_INTERRUPTED: u8 = 130;
/// Exit code of `design` when no (strongly) stabilising controller was found, and of `check`
/// when the closed loop is unstable.
pub const EXIT_NOT_STABILISED: u8 = 4;
/// Exit code of `design` when the controller stabilises but a plant's bound w·g ≤ b does not
/// hold (status `bound_violated`; `--json` says which plant in its `plants[].bound_met`).
pub const EXIT_BOUND_VIOLATED: u8 = 5;

/// A number for people: fixed-point with `prec` decimals in [1e-3, 1e6), scientific outside
/// (ε = 1e308 must not print a 309-digit objective).
pub(crate) fn fmt_num(x: f64, prec: usize) -> String {
    if x.is_finite() && x != 0.0 && !(1e-3..1e6).contains(&x.abs()) {
        format!("{x:.prec$e}")
    } else {
        format!("{x:.prec$}")
    }
}

/// Parses the command line and runs it: the `campaign` binary.
pub fn main() -> ExitCode {
    run_command_line(None)
}

/// [`main`], with the campaign jobs run by `fake` instead of the design when it is given: the
/// test-only binary examples/fake_campaign.rs, which the machinery tests (scheduling, journal,
/// kill -9, resume) run so that a campaign takes seconds. Its jobs carry
/// [`RunnerTag::Fake`](crate::campaign::RunnerTag::Fake) in their ids and `"runner": "fake"` in
/// their records, so they never pass for real ones. Only with the `test-support` feature, which
/// `cargo build` and `cargo install` leave off: the `campaign` binary has no way to fake
/// results.
#[cfg(feature = "test-support")]
pub fn main_with(fake: Option<FakeRunner>) -> ExitCode {
    run_command_line(fake.map(|f| Box::new(f) as Box<dyn JobRunner>))
}

/// [`main`], with the campaign jobs run by `fake` (with [`RunnerTag::Fake`](crate::campaign::RunnerTag::Fake)
/// ids) when it is given.
fn run_command_line(fake: Option<Box<dyn JobRunner>>) -> ExitCode {
    crate::malloc_tuning::keep_freed_memory();
    let cli = Cli::parse();
    if !matches!(cli.command, Command::Run(_) | Command::Design(_) | Command::Plot(_)) {
        signals::end_quietly_on_closed_stdout();
    }
    let result = match cli.command {
        Command::Run(a) => campaign::run(a, fake),
        Command::Status(a) => campaign::status(a, fake),
        Command::Report(a) => campaign::report(a, fake),
        Command::Trace(a) => campaign::trace(a),
        Command::Plot(a) => campaign::plot(a, fake),
        Command::Compare(a) => compare::run(a),
        Command::Export(a) => export::run(a),
        Command::Plants(a) => plants::list(a),
        Command::Plant(a) => plants::show(a),
        Command::Check(a) => check::run(a),
        Command::Design(a) => design::run(*a),
    };
    match result {
        Ok(code) => code,
        Err(e) => {
            eprintln!("error: {}", crate::campaign::for_terminal(&error_text(&e)));
            ExitCode::FAILURE
        }
    }
}

/// Prints `text` on stdout for the commands that write files (`run`, `design`, `plot`, which keep
/// the default SIGPIPE handling off, [`signals::end_quietly_on_closed_stdout`]): a closed stdout
/// (`campaign design … | head -3`) drops the rest of the text, as the reader asked, where
/// `print!` panicked with "failed printing to stdout" after the files were written. Any other
/// write error is returned.
pub(crate) fn print_out(text: &str) -> std::io::Result<()> {
    use std::io::Write;
    let mut out = std::io::stdout().lock();
    match out.write_all(text.as_bytes()).and_then(|()| out.flush()) {
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        r => r,
    }
}

/// An error and its causes, each cause left out when the text before it already contains it
/// (many errors print their source in their own message: `{e:#}` alone repeated it).
fn error_text(e: &anyhow::Error) -> String {
    let mut text = String::new();
    for cause in e.chain() {
        let c = cause.to_string();
        if !text.contains(&c) {
            if !text.is_empty() {
                text.push_str(": ");
            }
            text.push_str(&c);
        }
    }
    text
}

#[cfg(test)]
mod tests {
    use super::fmt_num;

    #[test]
    fn error_causes_are_not_repeated() {
        let io = std::io::Error::new(std::io::ErrorKind::NotFound, "No such file");
        let e = anyhow::Error::new(io).context("x.mcap: No such file").context("reading the trace");
        assert_eq!(super::error_text(&e), "reading the trace: x.mcap: No such file");
    }

    /// A negative number given to a numeric flag is that flag's value, for its own check to
    /// answer ("--rtol must be in [0, 1), found -1"), not clap's "unexpected argument '-1'".
    #[test]
    fn numeric_flags_take_negative_values() {
        use clap::Parser;
        for argv in [
            &["campaign", "compare", "--out", "o", "--rtol", "-1", "a=x", "b=y"][..],
            &["campaign", "export", "--results", "r", "--plant", "P", "--order", "-1"][..],
            &["campaign", "design", "--plant", "P", "--order", "1", "--out", "K.json", "--eps", "-1"][..],
        ] {
            if let Err(e) = super::Cli::try_parse_from(argv) {
                // export's --order is a usize: clap's own "invalid value '-1'" names the flag
                let e = e.to_string();
                assert!(!e.contains("unexpected argument") && e.contains("-1"), "{argv:?}: {e}");
            }
        }
    }

    #[test]
    fn numbers_stay_short() {
        assert_eq!(fmt_num(0.123456789, 6), "0.123457");
        assert_eq!(fmt_num(1e308, 6), "1.000000e308");
        assert_eq!(fmt_num(2.5e-9, 3), "2.500e-9");
        assert_eq!(fmt_num(0.0, 2), "0.00");
        assert_eq!(fmt_num(f64::INFINITY, 6), "inf");
        assert!(fmt_num(-1.7e300, 6).len() < 20);
    }
}
