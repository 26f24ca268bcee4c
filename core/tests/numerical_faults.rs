//! Numerical faults end in a typed error or an honest report, never a panic or a silently
//! wrong number: a model that returns NaN or fails, a non-positive effective mass, a solution
//! that blows up, a parameter at its bound, a flat objective.

use std::sync::Arc;

use stf_core::data::force_data::ForceData;
use stf_core::fit::{FitParam, ForceFit};
use stf_core::numerics::integrate::{integrate, OdeSystem, Settings, SimError};
use stf_core::physics::excitation::{Excitation, RotorAngle};
use stf_core::physics::force_model::{ForceModel, ModelError, ModelState};
use stf_core::physics::oscillator::Oscillator;
use stf_core::physics::oscillator_params::OscillatorParams;
use stf_core::physics::param_spec::ParamSpec;
use stf_core::simulate::Simulation;

/// A model whose force turns bad after `t_bad`: NaN, or an error, or a negative added mass.
struct Faulty {
    specs: Vec<ParamSpec>,
    fault: &'static str,
}

impl ForceModel for Faulty {
    fn name(&self) -> &str {
        "faulty"
    }
    fn params(&self) -> &[ParamSpec] {
        &self.specs
    }
    fn added_mass(&self, p: &[f64], s: &ModelState) -> Result<f64, ModelError> {
        Ok(if self.fault == "mass" && s.t > 1.0 {
            -2.0 * p[0]
        } else {
            0.0
        })
    }
    fn force(&self, _p: &[f64], s: &ModelState, _dz: &mut [f64]) -> Result<f64, ModelError> {
        match self.fault {
            "nan" if s.t > 1.0 => Ok(f64::NAN),
            "inf" if s.t > 1.0 => Ok(f64::INFINITY),
            "error" if s.t > 1.0 => Err(ModelError::new("faulty", "gave up")),
            _ => Ok(0.1 * s.v),
        }
    }
}

fn run_with(fault: &'static str) -> Result<(), SimError> {
    let model = Arc::new(Faulty {
        specs: vec![ParamSpec::new("m", "kg", 7.65, 0.0, 100.0, "")],
        fault,
    });
    let osc = Oscillator::new(
        OscillatorParams::FORCED,
        Excitation::Rotor(RotorAngle::constant(6.0)),
    )
    .with_model(model, vec![7.65])
    .map_err(|e| SimError::BadSettings(e.to_string()))?;
    Simulation::new(&osc).rate(100.0).run(0.0, 3.0).map(|_| ())
}

#[test]
fn a_model_returning_nan_or_infinity_is_a_non_finite_error_with_its_time() {
    for fault in ["nan", "inf"] {
        let err = run_with(fault).unwrap_err();
        assert!(matches!(err, SimError::NonFinite { .. }), "{fault}: {err}");
        let t = err.time().unwrap();
        assert!(t > 1.0 && t < 1.1, "{fault}: at {t}");
    }
}

#[test]
fn a_failing_model_stops_the_run_with_its_message_and_time() {
    let err = run_with("error").unwrap_err();
    let SimError::Model { time, source } = &err else {
        panic!("{err}");
    };
    assert!(*time > 1.0 && *time < 1.1);
    assert!(source.to_string().contains("gave up"));
}

#[test]
fn a_non_positive_effective_mass_is_an_error_not_a_nan() {
    let err = run_with("mass").unwrap_err();
    assert!(matches!(err, SimError::NonPositiveMass { .. }), "{err}");
}

/// y' = y², from y(0) = 1: blows up at t = 1.
struct BlowUp;
impl OdeSystem for BlowUp {
    fn dim(&self) -> usize {
        1
    }
    fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SimError> {
        dy[0] = y[0] * y[0];
        Ok(())
    }
}

#[test]
fn a_collapsing_step_is_a_typed_error_near_the_singularity() {
    let err = integrate(&BlowUp, 0.0, &[1.0], &[0.5, 2.0], &Settings::default()).unwrap_err();
    let t = err.time().unwrap();
    assert!(
        matches!(
            err,
            SimError::StepSizeTooSmall { .. } | SimError::NonFinite { .. }
        ),
        "{err}"
    );
    assert!((t - 1.0).abs() < 0.01, "stopped at {t}");
}

/// t, x, v, a and a viscous force 2·v of a sine motion.
type Signals = (Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>, Vec<f64>);

fn linear_data() -> Signals {
    let t: Vec<f64> = (0..2000).map(|i| i as f64 * 1e-3).collect();
    let x: Vec<f64> = t.iter().map(|t| 0.01 * (6.0 * t).sin()).collect();
    let v: Vec<f64> = t.iter().map(|t| 0.06 * (6.0 * t).cos()).collect();
    let a: Vec<f64> = t.iter().map(|t| -0.36 * (6.0 * t).sin()).collect();
    let f: Vec<f64> = v.iter().map(|v| 2.0 * v).collect();
    (t, x, v, a, f)
}

struct Damper {
    specs: Vec<ParamSpec>,
}
impl ForceModel for Damper {
    fn name(&self) -> &str {
        "damper"
    }
    fn params(&self) -> &[ParamSpec] {
        &self.specs
    }
    fn force(&self, p: &[f64], s: &ModelState, _dz: &mut [f64]) -> Result<f64, ModelError> {
        Ok(p[0] * s.v)
    }
}

#[test]
fn a_truth_beyond_the_bound_ends_at_the_bound_honestly() {
    let (t, x, v, a, f) = linear_data();
    let data = ForceData::new(&t, &x, &v, &a, &f);
    let model = Arc::new(Damper {
        specs: vec![ParamSpec::new("c", "N·s/m", 0.5, 0.0, 1.0, "")],
    });
    let r = ForceFit::new(model)
        .param(FitParam::new("c", 0.5).bounds(0.0, 1.0))
        .fit(&data, None)
        .unwrap();
    let c = r.value("c").unwrap();
    assert!(c <= 1.0 && c > 0.99, "c = {c}");
    assert!(r.rms > 0.01, "the misfit shows: rms {}", r.rms);
}

#[test]
fn a_flat_objective_gives_no_finite_uncertainty() {
    let (t, x, v, a, f) = linear_data();
    let zero = vec![0.0; t.len()];
    // The force does not depend on c when v is zero everywhere: the objective is flat.
    let data = ForceData::new(&t, &x, &zero, &a, &f);
    let model = Arc::new(Damper {
        specs: vec![ParamSpec::new("c", "N·s/m", 0.5, 0.0, 10.0, "")],
    });
    let r = ForceFit::new(model).fit(&data, None).unwrap();
    let se = r.std_error("c").unwrap();
    assert!(
        !se.is_finite() || se > 1e6,
        "std error {se} of an unidentifiable parameter"
    );
    let _ = v;
}
