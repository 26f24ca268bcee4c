//! Fitted values that make a model a simpler one: a wall with no gap and exponent 3 is a cubic
//! spring, a gate open at every speed the record reaches is its power law, a power law of
//! exponent 1 is viscous; values that use the model's own freedom are not reduced.

use stf_core::physics::force_model::{ForceModel, Reach};
use stf_models::{jamming_on_off::JammingOnOff, power_law::PowerLaw, wall_impact::WallImpact};

const REACH: Reach = Reach { x: 0.03, v: 0.2 };

#[test]
fn a_wall_without_a_gap_and_of_exponent_three_is_a_cubic_spring() {
    let wall = WallImpact::new();
    let got = wall.reduces_to(&[2e4, 1e-4, 2.97, 0.0], REACH);
    assert_eq!(got, Some(("cubic_stiffness".to_string(), vec![2e4])));
    assert_eq!(
        wall.reduces_to(&[2e4, 0.01, 3.0, 0.0], REACH),
        None,
        "a real gap"
    );
    assert_eq!(wall.reduces_to(&[2e4, 0.0, 1.5, 0.0], REACH), None, "Hertz");
    assert_eq!(
        wall.reduces_to(&[2e4, 0.0, 3.0, 2.0], REACH),
        None,
        "damped"
    );
}

#[test]
fn an_always_open_gate_is_its_power_law_and_exponent_one_is_viscous() {
    let gate = JammingOnOff::new();
    let open = gate.reduces_to(&[4.0, 1.5, 1e-3, 1e-3], REACH);
    assert_eq!(open, Some(("power_law".to_string(), vec![4.0, 1.5])));
    assert_eq!(gate.reduces_to(&[4.0, 1.5, 0.05, 0.01], REACH), None);
    let law = PowerLaw::new();
    assert_eq!(
        law.reduces_to(&[3.0, 1.01], REACH),
        Some(("viscous".to_string(), vec![3.0]))
    );
    assert_eq!(law.reduces_to(&[3.0, 1.5], REACH), None);
}
