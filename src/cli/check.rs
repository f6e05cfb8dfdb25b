//! `campaign check` (lands with the LTI-numerics issue).
use std::path::PathBuf;
use std::process::ExitCode;

/// Arguments of `campaign check`.
#[derive(clap::Args, Debug)]
pub struct CheckArgs {
    /// Plant name (from plants/) or path to a plant JSON file.
    #[arg(long)]
    pub plant: String,
    /// Controller JSON file {AK, BK, CK, DK}.
    #[arg(long)]
    pub controller: PathBuf,
    /// Print machine-readable JSON.
    #[arg(long)]
    pub json: bool,
}

pub fn run(_a: CheckArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`campaign check` is not available yet")
}
