//! `campaign export (--controller K.json|K.mat | --results DIR (--plant P --order K
//! [--objective strong|plain] | --job ID)) [--to matlab|python]`: prints the controller as
//! ready-to-paste MATLAB (`K = ss(AK,BK,CK,DK)`) or python-control (`K = control.ss(...)`) code,
//! with the sign convention u = K y stated in its comments (see `crate::lti::export`). From a
//! results folder it takes the best job of a `best.csv` entry, or a job by id (a unique prefix
//! will do), from the folder's journals. `--to` defaults to MATLAB.
use std::path::PathBuf;
use std::process::ExitCode;

use crate::campaign::{find_record, Entry};
use crate::lti::export::{export_code, ExportTarget};
use crate::lti::Controller;

/// Target language.
#[derive(clap::ValueEnum, Clone, Copy, Debug, Default)]
pub enum Target {
    /// MATLAB / Octave: `K = ss(AK, BK, CK, DK)`.
    #[default]
    Matlab,
    /// Python with numpy and python-control: `K = control.ss(AK, BK, CK, DK)`.
    Python,
}

/// Arguments of `campaign export`.
#[derive(clap::Args, Debug)]
#[command(after_help = "Sign convention: the controller is positive feedback, u = K y \
(xk' = AK xk + BK y, u = CK xk + DK y). MATLAB's lft(P, K) and python-control's P.lft(K) keep it; \
feedback() is negative by default in both, so use feedback(G, K, +1) / control.feedback(G, K, sign=1), or -K.")]
pub struct ExportArgs {
    /// Controller file: JSON {AK, BK, CK, DK} or MATLAB .mat.
    #[arg(long, required_unless_present = "results", conflicts_with = "results")]
    pub controller: Option<PathBuf>,
    /// A campaign's results folder (`results/<name>`, holding runs*.jsonl and best.csv): the
    /// controller of the best job of --plant and --order, or of the job --job.
    #[arg(long, value_name = "DIR")]
    pub results: Option<PathBuf>,
    /// With --results: the plant as best.csv names it.
    #[arg(long, requires_all = ["results", "order"], conflicts_with = "job")]
    pub plant: Option<String>,
    /// With --results and --plant: the controller order n_K.
    #[arg(long, requires = "plant", allow_hyphen_values = true)]
    pub order: Option<usize>,
    /// With --plant: the objective of the row (default: the strong row when the campaign ran
    /// both).
    #[arg(long, value_parser = ["strong", "plain"], requires = "plant")]
    pub objective: Option<String>,
    /// With --results: a job id (or a unique prefix of one).
    #[arg(long, value_name = "ID", requires = "results")]
    pub job: Option<String>,
    /// Language of the printed code.
    #[arg(long, value_enum, default_value_t)]
    pub to: Target,
}

pub fn run(a: ExportArgs) -> anyhow::Result<ExitCode> {
    let (k, source) = match (&a.controller, &a.results) {
        (Some(path), _) => (Controller::load(path)?, path.display().to_string()),
        (None, Some(dir)) => {
            let entry = match (&a.job, &a.plant, a.order) {
                (Some(id), _, _) => Entry::Job(id.clone()),
                (None, Some(plant), Some(order)) => {
                    Entry::Best { plant: plant.clone(), order, objective: a.objective.clone() }
                }
                _ => anyhow::bail!("--results needs --plant P --order K, or --job ID"),
            };
            let record = find_record(dir, &entry)?;
            let Some(k) = record.controller() else {
                anyhow::bail!("job {} of {} failed: it has no controller", record.job_id.0, dir.display())
            };
            let source = format!(
                "job {} ({}, n_K = {}, {}, eps = {}, seed {}) of {}",
                record.job_id.0,
                record.plant,
                record.order,
                record.options.objective.name(),
                record.eps,
                record.seed,
                dir.display()
            );
            (k.clone(), source)
        }
        (None, None) => anyhow::bail!("give --controller FILE, or --results DIR with --plant and --order or --job"),
    };
    let target = match a.to {
        Target::Matlab => ExportTarget::Matlab,
        Target::Python => ExportTarget::Python,
    };
    print!("{}", export_code(&k, target, &crate::campaign::for_terminal(&source)));
    Ok(ExitCode::SUCCESS)
}
