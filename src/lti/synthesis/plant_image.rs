//! The continuous-time image of a discrete-time plant under the bilinear transform
//! (docs/ALGORITHMS.md §10.4), and controllers of the image taken back to discrete time.
//!
//! The map z = ±(1 + s)/(1 − s) (`kernels/bilinear.rs`, the sign chosen on the whole plant's A)
//! takes every discrete controller of order n_K to a continuous one of the same order and back,
//! and the closed loop of the images to the image of the closed loop (the LFT commutes with a
//! change of the frequency variable); internal stability, the H∞ norm and the Hankel singular
//! values are kept. So continuous-time synthesis on the image (γ_opt, the central controller,
//! balanced truncation) is discrete-time synthesis on the plant.

use std::borrow::Cow;

use faer::Mat;

use super::full_order::linalg::{concat_cols, concat_rows};
use crate::lti::kernels::bilinear::{from_continuous, Cayley};
use crate::lti::system::controller::Controller;
use crate::lti::system::plant::Plant;
use crate::lti::system::state_space::StateSpace;
use crate::lti::system::time_domain::TimeDomain;

/// The continuous-time plant on which `plant`'s questions about stable controllers are asked:
/// `plant` itself in continuous time, its bilinear image ([`PlantImage`]: stable controllers and
/// stabilising ones correspond) in discrete time. A discrete-time plant without an image
/// ([`ImageError`]) is taken as it is.
pub fn continuous_time_image(plant: &Plant) -> Cow<'_, Plant> {
    match plant.domain {
        TimeDomain::Continuous => Cow::Borrowed(plant),
        TimeDomain::Discrete { .. } => PlantImage::new(plant).map_or(Cow::Borrowed(plant), |i| Cow::Owned(i.plant)),
    }
}

/// A discrete-time plant's continuous-time image.
#[derive(Debug, Clone)]
pub struct PlantImage {
    /// The image, a continuous-time plant of the same sizes and name.
    pub plant: Plant,
    /// The domain controllers are taken back to (the original plant's).
    domain: TimeDomain,
    /// Whether the map is z = −(1 + s)/(1 − s) (`kernels/bilinear.rs`).
    flipped: bool,
}

/// Why a plant has no image.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
pub enum ImageError {
    /// Plant data with NaN or infinity.
    #[error("plant has non-finite entries")]
    NonFinite,
    /// A has eigenvalues at both z = 1 and z = −1.
    #[error("A has eigenvalues at both z = 1 and z = −1: no bilinear image")]
    NoImage,
}

impl PlantImage {
    /// The image of `plant`'s matrices read as a discrete-time system (whatever its `domain`).
    pub fn new(plant: &Plant) -> Result<PlantImage, ImageError> {
        let d = plant.dims;
        let b = concat_cols(plant.b1.as_ref(), plant.b2.as_ref());
        let c = concat_rows(plant.c1.as_ref(), plant.c2.as_ref());
        let top = concat_cols(plant.d11.as_ref(), plant.d12.as_ref());
        let dd = concat_rows(top.as_ref(), concat_cols(plant.d21.as_ref(), plant.d22.as_ref()).as_ref());
        let sys = StateSpace { a: plant.a.clone(), b, c, d: dd };
        if !sys.is_finite() {
            return Err(ImageError::NonFinite);
        }
        let cayley = Cayley::new(&sys).ok_or(ImageError::NoImage)?;
        let image = cayley.sys;
        let block =
            |m: &Mat<f64>, r0: usize, c0: usize, r: usize, c: usize| m.as_ref().submatrix(r0, c0, r, c).to_owned();
        let plant_image = Plant {
            a: image.a,
            b1: block(&image.b, 0, 0, d.n, d.m1),
            b2: block(&image.b, 0, d.m1, d.n, d.m2),
            c1: block(&image.c, 0, 0, d.p1, d.n),
            c2: block(&image.c, d.p1, 0, d.p2, d.n),
            d11: block(&image.d, 0, 0, d.p1, d.m1),
            d12: block(&image.d, 0, d.m1, d.p1, d.m2),
            d21: block(&image.d, d.p1, 0, d.p2, d.m1),
            d22: block(&image.d, d.p1, d.m1, d.p2, d.m2),
            domain: TimeDomain::Continuous,
            ..plant.clone()
        };
        Ok(PlantImage { plant: plant_image, domain: plant.domain, flipped: cayley.flipped })
    }

    /// The discrete-time controller (in the original plant's domain) whose image is the
    /// continuous-time controller `k` of the image plant; `None` if `k` has a pole at s = 1
    /// (the map's singular point) or the result is not finite.
    pub fn controller_back(&self, k: &Controller) -> Option<Controller> {
        let sys = StateSpace { a: k.ak.clone(), b: k.bk.clone(), c: k.ck.clone(), d: k.dk.clone() };
        let back = from_continuous(&sys, self.flipped)?;
        Some(Controller::continuous(back.a, back.b, back.c, back.d).in_domain(self.domain))
    }
}
