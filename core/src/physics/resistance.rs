//! The bearing resistance of the trolley: viscous plus smoothed dry friction.
//!
//! ```text
//! F_R(v) = c·v + (T + ΔT / (1 + η|v|)) · v / sqrt(v² + ε²),   ε = 1e-3 / η
//! ```
//!
//! The static excess ΔT decays with speed; ε smooths the sign function so that the equation
//! stays an ODE. With η = 1e3, ε = 1e-6 m/s: the trolley "sticks" by creeping at ~1e-7 m/s.

use crate::physics::oscillator_params::OscillatorParams;

/// Smoothing velocity ε = 1e-3/η, m/s.
pub fn smoothing_velocity(p: &OscillatorParams) -> f64 {
    1e-3 / p.eta
}

/// Bearing resistance F_R(v), N.
#[inline]
pub fn bearing_resistance(p: &OscillatorParams, v: f64) -> f64 {
    let (viscous, dry, smooth_speed) = bearing_resistance_parts(p, v);
    viscous + dry / smooth_speed
}

/// The parts of F_R(v) = `viscous + dry / smooth_speed`: `c·v`, `(T + ΔT/(1 + η|v|))·v` and
/// `sqrt(v² + ε²)`, N, N·m/s and m/s. The right-hand side divides `dry` by the smoothed speed
/// last, so that only the square root and that division follow the velocity in its chain of
/// dependent operations (the rest runs beside them).
#[inline(always)]
pub fn bearing_resistance_parts(p: &OscillatorParams, v: f64) -> (f64, f64, f64) {
    let eps = smoothing_velocity(p);
    let dry = (p.t_friction + p.delta_t / (1.0 + p.eta * v.abs())) * v;
    (p.c * v, dry, (v * v + eps * eps).sqrt())
}

/// dF_R/dv, N·s/m (for implicit integrators and sensitivity estimates).
pub fn bearing_resistance_slope(p: &OscillatorParams, v: f64) -> f64 {
    let eps = smoothing_velocity(p);
    let r = (v * v + eps * eps).sqrt();
    let s = v / r;
    let ds = eps * eps / (r * r * r);
    let level = p.t_friction + p.delta_t / (1.0 + p.eta * v.abs());
    let dlevel = -p.delta_t * p.eta * v.signum() / (1.0 + p.eta * v.abs()).powi(2);
    p.c + level * ds + dlevel * s
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn far_from_rest_it_is_viscous_plus_coulomb() {
        let p = OscillatorParams::FORCED;
        let v = 0.1;
        let expected = p.c * v + p.t_friction + p.delta_t / (1.0 + p.eta * v);
        assert_relative_eq!(bearing_resistance(&p, v), expected, max_relative = 1e-9);
        assert_relative_eq!(bearing_resistance(&p, -v), -expected, max_relative = 1e-9);
    }

    #[test]
    fn at_rest_it_is_zero_and_its_ceiling_is_static_friction() {
        let p = OscillatorParams::FORCED;
        assert_eq!(bearing_resistance(&p, 0.0), 0.0);
        let near = bearing_resistance(&p, 1e-4);
        assert!(near < p.t_friction + p.delta_t && near > p.t_friction);
    }

    #[test]
    fn slope_matches_finite_difference() {
        let p = OscillatorParams::FORCED;
        for v in [-0.2_f64, -1e-5, 3e-7, 2e-6, 0.05] {
            let h = 1e-10_f64.max(v.abs() * 1e-6);
            let fd = (bearing_resistance(&p, v + h) - bearing_resistance(&p, v - h)) / (2.0 * h);
            assert_relative_eq!(bearing_resistance_slope(&p, v), fd, max_relative = 1e-4);
        }
    }
}
