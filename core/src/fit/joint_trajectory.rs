//! Fitting a least-squares problem of simulated displacements that is not one
//! [`super::TrajectoryFit`] — several records' trajectories fitted together over shared
//! parameters (a campaign's global fit) — by the rules of a trajectory fit: the same driver,
//! its refinement stopping where a parameter reaches a bound and releasing it, `S` reported
//! in mm² ([`super::FitResult::s_mm2`]), standard errors from the same block-robust
//! covariance. The caller gives the settings a trajectory fit would use
//! ([`super::FitSettings::for_simulation`] at its integrator's `rtol`).
//!
//! A residual evaluation that fails (a simulation that diverges at a trial point) is scored as
//! a penalty and counted, as in every fit: the step is rejected, the fit goes on.

use super::driver;
use super::error::FitError;
use super::fit_param::FitParam;
use super::objective::Residuals;
use super::result::{FitProgress, FitResult};
use super::solver::FitSettings;

/// Fit `problem`, whose residuals are displacements in m, as a trajectory fit is fitted:
/// `params` lists every parameter (free and fixed, in order); `problem` receives the user
/// values of the free ones.
pub fn fit_trajectory_residuals(
    problem: &dyn Residuals,
    params: &[FitParam],
    settings: &FitSettings,
    observer: Option<&(dyn Fn(FitProgress) + Sync)>,
) -> Result<FitResult, FitError> {
    driver::run(problem, params, settings, observer, true)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    /// r_i = y_i − a·sin(t_i), displacements of a few mm.
    struct Sine {
        t: Vec<f64>,
        y: Vec<f64>,
    }

    impl Residuals for Sine {
        fn len(&self) -> usize {
            self.t.len()
        }
        fn residuals(&self, a: &[f64], sink: &mut dyn FnMut(usize, f64)) -> Result<(), String> {
            for (i, (t, y)) in self.t.iter().zip(&self.y).enumerate() {
                sink(i, y - a[0] * t.sin());
            }
            Ok(())
        }
    }

    #[test]
    fn a_joint_displacement_problem_is_fitted_with_s_in_mm2() {
        let t: Vec<f64> = (0..300).map(|i| i as f64 * 0.05).collect();
        let y = t
            .iter()
            .enumerate()
            .map(|(i, t)| 3e-3 * t.sin() + 1e-5 * ((i * 7919 % 13) as f64 - 6.0))
            .collect();
        let problem = Sine { t, y };
        let params = [FitParam::new("a", 1e-3).bounds(0.0, 1e-2)];
        let fit =
            fit_trajectory_residuals(&problem, &params, &FitSettings::default(), None).unwrap();
        let a = fit.value("a").unwrap();
        assert!((a / 3e-3 - 1.0).abs() < 1e-3, "a = {a}");
        let s = fit.s_mm2.unwrap();
        assert!((s - fit.rss / fit.n_points as f64 * 1e6).abs() <= 1e-12 * s.max(1e-30));
        assert!(fit.convergence.converged());
    }
}
