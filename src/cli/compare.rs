//! `campaign compare LABEL=PATH LABEL=PATH… --out DIR`: methods compared over their entries
//! (`crate::campaign::methods`); this file only parses the arguments and prints the summary.
use std::path::PathBuf;
use std::process::ExitCode;

use crate::campaign::{compare_methods, load_sources, DEFAULT_RTOL};

/// Arguments of `campaign compare`.
#[derive(clap::Args, Debug)]
pub struct CompareArgs {
    /// Two or more sources `LABEL=PATH`: a results folder (its best.csv, CPU seconds from its
    /// journals) or a CSV file with columns plant, order, objective, gamma (optional cpu_s,
    /// stable, plant_fingerprint); format in campaigns/FORMAT.md.
    #[arg(value_name = "LABEL=PATH", num_args = 2.., required = true)]
    pub sources: Vec<String>,
    /// Output folder: entries.csv/.tex, summary.csv/.txt, profile_gamma.svg/.png (and
    /// profile_cpu.svg/.png when every source has CPU seconds).
    #[arg(long, value_name = "DIR")]
    pub out: PathBuf,
    /// Relative tolerance of a tie (and of "best" in the tables).
    #[arg(long, value_name = "RTOL", default_value_t = DEFAULT_RTOL, allow_hyphen_values = true)]
    pub rtol: f64,
}

/// `campaign compare`.
pub fn run(a: CompareArgs) -> anyhow::Result<ExitCode> {
    let sources = load_sources(&a.sources)?;
    let outcome = compare_methods(&sources, a.rtol, &a.out)?;
    print!("{}", outcome.text);
    for f in &outcome.files {
        println!("wrote {}", crate::campaign::for_terminal(&f.display().to_string()));
    }
    Ok(ExitCode::SUCCESS)
}
