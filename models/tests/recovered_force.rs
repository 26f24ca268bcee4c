//! The STF force recovered from a synthetic record's kinematics against the truth hidden in it.

use std::sync::Arc;

use stf_core::data::kinematics::{Kinematics, KinematicsSettings};
use stf_core::physics::excitation::{Excitation, RotorAngle};
use stf_core::physics::oscillator::Oscillator;
use stf_core::physics::oscillator_params::OscillatorParams;
use stf_core::simulate::synthetic::{sample_record, SensorNoise};
use stf_core::simulate::Simulation;

fn rms(a: &[f64]) -> f64 {
    (a.iter().map(|v| v * v).sum::<f64>() / a.len() as f64).sqrt()
}

/// Recovered minus true force, RMS over the record without 1 s at each edge (and, with
/// `skip_reversals`, without a filter window around each velocity reversal), the force
/// amplitude there, and the predicted noise floor.
fn recovery_error(
    p: OscillatorParams,
    noise: &SensorNoise,
    drop_omega: bool,
    skip_reversals: bool,
) -> (f64, f64, f64) {
    let osc = Oscillator::new(p, Excitation::Rotor(RotorAngle::sweep(4.0, 0.1, 10.0)))
        .with_model(Arc::new(stf_models::viscous::Viscous::new()), vec![3.0])
        .unwrap();
    let run = Simulation::new(&osc).rate(1000.0).run(10.0, 40.0).unwrap();
    let mut record = sample_record(&run, noise, 11, true);
    if drop_omega {
        record.omega = None;
    }
    let k = Kinematics::from_record(&record, &KinematicsSettings::default()).unwrap();
    let recovered = k.recovered_force(&p);
    let half = k.motion_filter.window();
    let near_reversal = |i: usize| {
        let lo = i.saturating_sub(half);
        let hi = (i + half).min(run.v.len() - 1);
        (lo..hi).any(|j| run.v[j] * run.v[j + 1] <= 0.0)
    };
    let inner: Vec<usize> = (1000..run.t.len() - 1000)
        .filter(|&i| !(skip_reversals && near_reversal(i)))
        .collect();
    let diff: Vec<f64> = inner.iter().map(|&i| recovered[i] - run.f_stf[i]).collect();
    let amplitude = inner
        .iter()
        .fold(0.0_f64, |m, &i| m.max(run.f_stf[i].abs()));
    (rms(&diff), amplitude, k.recovered_force_noise(&p))
}

#[test]
fn exact_record_recovers_the_viscous_force_within_2_percent() {
    // Without dry friction the acceleration is smooth and the filter follows it.
    let smooth = OscillatorParams {
        t_friction: 0.0,
        delta_t: 0.0,
        ..OscillatorParams::FORCED
    };
    for drop_omega in [false, true] {
        let (err, amplitude, _) = recovery_error(smooth, &SensorNoise::NONE, drop_omega, false);
        eprintln!(
            "exact, no dry friction, ω {}: RMS error {err:.5} N of amplitude {amplitude:.3} N ({:.3} %)",
            if drop_omega { "filtered from φ" } else { "from the record" },
            100.0 * err / amplitude
        );
        assert!(err < 0.02 * amplitude);
    }
    // With the paper's dry friction the acceleration jumps by 2·T/m at every velocity
    // reversal; no smoothing filter resolves that jump, so the recovered force is wrong for
    // a filter window around each reversal, and right elsewhere.
    let p = OscillatorParams::FORCED;
    let (all, amplitude, _) = recovery_error(p, &SensorNoise::NONE, true, false);
    let (away, _, _) = recovery_error(p, &SensorNoise::NONE, true, true);
    eprintln!(
        "exact, paper friction: RMS error {all:.4} N overall, {away:.5} N away from reversals, amplitude {amplitude:.3} N"
    );
    assert!(away < 0.02 * amplitude);
    assert!(all > away, "the reversals are where the error lives");
}

#[test]
fn noisy_record_error_is_the_reported_floor() {
    let p = OscillatorParams {
        t_friction: 0.0,
        delta_t: 0.0,
        ..OscillatorParams::FORCED
    };
    let (err, amplitude, floor) = recovery_error(p, &SensorNoise::RIG, true, false);
    eprintln!(
        "noisy: RMS error {err:.4} N of amplitude {amplitude:.3} N; predicted floor {floor:.4} N"
    );
    // The error is what the derivative noise predicts (not hidden), within a factor 1.5.
    assert!(
        err < 1.5 * floor && err > floor / 1.5,
        "error {err}, floor {floor}"
    );
}
