//! stf-models: the built-in shear-thickening fluid force models of stf-lab.
//!
//! Each model implements [`stf_core::force_model::ForceModel`] and is listed in [`BUILTINS`],
//! the one static table the registry reads. Models add: a [`stf_core::model_sum::ModelSum`] of
//! built-ins is a model too.
//!
//! ```
//! use stf_models::find;
//! let viscous = find("viscous").unwrap();
//! assert_eq!(viscous.params()[0].name, "c_s");
//! ```

#![deny(clippy::unwrap_used)]

use std::sync::Arc;

use stf_core::force_model::ForceModel;

pub mod viscous;

/// An entry of the table of built-in models.
pub struct BuiltinEntry {
    /// The name used in experiment files.
    pub name: &'static str,
    /// One line saying what the model is.
    pub summary: &'static str,
    /// Make the model.
    pub build: fn() -> Arc<dyn ForceModel>,
}

/// Every built-in model, in the order they are listed to users.
pub const BUILTINS: &[BuiltinEntry] = &[BuiltinEntry {
    name: "viscous",
    summary: viscous::SUMMARY,
    build: || Arc::new(viscous::Viscous::new()),
}];

/// The built-in model called `name`, if there is one.
pub fn find(name: &str) -> Option<Arc<dyn ForceModel>> {
    BUILTINS
        .iter()
        .find(|e| e.name == name)
        .map(|e| (e.build)())
}

/// The names of all built-in models.
pub fn names() -> Vec<&'static str> {
    BUILTINS.iter().map(|e| e.name).collect()
}
