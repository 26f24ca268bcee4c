//! The `[global]` section of a campaign file: which model is fitted jointly to all records,
//! which of its parameters are shared by every record, which follow a law of a condition
//! (`P = P0·(c/reference)^P_p`, or with `law = "linear" | "affine" | "power"` the channel
//! laws of x = c/reference: `P_gain·x`, `P_base + P_gain·x`, `P_base + P_gain·|x|^P_exp`), and
//! which record is held out. Parsed into a raw
//! serde type and checked into a trusted [`GlobalSpec`] before any unit starts; every error
//! names the campaign file, the line and the key, as the rest of the campaign file
//! (`super::file`).
//!
//! ```toml
//! [global]
//! model = "power_law"            # one of the experiment's [[models]] (a sum: "a + b")
//! shared = ["n"]                 # one value for every record
//! laws = { K = { condition = "concentration", reference = 0.40 } }
//! # or: laws = { F_y = { condition = "voltage", law = "affine" } }  # F_y_base + F_y_gain·c
//! holdout = "records/a2_c2.csv"  # a record of the list, left out of every fit
//! level = "trajectory"           # force | trajectory; default: the experiment's [fit] level, else force
//! ```
//!
//! Parameters neither shared nor given a law stay per record (and so does the force offset
//! `f_off` of an experiment with `[fit] offset = true`, unless it is shared). At trajectory
//! level the parameters are those a trajectory `fit` frees: the model's free ones, the
//! oscillator's of `[fit] system`, `x_off` with `offset`; the initial state `x0`, `v0` is each
//! record's own and may be neither shared nor given a law.

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::Result;
use serde::Deserialize;
use toml::Spanned;

use super::condition_names::configure_entry;
use super::units::Unit;
use crate::experiment::{error_at, line_of, Experiment, FitLevel, ModelEntry};

/// A law as written: `{ condition = "…", reference = … }`, optionally `law = "affine"`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawLaw {
    condition: String,
    reference: Option<f64>,
    law: Option<String>,
}

/// `[global]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawGlobal {
    model: Option<Spanned<String>>,
    #[serde(default)]
    shared: Vec<Spanned<String>>,
    #[serde(default)]
    laws: BTreeMap<String, Spanned<RawLaw>>,
    holdout: Option<Spanned<String>>,
    level: Option<FitLevel>,
}

pub use stf_study::joint::spec::{Form, GlobalSpec, Law};

/// Where errors point: the campaign file and its text.
pub(super) struct At<'a> {
    pub path: &'a Path,
    pub text: &'a str,
}

impl At<'_> {
    fn error(&self, offset: usize, key: &str, msg: impl std::fmt::Display) -> anyhow::Error {
        error_at(self.path, line_of(self.text, offset), key, msg)
    }
}

/// The label of a `[[models]]` entry: its models joined by ` + `.
fn entry_label(entry: &ModelEntry) -> String {
    entry.specs().collect::<Vec<_>>().join(" + ")
}

/// Compare model labels without spaces.
fn same_label(a: &str, b: &str) -> bool {
    let squeeze = |s: &str| s.chars().filter(|c| !c.is_whitespace()).collect::<String>();
    squeeze(a) == squeeze(b)
}

/// Check `[global]` against the campaign's conditions and units (the experiment is the
/// campaign's `experiment`, resolved, else the first unit's).
pub(super) fn check(
    raw: &Spanned<RawGlobal>,
    conditions: &[String],
    units: &[Unit],
    experiment: Option<&Path>,
    at: &At,
) -> Result<GlobalSpec> {
    let start = raw.span().start;
    let g = raw.get_ref();
    let Some(model) = &g.model else {
        return Err(at.error(start, "global", "missing `model`: the model fitted jointly"));
    };
    let exp_path = experiment.map_or_else(|| units[0].experiment.clone(), Path::to_path_buf);
    let exp = Experiment::load(&exp_path)?;
    let entry = find_entry(&exp, model, at)?;
    let level = g.level.or(exp.fit.level).unwrap_or(FitLevel::Force);
    let names = Names {
        model: model.get_ref(),
        params: param_names(&exp, entry, level)?,
    };
    let shared = check_shared(&g.shared, &names, at)?;
    let laws = g
        .laws
        .iter()
        .map(|(param, law)| {
            let law = check_law(param, law, &names, &shared, conditions, at)?;
            if law.form.is_none() {
                check_positive(units, &law.condition, &format!("global.laws.{param}"), at)?;
            }
            Ok(law)
        })
        .collect::<Result<Vec<_>>>()?;
    let holdout = holdout_of(g.holdout.as_ref(), units, at)?;
    let training = units.len() - usize::from(holdout.is_some());
    if training < 2 {
        return Err(at.error(
            start,
            "global",
            format!("a global fit needs at least 2 records to fit; there are {training}"),
        ));
    }
    Ok(GlobalSpec {
        model: model.get_ref().clone(),
        entry: entry.clone(),
        experiment: exp_path,
        shared,
        laws,
        holdout,
        level,
        line: line_of(at.text, start),
    })
}

/// The `[[models]]` entry of `exp` that `model` names.
fn find_entry<'e>(exp: &'e Experiment, model: &Spanned<String>, at: &At) -> Result<&'e ModelEntry> {
    exp.models
        .iter()
        .find(|e| same_label(&entry_label(e), model.get_ref()))
        .ok_or_else(|| {
            let known: Vec<String> = exp.models.iter().map(entry_label).collect();
            at.error(
                model.span().start,
                "global.model",
                format!(
                    "`{}` is not a [[models]] entry of {} (it has: {})",
                    model.get_ref(),
                    exp.path.display(),
                    known.join(", ")
                ),
            )
        })
}

/// The parameters a record's fit of `entry` has at `level` (in the order its values take):
/// the model's (at trajectory level the free ones, then the oscillator's of `[fit] system`),
/// then the offset with `[fit] offset`; at trajectory level the initial state `x0`, `v0`
/// (when fitted) is left out: it is each record's own.
fn param_names(exp: &Experiment, entry: &ModelEntry, level: FitLevel) -> Result<Vec<String>> {
    let configured = configure_entry(exp, entry)?;
    let trajectory = level == FitLevel::Trajectory;
    let mut names: Vec<String> = configured
        .params
        .iter()
        .filter(|p| !(trajectory && p.fixed))
        .map(|p| p.name.clone())
        .collect();
    if trajectory {
        names.extend(exp.fit.system_free.iter().map(|p| p.name().to_string()));
    }
    if exp.fit.offset {
        names.push(offset_name(level).to_string());
    }
    Ok(names)
}

/// The constant offset a fit at `level` frees with `[fit] offset`.
fn offset_name(level: FitLevel) -> &'static str {
    match level {
        FitLevel::Force => stf_core::fit::FORCE_OFFSET,
        FitLevel::Trajectory => stf_core::fit::DISPLACEMENT_OFFSET,
    }
}

/// The model as written and the parameters its fit has.
struct Names<'a> {
    model: &'a str,
    params: Vec<String>,
}

impl Names<'_> {
    /// Why `name` cannot be shared or follow a law: it is not a parameter of the fit.
    fn lacks(&self, name: &str) -> String {
        if stf_core::fit::INITIAL_STATE.contains(&name) {
            return format!(
                "`{name}` is each record's initial state: it stays per record (set `[fit] \
                 initial = \"record\"` to take it from the records instead)"
            );
        }
        format!(
            "`{}` has no parameter `{name}` (it has: {})",
            self.model,
            self.params.join(", ")
        )
    }
}

/// `shared`, checked: parameters of the fit, each once.
fn check_shared(given: &[Spanned<String>], names: &Names, at: &At) -> Result<Vec<String>> {
    let mut shared = Vec::new();
    for (i, s) in given.iter().enumerate() {
        let key = format!("global.shared[{i}]");
        let name = s.get_ref();
        if !names.params.contains(name) {
            return Err(at.error(s.span().start, &key, names.lacks(name)));
        }
        if shared.contains(name) {
            return Err(at.error(s.span().start, &key, format!("`{name}` is listed twice")));
        }
        shared.push(name.clone());
    }
    Ok(shared)
}

/// The law of `param`, checked: a parameter of the fit (not an offset, not shared), over a
/// listed condition, with a positive reference.
fn check_law(
    param: &str,
    law: &Spanned<RawLaw>,
    names: &Names,
    shared: &[String],
    conditions: &[String],
    at: &At,
) -> Result<Law> {
    let key = format!("global.laws.{param}");
    let offset = law.span().start;
    let law = law.get_ref();
    if [
        stf_core::fit::FORCE_OFFSET,
        stf_core::fit::DISPLACEMENT_OFFSET,
    ]
    .contains(&param)
    {
        return Err(at.error(
            offset,
            &key,
            format!("`{param}` is each record's offset: it may be shared, not follow a law"),
        ));
    }
    if !names.params.iter().any(|n| n == param) {
        return Err(at.error(offset, &key, names.lacks(param)));
    }
    if shared.iter().any(|s| s == param) {
        return Err(at.error(
            offset,
            &key,
            format!("`{param}` is shared already: a parameter is shared or follows a law"),
        ));
    }
    if !conditions.contains(&law.condition) {
        return Err(at.error(
            offset,
            &format!("{key}.condition"),
            format!(
                "`{}` is not a condition: `campaign.conditions` lists [{}]",
                law.condition,
                conditions.join(", ")
            ),
        ));
    }
    let form = law_form(law.law.as_deref(), &key, offset, at)?;
    let reference = match (law.reference, form) {
        (Some(r), _) => r,
        (None, Some(Form::Linear | Form::Affine)) => 1.0,
        (None, Some(f)) => {
            return Err(at.error(
                offset,
                &format!("{key}.reference"),
                format!(
                    "missing: a `{}` law divides the condition by a positive `reference`",
                    f.name()
                ),
            ))
        }
        (None, None) => {
            return Err(at.error(
                offset,
                &format!("{key}.reference"),
                "missing: the power law P0·(c/reference)^P_p needs a positive `reference` \
                 (or give `law = \"linear\"`, `\"affine\"` or `\"power\"`)",
            ))
        }
    };
    if !(reference.is_finite() && reference > 0.0) {
        return Err(at.error(
            offset,
            &format!("{key}.reference"),
            format!("a positive number, found {reference}"),
        ));
    }
    Ok(Law {
        param: param.to_string(),
        condition: law.condition.clone(),
        reference,
        form,
    })
}

/// The form named by a law's `law` key (none: the power law without offset).
fn law_form(name: Option<&str>, key: &str, offset: usize, at: &At) -> Result<Option<Form>> {
    let Some(name) = name else { return Ok(None) };
    Form::named(name).map(Some).ok_or_else(|| {
        at.error(
            offset,
            &format!("{key}.law"),
            format!("unknown law `{name}`: one of linear, affine, power"),
        )
    })
}

/// Every record's `condition` is positive (a power law of it needs that).
fn check_positive(units: &[Unit], condition: &str, key: &str, at: &At) -> Result<()> {
    for (i, u) in units.iter().enumerate() {
        let value = u
            .conditions
            .iter()
            .find(|(n, _)| n == condition)
            .map_or(f64::NAN, |(_, v)| *v);
        if value.is_nan() || value <= 0.0 {
            return Err(u.entry_error(
                at.path,
                &format!("records[{i}].{condition}"),
                condition,
                format!("`{key}` needs a positive `{condition}` on every record, found {value}"),
            ));
        }
    }
    Ok(())
}

/// The held-out record's index: `holdout` must be a record's `file` as written (or the same
/// file).
fn holdout_of(given: Option<&Spanned<String>>, units: &[Unit], at: &At) -> Result<Option<usize>> {
    let Some(h) = given else { return Ok(None) };
    let found = units.iter().position(|u| {
        u.record_given == *h.get_ref()
            || Path::new(&u.record_given)
                .components()
                .eq(Path::new(h.get_ref()).components())
    });
    match found {
        Some(i) => Ok(Some(i)),
        None => Err(at.error(
            h.span().start,
            "global.holdout",
            format!(
                "`{}` is not a record of this campaign (give its `file` as written in \
                 [[records]])",
                h.get_ref()
            ),
        )),
    }
}

#[cfg(test)]
mod tests {
    use super::super::file::Campaign;
    use crate::experiment::FitLevel;

    /// The campaign `text` (two records at c = 1 and 2 after it) parsed in a folder with a
    /// record `r.csv` and an experiment `e.toml` fitting `power_law` with an offset.
    fn parse(global: &str) -> anyhow::Result<Campaign> {
        parse_with("[fit]\noffset = true\n", global)
    }

    /// [`parse`] with the experiment's `[fit]` section `fit`.
    fn parse_with(fit: &str, global: &str) -> anyhow::Result<Campaign> {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("r.csv"), "t,phi,x\n0,0,0\n").unwrap();
        std::fs::write(dir.path().join("s.csv"), "t,phi,x\n0,0,0\n").unwrap();
        std::fs::write(
            dir.path().join("e.toml"),
            format!("{fit}\n[[models]]\nname = \"power_law\"\nparams = {{ n = {{ value = 1.5, fixed = true }} }}\n"),
        )
        .unwrap();
        let text = format!(
            "[campaign]\nexperiment = \"e.toml\"\ncommand = \"fit\"\nconditions = [\"c\"]\n\n\
             [[records]]\nfile = \"r.csv\"\nc = 1\n\n[[records]]\nfile = \"s.csv\"\nc = 2\n\n\
             [global]\n{global}"
        );
        Campaign::parse(&dir.path().join("c.toml"), &text)
    }

    fn message(global: &str) -> String {
        message_of(parse(global))
    }

    fn message_of(parsed: anyhow::Result<Campaign>) -> String {
        let e = format!("{:#}", parsed.unwrap_err());
        e.split_once("c.toml")
            .map_or(e.clone(), |(_, m)| m.to_string())
    }

    #[test]
    fn a_global_section_is_checked_into_its_spec() {
        let c = parse(
            "model = \"power_law\"\nshared = [\"n\", \"f_off\"]\nlaws = { K = { condition = \"c\", reference = 1 } }\n",
        )
        .unwrap();
        let g = c.global.unwrap();
        assert_eq!(g.shared, ["n", "f_off"]);
        assert_eq!(g.laws[0].param, "K");
        assert_eq!(g.laws[0].reference, 1.0);
        assert_eq!((g.holdout, g.line), (None, 14));
        assert_eq!(g.level, FitLevel::Force);
    }

    #[test]
    fn at_trajectory_level_the_parameters_are_those_a_trajectory_fit_frees() {
        let fit = "[fit]\nlevel = \"trajectory\"\nsystem = [\"k\"]\noffset = true\n";
        let c = parse_with(fit, "model = \"power_law\"\nshared = [\"k\", \"x_off\"]\n").unwrap();
        let g = c.global.unwrap();
        assert_eq!(
            (g.level, g.shared),
            (FitLevel::Trajectory, vec!["k".into(), "x_off".into()])
        );
        // `[global] level` overrides the experiment's.
        let g = parse_with(fit, "model = \"power_law\"\nlevel = \"force\"\n").unwrap();
        assert_eq!(g.global.unwrap().level, FitLevel::Force);
        let m = message_of(parse_with(
            fit,
            "model = \"power_law\"\nshared = [\"x0\"]\n",
        ));
        assert!(
            m.starts_with(":16: `global.shared[0]`: `x0` is each record's initial state"),
            "{m}"
        );
        // n is fixed: a trajectory fit does not free it; f_off is the force level's offset.
        let m = message_of(parse_with(fit, "model = \"power_law\"\nshared = [\"n\"]\n"));
        assert!(
            m.contains("has no parameter `n` (it has: K, k, x_off)"),
            "{m}"
        );
        let m = message_of(parse_with(
            fit,
            "model = \"power_law\"\nlaws = { x_off = { condition = \"c\", reference = 1 } }\n",
        ));
        assert!(
            m.contains("`global.laws.x_off`: `x_off` is each record's offset"),
            "{m}"
        );
        let m = message_of(parse_with(
            fit,
            "model = \"power_law\"\nlevel = \"motion\"\n",
        ));
        assert!(m.contains("unknown value `motion`"), "{m}");
    }

    #[test]
    fn each_bad_global_key_is_named_with_its_line() {
        assert_eq!(
            message("shared = [\"n\"]\n"),
            ":14: `global`: missing `model`: the model fitted jointly"
        );
        assert!(message("model = \"power_law\"\nshared = [\"n\", \"n\"]\n")
            .starts_with(":16: `global.shared[1]`: `n` is listed twice"));
        assert!(message(
            "model = \"power_law\"\nshared = [\"K\"]\nlaws = { K = { condition = \"c\", reference = 1.0 } }\n"
        )
        .starts_with(":17: `global.laws.K`: `K` is shared already"));
        assert!(message(
            "model = \"power_law\"\nlaws = { K = { condition = \"c\", reference = 0.0 } }\n"
        )
        .starts_with(":16: `global.laws.K.reference`: a positive number, found 0"));
        assert!(message(
            "model = \"power_law\"\nlaws = { f_off = { condition = \"c\", reference = 1.0 } }\n"
        )
        .starts_with(":16: `global.laws.f_off`: `f_off` is each record's offset"));
        assert!(
            message("model = \"power_law\"\nholdout = \"r.csv\"\n").starts_with(
                ":14: `global`: a global fit needs at least 2 records to fit; there are 1"
            )
        );
        assert!(message("model = \"power_law\"\nshraed = [\"n\"]\n")
            .starts_with(":16: `global`: unknown key `shraed`"));
    }
}
