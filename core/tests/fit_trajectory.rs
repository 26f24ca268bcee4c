//! Trajectory-level identification on synthetic free vibrations made here.

use std::sync::Arc;

use rand::rngs::StdRng;
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};
use stf_core::fit::{FitError, FitParam, FitSettings, Solver, TrajectoryData, TrajectoryFit};
use stf_core::physics::excitation::Excitation;
use stf_core::physics::force_model::{ForceModel, ModelError, ModelState};
use stf_core::physics::oscillator::Oscillator;
use stf_core::physics::oscillator_params::OscillatorParams;
use stf_core::physics::param_spec::ParamSpec;
use stf_core::simulate::Simulation;

fn record(
    osc: &Oscillator,
    x0: f64,
    t1: f64,
    rate: f64,
    sigma: f64,
    seed: u64,
) -> (Vec<f64>, Vec<f64>) {
    let run = Simulation::new(osc)
        .rate(rate)
        .initial(x0, 0.0)
        .run(0.0, t1)
        .unwrap();
    let mut rng = StdRng::seed_from_u64(seed);
    let normal = Normal::new(0.0, sigma).unwrap();
    let x = run.x.iter().map(|x| x + normal.sample(&mut rng)).collect();
    (run.t, x)
}

fn rel(a: f64, b: f64) -> f64 {
    (a / b - 1.0).abs()
}

#[test]
fn free_vibration_recovers_k_c_t_from_ten_percent_off() {
    let truth = OscillatorParams::FREE;
    let osc = Oscillator::new(truth, Excitation::None);
    let (t, x) = record(&osc, 0.03, 5.0, 200.0, 5e-5, 11);
    let start = |name: &str, f: f64| {
        let v = truth.get(name).unwrap() * f;
        FitParam::new(name, v).bounds(0.0, 3.0 * v)
    };
    let fit = TrajectoryFit::new(
        OscillatorParams {
            k: 0.0,
            c: 0.0,
            t_friction: 0.0,
            ..truth
        },
        Arc::new(Excitation::None),
    )
    .initial(0.03, 0.0)
    .free(start("k", 1.1))
    .free(start("c", 0.9))
    .free(start("T", 1.1));
    let data = TrajectoryData { t: &t, x: &x };
    let r = fit.fit(&data, None).unwrap();
    assert!(r.convergence.converged(), "{:?}", r.log);
    for name in ["k", "c", "T"] {
        let got = r.value(name).unwrap();
        assert!(
            rel(got, truth.get(name).unwrap()) < 0.01,
            "{name}: {got} ({:?})",
            r.params
        );
        assert!(r.std_error(name).unwrap().is_finite());
    }
    // S(μ) at the optimum lies at the noise floor: no worse than at the truth, and not far
    // below σ² (a fit that "explains" the noise would).
    let at_truth = TrajectoryFit::new(truth, Arc::new(Excitation::None))
        .initial(0.03, 0.0)
        .fit(&data, None)
        .unwrap();
    let (s_fit, s_truth) = (r.s_mm2.unwrap(), at_truth.s_mm2.unwrap());
    assert!(
        s_fit <= s_truth * (1.0 + 1e-6),
        "S {s_fit} vs {s_truth} mm²"
    );
    assert!(s_fit > 0.8 * 0.05 * 0.05, "S {s_fit} mm²");
    assert_eq!(at_truth.n_free, 0);
}

#[test]
fn a_displacement_offset_is_fitted_like_any_parameter() {
    let truth = OscillatorParams {
        t_friction: 0.0,
        ..OscillatorParams::FREE
    };
    let osc = Oscillator::new(truth, Excitation::None);
    let (t, x) = record(&osc, 0.02, 2.0, 100.0, 5e-5, 12);
    let x: Vec<f64> = x.iter().map(|x| x + 0.002).collect();
    let r = TrajectoryFit::new(truth, Arc::new(Excitation::None))
        .free(FitParam::new("k", 250.0).bounds(100.0, 500.0))
        .free(FitParam::new("x_off", 0.0))
        .fit(&TrajectoryData { t: &t, x: &x }, None)
        .unwrap();
    assert!(
        (r.value("x_off").unwrap() - 0.002).abs() < 5e-5,
        "{:?}",
        r.params
    );
    assert!(rel(r.value("k").unwrap(), truth.k) < 0.01);
}

/// Viscous STF that refuses c_s above 2 N·s/m.
struct Brittle(Vec<ParamSpec>);

impl ForceModel for Brittle {
    fn name(&self) -> &str {
        "brittle"
    }
    fn params(&self) -> &[ParamSpec] {
        &self.0
    }
    fn force(&self, p: &[f64], s: &ModelState, _: &mut [f64]) -> Result<f64, ModelError> {
        if p[0] > 2.0 {
            return Err(ModelError::new("brittle", "c_s too large"));
        }
        Ok(p[0] * s.v)
    }
}

#[test]
fn failed_simulations_are_penalties_not_crashes() {
    let truth = OscillatorParams {
        t_friction: 0.0,
        ..OscillatorParams::FREE
    };
    let model: Arc<dyn ForceModel> = Arc::new(Brittle(vec![ParamSpec::new(
        "c_s", "N·s/m", 1.0, 0.0, 10.0, "",
    )]));
    let osc = Oscillator::new(truth, Excitation::None)
        .with_model(model.clone(), vec![1.0])
        .unwrap();
    let (t, x) = record(&osc, 0.02, 2.0, 100.0, 5e-5, 13);
    let r = TrajectoryFit::new(truth, Arc::new(Excitation::None))
        .model(model, vec![1.95])
        .free(FitParam::new("c_s", 1.95).bounds(0.0, 10.0))
        // Nelder–Mead's first simplex reaches past c_s = 2.
        .settings(FitSettings::default().solver(Solver::NelderMead))
        .fit(&TrajectoryData { t: &t, x: &x }, None)
        .unwrap();
    assert!(r.failures > 0, "{:?}", r.log);
    assert!(r.last_failure.as_deref().unwrap().contains("c_s too large"));
    assert!(rel(r.value("c_s").unwrap(), 1.0) < 0.02, "{:?}", r.params);
}

#[test]
fn names_are_resolved_or_refused() {
    let fit = TrajectoryFit::new(OscillatorParams::FREE, Arc::new(Excitation::None));
    let t = [0.0, 0.1, 0.2];
    let x = [0.0, 0.0, 0.0];
    let err = fit
        .free(FitParam::new("stifness", 1.0))
        .fit(&TrajectoryData { t: &t, x: &x }, None)
        .unwrap_err();
    assert!(matches!(err, FitError::UnknownParam { ref name, .. } if name == "stifness"));
    assert!(err.to_string().contains("delta_T"));
}

#[test]
fn forced_sweep_identification_from_ten_percent_off_reaches_the_noise() {
    use stf_core::physics::excitation::RotorAngle;
    let truth = OscillatorParams::FORCED;
    let excitation = Arc::new(Excitation::Rotor(RotorAngle::sweep(2.35, 0.047, 50.0)));
    let osc = Oscillator::with_shared_excitation(truth, excitation.clone());
    let run = Simulation::new(&osc).rate(200.0).run(50.0, 200.0).unwrap();
    let mut rng = StdRng::seed_from_u64(3);
    let noise = Normal::new(0.0, 1e-4).unwrap();
    let x: Vec<f64> = run.x.iter().map(|x| x + noise.sample(&mut rng)).collect();
    let data = TrajectoryData { t: &run.t, x: &x };
    let s_truth = TrajectoryFit::new(truth, excitation.clone())
        .fit(&data, None)
        .unwrap()
        .s_mm2
        .unwrap();
    let mut fit = TrajectoryFit::new(truth, excitation);
    for (name, factor) in [
        ("k", 1.1),
        ("c", 0.9),
        ("T", 1.1),
        ("delta_T", 0.9),
        ("F0", 1.1),
    ] {
        let v = truth.get(name).unwrap() * factor;
        fit = fit.free(FitParam::new(name, v).bounds(0.0, 3.0 * v));
    }
    let r = fit.fit(&data, None).unwrap();
    let s = r.s_mm2.unwrap();
    eprintln!(
        "S = {s:.5} mm² vs {s_truth:.5} at the truth; k {:.4}, F0 {:.6}; {} simulations",
        r.value("k").unwrap(),
        r.value("F0").unwrap(),
        r.evaluations
    );
    assert!(s <= 1.05 * s_truth, "S = {s}, at the truth {s_truth}");
    assert!(rel(r.value("k").unwrap(), truth.k) < 0.005);
    assert!(rel(r.value("F0").unwrap(), truth.f0) < 0.005);
    assert!(r.convergence.converged(), "{:?}", r.convergence);
}

/// A forced sweep record sampled through the rig's sensors (ω = w0 + alpha·t from t = 0).
fn rig_sweep_record(
    w0: f64,
    alpha: f64,
    duration: f64,
    rate: f64,
) -> stf_core::data::record::Record {
    use stf_core::physics::excitation::RotorAngle;
    use stf_core::simulate::synthetic::{sample_record, SensorNoise};
    let drive = Excitation::Rotor(RotorAngle::sweep(w0, alpha, 0.0));
    let osc = Oscillator::new(OscillatorParams::FORCED, drive);
    let run = Simulation::new(&osc).rate(rate).run(0.0, duration).unwrap();
    sample_record(&run, &SensorNoise::RIG, 1, true)
}

/// Fit `rec` as `stf-lab fit` does: the drive is the record's own encoder angle
/// (Hermite-interpolated with the filtered ω), whose knots make the integrator's error jump
/// with any change of the parameters. The soft direction of the friction pair (ΔT at fixed
/// T + ΔT) then changed the residuals less than that noise over the default difference
/// step, and Levenberg–Marquardt stopped up the valley. Returns S at the truth (the forced
/// preset) and the 5-parameter fit from `factors` × the truth.
fn fit_like_the_cli(
    rec: &stf_core::data::record::Record,
    factors: [f64; 5],
) -> (f64, stf_core::fit::FitResult) {
    use stf_core::data::kinematics::{Kinematics, KinematicsSettings};
    let truth = OscillatorParams::FORCED;
    let k = Kinematics::from_record(rec, &KinematicsSettings::default()).unwrap();
    let excitation = Arc::new(k.excitation());
    let data = TrajectoryData {
        t: &rec.t,
        x: &rec.x,
    };
    let s_truth = TrajectoryFit::new(truth, excitation.clone())
        .initial(k.x[0], k.v[0])
        .fit(&data, None)
        .unwrap()
        .s_mm2
        .unwrap();
    let mut fit = TrajectoryFit::new(truth, excitation).initial(k.x[0], k.v[0]);
    for (name, factor) in ["k", "c", "T", "delta_T", "F0"].into_iter().zip(factors) {
        let v = truth.get(name).unwrap() * factor;
        // The bounds `stf-lab fit` gives an identification's parameters.
        fit = fit.free(FitParam::new(name, v).bounds(v / 5.0, v * 5.0));
    }
    (s_truth, fit.fit(&data, None).unwrap())
}

#[test]
fn a_measured_drive_sweep_fit_from_ten_percent_low_is_not_stopped_by_integrator_noise() {
    // ω 3 → 9 rad/s in 60 s at 50 Hz: breakaway, then resonance. Before the difference steps
    // rose above the residuals' noise this start ended at S ≈ 2 × S at the truth.
    let rec = rig_sweep_record(3.0, 0.1, 60.0, 50.0);
    let (s_truth, r) = fit_like_the_cli(&rec, [0.9; 5]);
    let s = r.s_mm2.unwrap();
    eprintln!(
        "S = {s:.5} mm² vs {s_truth:.5} at the truth; {} simulations; {:?}",
        r.evaluations, r.params
    );
    assert!(s <= 1.05 * s_truth, "S = {s}, at the truth {s_truth}");
}

/// The bundled record (experiments/records/forced_sweep.csv), three starts 10 % off (all
/// up, all down, mixed signs): each must end within 5 % of S at the truth. About 15 s in
/// release.
#[test]
#[ignore]
fn bundled_forced_sweep_from_three_ten_percent_off_starts_reaches_the_optimum() {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../experiments/records/forced_sweep.csv");
    let rec = stf_core::data::record::ReadOptions::default()
        .read(&path)
        .unwrap();
    for factors in [[1.1; 5], [0.9; 5], [1.1, 0.9, 1.1, 0.9, 1.1]] {
        let (s_truth, r) = fit_like_the_cli(&rec, factors);
        let s = r.s_mm2.unwrap();
        eprintln!(
            "{factors:?}: S = {s:.5} mm² vs {s_truth:.5} at the truth; {} simulations, {:.1} s",
            r.evaluations, r.wall_seconds
        );
        assert!(
            s <= 1.05 * s_truth,
            "{factors:?}: S = {s}, at the truth {s_truth}"
        );
    }
}
