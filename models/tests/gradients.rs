//! Every built-in without internal state gives the exact gradient of its force with respect
//! to its parameters (`ForceModel::gradient`, which the fitter uses instead of differences);
//! it must agree with central differences at any state and any parameters within the
//! bounds, and a sum's gradient is its parts' side by side (NaN for a part with state, which
//! the fitter differences).

use std::sync::Arc;

use proptest::prelude::*;
use stf_core::physics::force_model::{ForceModel, ModelState};
use stf_core::physics::model_sum::ModelSum;
use stf_models::{find, BUILTINS};

/// The whole force `m_a·a + f` at parameters `p`.
fn total(model: &dyn ForceModel, p: &[f64], s: &ModelState, a: f64) -> f64 {
    model.added_mass(p, s).unwrap() * a + model.force(p, s, &mut []).unwrap()
}

/// Central differences of the whole force, each step 1e-6 of the parameter (at least 1e-9
/// of its range), and the rounding noise each difference carries.
fn differences(model: &dyn ForceModel, p: &[f64], s: &ModelState, a: f64) -> Vec<(f64, f64)> {
    let f = total(model, p, s, a).abs();
    (0..p.len())
        .map(|j| {
            let spec = &model.params()[j];
            let h = 1e-6 * p[j].abs().max(1e-3 * (spec.max - spec.min));
            let (mut up, mut down) = (p.to_vec(), p.to_vec());
            up[j] += h;
            down[j] -= h;
            let d = (total(model, &up, s, a) - total(model, &down, s, a)) / (2.0 * h);
            (d, 100.0 * f64::EPSILON * f.max(1e-300) / h)
        })
        .collect()
}

/// Whether differences of the force of `model` at `p` and speed `v` can be trusted: not where
/// a jamming gate is closed beyond 1e-7 (its `½·(1 + tanh q)` then keeps few digits, and
/// differences of it none; the force there is below any sensor's resolution).
fn differentiable(model: &dyn ForceModel, p: &[f64], v: f64) -> bool {
    model.name() != "jamming_on_off" || (v.abs() - p[2]) / p[3] > -8.0
}

fn check(model: &dyn ForceModel, p: &[f64], x: f64, v: f64, a: f64) {
    if !differentiable(model, p, v) {
        return;
    }
    let s = ModelState {
        t: 0.0,
        x,
        v,
        z: &[],
    };
    let mut grad = vec![f64::NAN; p.len()];
    assert!(
        model.gradient(p, &s, a, &mut grad).unwrap(),
        "{}",
        model.name()
    );
    let fd = differences(model, p, &s, a);
    // Relative to the entry, beyond the differences' rounding noise (a saturated gate's
    // slope of 1e-11 differences to 0). A wrong formula is off by far more.
    for (j, (g, (d, noise))) in grad.iter().zip(&fd).enumerate() {
        let scale = g.abs().max(d.abs());
        assert!(
            (g - d).abs() <= 1e-4 * scale + noise + 1e-12,
            "{} ∂/∂{} at x {x}, v {v}, p {p:?}: exact {g}, differences {d}",
            model.name(),
            model.params()[j].name
        );
    }
}

/// Parameter values at the fractions `u` of the range between 1 % and 99 % of the bounds
/// (a difference step must stay inside).
fn inside(model: &dyn ForceModel, u: &[f64]) -> Vec<f64> {
    model
        .params()
        .iter()
        .zip(u)
        .map(|(s, f)| s.min + (0.01 + 0.98 * f) * (s.max - s.min))
        .collect()
}

proptest! {
    #[test]
    fn the_gradient_of_every_memoryless_built_in_matches_differences(
        u in prop::collection::vec(0.0..=1.0f64, 4),
        x in -0.05..0.05f64,
        v in -0.3..0.3f64,
        a in -5.0..5.0f64,
    ) {
        for entry in BUILTINS {
            let model = (entry.build)();
            if model.n_internal() > 0 {
                continue;
            }
            // The defaults (where the fits start), then anywhere within the bounds.
            let defaults: Vec<f64> = model.params().iter().map(|s| s.default).collect();
            check(model.as_ref(), &defaults, x, v, a);
            check(model.as_ref(), &inside(model.as_ref(), &u), x, v, a);
        }
    }
}

#[test]
fn at_rest_and_out_of_contact_the_gradient_is_finite() {
    for entry in BUILTINS {
        let model = (entry.build)();
        if model.n_internal() > 0 {
            continue;
        }
        let p: Vec<f64> = model.params().iter().map(|s| s.default).collect();
        let s = ModelState {
            t: 0.0,
            x: 0.0,
            v: 0.0,
            z: &[],
        };
        let mut grad = vec![f64::NAN; p.len()];
        assert!(model.gradient(&p, &s, 0.0, &mut grad).unwrap());
        assert!(
            grad.iter().all(|g| g.is_finite()),
            "{}: {grad:?}",
            entry.name
        );
    }
}

#[test]
fn a_sum_stacks_its_parts_gradients_and_leaves_those_of_a_part_with_state_to_differences() {
    let parts = |names: &[&str]| -> Arc<dyn ForceModel> {
        Arc::new(ModelSum::new(names.iter().map(|n| find(n).unwrap()).collect()).unwrap())
    };
    let sum = parts(&["power_law", "added_mass", "jamming_on_off"]);
    let p = [20.0, 1.5, 1.5, 50.0, 2.0, 0.05, 0.01];
    check(sum.as_ref(), &p, 0.01, 0.06, 2.0);
    let with_state = parts(&["power_law", "maxwell"]);
    let s = ModelState {
        t: 0.0,
        x: 0.0,
        v: 0.1,
        z: &[0.0],
    };
    let mut grad = [0.0; 4];
    assert!(with_state
        .gradient(&[20.0, 1.5, 5.0, 0.05], &s, 0.0, &mut grad)
        .unwrap());
    assert!(grad[..2].iter().all(|g| g.is_finite()), "{grad:?}");
    assert!(grad[2..].iter().all(|g| g.is_nan()), "{grad:?}");
    // A model with state alone gives none.
    let maxwell = find("maxwell").unwrap();
    assert!(!maxwell
        .gradient(&[5.0, 0.05], &s, 0.0, &mut [0.0; 2])
        .unwrap());
}
