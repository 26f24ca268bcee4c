//! The final model of a discovery as an experiment's `[[models]]` entry that loads as it is:
//! its terms by the names (or script paths) an experiment gives them, each parameter keyed by
//! the name the entry's own sum gives it (bare, or `model.P` where two parts share `P`), and an
//! effect "P follows channel c" (the term `part.P~c`: the part again with its amplitude a
//! linear law P_gain·c, added to the part) folded into the part as the affine law the two add
//! up to, `P = { law = "affine", channel = "c", base = P, gain = P_gain }`, the syntax an
//! experiment gives a law in. The law term's copies of the part's other parameters (its own
//! `v_s`, say) give way to the part's: the entry starts a refit at the discovery's fit (exactly
//! so for a part linear in its amplitude whose other parameters the two terms share).

use anyhow::Result;
use indexmap::IndexMap;
use stf_core::fit::FittedParam;
use stf_core::physics::channel_law::Law;

use crate::experiment::Experiment;
use crate::model_config::resolve;
use crate::outputs::models_entry::{EntryValue, LawEntry, ModelsEntry};

/// One term of the final model: its name, what the entry names it by, its own names of its
/// parameters and their values, and for a law term the part and parameter it moves.
struct Leaf {
    name: String,
    given: String,
    locals: Vec<String>,
    values: Vec<EntryValue>,
    law: Option<(String, String, String)>,
}

/// The entry of the final model of `terms` with the fitted `params` (in the model's order);
/// `script_paths` maps a script's model name to the path `[discover]` gave it by.
pub fn final_entry(
    exp: &Experiment,
    terms: &[&str],
    params: &[&FittedParam],
    script_paths: &[(String, String)],
) -> Result<ModelsEntry> {
    let mut leaves = Vec::new();
    for &term in terms {
        leaves.push(leaf(exp, term, &leaves, script_paths)?);
    }
    let n: usize = leaves.iter().map(|l| l.locals.len()).sum();
    let owned = n == params.len() && assign(&mut leaves, params);
    if !owned {
        // A model whose parameters are not laid out term by term: its own names.
        let given: Vec<&str> = leaves.iter().map(|l| l.given.as_str()).collect();
        return Ok(ModelsEntry::new(&given, params.iter().copied()));
    }
    fold_laws(&mut leaves);
    let given: Vec<&str> = leaves.iter().map(|l| l.given.as_str()).collect();
    Ok(ModelsEntry::with_values(&given, keyed(&leaves)))
}

/// The term `term` resolved: a script by its path, a law term `part.P~c` (whose part is among
/// the terms before it) as the part with P's place taken by `P_gain`, any other by its name.
fn leaf(
    exp: &Experiment,
    term: &str,
    before: &[Leaf],
    script_paths: &[(String, String)],
) -> Result<Leaf> {
    let law = term.split_once('~').and_then(|(left, channel)| {
        let (part, p) = left.rsplit_once('.')?;
        let known = before.iter().any(|l| l.name == part && l.law.is_none());
        known.then(|| (part.to_string(), p.to_string(), channel.to_string()))
    });
    let given = script_paths
        .iter()
        .find(|(name, _)| name == term)
        .map_or(term, |(_, path)| path.as_str());
    let resolved = match &law {
        Some((part, _, _)) => before
            .iter()
            .find(|l| &l.name == part)
            .map(|l| l.given.clone())
            .unwrap_or_else(|| part.clone()),
        None => given.to_string(),
    };
    let model = resolve(&resolved, &exp.dir, &exp.scripts)?;
    let locals = model
        .params()
        .iter()
        .map(|s| match &law {
            Some((_, p, _)) if &s.name == p => format!("{p}_gain"),
            _ => s.name.clone(),
        })
        .collect();
    Ok(Leaf {
        name: term.to_string(),
        given: given.to_string(),
        locals,
        values: Vec::new(),
        law,
    })
}

/// Give each leaf its values from `params`, in order; false when a name does not match the
/// leaf's own (bare, or ending in `.local`).
fn assign(leaves: &mut [Leaf], params: &[&FittedParam]) -> bool {
    let mut at = params.iter();
    for leaf in leaves.iter_mut() {
        for local in &leaf.locals {
            let Some(p) = at.next() else { return false };
            if p.name != *local && !p.name.ends_with(&format!(".{local}")) {
                return false;
            }
            let value = crate::digits::carried(p.value);
            leaf.values.push(EntryValue::Value(value));
        }
    }
    true
}

/// Fold each law term into its part: the part's P becomes the affine law with base P and the
/// law term's gain; the law term goes.
fn fold_laws(leaves: &mut Vec<Leaf>) {
    while let Some(i) = leaves.iter().position(|l| l.law.is_some()) {
        let law = leaves.remove(i);
        let Some((part, p, channel)) = law.law else {
            continue;
        };
        let gain_name = format!("{p}_gain");
        let gain = law
            .locals
            .iter()
            .position(|l| *l == gain_name)
            .and_then(|k| match law.values[k] {
                EntryValue::Value(v) => Some(v),
                EntryValue::Law(_) => None,
            });
        let Some(owner) = leaves.iter_mut().find(|l| l.name == part) else {
            continue;
        };
        let Some(k) = owner.locals.iter().position(|l| *l == p) else {
            continue;
        };
        if let (Some(gain), EntryValue::Value(base)) = (gain, &owner.values[k]) {
            owner.values[k] = EntryValue::Law(LawEntry {
                law: Law::Affine.name(),
                channel,
                base: Some(*base),
                gain,
                exp: None,
            });
        }
    }
}

/// Each value by the name the entry's sum gives it: bare, or `model.P` where another part has
/// a `P` too.
fn keyed(leaves: &[Leaf]) -> IndexMap<String, EntryValue> {
    let shared = |local: &str| {
        leaves
            .iter()
            .filter(|l| l.locals.iter().any(|x| x == local))
            .count()
            > 1
    };
    leaves
        .iter()
        .flat_map(|l| {
            l.locals.iter().zip(&l.values).map(move |(local, v)| {
                let key = if shared(local) {
                    format!("{}.{local}", l.name)
                } else {
                    local.clone()
                };
                (key, v.clone())
            })
        })
        .collect()
}
