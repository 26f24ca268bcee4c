//! Benchmark of discovery on the full-length paper sweep (run in release):
//!
//! ```text
//! cargo run --release --example bench_discovery                 # force level
//! cargo run --release --example bench_discovery -- --trajectory # and trajectory level
//! cargo run --release --example bench_discovery -- --shaker     # a 10⁵-sample shaker record
//! cargo run --release --example bench_discovery -- --silverbox  # 87 000 samples in volts
//! cargo run --release --example bench_discovery -- --only yield  # the cases whose label holds it
//! ```
//!
//! Records: the source study's 0.047 rad/s² sweep, ω 2.35 → 9.4 rad/s over t 50 → 200 s at
//! 1 kHz (150 001 samples) through the rig's sensors (seed 1), truth `power_law` K 20, n 1.5,
//! with nothing else, with `added_mass` m_a 1.5 kg hidden, or with `added_mass` and `yield`
//! F_y 2 N hidden; then the same three at 0.04 rad/s² with seed 11, a sweep rate and seed the
//! tests do not use. `[discover] base = "power_law"`, everything else default. Each case runs
//! `stf-lab simulate` and `stf-lab discover` as the command line does (experiment files and
//! records under `target/bench_discovery/`) and prints the discovery's wall time, its CPU time
//! (user + system, every thread), their ratio, the load average before it, and the verdict. Trajectory level discovers from t, φ and x
//! only (`[discover] level = "trajectory"`). `--shaker` runs trajectory-level discovery alone
//! on a shaker rig's record of 100 001 samples (the bundled `trajectory_discovery` rig: a
//! measured drive force `u`, a 0.5 → 1.5 Hz chirp over 500 s at 200 Hz, truth `viscous` with
//! a `cubic_stiffness` hidden, base `viscous`, every default candidate). `--silverbox` runs the
//! README's recommended trajectory-level discovery (`experiments/public_records/silverbox.toml`:
//! no `[system]`, the oscillator estimated from the record, `[fit] system = ["m", "k", "c",
//! "f_off"]`, `base = "none"`, every default candidate, `[validate]`) on a record in the
//! Silverbox's layout: columns `u, x` in volts, no time column, 610.35 Hz, 87 000 samples
//! (142.5 s); an electronic Duffing oscillator like the Silverbox (m 5.33e-6, c 2.24e-4, k 1.02,
//! resonance 69.7 Hz: 8.8 samples a period, a cubic spring k3 3.8 hidden) driven by a 0.02 V
//! chirp from 10 to 120 Hz, seed 5; the validation record is a 36 s chirp down from 120 to 10 Hz
//! at 0.025 V, seed 6. Timings depend on what else runs on the machine.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result};

/// One benchmark case: a label, the truth's extra effects (names and their parameters in
/// TOML), the record's seed and sweep rate (rad/s²), and the discovery level.
struct Case {
    label: &'static str,
    hidden: &'static [(&'static str, &'static str)],
    seed: u64,
    alpha: f64,
    trajectory: bool,
}

/// The shaker case (`--shaker`): trajectory level on 100 001 samples with a measured drive.
const SHAKER: Case = Case {
    label: "trajectory, shaker u, 100 001 samples, cubic_stiffness hidden",
    hidden: &[("cubic_stiffness", "k3 = 1e4")],
    seed: 7,
    alpha: 0.0,
    trajectory: true,
};

/// The shaker case's experiment file: the bundled `trajectory_discovery` rig, 500 s long.
fn shaker_experiment(record: &str) -> String {
    format!(
        "[data]\nfile = \"{record}\"\n\n[system]\npreset = \"forced\"\nT = 0.0\ndelta_T = 0.0\n\n\
         [simulate]\nchirp = {{ f0 = 0.5, f1 = 1.5, amplitude = 2.0, t1 = 500.0 }}\n\
         rate = 200.0\nnoise = true\nseed = 7\n\n[[simulate.truth]]\nname = \"viscous\"\n\
         plus = [\"cubic_stiffness\"]\nparams = {{ c_s = 1.0, k3 = 1e4 }}\n\n\
         [discover]\nbase = \"viscous\"\nlevel = \"trajectory\"\n"
    )
}

const MASS: (&str, &str) = ("added_mass", "m_a = 1.5");
const YIELD: (&str, &str) = ("yield", "F_y = 2.0");

/// The force-level cases: the paper's sweep rate and seed 1, then (so the bench does not
/// flatter records the tests tune on) seed 11 at 0.04 rad/s².
const CASES: [Case; 8] = [
    Case {
        label: "force, nothing hidden",
        hidden: &[],
        seed: 1,
        alpha: 0.047,
        trajectory: false,
    },
    Case {
        label: "force, added_mass hidden",
        hidden: &[MASS],
        seed: 1,
        alpha: 0.047,
        trajectory: false,
    },
    Case {
        label: "force, added_mass + yield hidden",
        hidden: &[MASS, YIELD],
        seed: 1,
        alpha: 0.047,
        trajectory: false,
    },
    Case {
        label: "force, nothing hidden, seed 11, 0.04 rad/s²",
        hidden: &[],
        seed: 11,
        alpha: 0.04,
        trajectory: false,
    },
    Case {
        label: "force, added_mass hidden, seed 11, 0.04 rad/s²",
        hidden: &[MASS],
        seed: 11,
        alpha: 0.04,
        trajectory: false,
    },
    Case {
        label: "force, added_mass + yield hidden, seed 11, 0.04 rad/s²",
        hidden: &[MASS, YIELD],
        seed: 11,
        alpha: 0.04,
        trajectory: false,
    },
    Case {
        label: "trajectory, nothing hidden",
        hidden: &[],
        seed: 1,
        alpha: 0.047,
        trajectory: true,
    },
    Case {
        label: "trajectory, added_mass hidden",
        hidden: &[MASS],
        seed: 1,
        alpha: 0.047,
        trajectory: true,
    },
];

/// The experiment file of `case`.
fn experiment(case: &Case, record: &str) -> String {
    if case.alpha == 0.0 {
        return shaker_experiment(record);
    }
    let names: Vec<String> = case
        .hidden
        .iter()
        .map(|(n, _)| format!("\"{n}\""))
        .collect();
    let plus = if names.is_empty() {
        String::new()
    } else {
        format!("plus = [{}]\n", names.join(", "))
    };
    let extra: String = case.hidden.iter().map(|(_, p)| format!(", {p}")).collect();
    let level = if case.trajectory {
        "level = \"trajectory\"\n"
    } else {
        ""
    };
    format!(
        "[data]\nfile = \"{record}\"\n\n[simulate]\n\
         sweep = {{ w0 = 2.35, alpha = {}, t0 = 50.0, t1 = 200.0 }}\n\
         rate = 1000.0\nnoise = true\nseed = {}\n\n[[simulate.truth]]\nname = \"power_law\"\n\
         {plus}params = {{ K = 20.0, n = 1.5{extra} }}\n\n[discover]\nbase = \"power_law\"\n{level}",
        case.alpha, case.seed
    )
}

/// The process's CPU time so far (user + system, all threads), seconds; NaN where
/// `/proc/self/stat` cannot be read (not Linux).
fn cpu_seconds() -> f64 {
    let Ok(stat) = std::fs::read_to_string("/proc/self/stat") else {
        return f64::NAN;
    };
    // Fields after the command name (which may hold spaces) in parentheses; utime and
    // stime are the 14th and 15th fields, in clock ticks (100 a second on Linux).
    let rest = stat.rsplit_once(')').map_or("", |(_, r)| r);
    let f: Vec<f64> = rest
        .split_whitespace()
        .skip(11)
        .take(2)
        .filter_map(|v| v.parse().ok())
        .collect();
    if f.len() == 2 {
        (f[0] + f[1]) / 100.0
    } else {
        f64::NAN
    }
}

/// The machine's one-minute load average, or NaN.
fn load() -> f64 {
    std::fs::read_to_string("/proc/loadavg")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse().ok())
        .unwrap_or(f64::NAN)
}

/// Run the discovery experiment `exp` into `out`: its wall and CPU seconds and the
/// `discovery.json` it wrote.
fn timed_discovery(exp: &Path, out: &Path) -> Result<(f64, f64, serde_json::Value)> {
    let clock = Instant::now();
    let cpu = cpu_seconds();
    let loaded = stf_lab::experiment::Experiment::load(exp)?;
    stf_lab::commands::discover::run_experiment(loaded, out, true, true)?;
    let wall = clock.elapsed().as_secs_f64();
    let cpu = cpu_seconds() - cpu;
    let json = serde_json::from_str(&std::fs::read_to_string(out.join("discovery.json"))?)?;
    Ok((wall, cpu, json))
}

/// Simulate the case's record, run discovery on it; the wall and CPU time of the discovery
/// and what it named.
fn run(case: &Case, dir: &Path) -> Result<(f64, f64, String)> {
    let hidden: Vec<&str> = case.hidden.iter().map(|(n, _)| *n).collect();
    let hidden = if hidden.is_empty() {
        "none".to_string()
    } else {
        hidden.join("+")
    };
    let record = format!("sweep_{hidden}_s{}_a{}.csv", case.seed, case.alpha);
    let stem = format!(
        "{}_{hidden}_s{}_a{}",
        if case.trajectory {
            "trajectory"
        } else {
            "force"
        },
        case.seed,
        case.alpha
    );
    let exp = dir.join(format!("{stem}.toml"));
    std::fs::write(&exp, experiment(case, &record))?;
    if !dir.join(&record).exists() {
        stf_lab::commands::simulate::run(&exp, &dir.join(&record), true)?;
    }
    let (wall, cpu, json) = timed_discovery(&exp, &dir.join(&stem))?;
    let effects: Vec<String> = json["effects"]
        .as_array()
        .map(|a| {
            a.iter()
                .filter_map(|e| e.as_str().map(String::from))
                .collect()
        })
        .unwrap_or_default();
    let named = if effects.is_empty() {
        "nothing named".to_string()
    } else {
        format!("named {}", effects.join(", "))
    };
    let unit = if case.trajectory { "m" } else { "N" };
    Ok((
        wall,
        cpu,
        format!(
            "{named}; gap {:.4e} → {:.4e} {unit}",
            json["gap_before"].as_f64().unwrap_or(f64::NAN),
            json["gap_after"].as_f64().unwrap_or(f64::NAN)
        ),
    ))
}

/// The Silverbox-layout case's oscillator: an electronic Duffing oscillator in volts.
const SILVERBOX_SYSTEM: &str =
    "[system]\npreset = \"forced\"\nm = 5.33e-6\nc = 2.24e-4\nk = 1.02\nT = 0.0\ndelta_T = 0.0\n";
/// The Silverbox's sample rate, Hz (10⁷/2¹⁴).
const SILVERBOX_RATE: f64 = 610.3515625;

/// The experiment file that simulates a Silverbox-layout record: `samples` samples of a chirp
/// from `f0` to `f1` Hz of `amplitude` V, with the rig's sensors and `seed`.
fn silverbox_simulation(
    record: &str,
    samples: usize,
    (f0, f1, amplitude): (f64, f64, f64),
    seed: u64,
) -> String {
    let t1 = (samples - 1) as f64 / SILVERBOX_RATE;
    format!(
        "[data]\nfile = \"{record}\"\n\n{SILVERBOX_SYSTEM}\n[simulate]\n\
         chirp = {{ f0 = {f0}, f1 = {f1}, amplitude = {amplitude}, t1 = {t1} }}\n\
         rate = {SILVERBOX_RATE}\nnoise = true\nseed = {seed}\n\n[[simulate.truth]]\n\
         name = \"cubic_stiffness\"\nparams = {{ k3 = 3.8 }}\n"
    )
}

/// The discovery experiment of the Silverbox-layout case: `silverbox.toml`'s settings.
fn silverbox_discovery(estimation: &str, validation: &str) -> String {
    format!(
        "[data]\nfile = \"{estimation}\"\nrate = {SILVERBOX_RATE}\n\
         units = {{ x = \"V\", u = {{ unit = \"V\", gain = 1.0 }} }}\n\n\
         [fit]\nlevel = \"trajectory\"\nsystem = [\"m\", \"k\", \"c\", \"f_off\"]\n\n\
         [discover]\nbase = \"none\"\nlevel = \"trajectory\"\n\n\
         [validate]\nfile = \"{validation}\"\n\n[output]\nreport = false\n"
    )
}

/// Simulate a Silverbox-layout record into `dir/name` (unless it is there): the simulated
/// record's `u` and `x` columns as they were written, without its time and STF force.
fn silverbox_record(
    dir: &Path,
    name: &str,
    samples: usize,
    chirp: (f64, f64, f64),
    seed: u64,
) -> Result<()> {
    let path = dir.join(name);
    if path.exists() {
        return Ok(());
    }
    let raw = format!("raw_{name}");
    let exp = dir.join(format!("simulate_{name}.toml"));
    std::fs::write(&exp, silverbox_simulation(&raw, samples, chirp, seed))?;
    stf_lab::commands::simulate::run(&exp, &dir.join(&raw), true)?;
    let mut reader = csv::Reader::from_path(dir.join(&raw))?;
    let header = reader.headers()?.clone();
    let col = |name: &str| {
        header
            .iter()
            .position(|h| h == name)
            .with_context(|| format!("no {name} column in {raw}"))
    };
    let (iu, ix) = (col("u")?, col("x")?);
    let mut text = String::from("u,x\n");
    let mut rows = 0;
    for row in reader.records() {
        let row = row?;
        text.push_str(&format!("{},{}\n", &row[iu], &row[ix]));
        rows += 1;
    }
    anyhow::ensure!(rows == samples, "{raw}: {rows} samples, expected {samples}");
    std::fs::write(&path, text)?;
    Ok(())
}

/// The Silverbox-layout case (`--silverbox`): the table row.
fn run_silverbox(dir: &Path) -> Result<String> {
    silverbox_record(
        dir,
        "silverbox_estimation.csv",
        87_000,
        (10.0, 120.0, 0.02),
        5,
    )?;
    silverbox_record(
        dir,
        "silverbox_validation.csv",
        22_000,
        (120.0, 10.0, 0.025),
        6,
    )?;
    let exp = dir.join("silverbox_discovery.toml");
    std::fs::write(
        &exp,
        silverbox_discovery("silverbox_estimation.csv", "silverbox_validation.csv"),
    )?;
    let before = load();
    let (wall, cpu, json) = timed_discovery(&exp, &dir.join("silverbox"))?;
    Ok(format!(
        "| trajectory, Silverbox layout (u, x in V), 87 000 samples, cubic_stiffness hidden, [validate] 22 000 | \
         {wall:.1} s | {cpu:.1} s | {:.2} | {before:.1} | effects {}; gap {:.4e} → {:.4e} V; validation RMS {:.4e} → {:.4e} V |",
        cpu / wall,
        json["effects"],
        json["gap_before"].as_f64().unwrap_or(f64::NAN),
        json["gap_after"].as_f64().unwrap_or(f64::NAN),
        json["validation"]["rms_before"].as_f64().unwrap_or(f64::NAN),
        json["validation"]["rms_after"].as_f64().unwrap_or(f64::NAN),
    ))
}

fn main() -> Result<()> {
    let trajectory = std::env::args().any(|a| a == "--trajectory");
    let shaker = std::env::args().any(|a| a == "--shaker");
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/bench_discovery");
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    // The commands print their own summaries as they go; the table comes last.
    let mut rows = Vec::new();
    if std::env::args().any(|a| a == "--silverbox") {
        rows.push(run_silverbox(&dir)?);
    }
    let cases: Vec<&Case> = if std::env::args().any(|a| a == "--silverbox") {
        vec![]
    } else if shaker {
        vec![&SHAKER]
    } else {
        CASES
            .iter()
            .filter(|c| trajectory || !c.trajectory)
            .collect()
    };
    let only: Option<String> = std::env::args().skip_while(|a| a != "--only").nth(1);
    for case in cases {
        if only
            .as_ref()
            .is_some_and(|o| !case.label.contains(o.as_str()))
        {
            continue;
        }
        let before = load();
        let (wall, cpu, verdict) = run(case, &dir).with_context(|| case.label)?;
        rows.push(format!(
            "| {} | {wall:.1} s | {cpu:.1} s | {:.2} | {before:.1} | {verdict} |",
            case.label,
            cpu / wall
        ));
    }
    println!(
        "\n| case | wall | CPU | CPU/wall | load before | verdict |\n|---|---|---|---|---|---|"
    );
    for row in rows {
        println!("{row}");
    }
    Ok(())
}
