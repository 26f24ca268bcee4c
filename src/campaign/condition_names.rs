//! A condition's name is a column of `campaign.csv`, beside the columns every campaign has
//! (`unit`, `status`, `model`, `rms` …) and a column per fitted parameter (`K`,
//! `K_std_error`, `n` …). A condition named as one of those would make two columns of one
//! name, which a spreadsheet or `pandas.read_csv` reads as the wrong one. Such a name is
//! refused when the campaign file is read, before any unit runs, rather than renamed in the
//! table: the user's own name stays the column's name, and the error says which column it
//! would duplicate and to choose another.

use std::collections::BTreeMap;

use stf_core::fit::{DISPLACEMENT_OFFSET, FORCE_OFFSET, INITIAL_STATE};

use super::csv_columns::{is_fixed_column, STD_ERROR_SUFFIX};
use crate::experiment::{Experiment, FitLevel, ModelEntry};
use crate::model_config::{configure_for, ConfiguredModel};

/// Why `name` cannot be a condition's name, if it cannot: a column of `campaign.csv` that
/// every campaign has, or a parameter's standard-error column.
pub fn fixed_clash(name: &str) -> Option<String> {
    if is_fixed_column(name) {
        Some(format!(
            "`{name}` is a column campaign.csv always has: a condition of that name would \
             make a second `{name}` column; choose another name (e.g. `{name}_condition`)"
        ))
    } else if name.ends_with(STD_ERROR_SUFFIX) {
        Some(format!(
            "`{name}` ends in `{STD_ERROR_SUFFIX}`, the columns of parameters' standard errors \
             in campaign.csv: choose another name"
        ))
    } else {
        None
    }
}

/// `entry` of `exp` configured alone, as a record's run configures it (no data scales; each
/// channel a parameter follows stood in for): its parameters, in the order its values take.
pub(super) fn configure_entry(
    exp: &Experiment,
    entry: &ModelEntry,
) -> anyhow::Result<ConfiguredModel> {
    let one = std::slice::from_ref(entry);
    let channels = stf_study::channels::Channels::stand_ins_for(one);
    configure_for(one, &exp.path, &exp.dir, &exp.scripts, None, &channels)
}

/// The parameters a run of `exp` may write as columns of `campaign.csv`, each with where it
/// comes from (`a parameter of power_law`): its models' parameters, the oscillator's
/// parameters it fits, its offset and initial state; with `discovers`, every built-in
/// model's (a discovery adds effects).
pub fn parameter_columns(exp: &Experiment, discovers: bool) -> BTreeMap<String, String> {
    let mut names = BTreeMap::new();
    for entry in &exp.models {
        // A model that does not resolve fails its unit with its own message.
        if let Ok(model) = configure_entry(exp, entry) {
            let of = entry.specs().collect::<Vec<_>>().join(" + ");
            for p in &model.params {
                names
                    .entry(p.name.clone())
                    .or_insert_with(|| format!("a parameter of {of}"));
            }
        }
    }
    if discovers {
        for listing in stf_plugins::registry::Registry::new().list() {
            for p in &listing.params {
                names.entry(p.name.to_string()).or_insert_with(|| {
                    format!("a parameter of {}, which discovery may add", listing.name)
                });
            }
        }
    }
    for p in &exp.fit.system_free {
        names
            .entry(p.name().to_string())
            .or_insert_with(|| "an oscillator parameter `[fit] system` fits".into());
    }
    if exp.fit.offset {
        for name in [FORCE_OFFSET, DISPLACEMENT_OFFSET] {
            names
                .entry(name.to_string())
                .or_insert_with(|| "the offset `[fit] offset` fits".into());
        }
    }
    if exp.fit.fit_initial && exp.fit.level != Some(FitLevel::Force) {
        for name in INITIAL_STATE {
            names
                .entry(name.to_string())
                .or_insert_with(|| "the initial state a trajectory fit fits".into());
        }
    }
    names
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_table_s_own_columns_are_refused() {
        for name in ["n", "K", "amplitude"] {
            assert!(fixed_clash(name).is_none(), "{name}");
        }
        for name in ["model", "rms", "status", "unit", "error", "K_std_error"] {
            assert!(fixed_clash(name).is_some(), "{name}");
        }
    }

    #[test]
    fn a_model_s_parameters_are_columns() {
        let exp = crate::experiment::Experiment::parse(
            std::path::Path::new("e.toml"),
            "[[models]]\nname = \"power_law\"\n[fit]\nlevel = \"force\"\noffset = true\n",
        )
        .unwrap();
        let names = parameter_columns(&exp, false);
        assert_eq!(names["n"], "a parameter of power_law");
        assert!(names.contains_key("K") && names.contains_key("f_off"));
        assert!(!names.contains_key("x0") && !names.contains_key("k3"));
        assert!(parameter_columns(&exp, true).contains_key("k3"));
    }
}
