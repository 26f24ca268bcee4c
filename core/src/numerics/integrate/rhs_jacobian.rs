//! Finite-difference derivatives of a right-hand side, and a spectral-radius estimate.
//!
//! The Jacobian is built column by column with forward differences, increment
//! `δ_j = sqrt(u·max(1e-5, |y_j|))` (u the unit round-off), as in Hairer & Wanner's codes;
//! `∂f/∂t` likewise. The spectral radius ρ(J) decides when a stiff phase is over: exactly for
//! one or two states, by a power iteration otherwise.

use super::SimError;

/// Forward-difference Jacobian `jac[i·n + j] = ∂f_i/∂y_j` at `(t, y)`, where `fy = f(t, y)`;
/// `work` (length n) is scratch. Returns the number of right-hand-side calls.
pub(crate) fn fd_jacobian<F>(
    mut f: F,
    t: f64,
    y: &[f64],
    fy: &[f64],
    jac: &mut [f64],
    work: &mut [f64],
) -> Result<u64, SimError>
where
    F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), SimError>,
{
    let n = y.len();
    let mut yp = y.to_vec();
    for j in 0..n {
        let delta = (f64::EPSILON * y[j].abs().max(1e-5)).sqrt();
        yp[j] = y[j] + delta;
        let step = yp[j] - y[j];
        f(t, &yp, work)?;
        yp[j] = y[j];
        for i in 0..n {
            jac[i * n + j] = (work[i] - fy[i]) / step;
        }
    }
    Ok(n as u64)
}

/// Forward-difference `∂f/∂t` at `(t, y)`, where `fy = f(t, y)`. One right-hand-side call.
pub(crate) fn fd_time_derivative<F>(
    mut f: F,
    t: f64,
    y: &[f64],
    fy: &[f64],
    ft: &mut [f64],
) -> Result<(), SimError>
where
    F: FnMut(f64, &[f64], &mut [f64]) -> Result<(), SimError>,
{
    let delta = (f64::EPSILON * t.abs().max(1e-5)).sqrt();
    let tp = t + delta;
    let step = tp - t;
    f(tp, y, ft)?;
    for (d, &f0) in ft.iter_mut().zip(fy) {
        *d = (*d - f0) / step;
    }
    Ok(())
}

/// An estimate of the spectral radius of the row-major `n × n` matrix `jac`.
pub(crate) fn spectral_radius(jac: &[f64], n: usize) -> f64 {
    match n {
        0 => 0.0,
        1 => jac[0].abs(),
        2 => {
            let (a, b, c, d) = (jac[0], jac[1], jac[2], jac[3]);
            let half_tr = 0.5 * (a + d);
            let det = a * d - b * c;
            let disc = half_tr * half_tr - det;
            if disc >= 0.0 {
                half_tr.abs() + disc.sqrt()
            } else {
                det.abs().sqrt()
            }
        }
        _ => power_iteration(jac, n),
    }
}

/// Growth rate of `‖Jᵏ·x‖` over a few power iterations (also right for a complex pair, whose
/// iterates rotate but grow at the rate |λ|).
fn power_iteration(jac: &[f64], n: usize) -> f64 {
    const WARM: usize = 8;
    const MEASURED: usize = 8;
    let mut x: Vec<f64> = (0..n).map(|i| 1.0 + 0.1 * i as f64).collect();
    let mut next = vec![0.0; n];
    let mut log_growth = 0.0;
    for it in 0..WARM + MEASURED {
        for (i, out) in next.iter_mut().enumerate() {
            *out = (0..n).map(|j| jac[i * n + j] * x[j]).sum();
        }
        let norm = next.iter().map(|v| v * v).sum::<f64>().sqrt();
        if !(norm > 0.0 && norm.is_finite()) {
            return if norm == 0.0 { 0.0 } else { f64::INFINITY };
        }
        if it >= WARM {
            log_growth += norm.ln();
        }
        for (xi, &ni) in x.iter_mut().zip(&next) {
            *xi = ni / norm;
        }
    }
    (log_growth / MEASURED as f64).exp()
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn linear(t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SimError> {
        dy[0] = 2.0 * y[0] - 3.0 * y[1] + t * t;
        dy[1] = 0.5 * y[0] * y[0];
        Ok(())
    }

    #[test]
    fn fd_jacobian_and_time_derivative_match_the_analytic_ones() {
        let (t, y) = (1.5, [0.7, -0.2]);
        let mut fy = [0.0; 2];
        linear(t, &y, &mut fy).unwrap();
        let mut jac = [0.0; 4];
        let mut work = [0.0; 2];
        fd_jacobian(linear, t, &y, &fy, &mut jac, &mut work).unwrap();
        let exact = [2.0, -3.0, 0.7, 0.0];
        for (a, b) in jac.iter().zip(exact) {
            assert!((a - b).abs() < 1e-6, "{jac:?}");
        }
        let mut ft = [0.0; 2];
        fd_time_derivative(linear, t, &y, &fy, &mut ft).unwrap();
        assert!((ft[0] - 3.0).abs() < 1e-6 && ft[1].abs() < 1e-12, "{ft:?}");
    }

    #[test]
    fn spectral_radius_of_small_and_larger_matrices() {
        // Oscillator: eigenvalues ±5i.
        assert!((spectral_radius(&[0.0, 1.0, -25.0, 0.0], 2) - 5.0).abs() < 1e-12);
        // Real eigenvalues −1 and −1000.
        assert!((spectral_radius(&[-1.0, 0.0, 0.0, -1000.0], 2) - 1000.0).abs() < 1e-9);
        // Block diagonal 3×3: rotation of radius 2 and a real −7.
        let m = [0.0, 2.0, 0.0, -2.0, 0.0, 0.0, 0.0, 0.0, -7.0];
        assert!((spectral_radius(&m, 3) - 7.0).abs() < 0.1);
        let m = [0.0, 9.0, 0.0, -9.0, 0.0, 0.0, 0.0, 0.0, -1.0];
        assert!((spectral_radius(&m, 3) - 9.0).abs() < 0.1);
    }
}
