//! Benchmark: the 0.047 rad/s² sweep (ω = 0.047·t, t 50 → 200 s, 1 kHz, from rest, no STF)
//! with plain Dormand–Prince and with the default method, against a tight reference.
//!
//! `cargo run --release -p stf-core --example bench_sweep [repeats]`
//!
//! Prints, for each method, the median and the best wall time of `repeats` runs (default 5; 40×
//! as many for the fast methods) of `integrate` alone and of a whole `Simulation::run` (which
//! also evaluates the drive and the forces at every sample, on a second thread where the run is
//! long), each with its mean CPU time, and the machine's load average before the runs (on a
//! shared machine the median moves with the load; the best run is the figure to compare); the right-hand-side calls and steps, and the largest |Δx| against the
//! reference (Dormand–Prince at rtol 1e-11, atol 1e-13) and between the two methods. Then, for sweep variants
//! (α 0.03; F0 ×0.8; α 0.06 with F0 ×1.2 and T ×0.8), the default method's work and its largest
//! |Δx| against a tight reference of each (one run each, untimed). Last, the sweep driven by the
//! bundled record's measured rotor angle (`experiments/records/forced_sweep.csv`), both methods.

use std::time::Instant;

use stf_core::data::kinematics::{Kinematics, KinematicsSettings};
use stf_core::data::record::Record;
use stf_core::numerics::integrate::{integrate, Method, Settings, Solution};
use stf_core::physics::excitation::{Excitation, RotorAngle};
use stf_core::physics::oscillator::Oscillator;
use stf_core::physics::oscillator_params::OscillatorParams;
use stf_core::simulate::Simulation;

/// CPU time of this process (user + system), s, from /proc (Linux; 0 elsewhere). On a
/// machine shared with other jobs it is a steadier figure than wall time.
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return 0.0;
    };
    // Fields after the parenthesised command name; utime and stime are the 12th and 13th.
    let rest = stat.rsplit(')').next().unwrap_or("");
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let ticks = |i: usize| {
        fields
            .get(i)
            .and_then(|v| v.parse::<f64>().ok())
            .unwrap_or(0.0)
    };
    (ticks(11) + ticks(12)) / 100.0
}

/// The machine's one-minute load average, or NaN.
fn load() -> f64 {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse().ok())
        .unwrap_or(f64::NAN)
}

/// Wall times of a repeated run, s.
struct Timing {
    best: f64,
    median: f64,
    /// Mean CPU time per run.
    cpu: f64,
}

/// The wall times of `repeats` runs, and the last result.
fn timed<T>(repeats: usize, mut f: impl FnMut() -> T) -> (Timing, T) {
    let mut walls = Vec::with_capacity(repeats.max(1));
    let mut last = None;
    let cpu0 = cpu_seconds();
    for _ in 0..repeats.max(1) {
        let start = Instant::now();
        let r = f();
        walls.push(start.elapsed().as_secs_f64());
        last = Some(r);
    }
    let cpu = (cpu_seconds() - cpu0) / walls.len() as f64;
    walls.sort_by(f64::total_cmp);
    let timing = Timing {
        best: walls[0],
        median: walls[walls.len() / 2],
        cpu,
    };
    match last {
        Some(r) => (timing, r),
        None => unreachable!("at least one repeat"),
    }
}

/// Best wall time of `repeats` runs, mean CPU time per run, and the last result.
fn best_of<T>(repeats: usize, f: impl FnMut() -> T) -> (f64, f64, T) {
    let (t, r) = timed(repeats, f);
    (t.best, t.cpu, r)
}

fn max_dx_mm(a: &Solution, b: &Solution) -> f64 {
    (0..a.t.len())
        .map(|i| (a.y(i)[0] - b.y(i)[0]).abs())
        .fold(0.0, f64::max)
        * 1e3
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let repeats: usize = match std::env::args().nth(1) {
        Some(s) => s.parse()?,
        None => 5,
    };
    let osc = Oscillator::new(
        OscillatorParams::FORCED,
        Excitation::Rotor(RotorAngle::sweep(2.35, 0.047, 50.0)),
    );
    let times: Vec<f64> = (0..=150_000).map(|i| 50.0 + i as f64 * 1e-3).collect();
    let y0 = osc.initial_state(0.0, 0.0);

    let tight = Settings::default()
        .method(Method::Dopri5)
        .rtol(1e-11)
        .atol(1e-13);
    let (t_ref, _, reference) = best_of(1, || integrate(&osc, times[0], &y0, &times, &tight));
    let reference = reference?;
    println!(
        "reference  dopri5 rtol 1e-11 atol 1e-13: {:8.2} ms, {:>9} RHS calls, {:>7} steps",
        t_ref * 1e3,
        reference.stats.rhs_calls,
        reference.stats.accepted + reference.stats.rejected
    );

    let mut rows = Vec::new();
    println!("load average before the timed runs: {:.2}", load());
    for method in [Method::Dopri5, Method::Auto, Method::Rodas4] {
        let settings = Settings::default().method(method);
        // Cheap methods get more repeats so that the CPU-time mean resolves the 10 ms tick
        // and the median is that of many runs.
        let reps = if method == Method::Dopri5 {
            repeats
        } else {
            40 * repeats
        };
        let (int, sol) = timed(reps, || integrate(&osc, times[0], &y0, &times, &settings));
        let sol = sol?;
        let (sim, run) = timed(reps, || {
            Simulation::new(&osc)
                .settings(settings.clone())
                .run_at(&times)
        });
        run?;
        let (t_int, t_sim) = (int.best, sim.best);
        println!(
            "{:<7} (rtol {:.0e}, {reps} runs): integrate median {:8.2} ms, best {:8.2} ms (CPU {:8.2} ms), \
             Simulation::run median {:8.2} ms, best {:8.2} ms (CPU {:8.2} ms), \
             {:>9} RHS calls, {:>7} accepted, {:>6} rejected, max |Δx| vs reference {:.2e} mm",
            method.name(),
            settings.rtol,
            int.median * 1e3,
            t_int * 1e3,
            int.cpu * 1e3,
            sim.median * 1e3,
            t_sim * 1e3,
            sim.cpu * 1e3,
            sol.stats.rhs_calls,
            sol.stats.accepted,
            sol.stats.rejected,
            max_dx_mm(&sol, &reference)
        );
        rows.push((method, t_int, t_sim, sol));
    }
    let (_, d_int, d_sim, dopri) = &rows[0];
    let (_, a_int, a_sim, auto) = &rows[1];
    println!(
        "default (auto) vs plain dopri5: integrate {:.2} ms vs {:.2} ms (×{:.1} faster), \
         Simulation::run {:.2} ms vs {:.2} ms (×{:.1}), RHS calls {} vs {}, max |Δx| between them {:.2e} mm",
        a_int * 1e3,
        d_int * 1e3,
        d_int / a_int,
        a_sim * 1e3,
        d_sim * 1e3,
        d_sim / a_sim,
        auto.stats.rhs_calls,
        dopri.stats.rhs_calls,
        max_dx_mm(auto, dopri)
    );
    variants(&times)?;
    measured_drive()
}

/// The sweep driven by the bundled record's measured rotor angle (15 001 samples at 100 Hz,
/// Hermite-interpolated between them): the default method, which ends a step at every sample,
/// and plain Dopri5, against a tight reference.
fn measured_drive() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../experiments/records/forced_sweep.csv");
    let record = Record::read(&path)?;
    let kinematics = Kinematics::from_record(&record, &KinematicsSettings::paper())?;
    let osc = Oscillator::new(OscillatorParams::FORCED, kinematics.excitation());
    let t = &kinematics.t;
    let y0 = osc.initial_state(0.0, 0.0);
    let tight = Settings::default()
        .method(Method::Dopri5)
        .rtol(1e-10)
        .atol(1e-12);
    let reference = integrate(&osc, t[0], &y0, t, &tight)?;
    let mut rows = Vec::new();
    for method in [Method::Dopri5, Method::Auto] {
        let settings = Settings::default().method(method);
        let (wall, _, sol) = best_of(5, || integrate(&osc, t[0], &y0, t, &settings));
        let sol = sol?;
        println!(
            "measured drive, {:<7}: integrate {:8.2} ms, {:>8} RHS calls, {:>6} accepted, {:>6} rejected, max |Δx| vs reference (dopri5 rtol 1e-10) {:.2e} mm",
            method.name(),
            wall * 1e3,
            sol.stats.rhs_calls,
            sol.stats.accepted,
            sol.stats.rejected,
            max_dx_mm(&sol, &reference)
        );
        rows.push(wall);
    }
    println!(
        "measured drive: default ×{:.1} faster than plain dopri5",
        rows[0] / rows[1]
    );
    Ok(())
}

/// The default method against a tight reference on variants of the sweep.
fn variants(times: &[f64]) -> Result<(), Box<dyn std::error::Error>> {
    let tight = Settings::default()
        .method(Method::Dopri5)
        .rtol(1e-11)
        .atol(1e-13);
    // (name, α, F0 factor, T factor); ω = α·t.
    let cases = [
        ("alpha 0.03", 0.03, 1.0, 1.0),
        ("F0 x0.8", 0.047, 0.8, 1.0),
        ("alpha 0.06, F0 x1.2, T x0.8", 0.06, 1.2, 0.8),
    ];
    for (name, alpha, f0, tf) in cases {
        let mut p = OscillatorParams::FORCED;
        p.f0 *= f0;
        p.t_friction *= tf;
        let osc = Oscillator::new(
            p,
            Excitation::Rotor(RotorAngle::sweep(alpha * times[0], alpha, times[0])),
        );
        let y0 = osc.initial_state(0.0, 0.0);
        let reference = integrate(&osc, times[0], &y0, times, &tight)?;
        let sol = integrate(&osc, times[0], &y0, times, &Settings::default())?;
        println!(
            "variant {name:<28}: auto {:>7} RHS calls, {:>6} accepted, {:>5} rejected, max |Δx| vs reference {:.2e} mm",
            sol.stats.rhs_calls,
            sol.stats.accepted,
            sol.stats.rejected,
            max_dx_mm(&sol, &reference)
        );
    }
    Ok(())
}
