//! The noise floor of a fit: the RMS residual that measurement noise alone leaves, against
//! which a fit's RMS residual is judged.
//!
//! Force level: the residual `F_meas − F_model(x, v, a)` carries the force sensor's noise and
//! the noise of the kinematics that the model is evaluated along (σ_x as measured, σ_v and σ_a
//! left by the derivative filter), propagated through the model. The two are independent, so
//! the floor is `√(σ_F² + σ_prop²)`, where `σ_prop² = mean_i Σ_q (ΔF_i,q)²` and `ΔF_i,q` is half
//! the change of the modelled force at sample i between the kinematic quantity q shifted by
//! +σ_q and by −σ_q (a central difference at the size of the noise, so a steep power law near
//! v = 0 is not linearised over a step larger than the noise itself). Trajectory level: the
//! residual `x_meas − x_sim` carries the position noise σ_x only.
//!
//! The floor is kept in SI; the unit it and the residuals are shown in ([`ShownIn`]) is the
//! caller's to give ([`NoiseFloor::shown_in`]): the record's own (mV for a record in volts, kN
//! for a force in kN), N or mm when none is given.

use serde::Serialize;

use super::error::FitError;
use super::force_fit::ForceFit;
use crate::data::force_data::ForceData;
use crate::data::kinematics::MotionNoise;

/// The quantity a fit's residuals measure.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Quantity {
    /// Force, N (force-level fits).
    Force,
    /// Displacement, m (trajectory-level fits).
    Displacement,
}

impl Quantity {
    /// The SI unit of the residuals.
    pub fn unit(self) -> &'static str {
        match self {
            Quantity::Force => "N",
            Quantity::Displacement => "m",
        }
    }

    /// The unit a reader expects when the record says nothing else: N, or mm for
    /// displacements.
    pub fn shown_in(self) -> ShownIn {
        match self {
            Quantity::Force => ShownIn::new("N", 1.0),
            Quantity::Displacement => ShownIn::new("mm", 1e3),
        }
    }
}

/// The unit residuals are shown in, and the factor from their SI values to it.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ShownIn {
    /// The unit's symbol (`N`, `kN`, `mm`, `mV`, …).
    pub unit: &'static str,
    /// From the SI value to the shown one.
    pub scale: f64,
}

impl ShownIn {
    /// The unit `unit`, a shown value being `scale` × the SI value.
    pub const fn new(unit: &'static str, scale: f64) -> Self {
        ShownIn { unit, scale }
    }

    /// `value` (SI) in this unit, to four decimals, with the unit.
    pub fn show(self, value: f64) -> String {
        format!("{:.4} {}", value * self.scale, self.unit)
    }
}

/// The RMS residual that measurement noise alone leaves.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct NoiseFloor {
    /// What the residuals measure.
    pub quantity: Quantity,
    /// The floor σ (N or m): `√(measured² + propagated²)`.
    pub sigma: f64,
    /// Noise of the fitted signal itself: the force sensor's, or the position noise.
    pub measured: f64,
    /// Noise of the kinematics propagated through the model (force level; 0 otherwise).
    pub propagated: f64,
    /// The unit the floor and the residuals are shown in (not written: the JSON is SI).
    #[serde(skip)]
    pub shown: ShownIn,
}

impl NoiseFloor {
    /// The floor of a trajectory-level fit: the position noise σ_x (m).
    pub fn displacement(sigma_x: f64) -> Self {
        NoiseFloor {
            quantity: Quantity::Displacement,
            sigma: sigma_x,
            measured: sigma_x,
            propagated: 0.0,
            shown: Quantity::Displacement.shown_in(),
        }
    }

    /// The floor of a force-level fit from the sensor's noise σ_F and the propagated noise (N).
    pub fn force(sensor: f64, propagated: f64) -> Self {
        NoiseFloor {
            quantity: Quantity::Force,
            sigma: sensor.hypot(propagated),
            measured: sensor,
            propagated,
            shown: Quantity::Force.shown_in(),
        }
    }

    /// The floor shown in `shown`, the record's own unit, instead of N or mm.
    pub fn shown_in(self, shown: ShownIn) -> Self {
        NoiseFloor { shown, ..self }
    }

    /// Whether the floor is a usable yardstick (positive and finite).
    pub fn is_usable(&self) -> bool {
        self.sigma > 0.0 && self.sigma.is_finite()
    }
}

impl ForceFit {
    /// The noise floor of this fit on `data` with the full parameter vector `values` (as for
    /// [`ForceFit::predict`]): the force sensor's noise `sensor` (N) combined with `motion`
    /// propagated through the model (see the module's text).
    pub fn noise_floor(
        &self,
        data: &ForceData,
        values: &[f64],
        sensor: f64,
        motion: MotionNoise,
    ) -> Result<NoiseFloor, FitError> {
        let n = data.t.len();
        let mut sum = vec![0.0; n];
        for (q, sigma) in [motion.x, motion.v, motion.a].into_iter().enumerate() {
            if !(sigma > 0.0 && sigma.is_finite()) {
                continue;
            }
            let side = |by: f64| {
                let column: Vec<f64> = [data.x, data.v, data.a][q].iter().map(|v| v + by).collect();
                let mut d = *data;
                match q {
                    0 => d.x = &column,
                    1 => d.v = &column,
                    _ => d.a = &column,
                }
                self.predict(&d, values)
            };
            let (up, down) = (side(sigma)?, side(-sigma)?);
            for (s, (up, down)) in sum.iter_mut().zip(up.iter().zip(&down)) {
                *s += (0.5 * (up - down)).powi(2);
            }
        }
        let propagated = (sum.iter().sum::<f64>() / n.max(1) as f64).sqrt();
        Ok(NoiseFloor::force(sensor, propagated))
    }
}

#[cfg(test)]
mod tests {
    use std::sync::Arc;

    use super::*;
    use crate::physics::force_model::{ForceModel, ModelError, ModelState};
    use crate::physics::param_spec::ParamSpec;

    /// F = c·v + m_a·a.
    struct Damper(Vec<ParamSpec>);
    impl ForceModel for Damper {
        fn name(&self) -> &str {
            "damper"
        }
        fn params(&self) -> &[ParamSpec] {
            &self.0
        }
        fn force(&self, p: &[f64], s: &ModelState, _: &mut [f64]) -> Result<f64, ModelError> {
            Ok(p[0] * s.v)
        }
        fn added_mass(&self, p: &[f64], _: &ModelState) -> Result<f64, ModelError> {
            Ok(p[1])
        }
    }

    #[test]
    fn a_linear_model_propagates_the_noise_by_its_coefficients() {
        let model = Arc::new(Damper(vec![
            ParamSpec::new("c", "N·s/m", 1.0, 0.0, 100.0, ""),
            ParamSpec::new("m_a", "kg", 0.0, 0.0, 10.0, ""),
        ]));
        let t: Vec<f64> = (0..50).map(|i| i as f64 * 0.01).collect();
        let zeros = vec![0.0; t.len()];
        let data = ForceData::new(&t, &zeros, &zeros, &zeros, &zeros);
        let motion = MotionNoise {
            x: 1e-4,
            v: 0.01,
            a: 0.5,
        };
        let floor = ForceFit::new(model)
            .noise_floor(&data, &[3.0, 0.2], 0.04, motion)
            .unwrap();
        // c·σ_v = 0.03 N and m_a·σ_a = 0.1 N; x does not enter.
        let propagated = 0.03f64.hypot(0.1);
        assert!((floor.propagated - propagated).abs() < 1e-12);
        assert!((floor.sigma - propagated.hypot(0.04)).abs() < 1e-12);
        assert_eq!(floor.quantity, Quantity::Force);
    }

    #[test]
    fn a_trajectory_floor_is_the_position_noise() {
        let floor = NoiseFloor::displacement(5e-5);
        assert_eq!((floor.sigma, floor.propagated), (5e-5, 0.0));
        assert_eq!(floor.shown.show(floor.sigma), "0.0500 mm");
        let volts = floor.shown_in(ShownIn::new("mV", 1e3));
        assert_eq!(volts.shown.show(volts.sigma), "0.0500 mV");
        assert!(!NoiseFloor::displacement(0.0).is_usable());
    }
}
