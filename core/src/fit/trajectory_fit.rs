//! Trajectory-level identification, as in the source study: simulate the oscillator (with or
//! without an STF model) and minimise `S(μ) = mean((x_exp − x_sim − x_off)²)`, reported in mm².
//!
//! Free parameters are named: the oscillator's (`m`, `k`, `c`, `T`, `delta_T`, `F0`, `eta`),
//! the STF model's (as its specs name them), the displacement offset `x_off` (m) and the
//! initial state `x0` (m), `v0` (m/s). Each evaluation is one simulation from the first
//! sample's time, from `(x0, v0)`: fitted, or as set by [`TrajectoryFit::initial`], or by
//! default `x0 = x_exp[0] − x_off` and `v0 = 0`. A simulation that fails scores a penalty.
//!
//! ```
//! use std::sync::Arc;
//! use stf_core::physics::excitation::Excitation;
//! use stf_core::fit::{FitParam, TrajectoryData, TrajectoryFit};
//! use stf_core::physics::{oscillator::Oscillator, oscillator_params::OscillatorParams};
//! use stf_core::simulate::Simulation;
//! let truth = OscillatorParams { t_friction: 0.0, ..OscillatorParams::FREE };
//! let osc = Oscillator::new(truth, Excitation::None);
//! let run = Simulation::new(&osc).rate(50.0).initial(0.03, 0.0).run(0.0, 2.0).unwrap();
//! let fit = TrajectoryFit::new(truth, Arc::new(Excitation::None))
//!     .free(FitParam::new("k", 250.0).bounds(100.0, 400.0));
//! let result = fit.fit(&TrajectoryData { t: &run.t, x: &run.x }, None).unwrap();
//! assert!((result.value("k").unwrap() / truth.k - 1.0).abs() < 1e-4);
//! ```

use std::sync::Arc;

use derive_setters::Setters;

use super::driver;
use super::error::FitError;
use super::fit_param::{full_values, held, FitParam};
use super::noise_floor::Quantity;
use super::objective::Residuals;
use super::residual_jacobian::error_settings;
use super::result::{FitProgress, FitResult};
use super::same_term::check_same_terms;
use super::solver::FitSettings;
use crate::data::kinematics::Kinematics;
use crate::numerics::integrate::{integrate, Settings, Solution};
use crate::physics::excitation::Excitation;
use crate::physics::force_model::ForceModel;
use crate::physics::oscillator::Oscillator;
use crate::physics::oscillator_params::{OscParam, OscillatorParams};
use crate::physics::param_spec::ParamSpec;

/// A measured displacement record (SI units, equal lengths, time strictly increasing).
#[derive(Clone, Copy, Debug)]
pub struct TrajectoryData<'a> {
    /// Time, s.
    pub t: &'a [f64],
    /// Displacement, m.
    pub x: &'a [f64],
}

/// Name of the constant displacement offset parameter, m.
pub const DISPLACEMENT_OFFSET: &str = "x_off";

/// Names of the initial displacement (m) and velocity (m/s) as fitted parameters: a record
/// that starts in motion has an initial state its noisy first samples give only roughly, and
/// the transient a wrong one leaves biases every other parameter.
pub const INITIAL_STATE: [&str; 2] = ["x0", "v0"];

impl Kinematics {
    /// The initial state as parameters to fit ([`initial_state_params`]), bounded by the
    /// record's own range of x and v.
    pub fn initial_state_params(&self) -> [FitParam; 2] {
        let (x0, v0) = self.initial_state();
        let (x_span, v_span) = self.state_span();
        initial_state_params(x0, v0, x_span, v_span)
    }
}

/// The initial state as two parameters to fit, starting from an estimate `(x0, v0)` (m, m/s)
/// such as [`crate::data::kinematics::Kinematics::initial_state`], within a tenth of the record's
/// own range of x and of v (`x_span`, `v_span`: the largest |x − mean| and |v|), so that the
/// bounds follow the record's scale, whatever its units (within 4 mm and 25 mm/s on the source
/// study's sweep).
pub fn initial_state_params(x0: f64, v0: f64, x_span: f64, v_span: f64) -> [FitParam; 2] {
    let positive = |s: f64| if s > 0.0 && s.is_finite() { s } else { 1.0 };
    let (dx, dv) = (0.1 * positive(x_span), 0.1 * positive(v_span));
    [
        FitParam::new(INITIAL_STATE[0], x0)
            .bounds(x0 - dx, x0 + dx)
            .scale(0.025 * dx),
        FitParam::new(INITIAL_STATE[1], v0)
            .bounds(v0 - dv, v0 + dv)
            .scale(0.04 * dv),
    ]
}

/// A trajectory-level fit of the oscillator and, optionally, an STF model.
#[derive(Clone, Setters)]
#[setters(generate = false)]
pub struct TrajectoryFit {
    pub(crate) system: OscillatorParams,
    /// The same fit driven by another excitation: another record's drive, for
    /// [`TrajectoryFit::validate`] (set that record's initial estimate with
    /// [`TrajectoryFit::initial`]).
    #[setters(generate)]
    pub(crate) excitation: Arc<Excitation>,
    pub(crate) model: Option<(Arc<dyn ForceModel>, Vec<f64>)>,
    pub(crate) free: Vec<FitParam>,
    pub(crate) initial: Option<(f64, f64)>,
    /// Integrator settings of the simulations.
    #[setters(generate, rename = "sim_settings")]
    pub(crate) sim: Settings,
    /// Settings of the optimiser.
    #[setters(generate)]
    settings: FitSettings,
}

/// Where a named parameter lives.
#[derive(Clone, Copy, Debug)]
enum Slot {
    Oscillator(OscParam),
    Model(usize),
    Offset,
    Initial(usize),
}

impl TrajectoryFit {
    /// Fit nothing yet: the oscillator `system` driven by `excitation`, no STF model.
    pub fn new(system: OscillatorParams, excitation: Arc<Excitation>) -> Self {
        TrajectoryFit {
            system,
            excitation,
            model: None,
            free: Vec::new(),
            initial: None,
            sim: Settings::default(),
            settings: FitSettings::default(),
        }
    }

    /// Add an STF model with its parameter values (in the order of its specs); those not
    /// named in [`TrajectoryFit::free`] stay at these values.
    pub fn model(mut self, model: Arc<dyn ForceModel>, values: Vec<f64>) -> Self {
        self.model = Some((model, values));
        self
    }

    /// A parameter to fit (or to hold, if `fixed`): an oscillator parameter, a model
    /// parameter, or `x_off` (the displacement offset, m, default scale 1 mm).
    pub fn free(mut self, mut p: FitParam) -> Self {
        if p.name == DISPLACEMENT_OFFSET && p.scale.is_none() && p.value == 0.0 {
            p.scale = Some(1e-3);
        }
        self.free.push(p);
        self
    }

    /// Initial displacement (m) and velocity (m/s) of every simulation.
    pub fn initial(mut self, x0: f64, v0: f64) -> Self {
        self.initial = Some((x0, v0));
        self
    }

    fn resolve(&self, name: &str) -> Result<Slot, FitError> {
        if name == DISPLACEMENT_OFFSET {
            return Ok(Slot::Offset);
        }
        if let Some(i) = INITIAL_STATE.iter().position(|n| *n == name) {
            return Ok(Slot::Initial(i));
        }
        let osc = name.parse::<OscParam>().ok();
        let model = self
            .model
            .as_ref()
            .and_then(|(m, _)| m.params().iter().position(|s| s.name == name));
        match (osc, model) {
            (Some(_), Some(_)) => Err(FitError::AmbiguousParam(name.to_string())),
            (Some(n), None) => Ok(Slot::Oscillator(n)),
            (None, Some(i)) => Ok(Slot::Model(i)),
            (None, None) => {
                let mut known: Vec<&str> = OscillatorParams::NAMES.to_vec();
                if let Some((m, _)) = &self.model {
                    known.extend(m.params().iter().map(|s| s.name.as_str()));
                }
                known.push(DISPLACEMENT_OFFSET);
                known.extend(INITIAL_STATE);
                Err(FitError::UnknownParam {
                    name: name.to_string(),
                    known: known.join(", "),
                })
            }
        }
    }

    /// The parameters given to [`TrajectoryFit::free`], in order.
    pub fn free_params(&self) -> &[FitParam] {
        &self.free
    }

    /// Whether the initial state `x0`, `v0` is fitted.
    pub(super) fn initial_is_free(&self) -> bool {
        self.free
            .iter()
            .any(|p| !p.fixed && INITIAL_STATE.contains(&p.name.as_str()))
    }

    /// The same fit with the parameter list `free` instead.
    pub(super) fn with_free(&self, free: Vec<FitParam>) -> Self {
        TrajectoryFit {
            free,
            ..self.clone()
        }
    }

    /// The simulated displacement with the offset at the samples of `data` for `values`
    /// (one per parameter given to [`TrajectoryFit::free`], in order; fixed or not): the
    /// fitted curve, when `values` are a fit's.
    pub fn predict(&self, data: &TrajectoryData, values: &[f64]) -> Result<Vec<f64>, FitError> {
        Ok(self.simulate(data, values)?.0)
    }

    /// [`TrajectoryFit::predict`] and the initial state (x0, v0) the simulation started from.
    pub(super) fn simulate(
        &self,
        data: &TrajectoryData,
        values: &[f64],
    ) -> Result<(Vec<f64>, [f64; 2]), FitError> {
        self.check(data)?;
        let held = self.with_free(held(&self.free, values)?);
        let problem = held.problem(data)?;
        let (sol, offset, initial) = problem.solve(&[], &self.sim).map_err(FitError::BadData)?;
        let x = sol.states.iter().step_by(sol.dim).map(|x| x + offset);
        Ok((x.collect(), initial))
    }

    /// Check `data` and the model's values.
    fn check(&self, data: &TrajectoryData) -> Result<(), FitError> {
        let n = data.t.len();
        if data.x.len() != n || n < 2 {
            return Err(FitError::BadData(format!(
                "t and x must have equal lengths ≥ 2 (got {n} and {})",
                data.x.len()
            )));
        }
        if let Some(i) = data.x.iter().position(|v| !v.is_finite()) {
            return Err(FitError::BadData(format!("x[{i}] is not finite")));
        }
        if let Some(i) = data
            .t
            .windows(2)
            .position(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater))
        {
            return Err(FitError::BadData(format!(
                "time must increase strictly (at sample {i})"
            )));
        }
        if let Some((m, values)) = &self.model {
            if values.len() != m.params().len() {
                return Err(FitError::BadData(format!(
                    "model `{}` expects {} values, got {}",
                    m.name(),
                    m.params().len(),
                    values.len()
                )));
            }
        }
        Ok(())
    }

    /// The residuals of this fit on `data`.
    fn problem<'a>(
        &'a self,
        data: &TrajectoryData<'a>,
    ) -> Result<TrajectoryResiduals<'a>, FitError> {
        let slots = self
            .free
            .iter()
            .map(|p| self.resolve(&p.name))
            .collect::<Result<Vec<_>, _>>()?;
        self.check_same_terms(&slots)?;
        Ok(TrajectoryResiduals {
            fit: self,
            data: *data,
            slots,
        })
    }

    /// Run the fit; `observer` is called after every simulation.
    pub fn fit(
        &self,
        data: &TrajectoryData,
        observer: Option<&(dyn Fn(FitProgress) + Sync)>,
    ) -> Result<FitResult, FitError> {
        self.check(data)?;
        let problem = self.problem(data)?;
        let settings = self.settings.clone().for_simulation(self.sim.rtol);
        driver::run(
            &problem,
            &self.free,
            &settings,
            observer,
            Quantity::Displacement,
        )
    }

    /// [`check_same_terms`] on the parameters this fit frees.
    fn check_same_terms(&self, slots: &[Slot]) -> Result<(), FitError> {
        let free = |i: usize| {
            self.free
                .iter()
                .zip(slots)
                .any(|(p, s)| !p.fixed && matches!(s, Slot::Model(j) if *j == i))
        };
        let model: Vec<(&ParamSpec, bool)> = self
            .model
            .iter()
            .flat_map(|(m, _)| m.params().iter().enumerate())
            .map(|(i, spec)| (spec, free(i)))
            .collect();
        let oscillator: Vec<&str> = self
            .free
            .iter()
            .zip(slots)
            .filter_map(|(p, s)| match s {
                Slot::Oscillator(param) if !p.fixed => Some(param.name()),
                _ => None,
            })
            .collect();
        check_same_terms(&model, &oscillator, &self.excitation)
    }
}

struct TrajectoryResiduals<'a> {
    fit: &'a TrajectoryFit,
    data: TrajectoryData<'a>,
    slots: Vec<Slot>,
}

impl TrajectoryResiduals<'_> {
    /// One simulation for the free values `x` integrated with `sim`: the integrator's
    /// solution, the displacement offset and the initial state (x0, v0) it started from.
    fn solve(&self, x: &[f64], sim: &Settings) -> Result<(Solution, f64, [f64; 2]), String> {
        let fit = self.fit;
        let mut system = fit.system;
        let mut model_values = fit.model.as_ref().map(|(_, v)| v.clone());
        let mut offset = 0.0;
        let mut initial: [Option<f64>; 2] = [None, None];
        for (value, slot) in full_values(&fit.free, x)?.into_iter().zip(&self.slots) {
            match *slot {
                Slot::Oscillator(param) => system[param] = value,
                Slot::Model(i) => {
                    if let Some(slot) = model_values.as_mut().and_then(|v| v.get_mut(i)) {
                        *slot = value;
                    }
                }
                Slot::Offset => offset = value,
                Slot::Initial(i) => initial[i] = Some(value),
            }
        }
        let mut osc = Oscillator::with_shared_excitation(system, fit.excitation.clone());
        if let (Some((m, _)), Some(values)) = (&fit.model, model_values) {
            osc = osc
                .with_model(m.clone(), values)
                .map_err(|e| e.to_string())?;
        }
        let d = &self.data;
        let (x0, v0) = fit.initial.unwrap_or((d.x[0] - offset, 0.0));
        let (x0, v0) = (initial[0].unwrap_or(x0), initial[1].unwrap_or(v0));
        let y0 = osc.initial_state(x0, v0);
        let sol = integrate(&osc, d.t[0], &y0, d.t, sim).map_err(|e| e.to_string())?;
        Ok((sol, offset, [x0, v0]))
    }

    /// Measured − simulated − offset at every sample, the simulation integrated with `sim`.
    fn stream(
        &self,
        x: &[f64],
        sim: &Settings,
        sink: &mut dyn FnMut(usize, f64),
    ) -> Result<(), String> {
        let (sol, offset, _) = self.solve(x, sim)?;
        for (i, &xe) in self.data.x.iter().enumerate() {
            sink(i, xe - sol.states[i * sol.dim] - offset);
        }
        Ok(())
    }
}

impl Residuals for TrajectoryResiduals<'_> {
    fn len(&self) -> usize {
        self.data.t.len()
    }

    fn residuals(&self, x: &[f64], sink: &mut dyn FnMut(usize, f64)) -> Result<(), String> {
        self.stream(x, &self.fit.sim, sink)
    }

    /// At the tolerances of [`error_settings`] when the fit's are looser.
    fn precise_residuals(
        &self,
        x: &[f64],
        sink: &mut dyn FnMut(usize, f64),
    ) -> Option<Result<(), String>> {
        let sim = error_settings(&self.fit.sim)?;
        Some(self.stream(x, &sim, sink))
    }
}
