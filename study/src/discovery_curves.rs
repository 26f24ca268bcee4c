//! What `discover` writes to redraw its curves: `discovery.json`'s `fitted` block — for the
//! base and the final model, the model's fitted parameters, the fitted offset (`f_off` or
//! `x_off`), the oscillator the model ran on (refitted at trajectory level; the experiment's
//! at force level, where the force prediction does not use it) and, at trajectory level, the
//! state the simulation started from (fitted or the record's estimate) — and
//! `discovered.csv`, the measured signal with the base's and the final model's curves.
//!
//! With the record's kinematics (force level) or drive (trajectory level), read as the
//! experiment reads it, those values alone give the curves again: the test
//! `tests/discover_command.rs` redraws them.

use std::collections::BTreeMap;
use std::sync::Arc;

use anyhow::Result;
use serde::Serialize;
use stf_core::discovery::{Discovery, TrajectoryPart};
use stf_core::fit::{FittedParam, DISPLACEMENT_OFFSET, FORCE_OFFSET, INITIAL_STATE};
use stf_core::physics::force_model::ForceModel;
use stf_core::physics::oscillator_params::OscillatorParams;

use crate::outputs::columns_csv::Columns;

/// The fitted values behind one curve.
#[derive(Clone, Debug, Serialize)]
pub struct FittedModel {
    /// The model (`power_law + cubic_stiffness`).
    pub name: String,
    /// Its parameters by name, as fitted.
    pub params: BTreeMap<String, f64>,
    /// The fitted offset (`f_off`, N, or `x_off`, m), if any.
    pub offset: Option<FittedOffset>,
    /// The oscillator's parameters, all of them.
    pub system: OscillatorParams,
    /// The state the simulation started from (trajectory level).
    pub initial: Option<InitialState>,
}

/// A fitted constant offset.
#[derive(Clone, Debug, Serialize)]
pub struct FittedOffset {
    /// `f_off` or `x_off`.
    pub name: &'static str,
    /// Its value, N or m.
    pub value: f64,
}

/// The state (x0 m, v0 m/s) a simulation started from.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct InitialState {
    /// Displacement, m.
    pub x0: f64,
    /// Velocity, m/s.
    pub v0: f64,
    /// Fitted with the model (`true`), or the record's estimate less the offset.
    pub fitted: bool,
}

/// The base's and the final model's values (`fitted` in discovery.json).
#[derive(Clone, Debug, Serialize)]
pub struct FittedCurves {
    /// The base model, fitted on the whole record.
    pub base: FittedModel,
    /// The final model, fitted on the whole record.
    #[serde(rename = "final")]
    pub final_model: FittedModel,
}

/// `model`'s parameters by name with `values` (in its order), and the offset `name` of the
/// fit's `params`.
fn fitted(
    model: &Arc<dyn ForceModel>,
    values: &[f64],
    params: &[FittedParam],
    offset: &'static str,
    system: OscillatorParams,
) -> FittedModel {
    let value_of = |name: &str| params.iter().find(|p| p.name == name).map(|p| p.value);
    FittedModel {
        name: model.name().to_string(),
        params: model
            .params()
            .iter()
            .zip(values)
            .map(|(s, &v)| (s.name.clone(), v))
            .collect(),
        offset: value_of(offset).map(|value| FittedOffset {
            name: offset,
            value,
        }),
        system,
        initial: None,
    }
}

/// The values behind a force-level discovery's curves; `system` is the experiment's.
pub fn force_curves(d: &Discovery, system: OscillatorParams) -> FittedCurves {
    let of = |model, values, params| fitted(model, values, params, FORCE_OFFSET, system);
    FittedCurves {
        base: of(&d.base_model, &d.base_values, &d.base_params),
        final_model: of(&d.final_model, &d.final_values, &d.final_params),
    }
}

/// The values behind a trajectory-level discovery's curves.
pub fn trajectory_curves(d: &Discovery, tf: &TrajectoryPart) -> FittedCurves {
    let of = |model, values, params: &[FittedParam], system, [x0, v0]: [f64; 2]| {
        let initial = InitialState {
            x0,
            v0,
            fitted: params.iter().any(|p| p.name == INITIAL_STATE[0]),
        };
        FittedModel {
            initial: Some(initial),
            ..fitted(model, values, params, DISPLACEMENT_OFFSET, system)
        }
    };
    FittedCurves {
        base: of(
            &d.base_model,
            &d.base_values,
            &d.base_params,
            tf.system_before,
            tf.initial_before,
        ),
        final_model: of(
            &d.final_model,
            &d.final_values,
            &d.final_params,
            tf.system_after,
            tf.initial_after,
        ),
    }
}

/// The text of `discovered.csv`: t, the measured `signal` (`f_stf` or `x`) and the base's
/// and the final model's curves (`signal_base`, `signal_final`), at full precision.
pub fn discovered_csv(
    signal: &str,
    t: &[f64],
    measured: &[f64],
    (base, final_curve): (&[f64], &[f64]),
) -> Result<Vec<u8>> {
    Columns::new()
        .with("t", t)
        .with(signal, measured)
        .with(format!("{signal}_base"), base)
        .with(format!("{signal}_final"), final_curve)
        .to_csv()
}
