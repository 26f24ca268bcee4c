//! A parameter that follows a measured control channel, fitted at force and trajectory level.
//!
//! A damper-like record: the forced rig swept 4 → 8 rad/s at 0.1 rad/s² (40 s, through
//! resonance) at 200 Hz with the rig's sensors, its STF force a viscous drag plus a Bouc–Wen
//! hysteretic force whose saturation follows a control channel switched at random between levels (each held for 1–4 s, as a
//! magnetorheological damper's coil voltage). Fitted from its starts (base at the saturation
//! force's default, gain 0), the law's coefficients and the viscous drag come back within 5 %, and the law's fit reaches the
//! sensor's noise while a constant saturation force stays well above it.

use std::sync::Arc;

use stf_core::data::force_data::ForceData;
use stf_core::data::kinematics::{Kinematics, KinematicsSettings};
use stf_core::fit::{FitParam, ForceFit, TrajectoryData, TrajectoryFit};
use stf_core::physics::channel_law::{ChannelLaw, Law, MeasuredChannel};
use stf_core::physics::excitation::{Excitation, RotorAngle};
use stf_core::physics::force_model::ForceModel;
use stf_core::physics::model_sum::ModelSum;
use stf_core::physics::oscillator::Oscillator;
use stf_core::physics::oscillator_params::OscillatorParams;
use stf_core::simulate::synthetic::{sample_record, SensorNoise};
use stf_core::simulate::Simulation;
use stf_models::find;

const RATE: f64 = 200.0;
const T1: f64 = 40.0;

/// A control channel on the sample grid: `levels` switched at random (a small LCG seeded by
/// `seed`), each held for 1–4 s.
fn control(seed: u64, levels: &[f64]) -> (Vec<f64>, Vec<f64>) {
    let mut state = seed
        .wrapping_mul(6364136223846793005)
        .wrapping_add(1442695040888963407);
    let mut next = || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64
    };
    let n = (T1 * RATE) as usize + 1;
    let t: Vec<f64> = (0..n).map(|i| i as f64 / RATE).collect();
    let mut u = Vec::with_capacity(n);
    let (mut level, mut until) = (0, 0.0);
    for &ti in &t {
        if ti >= until {
            level = (level + 1 + (next() * (levels.len() - 1) as f64) as usize) % levels.len();
            until = ti + 1.0 + 3.0 * next();
        }
        u.push(levels[level]);
    }
    (t, u)
}

/// `viscous + bouc_wen` with the hysteretic force following `channel` by `law`.
fn damper(channel: &Arc<MeasuredChannel>, law: Law) -> Arc<dyn ForceModel> {
    Arc::new(ChannelLaw::new(Arc::new(constant()), "F_bw", law, channel.clone()).unwrap())
}

/// `viscous + bouc_wen`, the force of a magnetorheological damper (Spencer's model less its
/// inner dashpot).
fn constant() -> ModelSum {
    ModelSum::new(vec![find("viscous").unwrap(), find("bouc_wen").unwrap()]).unwrap()
}

struct Case {
    /// The rotor's sweep, as simulated.
    sweep: RotorAngle,
    t: Vec<f64>,
    x: Vec<f64>,
    v: Vec<f64>,
    a: Vec<f64>,
    f: Vec<f64>,
}

/// Simulate the rig with `truth` (values `p`) and sample it with the rig's sensors.
fn record(truth: Arc<dyn ForceModel>, p: Vec<f64>, seed: u64) -> Case {
    let sweep = RotorAngle::sweep(4.0, 0.1, 0.0);
    let osc = Oscillator::new(OscillatorParams::FORCED, Excitation::Rotor(sweep.clone()))
        .with_model(truth, p)
        .unwrap();
    let run = Simulation::new(&osc).rate(RATE).run(0.0, T1).unwrap();
    let rec = sample_record(&run, &SensorNoise::RIG, seed, true);
    let k = Kinematics::from_record(&rec, &KinematicsSettings::default()).unwrap();
    Case {
        sweep,
        t: rec.t.clone(),
        x: rec.x.clone(),
        v: k.v.clone(),
        a: k.a.clone(),
        f: rec.f_stf.clone().unwrap(),
    }
}

/// Fit `viscous + bouc_wen` with F_bw following a control channel (`levels`, `seed`) by
/// `law` to the record of the `truth` values (the model's order), from the model's starts,
/// and check every value within 5 %.
fn check(law: Law, levels: &[f64], truth: &[f64], seed: u64) {
    let (t, u) = control(seed, levels);
    let channel = Arc::new(MeasuredChannel::new("u_ctrl", t, u).unwrap());
    let model = damper(&channel, law);
    let c = record(model.clone(), truth.to_vec(), seed);
    let data = ForceData::new(&c.t, &c.x, &c.v, &c.a, &c.f);
    let fit = ForceFit::new(model.clone()).fit(&data, None).unwrap();
    let names: Vec<String> = model.params().iter().map(|s| s.name.clone()).collect();
    for (name, want) in names.iter().zip(truth) {
        let got = fit.value(name).unwrap();
        eprintln!("{law:?} seed {seed}: {name} = {got:.5} (truth {want})");
        assert!(
            (got - want).abs() < 0.05 * want.abs(),
            "{law:?} seed {seed}: {name} = {got} against {want}"
        );
    }
    // A constant hysteretic force cannot follow the channel.
    let flat = ForceFit::new(Arc::new(constant()))
        .fit(&data, None)
        .unwrap();
    eprintln!(
        "{law:?} seed {seed}: RMS {:.4} N with the law, {:.4} N with a constant F_bw",
        fit.rms, flat.rms
    );
    assert!(
        fit.rms < 0.03,
        "the sensor's 0.02 N and a little filter noise: {}",
        fit.rms
    );
    assert!(flat.rms > 2.0 * fit.rms);
}

#[test]
fn an_affine_hysteretic_force_follows_a_two_level_control_channel() {
    // c_s, F_bw_base, F_bw_gain, x_bw, beta: F_bw 0.3 N at 0 V, 0.9 N at 1 V.
    for seed in [1, 2] {
        check(Law::Affine, &[0.0, 1.0], &[2.0, 0.3, 0.6, 3e-3, 0.7], seed);
    }
}

#[test]
fn a_linear_and_a_power_law_with_an_offset_are_recovered() {
    check(Law::Linear, &[0.5, 2.0], &[2.0, 0.4, 3e-3, 0.7], 3);
    // Three levels: a power law with an offset needs more than two to show its exponent.
    check(
        Law::Power,
        &[0.0, 0.5, 2.0],
        &[2.0, 0.2, 0.3, 1.5, 3e-3, 0.7],
        4,
    );
}

/// At trajectory level (x only, the rig's x sensor; the rotor's sweep as simulated), the
/// affine law's fit from the model's starts recovers every value within 5 % too.
#[test]
fn the_law_is_recovered_at_trajectory_level() {
    let truth = [2.0, 0.3, 0.6, 3e-3, 0.7];
    let (t, u) = control(1, &[0.0, 1.0]);
    let channel = Arc::new(MeasuredChannel::new("u_ctrl", t, u).unwrap());
    let model = damper(&channel, Law::Affine);
    let c = record(model.clone(), truth.to_vec(), 1);
    let starts: Vec<f64> = model.params().iter().map(|s| s.default).collect();
    let mut fit = TrajectoryFit::new(
        OscillatorParams::FORCED,
        Arc::new(Excitation::Rotor(c.sweep.clone())),
    )
    .model(model.clone(), starts);
    for spec in model.params() {
        fit = fit.free(FitParam::from_spec(spec));
    }
    let r = fit.fit(&TrajectoryData { t: &c.t, x: &c.x }, None).unwrap();
    for (spec, want) in model.params().iter().zip(truth) {
        let got = r.value(&spec.name).unwrap();
        eprintln!("trajectory: {} = {got:.5} (truth {want})", spec.name);
        assert!((got - want).abs() < 0.05 * want, "{} = {got}", spec.name);
    }
}
