//! The controller parameterisation (docs/ALGORITHMS.md §1):
//!
//! ```text
//! x = [ vec(Ak) ; vec(Bk) ; vec(Ck) ; vec(Dk) ]     (column-major vec)
//! nvar = nk² + nk·p + m·nk + m·p = (nk + m)(nk + p)
//! ```
//!
//! No canonical form: the full realisation is free (over-parameterised by the nk² similarity
//! transformations, as in HIFOO). Order 0 (static output feedback) is x = vec(Dk). Gradients with
//! respect to (Ak, Bk, Ck, Dk) ([`crate::lti::ControllerGradient`]) map to ∇ₓ by the same layout.

use faer::Mat;

use crate::lti::{Controller, Plant, TimeDomain};

/// Sizes of the controller being designed (order nk, m controls, p measurements) and its time
/// domain (the plant's).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ControllerShape {
    /// Order nk.
    pub nk: usize,
    /// The plant's controls m (rows of Dk; the controller's [`Controller::outputs`]).
    pub m: usize,
    /// The plant's measurements p (columns of Dk; the controller's [`Controller::inputs`]).
    pub p: usize,
    /// Continuous or discrete time.
    pub domain: TimeDomain,
}

impl ControllerShape {
    /// The shape of an existing controller.
    pub fn of(k: &Controller) -> Self {
        ControllerShape { nk: k.order(), m: k.outputs(), p: k.inputs(), domain: k.domain }
    }

    /// Controllers of order `nk` for `plant` (its m2 controls, p2 measurements and time domain).
    pub fn for_plant(plant: &Plant, nk: usize) -> Self {
        ControllerShape { nk, m: plant.dims.m2, p: plant.dims.p2, domain: plant.domain }
    }

    /// Number of variables (nk + m)(nk + p).
    pub fn nvar(&self) -> usize {
        (self.nk + self.m) * (self.nk + self.p)
    }

    /// The controller whose parameter vector is `x` (`x.len()` must be [`Self::nvar`]).
    pub fn controller(&self, x: &[f64]) -> Controller {
        assert_eq!(x.len(), self.nvar(), "parameter vector length does not match the controller shape");
        let (nk, m, p) = (self.nk, self.m, self.p);
        let mut off = 0;
        let mut block = |r: usize, c: usize| {
            let blk = &x[off..off + r * c];
            off += r * c;
            Mat::from_fn(r, c, |i, j| blk[i + j * r])
        };
        let ak = block(nk, nk);
        let bk = block(nk, p);
        let ck = block(m, nk);
        let dk = block(m, p);
        Controller { ak, bk, ck, dk, domain: self.domain }
    }

    /// Writes x = [vec Ak; vec Bk; vec Ck; vec Dk] of `k` (of this shape's sizes; its domain
    /// is not looked at: a gradient is written the same way) into `out`.
    pub fn write_x(&self, k: &Controller, out: &mut [f64]) {
        let sizes = |s: ControllerShape| (s.nk, s.m, s.p);
        assert_eq!(sizes(ControllerShape::of(k)), sizes(*self), "controller does not have this shape");
        assert_eq!(out.len(), self.nvar(), "output length does not match the controller shape");
        let mut off = 0;
        for mat in [&k.ak, &k.bk, &k.ck, &k.dk] {
            let (r, c) = (mat.nrows(), mat.ncols());
            for j in 0..c {
                for i in 0..r {
                    out[off + i + j * r] = mat[(i, j)];
                }
            }
            off += r * c;
        }
    }
}

/// x = [vec Ak; vec Bk; vec Ck; vec Dk] of a controller.
pub fn controller_to_x(k: &Controller) -> Vec<f64> {
    let shape = ControllerShape::of(k);
    let mut x = vec![0.0; shape.nvar()];
    shape.write_x(k, &mut x);
    x
}

/// The controller of shape `shape` with parameters `x` (see [`ControllerShape::controller`]).
pub fn x_to_controller(x: &[f64], shape: ControllerShape) -> Controller {
    shape.controller(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_is_column_major_blocks() {
        let shape = ControllerShape { nk: 2, m: 1, p: 3, domain: TimeDomain::Continuous };
        assert_eq!(shape.nvar(), 3 * 5);
        let x: Vec<f64> = (0..shape.nvar()).map(|i| i as f64).collect();
        let k = shape.controller(&x);
        // Ak = [0 2; 1 3]
        assert_eq!((k.ak[(0, 0)], k.ak[(1, 0)], k.ak[(0, 1)], k.ak[(1, 1)]), (0.0, 1.0, 2.0, 3.0));
        // Bk 2×3 starts at 4, column-major: Bk(1,2) = 4 + 1 + 2·2 = 9
        assert_eq!(k.bk[(1, 2)], 9.0);
        // Ck 1×2 at 10, Dk 1×3 at 12
        assert_eq!((k.ck[(0, 0)], k.ck[(0, 1)]), (10.0, 11.0));
        assert_eq!((k.dk[(0, 0)], k.dk[(0, 2)]), (12.0, 14.0));
    }

    #[test]
    fn round_trip_all_orders() {
        for (nk, m, p) in [(0, 1, 1), (0, 2, 3), (1, 2, 1), (3, 2, 2), (4, 1, 5)] {
            let shape = ControllerShape { nk, m, p, domain: TimeDomain::Continuous };
            let x: Vec<f64> = (0..shape.nvar()).map(|i| (i as f64 * 0.37).sin()).collect();
            let k = x_to_controller(&x, shape);
            assert_eq!(ControllerShape::of(&k), shape);
            let back = controller_to_x(&k);
            assert_eq!(back, x, "nk={nk} m={m} p={p}");
        }
    }
}
