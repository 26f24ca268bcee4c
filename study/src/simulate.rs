//! The simulate workflow: the oscillator of an experiment's `[system]`, driven as its
//! `[simulate]` section says (a rotor's angle, a measured force's chirp, or free vibration),
//! with its `truth` model plugged in, integrated at the sample times and sampled through the
//! rig's sensors ([`stf_core::simulate::synthetic`]), with the force sensor's offset and the
//! control channels (`[simulate] channels`, which the truth's laws may follow) beside it.
//! [`Simulated`] is what the record, its
//! JSON sidecar and the terminal lines are written from.

use std::time::Instant;

use anyhow::{bail, Context, Result};
use stf_core::data::record::Record;
use stf_core::data::response::{breakaway, peak, stop, BREAKAWAY_DISPLACEMENT, MOVING_SPEED};
use stf_core::numerics::interpolate::Linear;
use stf_core::physics::excitation::Excitation;
use stf_core::physics::oscillator::Oscillator;
use stf_core::simulate::synthetic::{sample_record, SensorNoise};
use stf_core::simulate::{Simulation, Trajectory};

use std::sync::Arc;

use stf_core::physics::channel_law::MeasuredChannel;

use crate::channels::Channels;
use crate::experiment::{Drive, Experiment};
use crate::model_config::configure_for;
use crate::outputs::simulate_json::{Summary, Truth};

/// A simulated run and the record sampled from it.
pub struct Simulated {
    /// The integrated run at the sample times.
    pub run: Trajectory,
    /// The record the rig's sensors would have written (`source` empty until written).
    pub record: Record,
    /// The truth model and its values (empty without one).
    pub truth: Vec<Truth>,
    /// The sensors' noise the record was sampled with.
    pub noise: SensorNoise,
    /// Whether it is free vibration (no drive).
    pub free: bool,
    /// How long the integration took, s.
    pub wall_s: f64,
    /// What the run shows: its peak, the breakaway, where free motion stops.
    pub summary: Summary,
    /// The control channels at the sample times, written as columns after the record's.
    pub channels: Vec<(String, Vec<f64>)>,
}

/// Simulate the `[simulate]` section of `exp`.
pub fn simulate(exp: &Experiment) -> Result<Simulated> {
    let Some(spec) = &exp.simulate else {
        bail!(
            "{}: has no [simulate] section to make a record from",
            exp.path.display()
        );
    };
    // The sample times, as `Simulation::run` makes them.
    let n = ((spec.t1 - spec.t0) * spec.rate).round() as usize + 1;
    let times: Vec<f64> = (0..n).map(|i| spec.t0 + i as f64 / spec.rate).collect();
    let (excitation, rotor) = excitation_of(&spec.drive, &times);
    let free = matches!(spec.drive, Drive::Free);
    let mut osc = Oscillator::new(exp.system, excitation);
    let mut truth_json = Vec::new();
    let channels: Vec<(String, Vec<f64>)> = spec
        .channels
        .iter()
        .map(|c| (c.name.clone(), c.signal.sample(&times, c.seed)))
        .collect();
    if !spec.truth.is_empty() {
        let measured = channels
            .iter()
            .map(|(name, v)| MeasuredChannel::new(name, times.clone(), v.clone()).map(Arc::new))
            .collect::<Result<Vec<_>, _>>()?;
        let truth = configure_for(
            &spec.truth,
            &exp.path,
            &exp.dir,
            &exp.scripts,
            None,
            &Channels::of(measured),
        )?;
        truth_json.push(Truth {
            model: truth.model.name().to_string(),
            params: truth
                .params
                .iter()
                .map(|p| (p.name.clone(), p.value))
                .collect(),
        });
        let values = truth.values();
        osc = osc
            .with_model(truth.model, values)
            .context("cannot plug the truth model into the oscillator")?;
    }
    let started = Instant::now();
    let run = Simulation::new(&osc)
        .settings(exp.integrator.clone())
        .initial(spec.x0, spec.v0)
        .run_at(&times)
        .with_context(|| format!("simulation of {} failed", exp.path.display()))?;
    let wall_s = started.elapsed().as_secs_f64();
    let noise = if spec.noise {
        SensorNoise::RIG
    } else {
        SensorNoise::NONE
    };
    let mut record = sample_record(&run, &noise, spec.seed, rotor);
    if let Some(f) = record.f_stf.as_mut() {
        f.iter_mut().for_each(|v| *v += spec.f_stf_offset);
    }
    Ok(Simulated {
        channels,
        summary: summary(&run, free),
        run,
        record,
        truth: truth_json,
        noise,
        free,
        wall_s,
    })
}

/// The excitation of `drive` at the sample `times`, and whether it is a rotor. A force is
/// tabulated at the sample times (held, or interpolated linearly).
fn excitation_of(drive: &Drive, times: &[f64]) -> (Excitation, bool) {
    match drive {
        Drive::Rotor(angle) => (Excitation::Rotor(angle.clone()), true),
        Drive::Free => (Excitation::None, false),
        Drive::Force(chirp) => {
            let u = times.iter().map(|&t| chirp.at(t)).collect();
            let held = if chirp.held() {
                Linear::held(times.to_vec(), u)
            } else {
                Linear::new(times.to_vec(), u)
            };
            (Excitation::Force(held), false)
        }
    }
}

/// What the run shows (`free`: free vibration, where motion stops).
fn summary(run: &Trajectory, free: bool) -> Summary {
    let omega = run.omega.as_deref();
    let pk = peak(&run.t, &run.x, omega);
    let brk = breakaway(&run.x, BREAKAWAY_DISPLACEMENT);
    let stops = if free {
        stop(&run.v, MOVING_SPEED)
    } else {
        None
    };
    Summary {
        peak_x_m: pk.map(|p| p.amplitude),
        peak_t_s: pk.map(|p| p.t),
        peak_omega_rad_s: pk.map(|p| p.omega),
        breakaway_omega_rad_s: brk.and_then(|i| omega.map(|w| w[i])),
        breakaway_t_s: brk.filter(|_| omega.is_some()).map(|i| run.t[i]),
        breakaway_displacement_m: BREAKAWAY_DISPLACEMENT,
        motion_stops_t_s: stops.map(|i| run.t[i]),
        motion_stops_x_m: stops.map(|i| run.x[i].abs()),
        samples: run.t.len(),
        rhs_calls: run.stats.rhs_calls,
        steps: run.stats.accepted,
    }
}
