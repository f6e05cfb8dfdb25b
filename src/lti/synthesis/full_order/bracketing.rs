//! The γ-iteration: feasibility ([`Problem::test`]) is monotone in γ, so γ_opt is found by
//! bracketing (factors of 10 from 2× the D11 bound, or from 1) and geometric bisection down to
//! the relative width [`GAMMA_RTOL`]; the reported `gamma` is the feasible end. With a known
//! feasible level (the previous δ of the regularisation), the bracket is searched downwards from
//! it in growing relative steps instead.

use super::gamma_test::Problem;
use super::{Binding, FullOrderError};

/// Relative width of the final γ bracket.
pub const GAMMA_RTOL: f64 = 1e-8;
/// Largest γ tried when searching a feasible level.
pub const GAMMA_MAX: f64 = 1e12;
/// Relative to the first trial, the smallest γ tried before declaring γ_opt = 0.
const GAMMA_MIN_REL: f64 = 1e-12;

/// A γ bracket: `lo` infeasible (or the D11 bound / 0), `hi` feasible.
#[derive(Debug, Clone)]
pub(crate) struct Bracket {
    pub(crate) lo: f64,
    pub(crate) hi: f64,
    pub(crate) binding: Binding,
}

/// Bracket and bisect γ_opt of `prob` to relative width `rtol`, counting γ-tests in `tests`.
/// `warm`: a γ known feasible (previous δ), searched downwards from.
pub(crate) fn gamma_opt(
    prob: &Problem,
    rtol: f64,
    warm: Option<f64>,
    tests: &mut usize,
) -> Result<Bracket, FullOrderError> {
    let floor = prob.gamma_d;
    let mut lo_binding = Binding::Feedthrough;
    let (mut lo, mut hi);
    match warm {
        Some(w) => {
            // Step down from w by growing relative amounts until infeasible.
            hi = w;
            let mut delta = 1e-5;
            loop {
                let g = (hi * (1.0 - delta)).max(floor);
                if g <= floor {
                    lo = floor;
                    break;
                }
                *tests += 1;
                match prob.test(g) {
                    Ok(_) => {
                        hi = g;
                        delta = (delta * 10.0).min(0.9);
                    }
                    Err((bnd, _)) => {
                        lo = g;
                        lo_binding = bnd;
                        break;
                    }
                }
            }
        }
        None => {
            let start = if floor > 0.0 { 2.0 * floor } else { 1.0 };
            *tests += 1;
            match prob.test(start) {
                Ok(_) => {
                    hi = start;
                    loop {
                        let g = hi / 10.0;
                        if g <= floor {
                            lo = floor;
                            break;
                        }
                        if g < GAMMA_MIN_REL * start {
                            return Ok(Bracket { lo: 0.0, hi, binding: Binding::None });
                        }
                        *tests += 1;
                        match prob.test(g) {
                            Ok(_) => hi = g,
                            Err((bnd, _)) => {
                                lo = g;
                                lo_binding = bnd;
                                break;
                            }
                        }
                    }
                }
                Err((bnd, why)) => {
                    lo = start;
                    lo_binding = bnd;
                    let mut last = why;
                    loop {
                        let g = lo * 10.0;
                        if g > GAMMA_MAX {
                            return Err(FullOrderError::NoFeasibleGamma { gamma_max: GAMMA_MAX, last });
                        }
                        *tests += 1;
                        match prob.test(g) {
                            Ok(_) => {
                                hi = g;
                                break;
                            }
                            Err((bnd, why)) => {
                                lo = g;
                                lo_binding = bnd;
                                last = why;
                            }
                        }
                    }
                }
            }
        }
    }
    while hi - lo > rtol * hi {
        let mid = if lo > 0.0 { (lo * hi).sqrt() } else { 0.5 * hi };
        *tests += 1;
        match prob.test(mid) {
            Ok(_) => hi = mid,
            Err((bnd, _)) => {
                lo = mid;
                lo_binding = bnd;
            }
        }
    }
    Ok(Bracket { lo, hi, binding: lo_binding })
}
