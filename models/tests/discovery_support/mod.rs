//! Shared by the discovery tests: synthetic sweep records whose truth is a sum of built-ins,
//! and the candidate vocabulary of docs/ARCHITECTURE.md §5.
//!
//! A record: the forced reference oscillator driven by a rotor sweep ω = 4 → 10 rad/s at
//! 0.1 rad/s² (60 s, through resonance at 5.9 rad/s), simulated with the truth model,
//! sampled at 200 Hz through the rig's sensors ([`SensorNoise::RIG`]: x noise 0.05 mm,
//! quantized to 0.01 mm, force noise 0.02 N, 2048-count encoder). v and a come from the
//! derivative filter ([`Kinematics::from_record`]) unless `exact_kinematics` is set.

#![allow(dead_code)]

use std::sync::Arc;

use stf_core::data::force_data::ForceData;
use stf_core::data::kinematics::{Kinematics, KinematicsSettings};
use stf_core::discovery::{discover_force, Candidate, Discovery, DiscoverySettings};
use stf_core::physics::excitation::{Excitation, RotorAngle};
use stf_core::physics::force_model::ForceModel;
use stf_core::physics::model_sum::ModelSum;
use stf_core::physics::oscillator::Oscillator;
use stf_core::physics::oscillator_params::OscillatorParams;
use stf_core::regimes::cycles_from_phase;
use stf_core::simulate::synthetic::{sample_record, SensorNoise};
use stf_core::simulate::Simulation;
use stf_models::{find, BUILTINS};

/// A part of a truth model: a built-in's name and its parameter values.
pub type Part<'a> = (&'a str, &'a [f64]);

/// A synthetic record ready for discovery.
pub struct Case {
    pub t: Vec<f64>,
    pub x: Vec<f64>,
    pub v: Vec<f64>,
    pub a: Vec<f64>,
    pub f: Vec<f64>,
    pub phi: Vec<f64>,
    /// The true STF force of each part of the truth, N (noise-free).
    pub part_forces: Vec<Vec<f64>>,
    /// The kinematics v and a were filtered with (none with exact kinematics): their noise
    /// enters the floor, their filter's window the test's blocks.
    pub kinematics: Option<Kinematics>,
}

impl Case {
    pub fn data(&self) -> ForceData<'_> {
        ForceData {
            t: &self.t,
            x: &self.x,
            v: &self.v,
            a: &self.a,
            f: &self.f,
        }
    }

    /// RMS of the true force of part `i`, N.
    pub fn part_rms(&self, i: usize) -> f64 {
        let f = &self.part_forces[i];
        (f.iter().map(|v| v * v).sum::<f64>() / f.len() as f64).sqrt()
    }
}

fn build(parts: &[Part]) -> (Arc<dyn ForceModel>, Vec<f64>) {
    let models: Vec<Arc<dyn ForceModel>> = parts.iter().map(|(n, _)| find(n).unwrap()).collect();
    let values: Vec<f64> = parts.iter().flat_map(|(_, v)| v.iter().copied()).collect();
    let model: Arc<dyn ForceModel> = Arc::new(ModelSum::new(models).unwrap());
    (model, values)
}

/// Simulate `truth` over the sweep and sample it with the rig's noise (`seed`).
pub fn record(truth: &[Part], seed: u64, exact_kinematics: bool) -> Case {
    record_at(truth, seed, exact_kinematics, 200.0, 60.0)
}

/// The same sampled at `rate` (Hz) over the first `t1` seconds of the sweep.
pub fn record_at(truth: &[Part], seed: u64, exact_kinematics: bool, rate: f64, t1: f64) -> Case {
    let sweep = RotorAngle::sweep(4.0, 0.1, 0.0);
    record_swept(truth, seed, exact_kinematics, rate, (sweep, t1))
}

/// The paper's sweep, ω 2.35 → 9.4 rad/s at 0.047 rad/s² (150 s), sampled at 1 kHz: 150 001
/// samples.
pub fn paper_record(truth: &[Part], seed: u64) -> Case {
    let sweep = RotorAngle::sweep(2.35, 0.047, 0.0);
    record_swept(truth, seed, false, 1000.0, (sweep, 150.0))
}

/// The same over the rotor `sweep` (its angle and its end, s).
fn record_swept(
    truth: &[Part],
    seed: u64,
    exact_kinematics: bool,
    rate: f64,
    (sweep, t1): (RotorAngle, f64),
) -> Case {
    let (model, values) = build(truth);
    let osc = Oscillator::new(OscillatorParams::FORCED, Excitation::Rotor(sweep))
        .with_model(model, values)
        .unwrap();
    let run = Simulation::new(&osc).rate(rate).run(0.0, t1).unwrap();
    let rec = sample_record(&run, &SensorNoise::RIG, seed, true);
    // The force of each part alone along the true motion (a part with internal state gets
    // its share of the simulated state).
    let mut part_forces = Vec::new();
    let mut z_off = 0;
    for (name, vals) in truth {
        let m = find(name).unwrap();
        let nz = m.n_internal();
        let f: Vec<f64> = (0..run.t.len())
            .map(|i| {
                let z: Vec<f64> = (z_off..z_off + nz).map(|j| run.z[j][i]).collect();
                let s = stf_core::physics::force_model::ModelState {
                    t: run.t[i],
                    x: run.x[i],
                    v: run.v[i],
                    z: &z,
                };
                let mut dz = vec![0.0; nz];
                m.added_mass(vals, &s).unwrap() * run.a[i] + m.force(vals, &s, &mut dz).unwrap()
            })
            .collect();
        z_off += nz;
        part_forces.push(f);
    }
    let (v, a, kinematics) = if exact_kinematics {
        (run.v.clone(), run.a.clone(), None)
    } else {
        let k = Kinematics::from_record(&rec, &KinematicsSettings::default()).unwrap();
        (k.v.clone(), k.a.clone(), Some(k))
    };
    Case {
        t: rec.t.clone(),
        x: rec.x.clone(),
        v,
        a,
        f: rec.f_stf.clone().unwrap(),
        phi: rec.phi.clone().unwrap(),
        part_forces,
        kinematics,
    }
}

/// Every built-in as a candidate, by its own name.
pub fn vocabulary() -> Vec<Candidate> {
    BUILTINS
        .iter()
        .map(|e| Candidate::new(e.name, (e.build)()))
        .collect()
}

/// Run discovery from the built-in `base` with the whole vocabulary, the record's kinematics
/// noise in the floor and its filter's window setting the test's blocks.
pub fn discover(case: &Case, base: &str, settings: &DiscoverySettings) -> Discovery {
    let cycles = cycles_from_phase(&case.t, &case.phi).unwrap();
    let settings = &match &case.kinematics {
        Some(k) => settings.clone().kinematics(k),
        None => settings.clone(),
    };
    discover_force(
        find(base).unwrap(),
        &vocabulary(),
        &case.data(),
        &cycles,
        settings,
    )
    .unwrap()
}

/// Print what a run found, for the test log.
pub fn print(label: &str, case: &Case, d: &Discovery) {
    eprintln!("== {label}");
    for i in 0..case.part_forces.len() {
        eprintln!("   truth part {i}: RMS {:.4} N", case.part_rms(i));
    }
    for s in &d.steps {
        eprintln!("   step on `{}`: {}", s.current, s.verdict);
        for c in &s.candidates {
            eprintln!(
                "      {:<16} train {:.4} holdout {:.4} gain {:+.4} z {:6.1} n {:4} ΔBIC {:+9.1} expl {:5.2} share {:5.2} sig {} {} evals {} {:.2}s {:?}",
                c.name, c.train_rms,
                c.holdout_rms,
                c.holdout_gain, c.gain_z, c.effective_n,
                c.delta_bic,
                c.explained_fraction,
                c.explained_share,
                c.significant,
                c.failure.as_deref().unwrap_or(""),
                c.evaluations,
                c.wall_seconds, c.params.iter().map(|p| format!("{}={:.3e}", p.name, p.value)).collect::<Vec<_>>()
            );
        }
    }
    eprintln!(
        "   effects {:?}; gap {:.4} → {:.4} N, floor {:.4} N (sensor {:.4}, kinematics {:.4}) ({:.2}×); {}",
        d.effects,
        d.gap_before,
        d.gap_after,
        d.noise_floor,
        d.noise_floor_parts.measured,
        d.noise_floor_parts.propagated,
        d.gap_after / d.noise_floor,
        d.where_before.summary
    );
}
