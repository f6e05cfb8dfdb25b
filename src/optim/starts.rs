//! Random starting points of a multi-start search.

use rand::RngCore;
use rand_distr::{Distribution, StandardNormal};

/// `count` standard-normal starting points in ℝ^nvar (HANSO's default x0 = randn(nvar, count)).
pub fn random_starts(nvar: usize, count: usize, rng: &mut dyn RngCore) -> Vec<Vec<f64>> {
    (0..count).map(|_| (0..nvar).map(|_| StandardNormal.sample(&mut *rng)).collect()).collect()
}
