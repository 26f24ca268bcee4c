//! Experiment files: TOML parsed into raw serde structs, then validated into a trusted
//! [`Experiment`].
//!
//! Unknown keys are errors (a misspelled `stifnes` must not fall back to a default); every
//! error names the file, the line and the key path. Paths in the file are relative to it.

use std::collections::BTreeMap;
use std::ops::Range;
use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use serde::{Deserialize, Serialize};
use stf_core::data::bounded::{read_file_to_string, BoundedError};
use stf_core::data::kinematics::KinematicsSettings;
use stf_core::data::record::ReadOptions;
use stf_core::fit::{FitSettings, Solver};
use stf_core::numerics::derivative::{Boundary, PolyFilter};
use stf_core::numerics::integrate::{Method, Settings};
use stf_core::numerics::reconstruct::DriveSmoothing;
use stf_core::physics::excitation::RotorAngle;
use stf_core::physics::oscillator_params::OscillatorParams;
use stf_core::regimes::RegimeThresholds;
use stf_core::simulate::{count_text, sample_count, DEFAULT_MAX_SAMPLES};
use toml::Spanned;

use crate::data_layout::{self, RawData};

mod finite;
mod scripts;
mod validate;
pub use validate::ValidateSpec;

/// A parameter value: a number, or a table with value / min / max / fixed.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(untagged)]
pub enum RawParam {
    /// Just the value.
    Value(f64),
    /// Value with bounds and a fixed/free switch.
    Table(RawParamTable),
}

/// The table form of a parameter.
#[derive(Clone, Debug, Default, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawParamTable {
    /// Initial or fixed value.
    pub value: Option<f64>,
    /// Lower bound.
    pub min: Option<f64>,
    /// Upper bound.
    pub max: Option<f64>,
    /// Held at its value in fits.
    pub fixed: Option<bool>,
}

/// One `[[models]]` (or `[[simulate.truth]]`) entry.
#[derive(Clone, Debug, Deserialize, Serialize)]
#[serde(deny_unknown_fields)]
pub struct RawModel {
    /// A built-in model's name.
    pub name: Option<String>,
    /// A script model's path (relative to the experiment file).
    pub script: Option<String>,
    /// Further models added to this one (`name = "power_law", plus = ["added_mass"]`).
    #[serde(default)]
    pub plus: Vec<String>,
    /// Parameter values and bounds; the rest take the model's defaults.
    #[serde(default)]
    pub params: BTreeMap<String, Spanned<RawParam>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(non_snake_case)]
struct RawSystem {
    preset: Option<String>,
    m: Option<f64>,
    k: Option<f64>,
    c: Option<f64>,
    #[serde(rename = "T")]
    t_friction: Option<f64>,
    delta_T: Option<f64>,
    F0: Option<f64>,
    eta: Option<f64>,
    f_off: Option<f64>,
    phi_off: Option<f64>,
    u_off: Option<f64>,
}

#[derive(Debug, Deserialize, Serialize, Clone)]
#[serde(deny_unknown_fields)]
struct RawSweep {
    w0: f64,
    alpha: f64,
    t0: f64,
    t1: f64,
    phi0: Option<f64>,
}

#[derive(Debug, Deserialize, Serialize, Clone)]
#[serde(deny_unknown_fields)]
struct RawConstant {
    omega: f64,
    #[serde(default)]
    t0: f64,
    t1: f64,
    #[serde(default)]
    phi0: f64,
}

#[derive(Debug, Deserialize, Serialize, Clone)]
#[serde(deny_unknown_fields)]
struct RawProfile {
    t: Vec<f64>,
    omega: Vec<f64>,
    #[serde(default)]
    phi0: f64,
}

#[derive(Debug, Deserialize, Serialize, Clone)]
#[serde(deny_unknown_fields)]
struct RawFree {
    t1: f64,
}

#[derive(Debug, Deserialize, Serialize, Clone)]
#[serde(deny_unknown_fields)]
struct RawChirp {
    f0: f64,
    f1: f64,
    amplitude: f64,
    #[serde(default)]
    t0: f64,
    t1: f64,
    /// How the shaker's amplifier holds each sample: `"linear"` (default) or `"zoh"`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    hold: Option<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSimulate {
    sweep: Option<RawSweep>,
    constant: Option<RawConstant>,
    profile: Option<RawProfile>,
    free: Option<RawFree>,
    chirp: Option<Spanned<RawChirp>>,
    #[serde(default = "default_rate")]
    rate: f64,
    #[serde(default = "yes")]
    noise: bool,
    #[serde(default = "one")]
    seed: u64,
    #[serde(default)]
    x0: f64,
    #[serde(default)]
    v0: f64,
    #[serde(default)]
    truth: Vec<Spanned<RawModel>>,
    /// The most samples the run may make (default `DEFAULT_MAX_SAMPLES`).
    max_samples: Option<Spanned<f64>>,
}

fn default_rate() -> f64 {
    1000.0
}
fn yes() -> bool {
    true
}
fn one() -> u64 {
    1
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawIntegrator {
    method: Option<Method>,
    rtol: Option<f64>,
    atol: Option<f64>,
    h_max: Option<f64>,
}

/// A `[data] drive` value as written.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
pub(crate) enum RawDrive {
    Named(String),
    Filter(RawFilterSpec),
}

/// The drive reconstruction a `[data] drive` value asks for.
fn drive_smoothing(raw: &RawDrive) -> Result<DriveSmoothing, String> {
    match raw {
        RawDrive::Named(name) => match name.as_str() {
            "auto" => Ok(DriveSmoothing::Auto),
            "samples" => Ok(DriveSmoothing::Samples(PolyFilter::paper_omega())),
            "zoh" => Ok(DriveSmoothing::Held),
            other => Err(format!(
                "unknown drive reconstruction `{other}`; known: auto, samples, zoh, or {{ order, window }}"
            )),
        },
        RawDrive::Filter(spec) => PolyFilter::new(spec.order, spec.window)
            .map(DriveSmoothing::Filter)
            .map_err(|e| e.to_string()),
    }
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFit {
    level: Option<String>,
    solver: Option<String>,
    max_iters: Option<u64>,
    seed: Option<u64>,
    #[serde(default)]
    system: Vec<String>,
    #[serde(default)]
    offset: bool,
    initial: Option<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct RawFilterSpec {
    order: usize,
    window: usize,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFilter {
    motion: Option<RawFilterSpec>,
    omega: Option<RawFilterSpec>,
    boundary: Option<String>,
    #[serde(default)]
    paper: bool,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawStage {
    data: String,
    preset: Option<String>,
    free: Vec<String>,
    #[serde(default)]
    set: BTreeMap<String, f64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDiscover {
    base: String,
    candidates: Option<Vec<String>>,
    max_effects: Option<usize>,
    holdout_every: Option<usize>,
    level: Option<String>,
    scout_from: Option<usize>,
}

/// A validated `[discover]` section.
#[derive(Clone, Debug)]
pub struct DiscoverSpec {
    /// The base model: a name, a script path, or `a + b`.
    pub base: String,
    /// Candidate effects (default: the vocabulary of docs/ARCHITECTURE.md §5).
    pub candidates: Option<Vec<String>>,
    /// At most this many effects are added.
    pub max_effects: Option<usize>,
    /// Every k-th cycle is held out for scoring.
    pub holdout_every: Option<usize>,
    /// Records of at least this many samples are scouted at trajectory level (0: never).
    pub scout_from: Option<usize>,
    /// `force` or `trajectory`; `None`: as `[fit] level`, else force when the record has
    /// `f_stf`.
    pub level: Option<FitLevel>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawExperiment {
    data: Option<Spanned<RawData>>,
    system: Option<Spanned<RawSystem>>,
    integrator: Option<Spanned<RawIntegrator>>,
    #[serde(default)]
    models: Vec<Spanned<RawModel>>,
    simulate: Option<Spanned<RawSimulate>>,
    discover: Option<RawDiscover>,
    fit: Option<Spanned<RawFit>>,
    filter: Option<Spanned<RawFilter>>,
    #[serde(default)]
    identify: Vec<Spanned<RawStage>>,
    regimes: Option<Spanned<toml::Value>>,
    output: Option<RawOutput>,
    validate: Option<Spanned<validate::RawValidate>>,
    scripts: Option<Spanned<scripts::RawScripts>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawOutput {
    report: Option<bool>,
}

/// What the commands write besides their JSON.
#[derive(Clone, Debug)]
pub struct OutputSpec {
    /// Figures (SVG, PNG, CSV), report.html and report.md.
    pub report: bool,
}

/// Whether models are fitted to the measured force or to the measured motion.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FitLevel {
    /// Against `f_stf`, along the record's kinematics.
    Force,
    /// Against `x`, by simulating the oscillator driven as in the record.
    Trajectory,
}

/// A validated `[fit]` section.
#[derive(Clone, Debug)]
pub struct FitSpec {
    /// Force or trajectory level; `None`: force when the record has `f_stf`.
    pub level: Option<FitLevel>,
    /// Optimiser settings.
    pub settings: FitSettings,
    /// Oscillator parameters fitted along with a model (trajectory level).
    pub system_free: Vec<String>,
    /// Fit a constant offset (force: `f_off`, trajectory: `x_off`).
    pub offset: bool,
    /// Trajectory level: fit the initial state `x0`, `v0` (the default, `initial = "fit"`)
    /// or take it from the record (`initial = "record"`).
    pub fit_initial: bool,
}

/// One stage of an oscillator identification (`[[identify]]`).
#[derive(Clone, Debug)]
pub struct StageSpec {
    /// The record, resolved.
    pub data: PathBuf,
    /// Start values replaced by a preset before this stage.
    pub preset: Option<OscillatorParams>,
    /// Oscillator parameters fitted in this stage.
    pub free: Vec<String>,
    /// Values set (and held) before this stage.
    pub set: Vec<(String, f64)>,
    /// Line in the file.
    pub line: usize,
}

/// A model as the experiment file gives it, with where it stands in the file.
#[derive(Clone, Debug)]
pub struct ModelEntry {
    /// The raw entry.
    pub raw: RawModel,
    /// Line of the entry in the file (1-based).
    pub line: usize,
    /// Key path (`models[0]`, `simulate.truth[1]`).
    pub key: String,
    /// Line of each parameter given in `params`.
    pub param_lines: BTreeMap<String, usize>,
}

/// How the rotor (or nothing) drives a simulation.
#[derive(Clone, Debug)]
pub enum Drive {
    /// The rotor with a prescribed angle.
    Rotor(RotorAngle),
    /// No drive: free vibration from the initial state.
    Free,
    /// A measured-style force `u(t)` (a shaker), recorded in the `u` column.
    Force(Chirp),
}

/// A linear chirp force `u = A·sin(2π·(f0·s + (f1 − f0)·s²/(2·(t1 − t0))))`, `s = t − t0`:
/// the frequency sweeps linearly from `f0` at `t0` to `f1` at `t1`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Chirp {
    /// Frequency at `t0`, Hz.
    pub f0: f64,
    /// Frequency at `t1`, Hz.
    pub f1: f64,
    /// Force amplitude A, N.
    pub amplitude: f64,
    /// Start time, s.
    pub t0: f64,
    /// End time, s.
    pub t1: f64,
    /// The force is held from each sample to the next (a DAC's zero-order hold), instead of
    /// varying linearly between them.
    pub held: bool,
}

impl Chirp {
    /// The force at time `t`, N.
    pub fn at(&self, t: f64) -> f64 {
        let s = t - self.t0;
        let rate = (self.f1 - self.f0) / (self.t1 - self.t0);
        self.amplitude * (std::f64::consts::TAU * (self.f0 * s + 0.5 * rate * s * s)).sin()
    }
}

/// A validated `[simulate]` section.
#[derive(Clone, Debug)]
pub struct SimulateSpec {
    /// The drive.
    pub drive: Drive,
    /// Start and end time, s.
    pub t0: f64,
    /// End time, s.
    pub t1: f64,
    /// Samples per second.
    pub rate: f64,
    /// The most samples the run may make (`max_samples`).
    pub max_samples: u64,
    /// Sensor noise on or off.
    pub noise: bool,
    /// Random seed.
    pub seed: u64,
    /// Initial displacement (m) and velocity (m/s).
    pub x0: f64,
    /// Initial velocity.
    pub v0: f64,
    /// The hidden models.
    pub truth: Vec<ModelEntry>,
    /// The section as written, for the sidecar.
    pub as_json: serde_json::Value,
}

/// A validated experiment.
#[derive(Clone, Debug)]
pub struct Experiment {
    /// The file it came from.
    pub path: PathBuf,
    /// The folder paths are relative to.
    pub dir: PathBuf,
    /// The oscillator's parameters.
    pub system: OscillatorParams,
    /// Whether the file has a `[system]` section; without one, a rig driven by a measured
    /// force starts from the oscillator its record shows (see [`crate::fitting::load_data`]).
    pub system_given: bool,
    /// Integrator settings.
    pub integrator: Settings,
    /// Models to fit or compare.
    pub models: Vec<ModelEntry>,
    /// `[simulate]`, if present.
    pub simulate: Option<SimulateSpec>,
    /// `[data] file`, resolved.
    pub data_file: Option<PathBuf>,
    /// Line of `[data]` in the file.
    pub data_line: usize,
    /// Time window of the data, s.
    pub data_window: Option<(f64, f64)>,
    /// How to read the record: its layout (`[data]` columns, units, offsets, …).
    pub data_layout: ReadOptions,
    /// Whether records are checked for plausibility (`[data] plausibility`).
    pub data_plausibility: bool,
    /// `[fit]`.
    pub fit: FitSpec,
    /// `[filter]`.
    pub kinematics: KinematicsSettings,
    /// `[[identify]]` stages.
    pub identify: Vec<StageSpec>,
    /// `[output]`.
    pub output: OutputSpec,
    /// `[regimes]` thresholds (defaults where not given).
    pub regimes: RegimeThresholds,
    /// `[discover] base`.
    pub discover: Option<DiscoverSpec>,
    /// `[validate]`: the second record every fitted model is scored on.
    pub validate: Option<ValidateSpec>,
    /// `[scripts]`: the limits script models run under, and this run's operation counters.
    pub scripts: stf_plugins::ScriptRun,
}

/// Accepted `[integrator]` tolerances: key, least, most, and what else is accepted. Beyond
/// them a run takes minutes to hours (`rtol = 1e-300` asks for more digits than a double
/// holds; `h_max = 1e-300` for more steps than the integrator's limit) or means nothing.
const TOLERANCE_RANGES: [(&str, f64, f64, &str); 3] = [
    ("rtol", 1e-13, 0.1, ""),
    ("atol", 1e-15, 1e-2, ""),
    ("h_max", 1e-5, 1e3, " s, or 0 (no limit)"),
];

/// The most bytes an experiment file may hold: 16 MiB, thousands of times a real one (a
/// long `profile` included), so that a wrong path (`/dev/zero`) is an error, not a full memory.
pub const MAX_EXPERIMENT_BYTES: u64 = 16 << 20;

/// `[simulate] max_samples` (default [`DEFAULT_MAX_SAMPLES`]), and the run's sample count
/// checked against it before anything is allocated.
fn sample_limit(cx: &Ctx, span: &Range<usize>, s: &RawSimulate, t0: f64, t1: f64) -> Result<u64> {
    let limit = match &s.max_samples {
        None => DEFAULT_MAX_SAMPLES,
        Some(m) => {
            let v = *m.get_ref();
            if !(v >= 2.0 && v <= u64::MAX as f64) {
                return Err(cx.at(
                    m.span(),
                    "simulate.max_samples",
                    format!("{v} is not a sample count (at least 2)"),
                ));
            }
            v as u64
        }
    };
    let count = sample_count(t0, t1, s.rate);
    if !(count <= limit as f64) {
        return Err(cx.at(
            span.clone(),
            "simulate.rate",
            format!(
                "{} samples/s from t0 = {t0} to t1 = {t1} s asks for {} samples, over the limit \
                 of {limit} (`simulate.max_samples`; a run holds about 140 bytes a sample)",
                s.rate,
                count_text(count)
            ),
        ));
    }
    Ok(limit)
}

/// 1-based line of a byte offset.
pub fn line_of(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].matches('\n').count() + 1
}

/// The text of the experiment file at `path`, at most `limit` bytes.
pub fn read_text(path: &Path, limit: u64) -> Result<String> {
    read_file_to_string(path, limit).map_err(|e| match e {
        BoundedError::TooLarge { .. } => {
            anyhow::anyhow!("{}: the experiment file {e}", path.display())
        }
        BoundedError::Io(e) => {
            anyhow::anyhow!("cannot read experiment file {}: {e}", path.display())
        }
    })
}

/// `FILE:LINE: `KEY`: MSG`, the form of every error about a value in an experiment file.
pub fn error_at(file: &Path, line: usize, key: &str, msg: impl std::fmt::Display) -> anyhow::Error {
    anyhow::anyhow!("{}:{}: `{}`: {}", file.display(), line, key, msg)
}

/// Where errors point: the experiment file and its text.
pub(crate) struct Ctx<'a> {
    file: &'a Path,
    text: &'a str,
}

impl Ctx<'_> {
    /// The 1-based line of a byte offset.
    pub(crate) fn line(&self, offset: usize) -> usize {
        line_of(self.text, offset)
    }

    /// An error at `span`'s line, about `key`.
    pub(crate) fn at(
        &self,
        span: Range<usize>,
        key: &str,
        msg: impl std::fmt::Display,
    ) -> anyhow::Error {
        error_at(self.file, line_of(self.text, span.start), key, msg)
    }
}

impl Experiment {
    /// Read and validate an experiment file.
    pub fn load(path: &Path) -> Result<Experiment> {
        Self::load_capped(path, MAX_EXPERIMENT_BYTES)
    }

    /// [`Experiment::load`], refusing a file of more than `limit` bytes.
    pub fn load_capped(path: &Path, limit: u64) -> Result<Experiment> {
        let text = read_text(path, limit)?;
        Self::parse(path, &text)
    }

    /// Validate the text of an experiment file that lives at `path`.
    pub fn parse(path: &Path, text: &str) -> Result<Experiment> {
        // Before deserialising, which refuses a number beyond a double's range without its key.
        if let Some((key, at)) = finite::first_non_finite(text) {
            return Err(error_at(
                path,
                line_of(text, at),
                &key,
                "NaN, infinity and numbers beyond a double's range (±1.8e308) are not \
                 accepted: give a finite number",
            ));
        }
        let raw: RawExperiment = toml::from_str(text).map_err(|e| {
            let line = e.span().map_or(0, |s| line_of(text, s.start));
            anyhow::anyhow!("{}:{}: {}", path.display(), line, e.message().trim_end())
        })?;
        let cx = Ctx { file: path, text };
        let dir = path
            .parent()
            .map(Path::to_path_buf)
            .unwrap_or_else(|| PathBuf::from("."));
        let dir = if dir.as_os_str().is_empty() {
            PathBuf::from(".")
        } else {
            dir
        };

        let mut system = OscillatorParams::FORCED;
        if let Some(s) = &raw.system {
            let span = s.span();
            let s = s.get_ref();
            if let Some(name) = &s.preset {
                system = OscillatorParams::preset(name).ok_or_else(|| {
                    cx.at(
                        span.clone(),
                        "system.preset",
                        format!("unknown preset `{name}`; known: forced, free"),
                    )
                })?;
            }
            let given = [
                ("m", s.m),
                ("k", s.k),
                ("c", s.c),
                ("T", s.t_friction),
                ("delta_T", s.delta_T),
                ("F0", s.F0),
                ("eta", s.eta),
                ("f_off", s.f_off),
                ("phi_off", s.phi_off),
                ("u_off", s.u_off),
            ];
            for (name, value) in given {
                if let Some(v) = value {
                    let must_be_positive = matches!(name, "m" | "k" | "eta");
                    let signed = OscillatorParams::OFFSETS.contains(&name);
                    if !v.is_finite() || (v < 0.0 && !signed) || (must_be_positive && v == 0.0) {
                        return Err(cx.at(
                            span.clone(),
                            &format!("system.{name}"),
                            format!("{v} is not a valid value"),
                        ));
                    }
                    system.set(name, v);
                }
            }
        }

        let mut integrator = Settings::default();
        if let Some(i) = &raw.integrator {
            let span = i.span();
            let i = i.get_ref();
            if let Some(m) = i.method {
                integrator.method = m;
            }
            for (name, value, slot) in [
                ("rtol", i.rtol, &mut integrator.rtol),
                ("atol", i.atol, &mut integrator.atol),
                ("h_max", i.h_max, &mut integrator.h_max),
            ] {
                if let Some(v) = value {
                    let (lo, hi, what) = TOLERANCE_RANGES
                        .iter()
                        .find(|(n, ..)| *n == name)
                        .map(|&(_, lo, hi, what)| (lo, hi, what))
                        .unwrap_or((0.0, f64::MAX, ""));
                    let off = name == "h_max" && v == 0.0;
                    if !off && !(lo..=hi).contains(&v) {
                        return Err(cx.at(
                            span.clone(),
                            &format!("integrator.{name}"),
                            format!("{v} is outside the accepted range [{lo:e}, {hi:e}]{what}"),
                        ));
                    }
                    *slot = v;
                }
            }
        }

        let entries = |list: &[Spanned<RawModel>], prefix: &str| -> Result<Vec<ModelEntry>> {
            list.iter()
                .enumerate()
                .map(|(i, m)| {
                    let key = format!("{prefix}[{i}]");
                    let r = m.get_ref();
                    match (&r.name, &r.script) {
                        (Some(_), Some(_)) => {
                            Err(cx.at(m.span(), &key, "give either `name` or `script`, not both"))
                        }
                        (None, None) => Err(cx.at(
                            m.span(),
                            &key,
                            "a model needs `name` (a built-in) or `script` (a .rhai file)",
                        )),
                        _ => Ok(ModelEntry {
                            raw: r.clone(),
                            line: line_of(text, m.span().start),
                            key,
                            param_lines: r
                                .params
                                .iter()
                                .map(|(k, v)| (k.clone(), line_of(text, v.span().start)))
                                .collect(),
                        }),
                    }
                })
                .collect()
        };
        let models = entries(&raw.models, "models")?;

        let simulate = match &raw.simulate {
            None => None,
            Some(s) => {
                let span = s.span();
                let s = s.get_ref();
                let drives = [
                    s.sweep.is_some(),
                    s.constant.is_some(),
                    s.profile.is_some(),
                    s.free.is_some(),
                    s.chirp.is_some(),
                ];
                if drives.iter().filter(|d| **d).count() != 1 {
                    return Err(cx.at(
                        span,
                        "simulate",
                        "give exactly one of `sweep`, `constant`, `profile`, `free` or `chirp`",
                    ));
                }
                let (drive, t0, t1, as_json) = if let Some(w) = &s.sweep {
                    let mut angle = RotorAngle::sweep(w.w0, w.alpha, w.t0);
                    if let (Some(p), RotorAngle::Sweep { phi0, .. }) = (w.phi0, &mut angle) {
                        *phi0 = p;
                    }
                    (
                        Drive::Rotor(angle),
                        w.t0,
                        w.t1,
                        serde_json::json!({ "sweep": w }),
                    )
                } else if let Some(c) = &s.constant {
                    let angle = RotorAngle::Constant {
                        omega: c.omega,
                        phi0: c.phi0,
                    };
                    (
                        Drive::Rotor(angle),
                        c.t0,
                        c.t1,
                        serde_json::json!({ "constant": c }),
                    )
                } else if let Some(p) = &s.profile {
                    if p.t.len() != p.omega.len() || p.t.len() < 2 {
                        return Err(cx.at(
                            span,
                            "simulate.profile",
                            "`t` and `omega` need the same length, at least 2",
                        ));
                    }
                    if p.t.windows(2).any(|w| !(w[1] > w[0])) {
                        return Err(cx.at(span, "simulate.profile.t", "times must increase"));
                    }
                    let (t0, t1) = (p.t[0], p.t[p.t.len() - 1]);
                    let angle = RotorAngle::Profile {
                        t: p.t.clone(),
                        omega: p.omega.clone(),
                        phi0: p.phi0,
                    };
                    (
                        Drive::Rotor(angle),
                        t0,
                        t1,
                        serde_json::json!({ "profile": p }),
                    )
                } else if let Some(f) = &s.free {
                    (Drive::Free, 0.0, f.t1, serde_json::json!({ "free": f }))
                } else if let Some(c) = &s.chirp {
                    let (at, c) = (c.span(), c.get_ref());
                    for (name, v) in [("f0", c.f0), ("f1", c.f1), ("t0", c.t0), ("t1", c.t1)] {
                        let is_frequency = name.starts_with('f');
                        if !v.is_finite() || (is_frequency && v < 0.0) {
                            return Err(cx.at(
                                at.clone(),
                                &format!("simulate.chirp.{name}"),
                                format!("{v} is not a valid value"),
                            ));
                        }
                    }
                    if !(c.amplitude.is_finite() && c.amplitude > 0.0) {
                        return Err(cx.at(
                            at,
                            "simulate.chirp.amplitude",
                            format!("{} must be a positive force, N", c.amplitude),
                        ));
                    }
                    let held = match c.hold.as_deref() {
                        None | Some("linear") => false,
                        Some("zoh") => true,
                        Some(other) => {
                            return Err(cx.at(
                                at,
                                "simulate.chirp.hold",
                                format!("unknown hold `{other}`; known: linear, zoh"),
                            ))
                        }
                    };
                    let chirp = Chirp {
                        f0: c.f0,
                        f1: c.f1,
                        amplitude: c.amplitude,
                        t0: c.t0,
                        t1: c.t1,
                        held,
                    };
                    (
                        Drive::Force(chirp),
                        c.t0,
                        c.t1,
                        serde_json::json!({ "chirp": c }),
                    )
                } else {
                    bail!("unreachable: no drive");
                };
                if !(t1 > t0) {
                    return Err(cx.at(
                        span,
                        "simulate",
                        format!("t1 = {t1} must exceed t0 = {t0}"),
                    ));
                }
                if !(s.rate > 0.0 && s.rate.is_finite()) {
                    return Err(cx.at(span, "simulate.rate", "must be a positive number"));
                }
                let max_samples = sample_limit(&cx, &span, s, t0, t1)?;
                let mut as_json = as_json;
                as_json["rate"] = s.rate.into();
                as_json["noise"] = s.noise.into();
                as_json["seed"] = s.seed.into();
                as_json["x0"] = s.x0.into();
                as_json["v0"] = s.v0.into();
                Some(SimulateSpec {
                    drive,
                    t0,
                    t1,
                    rate: s.rate,
                    max_samples,
                    noise: s.noise,
                    seed: s.seed,
                    x0: s.x0,
                    v0: s.v0,
                    truth: entries(&s.truth, "simulate.truth")?,
                    as_json,
                })
            }
        };

        let mut fit = FitSpec {
            level: None,
            settings: FitSettings::default(),
            system_free: Vec::new(),
            offset: false,
            fit_initial: true,
        };
        if let Some(f) = &raw.fit {
            let span = f.span();
            let f = f.get_ref();
            fit.level = match f.level.as_deref() {
                None => None,
                Some("force") => Some(FitLevel::Force),
                Some("trajectory") => Some(FitLevel::Trajectory),
                Some(other) => {
                    return Err(cx.at(
                        span,
                        "fit.level",
                        format!("unknown level `{other}`; known: force, trajectory"),
                    ))
                }
            };
            if let Some(name) = &f.solver {
                fit.settings.solver = Solver::ALL
                    .into_iter()
                    .find(|s| s.name() == name)
                    .ok_or_else(|| {
                        let known: Vec<&str> = Solver::ALL.iter().map(|s| s.name()).collect();
                        cx.at(
                            span.clone(),
                            "fit.solver",
                            format!("unknown solver `{name}`; known: {}", known.join(", ")),
                        )
                    })?;
            }
            if let Some(n) = f.max_iters {
                fit.settings.max_iters = n;
            }
            if let Some(seed) = f.seed {
                fit.settings.seed = seed;
            }
            for name in &f.system {
                if OscillatorParams::get(&OscillatorParams::FORCED, name).is_none() {
                    return Err(cx.at(
                        span.clone(),
                        "fit.system",
                        format!(
                            "`{name}` is not an oscillator parameter; known: {}",
                            OscillatorParams::NAMES.join(", ")
                        ),
                    ));
                }
            }
            fit.system_free = f.system.clone();
            fit.offset = f.offset;
            fit.fit_initial = match f.initial.as_deref() {
                None | Some("fit") => true,
                Some("record") => false,
                Some(other) => {
                    return Err(cx.at(
                        span,
                        "fit.initial",
                        format!("unknown initial state `{other}`; known: fit, record"),
                    ))
                }
            };
        }

        let mut kinematics = KinematicsSettings::default();
        if let Some(f) = &raw.filter {
            let span = f.span();
            let f = f.get_ref();
            if f.paper {
                kinematics = KinematicsSettings::paper();
            }
            if let Some(b) = &f.boundary {
                kinematics.boundary = match b.as_str() {
                    "shifted" => Boundary::Shifted,
                    "zero" => Boundary::Zero,
                    other => {
                        return Err(cx.at(
                            span,
                            "filter.boundary",
                            format!("unknown boundary `{other}`; known: shifted, zero"),
                        ))
                    }
                };
            }
            let boundary = kinematics.boundary;
            let make = |key: &str, spec: &RawFilterSpec| {
                PolyFilter::new(spec.order, spec.window)
                    .map(|f| f.boundary(boundary))
                    .map_err(|e| cx.at(span.clone(), key, e))
            };
            if let Some(m) = &f.motion {
                kinematics.motion = Some(make("filter.motion", m)?);
            } else if let Some(m) = kinematics.motion.as_mut() {
                *m = m.boundary(boundary);
            }
            if let Some(o) = &f.omega {
                kinematics.drive = DriveSmoothing::Filter(make("filter.omega", o)?);
            } else if let DriveSmoothing::Samples(f) = &mut kinematics.drive {
                *f = f.boundary(boundary);
            }
        }

        let mut identify = Vec::new();
        for (i, st) in raw.identify.iter().enumerate() {
            let span = st.span();
            let key = format!("identify[{i}]");
            let r = st.get_ref();
            let preset = match &r.preset {
                None => None,
                Some(name) => Some(OscillatorParams::preset(name).ok_or_else(|| {
                    cx.at(
                        span.clone(),
                        &format!("{key}.preset"),
                        format!("unknown preset `{name}`; known: forced, free"),
                    )
                })?),
            };
            for name in r.free.iter().chain(r.set.keys()) {
                if OscillatorParams::FORCED.get(name).is_none() {
                    return Err(cx.at(
                        span.clone(),
                        &key,
                        format!(
                            "`{name}` is not an oscillator parameter; known: {}",
                            OscillatorParams::NAMES.join(", ")
                        ),
                    ));
                }
            }
            identify.push(StageSpec {
                data: dir.join(&r.data),
                preset,
                free: r.free.clone(),
                set: r.set.iter().map(|(k, v)| (k.clone(), *v)).collect(),
                line: line_of(text, span.start),
            });
        }

        let regimes = match &raw.regimes {
            None => RegimeThresholds::default(),
            Some(v) => {
                let th: RegimeThresholds = v
                    .get_ref()
                    .clone()
                    .try_into()
                    .map_err(|e: toml::de::Error| cx.at(v.span(), "regimes", e.message()))?;
                th.validate().map_err(|e| cx.at(v.span(), "regimes", e))?;
                th
            }
        };

        let data = data_layout::parse(&cx, raw.data.as_ref(), &dir)?;
        if let Some(d) = &raw.data {
            if let Some(drive) = &d.get_ref().drive {
                let omega_set = raw
                    .filter
                    .as_ref()
                    .is_some_and(|f| f.get_ref().omega.is_some());
                if omega_set {
                    return Err(cx.at(
                        d.span(),
                        "data.drive",
                        "set either `[data] drive` or `[filter] omega`, not both (they are the same \
                         setting)",
                    ));
                }
                kinematics.drive =
                    drive_smoothing(drive).map_err(|e| cx.at(d.span(), "data.drive", e))?;
            }
        }
        Ok(Experiment {
            validate: validate::spec(raw.validate.as_ref(), &cx, &dir)?,
            scripts: scripts::run(raw.scripts.as_ref(), &cx)?,
            path: path.to_path_buf(),
            data_window: data.window,
            data_layout: data.layout,
            data_plausibility: data.plausibility,
            fit,
            kinematics,
            identify,
            regimes,
            output: OutputSpec {
                report: raw.output.as_ref().and_then(|o| o.report).unwrap_or(true),
            },
            data_file: data.file,
            data_line: data.line,
            dir,
            system,
            system_given: raw.system.is_some(),
            integrator,
            models,
            simulate,
            discover: match raw.discover {
                None => None,
                Some(d) => Some(DiscoverSpec {
                    level: match d.level.as_deref() {
                        None => None,
                        Some("force") => Some(FitLevel::Force),
                        Some("trajectory") => Some(FitLevel::Trajectory),
                        Some(other) => {
                            let at = text.find("[discover]").unwrap_or(0);
                            return Err(cx.at(
                                at..at,
                                "discover.level",
                                format!("unknown level `{other}`; known: force, trajectory"),
                            ));
                        }
                    },
                    base: d.base,
                    candidates: d.candidates,
                    max_effects: d.max_effects,
                    holdout_every: d.holdout_every,
                    scout_from: d.scout_from,
                }),
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Experiment> {
        Experiment::parse(Path::new("exp.toml"), text)
    }

    #[test]
    fn tolerances_that_would_run_for_minutes_are_refused_with_the_range() {
        for (text, key, range) in [
            ("rtol = 1e-300", "integrator.rtol", "[1e-13, 1e-1]"),
            ("atol = 1e-300", "integrator.atol", "[1e-15, 1e-2]"),
            (
                "h_max = 1e-300",
                "integrator.h_max",
                "[1e-5, 1e3] s, or 0 (no limit)",
            ),
            ("rtol = 0.5", "integrator.rtol", "[1e-13, 1e-1]"),
            ("h_max = -1.0", "integrator.h_max", "or 0"),
        ] {
            let msg = format!(
                "{:#}",
                parse(&format!("[integrator]\n{text}\n")).unwrap_err()
            );
            assert!(
                msg.starts_with(&format!("exp.toml:1: `{key}`:"))
                    && msg.contains("outside the accepted range")
                    && msg.contains(range),
                "{msg}"
            );
        }
        assert!(parse("[integrator]\nrtol = 1e-11\natol = 1e-12\nh_max = 0.0\n").is_ok());
    }

    #[test]
    fn the_drive_reconstruction_and_initial_state_are_settings() {
        use stf_core::numerics::reconstruct::DriveSmoothing;
        let e = parse("[data]\nfile = \"r.csv\"\ndrive = \"samples\"\n").unwrap();
        assert!(matches!(e.kinematics.drive, DriveSmoothing::Samples(_)));
        let e = parse("[data]\nfile = \"r.csv\"\ndrive = { order = 2, window = 101 }\n").unwrap();
        assert!(matches!(e.kinematics.drive, DriveSmoothing::Filter(f) if f.window() == 101));
        let e = parse("[data]\nfile = \"r.csv\"\n").unwrap();
        assert_eq!(e.kinematics.drive, DriveSmoothing::Auto);
        assert!(e.fit.fit_initial);
        let e = parse("[fit]\ninitial = \"record\"\n").unwrap();
        assert!(!e.fit.fit_initial);
        for (text, key) in [
            ("[data]\nfile = \"r.csv\"\ndrive = \"smooth\"\n", "data.drive"),
            (
                "[data]\nfile = \"r.csv\"\ndrive = \"auto\"\n[filter]\nomega = { order = 2, window = 9 }\n",
                "data.drive",
            ),
            ("[fit]\ninitial = \"guess\"\n", "fit.initial"),
        ] {
            let msg = format!("{:#}", parse(text).unwrap_err());
            assert!(msg.contains(key) && msg.contains("exp.toml:"), "{msg}");
        }
    }

    #[test]
    fn the_design_example_parses() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("record.csv"), "t,phi,x\n0,0,0\n").unwrap();
        let e = Experiment::parse(
            &dir.path().join("exp.toml"),
            r#"
[data]
file = "record.csv"

[system]
m = 7.65

[[models]]
name = "power_law"
params = { K = 2.0, n = { value = 1.2, min = 1.0, max = 4.0 } }

[discover]
base = "power_law"
scout_from = 0

[simulate]
sweep = { w0 = 2.35, alpha = 0.047, t0 = 50.0, t1 = 200.0 }
rate = 1000.0
noise = true
seed = 1

[[simulate.truth]]
name = "power_law"
params = { K = 4.0, n = 1.5 }
"#,
        )
        .unwrap();
        assert_eq!(e.models.len(), 1);
        assert_eq!(e.models[0].line, 8); // the `[[models]]` header
        assert_eq!(e.data_file.unwrap(), dir.path().join("record.csv"));
        let s = e.simulate.unwrap();
        assert_eq!((s.t0, s.t1), (50.0, 200.0));
        assert_eq!(s.truth[0].key, "simulate.truth[0]");
        assert_eq!(e.discover.unwrap().scout_from, Some(0));
    }

    #[test]
    fn a_run_too_long_for_memory_names_the_key_the_samples_and_the_limit() {
        // The issue's case: 10⁹ s at 1 MHz, 10¹⁵ samples. Parsing allocates nothing.
        let msg = parse("[simulate]\nconstant = { omega = 6.0, t1 = 1e9 }\nrate = 1e6\n")
            .unwrap_err()
            .to_string();
        assert_eq!(
            msg,
            "exp.toml:1: `simulate.rate`: 1000000 samples/s from t0 = 0 to t1 = 1000000000 s \
             asks for 1.00e15 samples, over the limit of 10000000 (`simulate.max_samples`; a \
             run holds about 140 bytes a sample)"
        );
        let msg = parse("[simulate]\nconstant = { omega = 6.0, t1 = 1.0 }\nrate = 1e300\n")
            .unwrap_err()
            .to_string();
        assert!(msg.contains("asks for 1.00e300 samples"), "{msg}");
        // The limit is a setting: raised, the same run parses; lowered, a short one is refused.
        let e = parse(
            "[simulate]\nconstant = { omega = 6.0, t1 = 1e9 }\nrate = 1e6\nmax_samples = 2e15\n",
        )
        .unwrap();
        assert_eq!(e.simulate.unwrap().max_samples, 2_000_000_000_000_000);
        let msg = parse("[simulate]\nfree = { t1 = 1.0 }\nrate = 100.0\nmax_samples = 100\n")
            .unwrap_err()
            .to_string();
        assert!(msg.contains("101 samples, over the limit of 100"), "{msg}");
        let msg = parse("[simulate]\nfree = { t1 = 1.0 }\nmax_samples = -3\n")
            .unwrap_err()
            .to_string();
        assert!(
            msg.starts_with("exp.toml:3: `simulate.max_samples`: -3 is not"),
            "{msg}"
        );
    }

    #[test]
    fn an_experiment_file_over_the_cap_is_refused_with_its_size() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("big.toml");
        let text = "# padding\n".repeat(120);
        std::fs::write(&path, &text).unwrap();
        let msg = Experiment::load_capped(&path, 1000)
            .unwrap_err()
            .to_string();
        assert_eq!(
            msg,
            format!(
                "{}: the experiment file is {} bytes, over the limit of 1000 bytes",
                path.display(),
                text.len()
            )
        );
        assert!(Experiment::load_capped(&path, text.len() as u64).is_ok());
        #[cfg(unix)]
        {
            let msg = Experiment::load_capped(Path::new("/dev/zero"), 4096)
                .unwrap_err()
                .to_string();
            assert_eq!(
                msg,
                "/dev/zero: the experiment file holds more than the limit of 4096 bytes"
            );
        }
    }

    #[test]
    fn a_misspelled_key_is_an_error_with_file_and_line() {
        let err = parse("[system]\nm = 7.65\nstifnes = 3.0\n").unwrap_err();
        let msg = format!("{err:#}");
        assert!(msg.contains("exp.toml:3"), "{msg}");
        assert!(msg.contains("stifnes"), "{msg}");
    }

    #[test]
    fn a_missing_record_names_the_file_line_and_key() {
        let mut exp = parse("# comment\n[data]\nfile = \"nowhere.csv\"\n").unwrap();
        let err = crate::fitting::load_data(&mut exp).err().unwrap();
        let msg = format!("{err:#}");
        assert!(
            msg.contains("exp.toml:2") && msg.contains("data.file"),
            "{msg}"
        );
        assert!(msg.contains("nowhere.csv"), "{msg}");
    }

    #[test]
    fn an_unknown_solver_or_preset_names_the_key_and_the_known_ones() {
        let msg = format!("{:#}", parse("\n[fit]\nsolver = \"newton\"\n").unwrap_err());
        assert!(
            msg.contains("exp.toml:2") && msg.contains("fit.solver"),
            "{msg}"
        );
        assert!(msg.contains("nelder_mead"), "{msg}");
        let msg = format!("{:#}", parse("[system]\npreset = \"forcd\"\n").unwrap_err());
        assert!(
            msg.contains("exp.toml:1") && msg.contains("system.preset"),
            "{msg}"
        );
    }

    #[test]
    fn a_misspelled_key_inside_a_model_names_its_line() {
        let msg = format!(
            "{:#}",
            parse("[[models]]\nname = \"viscous\"\nparmas = { c_s = 1.0 }\n").unwrap_err()
        );
        assert!(
            msg.contains("exp.toml:3") && msg.contains("parmas"),
            "{msg}"
        );
    }

    #[test]
    fn two_drives_are_an_error() {
        let err = parse("[simulate]\nsweep = { w0 = 1.0, alpha = 0.1, t0 = 0.0, t1 = 5.0 }\nconstant = { omega = 2.0, t1 = 3.0 }\n")
            .unwrap_err();
        assert!(format!("{err:#}").contains("exactly one"));
    }

    #[test]
    fn a_chirp_drive_parses_and_a_bad_value_names_file_line_and_key() {
        let e = parse(
            "[simulate]\nrate = 200.0\nchirp = { f0 = 0.5, f1 = 1.5, amplitude = 2.0, t1 = 20.0 }\n",
        )
        .unwrap();
        let s = e.simulate.unwrap();
        assert_eq!((s.t0, s.t1), (0.0, 20.0));
        let Drive::Force(chirp) = s.drive else {
            panic!("not a force drive: {:?}", s.drive)
        };
        // The frequency sweeps 0.5 → 1.5 Hz: the phase is 2π·(0.5·t + 0.025·t²).
        let t = 7.3;
        let expected = 2.0 * (std::f64::consts::TAU * (0.5 * t + 0.025 * t * t)).sin();
        assert!((chirp.at(t) - expected).abs() < 1e-12);
        assert_eq!(s.as_json["chirp"]["amplitude"], 2.0);

        for (bad, key) in [
            ("f0 = -0.5, f1 = 1.5, amplitude = 2.0", "simulate.chirp.f0"),
            ("f0 = 0.5, f1 = nan, amplitude = 2.0", "simulate.chirp.f1"),
            (
                "f0 = 0.5, f1 = 1.5, amplitude = 0.0",
                "simulate.chirp.amplitude",
            ),
            (
                "f0 = 0.5, f1 = 1.5, amplitude = inf",
                "simulate.chirp.amplitude",
            ),
        ] {
            let text = format!("[simulate]\nrate = 200.0\n\nchirp = {{ {bad}, t1 = 20.0 }}\n");
            let msg = format!("{:#}", parse(&text).unwrap_err());
            assert!(msg.contains("exp.toml:4") && msg.contains(key), "{msg}");
        }
        let msg = format!(
            "{:#}",
            parse(
                "[simulate]\nchirp = { f0 = 0.5, f1 = 1.5, amplitude = 2.0, t0 = 5.0, t1 = 5.0 }\n"
            )
            .unwrap_err()
        );
        assert!(msg.contains("t1 = 5 must exceed t0 = 5"), "{msg}");
        let msg = format!(
            "{:#}",
            parse("[simulate]\nchirp = { f0 = 0.5, f1 = 1.5, amplitud = 2.0, t1 = 5.0 }\n")
                .unwrap_err()
        );
        assert!(
            msg.contains("exp.toml:2") && msg.contains("amplitud"),
            "{msg}"
        );
    }

    const VALID: &str = r#"
[system]
preset = "forced"
k = 270.0

[integrator]
method = "auto"

[fit]
solver = "auto"
system = ["k"]

[filter]
motion = { order = 3, window = 101 }

[[models]]
name = "power_law"
plus = ["added_mass"]
params = { K = 2.0, n = { value = 1.2, min = 1.0, max = 4.0 } }

[simulate]
sweep = { w0 = 2.35, alpha = 0.047, t0 = 50.0, t1 = 200.0 }

[[simulate.truth]]
name = "viscous"

[regimes]
on_k = 3.0

[validate]
file = "v.csv"
window = [0.0, 5.0]
"#;

    proptest::proptest! {
        /// Any text is an experiment or an error, never a panic. Long run (documented in the
        /// README): `PROPTEST_CASES=1000000 cargo test --release --bin stf-lab never_panics`.
        #[test]
        fn the_parser_never_panics_on_any_text(text in "\\PC{0,400}") {
            let _ = parse(&text);
        }

        /// Nor on a valid file with bytes replaced, cut or repeated.
        #[test]
        fn the_parser_never_panics_on_a_mutated_experiment(
            edits in proptest::collection::vec((0usize..600, proptest::char::any()), 1..6),
            cut in 0usize..700,
        ) {
            let mut chars: Vec<char> = VALID.chars().collect();
            for (at, c) in edits {
                let i = at % chars.len();
                chars[i] = c;
            }
            let text: String = chars.into_iter().take(cut.max(1)).collect();
            let _ = parse(&text);
        }
    }
}
