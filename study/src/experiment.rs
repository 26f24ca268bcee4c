//! Experiment files: TOML parsed into raw serde structs, then checked section by section into
//! a trusted [`Experiment`].
//!
//! Each section has a file under `experiment/` with its raw serde type (enums of names are
//! serde enums), its checked type and its check; `[data]` is `crate::data_layout`.
//! [`Experiment::parse`] is the sequence of those checks. Unknown keys are errors (a
//! misspelled `stifnes` must not fall back to a default); every error names the file, the
//! line and the key path ([`context`]). Paths in the file are relative to it.

use std::path::{Path, PathBuf};

use anyhow::Result;
use serde::Deserialize;
use stf_core::data::bounded::{read_file_to_string, BoundedError};
use stf_core::data::kinematics::KinematicsSettings;
use stf_core::data::record::ReadOptions;
use stf_core::numerics::integrate::Settings;
use stf_core::physics::oscillator_params::OscillatorParams;
use stf_core::regimes::RegimeThresholds;
use toml::Spanned;

use crate::data_layout::{self, RawData};

pub mod context;
mod counts;
mod discover;
mod drive;
mod filter;
mod finite;
mod fit;
mod identify;
mod integrator;
pub mod mistakes;
mod models;
mod output;
pub mod plain_words;
pub mod raw_drive;
mod regimes;
mod scripts;
mod simulate;
mod system;
mod validate;

pub use context::Ctx;
pub use context::{error_at, line_of};
pub use discover::DiscoverSpec;
pub use drive::{Chirp, Drive};
pub use fit::{FitLevel, FitSpec};
pub use identify::StageSpec;
pub use mistakes::Mistakes;
pub use models::{LawGiven, ModelEntry, ModelSource, ParamGiven, ParamOverride};
pub use output::OutputSpec;
pub use raw_drive::RawDrive;
pub use simulate::{SimChannel, SimulateSpec};
pub use validate::ValidateSpec;

/// The whole file as written: one raw type per section.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawExperiment {
    data: Option<Spanned<RawData>>,
    system: Option<Spanned<system::RawSystem>>,
    integrator: Option<Spanned<integrator::RawIntegrator>>,
    #[serde(default)]
    models: Vec<Spanned<models::RawModel>>,
    simulate: Option<Spanned<simulate::RawSimulate>>,
    discover: Option<Spanned<DiscoverSpec>>,
    fit: Option<Spanned<fit::RawFit>>,
    filter: Option<Spanned<filter::RawFilter>>,
    #[serde(default)]
    identify: Vec<Spanned<identify::RawStage>>,
    regimes: Option<Spanned<toml::Value>>,
    #[serde(default)]
    output: OutputSpec,
    validate: Option<Spanned<validate::RawValidate>>,
    scripts: Option<Spanned<scripts::RawScripts>>,
}

/// A checked experiment.
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
    /// Measured channels the record carries (`[data] channels`), besides those laws name.
    pub data_channels: Vec<String>,
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

/// The most bytes an experiment file may hold: 16 MiB, thousands of times a real one (a
/// long `profile` included), so that a wrong path (`/dev/zero`) is an error, not a full memory.
pub const MAX_EXPERIMENT_BYTES: u64 = 16 << 20;

/// The text of the experiment file at `path`, at most `limit` bytes.
pub fn read_text(path: &Path, limit: u64) -> Result<String> {
    read_file_to_string(path, limit).map_err(|e| match e {
        BoundedError::TooLarge { .. } | BoundedError::NoMemory { .. } => {
            anyhow::anyhow!("{}: the experiment file {e}", path.display())
        }
        BoundedError::Io(e) => {
            anyhow::anyhow!("cannot read experiment file {}: {e}", path.display())
        }
    })
}

/// The folder of the file at `path`, `.` for a bare name.
fn folder_of(path: &Path) -> PathBuf {
    match path.parent() {
        Some(dir) if !dir.as_os_str().is_empty() => dir.to_path_buf(),
        _ => PathBuf::from("."),
    }
}

impl Experiment {
    /// This experiment with its `[data] file` replaced by `record` (a campaign runs one
    /// experiment on many records): the layout keys of `[data]` stay; the file is untouched.
    pub fn with_data_file(mut self, record: PathBuf) -> Experiment {
        self.data_file = Some(record);
        self
    }

    /// Read and check an experiment file.
    pub fn load(path: &Path) -> Result<Experiment> {
        Self::load_capped(path, MAX_EXPERIMENT_BYTES)
    }

    /// [`Experiment::load`], refusing a file of more than `limit` bytes.
    pub fn load_capped(path: &Path, limit: u64) -> Result<Experiment> {
        let text = read_text(path, limit)?;
        Self::parse(path, &text)
    }

    /// Validate the text of an experiment file that lives at `path`. Every mistake is
    /// reported at once ([`mistakes::Mistakes`]): each value the reading refuses, then each
    /// section's error.
    pub fn parse(path: &Path, text: &str) -> Result<Experiment> {
        let cx = Ctx { file: path, text };
        // NaN and infinities are refused first, with their key (deserialising refuses a
        // number beyond a double's range without it).
        let mut read = mistakes::read_all::<RawExperiment>(&cx, text);
        let mut errors = std::mem::take(&mut read.errors);
        if let Some(raw) = read.raw.take() {
            let cx = Ctx {
                file: path,
                text: &read.text,
            };
            match Self::check(raw, &cx) {
                Ok(exp) if errors.is_empty() => return Ok(exp),
                Ok(_) => {}
                Err(more) => errors.extend(more.into_iter().filter(|e| !read.follows(e))),
            }
        }
        Err(Mistakes::of(path, errors))
    }

    /// Settings for `record` built in code, no experiment file: every section at its default
    /// (the source study's oscillator, its filters and thresholds, the default solver), no
    /// model yet ([`Experiment::with_model`]). Script paths are relative to the record's
    /// folder; messages name the record.
    ///
    /// ```no_run
    /// use stf_study::prelude::*;
    /// let mut exp = Experiment::for_record("experiments/records/power_law_sweep.csv")?
    ///     .with_model("power_law")
    ///     .with_model("viscous");
    /// let fitted = fit(&mut exp, &Silent)?;
    /// # Ok::<(), StudyError>(())
    /// ```
    pub fn for_record(record: impl Into<PathBuf>) -> Result<Experiment> {
        let record = record.into();
        let text = String::new();
        let cx = Ctx {
            file: &record,
            text: &text,
        };
        let mut exp = Self::check(RawExperiment::default(), &cx)
            .map_err(|errors| Mistakes::of(&record, errors))?;
        exp.data_file = Some(record);
        Ok(exp)
    }

    /// These settings with one more model to fit: a built-in's name, a sum (`"power_law +
    /// added_mass"`) or a rhai script's path (ending in `.rhai`), its parameters at their
    /// defaults.
    pub fn with_model(mut self, model: &str) -> Experiment {
        let source = if model.ends_with(".rhai") {
            ModelSource::Script(model.to_string())
        } else {
            ModelSource::Name(model.to_string())
        };
        self.models.push(ModelEntry {
            source,
            plus: Vec::new(),
            params: Vec::new(),
            line: 0,
            key: format!("models[{}]", self.models.len()),
        });
        self
    }

    /// The sections of `raw`, checked in turn, every section's error kept; `cx` is the file
    /// they come from.
    fn check(raw: RawExperiment, cx: &Ctx) -> Result<Experiment, Vec<anyhow::Error>> {
        let dir = folder_of(cx.file);
        let mut errors = Vec::new();
        let e = &mut errors;
        let system = keep(e, system::check(raw.system.as_ref(), cx));
        let integrator = keep(e, integrator::check(raw.integrator.as_ref(), cx));
        let models = keep(e, models::check(&raw.models, "models", cx));
        let simulate = keep(e, simulate::check(raw.simulate.as_ref(), cx));
        let fit = keep(e, fit::check(raw.fit.as_ref(), cx));
        let kinematics = keep(e, filter::check(raw.filter.as_ref(), cx)).and_then(|k| {
            let drive = filter::with_drive(k, raw.filter.as_ref(), raw.data.as_ref(), cx);
            keep(e, drive)
        });
        let identify = keep(e, identify::check(&raw.identify, cx, &dir));
        let regimes = keep(e, regimes::check(raw.regimes.as_ref(), cx));
        let data = keep(e, data_layout::parse(cx, raw.data.as_ref(), &dir));
        let validate = keep(e, validate::spec(raw.validate.as_ref(), cx, &dir));
        let scripts = keep(e, scripts::run(raw.scripts.as_ref(), cx));
        let (
            Some(system),
            Some(integrator),
            Some(models),
            Some(simulate),
            Some(fit),
            Some(kinematics),
            Some(identify),
            Some(regimes),
            Some(data),
            Some(validate),
            Some(scripts),
        ) = (
            system, integrator, models, simulate, fit, kinematics, identify, regimes, data,
            validate, scripts,
        )
        else {
            return Err(errors);
        };
        Ok(Experiment {
            validate,
            scripts,
            path: cx.file.to_path_buf(),
            data_window: data.window,
            data_layout: data.layout,
            data_plausibility: data.plausibility,
            data_channels: data.channels,
            fit,
            kinematics,
            identify,
            regimes,
            output: raw.output,
            data_file: data.file,
            data_line: data.line,
            dir,
            system,
            system_given: raw.system.is_some(),
            integrator,
            models,
            simulate,
            discover: raw.discover.map(|d| {
                let line = cx.line(d.span().start);
                DiscoverSpec {
                    line,
                    ..d.into_inner()
                }
            }),
        })
    }
}

/// The value of `r`, or none with its error added to `errors`: how a check goes on past a
/// section's error to report the next section's too.
fn keep<T>(errors: &mut Vec<anyhow::Error>, r: Result<T>) -> Option<T> {
    r.map_err(|e| errors.push(e)).ok()
}

/// `text` parsed as the experiment file `exp.toml`: what the tests of every section check.
#[cfg(test)]
pub fn parse_exp(text: &str) -> Result<Experiment> {
    Experiment::parse(Path::new("exp.toml"), text)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::parse_exp as parse;

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
    fn paths_are_relative_to_the_file_s_folder() {
        assert_eq!(folder_of(Path::new("exp.toml")), Path::new("."));
        assert_eq!(folder_of(Path::new("a/b/exp.toml")), Path::new("a/b"));
        let e = parse("[data]\nfile = \"r.csv\"\n").unwrap();
        assert_eq!(
            (e.dir.as_path(), e.data_file.unwrap()),
            (Path::new("."), "./r.csv".into())
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
        /// Any text is an experiment or an error, never a panic. Long run (documented in
        /// docs/robustness.md): `PROPTEST_CASES=1000000 cargo test --release --bin stf-lab never_panics`.
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
