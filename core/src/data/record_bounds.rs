//! Bounds that follow the record: a model's parameter bounds are set for the source study's
//! trolley (an added mass up to 20 kg, a yield force up to 50 N), and a record of another rig
//! — a 95 kg positioning axis, an electronic oscillator in volts — needs values far outside
//! them. Each parameter whose unit is one of the common ones below gets a typical size from
//! the record (the RMS force `F`, the largest |x| `X`, |v| `V`, |a| `A`); where its upper bound
//! is less than [`ROOM`] times that size, the bound is raised to [`WIDE`] times it. Bounds are
//! only ever widened, never narrowed, so a record at the trolley's scale keeps them as they are.
//!
//! | unit | size |
//! |---|---|
//! | `kg` | F/A |
//! | `N·s/m` | F/V |
//! | `N` | F |
//! | `N/m` | F/X |
//! | `N/m³` | F/X³ |
//! | `m` | X |
//! | `m/s` | V |
//!
//! A default start more than [`FAR`] typical sizes from the record's (either way) starts at the
//! typical size instead: a cubic spring's 1e5 N/m³ is a start for the trolley, and for an
//! electronic oscillator in volts (k3 ≈ 4 V/V³) a start in another basin.
//!
//! A model whose bounds change is wrapped ([`Widened`]): it forces as the original and only
//! reports other specs.

use std::sync::Arc;

use crate::physics::force_model::{ForceModel, ModelError, ModelState, Reach};
use crate::physics::param_spec::ParamSpec;
use crate::physics::track::Track;

/// An upper bound below this many typical sizes is too tight for the record.
pub const ROOM: f64 = 10.0;
/// A widened upper bound is this many typical sizes.
pub const WIDE: f64 = 1000.0;

/// A positive default more than this many typical sizes from the record's, either way, is
/// moved to the typical size.
pub const FAR: f64 = 100.0;

/// The typical sizes of a record's force and motion.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DataScales {
    /// RMS of the force, N.
    pub force: f64,
    /// Largest |x|, m.
    pub x: f64,
    /// Largest |v|, m/s.
    pub v: f64,
    /// Largest |a|, m/s².
    pub a: f64,
}

impl DataScales {
    /// The sizes of a force `f` along the motion `x`, `v`, `a` (equal lengths).
    pub fn of(f: &[f64], x: &[f64], v: &[f64], a: &[f64]) -> Self {
        let max = |s: &[f64]| s.iter().fold(0.0_f64, |m, v| m.max(v.abs()));
        let rms = (f.iter().map(|v| v * v).sum::<f64>() / f.len().max(1) as f64).sqrt();
        DataScales {
            force: rms,
            x: max(x),
            v: max(v),
            a: max(a),
        }
    }

    /// The typical size of a parameter of `unit`, if the unit is one of the table's.
    pub fn size_of(&self, unit: &str) -> Option<f64> {
        let s = match unit {
            "kg" => self.force / self.a,
            "N·s/m" => self.force / self.v,
            "N" => self.force,
            "N/m" => self.force / self.x,
            "N/m³" => self.force / self.x.powi(3),
            "m" => self.x,
            "m/s" => self.v,
            _ => return None,
        };
        (s > 0.0 && s.is_finite()).then_some(s)
    }

    /// `spec` with its upper bound widened where the record needs it, and its default moved
    /// to the typical size where it is more than [`FAR`] from it.
    pub fn widen(&self, spec: &ParamSpec) -> ParamSpec {
        let mut spec = spec.clone();
        if let Some(size) = self.size_of(&spec.unit) {
            if spec.max.is_finite() && spec.max < ROOM * size {
                spec.max = WIDE * size;
            }
            let far = spec.default > FAR * size || spec.default < size / FAR;
            if spec.default > 0.0 && far && (spec.min..=spec.max).contains(&size) {
                spec.default = size;
            }
        }
        spec
    }
}

/// `model` with the bounds `scales` asks for: itself when none changes.
pub fn widened(model: Arc<dyn ForceModel>, scales: &DataScales) -> Arc<dyn ForceModel> {
    let specs: Vec<ParamSpec> = model.params().iter().map(|s| scales.widen(s)).collect();
    if specs.as_slice() == model.params() {
        return model;
    }
    Arc::new(Widened {
        inner: model,
        specs,
    })
}

/// A model with other parameter bounds; everything else is the inner model's, its parts as
/// a sum included (an integration resolves a widened sum into its parts as it does the sum:
/// the bounds matter to a fit, never to the force).
pub struct Widened {
    inner: Arc<dyn ForceModel>,
    specs: Vec<ParamSpec>,
}

impl ForceModel for Widened {
    fn name(&self) -> &str {
        self.inner.name()
    }
    fn summary(&self) -> &str {
        self.inner.summary()
    }
    fn terms(&self) -> Vec<&str> {
        self.inner.terms()
    }
    fn summands(&self) -> Option<&[Arc<dyn ForceModel>]> {
        self.inner.summands()
    }
    fn params(&self) -> &[ParamSpec] {
        &self.specs
    }
    fn n_internal(&self) -> usize {
        self.inner.n_internal()
    }
    fn initial_internal(&self, p: &[f64], z0: &mut [f64]) {
        self.inner.initial_internal(p, z0)
    }
    fn added_mass(&self, p: &[f64], s: &ModelState) -> Result<f64, ModelError> {
        self.inner.added_mass(p, s)
    }
    fn force(&self, p: &[f64], s: &ModelState, dz: &mut [f64]) -> Result<f64, ModelError> {
        self.inner.force(p, s, dz)
    }
    fn mass_and_force(
        &self,
        p: &[f64],
        s: &ModelState,
        dz: &mut [f64],
    ) -> Result<(f64, f64), ModelError> {
        self.inner.mass_and_force(p, s, dz)
    }
    fn rates(&self, p: &[f64], s: &ModelState, dz: &mut [f64]) -> Result<(), ModelError> {
        self.inner.rates(p, s, dz)
    }
    fn gradient(
        &self,
        p: &[f64],
        s: &ModelState,
        a: f64,
        grad: &mut [f64],
    ) -> Result<bool, ModelError> {
        self.inner.gradient(p, s, a, grad)
    }
    fn mass_and_force_along(
        &self,
        p: &[f64],
        track: &Track,
        rows: Option<&[usize]>,
        mass: &mut [f64],
        force: &mut [f64],
    ) -> Result<(), ModelError> {
        self.inner.mass_and_force_along(p, track, rows, mass, force)
    }
    fn mass_and_force_lanes(
        &self,
        ps: &[&[f64]],
        track: &Track,
        rows: Option<&[usize]>,
    ) -> Option<Vec<(Vec<f64>, Vec<f64>)>> {
        self.inner.mass_and_force_lanes(ps, track, rows)
    }
    fn gradient_along(
        &self,
        p: &[f64],
        track: &Track,
        a: &[f64],
        rows: Option<&[usize]>,
        grad: &mut [f64],
    ) -> Result<bool, ModelError> {
        self.inner.gradient_along(p, track, a, rows, grad)
    }
    fn reduces_to(&self, p: &[f64], reach: Reach) -> Option<(String, Vec<f64>)> {
        self.inner.reduces_to(p, reach)
    }
    fn equation(&self, values: &[String]) -> Option<String> {
        self.inner.equation(values)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec(unit: &str, max: f64) -> ParamSpec {
        ParamSpec::new("p", unit, 1.0, 0.0, max, "")
    }

    /// A 95 kg axis pushed by ~60 N at ~1 m/s²: an added mass bound of 20 kg is raised; the
    /// trolley (7.65 kg, a few N at a few m/s²) keeps it.
    #[test]
    fn bounds_widen_only_where_the_record_needs_it() {
        let axis = DataScales {
            force: 60.0,
            x: 0.25,
            v: 0.5,
            a: 1.0,
        };
        assert_eq!(axis.widen(&spec("kg", 20.0)).max, 6e4);
        assert_eq!(axis.widen(&spec("N", 50.0)).max, 6e4);
        let trolley = DataScales {
            force: 0.5,
            x: 0.03,
            v: 0.2,
            a: 2.0,
        };
        assert_eq!(trolley.widen(&spec("kg", 20.0)).max, 20.0);
        assert_eq!(trolley.widen(&spec("N", 50.0)).max, 50.0);
        assert_eq!(
            axis.widen(&spec("N·(s/m)ⁿ", 50.0)).max,
            50.0,
            "unknown unit: as is"
        );
    }

    /// An electronic oscillator in volts (x ≈ 0.2 V, a force of 0.05 V RMS): the cubic
    /// spring's trolley start 1e5 moves to the record's size F/X³ ≈ 6; the trolley keeps it.
    #[test]
    fn a_default_far_from_the_record_starts_at_its_size() {
        let volts = DataScales {
            force: 0.05,
            x: 0.2,
            v: 50.0,
            a: 2e4,
        };
        let k3 = ParamSpec::new("k3", "N/m³", 1e5, 0.0, 1e9, "");
        let moved = volts.widen(&k3);
        assert!((moved.default - 6.25).abs() < 1e-9, "{}", moved.default);
        assert_eq!(moved.max, 1e9);
        let trolley = DataScales {
            force: 5.0,
            x: 0.03,
            v: 0.3,
            a: 5.0,
        };
        assert_eq!(trolley.widen(&k3).default, 1e5);
        let below = ParamSpec::new("c", "N·s/m", 1e-6, 0.0, 1e3, "");
        assert_eq!(trolley.widen(&below).default, 5.0 / 0.3);
    }
}
