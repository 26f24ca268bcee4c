//! A campaign at cluster scale, behind `#[ignore]` (tens of minutes on 2 cores):
//!
//! ```text
//! cargo test --release --test campaign_scale -- --ignored --nocapture
//! ```
//!
//! 3 000 small units (`STF_LAB_SCALE_UNITS`): the 10 bundled records cut to 4 s each, 300
//! repeats of each in a records table, fitted with the bundled `power_law.toml`. It checks, and
//! prints what it measured:
//! - a plain loop of `stf-lab fit` over the first 100 records (the time per unit to beat);
//! - locally with `--jobs 2`: killed after a fifth of the units, the rerun runs only the
//!   unfinished ones, and ends with every unit finished (wall time, peak memory);
//! - `--collect` alone, the step of the collect job (wall time, peak memory), and the figures
//!   are aggregated, not one marker per record; `campaign.csv` loads in pandas when a Python
//!   with pandas is found (`STF_LAB_PYTHON`, `/work/venv-py/bin/python`, `python3`);
//! - on the single-node Slurm of `tests/slurm/start.sh` (skipped without it, unless
//!   `STF_LAB_REQUIRE_SLURM=1`), with the cluster's own `MaxArraySize` and the default units
//!   per task (`STF_LAB_SCALE_UNITS_PER_TASK` sets one): the collect job completes with
//!   every unit finished (wall time from submission to the collect job's end).
//!
//! The program is copied first, so a rebuild meanwhile does not change the binary under test.
//! Peak memory is `/usr/bin/time -v`'s maximum resident set size: of the campaign process or
//! of any one of its units, whichever is larger.

mod common;

use std::io::{BufRead, BufReader};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use common::slurm::{job_ids, logs, slurm, text, wait_up_to};
use common::{read_json, root};

/// The bundled records and their conditions (as in `experiments/campaign/campaign.toml`).
const RECORDS: [(&str, f64, f64); 10] = [
    ("a1_c1", 0.035, 0.36),
    ("a1_c2", 0.035, 0.40),
    ("a1_c3", 0.035, 0.44),
    ("a2_c1", 0.0462, 0.36),
    ("a2_c2", 0.0462, 0.40),
    ("a2_c3", 0.0462, 0.44),
    ("a3_c1", 0.06, 0.36),
    ("a3_c2", 0.06, 0.40),
    ("a3_c3", 0.06, 0.44),
    ("a2_c4", 0.0462, 0.46),
];

/// Samples kept of each record (4 s at 100 Hz): a small unit.
const SAMPLES: usize = 400;

/// The longest wait for the campaign's jobs on the test cluster (3 000 units take about half
/// an hour on 2 busy cores).
const SLURM_PATIENCE: Duration = Duration::from_secs(4 * 3600);

/// Records of the plain loop.
const LOOP_RECORDS: usize = 100;

/// Print a measured line at once (a long run shows its progress) and keep it for the summary.
fn say(table: &mut Vec<String>, line: String) {
    println!("{line}");
    table.push(line);
}

/// A number from the environment, else `default`.
fn setting(name: &str, default: usize) -> usize {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// The campaign of `n` units in `dir`: the records cut to [`SAMPLES`], a records table of
/// `n` rows (record `i % 10`), the experiment. The campaign file's path.
fn scale_campaign(dir: &Path, n: usize) -> PathBuf {
    let from = root().join("experiments/campaign");
    std::fs::create_dir_all(dir.join("records")).unwrap();
    std::fs::copy(from.join("power_law.toml"), dir.join("power_law.toml")).unwrap();
    for (stem, _, _) in RECORDS {
        let body = std::fs::read_to_string(from.join(format!("records/{stem}.csv"))).unwrap();
        let cut: Vec<&str> = body.lines().take(SAMPLES + 1).collect();
        std::fs::write(
            dir.join(format!("records/{stem}.csv")),
            cut.join("\n") + "\n",
        )
        .unwrap();
    }
    let mut table = String::from("file,F0,concentration\n");
    for i in 0..n {
        let (stem, f0, c) = RECORDS[i % RECORDS.len()];
        table.push_str(&format!("records/{stem}.csv,{f0},{c}\n"));
    }
    std::fs::write(dir.join("records.csv"), table).unwrap();
    let file = dir.join("campaign.toml");
    std::fs::write(
        &file,
        "[campaign]\nexperiment = \"power_law.toml\"\ncommand = \"fit\"\n\
         conditions = [\"F0\", \"concentration\"]\nunits = { F0 = \"kg·m\" }\n\
         records = \"records.csv\"\n",
    )
    .unwrap();
    file
}

/// What `/usr/bin/time -v` said: wall time and peak memory.
struct Measured {
    wall: Duration,
    peak_kb: u64,
    stdout: String,
    stderr: String,
    ok: bool,
}

/// Run `exe ARGS` under `/usr/bin/time -v` with `env`.
fn measured(exe: &Path, args: &[&std::ffi::OsStr], env: &[(&str, &std::ffi::OsStr)]) -> Measured {
    let started = Instant::now();
    let mut cmd = Command::new("/usr/bin/time");
    cmd.arg("-v").arg(exe).args(args);
    for (k, v) in env {
        cmd.env(k, v);
    }
    let o = cmd.output().unwrap();
    let stderr = text(&o.stderr);
    let peak_kb = stderr
        .lines()
        .find_map(|l| {
            l.trim()
                .strip_prefix("Maximum resident set size (kbytes): ")
        })
        .and_then(|v| v.trim().parse().ok())
        .unwrap_or(0);
    Measured {
        wall: started.elapsed(),
        peak_kb,
        stdout: text(&o.stdout),
        stderr,
        ok: o.status.success(),
    }
}

/// The units under `out` with a `unit.json` saying `ok`.
fn finished_units(out: &Path) -> usize {
    let Ok(dirs) = std::fs::read_dir(out.join("units")) else {
        return 0;
    };
    dirs.filter_map(|e| e.ok())
        .filter(|e| {
            std::fs::read_to_string(e.path().join("unit.json"))
                .is_ok_and(|t| t.contains("\"status\": \"ok\""))
        })
        .count()
}

/// A Python that imports pandas, if there is one.
fn python_with_pandas() -> Option<String> {
    let candidates = [
        std::env::var("STF_LAB_PYTHON").ok(),
        Some("/work/venv-py/bin/python".into()),
        Some("python3".into()),
    ];
    candidates.into_iter().flatten().find(|p| {
        Command::new(p)
            .args(["-c", "import pandas"])
            .output()
            .is_ok_and(|o| o.status.success())
    })
}

/// The plain loop: `stf-lab fit` on the first `records` records, one after another,
/// each with an experiment file of its own. Seconds per record.
fn plain_loop(exe: &Path, dir: &Path, records: usize) -> f64 {
    let experiment = std::fs::read_to_string(dir.join("power_law.toml")).unwrap();
    let started = Instant::now();
    for i in 0..records {
        let (stem, _, _) = RECORDS[i % RECORDS.len()];
        let exp = dir.join(format!("loop-{i}.toml"));
        std::fs::write(
            &exp,
            experiment.replace("records/a1_c1.csv", &format!("records/{stem}.csv")),
        )
        .unwrap();
        let o = Command::new(exe)
            .arg("fit")
            .arg(&exp)
            .arg("--out")
            .arg(dir.join(format!("loop-out/{i}")))
            .arg("--quiet")
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", text(&o.stderr));
    }
    started.elapsed().as_secs_f64() / records as f64
}

/// Run the campaign locally with `--jobs 2` and SIGKILL it once `stop_after` units have
/// ended. How many units had finished.
fn killed_run(exe: &Path, file: &Path, out: &Path, stop_after: usize) -> usize {
    let mut child = Command::new(exe)
        .arg("campaign")
        .arg(file)
        .arg("--out")
        .arg(out)
        .args(["--jobs", "2"])
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let lines = BufReader::new(child.stdout.take().unwrap()).lines();
    let mut ended = 0;
    for line in lines.map_while(Result::ok) {
        if line.starts_with('[') && line.contains("] unit ") {
            ended += 1;
            if ended >= stop_after {
                break;
            }
        }
    }
    child.kill().unwrap();
    child.wait().unwrap();
    finished_units(out)
}

/// The figures of the report are aggregated (a caption says so) and `campaign.csv` has a row
/// per record and model; with pandas, it loads there too.
fn check_outputs(out: &Path, n: usize) {
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        report.contains("each marker is the mean of the records at that concentration"),
        "the figures of {n} records are not aggregated"
    );
    if 2 * n > 200 {
        assert!(report.contains(&format!("The first 200 of {} rows", 2 * n)));
    }
    let figure =
        std::fs::read_to_string(out.join("figures/power_law_K_vs_concentration.csv")).unwrap();
    // Three series (one per F0), at most 4 concentrations each: a handful of markers.
    assert!(figure.lines().count() <= 5, "{figure}");
    if let Some(python) = python_with_pandas() {
        let o = Command::new(&python)
            .arg("-c")
            .arg(
                "import sys, pandas\n\
                 t = pandas.read_csv(sys.argv[1])\n\
                 print(len(t), (t.status == 'ok').sum(), t.K.notna().sum())",
            )
            .arg(out.join("campaign.csv"))
            .output()
            .unwrap();
        assert!(o.status.success(), "{}", text(&o.stderr));
        let said = text(&o.stdout);
        assert_eq!(said.trim(), format!("{} {} {n}", 2 * n, 2 * n), "{said}");
        println!("pandas ({python}): campaign.csv read, {} rows", 2 * n);
    } else {
        println!("pandas: no Python with pandas found; campaign.csv not loaded there");
    }
}

#[test]
#[ignore = "tens of minutes: a campaign of 3 000 units, locally and on Slurm"]
fn thousands_of_units_locally_and_on_single_node_slurm() {
    let n = setting("STF_LAB_SCALE_UNITS", 3000);
    let tmp = tempfile::tempdir().unwrap();
    let exe = tmp.path().join("stf-lab");
    std::fs::copy(env!("CARGO_BIN_EXE_stf-lab"), &exe).unwrap();
    let dir = tmp.path().join("campaign");
    let file = scale_campaign(&dir, n);
    let mut table = vec![format!(
        "units: {n} ({SAMPLES} samples each, fit of 2 models)"
    )];

    let loop_records = LOOP_RECORDS.min(n);
    let per_unit_loop = plain_loop(&exe, &dir, loop_records);
    say(
        &mut table,
        format!(
            "plain loop of `stf-lab fit`, {loop_records} records: {per_unit_loop:.3} s per record"
        ),
    );

    // Locally, killed after a fifth of the units, then resumed.
    let out = tmp.path().join("local");
    let started = Instant::now();
    let done = killed_run(&exe, &file, &out, n / 5);
    let before_kill = started.elapsed();
    assert!(
        done > 0 && done < n,
        "{done} of {n} finished before the kill"
    );
    let rerun = measured(
        &exe,
        &[
            "campaign".as_ref(),
            file.as_os_str(),
            "--out".as_ref(),
            out.as_os_str(),
            "--jobs".as_ref(),
            "2".as_ref(),
        ],
        &[],
    );
    assert!(rerun.ok, "{}{}", rerun.stdout, rerun.stderr);
    let to_run = format!("{n} unit(s), {} to run", n - done);
    assert!(rerun.stdout.contains(&to_run), "{to_run:?} not said");
    assert_eq!(
        rerun
            .stdout
            .matches(": unchanged since its last run, skipped")
            .count(),
        done
    );
    assert_eq!(finished_units(&out), n);
    let local_wall = before_kill + rerun.wall;
    say(
        &mut table,
        format!(
            "local --jobs 2: killed after {done} finished units ({:.0} s), rerun ran {} units in \
         {:.0} s (peak {} MB); {:.0} s in all, {:.3} s per unit",
            before_kill.as_secs_f64(),
            n - done,
            rerun.wall.as_secs_f64(),
            rerun.peak_kb / 1024,
            local_wall.as_secs_f64(),
            local_wall.as_secs_f64() / n as f64
        ),
    );

    let collect = measured(
        &exe,
        &[
            "campaign".as_ref(),
            file.as_os_str(),
            "--out".as_ref(),
            out.as_os_str(),
            "--collect".as_ref(),
            "--quiet".as_ref(),
        ],
        &[],
    );
    assert!(collect.ok, "{}", collect.stderr);
    say(
        &mut table,
        format!(
            "--collect (table, report, figures of {n} units): {:.1} s, peak {} MB",
            collect.wall.as_secs_f64(),
            collect.peak_kb / 1024
        ),
    );
    check_outputs(&out, n);
    assert_eq!(read_json(&out.join("campaign.json"))["failed"], 0);

    if let Some(conf) = slurm() {
        let cluster = tmp.path().join("cluster");
        if let Some(k) = std::env::var_os("STF_LAB_SCALE_UNITS_PER_TASK") {
            let body = std::fs::read_to_string(&file).unwrap();
            let k = k.to_string_lossy().into_owned();
            std::fs::write(&file, format!("{body}\n[slurm]\nunits_per_task = {k}\n")).unwrap();
        }
        let started = Instant::now();
        let o = Command::new(&exe)
            .arg("campaign")
            .arg(&file)
            .arg("--out")
            .arg(&cluster)
            .args(["--slurm", "--time", "00:10:00", "--mem", "500M"])
            .env("SLURM_CONF", &conf)
            .output()
            .unwrap();
        let said = text(&o.stdout);
        assert!(o.status.success(), "{said}{}", text(&o.stderr));
        let plan = said
            .lines()
            .find(|l| l.contains(" task(s) of at most "))
            .unwrap_or("");
        let (units, collect_job) = job_ids(&said);
        let state = wait_up_to(&collect_job, &cluster, &conf, SLURM_PATIENCE);
        let wall = started.elapsed();
        assert_eq!(state, "COMPLETED", "{}", logs(&cluster, &conf));
        for id in &units {
            assert_eq!(wait_up_to(id, &cluster, &conf, SLURM_PATIENCE), "COMPLETED");
        }
        assert_eq!(finished_units(&cluster), n);
        assert_eq!(read_json(&cluster.join("campaign.json"))["failed"], 0);
        say(
            &mut table,
            format!(
                "Slurm: {plan}; submission to the collect job's end {:.0} s, {:.3} s per unit",
                wall.as_secs_f64(),
                wall.as_secs_f64() / n as f64
            ),
        );
    }
    println!("\n{}", table.join("\n"));
}
