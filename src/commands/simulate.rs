//! `stf-lab simulate EXP.toml --out F.csv`: write a synthetic record and its JSON sidecar.
//!
//! A rotor drive writes `t, phi, x, f_stf`; free vibration `t, x, f_stf`; a force drive (a
//! shaker, `chirp`) writes `t, x, f_stf, u`. The force `u` is tabulated at the sample times and
//! drives the oscillator linearly interpolated, as a measured force does when a record is
//! replayed; it is written exact (the rig's sensor model has no drive-force sensor, only the
//! displacement, STF-force and encoder noise of `SensorNoise::RIG`).
//!
//! The record and its sidecar are refused if they would be one file (`--out rec.json`) or
//! replace something that is not a regular file; they are staged beside their targets and
//! renamed into place together, the record locked for the run ([`crate::staged_files`]).

use std::path::Path;
use std::time::Instant;

use anyhow::{bail, Context, Result};
use stf_core::data::response::{breakaway, peak, stop, BREAKAWAY_DISPLACEMENT, MOVING_SPEED};
use stf_core::numerics::interpolate::Linear;
use stf_core::physics::excitation::Excitation;
use stf_core::physics::oscillator::Oscillator;
use stf_core::simulate::synthetic::{sample_record, SensorNoise};
use stf_core::simulate::{Simulation, Trajectory as SimRun};

use crate::experiment::{Drive, Experiment};
use crate::model_config::configure_for;
use crate::output::{check_distinct, check_overwrite, ensure_parent, write_json};
use crate::output_lock::OutputLock;
use crate::outputs::simulate_json::{SimulateJson, Summary, Truth};
use crate::say;
use crate::staged_files::{clean_stale, StagedFiles};

/// Run the `[simulate]` section of `exp_path` and write the record to `out`.
pub fn run(exp_path: &Path, out: &Path, force: bool) -> Result<()> {
    let exp = Experiment::load(exp_path)?;
    let Some(spec) = &exp.simulate else {
        bail!(
            "{}: has no [simulate] section to make a record from",
            exp_path.display()
        );
    };
    let sidecar = out.with_extension("json");
    let _lock = claim_outputs(out, &sidecar, force)?;

    // The sample times, as `Simulation::run` makes them.
    let n = ((spec.t1 - spec.t0) * spec.rate).round() as usize + 1;
    let times: Vec<f64> = (0..n).map(|i| spec.t0 + i as f64 / spec.rate).collect();
    let (excitation, rotor) = excitation_of(&spec.drive, &times);
    let free = matches!(spec.drive, Drive::Free);
    let mut osc = Oscillator::new(exp.system, excitation);
    let mut truth_json = Vec::new();
    if !spec.truth.is_empty() {
        let truth = configure_for(&spec.truth, &exp.path, &exp.dir, &exp.scripts, None)?;
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
        .with_context(|| format!("simulation of {} failed", exp_path.display()))?;
    let wall = started.elapsed();

    let noise = if spec.noise {
        SensorNoise::RIG
    } else {
        SensorNoise::NONE
    };
    let mut record = sample_record(&run, &noise, spec.seed, rotor);
    record.source = out.display().to_string();

    let mut staged = StagedFiles::new();
    record
        .write_csv(&staged.stage(out))
        .with_context(|| format!("cannot write {}", out.display()))?;
    let meta = SimulateJson {
        generator: "stf-lab simulate",
        version: env!("CARGO_PKG_VERSION"),
        experiment_file: exp_path.display().to_string(),
        experiment: crate::experiment::read_text(exp_path, crate::experiment::MAX_EXPERIMENT_BYTES)
            .unwrap_or_default(),
        simulate: &spec.as_json,
        system: exp.system,
        integrator: (&exp.integrator).into(),
        truth: truth_json,
        noise,
        seed: spec.seed,
        record: out.display().to_string(),
        summary: summary(&run, free),
    };
    write_json(&staged.stage(&sidecar), &meta)
        .with_context(|| format!("cannot write {}", sidecar.display()))?;
    staged.commit()?;

    say!(
        "simulated {:.1} s ({} samples) in {:.0} ms, {} right-hand-side calls",
        spec.t1 - spec.t0,
        run.t.len(),
        wall.as_secs_f64() * 1e3,
        run.stats.rhs_calls
    );
    print_outcome(&run, free);
    say!("wrote {} and {}", out.display(), sidecar.display());
    Ok(())
}

/// Check that the record `out` and its `sidecar` may be written (distinct, regular or new,
/// replaced only with `force`), lock the record and clear what an interrupted run left.
fn claim_outputs(out: &Path, sidecar: &Path, force: bool) -> Result<OutputLock> {
    if check_distinct(&[("the record", out), ("its JSON sidecar", sidecar)]).is_err() {
        bail!(
            "{}: the JSON sidecar is written to the record's path with the extension .json, \
             which is the record itself; give the record another extension (e.g. .csv)",
            out.display()
        );
    }
    check_overwrite(out, force)?;
    check_overwrite(sidecar, force)?;
    ensure_parent(out)?;
    let lock = OutputLock::acquire(out)?;
    for target in [out, sidecar] {
        for name in clean_stale(target)? {
            crate::tell!(
                "note: removed {name}, left beside {} by an interrupted run",
                target.display()
            );
        }
    }
    Ok(lock)
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

/// What the run shows, for the sidecar (`free`: free vibration, where motion stops).
fn summary(run: &SimRun, free: bool) -> Summary {
    let omega = run.omega.as_deref();
    let pk = peak(&run.t, &run.x, omega);
    let brk = breakaway(&run.x, BREAKAWAY_DISPLACEMENT);
    Summary {
        peak_x_m: pk.map(|p| p.amplitude),
        peak_t_s: pk.map(|p| p.t),
        peak_omega_rad_s: pk.map(|p| p.omega),
        breakaway_omega_rad_s: brk.and_then(|i| omega.map(|w| w[i])),
        motion_stops_t_s: if free {
            stop(&run.v, MOVING_SPEED).map(|i| run.t[i])
        } else {
            None
        },
        samples: run.t.len(),
        rhs_calls: run.stats.rhs_calls,
        steps: run.stats.accepted,
    }
}

/// The terminal lines of the run: its peak, the breakaway and where free motion stops.
fn print_outcome(run: &SimRun, free: bool) {
    let omega = run.omega.as_deref();
    if let Some(p) = peak(&run.t, &run.x, omega) {
        if p.omega.is_finite() {
            say!(
                "peak |x| = {:.2} mm at ω = {:.2} rad/s (t = {:.1} s)",
                p.amplitude * 1e3,
                p.omega,
                p.t
            );
        } else {
            say!("peak |x| = {:.2} mm at t = {:.2} s", p.amplitude * 1e3, p.t);
        }
    }
    match (breakaway(&run.x, BREAKAWAY_DISPLACEMENT), omega) {
        (Some(i), Some(w)) => say!(
            "breakaway (|x| first above {:.1} mm) at ω = {:.2} rad/s (t = {:.1} s)",
            BREAKAWAY_DISPLACEMENT * 1e3,
            w[i],
            run.t[i]
        ),
        (None, Some(_)) => say!("the trolley never broke away from sticking"),
        _ => {}
    }
    if free {
        if let Some(i) = stop(&run.v, MOVING_SPEED) {
            say!(
                "motion stops at t = {:.2} s, {:.2} mm from zero",
                run.t[i],
                run.x[i].abs() * 1e3
            );
        }
    }
}
