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

use super::{OdeSystem, Settings, SimError, Solution, Stats};

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

pub(super) fn integrate(
    sys: &dyn OdeSystem,
    t0: f64,
    y0: &[f64],
    t_out: &[f64],
    s: &Settings,
) -> Result<Solution, SimError> {
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
        let mut solver = Dopri5::from_param(
            adapter,
            t0,
            t_end,
            t_end - t0,
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
            OutputType::Continuous,
        );
        let mut model = ContinuousOutputModel::default();
        let result = solver.integrate_with_continuous_output_model(&mut model);
        drop(solver);
        stats.rhs_calls = calls.get();
        if let Some(e) = error.into_inner() {
            return Err(e);
        }
        let st = match result {
            Ok(st) => st,
            Err(IntegrationError::StepSizeUnderflow { x }) => {
                return Err(SimError::StepSizeTooSmall { time: x })
            }
            Err(IntegrationError::MaxNumStepReached { x, n_step }) => {
                return Err(SimError::TooManySteps {
                    time: x,
                    steps: u64::from(n_step),
                })
            }
            Err(IntegrationError::StiffnessDetected { x }) => {
                return Err(SimError::StepSizeTooSmall { time: x })
            }
        };
        stats.accepted = u64::from(st.accepted_steps);
        stats.rejected = u64::from(st.rejected_steps);
        for &t in &t_out[first_after..] {
            let y = model.evaluate(t).ok_or(SimError::BadSettings(format!(
                "no solution at t = {t} s (integrated {t0} → {t_end})"
            )))?;
            states.extend_from_slice(y.as_slice());
        }
    }
    Ok(Solution {
        t: t_out.to_vec(),
        states,
        dim,
        stats,
    })
}
