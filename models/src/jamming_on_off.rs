//! `jamming_on_off`: a force that is on only while the blade moves faster than a critical
//! speed — on–off jamming of the fluid around the blade.
//!
//! ## Mechanism
//! A dense suspension flows like a liquid when sheared slowly and jams into a solid-like plug
//! when driven faster than a critical rate (discontinuous shear thickening; Brown & Jaeger,
//! Rep. Prog. Phys. 77, 046602, 2014). Waitukaitis & Jaeger (Nature 487, 205, 2012) showed that
//! an impactor above the onset speed drives a jamming front ahead of it, and the resistance is
//! the momentum handed to the freshly jammed fluid, F ∝ ρ·A·v² — quadratic in speed. When the
//! blade slows below the onset speed the plug melts back into a liquid within milliseconds and
//! the force vanishes. Here, with the blade's speed as the proxy for the shear rate:
//!
//! ```text
//! F = K_j·|v|^n_j·sign v · G(|v|),    G(s) = ½·(1 + tanh((s − v_c)/w))
//! ```
//!
//! ## What it does on the source study's sweep
//! Before resonance (ω < 3.75 rad/s) the trolley sticks in its bearings, |v| ≪ v_c and the
//! force is nil. Past resonance the blade oscillates ≈ 8 mm at ω ≈ 10 rad/s, so its peak speed
//! ω·X ≈ 0.08–0.1 m/s passes v_c = 0.05 m/s twice per rotor cycle: each pass through the middle
//! of the stroke switches the plug on for a pulse (≈ 60 % of each half cycle) and near the
//! turning points, where the blade is slow, the force is zero — on–off spikes with the fluid at
//! rest in between. Through resonance (|v| up to ≈ 0.25 m/s without STF) the plug stays jammed
//! for most of the stroke: strong damping. The force opposes the motion (F·v ≥ 0, purely
//! dissipative) and is odd in v. The pulses sit where |v| is largest; spikes at the turning
//! points (in phase with the acceleration) are what `wall_impact` and `added_mass` add.
//!
//! ## Steepness of the gate
//! The gate is a tanh of width `w` rather than a hard switch so the right-hand side stays
//! smooth for the integrator. The default w = 2 mm/s = v_c/25 makes G go from 1.8 % to 98 %
//! between v_c − 2w and v_c + 2w (46 → 54 mm/s). At ω = 10 rad/s and X = 8 mm the blade's
//! speed sweeps through that band in ≈ 12 ms, 2 % of the 0.63 s rotor period, so each pulse
//! switches on and off abruptly on the scale of the cycle (the rise of the force to its peak
//! then follows |v|^n_j). A steeper gate would not change the cycle's picture but would make
//! fits in `v_c` rougher. The largest slope of the force, ≈ K_j·v_c²/(2w) = 62.5 N·s/m at the
//! defaults, is a damping rate of ≈ 8 s⁻¹ on the 7.65 kg trolley, far from limiting an
//! explicit integrator's step. At rest G = ½(1 − tanh(v_c/w)) ≈ 2·10⁻²²,
//! so the force is zero for every practical purpose.
//!
//! | parameter | unit | default | bounds | meaning |
//! |---|---|---|---|---|
//! | `K_j` | N·(s/m)^n_j | 100 | [0, 1e5] | jammed drag coefficient (1 N at 0.1 m/s with n_j = 2) |
//! | `n_j` | — | 2 | [1, 4] | exponent of the jammed drag (2: momentum transfer to the front) |
//! | `v_c` | m/s | 0.05 | [0, 1] | critical speed of jamming onset |
//! | `w` | m/s | 0.002 | [1e-4, 0.1] | width of the onset gate |

use stf_core::physics::force_model::{ModelError, ModelState, Reach, NEGLIGIBLE_SHARE};
use stf_core::physics::param_spec::ParamSpec;

use crate::builtin::builtin;
use crate::power_law::{power_law_force, power_law_gradient};
use crate::values::take;

builtin! {
    /// On–off jamming above a critical speed; see the [module doc](self).
    JammingOnOff: "jamming_on_off",
    "on–off jamming: F = K_j·|v|^n_j·sign v only above a critical speed v_c",
    params [
        ParamSpec::new("K_j", "N·(s/m)^n_j", 100.0, 0.0, 1e5,
            "drag coefficient of the jammed fluid"),
        ParamSpec::new(
            "n_j",
            "",
            2.0,
            1.0,
            4.0,
            "exponent of the jammed drag (2: momentum transfer to the jamming front)",
        ),
        ParamSpec::new("v_c", "m/s", 0.05, 0.0, 1.0, "critical speed above which the fluid jams"),
        ParamSpec::new("w", "m/s", 0.002, 1e-4, 0.1, "width of the smooth jamming gate"),
    ];
    impl {
        /// The law with its values, `k_j·|v|^n_j·sgn v·½(1 + tanh((|v| − v_c)/w))`.
        fn equation(&self, values: &[String]) -> Option<String> {
            let [k_j, n_j, v_c, w] = values else { return None };
            Some(format!("{k_j}·|v|^{n_j}·sgn v·½(1 + tanh((|v| − {v_c})/{w}))"))
        }
        #[inline]
        fn force(&self, p: &[f64], s: &ModelState, _dz: &mut [f64]) -> Result<f64, ModelError> {
            let [k_j, n_j, v_c, w] = take(self.name(), p)?;
            Ok(power_law_force(k_j, n_j, s.v) * jamming_gate(s.v.abs(), v_c, w))
        }
        fn gradient(
            &self,
            p: &[f64],
            s: &ModelState,
            _a: f64,
            grad: &mut [f64],
        ) -> Result<bool, ModelError> {
            let [k_j, n_j, v_c, w] = take(self.name(), p)?;
            let speed = s.v.abs();
            let (dk, dn) = power_law_gradient(k_j, n_j, s.v);
            let gate = jamming_gate(speed, v_c, w);
            // dG/dq = ½·sech²(q), q = (|v| − v_c)/w; a hard switch (w = 0) has no slope.
            let (dvc, dw) = if w > 0.0 {
                let q = (speed - v_c) / w;
                let slope = 0.5 / q.cosh().powi(2) * power_law_force(k_j, n_j, s.v);
                (-slope / w, -slope * q / w)
            } else {
                (0.0, 0.0)
            };
            grad[..4].copy_from_slice(&[dk * gate, dn * gate, dvc, dw]);
            Ok(true)
        }
        /// A gate open at every speed but the slowest 5 % of the record's (`v_c + 2w` below it):
        /// the ungated `power_law`.
        fn reduces_to(&self, p: &[f64], reach: Reach) -> Option<(String, Vec<f64>)> {
            let [k_j, n_j, v_c, w] = take(self.name(), p).ok()?;
            (v_c + 2.0 * w < NEGLIGIBLE_SHARE * reach.v)
                .then(|| ("power_law".to_string(), vec![k_j, n_j]))
        }
    }
}

/// The jamming gate `½·(1 + tanh((speed − v_c)/w))`; a hard step when `w` is 0.
#[inline]
pub fn jamming_gate(speed: f64, v_c: f64, w: f64) -> f64 {
    if w > 0.0 {
        0.5 * (1.0 + ((speed - v_c) / w).tanh())
    } else if speed > v_c {
        1.0
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use stf_core::physics::force_model::ForceModel;

    fn at(v: f64) -> f64 {
        let m = JammingOnOff::new();
        let s = ModelState {
            t: 0.0,
            x: 0.0,
            v,
            z: &[],
        };
        m.force(&[100.0, 2.0, 0.05, 0.005], &s, &mut []).unwrap()
    }

    #[test]
    fn half_on_at_the_critical_speed_full_above_off_below() {
        // At v_c the gate is exactly ½: ½·100·0.05² = 0.125 N.
        assert_relative_eq!(at(0.05), 0.125, max_relative = 1e-12);
        assert_relative_eq!(at(-0.05), -0.125, max_relative = 1e-12);
        // Ten widths above: the plain quadratic law, 100·0.1² = 1 N, to 1e-8.
        assert!((at(0.1) - 1.0).abs() < 1e-8);
        // Four widths below (0.03 m/s): gate ½(1 − tanh 4) = 3.4e-4 of 0.09 N.
        let expected = 0.5 * (1.0 - 4f64.tanh()) * 100.0 * 0.03 * 0.03;
        assert_relative_eq!(at(0.03), expected, max_relative = 1e-9);
        assert!(at(0.03) < 1e-4);
        assert_eq!(at(0.0), 0.0);
    }

    #[test]
    fn zero_width_is_a_hard_switch() {
        assert_eq!(jamming_gate(0.049, 0.05, 0.0), 0.0);
        assert_eq!(jamming_gate(0.051, 0.05, 0.0), 1.0);
    }
}
