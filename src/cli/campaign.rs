//! `campaign run | status | report | trace` (lands with the campaign-runner issue).
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `campaign run`.
#[derive(clap::Args, Debug)]
pub struct RunArgs {
    /// Campaign file (TOML).
    pub file: PathBuf,
}
/// Arguments of `campaign status`.
#[derive(clap::Args, Debug)]
pub struct StatusArgs {
    /// Campaign file (TOML).
    pub file: PathBuf,
}
/// Arguments of `campaign report`.
#[derive(clap::Args, Debug)]
pub struct ReportArgs {
    /// Campaign file (TOML).
    pub file: PathBuf,
}
/// Arguments of `campaign trace`.
#[derive(clap::Args, Debug)]
pub struct TraceArgs {
    /// Trace file (.mcap).
    pub file: PathBuf,
}

pub fn run(_a: RunArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`campaign run` is not available yet")
}
pub fn status(_a: StatusArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`campaign status` is not available yet")
}
pub fn report(_a: ReportArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`campaign report` is not available yet")
}
pub fn trace(_a: TraceArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`campaign trace` is not available yet")
}
