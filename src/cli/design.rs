//! `campaign design` (lands with the design issue).
use std::process::ExitCode;

/// Arguments of `campaign design`.
#[derive(clap::Args, Debug)]
pub struct DesignArgs {
    /// Plant name (from plants/) or path to a plant JSON file.
    #[arg(long)]
    pub plant: String,
}

pub fn run(_a: DesignArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("`campaign design` is not available yet")
}
