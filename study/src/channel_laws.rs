//! Parameters that follow a measured channel, as an experiment's entries give them
//! (`F_y = { law = "affine", channel = "u_ctrl", base = 20.0 }`): the part of the sum that owns
//! the parameter is wrapped in core's [`ChannelLaw`] over the record's channel, so the law's
//! coefficients (`F_y_base`, `F_y_gain`, `F_y_exp`) take the parameter's place among the
//! sum's parameters; the starts the entry gives are then set on them. A parameter no part
//! has, a name two parts share, or a channel the record lacks is an error naming the file,
//! line and key.

use std::path::Path;
use std::sync::Arc;

use anyhow::Result;
use stf_core::fit::FitParam;
use stf_core::physics::channel_law::{ChannelLaw, Law};
use stf_core::physics::force_model::ForceModel;
use stf_core::physics::model_sum::ModelSum;

use crate::channels::Channels;
use crate::experiment::{error_at, LawGiven, ModelEntry};

/// A law put on a part: which part, its parameter (the part's own name for it) and the
/// entry's starts of the coefficients.
pub struct Applied {
    model: String,
    param: String,
    law: Law,
    starts: Vec<Option<f64>>,
}

/// Wrap the parts whose parameters `entries` give laws of `channels`; what was put where.
pub fn wrap(
    parts: &mut [Arc<dyn ForceModel>],
    entries: &[ModelEntry],
    file: &Path,
    channels: &Channels,
) -> Result<Vec<Applied>> {
    let mut applied = Vec::new();
    for entry in entries {
        for given in &entry.params {
            let Some(law) = &given.law else { continue };
            let key = format!("{}.params.{}", entry.key, given.name);
            let at = |msg: String| error_at(file, given.line, &key, msg);
            let (part, param) = owner(parts, &given.name).map_err(at)?;
            let channel = channels
                .get(&law.channel)
                .ok_or_else(|| at(missing(law, channels)))?;
            let wrapped = ChannelLaw::new(parts[part].clone(), &param, law.law, channel.clone())
                .map_err(|e| at(e.to_string()))?;
            parts[part] = Arc::new(wrapped);
            applied.push(Applied {
                model: parts[part].name().to_string(),
                param,
                law: law.law,
                starts: law.starts.clone(),
            });
        }
    }
    Ok(applied)
}

/// Set the entries' starts of the laws' coefficients on `params` (the settings of `sum`).
pub fn start(params: &mut [FitParam], sum: &ModelSum, applied: &[Applied]) {
    for a in applied {
        for (suffix, value) in a.law.coefficients().iter().zip(&a.starts) {
            let name = format!("{}.{}_{suffix}", a.model, a.param);
            if let (Some(v), Some(i)) = (value, sum.param_index(&name)) {
                params[i].value = *v;
            }
        }
    }
}

/// The part that owns the parameter `name` (bare, or prefixed with its model's name
/// `yield.F_y`) and the part's own name for it.
fn owner(parts: &[Arc<dyn ForceModel>], name: &str) -> Result<(usize, String), String> {
    let has = |p: &Arc<dyn ForceModel>, n: &str| p.params().iter().any(|s| s.name == n);
    if let Some((model, bare)) = name.split_once('.') {
        if let Some(i) = parts.iter().position(|p| p.name() == model && has(p, bare)) {
            return Ok((i, bare.to_string()));
        }
    }
    let owners: Vec<usize> = (0..parts.len()).filter(|&i| has(&parts[i], name)).collect();
    match owners[..] {
        [i] => Ok((i, name.to_string())),
        [] => {
            let known: Vec<String> = parts
                .iter()
                .flat_map(|p| p.params().iter().map(|s| s.name.clone()))
                .collect();
            Err(format!(
                "no model of the entry has a parameter `{name}` to follow a channel{}; their \
                 parameters: {}",
                stf_core::names::did_you_mean(name, known.iter().map(String::as_str)),
                known.join(", ")
            ))
        }
        _ => {
            let names: Vec<String> = owners
                .iter()
                .map(|&i| format!("`{}.{name}`", parts[i].name()))
                .collect();
            Err(format!(
                "`{name}` is a parameter of more than one model: name the one that follows \
                 the channel ({})",
                names.join(" or ")
            ))
        }
    }
}

/// Why a law's channel is not there.
fn missing(law: &LawGiven, channels: &Channels) -> String {
    let c = &law.channel;
    if channels.is_empty() {
        format!(
            "follows channel `{c}`, but there is no record to read it from here (a law needs \
             the record's column `{c}`; `[simulate]` makes one with `channels.{c} = {{ levels = \
             [0.0, 1.0], hold = 2.0 }}`)"
        )
    } else {
        let known = channels.names();
        format!(
            "follows channel `{c}`, which is not among the record's channels{}: {}",
            stf_core::names::did_you_mean(c, known.iter().copied()),
            known.join(", ")
        )
    }
}
