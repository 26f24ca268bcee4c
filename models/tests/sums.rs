//! Built-ins add: the parameters of a sum are those of its parts and the forces add.

use std::sync::Arc;

use approx::assert_relative_eq;
use stf_core::physics::excitation::{Excitation, RotorAngle};
use stf_core::physics::force_model::{ForceModel, ModelState};
use stf_core::physics::model_sum::ModelSum;
use stf_core::physics::oscillator::Oscillator;
use stf_core::physics::oscillator_params::OscillatorParams;
use stf_core::physics::param_spec::defaults;
use stf_models::find;

fn sum(names: &[&str]) -> ModelSum {
    ModelSum::new(names.iter().map(|n| find(n).unwrap()).collect()).unwrap()
}

fn param_names(m: &dyn ForceModel) -> Vec<String> {
    m.params().iter().map(|s| s.name.clone()).collect()
}

#[test]
fn power_law_plus_added_mass_has_k_n_and_m_a() {
    let m = sum(&["power_law", "added_mass"]);
    assert_eq!(param_names(&m), ["K", "n", "m_a"]);
    assert_eq!(m.param_index("power_law.K"), Some(0));
    let s = ModelState {
        t: 0.0,
        x: 0.0,
        v: -0.2,
        z: &[],
    };
    // K = 4, n = 2 at v = −0.2: −0.16 N; m_a = 1.5 kg.
    assert_relative_eq!(
        m.force(&[4.0, 2.0, 1.5], &s, &mut []).unwrap(),
        -0.16,
        max_relative = 1e-12
    );
    assert_eq!(m.added_mass(&[4.0, 2.0, 1.5], &s).unwrap(), 1.5);
}

#[test]
fn viscous_plus_maxwell_stacks_the_state_and_adds_forces() {
    let m = sum(&["viscous", "maxwell"]);
    assert_eq!(param_names(&m), ["c_s", "c_m", "tau"]);
    assert_eq!(m.n_internal(), 1);
    let s = ModelState {
        t: 0.0,
        x: 0.0,
        v: 0.1,
        z: &[0.3],
    };
    let mut dz = [0.0];
    // 2·0.1 + 0.3 = 0.5 N; dF/dt = (5·0.1 − 0.3)/0.05 = 4 N/s.
    let f = m.force(&[2.0, 5.0, 0.05], &s, &mut dz).unwrap();
    assert_relative_eq!(f, 0.5, max_relative = 1e-12);
    assert_relative_eq!(dz[0], 4.0, max_relative = 1e-12);
}

#[test]
fn a_sum_of_four_builtins_has_no_clashing_names() {
    let m = sum(&["power_law", "jamming_on_off", "wall_impact", "yield"]);
    assert_eq!(
        param_names(&m),
        ["K", "n", "K_j", "n_j", "v_c", "w", "k_w", "gap", "p", "c_r", "F_y", "v_s"]
    );
}

#[test]
fn every_builtin_runs_in_the_oscillator_at_its_defaults() {
    for name in stf_models::names() {
        let model = find(name).unwrap();
        let values = defaults(model.params());
        let osc = Oscillator::new(
            OscillatorParams::FORCED,
            Excitation::Rotor(RotorAngle::constant(8.0)),
        )
        .with_model(model, values)
        .unwrap();
        let run = stf_core::simulate::Simulation::new(&osc)
            .rate(100.0)
            .run(0.0, 2.0)
            .unwrap();
        assert!(
            run.x.iter().chain(&run.f_stf).all(|v| v.is_finite()),
            "{name}"
        );
        assert!(
            run.x.iter().any(|x| x.abs() > 1e-4),
            "{name}: it never moved"
        );
    }
}

#[test]
fn a_sum_with_all_builtins_is_a_model() {
    let all = ModelSum::new(
        stf_models::names()
            .iter()
            .map(|n| find(n).unwrap())
            .collect(),
    );
    let m = all.unwrap();
    // `maxwell` and `bouc_wen` carry one state each.
    assert_eq!(m.n_internal(), 2);
    let values = defaults(m.params());
    let osc = Oscillator::new(
        OscillatorParams::FORCED,
        Excitation::Rotor(RotorAngle::constant(8.0)),
    )
    .with_model(Arc::new(m), values)
    .unwrap();
    let run = stf_core::simulate::Simulation::new(&osc)
        .rate(100.0)
        .run(0.0, 1.0)
        .unwrap();
    assert!(run.f_stf.iter().all(|f| f.is_finite()));
}
