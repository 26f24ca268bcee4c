//! stf-plugins: force models written as rhai scripts, and the registry that maps a model name
//! or a script path to a [`stf_core::physics::force_model::ForceModel`].
//!
//! ```
//! use stf_plugins::registry::Registry;
//! let registry = Registry::new();
//! let viscous = registry.resolve("viscous", std::path::Path::new(".")).unwrap();
//! assert_eq!(viscous.name(), "viscous");
//! assert!(registry.resolve("nonesuch", std::path::Path::new(".")).is_err());
//! ```

#![deny(clippy::unwrap_used)]

pub mod error;
pub mod limits;
pub mod registry;
pub mod sandbox;
mod script_compiled;
pub mod script_model;
mod script_params;
mod script_size;

pub use error::{ScriptError, ScriptLocation};
pub use limits::{ScriptLimits, ScriptRun};
pub use script_model::ScriptModel;
