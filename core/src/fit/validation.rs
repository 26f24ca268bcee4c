//! Scoring a fitted model on a record it was not fitted to: system identification's standard
//! of estimating on one measurement and validating on another.
//!
//! [`ForceFit::validate`] predicts the STF force from the other record's kinematics with the
//! fitted values. [`TrajectoryFit::validate`] simulates the fitted oscillator and model driven
//! by the other record's drive (set it with [`TrajectoryFit::excitation`]) from that record's
//! own initial state: refitted on it when `x0`, `v0` are free parameters of the fit (the
//! initial state belongs to a record, not to the model), else its estimate as given to
//! [`TrajectoryFit::initial`]; every other value stays as fitted. An offset the fit fitted
//! (`f_off`, `x_off`) belongs to the sensor, not to the model: it is fitted again on the
//! other record, every model value held, by the rule of every fitted offset
//! ([`super::offset`]: from the least-squares value, within bounds from that record's scale,
//! flagged when it ends at or is held by a bound). Both give a [`Validation`]: the RMS of
//! measured − predicted and that RMS over the RMS of the measured signal.
//!
//! ```
//! use std::sync::Arc;
//! use stf_core::data::force_data::ForceData;
//! use stf_core::fit::ForceFit;
//! use stf_core::physics::force_model::{ForceModel, ModelError, ModelState};
//! use stf_core::physics::param_spec::ParamSpec;
//! struct Lin(Vec<ParamSpec>);
//! impl ForceModel for Lin {
//!     fn name(&self) -> &str { "lin" }
//!     fn params(&self) -> &[ParamSpec] { &self.0 }
//!     fn force(&self, p: &[f64], s: &ModelState, _: &mut [f64]) -> Result<f64, ModelError> {
//!         Ok(p[0] * s.v)
//!     }
//! }
//! let fit = ForceFit::new(Arc::new(Lin(vec![ParamSpec::new("c", "N·s/m", 1.0, 0.0, 9.0, "")])));
//! // Another record: the force is 3·v; the fitted value 2.9 misses a thirtieth of it.
//! let t: Vec<f64> = (0..100).map(|i| i as f64 * 0.01).collect();
//! let v: Vec<f64> = t.iter().map(|t| (5.0 * t).cos()).collect();
//! let f: Vec<f64> = v.iter().map(|v| 3.0 * v).collect();
//! let zeros = vec![0.0; t.len()];
//! let other = ForceData::new(&t, &zeros, &v, &zeros, &f);
//! let score = fit.validate(&other, &[2.9]).unwrap();
//! assert!((score.normalised - 1.0 / 30.0).abs() < 1e-12);
//! ```

use serde::Serialize;

use super::error::FitError;
use super::fit_param::{held, FitParam};
use super::force_fit::{ForceFit, FORCE_OFFSET};
use super::offset::{least_squares_offset, offset_param};
use super::result::FitResult;
use super::trajectory_fit::{
    initial_state_params, TrajectoryData, TrajectoryFit, DISPLACEMENT_OFFSET, INITIAL_STATE,
};
use super::warning::{fit_warnings, FitWarning};
use crate::data::force_data::ForceData;

/// A fitted model's error on a record it was not fitted to.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Validation {
    /// RMS of measured − predicted: N at force level, m at trajectory level.
    pub rms: f64,
    /// RMS of the measured signal, same unit.
    pub measured_rms: f64,
    /// `rms / measured_rms` (NaN when the measured signal is all zeros).
    pub normalised: f64,
    /// Samples scored.
    pub samples: usize,
    /// The state (x0 m, v0 m/s) the simulation started from (trajectory level).
    pub initial: Option<[f64; 2]>,
    /// Whether that state was fitted to the record (with every other value held).
    pub initial_fitted: bool,
    /// The record's own offset (`f_off` N, `x_off` m), fitted on it with every model value
    /// held; none when the fit fitted no offset.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub offset: Option<f64>,
    /// Whether that offset ended at or is held by a bound of its box (± twice the record's
    /// largest |value|): the score is then biased.
    #[serde(skip_serializing_if = "std::ops::Not::not")]
    pub offset_on_bound: bool,
    /// The prediction at every sample (not serialized).
    #[serde(skip)]
    pub predicted: Vec<f64>,
}

impl Validation {
    /// The score of `predicted` against `measured` (equal lengths).
    pub fn of(measured: &[f64], predicted: Vec<f64>) -> Self {
        let error = rms(measured.iter().zip(&predicted).map(|(m, p)| m - p));
        let measured_rms = rms(measured.iter().copied());
        Validation {
            rms: error,
            measured_rms,
            normalised: error / measured_rms,
            samples: measured.len(),
            initial: None,
            initial_fitted: false,
            offset: None,
            offset_on_bound: false,
            predicted,
        }
    }
}

impl Validation {
    /// This score with the record's own `offset` (fitted on it, flagged `on_bound`): the
    /// measured RMS is then that of the signal less the offset, about which it swings.
    fn with_offset(mut self, measured: &[f64], offset: f64, on_bound: bool) -> Self {
        self.measured_rms = rms(measured.iter().map(|m| m - offset));
        self.normalised = self.rms / self.measured_rms;
        self.offset = Some(offset);
        self.offset_on_bound = on_bound;
        self
    }
}

/// RMS of the values (0 when there are none).
fn rms(values: impl Iterator<Item = f64>) -> f64 {
    let (sum, n) = values.fold((0.0, 0usize), |(s, n), v| (s + v * v, n + 1));
    if n == 0 {
        0.0
    } else {
        (sum / n as f64).sqrt()
    }
}

impl ForceFit {
    /// Score the fitted `values` (as for [`ForceFit::predict`]: the model's parameters, then
    /// the offset) on another record's kinematics and force; an offset is fitted again on
    /// that record (see the module's doc).
    pub fn validate(&self, data: &ForceData, values: &[f64]) -> Result<Validation, FitError> {
        let params = self.params();
        if !params.iter().any(|p| p.name == FORCE_OFFSET) {
            return Ok(Validation::of(data.f, self.predict(data, values)?));
        }
        let mut bare = held(&params, values)?;
        let last = bare.len() - 1;
        bare[last].value = 0.0;
        let without: Vec<f64> = bare.iter().map(|p| p.value).collect();
        let start = least_squares_offset(data.f, &self.predict(data, &without)?);
        bare[last] = offset_param(FORCE_OFFSET, data.f, start);
        let refit = bare[..last]
            .iter()
            .cloned()
            .fold(self.clone().filter_noise(None), ForceFit::param)
            .offset(bare[last].clone());
        let result = refit.fit_plain(data)?;
        let offset = result.value(FORCE_OFFSET).unwrap_or(start);
        let mut all = without;
        all[last] = offset;
        let flagged = on_bound(&result, &refit.params(), FORCE_OFFSET);
        let score = Validation::of(data.f, self.predict(data, &all)?);
        Ok(score.with_offset(data.f, offset, flagged))
    }
}

/// Whether the fit `result` of `params` flags `name` as ending at or held by a bound.
fn on_bound(result: &FitResult, params: &[FitParam], name: &str) -> bool {
    fit_warnings(result, params, None)
        .iter()
        .any(|w| matches!(w, FitWarning::OnBound { param, .. } if param == name))
}

/// The largest |x − mean| of `x`.
fn x_span(x: &[f64]) -> f64 {
    let mean = x.iter().sum::<f64>() / x.len().max(1) as f64;
    x.iter().fold(0.0_f64, |m, v| m.max((v - mean).abs()))
}

/// The largest |v| of central differences of the record's x.
fn v_span(data: &TrajectoryData) -> f64 {
    (1..data.x.len().saturating_sub(1))
        .map(|i| (data.x[i + 1] - data.x[i - 1]) / (data.t[i + 1] - data.t[i - 1]))
        .fold(0.0_f64, |m, v| m.max(v.abs()))
}

impl TrajectoryFit {
    /// Score the fitted `values` (one per parameter given to [`TrajectoryFit::free`], in that
    /// order) on `data`, a record driven by this fit's excitation: see the
    /// doc of [`Validation`]. With `x0`, `v0` free, they are refitted from the estimate given to
    /// [`TrajectoryFit::initial`] (within a tenth of the record's range of x and v).
    pub fn validate(&self, data: &TrajectoryData, values: &[f64]) -> Result<Validation, FitError> {
        let given = held(self.free_params(), values)?;
        let refit = self.initial_is_free();
        let (x0, v0) = self
            .initial
            .unwrap_or((data.x.first().copied().unwrap_or(0.0), 0.0));
        let start = initial_state_params(x0, v0, x_span(data.x), v_span(data));
        let mut held: Vec<_> = given
            .iter()
            .map(|p| match INITIAL_STATE.iter().position(|n| *n == p.name) {
                Some(i) if refit => start[i].clone(),
                _ => FitParam::new(&p.name, p.value).fixed(true),
            })
            .collect();
        let offset_at = held.iter().position(|p| p.name == DISPLACEMENT_OFFSET);
        if let Some(k) = offset_at {
            held[k].value = 0.0;
            let bare: Vec<f64> = held.iter().map(|p| p.value).collect();
            let (x, _) = self.with_free(held.clone()).simulate(data, &bare)?;
            let start = least_squares_offset(data.x, &x);
            held[k] = offset_param(DISPLACEMENT_OFFSET, data.x, start);
        }
        let held_fit = self.with_free(held.clone());
        let (values, on_bound_now) = if refit || offset_at.is_some() {
            let result = held_fit.fit(data, None)?;
            let flagged = on_bound(&result, &held, DISPLACEMENT_OFFSET);
            let values = held
                .iter()
                .map(|p| result.value(&p.name).unwrap_or(p.value))
                .collect();
            (values, flagged)
        } else {
            (values.to_vec(), false)
        };
        let (predicted, initial) = held_fit.simulate(data, &values)?;
        let mut score = Validation::of(data.x, predicted);
        if let Some(k) = offset_at {
            score = score.with_offset(data.x, values[k], on_bound_now);
        }
        score.initial = Some(initial);
        score.initial_fitted = refit;
        Ok(score)
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::fit::FitParam;
    use crate::physics::excitation::{Excitation, RotorAngle};
    use crate::physics::oscillator::Oscillator;
    use crate::physics::oscillator_params::OscillatorParams;
    use crate::simulate::Simulation;

    /// x of the forced trolley on a constant-speed rotor from (x0, v0), at 100 Hz for 10 s.
    fn run(system: OscillatorParams, omega: f64, x0: f64, v0: f64) -> (Vec<f64>, Vec<f64>) {
        let osc = Oscillator::new(system, Excitation::Rotor(RotorAngle::constant(omega)));
        let t: Vec<f64> = (0..1001).map(|i| i as f64 / 100.0).collect();
        let r = Simulation::new(&osc).initial(x0, v0).run_at(&t).unwrap();
        (r.t, r.x)
    }

    #[test]
    fn the_true_values_predict_another_drive_and_its_initial_state_is_refitted() {
        let truth = OscillatorParams::FORCED;
        // The other record: another speed, started 1 mm off and moving.
        let (t, x) = run(truth, 7.0, 1e-3, 0.01);
        let data = TrajectoryData { t: &t, x: &x };
        let fit = TrajectoryFit::new(truth, Arc::new(Excitation::None))
            .free(FitParam::new("k", 260.0))
            .free(FitParam::new("x0", 0.0))
            .free(FitParam::new("v0", 0.0))
            .excitation(Arc::new(Excitation::Rotor(RotorAngle::constant(7.0))))
            .initial(0.0, 0.0);
        let score = fit.validate(&data, &[truth.k, 0.0, 0.0]).unwrap();
        assert!(score.initial_fitted);
        let [x0, v0] = score.initial.unwrap();
        assert!(
            (x0 - 1e-3).abs() < 1e-6 && (v0 - 0.01).abs() < 1e-4,
            "{x0} {v0}"
        );
        assert!(score.rms < 1e-7, "{}", score.rms);
        // A wrong stiffness misses; held at the record's estimate, so does a wrong start.
        let wrong = fit.validate(&data, &[0.8 * truth.k, 0.0, 0.0]).unwrap();
        assert!(wrong.normalised > 0.05, "{}", wrong.normalised);
        let held = TrajectoryFit::new(
            truth,
            Arc::new(Excitation::Rotor(RotorAngle::constant(7.0))),
        )
        .free(FitParam::new("k", 260.0))
        .initial(0.0, 0.0);
        let score = held.validate(&data, &[truth.k]).unwrap();
        assert!(!score.initial_fitted && score.initial == Some([0.0, 0.0]));
        assert!(score.rms > 1e-5, "{}", score.rms);
        assert!(held.validate(&data, &[1.0, 2.0]).is_err());
    }
}
