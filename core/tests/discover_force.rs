//! Force-level discovery with the re-check off and the polish on (the trajectory level's
//! defaults): the same effect is named as with the force level's own.

use std::sync::Arc;

use stf_core::data::force_data::ForceData;
use stf_core::discovery::{discover_force, Candidate, DiscoverySettings};
use stf_core::physics::force_model::{ForceModel, ModelState};
use stf_core::physics::param_spec::ParamSpec;
use stf_core::regimes::cycles_from_phase;

mod support;

/// `p·g(state)`, p in [0, 100] from 1.
fn term(name: &'static str, g: fn(&ModelState) -> f64) -> Arc<dyn ForceModel> {
    support::term(name, ParamSpec::new("p", "", 1.0, 0.0, 100.0, ""), g)
}

#[test]
fn the_re_check_off_and_the_polish_on_name_the_same_effect_at_force_level() {
    // 40 cycles at 6 rad/s; F = 2·v + 0.5·x plus a deterministic "noise".
    let t: Vec<f64> = (0..8400).map(|i| i as f64 / 200.0).collect();
    let phi: Vec<f64> = t.iter().map(|t| 6.0 * t).collect();
    let x: Vec<f64> = phi.iter().map(|p| 0.01 * p.sin()).collect();
    let v: Vec<f64> = phi.iter().map(|p| 0.06 * p.cos()).collect();
    let a: Vec<f64> = x.iter().map(|x| -36.0 * x).collect();
    let f: Vec<f64> = (0..t.len())
        .map(|i| 2.0 * v[i] + 0.5 * x[i] + 1e-4 * ((i * 7919 % 13) as f64 - 6.0))
        .collect();
    let data = ForceData::new(&t, &x, &v, &a, &f);
    let cycles = cycles_from_phase(&t, &phi).unwrap();
    let candidates = [
        Candidate::new("spring", term("spring", |s| s.x)),
        Candidate::new("cubic", term("cubic", |s| 1e4 * s.x.powi(3))),
    ];
    let run = |s: &DiscoverySettings| {
        discover_force(term("damper", |s| s.v), &candidates, &data, &cycles, s).unwrap()
    };
    let own = run(&DiscoverySettings::default());
    let swapped = run(&DiscoverySettings::default()
        .recheck(Some(false))
        .polish(Some(true)));
    assert_eq!(own.effects, ["spring"]);
    assert_eq!(swapped.effects, own.effects);
    assert!(swapped.gap_after < 0.2 * swapped.gap_before);
    assert!((swapped.gap_after / own.gap_after - 1.0).abs() < 1e-3);
}
