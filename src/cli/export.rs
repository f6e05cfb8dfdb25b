//! `campaign export --controller K.json|K.mat --to matlab|python`: prints the controller as
//! ready-to-paste MATLAB (`K = ss(AK,BK,CK,DK)`) or python-control (`K = control.ss(...)`) code,
//! with the sign convention u = K y stated in its comments (see `crate::lti::export`).
use std::path::PathBuf;
use std::process::ExitCode;

use crate::lti::export::{export_code, ExportTarget};
use crate::lti::Controller;

/// Target language.
#[derive(clap::ValueEnum, Clone, Copy, Debug)]
pub enum Target {
    /// MATLAB / Octave: `K = ss(AK, BK, CK, DK)`.
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
    #[arg(long)]
    pub controller: PathBuf,
    /// Language of the printed code.
    #[arg(long, value_enum)]
    pub to: Target,
}

pub fn run(a: ExportArgs) -> anyhow::Result<ExitCode> {
    let k = Controller::load(&a.controller)?;
    let target = match a.to {
        Target::Matlab => ExportTarget::Matlab,
        Target::Python => ExportTarget::Python,
    };
    print!("{}", export_code(&k, target, &a.controller.display().to_string()));
    Ok(ExitCode::SUCCESS)
}
