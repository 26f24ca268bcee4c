//! The default integrator on the rig with stiff STF models: a stiff `wall_impact` contact and a
//! steep `jamming_on_off` gate, each on a stretch of the source study's sweep where it acts.
//!
//! Each run with the default settings (what an experiment file gets without `[integrator]`)
//! must sample x within 1e-3 mm of a tight Dormand–Prince reference of the same model (rtol
//! 1e-11, atol 1e-13), the accuracy the paper's 150 s sweep is held to; a hundred times tighter
//! tolerances must bring it at least ten times closer (the accuracy follows the tolerance: no
//! silent loss); and with the step budget cut to a tenth of what the run needs, it must end with
//! the budget's error, not a result.
//!
//! The windows are 4 s long: impacts and stick–slip make the rig sensitive to small
//! differences (on the wall case below, a difference in x doubles every one to two seconds
//! whatever the method), so over long windows the comparison measures that sensitivity, not
//! the integrator.

use std::sync::Arc;

use stf_core::numerics::integrate::{Method, Settings, SimError};
use stf_core::physics::excitation::{Excitation, RotorAngle};
use stf_core::physics::force_model::ForceModel;
use stf_core::physics::oscillator::Oscillator;
use stf_core::physics::oscillator_params::OscillatorParams;
use stf_core::physics::param_spec::defaults;
use stf_core::simulate::{Simulation, Trajectory};
use stf_models::jamming_on_off::JammingOnOff;
use stf_models::wall_impact::WallImpact;

/// The largest |Δx| the default method may leave, m (1e-3 mm).
const TOLERANCE_X: f64 = 1e-6;

/// `model` with its defaults, `overrides` set by name, on the forced rig swept at 0.047 rad/s²
/// from ω = `w0`.
fn rig(model: Arc<dyn ForceModel>, overrides: &[(&str, f64)], w0: f64) -> Oscillator {
    let mut values = defaults(model.params());
    for (name, value) in overrides {
        let i = model.params().iter().position(|p| p.name == *name).unwrap();
        values[i] = *value;
    }
    Oscillator::new(
        OscillatorParams::FORCED,
        Excitation::Rotor(RotorAngle::sweep(w0, 0.047, 0.0)),
    )
    .with_model(model, values)
    .unwrap()
}

fn run(osc: &Oscillator, settings: Settings, t1: f64) -> Result<Trajectory, SimError> {
    Simulation::new(osc)
        .settings(settings)
        .rate(1000.0)
        .run(0.0, t1)
}

fn max_dx(a: &Trajectory, b: &Trajectory) -> f64 {
    a.x.iter()
        .zip(&b.x)
        .map(|(p, q)| (p - q).abs())
        .fold(0.0, f64::max)
}

/// Runs `osc` with the default settings and against the tight reference; returns the default
/// run (after the checks common to every stiff case).
fn check_against_reference(name: &str, osc: &Oscillator, t1: f64) -> Trajectory {
    let tight = Settings::default()
        .method(Method::Dopri5)
        .rtol(1e-11)
        .atol(1e-13);
    let reference = run(osc, tight, t1).unwrap();
    let default = run(osc, Settings::default(), t1).unwrap();
    let tighter = run(osc, Settings::default().rtol(1e-9).atol(1e-11), t1).unwrap();
    let dx = max_dx(&default, &reference);
    let dx_tighter = max_dx(&tighter, &reference);
    eprintln!(
        "{name}: max |Δx| {:.2e} mm at the defaults, {:.2e} mm at rtol 1e-9; default {:?}, reference {:?}",
        dx * 1e3,
        dx_tighter * 1e3,
        default.stats,
        reference.stats
    );
    assert!(
        dx < TOLERANCE_X,
        "{name}: max |Δx| {:.2e} mm against the reference",
        dx * 1e3
    );
    assert!(
        dx_tighter < dx / 10.0,
        "{name}: rtol 1e-9 leaves {:.2e} mm against {:.2e} mm at the defaults",
        dx_tighter * 1e3,
        dx * 1e3
    );
    // A budget of a tenth of the steps the run took ends it with the budget's error.
    let steps = default.stats.accepted + default.stats.rejected;
    let cut = Settings::default().max_steps((steps / 10) as u32);
    match run(osc, cut, t1) {
        Err(SimError::TooManySteps { .. }) => {}
        other => panic!("{name}: a tenth of the steps gave {other:?}"),
    }
    default
}

#[test]
fn a_stiff_wall_contact_keeps_x_within_a_micrometre() {
    // k_w = 1e8 N/m^1.5: 3 000 N at 1 mm into the wall, 300 times the default stiffness. Near
    // resonance the swing (≈ 40 mm without STF) reaches a 5 mm gap on every stroke.
    let osc = rig(
        Arc::new(WallImpact::new()),
        &[("k_w", 1e8), ("gap", 0.005)],
        6.2,
    );
    let run = check_against_reference("wall_impact k_w 1e8", &osc, 4.0);
    let peak_force = run.f_stf.iter().map(|f| f.abs()).fold(0.0, f64::max);
    let peak_x = run.x.iter().map(|x| x.abs()).fold(0.0, f64::max);
    eprintln!(
        "wall_impact: peak |F| {peak_force:.1} N, peak |x| {:.2} mm",
        peak_x * 1e3
    );
    assert!(
        peak_x > 0.005,
        "the blade must reach the wall (peak {peak_x} m)"
    );
    assert!(
        peak_force > 100.0,
        "contacts must be hard (peak {peak_force} N)"
    );
}

#[test]
fn a_steep_jamming_gate_keeps_x_within_a_micrometre() {
    // w = 1e-4 m/s, the gate's lower bound: on and off within ±0.2 mm/s of v_c, a slope of
    // 1 250 N·s/m, twenty times the default.
    let osc = rig(Arc::new(JammingOnOff::new()), &[("w", 1e-4)], 8.5);
    let run = check_against_reference("jamming_on_off w 1e-4", &osc, 4.0);
    let on = run.f_stf.iter().filter(|f| f.abs() > 0.1).count();
    let off = run.f_stf.iter().filter(|f| f.abs() < 0.01).count();
    eprintln!(
        "jamming_on_off: {on} samples on, {off} off of {}",
        run.t.len()
    );
    assert!(
        on > run.t.len() / 20 && off > run.t.len() / 20,
        "the gate must switch: {on} on, {off} off"
    );
}
