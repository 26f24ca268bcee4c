//! The study API in one import: read an experiment (or build its settings in code), run a
//! workflow, read the typed result. Each call returns a [`StudyError`] whose kind says what
//! failed; the results are the types the command line renders and writes, so a number read
//! here is the number `fit.json`, `compare.json` or `discovery.json` holds.
//!
//! ```
//! use stf_study::prelude::*;
//!
//! # fn main() -> Result<(), StudyError> {
//! # std::env::set_current_dir("..").expect("the workspace root, where experiments/ is");
//! // A power law fitted to the bundled record (force level: it has `f_stf`).
//! let mut exp = read_experiment("experiments/power_law_fit.toml")?;
//! let fitted = fit(&mut exp, &Silent)?;
//! for f in &fitted.fits {
//!     println!("{}: RMS {:.4} N, AIC {:.1}", f.label, f.result.rms, f.result.aic);
//! }
//! println!("{}", fitted.verdict().text);
//!
//! // Four models compared regime by regime on an on–off jamming record.
//! let mut exp = read_experiment("experiments/jamming_compare.toml")?;
//! let compared = compare(&mut exp, &Silent)?;
//! println!("best by force error: {:?}", compared.compared.ranking.overall.first());
//!
//! // The effect a power law misses, named and added.
//! let mut exp = read_experiment("experiments/discovery.toml")?;
//! let found = discover(&mut exp, &Silent)?;
//! println!("effects {:?}: gap {:.4} → {:.4} N", found.found.effects,
//!          found.found.gap_before, found.found.gap_after);
//! # Ok(())
//! # }
//! ```

use std::path::Path;

pub use crate::compare::CompareResult;
pub use crate::discover::Discovered;
pub use crate::error::{ErrorKind, StudyError};
pub use crate::experiment::{Experiment, FitLevel};
pub use crate::fit::Fitted;
pub use crate::fitting::{FitData, ModelFit};
pub use crate::identify::Identification;
pub use crate::observer::{Job, Observer, Silent};

/// Read and check an experiment file (TOML): the typed settings of every workflow. Settings
/// can also be built in code: [`Experiment::for_record`] and [`Experiment::with_model`].
pub fn read_experiment(path: impl AsRef<Path>) -> Result<Experiment, StudyError> {
    Ok(Experiment::load(path.as_ref())?)
}

/// Fit every model of `exp` to its record, at the record's level
/// ([`crate::fit::fit`]).
pub fn fit(exp: &mut Experiment, observer: &dyn Observer) -> Result<Fitted, StudyError> {
    Ok(crate::fit::fit(exp, observer)?)
}

/// Run the `[[identify]]` stages of `exp` ([`crate::identify::identify`]).
pub fn identify(exp: &Experiment, observer: &dyn Observer) -> Result<Identification, StudyError> {
    Ok(crate::identify::identify(exp, observer)?)
}

/// Fit every model of `exp`, then compare them regime by regime
/// ([`crate::compare::compare`]).
pub fn compare(exp: &mut Experiment, observer: &dyn Observer) -> Result<CompareResult, StudyError> {
    Ok(crate::compare::compare(exp, observer)?)
}

/// Discover what the base of `exp`'s `[discover]` misses ([`crate::discover::discover`]).
pub fn discover(exp: &mut Experiment, observer: &dyn Observer) -> Result<Discovered, StudyError> {
    Ok(crate::discover::discover(exp, observer)?)
}
