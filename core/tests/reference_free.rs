//! Free vibration from x0 = 30 mm against an independent implementation's curve.

use stf_core::data::response::{stop, MOVING_SPEED};
use stf_core::physics::excitation::Excitation;
use stf_core::physics::oscillator::Oscillator;
use stf_core::physics::oscillator_params::OscillatorParams;
use stf_core::simulate::Simulation;

fn reference() -> Vec<(f64, f64, f64)> {
    let text = include_str!("data/free_vibration_x0_30mm.csv");
    text.lines()
        .skip(1)
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|c| c.parse().unwrap()).collect();
            (v[0], v[1], v[2])
        })
        .collect()
}

#[test]
fn free_vibration_matches_the_reference_and_stops_near_3_2_s() {
    let osc = Oscillator::new(OscillatorParams::FREE, Excitation::None);
    let run = Simulation::new(&osc)
        .rate(100.0)
        .initial(0.03, 0.0)
        .run(0.0, 20.0)
        .unwrap();
    let reference = reference();
    assert_eq!(reference.len(), run.t.len());
    let mut worst: f64 = 0.0;
    for (i, &(t, x, _v)) in reference.iter().enumerate() {
        assert!((run.t[i] - t).abs() < 1e-9);
        worst = worst.max((run.x[i] - x).abs());
    }
    let stops = run.t[stop(&run.v, MOVING_SPEED).unwrap()];
    let rest = run.x.last().unwrap().abs();
    eprintln!(
        "max |Δx| = {:.4} mm, stops at {stops:.2} s, {:.3} mm from zero",
        worst * 1e3,
        rest * 1e3
    );
    assert!(worst < 0.01e-3, "max |Δx| = {worst}");
    assert!((stops - 3.2).abs() < 0.2, "stops at {stops}");
    assert!((rest - 0.28e-3).abs() < 0.02e-3, "rests at {rest}");
}
