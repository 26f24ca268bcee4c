//! The records of a `[global]` fit, each read with its own experiment's layout and
//! kinematics (as the per-record `fit` reads it) and fitted alone with the global model, as
//! `fit` would fit it (the per-record alternative, and the joint fit's start):
//!
//! - at force level, against its `f_stf` along its kinematics;
//! - at trajectory level, against its `x`, simulating the oscillator of the record's own
//!   experiment (its `[system]`: a record taken at another forcing amplitude names an
//!   experiment with that `F0`) with the global experiment's model, fit settings, integrator
//!   and `[fit] system` / `offset` / `initial` choices.
//!
//! The joint fit then gives the model's parameters the bounds that the data of all training
//! records together call for ([`rebound`]), as a per-record fit widens them to its record's.

use anyhow::{bail, Result};
use stf_core::data::record_bounds::DataScales;
use stf_core::fit::{FitParam, FORCE_OFFSET};

use super::fit::{self as global_fit, JointRecord, RecordFit};
use super::prediction_cache::PredictionCache;
use super::spec::GlobalSpec;
use super::Unit;
use crate::experiment::{Experiment, FitLevel};
use crate::fitting::{self, ModelFit, Predictor};
use crate::model_config::{configure_for, ConfiguredModel};
use crate::shown_units::ShownUnits;

/// A record loaded and fitted alone.
pub struct Loaded<'c> {
    /// Its unit.
    pub unit: &'c Unit,
    /// Its data and predictor in the joint problem.
    pub joint: JointRecord,
    /// Its own fit of the global model.
    pub own: ModelFit,
    /// The units its motion and parameters are shown in.
    pub units: ShownUnits,
}

/// The global model configured for data of `scales` (bounds widened to them).
pub fn configure(
    spec: &GlobalSpec,
    gexp: &Experiment,
    scales: &DataScales,
) -> Result<ConfiguredModel> {
    configure_for(
        std::slice::from_ref(&spec.entry),
        &gexp.path,
        &gexp.dir,
        &gexp.scripts,
        Some(scales),
        &crate::channels::Channels::none(),
    )
}

/// Read `unit`'s record with its experiment's layout, derive its kinematics, fit the global
/// model to it alone at the spec's level (as `fit` would, with the global experiment's
/// settings).
pub fn load_one<'c>(spec: &GlobalSpec, gexp: &Experiment, unit: &'c Unit) -> Result<Loaded<'c>> {
    let mut exp = Experiment::load(&unit.experiment)?.with_data_file(unit.record.clone());
    let data = fitting::load_data_at(&mut exp, Some(spec.level))?;
    if data.level != spec.level {
        bail!("the record cannot be fitted at the global fit's level");
    }
    // The record's own oscillator (after `load_data_at`, which may take it from the record);
    // everything else the global experiment's.
    let mut fexp = gexp.clone();
    fexp.system = exp.system;
    fexp.system_given = exp.system_given;
    let configured = configure(spec, gexp, &data.scales(&fexp.system))?;
    let hidden = crate::observer::Silent;
    let own = fitting::fit_model(&fexp, &data, Some(&configured), &hidden)?;
    let k = &data.kinematics;
    let (f, fit, params) = match (&own.predictor, spec.level) {
        (Predictor::Trajectory(fit), FitLevel::Trajectory) => (
            k.recovered_force(&fexp.system),
            RecordFit::Trajectory {
                fit: fit.clone(),
                t: data.record.t.clone(),
                x: data.record.x.clone(),
            },
            fit.free_params().to_vec(),
        ),
        _ => {
            let mut params = configured.params.clone();
            params.extend(gexp.fit.offset.then(force_offset));
            let fit = global_fit::predictor(
                configured.model.clone(),
                &configured.params,
                gexp.fit.offset,
            );
            let f = data.record.f_stf.clone().unwrap_or_default();
            (f, RecordFit::Force(fit), params)
        }
    };
    let joint = JointRecord {
        t: k.t.clone(),
        x: k.x.clone(),
        v: k.v.clone(),
        a: k.a.clone(),
        f,
        fit,
        params,
        conditions: unit.conditions.clone(),
        cache: PredictionCache::default(),
    };
    Ok(Loaded {
        unit,
        joint,
        own,
        units: data.units,
    })
}

/// The force offset a force-level fit frees with `[fit] offset = true`.
fn force_offset() -> FitParam {
    FitParam::new(FORCE_OFFSET, 0.0).bounds(-100.0, 100.0)
}

/// The data scales of `records` together (the model's bounds are widened to them as a
/// per-record fit widens them to its record's): the measured force at force level, the
/// force recovered with each record's oscillator at trajectory level.
pub fn union_scales<'a>(records: impl Iterator<Item = &'a JointRecord> + Clone) -> DataScales {
    let cat = |f: fn(&JointRecord) -> &Vec<f64>| -> Vec<f64> {
        records.clone().flat_map(|r| f(r).iter().copied()).collect()
    };
    DataScales::of(
        &cat(|r| &r.f),
        &cat(|r| &r.x),
        &cat(|r| &r.v),
        &cat(|r| &r.a),
    )
}

/// `record`'s parameters with the model's start values and bounds of `configured` (the
/// model configured for all training records), by name; the others (offsets, the
/// oscillator's, the initial state) as they were.
pub fn rebound(record: &mut JointRecord, configured: &ConfiguredModel) {
    for p in &mut record.params {
        if let Some(c) = configured.params.iter().find(|c| c.name == p.name) {
            *p = c.clone();
        }
    }
}
