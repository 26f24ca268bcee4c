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
//! renamed into place as one unit ([`crate::writing::staged_files`]: a commit cut short by a kill
//! is finished by the next run). The record and the sidecar are both locked for the run, so
//! two runs whose records differ but share a sidecar (`--out q.csv`, `--out q.CSV`) cannot
//! write it at once.

use std::path::Path;

use anyhow::{bail, Context, Result};

use crate::experiment::Experiment;
use crate::outputs::simulate_json::{SimulateJson, Summary};
use crate::say;
use crate::writing::lock::OutputLock;
use crate::writing::staged_files::{finish_commits, StagedFiles};
use crate::writing::{check_distinct, check_overwrite, check_regular_or_new};
use crate::writing::{clean_stale, ensure_parent};
use crate::writing::{write_json, write_with};

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
    let _locks = claim_outputs(out, &sidecar, force)?;
    let simulated = stf_study::simulate::simulate(&exp)?;
    let (run, mut record) = (&simulated.run, simulated.record.clone());
    record.source = out.display().to_string();

    let mut staged = StagedFiles::new();
    write_with(&staged.stage(out)?, |w| {
        let extra: Vec<(&str, &[f64])> = simulated
            .channels
            .iter()
            .map(|(name, v)| (name.as_str(), v.as_slice()))
            .collect();
        record
            .write_csv_with(&extra, w)
            .map_err(std::io::Error::other)
    })
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
        truth: simulated.truth.clone(),
        noise: simulated.noise,
        seed: spec.seed,
        record: out.display().to_string(),
        summary: simulated.summary.clone(),
    };
    write_json(&staged.stage(&sidecar)?, &meta)
        .with_context(|| format!("cannot write {}", sidecar.display()))?;
    staged.commit()?;

    say!(
        "simulated {:.1} s ({} samples) in {:.0} ms, {} right-hand-side calls",
        spec.t1 - spec.t0,
        run.t.len(),
        simulated.wall_s * 1e3,
        run.stats.rhs_calls
    );
    print_outcome(&simulated.summary, simulated.free);
    say!("wrote {} and {}", out.display(), sidecar.display());
    Ok(())
}

/// Check that the record `out` and its `sidecar` may be written (distinct, regular or new,
/// replaced only with `force`), lock both, finish a commit a killed run left and clear its
/// temporaries — before a refusal to replace them, so that a rerun without `--force` puts
/// right what a killed run left too.
fn claim_outputs(out: &Path, sidecar: &Path, force: bool) -> Result<[OutputLock; 2]> {
    if check_distinct(&[("the record", out), ("its JSON sidecar", sidecar)]).is_err() {
        bail!(
            "{}: the JSON sidecar is written to the record's path with the extension .json, \
             which is the record itself; give the record another extension (e.g. .csv)",
            out.display()
        );
    }
    check_regular_or_new(out)?;
    check_regular_or_new(sidecar)?;
    ensure_parent(out)?;
    let locks = [OutputLock::acquire(out)?, OutputLock::acquire(sidecar)?];
    for note in finish_commits(out)? {
        crate::tell!("note: {note}");
    }
    for target in [out, sidecar] {
        for name in clean_stale(target)? {
            crate::tell!(
                "note: removed {name}, left beside {} by an interrupted run",
                target.display()
            );
        }
    }
    check_overwrite(out, force)?;
    check_overwrite(sidecar, force)?;
    Ok(locks)
}

/// The terminal lines of the run: its peak, the breakaway and where free motion stops
/// (from the sidecar's summary).
fn print_outcome(s: &Summary, free: bool) {
    if let (Some(x), Some(t)) = (s.peak_x_m, s.peak_t_s) {
        match s.peak_omega_rad_s.filter(|w| w.is_finite()) {
            Some(w) => say!(
                "peak |x| = {:.2} mm at ω = {w:.2} rad/s (t = {t:.1} s)",
                x * 1e3
            ),
            None => say!("peak |x| = {:.2} mm at t = {t:.2} s", x * 1e3),
        }
    }
    let threshold_mm = s.breakaway_displacement_m * 1e3;
    match (s.breakaway_omega_rad_s, s.breakaway_t_s) {
        (Some(w), Some(t)) => say!(
            "breakaway (|x| first above {threshold_mm:.1} mm) at ω = {w:.2} rad/s (t = {t:.1} s)"
        ),
        _ if s.peak_omega_rad_s.is_some_and(f64::is_finite) => {
            say!("the trolley never broke away from sticking")
        }
        _ => {}
    }
    if free {
        if let (Some(t), Some(x)) = (s.motion_stops_t_s, s.motion_stops_x_m) {
            say!("motion stops at t = {t:.2} s, {:.2} mm from zero", x * 1e3);
        }
    }
}
