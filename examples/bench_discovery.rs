//! Benchmark of discovery on the full-length paper sweep (run in release):
//!
//! ```text
//! cargo run --release --example bench_discovery                 # force level
//! cargo run --release --example bench_discovery -- --trajectory # and trajectory level
//! cargo run --release --example bench_discovery -- --shaker     # a 10⁵-sample shaker record
//! ```
//!
//! Records: the source study's 0.047 rad/s² sweep, ω 2.35 → 9.4 rad/s over t 50 → 200 s at
//! 1 kHz (150 001 samples) through the rig's sensors, truth `power_law` K 20, n 1.5, with
//! nothing else or with `added_mass` m_a 1.5 kg hidden; `[discover] base = "power_law"`,
//! everything else default. Each case runs `stf-lab simulate` and `stf-lab discover` as the
//! command line does (experiment files and records under `target/bench_discovery/`) and
//! prints the discovery's wall time and verdict. Trajectory level discovers from t, φ and x
//! only (`[discover] level = "trajectory"`). `--shaker` runs trajectory-level discovery alone
//! on a shaker rig's record of 100 001 samples (the bundled `trajectory_discovery` rig: a
//! measured drive force `u`, a 0.5 → 1.5 Hz chirp over 500 s at 200 Hz, truth `viscous` with
//! a `cubic_stiffness` hidden, base `viscous`, every default candidate). Timings depend on
//! what else runs on the machine.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result};

/// One benchmark case: a label, the truth's extra effect and the discovery level.
struct Case {
    label: &'static str,
    hidden: Option<&'static str>,
    trajectory: bool,
}

/// The shaker case (`--shaker`): trajectory level on 100 001 samples with a measured drive.
const SHAKER: Case = Case {
    label: "trajectory, shaker u, 100 001 samples, cubic_stiffness hidden",
    hidden: Some("cubic_stiffness"),
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

const CASES: [Case; 4] = [
    Case {
        label: "force, nothing hidden",
        hidden: None,
        trajectory: false,
    },
    Case {
        label: "force, added_mass hidden",
        hidden: Some("added_mass"),
        trajectory: false,
    },
    Case {
        label: "trajectory, nothing hidden",
        hidden: None,
        trajectory: true,
    },
    Case {
        label: "trajectory, added_mass hidden",
        hidden: Some("added_mass"),
        trajectory: true,
    },
];

/// The experiment file of `case`.
fn experiment(case: &Case, record: &str) -> String {
    if case.hidden == Some("cubic_stiffness") {
        return shaker_experiment(record);
    }
    let (plus, extra) = match case.hidden {
        Some("added_mass") => ("plus = [\"added_mass\"]\n", ", m_a = 1.5"),
        _ => ("", ""),
    };
    let level = if case.trajectory {
        "level = \"trajectory\"\n"
    } else {
        ""
    };
    format!(
        "[data]\nfile = \"{record}\"\n\n[simulate]\n\
         sweep = {{ w0 = 2.35, alpha = 0.047, t0 = 50.0, t1 = 200.0 }}\n\
         rate = 1000.0\nnoise = true\nseed = 1\n\n[[simulate.truth]]\nname = \"power_law\"\n\
         {plus}params = {{ K = 20.0, n = 1.5{extra} }}\n\n[discover]\nbase = \"power_law\"\n{level}"
    )
}

/// Simulate the case's record, run discovery on it; the wall time of the discovery and
/// what it named.
fn run(case: &Case, dir: &Path) -> Result<(f64, String)> {
    let stem = format!(
        "{}_{}",
        if case.trajectory {
            "trajectory"
        } else {
            "force"
        },
        case.hidden.unwrap_or("none")
    );
    let record = format!("sweep_{}.csv", case.hidden.unwrap_or("none"));
    let exp = dir.join(format!("{stem}.toml"));
    std::fs::write(&exp, experiment(case, &record))?;
    if !dir.join(&record).exists() {
        stf_lab::commands::simulate::run(&exp, &dir.join(&record), true)?;
    }
    let out = dir.join(&stem);
    let clock = Instant::now();
    let loaded = stf_lab::experiment::Experiment::load(&exp)?;
    stf_lab::commands::discover::run_experiment(loaded, &out, true, true)?;
    let wall = clock.elapsed().as_secs_f64();
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("discovery.json"))?)?;
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
        format!(
            "{named}; gap {:.4e} → {:.4e} {unit}",
            json["gap_before"].as_f64().unwrap_or(f64::NAN),
            json["gap_after"].as_f64().unwrap_or(f64::NAN)
        ),
    ))
}

fn main() -> Result<()> {
    let trajectory = std::env::args().any(|a| a == "--trajectory");
    let shaker = std::env::args().any(|a| a == "--shaker");
    let dir = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("target/bench_discovery");
    std::fs::create_dir_all(&dir).with_context(|| format!("creating {}", dir.display()))?;
    // The commands print their own summaries as they go; the table comes last.
    let mut rows = Vec::new();
    let cases: Vec<&Case> = if shaker {
        vec![&SHAKER]
    } else {
        CASES
            .iter()
            .filter(|c| trajectory || !c.trajectory)
            .collect()
    };
    for case in cases {
        let (wall, verdict) = run(case, &dir).with_context(|| case.label)?;
        rows.push(format!("| {} | {wall:.1} s | {verdict} |", case.label));
    }
    println!("\n| case | wall | verdict |\n|---|---|---|");
    for row in rows {
        println!("{row}");
    }
    Ok(())
}
