//! `wall_impact`: Hunt–Crossley contact once the blade's excursion passes a gap.
//!
//! When the fluid between the blade and the container's end walls jams, the plug transmits
//! the wall's reaction back to the blade: the blade "hits the wall" through the plug once
//! |x| exceeds a free gap. The contact is the Hunt–Crossley law (Hunt & Crossley, J. Appl.
//! Mech. 42, 440, 1975), a Hertz-type elastic force with damping proportional to it, which
//! starts at zero on contact (no force jump) and dissipates energy in each impact:
//!
//! ```text
//! δ = |x| − gap,   F = sign(x)·k_w·δᵖ·(1 + (3/2)·c_r·δ̇)   for δ > 0,   δ̇ = v·sign(x)
//! ```
//!
//! clipped at zero so the contact never pulls (F·sign x ≥ 0) when it separates fast. `p = 1.5`
//! is Hertz's sphere–plane contact, `p = 1` a linear spring; `c_r` (s/m) is Hunt–Crossley's
//! damping factor α, tied to the coefficient of restitution by e ≈ 1 − α·v_impact (for α·v
//! small). The law is odd under (x, v) → (−x, −v).
//!
//! | parameter | unit | default | bounds | meaning |
//! |---|---|---|---|---|
//! | `k_w` | N/mᵖ | 3e5 | [0, 1e9] | contact stiffness (10 N at 1 mm with p = 1.5) |
//! | `gap` | m | 0.01 | [0, 0.1] | free travel before the plug reaches the wall |
//! | `p` | — | 1.5 | [1, 3] | contact exponent (Hertz: 1.5) |
//! | `c_r` | s/m | 0.5 | [0, 10] | Hunt–Crossley damping factor α |

use stf_core::physics::force_model::{ModelError, ModelState, Reach, NEGLIGIBLE_SHARE};
use stf_core::physics::param_spec::ParamSpec;

use crate::builtin::builtin;
use crate::values::take;

builtin! {
    /// Contact of the jammed plug with the container walls; see the [module doc](self).
    WallImpact: "wall_impact",
    "Hunt–Crossley wall contact once |x| passes a gap",
    params [
        ParamSpec::new("k_w", "N/m^p", 3e5, 0.0, 1e9, "contact stiffness"),
        ParamSpec::new("gap", "m", 0.01, 0.0, 0.1, "free travel before the plug meets the wall"),
        ParamSpec::new("p", "", 1.5, 1.0, 3.0, "contact exponent (Hertz: 1.5)"),
        ParamSpec::new("c_r", "s/m", 0.5, 0.0, 10.0, "Hunt–Crossley damping factor"),
    ];
    impl {
        /// The law with its values, `k_w·max(|x| − gap, 0)^p·(1 + 1.5·c_r·v·sgn x)·sgn x`.
        fn equation(&self, values: &[String]) -> Option<String> {
            let [k_w, gap, p, c_r] = values else { return None };
            Some(format!("{k_w}·max(|x| − {gap}, 0)^{p}·(1 + 1.5·{c_r}·v·sgn x)·sgn x"))
        }
        #[inline]
        fn force(&self, p: &[f64], s: &ModelState, _dz: &mut [f64]) -> Result<f64, ModelError> {
            let [k_w, gap, expo, c_r] = take(self.name(), p)?;
            Ok(hunt_crossley(k_w, gap, expo, c_r, s.x, s.v))
        }
        fn gradient(
            &self,
            p: &[f64],
            s: &ModelState,
            _a: f64,
            grad: &mut [f64],
        ) -> Result<bool, ModelError> {
            let [k_w, gap, expo, c_r] = take(self.name(), p)?;
            grad[..4].copy_from_slice(&hunt_crossley_gradient(k_w, gap, expo, c_r, s.x, s.v));
            Ok(true)
        }
        /// No gap, exponent 3 (within 0.1) and negligible damping: `k_w·x³`, a cubic spring.
        fn reduces_to(&self, p: &[f64], reach: Reach) -> Option<(String, Vec<f64>)> {
            let [k_w, gap, expo, c_r] = take(self.name(), p).ok()?;
            let cubic = gap < NEGLIGIBLE_SHARE * reach.x
                && (expo - 3.0).abs() < 0.1
                && c_r * reach.v < NEGLIGIBLE_SHARE;
            cubic.then(|| ("cubic_stiffness".to_string(), vec![k_w]))
        }
    }
}

/// The Hunt–Crossley contact force at displacement `x` and velocity `v`.
#[inline]
pub fn hunt_crossley(k_w: f64, gap: f64, p: f64, c_r: f64, x: f64, v: f64) -> f64 {
    let delta = x.abs() - gap;
    if delta.is_nan() || delta <= 0.0 {
        return 0.0;
    }
    let side = x.signum();
    let magnitude = k_w * delta.powf(p) * (1.0 + 1.5 * c_r * v * side);
    side * magnitude.max(0.0)
}

/// `(∂F/∂k_w, ∂F/∂gap, ∂F/∂p, ∂F/∂c_r)` of [`hunt_crossley`]; zero out of contact and where
/// the damping term cancels the contact force.
#[inline]
pub fn hunt_crossley_gradient(k_w: f64, gap: f64, p: f64, c_r: f64, x: f64, v: f64) -> [f64; 4] {
    let delta = x.abs() - gap;
    if delta.is_nan() || delta <= 0.0 {
        return [0.0; 4];
    }
    let side = x.signum();
    let damping = 1.0 + 1.5 * c_r * v * side;
    let elastic = delta.powf(p);
    if k_w * elastic * damping <= 0.0 {
        return [0.0; 4];
    }
    let f = side * k_w * elastic * damping;
    [
        side * elastic * damping,
        -f * p / delta,
        f * delta.ln(),
        k_w * elastic * 1.5 * v,
    ]
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn hertz_contact_with_hunt_crossley_damping() {
        // δ = 0.012 − 0.01 = 2 mm; k_w·δ^1.5 = 1e6·8.944e-5 = 89.44 N; moving in at 0.1 m/s
        // with c_r = 2: factor 1 + 1.5·2·0.1 = 1.3.
        let elastic = 1e6 * 0.002f64.powf(1.5);
        assert_relative_eq!(
            hunt_crossley(1e6, 0.01, 1.5, 2.0, 0.012, 0.1),
            1.3 * elastic,
            max_relative = 1e-12
        );
        // Same on the other wall, moving into it: mirrored.
        assert_relative_eq!(
            hunt_crossley(1e6, 0.01, 1.5, 2.0, -0.012, -0.1),
            -1.3 * elastic,
            max_relative = 1e-12
        );
        // Moving away: 1 − 0.3.
        assert_relative_eq!(
            hunt_crossley(1e6, 0.01, 1.5, 2.0, 0.012, -0.1),
            0.7 * elastic,
            max_relative = 1e-12
        );
    }

    #[test]
    fn no_force_inside_the_gap_and_never_a_pull() {
        assert_eq!(hunt_crossley(1e6, 0.01, 1.5, 2.0, 0.009, 5.0), 0.0);
        assert_eq!(hunt_crossley(1e6, 0.01, 1.5, 2.0, -0.01, 5.0), 0.0);
        // Separating fast enough that 1 + 1.5·c_r·δ̇ < 0: clipped to zero.
        assert_eq!(hunt_crossley(1e6, 0.01, 1.5, 2.0, 0.012, -1.0), 0.0);
        assert_eq!(hunt_crossley(1e6, 0.01, 1.5, 2.0, -0.012, 1.0), 0.0);
    }
}
