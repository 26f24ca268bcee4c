//! A trajectory-level fit scored on a subset of the samples: the oscillator (some of its
//! parameters free) with an STF model, simulated through the whole record, its displacement
//! compared with the measured one at the chosen samples only.
//!
//! The simulation always runs through the whole record, so the held-out cycles are driven by
//! the same history as in reality, and the residuals of any samples can be read off one run.
//! Parameters are, in order: the oscillator's free ones (by [`OscillatorParams`] name, or
//! `x0`, `v0` for the initial state), every parameter of the model (in its order), then the
//! displacement offset `x_off` if fitted.

use std::sync::Arc;

use crate::fit::{
    error_settings, fit_residuals, full_values, FitError, FitParam, FitResult, FitSettings,
    Residuals, INITIAL_STATE,
};
use crate::numerics::integrate::{integrate, Settings};
use crate::physics::excitation::Excitation;
use crate::physics::force_model::ForceModel;
use crate::physics::oscillator::Oscillator;
use crate::physics::oscillator_params::{OscParam, OscillatorParams};
use crate::simulate::{Simulation, Trajectory};

/// The oscillator side of a trajectory-level fit: everything but the STF model.
#[derive(Clone)]
pub(super) struct Rig<'a> {
    pub system: OscillatorParams,
    pub excitation: Arc<Excitation>,
    /// Names of the oscillator parameters that are fitted (the first parameters).
    pub oscillator: Vec<&'a str>,
    pub initial: Option<(f64, f64)>,
    pub sim: Settings,
    pub fit_offset: bool,
    /// Whether every simulation starts from `initial` whatever values `x0`, `v0` are given
    /// (the pieces of a [`super::scout::Scout`]: their starts come from a whole-record run).
    pub fixed_start: bool,
    pub t: &'a [f64],
    pub x: &'a [f64],
}

/// What a trajectory-level fit evaluates: a model's displacement residual along some stretch
/// of the record, for the full parameter vector (oscillator's, model's, offset).
pub(super) trait Track: Sync {
    /// Measured − simulated − offset at every sample of the track, m.
    fn residual(&self, model: &Arc<dyn ForceModel>, values: &[f64]) -> Result<Vec<f64>, String>;
    /// Relative tolerance of the track's integrator (sets the finite-difference step).
    fn rtol(&self) -> f64;
    /// Whether the initial state `x0`, `v0` has no effect (and must be held fixed).
    fn fixes_start(&self) -> bool;
    /// [`Track::residual`] from simulations at the tolerances behind standard errors
    /// ([`crate::fit::error_settings`]), or `None` when the track's are no looser or its
    /// standard errors are never read (a scout's: it only says where a fit on the whole
    /// record starts).
    fn precise_residual(
        &self,
        _model: &Arc<dyn ForceModel>,
        _values: &[f64],
    ) -> Option<Result<Vec<f64>, String>> {
        None
    }
}

impl Track for Rig<'_> {
    /// The displacement residual alone, at the cost of the integration only: what a fit
    /// evaluates.
    fn residual(&self, model: &Arc<dyn ForceModel>, values: &[f64]) -> Result<Vec<f64>, String> {
        let (osc, [x0, v0], offset) = self.setup(model, values)?;
        let Some(&t0) = self.t.first() else {
            return Ok(Vec::new());
        };
        let y0 = osc.initial_state(x0, v0);
        let sol = integrate(&osc, t0, &y0, self.t, &self.sim).map_err(|e| e.to_string())?;
        let x: Vec<f64> = sol.states.iter().step_by(sol.dim).copied().collect();
        self.residual_of(&x, offset)
    }
    fn rtol(&self) -> f64 {
        self.sim.rtol
    }
    fn fixes_start(&self) -> bool {
        self.fixed_start
    }
    fn precise_residual(
        &self,
        model: &Arc<dyn ForceModel>,
        values: &[f64],
    ) -> Option<Result<Vec<f64>, String>> {
        let sim = error_settings(&self.sim)?;
        let precise = Rig {
            sim,
            ..self.clone()
        };
        Some(precise.residual(model, values))
    }
}

/// One evaluation: the model's simulated motion and the displacement residual.
pub(super) struct Run {
    pub sim: Trajectory,
    /// Measured − simulated x (with the offset) at every sample, m.
    pub residual: Vec<f64>,
}

impl Rig<'_> {
    /// Simulate `model` on the rig with the full parameter vector `values` (oscillator's,
    /// model's, offset): the whole motion and the displacement residual.
    pub fn run(&self, model: &Arc<dyn ForceModel>, values: &[f64]) -> Result<Run, String> {
        let (osc, [x0, v0], offset) = self.setup(model, values)?;
        let sim = Simulation::new(&osc)
            .settings(self.sim.clone())
            .initial(x0, v0)
            .run_at(self.t)
            .map_err(|e| e.to_string())?;
        let residual = self.residual_of(&sim.x, offset)?;
        Ok(Run { sim, residual })
    }

    /// The state (x0 m, v0 m/s) a simulation with `values` starts from: fitted, or the
    /// setup's estimate less the offset.
    pub fn start(&self, model: &Arc<dyn ForceModel>, values: &[f64]) -> Result<[f64; 2], String> {
        Ok(self.setup(model, values)?.1)
    }

    /// The oscillator with `values` set, its initial state (x0, v0) and the displacement
    /// offset.
    fn setup(
        &self,
        model: &Arc<dyn ForceModel>,
        values: &[f64],
    ) -> Result<(Oscillator, [f64; 2], f64), String> {
        let n_osc = self.oscillator.len();
        let n_model = model.params().len();
        let expected = n_osc + n_model + usize::from(self.fit_offset);
        if values.len() != expected {
            return Err(format!(
                "expected {expected} parameter values, got {}",
                values.len()
            ));
        }
        let mut system = self.system;
        let mut initial: [Option<f64>; 2] = [None, None];
        for (name, &v) in self.oscillator.iter().zip(values) {
            if let Some(i) = INITIAL_STATE.iter().position(|n| n == name) {
                if !self.fixed_start {
                    initial[i] = Some(v);
                }
            } else {
                let param: OscParam = name.parse().map_err(|e| format!("{e}"))?;
                system[param] = v;
            }
        }
        // Checked above: a value after the model's is the offset, fitted.
        let offset = values.get(n_osc + n_model).copied().unwrap_or(0.0);
        let osc = Oscillator::with_shared_excitation(system, self.excitation.clone())
            .with_model(model.clone(), values[n_osc..n_osc + n_model].to_vec())
            .map_err(|e| e.to_string())?;
        let (x0, v0) = self
            .initial
            .unwrap_or((self.x.first().copied().unwrap_or(0.0), 0.0));
        let start = [initial[0].unwrap_or(x0 - offset), initial[1].unwrap_or(v0)];
        Ok((osc, start, offset))
    }

    /// Measured − simulated − offset, checked for length and finiteness.
    fn residual_of(&self, simulated: &[f64], offset: f64) -> Result<Vec<f64>, String> {
        if simulated.len() != self.x.len() {
            return Err("the simulation returned too few samples".into());
        }
        let residual: Vec<f64> = self
            .x
            .iter()
            .zip(simulated)
            .map(|(m, s)| m - s - offset)
            .collect();
        if let Some(i) = residual.iter().position(|r| !r.is_finite()) {
            return Err(format!("non-finite displacement at sample {i}"));
        }
        Ok(residual)
    }

    /// The oscillator's parameters with the fitted values of `values` set.
    pub fn system_of(&self, values: &[f64]) -> OscillatorParams {
        let mut system = self.system;
        for (name, &v) in self.oscillator.iter().zip(values) {
            if let Ok(param) = name.parse::<OscParam>() {
                system[param] = v;
            }
        }
        system
    }
}

/// The residuals of the rig with `model` at the samples `subset`.
struct SubsetProblem<'a> {
    track: &'a dyn Track,
    model: &'a Arc<dyn ForceModel>,
    params: &'a [FitParam],
    subset: &'a [usize],
}

impl Residuals for SubsetProblem<'_> {
    fn len(&self) -> usize {
        self.subset.len()
    }

    fn residuals(&self, x: &[f64], sink: &mut dyn FnMut(usize, f64)) -> Result<(), String> {
        let full = full_values(self.params, x)?;
        let residual = self.track.residual(self.model, &full)?;
        for (k, &i) in self.subset.iter().enumerate() {
            sink(k, residual[i]);
        }
        Ok(())
    }

    fn precise_residuals(
        &self,
        x: &[f64],
        sink: &mut dyn FnMut(usize, f64),
    ) -> Option<Result<(), String>> {
        let full = match full_values(self.params, x) {
            Ok(full) => full,
            Err(e) => return Some(Err(e.to_string())),
        };
        let residual = match self.track.precise_residual(self.model, &full)? {
            Ok(r) => r,
            Err(e) => return Some(Err(e)),
        };
        for (k, &i) in self.subset.iter().enumerate() {
            sink(k, residual[i]);
        }
        Some(Ok(()))
    }
}

/// Fit `params` (all of them, in the rig's order) of `model` along `track` at its samples
/// `subset`; statistics are those of the subset, and `s_mm2` is set. The finite-difference
/// step follows the track's integrator ([`FitSettings::for_simulation`]).
pub(super) fn fit_on(
    track: &dyn Track,
    model: &Arc<dyn ForceModel>,
    params: &[FitParam],
    subset: &[usize],
    settings: &FitSettings,
) -> Result<FitResult, FitError> {
    let problem = SubsetProblem {
        track,
        model,
        params,
        subset,
    };
    let settings = settings.clone().for_simulation(track.rtol());
    let mut result = fit_residuals(&problem, params, &settings, None)?;
    result.s_mm2 = Some(result.rms * result.rms * 1e6);
    Ok(result)
}
