//! Why a discovery run could not start or finish: typed errors saying what was wrong.

use thiserror::Error;

use crate::fit::FitError;
use crate::physics::force_model::ModelError;
use crate::regimes::RegimeError;

/// A discovery request was invalid, or a fit it needs could not run.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum DiscoveryError {
    /// Settings out of range.
    #[error("bad discovery settings: {0}")]
    BadSettings(String),
    /// The data cannot be analysed (lengths differ, too few cycles, …).
    #[error("bad discovery data: {0}")]
    BadData(String),
    /// Holding out every `every`-th whole cycle holds out none: the record has fewer.
    #[error(
        "holdout_every = {every} holds out none of the record's {cycles} whole cycles (one in \
         {every} is held out to score each effect): give holdout_every at most {cycles}, or \
         leave it out (the default holds out one cycle in 4)"
    )]
    NoHoldout {
        /// Whole cycles of the record.
        cycles: usize,
        /// One cycle in this many is held out.
        every: usize,
    },
    /// Two candidates share a name, or a candidate has the base model's name.
    #[error("candidate `{0}` is listed twice or is the base model itself")]
    DuplicateCandidate(String),
    /// The base model (or the model grown from it) could not be fitted.
    #[error("fitting `{model}`: {source}")]
    Fit {
        /// The model being fitted.
        model: String,
        /// Why the fit failed.
        source: FitError,
    },
    /// A sum of models could not be formed.
    #[error(transparent)]
    Model(#[from] ModelError),
    /// The noise floor or the cycles could not be computed.
    #[error(transparent)]
    Regime(#[from] RegimeError),
}
