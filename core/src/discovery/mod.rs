//! Discovery: find where a model and the measurement disagree, name the missing effect, add
//! it, and show the gap shrink.
//!
//! At force level (records with a measured F_STF and kinematics, [`ForceData`]),
//! [`discover_force`] runs the workflow:
//!
//! 1. fit the base model on the whole record;
//! 2. locate its residual against the noise floor ([`force_gap`]: by regime, ω band, |x|, |v|, |a|
//!    and direction of motion, in words);
//! 3. add each [`Candidate`] not yet in the model to it ([`crate::physics::model_sum::ModelSum`]),
//!    refit the sum from the current values (the new parameters from their defaults) on the
//!    training cycles and score it on the held-out ones ([`holdout`]) and by AIC/BIC; accept
//!    the best only if the data demand it ([`acceptance`]), naming ties;
//! 4. repeat until nothing is significant or `max_effects` are added;
//! 5. refit the final model on the whole record: gap (RMS residual) before and after.
//!
//! At trajectory level (records with a measured displacement only), [`discover_trajectory`]
//! runs the same workflow on the simulated oscillator against the measured x, refitting the
//! oscillator's own parameters with every model ([`trajectory_level`]).
//!
//! Either result scores its base and final models on another record ([`before_after_validation`]).
//!
//! Core knows no model library: the caller passes the base and the candidates (built-ins of
//! docs/ARCHITECTURE.md §5, scripts) as [`std::sync::Arc`]`<dyn ForceModel>`.
//!
//! [`ForceData`]: crate::data::force_data::ForceData

pub mod acceptance;
pub mod before_after_validation;
pub mod blocks;
pub mod candidate;
mod choice;
mod costly_first;
pub mod error;
pub mod findings;
pub mod force_gap;
pub mod force_level;
pub mod holdout;
mod level;
pub mod progress;
mod reconsider;
pub mod score;
mod scout;
mod search;
mod search_model;
pub mod settings;
mod trajectory_gap;
pub mod trajectory_level;
pub mod trajectory_setup;
mod trajectory_starts;
mod trajectory_subset_fit;

pub use before_after_validation::DiscoveryValidation;
pub use candidate::Candidate;
pub use error::DiscoveryError;
pub use findings::{Discovery, TrajectoryPart};
pub use force_gap::{locate_gap, GapBreakdown, GapGroup, GapLocation};
pub use force_level::discover_force;
pub use holdout::HoldoutSplit;
pub use progress::{DiscoveryEvent, Observer};
pub use score::{CandidateScore, Step};
pub use settings::DiscoverySettings;
pub use trajectory_level::discover_trajectory;
pub use trajectory_setup::{ForceHint, TrajectorySetup};
