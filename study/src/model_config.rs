//! Force models as an experiment file names them: built-ins or scripts, summed, with their
//! parameter values, bounds and fixed/free switches resolved once. The entries come checked
//! from the experiment file (`crate::experiment::ModelEntry`); what needs the registry —
//! whether a name or script resolves, whether a parameter is the model's and within its
//! bounds — is checked here. A parameter's checked setting is core's
//! [`stf_core::fit::FitParam`] (value, bounds, fixed), what every fit takes.

use std::path::Path;
use std::sync::Arc;

use anyhow::{anyhow, Result};
use stf_core::data::record_bounds::{widened, DataScales};
use stf_core::fit::FitParam;
use stf_core::physics::force_model::ForceModel;
use stf_core::physics::model_sum::{neutral_amplitude, ModelSum};

use stf_plugins::ScriptRun;

use crate::channels::Channels;
use crate::experiment::context::place;
use crate::experiment::{error_at, ModelEntry, ModelSource, ParamGiven};

/// A model ready to plug into the oscillator.
#[derive(Clone)]
pub struct ConfiguredModel {
    /// The model (a sum of the entry's parts).
    pub model: Arc<dyn ForceModel>,
    /// Parameter settings (name in the sum, value, bounds, fixed), in the model's order.
    pub params: Vec<FitParam>,
    /// The parts summed, in order.
    pub parts: Vec<Arc<dyn ForceModel>>,
    /// The record's channels its parameters' laws follow (none for constant parameters):
    /// the model reads them from the record it was configured for.
    pub channels: Vec<String>,
}

impl ConfiguredModel {
    /// The sum of all parts but the last, with the settings of their parameters, and the
    /// index in `params` of the last part's amplitude (its first parameter, by the models'
    /// convention) with its neutral start ([`neutral_amplitude`]): `None` for a single
    /// model, or when the last part's amplitude cannot start neutral (fixed, no positive
    /// default, or bounds that exclude the neutral value).
    pub fn base(&self) -> Option<(ConfiguredModel, (usize, f64))> {
        let (last, rest) = self.parts.split_last()?;
        if rest.is_empty() {
            return None;
        }
        let n_base = self.params.len() - last.params().len();
        let amp = self.params.get(n_base)?;
        let neutral = neutral_amplitude(last.as_ref())?;
        if amp.fixed || !(amp.min..=amp.max).contains(&neutral) {
            return None;
        }
        let sum = ModelSum::new(rest.to_vec()).ok()?;
        let params = sum
            .params()
            .iter()
            .zip(&self.params)
            .map(|(spec, p)| FitParam {
                name: spec.name.clone(),
                ..p.clone()
            })
            .collect();
        let base = ConfiguredModel {
            model: Arc::new(sum),
            params,
            parts: rest.to_vec(),
            channels: self.channels.clone(),
        };
        Some((base, (n_base, neutral)))
    }

    /// This model started from `base_values` (the fitted values of [`Self::base`]'s
    /// parameters, in order) with the last part's amplitude (index and neutral value `amp`)
    /// neutral; its other parameters as they are. Fixed parameters keep their values.
    pub fn started_from(&self, base_values: &[f64], amp: (usize, f64)) -> ConfiguredModel {
        let mut out = self.clone();
        for (p, &v) in out.params.iter_mut().zip(base_values) {
            if !p.fixed && v.is_finite() {
                p.value = v.clamp(p.min, p.max);
            }
        }
        out.params[amp.0].value = amp.1;
        out
    }

    /// The parameter values, in order.
    pub fn values(&self) -> Vec<f64> {
        self.params.iter().map(|p| p.value).collect()
    }
}

/// Resolve a model name or script path (relative to `dir`) to a model, through the registry;
/// scripts load in `run` (the experiment's `[scripts]` limits and operation counters).
pub fn resolve(spec: &str, dir: &Path, run: &ScriptRun) -> Result<Arc<dyn ForceModel>> {
    Ok(stf_plugins::registry::Registry::in_run(run.clone()).resolve(spec, dir)?)
}

/// [`resolve`] for a path given as a script (`script = "…"`): a folder or a file that is not
/// a `.rhai` script is named as such.
pub fn resolve_script(path: &str, dir: &Path, run: &ScriptRun) -> Result<Arc<dyn ForceModel>> {
    Ok(stf_plugins::registry::Registry::in_run(run.clone()).resolve_script(path, dir)?)
}

/// Build one model from experiment entries: the parts of every entry are summed (one entry
/// for a `[[models]]` item, all of them for `[[simulate.truth]]`), then each entry's `params`
/// are applied. `file` is the experiment file, `dir` its folder, `run` where scripts load.
/// For a record of sizes `scales`, each model's bounds are widened where the record needs it
/// ([`widened`]) before the entries' own values and bounds apply. A parameter given a law
/// (`F_y = { law = "affine", channel = "u_ctrl" }`) becomes its law of the record's
/// `channels` (core's `ChannelLaw`, wrapping its part: `crate::channel_laws`): its coefficients take its place.
pub fn configure_for(
    entries: &[ModelEntry],
    file: &Path,
    dir: &Path,
    run: &ScriptRun,
    scales: Option<&DataScales>,
    channels: &Channels,
) -> Result<ConfiguredModel> {
    let mut parts = Vec::new();
    for entry in entries {
        for (i, spec) in entry.specs().enumerate() {
            let model = match &entry.source {
                ModelSource::Script(path) if i == 0 => resolve_script(path, dir, run),
                _ => resolve(spec, dir, run),
            };
            // The cause stays typed (a script's error is a model error to a front end).
            let model = model.map_err(|e| e.context(place(file, entry.line, &entry.key)))?;
            parts.push(match scales {
                Some(s) => widened(model, s),
                None => model,
            });
        }
    }
    let laws = crate::channel_laws::wrap(&mut parts, entries, file, channels)?;
    let sum = ModelSum::new(parts).map_err(|e| {
        let line = entries.first().map_or(0, |e| e.line);
        anyhow!("{}:{}: {}", file.display(), line, e)
    })?;
    let mut params: Vec<FitParam> = sum.params().iter().map(FitParam::from_spec).collect();
    crate::channel_laws::start(&mut params, &sum, &laws);
    let errors: Vec<anyhow::Error> = entries
        .iter()
        .flat_map(|entry| entry.params.iter().map(move |given| (entry, given)))
        .filter(|(_, given)| given.law.is_none())
        .filter_map(|(entry, given)| apply(&mut params, &sum, entry, given, file).err())
        .collect();
    if !errors.is_empty() {
        return Err(crate::experiment::Mistakes::of(file, errors));
    }
    Ok(ConfiguredModel {
        channels: crate::channels::named_by(entries),
        parts: sum.parts().to_vec(),
        model: Arc::new(sum),
        params,
    })
}

/// Set the parameter `given` of `entry` in `params` (the settings of `sum`): it must be one
/// of the sum's parameters, and its value within its bounds.
fn apply(
    params: &mut [FitParam],
    sum: &ModelSum,
    entry: &ModelEntry,
    given: &ParamGiven,
    file: &Path,
) -> Result<()> {
    let name = &given.name;
    let at = |msg: String| {
        error_at(
            file,
            given.line,
            &format!("{}.params.{name}", entry.key),
            msg,
        )
    };
    let i = sum.param_index(name).ok_or_else(|| {
        let known: Vec<&str> = sum.params().iter().map(|s| s.name.as_str()).collect();
        at(format!(
            "`{}` has no parameter `{name}`{}; its parameters: {}",
            sum.name(),
            stf_core::names::did_you_mean(name, known.iter().copied()),
            known.join(", ")
        ))
    })?;
    let p = &mut params[i];
    given.set.apply(p);
    if !(p.value.is_finite() && p.min <= p.value && p.value <= p.max) {
        return Err(at(out_of_bounds(name, p)));
    }
    Ok(())
}

/// Why `p`'s value is refused, and the fix: the bounds widened in the same entry, with a
/// bound past the value (`K = { value = 50, max = 100 }`).
fn out_of_bounds(name: &str, p: &FitParam) -> String {
    use crate::digits::shown;
    let past = |x: f64, up: bool| match (x == 0.0, (x > 0.0) == up) {
        (true, _) => {
            if up {
                1.0
            } else {
                -1.0
            }
        }
        (false, true) => 2.0 * x,
        (false, false) => x / 2.0,
    };
    let widened = if p.value > p.max {
        format!("max = {}", shown(past(p.value, true)))
    } else {
        format!("min = {}", shown(past(p.value, false)))
    };
    format!(
        "{} lies outside its bounds [{}, {}]: give a start value within them, or widen them \
         in this entry: `{name} = {{ value = {}, {widened} }}`",
        shown(p.value),
        shown(p.min),
        shown(p.max),
        shown(p.value)
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    fn models_of(text: &str) -> Result<ConfiguredModel> {
        let exp = crate::experiment::parse_exp(text)?;
        configure_for(
            &exp.models,
            &exp.path,
            &exp.dir,
            &exp.scripts,
            None,
            &Channels::none(),
        )
    }

    #[test]
    fn a_misspelled_model_lists_the_known_ones_with_file_line_and_key() {
        let err = models_of("\n[[models]]\nname = \"powr_law\"\n")
            .err()
            .unwrap();
        let msg = format!("{err:#}");
        assert!(
            msg.contains("exp.toml:2") && msg.contains("models[0]"),
            "{msg}"
        );
        assert!(
            msg.contains("powr_law") && msg.contains("power_law"),
            "{msg}"
        );
    }

    #[test]
    fn a_misspelled_parameter_lists_the_model_s_parameters() {
        let err = models_of("[[models]]\nname = \"power_law\"\nparams = { k = 2.0 }\n")
            .err()
            .unwrap();
        let msg = format!("{err:#}");
        assert!(
            msg.contains("exp.toml:3") && msg.contains("models[0].params.k"),
            "{msg}"
        );
        assert!(
            msg.contains("(did you mean `K`?); its parameters: K, n"),
            "{msg}"
        );
    }

    #[test]
    fn a_bound_that_excludes_its_value_is_an_error() {
        let err = models_of(
            "[[models]]\nname = \"power_law\"\nparams = { n = { value = 0.5, min = 1.0 } }\n",
        )
        .err()
        .unwrap();
        let msg = format!("{err:#}");
        assert!(
            msg.contains("exp.toml:3") && msg.contains("models[0].params.n"),
            "{msg}"
        );
        assert!(
            msg.contains("0.5 lies outside its bounds [1, ")
                && msg.contains("widen them in this entry: `n = { value = 0.5, min = 0.25 }`"),
            "{msg}"
        );
    }

    #[test]
    fn sums_and_prefixed_names_resolve() {
        let m = models_of(
            "[[models]]\nname = \"power_law\"\nplus = [\"added_mass\"]\nparams = { K = 3.0, \"added_mass.m_a\" = 1.0 }\n",
        )
        .unwrap();
        assert_eq!(m.model.name(), "power_law + added_mass");
        assert_eq!(m.values()[0], 3.0);
        assert_eq!(m.values()[2], 1.0);
    }
}
