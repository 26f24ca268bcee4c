//! stf-models: the built-in shear-thickening fluid force models of stf-lab.
//!
//! Each model implements [`stf_core::physics::force_model::ForceModel`] and is listed in [`BUILTINS`],
//! the one static table the registry reads. Models add: a [`stf_core::physics::model_sum::ModelSum`] of
//! built-ins is a model too.
//!
//! | name | law | parameters |
//! |---|---|---|
//! | `viscous` | c_s·v | `c_s` |
//! | `power_law` | K·\|v\|ⁿ·sign v | `K`, `n` |
//! | `added_mass` | m_a·ẍ | `m_a` |
//! | `yield` | F_y·v/√(v² + v_s²) | `F_y`, `v_s` |
//! | `wall_impact` | Hunt–Crossley contact past \|x\| = gap | `k_w`, `gap`, `p`, `c_r` |
//! | `cubic_stiffness` | k3·x³ | `k3` |
//! | `maxwell` | dF/dt = (c_m·v − F)/τ | `c_m`, `tau` |
//! | `jamming_on_off` | K_j·\|v\|^n_j·sign v, gated on above v_c | `K_j`, `n_j`, `v_c`, `w` |
//! | `bouc_wen` | F_bw·w, ẇ = (ẋ − beta·\|ẋ\|·w − (1 − beta)·ẋ·\|w\|)/x_bw | `F_bw`, `x_bw`, `beta` |
//! | `linear_spring` | k_s·x | `k_s` |
//!
//! ```
//! use stf_models::find;
//! let viscous = find("viscous").unwrap();
//! assert_eq!(viscous.params()[0].name, "c_s");
//! ```

#![deny(clippy::unwrap_used)]
#![cfg_attr(test, allow(clippy::unwrap_used))]

use std::sync::Arc;

use stf_core::physics::force_model::ForceModel;

pub mod added_mass;
pub mod bouc_wen;
mod builtin;
pub mod cubic_stiffness;
pub mod jamming_on_off;
pub mod linear_spring;
pub mod maxwell;
pub mod power_law;
mod values;
pub mod viscous;
pub mod wall_impact;
pub mod yield_stress;

/// An entry of the table of built-in models.
pub struct BuiltinEntry {
    /// The name used in experiment files.
    pub name: &'static str,
    /// One line saying what the model is.
    pub summary: &'static str,
    /// Make the model.
    pub build: fn() -> Arc<dyn ForceModel>,
}

/// Every built-in model, in the order they are listed to users. The names are those of the
/// discovery vocabulary (docs/ARCHITECTURE.md §5).
pub const BUILTINS: &[BuiltinEntry] = &[
    viscous::Viscous::ENTRY,
    power_law::PowerLaw::ENTRY,
    added_mass::AddedMass::ENTRY,
    yield_stress::Yield::ENTRY,
    wall_impact::WallImpact::ENTRY,
    cubic_stiffness::CubicStiffness::ENTRY,
    maxwell::Maxwell::ENTRY,
    jamming_on_off::JammingOnOff::ENTRY,
    bouc_wen::BoucWen::ENTRY,
    linear_spring::LinearSpring::ENTRY,
];

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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_entry_builds_a_model_of_its_own_name_with_sane_specs() {
        let expected = [
            "viscous",
            "power_law",
            "added_mass",
            "yield",
            "wall_impact",
            "cubic_stiffness",
            "maxwell",
            "jamming_on_off",
            "bouc_wen",
            "linear_spring",
        ];
        assert_eq!(names(), expected);
        for e in BUILTINS {
            let m = (e.build)();
            assert_eq!(m.name(), e.name);
            assert_eq!(m.summary(), e.summary);
            assert!(!m.params().is_empty(), "{}", e.name);
            for s in m.params() {
                assert!(
                    s.min <= s.default && s.default <= s.max,
                    "{}.{}",
                    e.name,
                    s.name
                );
                assert!(!s.doc.is_empty(), "{}.{}", e.name, s.name);
            }
        }
        assert!(find("no_such_model").is_none());
    }
}
