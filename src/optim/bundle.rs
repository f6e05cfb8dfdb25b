//! The gradient bundle and the local optimality certificate (HANSO 2.x; docs/ALGORITHMS.md §7.3).
//!
//! BFGS keeps the gradients of consecutive iterates as long as each step is ≤ `evaldist`
//! (a longer step resets the bundle to the new point), at most `ngrad` of them, newest first.
//! d = the smallest vector in their convex hull (the simplex QP of [`qp`](super::qp)) approximates
//! the minimum-norm element of the Clarke r-subdifferential with r ≈ evaldist, so
//!
//! * dnorm = ‖d‖ small **and** evaldist = maxⱼ ‖x − Xⱼ‖ small ⇒ x is close to a Clarke stationary
//!   point ("the smaller dnorm and evaldist, the more likely x is an approximate stationary point").
//!
//! `evaldist` in the result is the actual largest distance, which may exceed the option of that
//! name because the reset test is on consecutive steps.
//!
//! Each gradient enters the hull in its own unit, g / u with u = [`Objective::gradient_unit`] at
//! its point (1 unless the objective says otherwise): for f = max(f₁, ε·f₂) the hull of
//! {∇f₁, ε∇f₂} has a vector of norm ≤ ε‖∇f₂‖ wherever both terms are near, which an absolute
//! `normtol` would take for stationarity whenever ε is small; the hull of {∇f₁, ∇f₂} contains 0
//! at exactly the same points. The units change the certificate only, never a step.
//!
//! [`Objective::gradient_unit`]: super::objective::Objective::gradient_unit

use super::qp::{min_norm_in_hull, MinNormResult};
use crate::numeric::dot;
use std::collections::VecDeque;

/// Points and their gradients, newest first.
#[derive(Debug, Clone)]
pub(crate) struct GradBundle {
    cap: usize,
    pub(crate) xs: VecDeque<Vec<f64>>,
    pub(crate) gs: VecDeque<Vec<f64>>,
}

pub(crate) fn dist(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(u, v)| (u - v) * (u - v)).sum::<f64>().sqrt()
}

impl GradBundle {
    /// A bundle of (x, g) alone, g in `unit` (module docs).
    pub(crate) fn new(cap: usize, x: &[f64], g: &[f64], unit: f64) -> Self {
        let mut b = GradBundle { cap: cap.max(1), xs: VecDeque::new(), gs: VecDeque::new() };
        b.reset(x, g, unit);
        b
    }

    /// Forget everything but (x, g), g in `unit`.
    pub(crate) fn reset(&mut self, x: &[f64], g: &[f64], unit: f64) {
        self.xs.clear();
        self.gs.clear();
        self.push(x, g, unit);
    }

    /// Prepend (x, g), g in `unit`, dropping the oldest beyond the capacity.
    pub(crate) fn push(&mut self, x: &[f64], g: &[f64], unit: f64) {
        self.xs.push_front(x.to_vec());
        self.gs.push_front(in_unit(g, unit));
        while self.xs.len() > self.cap {
            self.xs.pop_back();
            self.gs.pop_back();
        }
    }

    /// The min-norm element of the hull of the gradients.
    pub(crate) fn min_norm(&self) -> MinNormResult {
        let cols: Vec<&[f64]> = self.gs.iter().map(|g| g.as_slice()).collect();
        min_norm_in_hull(&cols)
    }

    /// dnorm: ‖the min-norm element of the hull‖ (of a single gradient, its norm).
    pub(crate) fn dnorm(&self) -> f64 {
        match self.gs.len() {
            1 => dot(&self.gs[0], &self.gs[0]).sqrt(),
            _ => self.min_norm().dnorm,
        }
    }

    /// maxⱼ ‖x − Xⱼ‖.
    pub(crate) fn evaldist(&self, x: &[f64]) -> f64 {
        self.xs.iter().map(|xj| dist(x, xj)).fold(0.0, f64::max)
    }
}

/// g / `unit` (module docs).
pub(crate) fn in_unit(g: &[f64], unit: f64) -> Vec<f64> {
    if unit == 1.0 {
        g.to_vec()
    } else {
        g.iter().map(|v| v / unit).collect()
    }
}

/// The certificate at (x, ∇f(x)) from gradients `gs` taken at `xs` (HANSO `postprocess`), each
/// gradient in its unit (`units`, module docs; `g` in `unit`): if x is not one of the points,
/// (x, ∇f(x)) is added first. Returns (dnorm, evaldist).
pub(crate) fn certificate_at(
    (x, g, unit): (&[f64], &[f64], f64),
    xs: &[Vec<f64>],
    gs: &[Vec<f64>],
    units: &[f64],
) -> (f64, f64) {
    let mut cols: Vec<Vec<f64>> = gs.iter().zip(units).map(|(v, &u)| in_unit(v, u)).collect();
    if !xs.iter().any(|xj| xj.as_slice() == x) {
        cols.insert(0, in_unit(g, unit));
    }
    let cols: Vec<&[f64]> = cols.iter().map(|v| v.as_slice()).collect();
    let ed = xs.iter().map(|xj| dist(x, xj)).fold(0.0, f64::max);
    (min_norm_in_hull(&cols).dnorm, ed)
}
