//! The campaign's `[global]` section: the joint fit is the study's
//! ([`stf_study::joint`]); this writes its result to `DIR/global.json`.

use std::path::Path;

use anyhow::Result;
use stf_study::joint::{JointInputs, Unit};

pub use stf_study::joint::{Criteria, GlobalJson, LawJson};

use super::file::Campaign;

/// The name of the global fit's JSON in the campaign folder.
pub const GLOBAL_JSON: &str = "global.json";

/// Run `[global]` of `campaign` and write `DIR/global.json`.
pub fn write(campaign: &Campaign, out: &Path) -> Result<GlobalJson> {
    let units = campaign.units.iter().map(|u| Unit {
        number: u.number,
        record_given: u.record_given.clone(),
        record: u.record.clone(),
        experiment: u.experiment.clone(),
        conditions: u.conditions.clone(),
    });
    let inputs = JointInputs {
        path: &campaign.path,
        units: units.collect(),
        condition_units: campaign.condition_units.clone(),
        global: campaign.global.as_ref(),
    };
    let json = stf_study::joint::run(&inputs)?;
    crate::writing::write_json(&out.join(GLOBAL_JSON), &json)?;
    Ok(json)
}
