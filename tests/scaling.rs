//! Plant-scaled controller variables (`design::scaling`): the scales of shipped plants, and the
//! scaled objective against the unscaled one and against finite differences.

use std::cell::RefCell;
use std::rc::Rc;

use hinfix::design::{
    channel_scales, variable_scaling, ComponentCache, ControllerShape, DesignObjective, ObjectivePhase,
};
use hinfix::lti::{Plant, DEFAULT_HINF_TOL};
use hinfix::optim::Objective;

fn plant(name: &str) -> Plant {
    Plant::load(format!("{}/plants/{name}.json", env!("CARGO_MANIFEST_DIR"))).unwrap()
}

/// AC10's measurements differ by ~10⁵ in size. Independent check (SciPy 1.17.1,
/// `scipy.linalg.matrix_balance(A, permute=False)`, a different balancing rule than ours): rows
/// of C2·T with norms 5.03e-2 and 5.19e3 (ratio 1.0e5), columns of T⁻¹B2 both 6250. Ours: row
/// norms 0.33 and 9.9e4, column norms 49 and 24. The scales are powers of two near 1/norm.
#[test]
fn ac10_measurements_are_scaled_apart_and_alike_plants_are_not_scaled() {
    let (su, sy) = channel_scales(&plant("AC10")).expect("AC10's channels differ");
    assert!([&su, &sy].iter().all(|v| v.iter().all(|s| s.log2().fract() == 0.0)), "{su:?} {sy:?}");
    let ratio = sy[0] / sy[1];
    assert!((1e4..1e6).contains(&ratio), "measurement scales {sy:?}");
    assert!(su[0] / su[1] <= 4.0 && su[1] / su[0] <= 4.0, "control scales {su:?}");
    for name in ["HE1", "Enns", "REA2", "AC8"] {
        assert_eq!(channel_scales(&plant(name)), None, "{name}");
    }
    let shape = ControllerShape { nk: 1, m: 2, p: 2, domain: Default::default() };
    let d = variable_scaling(&plant("AC10"), shape).unwrap();
    // [Ak; Bk (1×2); Ck (2×1); Dk (2×2) column-major]
    let want = [1.0, sy[0], sy[1], su[0], su[1], su[0] * sy[0], su[1] * sy[0], su[0] * sy[1], su[1] * sy[1]];
    assert_eq!(d, want);
}

fn objective<'p>(p: &'p Plant, phase: ObjectivePhase, d: Option<&[f64]>) -> DesignObjective<'p> {
    let shape = ControllerShape::for_plant(p, 1);
    let cache = Rc::new(RefCell::new(ComponentCache::default()));
    DesignObjective::new(p, shape, phase, true, 1e-3, DEFAULT_HINF_TOL, cache).with_scaling(d.map(Into::into))
}

/// f(x̃) = f(d ∘ x̃) and ∇f(x̃) = d ∘ ∇f(d ∘ x̃) bit for bit (d holds powers of two), and the scaled
/// gradient matches central differences in x̃.
#[test]
fn scaled_objective_is_the_same_function_with_the_chain_rule_gradient() {
    let p = plant("REA2");
    let shape = ControllerShape::for_plant(&p, 1);
    // REA2 is not scaled by default (channels 4× apart); this d (s_u = [1/16, 1/4],
    // s_y = [1/2, 2]) tests the mapping.
    let d = [1.0, 0.5, 2.0, 0.0625, 0.25, 0.03125, 0.125, 0.125, 0.5];
    // A stabilising order-1 point of REA2 (‖Tzw‖∞ ≈ 1.16; from a short design, rounded) in scaled
    // variables, and a point that is not.
    let xs_stable: Vec<f64> = [-2.58, -1.95, -3.16, -0.273, 1.95, -59.3, -6.09, -11.0, -12.7].to_vec();
    let xs_random: Vec<f64> = (0..shape.nvar()).map(|i| ((i * 7 + 3) as f64).sin()).collect();
    let mut finite = 0;
    for phase in [ObjectivePhase::Stabilisation, ObjectivePhase::Performance] {
        for xs in [&xs_stable, &xs_random] {
            let x: Vec<f64> = xs.iter().zip(&d).map(|(v, s)| v * s).collect();
            let (mut g, mut gs) = (vec![0.0; x.len()], vec![0.0; x.len()]);
            let f = objective(&p, phase, None).eval(&x, &mut g);
            let fs = objective(&p, phase, Some(&d[..])).eval(xs, &mut gs);
            assert_eq!(f.to_bits(), fs.to_bits(), "{phase:?}");
            if !f.is_finite() {
                continue;
            }
            finite += 1;
            for i in 0..x.len() {
                assert_eq!((g[i] * d[i]).to_bits(), gs[i].to_bits(), "{phase:?} entry {i}");
            }
        }
    }
    assert!(finite >= 3, "the performance objective must be finite at the stable point ({finite})");
    // Central differences of the scaled stabilisation objective (smooth at this point).
    let mut obj = objective(&p, ObjectivePhase::Stabilisation, Some(&d[..]));
    let mut gs = vec![0.0f64; shape.nvar()];
    let f0 = obj.eval(&xs_stable, &mut gs);
    assert!(f0.is_finite());
    let h = 1e-6;
    for i in 0..shape.nvar() {
        let mut e = vec![0.0; shape.nvar()];
        let (mut xp, mut xm) = (xs_stable.clone(), xs_stable.clone());
        xp[i] += h;
        xm[i] -= h;
        let fd = (obj.eval(&xp, &mut e) - obj.eval(&xm, &mut e)) / (2.0 * h);
        assert!((fd - gs[i]).abs() <= 1e-5 * (1.0 + gs[i].abs()), "entry {i}: fd {fd} vs {}", gs[i]);
    }
}
