//! `campaign plants` and `campaign plant NAME`.
use std::process::ExitCode;

/// Arguments of `campaign plants`.
#[derive(clap::Args, Debug)]
pub struct PlantsArgs {}
/// Arguments of `campaign plant`.
#[derive(clap::Args, Debug)]
pub struct PlantArgs {
    /// Plant name or path.
    pub name: String,
    /// Print JSON.
    #[arg(long)]
    pub json: bool,
}

pub fn list(_a: PlantsArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("not yet")
}
pub fn show(_a: PlantArgs) -> anyhow::Result<ExitCode> {
    anyhow::bail!("not yet")
}
