//! Probe of the forced-sweep trajectory fit's landscape (investigation, not a bench).
use std::path::Path;
use std::sync::Arc;

use stf_core::fit::{FitParam, TrajectoryData, TrajectoryFit};
use stf_core::kinematics::{Kinematics, KinematicsSettings};
use stf_core::record::ReadOptions;
use stf_core::system::OscillatorParams;

fn main() {
    let rec = ReadOptions::default()
        .read(Path::new("experiments/records/forced_sweep.csv"))
        .unwrap();
    let k = Kinematics::from_record(&rec, &KinematicsSettings::default()).unwrap();
    let exc = Arc::new(k.excitation());
    let truth = OscillatorParams::FORCED;
    let stuck = OscillatorParams {
        k: 269.9757298635288,
        c: 3.8007280174831513,
        t_friction: 0.5215367113626861,
        delta_t: 0.15403589233372944,
        f0: 0.04607624720833514,
        ..truth
    };
    let mode = std::env::args().nth(1).unwrap_or_default();
    let data = TrajectoryData {
        t: &rec.t,
        x: &rec.x,
    };
    let eval = |p: OscillatorParams| -> (f64, Vec<f64>) {
        let osc = stf_core::oscillator::Oscillator::with_shared_excitation(p, exc.clone());
        let y0 = osc.initial_state(k.x[0], k.v[0]);
        let env = |k: &str, d: f64| {
            std::env::var(k)
                .ok()
                .and_then(|v| v.parse().ok())
                .unwrap_or(d)
        };
        let sim = stf_core::integrate::Settings {
            rtol: env("RTOL", 1e-7),
            atol: env("ATOL", 1e-9),
            ..Default::default()
        };
        let sol = stf_core::integrate::integrate(&osc, rec.t[0], &y0, &rec.t, &sim).unwrap();
        let r: Vec<f64> = rec
            .x
            .iter()
            .enumerate()
            .map(|(i, xe)| xe - sol.states[i * sol.dim])
            .collect();
        (
            r.iter().map(|v| v * v).sum::<f64>() / r.len() as f64 * 1e6,
            r,
        )
    };
    let lerp = |a: f64, b: f64, s: f64| a + (b - a) * s;
    let at = |s: f64| OscillatorParams {
        k: lerp(stuck.k, truth.k, s),
        c: lerp(stuck.c, truth.c, s),
        t_friction: lerp(stuck.t_friction, truth.t_friction, s),
        delta_t: lerp(stuck.delta_t, truth.delta_t, s),
        f0: lerp(stuck.f0, truth.f0, s),
        ..truth
    };
    if mode == "line" {
        for i in 0..=40 {
            let s = i as f64 / 40.0;
            println!("s {s:.3} S {:.6}", eval(at(s)).0);
        }
        for i in 0..=20 {
            let s = i as f64 * 0.0025;
            println!("fine s {s:.4} S {:.6}", eval(at(s)).0);
        }
    }
    if mode == "fit" || mode == "fitabs" {
        let f: Vec<f64> = std::env::args()
            .skip(2)
            .map(|a| a.parse().unwrap())
            .collect();
        let mut fit = TrajectoryFit::new(truth, exc.clone()).initial(k.x[0], k.v[0]);
        for (i, name) in ["k", "c", "T", "delta_T", "F0"].iter().enumerate() {
            let v = if mode == "fitabs" {
                f[i]
            } else {
                truth.get(name).unwrap() * f[i]
            };
            fit = fit.free(FitParam::new(*name, v).bounds(v / 5.0, v * 5.0));
        }
        let env = |k: &str, d: f64| {
            std::env::var(k)
                .ok()
                .and_then(|v| v.parse().ok())
                .unwrap_or(d)
        };
        let sim = stf_core::integrate::Settings {
            rtol: env("RTOL", 1e-7),
            atol: env("ATOL", 1e-9),
            ..Default::default()
        };
        let fit = fit
            .sim_settings(sim)
            .settings(stf_core::fit::FitSettings::default().fd_step(env("FD", 1e-5)));
        let r = fit.fit(&data, None).unwrap();
        println!(
            "S {:.5} evals {} wall {:.2} {:?}",
            r.s_mm2.unwrap(),
            r.evaluations,
            r.wall_seconds,
            r.convergence
        );
        for p in &r.params {
            println!("  {} {:.5}", p.name, p.value);
        }
        for l in &r.log {
            println!("  {l}");
        }
    }
    if mode == "grad" {
        let names = ["k", "c", "T", "delta_T", "F0"];
        let (s0, r0) = eval(stuck);
        let n = r0.len() as f64;
        for name in names {
            let x = stuck.get(name).unwrap();
            let mut line = format!("{name:>8}:");
            for h in [1e-5, 1e-4, 3e-4, 1e-3, 1e-2] {
                let mut p = stuck;
                p.set(name, x * (1.0 + h));
                let (sp, rp) = eval(p);
                let mut q = stuck;
                q.set(name, x * (1.0 - h));
                let (sm, _) = eval(q);
                // GN gradient from forward-difference jacobian: dS/dlnx = 2/N sum r * dr
                let gn: f64 = r0
                    .iter()
                    .zip(&rp)
                    .map(|(a, b)| 2.0 * a * (b - a) / h)
                    .sum::<f64>()
                    / n
                    * 1e6;
                line += &format!(
                    "  h {h:.0e}: fwd {:+.4} cen {:+.4} gn {:+.4}",
                    (sp - s0) / h,
                    (sp - sm) / (2.0 * h),
                    gn
                );
            }
            println!("{line}");
        }
        // direction truth - stuck in ln coordinates, predicted derivative
        let d: Vec<f64> = names
            .iter()
            .map(|n| (truth.get(n).unwrap() / stuck.get(n).unwrap()).ln())
            .collect();
        println!("ln-direction to truth {d:?}");
    }
    if mode == "synth" {
        use stf_core::excitation::{Excitation, RotorAngle};
        let a: Vec<f64> = std::env::args()
            .skip(2)
            .map(|a| a.parse().unwrap())
            .collect();
        let (w0, alpha, dur, rate, seed) = (a[0], a[1], a[2], a[3], a[4] as u64);
        let f = &a[5..10];
        let excitation = Arc::new(Excitation::Rotor(RotorAngle::sweep(w0, alpha, 0.0)));
        let osc =
            stf_core::oscillator::Oscillator::with_shared_excitation(truth, excitation.clone());
        let run = stf_core::simulate::Simulation::new(&osc)
            .rate(rate)
            .run(0.0, dur)
            .unwrap();
        let rec = stf_core::synthetic::sample_record(
            &run,
            &stf_core::synthetic::SensorNoise::RIG,
            seed,
            true,
        );
        let data = TrajectoryData {
            t: &rec.t,
            x: &rec.x,
        };
        let (excitation, x0, v0) = if a.get(10) == Some(&1.0) {
            let k = Kinematics::from_record(&rec, &KinematicsSettings::default()).unwrap();
            (Arc::new(k.excitation()), k.x[0], k.v[0])
        } else {
            (excitation, rec.x[0], 0.0)
        };
        let clock = std::time::Instant::now();
        let s_truth = TrajectoryFit::new(truth, excitation.clone())
            .initial(x0, v0)
            .fit(&data, None)
            .unwrap()
            .s_mm2
            .unwrap();
        let one = clock.elapsed().as_secs_f64();
        let excitation_line = excitation.clone();
        let mut fit = TrajectoryFit::new(truth, excitation).initial(x0, v0);
        for (i, name) in ["k", "c", "T", "delta_T", "F0"].iter().enumerate() {
            let v = truth.get(name).unwrap() * f[i];
            fit = fit.free(FitParam::new(*name, v).bounds(v / 5.0, v * 5.0));
        }
        let r = fit.fit(&data, None).unwrap();
        println!(
            "n {} one {:.3}s S_truth {s_truth:.5} S {:.5} ratio {:.3} evals {} wall {:.2}",
            rec.t.len(),
            one,
            r.s_mm2.unwrap(),
            r.s_mm2.unwrap() / s_truth,
            r.evaluations,
            r.wall_seconds
        );
        if std::env::var("V").is_ok() {
            for p in &r.params {
                println!(
                    "  {} {:.5} ({:+.2} %)",
                    p.name,
                    p.value,
                    100.0 * (p.value / truth.get(&p.name).unwrap() - 1.0)
                );
            }
            for l in &r.log {
                println!("  {l}");
            }
        }
        if std::env::var("LINE").is_ok() {
            let mut end = truth;
            for p in &r.params {
                end.set(&p.name, p.value);
            }
            for i in 0..=20 {
                let s = i as f64 / 20.0;
                let mut q = truth;
                for name in ["k", "c", "T", "delta_T", "F0"] {
                    q.set(
                        name,
                        end.get(name).unwrap()
                            + s * (truth.get(name).unwrap() - end.get(name).unwrap()),
                    );
                }
                let fit = TrajectoryFit::new(q, excitation_line.clone()).initial(x0, v0);
                println!(
                    "  line s {s:.2} S {:.5}",
                    fit.fit(&data, None).unwrap().s_mm2.unwrap()
                );
            }
        }
    }
    if mode == "noise" {
        for (label, p0) in [("truth", truth), ("stuck", stuck)] {
            for name in ["k", "T", "delta_T"] {
                let (_, r0) = eval(p0);
                let mut out = format!("{label} {name}: rms|r(x(1+h)) - r(x)| mm:");
                for h in [1e-9, 1e-8, 1e-7, 1e-6, 1e-5, 1e-4, 1e-3, 1e-2] {
                    let mut p = p0;
                    p.set(name, p0.get(name).unwrap() * (1.0 + h));
                    let (_, r) = eval(p);
                    let d = (r.iter().zip(&r0).map(|(a, b)| (a - b).powi(2)).sum::<f64>()
                        / r.len() as f64)
                        .sqrt()
                        * 1e3;
                    out += &format!(" {h:.0e}:{d:.2e}");
                }
                println!("{out}");
            }
        }
    }
    if mode == "phases" {
        for (label, p) in [("truth", truth), ("stuck", stuck)] {
            let (s, r) = eval(p);
            println!("{label}: S {s:.5}");
            // per 10 s window, mean square (mm^2) and contribution to S
            let n = r.len() as f64;
            for w in 0..15 {
                let seg: Vec<f64> = rec
                    .t
                    .iter()
                    .zip(&r)
                    .filter(|(t, _)| **t >= 50.0 + 10.0 * w as f64 && **t < 60.0 + 10.0 * w as f64)
                    .map(|(_, r)| *r)
                    .collect();
                let ss: f64 = seg.iter().map(|v| v * v).sum();
                println!(
                    "  t {:>3}-{:>3}: ms {:.5} mm2, share of S {:.5}, max|x_exp| {:.2} mm",
                    50 + 10 * w,
                    60 + 10 * w,
                    ss / seg.len() as f64 * 1e6,
                    ss / n * 1e6,
                    rec.t
                        .iter()
                        .zip(&rec.x)
                        .filter(
                            |(t, _)| **t >= 50.0 + 10.0 * w as f64 && **t < 60.0 + 10.0 * w as f64
                        )
                        .map(|(_, x)| x.abs())
                        .fold(0.0, f64::max)
                        * 1e3
                );
            }
        }
    }
}
