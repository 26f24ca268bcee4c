//! The `[fit]` section of an experiment file: the fit `level` (`force`, `trajectory`), the
//! `solver` (a serde enum of core's, [`Solver`]), `max_iters` and `seed`, oscillator
//! parameters fitted along (`system`), a constant `offset`, whether a trajectory fit
//! fits its `initial` state or takes the record's, and a `trace` file to which every fit
//! appends each iteration's cost and parameters (core's `FitSettings::trace`; relative to the
//! experiment file).

use std::path::PathBuf;

use anyhow::Result;
use serde::Deserialize;
use stf_core::fit::{FitSettings, Solver};
use stf_core::physics::oscillator_params::OscParam;
use toml::Spanned;

use super::Ctx;

/// Whether models are fitted to the measured force or to the measured motion.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FitLevel {
    /// Against `f_stf`, along the record's kinematics.
    Force,
    /// Against `x`, by simulating the oscillator driven as in the record.
    Trajectory,
}

impl FitLevel {
    /// The level's one name, in outputs and messages: `force` or `trajectory`.
    pub fn name(self) -> &'static str {
        match self {
            FitLevel::Force => "force",
            FitLevel::Trajectory => "trajectory",
        }
    }

    /// The measured signal fits aim at.
    pub fn signal(self) -> Signal {
        match self {
            FitLevel::Force => Signal {
                column: "f_stf",
                what: "STF force",
                si_unit: "N",
            },
            FitLevel::Trajectory => Signal {
                column: "x",
                what: "displacement",
                si_unit: "m",
            },
        }
    }
}

/// The measured signal fits aim at, at one level, and how it is said.
#[derive(Clone, Copy, Debug)]
pub struct Signal {
    /// Its column: `f_stf` or `x`.
    pub column: &'static str,
    /// What it is: `STF force` or `displacement`.
    pub what: &'static str,
    /// Its SI unit, that of the errors in JSON: N or m.
    pub si_unit: &'static str,
}

/// Where a trajectory fit's initial state comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Deserialize)]
#[serde(rename_all = "snake_case")]
enum Initial {
    /// Fitted with the other parameters (the default).
    Fit,
    /// The record's estimated state.
    Record,
}

/// `[fit]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawFit {
    level: Option<FitLevel>,
    solver: Option<Solver>,
    #[serde(default, deserialize_with = "super::counts::iterations")]
    max_iters: Option<u64>,
    seed: Option<u64>,
    #[serde(default)]
    system: Vec<String>,
    #[serde(default)]
    offset: bool,
    initial: Option<Initial>,
    trace: Option<PathBuf>,
}

/// A checked `[fit]` section.
#[derive(Clone, Debug)]
pub struct FitSpec {
    /// Force or trajectory level; `None`: force when the record has `f_stf`.
    pub level: Option<FitLevel>,
    /// Optimiser settings.
    pub settings: FitSettings,
    /// Oscillator parameters fitted along with a model (trajectory level).
    pub system_free: Vec<OscParam>,
    /// Fit a constant offset (force: `f_off`, trajectory: `x_off`).
    pub offset: bool,
    /// Trajectory level: fit the initial state `x0`, `v0` (the default, `initial = "fit"`)
    /// or take it from the record (`initial = "record"`).
    pub fit_initial: bool,
}

impl Default for FitSpec {
    fn default() -> FitSpec {
        FitSpec {
            level: None,
            settings: FitSettings::default(),
            system_free: Vec::new(),
            offset: false,
            fit_initial: true,
        }
    }
}

/// Check `[fit]` (absent: the defaults): every name in `system` is an oscillator parameter.
pub(super) fn check(raw: Option<&Spanned<RawFit>>, cx: &Ctx) -> Result<FitSpec> {
    let mut fit = FitSpec::default();
    let Some(f) = raw else {
        return Ok(fit);
    };
    let (span, f) = (f.span(), f.get_ref());
    fit.system_free = f
        .system
        .iter()
        .map(|n| n.parse::<OscParam>())
        .collect::<Result<_, _>>()
        .map_err(|e| cx.at(span, "fit.system", e))?;
    fit.level = f.level;
    if let Some(solver) = f.solver {
        fit.settings.solver = solver;
    }
    if let Some(n) = f.max_iters {
        fit.settings.max_iters = n;
    }
    if let Some(seed) = f.seed {
        fit.settings.seed = seed;
    }
    fit.settings.trace = f.trace.as_ref().map(|t| super::folder_of(cx.file).join(t));
    fit.offset = f.offset;
    fit.fit_initial = f.initial != Some(Initial::Record);
    Ok(fit)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::parse_exp as parse;

    #[test]
    fn the_section_s_keys_set_the_fit() {
        let e = parse(
            "[fit]\nlevel = \"trajectory\"\nsolver = \"nelder_mead\"\nmax_iters = 50\nseed = 9\n\
             system = [\"k\", \"c\"]\noffset = true\ninitial = \"record\"\n",
        )
        .unwrap();
        let f = &e.fit;
        assert_eq!(f.level, Some(FitLevel::Trajectory));
        assert_eq!(f.settings.solver, Solver::NelderMead);
        assert_eq!((f.settings.max_iters, f.settings.seed), (50, 9));
        assert_eq!(f.system_free, [OscParam::K, OscParam::C]);
        assert!(f.offset && !f.fit_initial);
        assert_eq!(f.settings.trace, None);
        let e = parse("[fit]\ntrace = \"fit-trace.txt\"\n").unwrap();
        let trace = e.fit.settings.trace.unwrap();
        assert_eq!(trace.file_name().unwrap(), "fit-trace.txt");
        let e = parse("[fit]\nlevel = \"force\"\ninitial = \"fit\"\n").unwrap();
        assert_eq!(e.fit.level, Some(FitLevel::Force));
        assert!(e.fit.fit_initial);
        let e = parse("").unwrap();
        assert_eq!(e.fit.level, None);
        assert!(e.fit.fit_initial && !e.fit.offset);
    }

    #[test]
    fn an_unknown_name_names_file_line_key_and_the_known_ones() {
        for (text, key, known) in [
            ("level = \"forc\"", "fit.level", "one of: force, trajectory"),
            ("initial = \"guess\"", "fit.initial", "one of: fit, record"),
            ("solver = \"newton\"", "fit.solver", "nelder_mead"),
        ] {
            let msg = format!("{:#}", parse(&format!("\n[fit]\n{text}\n")).unwrap_err());
            assert!(
                msg.starts_with(&format!("exp.toml:3: `{key}`: unknown value"))
                    && msg.contains(known),
                "{msg}"
            );
        }
        let msg = format!(
            "{:#}",
            parse("[fit]\nsystem = [\"k\", \"q\"]\n").unwrap_err()
        );
        assert!(
            msg.starts_with(
                "exp.toml:1: `fit.system`: `q` is not an oscillator parameter; known: m, k"
            ),
            "{msg}"
        );
    }
}
