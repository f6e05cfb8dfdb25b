//! The optimiser options of the two phases of a HIFOO run (docs/ALGORITHMS.md §8.3, §8.4): BFGS on
//! f_s = max(α(Acl), ε·α(Ak)) with fvalquit = 0 (stop as soon as Acl and Ak are Hurwitz), BFGS
//! on f_h = max(‖Tzw‖∞, ε·‖K‖∞) with fvalquit = −∞, and gradient sampling (HANSO 2.0's rule: only
//! from an uncertified point). How they are sequenced is in [`super::search`].

use crate::optim::{BfgsOptions, GradSampOptions, OptimError};

use super::options::DesignOptions;
use super::outcome::DesignError;

/// BFGS options of both phases from the design options (fvalquit is set per phase; the restart
/// period `bfgs_restart` serves both).
pub(crate) fn bfgs_options(opts: &DesignOptions, fvalquit: f64) -> BfgsOptions {
    BfgsOptions {
        normtol: opts.normtol,
        evaldist: opts.evaldist,
        maxit: opts.maxit,
        fvalquit,
        restart_every: opts.bfgs_restart,
        ..Default::default()
    }
}

/// BFGS options of an f_h local search (fvalquit = −∞): `maxit`, or `continued_maxit` (0: `maxit`)
/// for a local search of the continued search.
pub(crate) fn perf_bfgs_options(opts: &DesignOptions, continued: bool) -> BfgsOptions {
    let maxit = if continued && opts.continued_maxit > 0 { opts.continued_maxit } else { opts.maxit };
    BfgsOptions { maxit, ..bfgs_options(opts, f64::NEG_INFINITY) }
}

/// Gradient-sampling options of both phases.
pub(crate) fn gradsamp_options(opts: &DesignOptions, fvalquit: f64) -> GradSampOptions {
    GradSampOptions { maxit: opts.gradsamp_maxit, fvalquit, only_if_uncertified: true, ..Default::default() }
}

pub(crate) fn optim_error(e: OptimError) -> DesignError {
    match e {
        OptimError::Options { field, value, range } => {
            DesignError::Options { field, problem: format!("{value} is out of range (must be {range})") }
        }
        other => DesignError::Numerical(other),
    }
}
