//! A discovery's base and final models scored on a record neither was fitted to: the error
//! before and after the effects were added, where the held-out cycles of the same record can
//! only say it of that record.
//!
//! At force level ([`Discovery::validate`]) each model predicts the STF force from the other
//! record's kinematics with its fitted values and offset. At trajectory level
//! ([`Discovery::validate_trajectory`]) each is simulated with the oscillator as refitted with
//! it, driven by the other record's drive, from that record's initial state — refitted on it
//! when the discovery fitted `x0`, `v0`, else its estimate less the offset — everything else
//! as fitted ([`crate::fit::TrajectoryFit::validate`]).

use std::sync::Arc;

use super::error::DiscoveryError;
use super::findings::Discovery;
use crate::data::force_data::ForceData;
use crate::fit::{
    FitParam, FittedParam, ForceFit, TrajectoryData, TrajectoryFit, Validation,
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

/// The value of `name` among a fit's parameters.
fn value_of(params: &[FittedParam], name: &str) -> Option<f64> {
    params.iter().find(|p| p.name == name).map(|p| p.value)
}

/// The error of `model` with `values` and the offset of `params` on `data`.
fn force_score(
    model: &Arc<dyn ForceModel>,
    values: &[f64],
    params: &[FittedParam],
    data: &ForceData,
) -> Result<Validation, DiscoveryError> {
    let mut fit = ForceFit::new(model.clone());
    let mut all = values.to_vec();
    if let Some(offset) = value_of(params, FORCE_OFFSET) {
        fit = fit.offset(FitParam::new(FORCE_OFFSET, offset));
        all.push(offset);
    }
    fit.validate(data, &all)
        .map_err(|source| DiscoveryError::Fit {
            model: model.name().to_string(),
            source,
        })
}

impl Discovery {
    /// The base's and the final model's errors on another record's kinematics and force
    /// (force-level discovery).
    pub fn validate(&self, data: &ForceData) -> Result<DiscoveryValidation, DiscoveryError> {
        Ok(DiscoveryValidation {
            before: force_score(&self.base_model, &self.base_values, &self.base_params, data)?,
            after: force_score(
                &self.final_model,
                &self.final_values,
                &self.final_params,
                data,
            )?,
        })
    }
}

/// The error on `data` of `model` with `values` on the oscillator `system`, with the offset
/// and (refitted) initial state of `params`.
fn trajectory_score(
    (model, values, system): (&Arc<dyn ForceModel>, &[f64], OscillatorParams),
    params: &[FittedParam],
    on: &TrajectoryFit,
    data: &TrajectoryData,
) -> Result<Validation, DiscoveryError> {
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
            let fixed = name == DISPLACEMENT_OFFSET;
            fit = fit.free(FitParam::new(name, v).fixed(fixed));
            held.push(v);
        }
    }
    fit.validate(data, &held)
        .map_err(|source| DiscoveryError::Fit {
            model: model.name().to_string(),
            source,
        })
}

impl Discovery {
    /// The base's and the final model's errors on another record's displacement `data`
    /// (trajectory-level discovery; an error for a force-level one). `on` gives that
    /// record's drive, its initial-state estimate and the integrator; its oscillator, model
    /// and free parameters are not used.
    pub fn validate_trajectory(
        &self,
        on: &TrajectoryFit,
        data: &TrajectoryData,
    ) -> Result<DiscoveryValidation, DiscoveryError> {
        let (d, Some(part)) = (self, &self.trajectory) else {
            return Err(DiscoveryError::BadSettings(
                "a force-level discovery has no oscillator to simulate".into(),
            ));
        };
        Ok(DiscoveryValidation {
            before: trajectory_score(
                (&d.base_model, &d.base_values, part.system_before),
                &d.base_params,
                on,
                data,
            )?,
            after: trajectory_score(
                (&d.final_model, &d.final_values, part.system_after),
                &d.final_params,
                on,
                data,
            )?,
        })
    }
}
