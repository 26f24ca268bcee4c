//! Laws every built-in must obey, for any parameters within their bounds: dissipative models
//! never add energy (F·v ≥ 0), odd laws satisfy F(−x, −v) = −F(x, v), contacts never pull.

use proptest::prelude::*;
use stf_core::physics::force_model::{ForceModel, ModelState};
use stf_models::find;

/// Parameter values of `model` placed at the fractions `u` (in [0, 1]) of their bounds.
fn within_bounds(model: &dyn ForceModel, u: &[f64]) -> Vec<f64> {
    model
        .params()
        .iter()
        .zip(u)
        .map(|(s, f)| s.min + f * (s.max - s.min))
        .collect()
}

fn force(name: &str, u: &[f64], x: f64, v: f64, z: &[f64]) -> f64 {
    let model = find(name).unwrap();
    let p = within_bounds(model.as_ref(), u);
    let mut dz = vec![0.0; model.n_internal()];
    model
        .force(&p, &ModelState { t: 0.0, x, v, z }, &mut dz)
        .unwrap()
}

const DISSIPATIVE: [&str; 4] = ["viscous", "power_law", "yield", "jamming_on_off"];
const ODD: [&str; 7] = [
    "viscous",
    "power_law",
    "yield",
    "cubic_stiffness",
    "wall_impact",
    "jamming_on_off",
    "linear_spring",
];

fn fractions() -> impl Strategy<Value = Vec<f64>> {
    prop::collection::vec(0.0..=1.0f64, 4)
}

proptest! {
    #[test]
    fn dissipative_models_never_add_energy(u in fractions(), x in -0.1..0.1f64, v in -1.0..1.0f64) {
        for name in DISSIPATIVE {
            let f = force(name, &u, x, v, &[]);
            prop_assert!(f.is_finite(), "{name}: F = {f}");
            prop_assert!(f * v >= 0.0, "{name}: F·v = {} < 0", f * v);
        }
    }

    #[test]
    fn odd_laws_flip_sign_with_the_state(u in fractions(), x in -0.1..0.1f64, v in -1.0..1.0f64) {
        for name in ODD {
            let (f, g) = (force(name, &u, x, v, &[]), force(name, &u, -x, -v, &[]));
            prop_assert_eq!(g, -f, "{}", name);
        }
    }

    #[test]
    fn maxwell_is_odd_in_its_state_too(u in fractions(), v in -1.0..1.0f64, z in -10.0..10.0f64) {
        let model = find("maxwell").unwrap();
        let p = within_bounds(model.as_ref(), &u);
        let (mut dz, mut dz_neg) = ([0.0], [0.0]);
        let f = model.force(&p, &ModelState { t: 0.0, x: 0.0, v, z: &[z] }, &mut dz).unwrap();
        let g = model.force(&p, &ModelState { t: 0.0, x: 0.0, v: -v, z: &[-z] }, &mut dz_neg).unwrap();
        prop_assert_eq!(g, -f);
        prop_assert_eq!(dz_neg[0], -dz[0]);
    }

    #[test]
    fn bouc_wen_is_odd_in_its_state_and_never_passes_its_saturation(
        u in fractions(), v in -1.0..1.0f64, z in -3.0..3.0f64,
    ) {
        let model = find("bouc_wen").unwrap();
        let p = within_bounds(model.as_ref(), &u);
        let (mut dz, mut dz_neg) = ([0.0], [0.0]);
        let f = model.force(&p, &ModelState { t: 0.0, x: 0.0, v, z: &[z] }, &mut dz).unwrap();
        let g = model.force(&p, &ModelState { t: 0.0, x: 0.0, v: -v, z: &[-z] }, &mut dz_neg).unwrap();
        prop_assert_eq!(g, -f);
        prop_assert_eq!(dz_neg[0], -dz[0]);
        prop_assert!(f.abs() <= p[0], "|F| = {} above F_bw = {}", f.abs(), p[0]);
        // At or past saturation the state never loads further.
        if z.abs() >= 1.0 {
            let scale = v.abs() / p[1];
            prop_assert!(dz[0] * z.signum() <= 1e-12 * scale || v * z < 0.0, "ż = {} at z = {z}", dz[0]);
        }
    }

    #[test]
    fn the_wall_never_pulls(u in fractions(), x in -0.2..0.2f64, v in -5.0..5.0f64) {
        let f = force("wall_impact", &u, x, v, &[]);
        prop_assert!(f * x.signum() >= 0.0, "F = {f} at x = {x}");
    }

    #[test]
    fn conservative_models_store_no_more_than_they_get(u in fractions(), x in -0.1..0.1f64) {
        // cubic_stiffness is a spring: F·x ≥ 0 (it pushes back towards the middle).
        for name in ["cubic_stiffness", "linear_spring"] {
            let f = force(name, &u, x, 0.3, &[]);
            prop_assert!(f * x >= 0.0, "{name}");
        }
    }
}
