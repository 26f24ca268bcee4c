//! `power_law`: shear thickening as a power of the blade's speed, `F = K·|v|ⁿ·sign v`.
//!
//! An Ostwald–de Waele (power-law) fluid has a shear stress `τ = K'·γ̇ⁿ`; with the shear rate
//! around the blade proportional to its speed (γ̇ ∝ v / gap) the drag on the blade scales the
//! same way, `F = K·|v|ⁿ`, the geometry folded into `K`. `n > 1` is shear thickening
//! (cornstarch suspensions and silica STFs show n ≈ 1.5–3 in their thickening branch), `n = 1`
//! is the Newtonian [`crate::viscous`] model. The force always opposes the motion, so the
//! model only dissipates energy (F·v ≥ 0), and it is odd: F(−v) = −F(v).
//!
//! | parameter | unit | default | bounds | meaning |
//! |---|---|---|---|---|
//! | `K` | N·(s/m)ⁿ | 5 | [0, 1e4] | consistency: the force at 1 m/s |
//! | `n` | — | 1.6 | [1, 4] | flow index; n > 1 thickens |

use stf_core::physics::force_model::{ModelError, ModelState, Reach};
use stf_core::physics::param_spec::ParamSpec;

use crate::builtin::builtin;
use crate::values::take;

builtin! {
    /// Power-law drag of the blade, `F = K·|v|ⁿ·sign v`; see the [module doc](self).
    PowerLaw: "power_law",
    "shear thickening F = K·|v|ⁿ·sign v (n > 1)",
    params [
        ParamSpec::new("K", "N·(s/m)ⁿ", 5.0, 0.0, 1e4, "consistency: drag at a speed of 1 m/s"),
        ParamSpec::new("n", "", 1.6, 1.0, 4.0, "flow index; n > 1 is shear thickening"),
    ];
    impl {
        /// The law with its values, `k·|v|^n·sgn v`.
        fn equation(&self, values: &[String]) -> Option<String> {
            let [k, n] = values else { return None };
            Some(format!("{k}·|v|^{n}·sgn v"))
        }
        #[inline]
        fn force(&self, p: &[f64], s: &ModelState, _dz: &mut [f64]) -> Result<f64, ModelError> {
            let [k, n] = take(self.name(), p)?;
            Ok(power_law_force(k, n, s.v))
        }
        fn gradient(
            &self,
            p: &[f64],
            s: &ModelState,
            _a: f64,
            grad: &mut [f64],
        ) -> Result<bool, ModelError> {
            let [k, n] = take(self.name(), p)?;
            let (dk, dn) = power_law_gradient(k, n, s.v);
            grad[..2].copy_from_slice(&[dk, dn]);
            Ok(true)
        }
        /// An exponent of 1 (within 0.02): `K·v`, the `viscous` law.
        fn reduces_to(&self, p: &[f64], _reach: Reach) -> Option<(String, Vec<f64>)> {
            let [k, n] = take(self.name(), p).ok()?;
            ((n - 1.0).abs() < 0.02).then(|| ("viscous".to_string(), vec![k]))
        }
    }
}

/// `K·|v|ⁿ·sign v`, zero at v = 0 for every n > 0.
#[inline]
pub fn power_law_force(k: f64, n: f64, v: f64) -> f64 {
    if v == 0.0 {
        0.0
    } else {
        k * v.abs().powf(n) * v.signum()
    }
}

/// `(∂F/∂K, ∂F/∂n)` of [`power_law_force`]: `|v|ⁿ·sign v` and `K·|v|ⁿ·ln|v|·sign v`, both
/// zero at v = 0.
#[inline]
pub fn power_law_gradient(k: f64, n: f64, v: f64) -> (f64, f64) {
    if v == 0.0 {
        return (0.0, 0.0);
    }
    // exp(n·ln|v|): one logarithm serves both entries (a gradient needs no last-bit power).
    let ln = v.abs().ln();
    let unit = (n * ln).exp() * v.signum();
    (unit, k * unit * ln)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use stf_core::physics::force_model::ForceModel;

    fn at(v: f64, p: &[f64]) -> f64 {
        let s = ModelState {
            t: 0.0,
            x: 0.0,
            v,
            z: &[],
        };
        PowerLaw::new().force(p, &s, &mut []).unwrap()
    }

    #[test]
    fn quadratic_law_gives_k_v_squared_against_the_motion() {
        // K = 5, n = 2: F(−0.3 m/s) = −5·0.09 = −0.45 N.
        assert_relative_eq!(at(-0.3, &[5.0, 2.0]), -0.45, max_relative = 1e-12);
        // n = 1.5 at 0.04 m/s: 10·0.008 = 0.08 N.
        assert_relative_eq!(at(0.04, &[10.0, 1.5]), 0.08, max_relative = 1e-12);
        assert_eq!(at(0.0, &[5.0, 1.6]), 0.0);
    }

    #[test]
    fn the_contract_names_are_k_and_n() {
        let names: Vec<_> = PowerLaw::new()
            .params()
            .iter()
            .map(|s| s.name.clone())
            .collect();
        assert_eq!(names, ["K", "n"]);
    }
}
