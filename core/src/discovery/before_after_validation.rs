//! A discovery's base and final models scored on a record neither was fitted to: the error
//! before and after the effects were added, where the held-out cycles of the same record can
//! only say it of that record.
//!
//! At force level ([`Discovery::validate`]) each model predicts the STF force from the other
//! record's kinematics with its fitted values. An offset the discovery fitted belongs to the
//! sensor: it is fitted again on the other record as every offset is (from the least-squares
//! value, bounds from that record's scale: [`ForceFit::validate`]), so a record whose sensor
//! reads 150 N off is scored on the model's error, not on the two records' difference. At trajectory level
//! ([`Discovery::validate_trajectory`]) each is simulated with the oscillator as refitted with
//! it, driven by the other record's drive, from that record's initial state — refitted on it
//! when the discovery fitted `x0`, `v0`, else its estimate less the offset — everything else
//! as fitted but the displacement offset, fitted again on that record
//! ([`crate::fit::TrajectoryFit::validate`]).

use std::sync::Arc;

use super::error::DiscoveryError;
use super::findings::Discovery;
use crate::data::force_data::ForceData;
use crate::fit::{
    FitError, FitParam, FittedParam, ForceFit, TrajectoryData, TrajectoryFit, Validation,
    DISPLACEMENT_OFFSET, FORCE_OFFSET, INITIAL_STATE,
};
use crate::physics::force_model::ForceModel;
use crate::physics::oscillator_params::OscillatorParams;

/// The base's and the final model's errors on another record.
#[derive(Clone, Debug, PartialEq)]
pub struct DiscoveryValidation {
    /// The base model, as fitted on the discovery's record.
    pub before: Validation,
    /// The final model, as fitted on the discovery's record.
    pub after: Validation,
}

/// A model as fitted by the discovery: the model, its values and its fitted parameters.
type Fitted<'a> = (&'a Arc<dyn ForceModel>, &'a [f64], &'a [FittedParam]);

/// The value of `name` among a fit's parameters.
fn value_of(params: &[FittedParam], name: &str) -> Option<f64> {
    params.iter().find(|p| p.name == name).map(|p| p.value)
}

/// The error of `model` with `values` and the offset of `params` on `data`.
fn force_score((model, values, params): Fitted, data: &ForceData) -> Result<Validation, FitError> {
    let mut fit = ForceFit::new(model.clone());
    let mut all = values.to_vec();
    if let Some(offset) = value_of(params, FORCE_OFFSET) {
        fit = fit.offset(FitParam::new(FORCE_OFFSET, offset));
        all.push(offset);
    }
    fit.validate(data, &all)
}

/// The error on `data` of `model` with `values` on the oscillator `system`, with the offset
/// and (refitted) initial state of `params`.
fn trajectory_score(
    (model, values, params): Fitted,
    system: OscillatorParams,
    on: &TrajectoryFit,
    data: &TrajectoryData,
) -> Result<Validation, FitError> {
    let mut fit = TrajectoryFit::new(system, on.excitation.clone())
        .model(model.clone(), values.to_vec())
        .sim_settings(on.sim.clone());
    // As the discovery's simulations: a fitted start is refitted from the estimate, a start
    // not fitted is the estimate less the offset.
    let offset = value_of(params, DISPLACEMENT_OFFSET).unwrap_or(0.0);
    let refit = value_of(params, INITIAL_STATE[0]).is_some();
    if let Some((x0, v0)) = on.initial {
        fit = fit.initial(if refit { x0 } else { x0 - offset }, v0);
    }
    let mut held = Vec::new();
    for name in std::iter::once(DISPLACEMENT_OFFSET).chain(INITIAL_STATE) {
        if let Some(v) = value_of(params, name) {
            fit = fit.free(FitParam::new(name, v));
            held.push(v);
        }
    }
    fit.validate(data, &held)
}

impl Discovery {
    /// The base's and the final model's errors on another record's kinematics and force
    /// (force-level discovery).
    pub fn validate(&self, data: &ForceData) -> Result<DiscoveryValidation, DiscoveryError> {
        self.before_after(|fitted, _| force_score(fitted, data))
    }

    /// The base's and the final model's errors on another record's displacement `data`
    /// (trajectory-level discovery; an error for a force-level one). `on` gives that
    /// record's drive, its initial-state estimate and the integrator; its oscillator, model
    /// and free parameters are not used.
    pub fn validate_trajectory(
        &self,
        on: &TrajectoryFit,
        data: &TrajectoryData,
    ) -> Result<DiscoveryValidation, DiscoveryError> {
        let Some(part) = &self.trajectory else {
            return Err(DiscoveryError::BadSettings(
                "a force-level discovery has no oscillator to simulate".into(),
            ));
        };
        let systems = [part.system_before, part.system_after];
        self.before_after(|fitted, i| trajectory_score(fitted, systems[i], on, data))
    }

    /// `score` of the base model (0) and of the final one (1), an error naming the model.
    fn before_after(
        &self,
        score: impl Fn(Fitted, usize) -> Result<Validation, FitError>,
    ) -> Result<DiscoveryValidation, DiscoveryError> {
        let fitted: [Fitted; 2] = [
            (&self.base_model, &self.base_values, &self.base_params),
            (&self.final_model, &self.final_values, &self.final_params),
        ];
        let [before, after] = [0, 1].map(|i| {
            score(fitted[i], i).map_err(|source| DiscoveryError::Fit {
                model: fitted[i].0.name().to_string(),
                source,
            })
        });
        Ok(DiscoveryValidation {
            before: before?,
            after: after?,
        })
    }
}
