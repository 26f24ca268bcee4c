//! The explicit Dormand–Prince 5(4) method of `ode_solvers`, wrapped.
//!
//! Stiffness detection is off (the stuck phase of the dry-friction model would abort it at
//! once); the solution is sampled through the solver's continuous output model, so no sample
//! lies beyond the last step. A failing right-hand side is stashed and stops the run through
//! `solout`.

use std::cell::{Cell, RefCell};

use ode_solvers::continuous_output_model::ContinuousOutputModel;
use ode_solvers::dop_shared::IntegrationError;
use ode_solvers::{DVector, Dopri5, OutputType, System};

use super::{OdeSystem, Settings, SimError, Stats};

struct Adapter<'a> {
    sys: &'a dyn OdeSystem,
    error: &'a RefCell<Option<SimError>>,
    calls: &'a Cell<u64>,
}

impl System<f64, DVector<f64>> for Adapter<'_> {
    fn system(&self, t: f64, y: &DVector<f64>, dy: &mut DVector<f64>) {
        self.calls.set(self.calls.get() + 1);
        if self.error.borrow().is_some() {
            dy.fill(0.0);
            return;
        }
        if let Err(e) = self.sys.rhs(t, y.as_slice(), dy.as_mut_slice()) {
            *self.error.borrow_mut() = Some(e);
            dy.fill(0.0);
        } else if dy.iter().any(|d| !d.is_finite()) {
            *self.error.borrow_mut() = Some(SimError::NonFinite {
                time: t,
                what: "the right-hand side".into(),
            });
            dy.fill(0.0);
        }
    }

    fn solout(&mut self, _t: f64, _y: &DVector<f64>, _dy: &DVector<f64>) -> bool {
        self.error.borrow().is_some()
    }
}

/// The common step of `t0, outputs…` if they are evenly spaced (relative 1e-9).
fn uniform_step(t0: f64, outputs: &[f64]) -> Option<f64> {
    let last = *outputs.last()?;
    let dx = outputs[0] - t0;
    let n = outputs.len() as f64;
    let even = dx > 0.0
        && ((last - t0) / n - dx).abs() <= 1e-9 * dx
        && outputs
            .iter()
            .enumerate()
            .all(|(i, &t)| (t - (t0 + (i as f64 + 1.0) * dx)).abs() <= 1e-9 * dx.max(t.abs()));
    even.then_some(dx)
}

/// Integrate with Dormand–Prince 5(4) from `ode_solvers`: the sampled states, row after row,
/// and the work.
pub(super) fn integrate(
    sys: &dyn OdeSystem,
    t0: f64,
    y0: &[f64],
    t_out: &[f64],
    s: &Settings,
) -> Result<(Vec<f64>, Stats), SimError> {
    let dim = y0.len();
    let t_end = *t_out.last().unwrap_or(&t0);
    let mut states = Vec::with_capacity(t_out.len() * dim);
    // Samples at t0 itself need no integration.
    let first_after = t_out.iter().position(|&t| t > t0).unwrap_or(t_out.len());
    for _ in 0..first_after {
        states.extend_from_slice(y0);
    }
    let mut stats = Stats::default();
    if first_after < t_out.len() {
        let error = RefCell::new(None);
        let calls = Cell::new(0);
        let adapter = Adapter {
            sys,
            error: &error,
            calls: &calls,
        };
        let h_max = if s.h_max > 0.0 { s.h_max } else { t_end - t0 };
        let outputs = &t_out[first_after..];
        let step = uniform_step(t0, outputs);
        // Uniform outputs use the solver's dense output directly; the run goes half a step
        // past the end so the last sample is interpolated, never extrapolated.
        let (x_end, dx, out_type) = match step {
            Some(dx) => (t_end + 0.5 * dx, dx, OutputType::Dense),
            None => (t_end, t_end - t0, OutputType::Continuous),
        };
        let mut solver = Dopri5::from_param(
            adapter,
            t0,
            x_end,
            dx,
            DVector::from_column_slice(y0),
            s.rtol,
            s.atol,
            0.9,
            0.04,
            0.2,
            10.0,
            h_max,
            0.0,
            s.max_steps,
            u32::MAX,
            out_type,
        );
        let mut model = ContinuousOutputModel::default();
        let result = if step.is_some() {
            solver.integrate()
        } else {
            solver.integrate_with_continuous_output_model(&mut model)
        };
        stats.rhs_calls = calls.get();
        if let Some(e) = error.borrow_mut().take() {
            return Err(e);
        }
        let st = result.map_err(sim_error)?;
        stats.accepted = u64::from(st.accepted_steps);
        stats.rejected = u64::from(st.rejected_steps);
        let missing = |t: f64| {
            SimError::BadSettings(format!(
                "no solution at t = {t} s (integrated {t0} → {t_end})"
            ))
        };
        if step.is_some() {
            dense_samples(&solver, outputs, &mut states, missing)?;
        } else {
            for &t in outputs {
                let y = model.evaluate(t).ok_or_else(|| missing(t))?;
                states.extend_from_slice(y.as_slice());
            }
        }
    }
    Ok((states, stats))
}

/// The solver's failure as the simulation's error.
fn sim_error(e: IntegrationError) -> SimError {
    match e {
        IntegrationError::StepSizeUnderflow { x } => SimError::StepSizeTooSmall { time: x },
        IntegrationError::MaxNumStepReached { x, n_step } => SimError::TooManySteps {
            time: x,
            steps: u64::from(n_step),
        },
        IntegrationError::StiffnessDetected { x } => SimError::StepSizeTooSmall { time: x },
    }
}

/// The states at `outputs` from the solver's dense samples t0, t0 + dx, …: `outputs[k]` is
/// sample k + 1.
fn dense_samples<F: Fn(f64) -> SimError>(
    solver: &Dopri5<f64, DVector<f64>, Adapter<'_>>,
    outputs: &[f64],
    states: &mut Vec<f64>,
    missing: F,
) -> Result<(), SimError> {
    let (ys, ts) = (solver.y_out(), solver.x_out());
    for (k, &t) in outputs.iter().enumerate() {
        let i = k + 1;
        let (ti, yi) = ts.get(i).zip(ys.get(i)).ok_or_else(|| missing(t))?;
        debug_assert!((ti - t).abs() < 1e-6);
        states.extend_from_slice(yi.as_slice());
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::{integrate, Method, OdeSystem, Settings, SimError};

    struct Oscillator;
    impl OdeSystem for Oscillator {
        fn dim(&self) -> usize {
            2
        }
        fn rhs(&self, _t: f64, y: &[f64], dy: &mut [f64]) -> Result<(), SimError> {
            dy[0] = y[1];
            dy[1] = -y[0];
            Ok(())
        }
    }

    #[test]
    fn uniform_and_uneven_outputs_agree_with_the_exact_solution() {
        let s = Settings::default()
            .method(Method::Dopri5)
            .rtol(1e-10)
            .atol(1e-12);
        let even: Vec<f64> = (0..=100).map(|i| i as f64 * 0.1).collect();
        let uneven = [0.3, 0.35, 2.0, 9.99, 10.0];
        for times in [&even[..], &even[1..], &uneven[..]] {
            let sol = integrate(&Oscillator, 0.0, &[1.0, 0.0], times, &s).unwrap();
            for (i, &t) in times.iter().enumerate() {
                assert!(
                    (sol.y(i)[0] - t.cos()).abs() < 1e-8,
                    "t {t}: {}",
                    sol.y(i)[0]
                );
                assert!((sol.y(i)[1] + t.sin()).abs() < 1e-8);
            }
        }
    }

    struct Failing;
    impl OdeSystem for Failing {
        fn dim(&self) -> usize {
            1
        }
        fn rhs(&self, t: f64, _y: &[f64], dy: &mut [f64]) -> Result<(), SimError> {
            if t > 0.5 {
                return Err(SimError::NonFinite {
                    time: t,
                    what: "test".into(),
                });
            }
            dy[0] = 1.0;
            Ok(())
        }
    }

    #[test]
    fn a_failing_right_hand_side_stops_the_run_with_its_time() {
        let s = Settings::default().method(Method::Dopri5);
        let err = integrate(&Failing, 0.0, &[0.0], &[1.0, 2.0], &s).unwrap_err();
        let t = err.time().unwrap();
        assert!(t > 0.5 && t < 1.0, "{err}");
    }
}
