//! `stf-lab campaign --slurm`: a small campaign (three records of the bundled example and a
//! `[global]` fit) run through a real single-node Slurm, brought up on this machine by
//! `tests/slurm/start.sh`, gives the units, `campaign.json`, `campaign.csv` and
//! `global.json` of a local run, timing fields apart; a unit that fails on the cluster is
//! named by the collect job; four units with `[slurm] max_array_size = 3` go to two arrays,
//! and an array task cancelled by the scheduler (`scancel`) is named by the collect job and
//! rerun alone by the next submission, the finished units untouched. Without Slurm (no
//! `sbatch`, `slurmctld`, `slurmd` or `munged` on PATH, or not root) these tests say why they
//! are skipped and pass, unless `STF_LAB_REQUIRE_SLURM=1` (CI), where they fail.
//!
//! The other tests need no Slurm: `--dry-run` prints the scripts and calls no `sbatch`, a
//! stand-in `sbatch` and `scontrol` show what is submitted and in which order (arrays cut at
//! the `MaxArraySize` scontrol says), a missing `sbatch` is a clear error, and `--collect`
//! names the units that did not finish.
//!
//! Every wait has a time limit and ends with the jobs' and daemons' logs.

mod common;

use std::path::{Path, PathBuf};
use std::process::Output;
use std::time::{Duration, Instant};

use common::slurm::{collected, job_ids, logs, scancel, slurm, submitted, text, wait_for};
use common::{read_json, root, stf_lab};

/// Three records of the bundled campaign (three concentrations, three amplitudes) copied into
/// `dir`, with its experiment, a `[global]` fit (n shared, K a law of the concentration) and,
/// when `broken`, a fourth record that cannot be read. The campaign file's path.
fn small_campaign(dir: &Path, broken: bool) -> PathBuf {
    let from = root().join("experiments/campaign");
    std::fs::create_dir_all(dir.join("records")).unwrap();
    std::fs::copy(from.join("power_law.toml"), dir.join("power_law.toml")).unwrap();
    let records = [
        ("a1_c1", 0.035, 0.36),
        ("a2_c2", 0.0462, 0.40),
        ("a3_c3", 0.06, 0.44),
    ];
    let mut text = String::from(
        "[campaign]\nexperiment = \"power_law.toml\"\ncommand = \"fit\"\n\
         conditions = [\"F0\", \"concentration\"]\n",
    );
    for (stem, f0, c) in records {
        let name = format!("records/{stem}.csv");
        std::fs::copy(from.join(&name), dir.join(&name)).unwrap();
        text.push_str(&format!(
            "\n[[records]]\nfile = \"{name}\"\nF0 = {f0}\nconcentration = {c}\n"
        ));
    }
    if broken {
        std::fs::write(dir.join("records/broken.csv"), "t,phi,x\n0,0,0\n1,zero,0\n").unwrap();
        text.push_str(
            "\n[[records]]\nfile = \"records/broken.csv\"\nF0 = 1\nconcentration = 0.5\n",
        );
    } else {
        text.push_str(
            "\n[global]\nmodel = \"power_law\"\nshared = [\"n\"]\n\
             laws = { K = { condition = \"concentration\", reference = 0.40 } }\n",
        );
    }
    let file = dir.join("campaign.toml");
    std::fs::write(&file, text).unwrap();
    file
}

/// `stf-lab campaign FILE --out OUT ARGS…`, with `env` set.
fn campaign(file: &Path, out: &Path, args: &[&str], env: &[(&str, &std::ffi::OsStr)]) -> Output {
    let mut cmd = stf_lab();
    cmd.arg("campaign")
        .arg(file)
        .arg("--out")
        .arg(out)
        .args(args);
    for (k, v) in env {
        cmd.env(k, v);
    }
    cmd.output().unwrap()
}

/// The timing fields of the results: measured, so never the same twice.
const TIMING: [&str; 2] = ["wall_seconds", "joint_fit_seconds"];

/// A JSON or CSV result with its timing fields ([`TIMING`]) left out and the output folder's
/// path replaced by `OUT`, as text.
fn comparable(path: &Path, out: &Path) -> String {
    let body = std::fs::read_to_string(path).unwrap();
    let body = body.replace(out.to_str().unwrap(), "OUT");
    if path.extension().is_some_and(|e| e == "json") {
        let mut value: serde_json::Value = serde_json::from_str(&body).unwrap();
        drop_timing(&mut value);
        return serde_json::to_string_pretty(&value).unwrap();
    }
    let mut reader = csv::ReaderBuilder::new()
        .has_headers(false)
        .from_reader(body.as_bytes());
    let rows: Vec<csv::StringRecord> = reader.records().map(|r| r.unwrap()).collect();
    let keep: Vec<usize> = (0..rows.first().map_or(0, |r| r.len()))
        .filter(|&i| !TIMING.contains(&&rows[0][i]))
        .collect();
    rows.iter()
        .map(|r| keep.iter().map(|&i| &r[i]).collect::<Vec<_>>().join(","))
        .collect::<Vec<_>>()
        .join("\n")
}

/// Remove every timing key ([`TIMING`]).
fn drop_timing(value: &mut serde_json::Value) {
    match value {
        serde_json::Value::Object(map) => {
            for key in TIMING {
                map.remove(key);
            }
            map.values_mut().for_each(drop_timing);
        }
        serde_json::Value::Array(items) => items.iter_mut().for_each(drop_timing),
        _ => {}
    }
}

/// The JSON and CSV results under `out` (units and campaign), by path relative to `out`.
fn results(out: &Path) -> Vec<PathBuf> {
    let mut found = Vec::new();
    let mut folders = vec![out.to_path_buf()];
    while let Some(dir) = folders.pop() {
        for e in std::fs::read_dir(&dir).unwrap().map(|e| e.unwrap().path()) {
            let name = e.strip_prefix(out).unwrap().to_path_buf();
            if e.is_dir() && (dir != out || name == Path::new("units")) {
                folders.push(e);
            } else if e.extension().is_some_and(|x| x == "json" || x == "csv") {
                found.push(name);
            }
        }
    }
    found.sort();
    found
}

#[test]
fn a_campaign_through_single_node_slurm_gives_the_local_run_s_outputs() {
    let Some(conf) = slurm() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let file = small_campaign(&tmp.path().join("campaign"), false);
    let local = tmp.path().join("local");
    let run = campaign(&file, &local, &["--jobs", "1", "--quiet"], &[]);
    assert!(run.status.success(), "{}", text(&run.stderr));

    let cluster = tmp.path().join("cluster");
    let env = [("SLURM_CONF", conf.as_os_str())];
    let flags = ["--slurm", "--time", "00:10:00", "--mem", "500M"];
    let (_, units, collect) = submitted(&campaign(&file, &cluster, &flags, &env));
    assert_eq!(units.len(), 1, "three units fit one array");
    collected(&collect, &cluster, &conf, "COMPLETED");
    assert_eq!(wait_for(&units[0], &cluster, &conf), "COMPLETED");

    let names = results(&local);
    assert_eq!(names, results(&cluster));
    for want in [
        "campaign.json",
        "campaign.csv",
        "global.json",
        "units/002-a2_c2/unit.json",
    ] {
        assert!(names.contains(&PathBuf::from(want)), "{want} in {names:?}");
    }
    assert!(names.iter().filter(|n| n.ends_with("fit.json")).count() == 3);
    for name in &names {
        assert_eq!(
            comparable(&local.join(name), &local),
            comparable(&cluster.join(name), &cluster),
            "{} differs between the local and the Slurm run",
            name.display()
        );
    }
    // The array ran every unit, each logged in DIR/slurm/.
    for n in 1..=3 {
        assert!(
            cluster.join(format!("slurm/unit-{n}.log")).is_file(),
            "unit {n}'s log"
        );
    }

    // Submitted again, every unit is finished: nothing goes to Slurm, the table is collected
    // at once.
    let again = campaign(&file, &cluster, &flags, &env);
    let said = text(&again.stdout);
    assert!(again.status.success(), "{said}{}", text(&again.stderr));
    assert!(
        said.contains("nothing to submit: the table is collected here"),
        "{said}"
    );
    assert!(!said.contains("units job:"), "{said}");
}

#[test]
fn a_unit_failing_on_the_cluster_is_named_by_the_collect_job() {
    let Some(conf) = slurm() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let file = small_campaign(&tmp.path().join("campaign"), true);
    let out = tmp.path().join("out");
    let env = [("SLURM_CONF", conf.as_os_str())];
    let flags = ["--slurm", "--time", "00:10:00"];
    let (_, units, collect) = submitted(&campaign(&file, &out, &flags, &env));
    let log = collected(&collect, &out, &conf, "FAILED");
    // Three tasks ran their unit, the fourth failed; the collect job ran all the same.
    assert_eq!(wait_for(&units[0], &out, &conf), "COMPLETED,FAILED");
    assert!(
        log.contains("1 of 4 unit(s) failed") && log.contains("unit 4 (records/broken.csv): "),
        "{log}"
    );
    let rows = read_json(&out.join("campaign.json"))["rows"].clone();
    let failed: Vec<&serde_json::Value> = rows
        .as_array()
        .unwrap()
        .iter()
        .filter(|r| r["status"] == "failed")
        .collect();
    assert_eq!(failed.len(), 1);
    assert!(
        failed[0]["error"].as_str().unwrap().contains("broken.csv"),
        "{}",
        failed[0]
    );
}

/// A stand-in `sbatch` in `dir` that appends its arguments to `dir/calls` and prints the
/// job ids 41, 42, …; and a stand-in `scontrol` whose configuration says `MaxArraySize = 2`.
fn fake_sbatch(dir: &Path) {
    let sbatch = "#!/bin/sh\n\
        echo \"$@\" >> \"$(dirname \"$0\")/calls\"\n\
        n=$(wc -l < \"$(dirname \"$0\")/calls\")\n\
        echo $((40 + n))\n";
    write_script(&dir.join("sbatch"), sbatch);
    fake_scontrol(dir, 2);
}

/// A stand-in `scontrol` in `dir` whose configuration says `MaxArraySize = max`.
fn fake_scontrol(dir: &Path, max: usize) {
    let scontrol = format!(
        "#!/bin/sh\n\
         echo \"Configuration data as of 2026-11-27T22:00:00\"\n\
         echo \"MaxArraySize            = {max}\"\n\
         echo \"MaxJobCount             = 10000\"\n"
    );
    write_script(&dir.join("scontrol"), &scontrol);
}

/// An executable file at `path`.
fn write_script(path: &Path, body: &str) {
    std::fs::write(path, body).unwrap();
    let mut mode = std::fs::metadata(path).unwrap().permissions();
    std::os::unix::fs::PermissionsExt::set_mode(&mut mode, 0o755);
    std::fs::set_permissions(path, mode).unwrap();
}

/// PATH with `dir` first.
fn path_with(dir: &Path) -> std::ffi::OsString {
    let rest = std::env::var_os("PATH").unwrap_or_default();
    let mut all = vec![dir.to_path_buf()];
    all.extend(std::env::split_paths(&rest));
    std::env::join_paths(all).unwrap()
}

#[test]
fn a_dry_run_prints_the_scripts_of_the_unfinished_units_and_submits_nothing() {
    let tmp = tempfile::tempdir().unwrap();
    let file = small_campaign(&tmp.path().join("campaign"), false);
    let out = tmp.path().join("out");
    // Unit 2 is finished: only units 1 and 3 go into the array.
    let run = campaign(&file, &out, &["--unit", "2", "--quiet"], &[]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    let bin = tmp.path().join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    fake_sbatch(&bin);
    let path = path_with(&bin);
    let flags = [
        "--slurm",
        "--dry-run",
        "--partition",
        "short",
        "--time",
        "00:20:00",
        "--mem",
        "2G",
        "--account",
        "lab",
    ];
    let run = campaign(&file, &out, &flags, &[("PATH", path.as_os_str())]);
    let said = text(&run.stdout);
    assert!(run.status.success(), "{said}{}", text(&run.stderr));
    assert!(!bin.join("calls").exists(), "--dry-run called sbatch");
    assert!(!out.join("slurm").exists(), "--dry-run wrote the scripts");
    let out = out.canonicalize().unwrap();
    let slurm = out.join("slurm");
    for line in [
        "2 unit(s) in 2 task(s) of at most 1 unit(s) (the default for these commands), 1 \
         array(s) of at most 2 task(s) (the cluster's MaxArraySize (scontrol show config))"
            .to_string(),
        "#SBATCH --array=0-1\n".into(),
        "  0) units=\"1\" ;;\n  1) units=\"3\" ;;\n".into(),
        format!("#SBATCH --output={}/array-1-task-%a.log", slurm.display()),
        "#SBATCH --partition=short".into(),
        "#SBATCH --time=00:20:00".into(),
        "#SBATCH --mem=2G".into(),
        "#SBATCH --account=lab".into(),
        "--unit \"$n\" --quiet".into(),
        "} > \"unit-$n.log\" 2>&1".into(),
        format!("--out {} --collect --quiet", out.display()),
        format!("sbatch --parsable {}/units-1.sbatch", slurm.display()),
        format!(
            "sbatch --parsable --dependency=afterany:<units job 1 id> {}/collect.sbatch",
            slurm.display()
        ),
    ] {
        assert!(said.contains(&line), "no {line:?} in:\n{said}");
    }
    assert_eq!(
        said.matches("#SBATCH --partition=short").count(),
        2,
        "{said}"
    );
}

/// `file`'s text with `[slurm]` settings added.
fn with_slurm_settings(file: &Path, settings: &str) {
    let body = std::fs::read_to_string(file).unwrap();
    std::fs::write(file, format!("{body}\n[slurm]\n{settings}")).unwrap();
}

#[test]
fn the_collect_job_is_submitted_after_every_array_whatever_their_tasks_end_with() {
    let tmp = tempfile::tempdir().unwrap();
    let file = small_campaign(&tmp.path().join("campaign"), false);
    // Three units, at most 2 tasks per array: two arrays.
    with_slurm_settings(
        &file,
        "units_per_task = 1\nthrottle = 5\ncpus_per_task = 2\n",
    );
    let out = tmp.path().join("out");
    let bin = tmp.path().join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    fake_sbatch(&bin);
    let path = path_with(&bin);
    let run = campaign(&file, &out, &["--slurm"], &[("PATH", path.as_os_str())]);
    let said = text(&run.stdout);
    assert!(run.status.success(), "{said}{}", text(&run.stderr));
    assert_eq!(
        job_ids(&said),
        (vec!["41".to_string(), "42".to_string()], "43".to_string())
    );
    let slurm = out.canonicalize().unwrap().join("slurm");
    let calls = std::fs::read_to_string(bin.join("calls")).unwrap();
    assert_eq!(
        calls,
        format!(
            "--parsable {0}/units-1.sbatch\n--parsable {0}/units-2.sbatch\n\
             --parsable --dependency=afterany:41:42 {0}/collect.sbatch\n",
            slurm.display()
        )
    );
    let first = std::fs::read_to_string(slurm.join("units-1.sbatch")).unwrap();
    assert!(first.contains("#SBATCH --array=0-1%5\n"), "{first}");
    assert!(first.contains("#SBATCH --cpus-per-task=2\n"), "{first}");
    assert!(first.contains("  0) units=\"1\" ;;\n  1) units=\"2\" ;;\n"));
    let second = std::fs::read_to_string(slurm.join("units-2.sbatch")).unwrap();
    assert!(second.contains("#SBATCH --array=0-0%5\n"), "{second}");
    assert!(second.contains("  0) units=\"3\" ;;\n"), "{second}");
    assert!(slurm.join("collect.sbatch").is_file());

    // Three units per task: one array, one task; the second array's script of the last
    // submission is removed, so DIR/slurm/ holds only what this one submitted.
    let body = std::fs::read_to_string(&file).unwrap();
    std::fs::write(
        &file,
        body.replace("units_per_task = 1", "units_per_task = 3"),
    )
    .unwrap();
    let run = campaign(&file, &out, &["--slurm"], &[("PATH", path.as_os_str())]);
    let said = text(&run.stdout);
    assert!(run.status.success(), "{said}{}", text(&run.stderr));
    assert_eq!(job_ids(&said).0, ["44"]);
    let first = std::fs::read_to_string(slurm.join("units-1.sbatch")).unwrap();
    assert!(first.contains("  0) units=\"1 2 3\" ;;\n"), "{first}");
    assert!(!slurm.join("units-2.sbatch").exists());
}

#[test]
fn slurm_without_sbatch_is_a_clear_error() {
    let tmp = tempfile::tempdir().unwrap();
    let file = small_campaign(&tmp.path().join("campaign"), false);
    let empty = tmp.path().join("empty");
    std::fs::create_dir_all(&empty).unwrap();
    let out = tmp.path().join("out");
    let run = campaign(&file, &out, &["--slurm"], &[("PATH", empty.as_os_str())]);
    assert!(!run.status.success());
    let e = text(&run.stderr);
    assert!(e.contains("sbatch is not on PATH"), "{e}");
}

#[test]
fn collect_names_the_units_that_did_not_finish() {
    let tmp = tempfile::tempdir().unwrap();
    let file = small_campaign(&tmp.path().join("campaign"), false);
    let out = tmp.path().join("out");
    let run = campaign(&file, &out, &["--unit", "1", "--quiet"], &[]);
    assert!(run.status.success(), "{}", text(&run.stderr));
    let run = campaign(&file, &out, &["--collect", "--quiet"], &[]);
    assert!(!run.status.success());
    let e = text(&run.stderr);
    assert!(e.contains("2 of 3 unit(s) failed"), "{e}");
    for (n, stem) in [(2, "a2_c2"), (3, "a3_c3")] {
        assert!(
            e.contains(&format!(
                "unit {n} (records/{stem}.csv): it did not finish: no unit.json in"
            )),
            "{e}"
        );
    }
    let rows = read_json(&out.join("campaign.json"))["rows"].clone();
    let ok = rows
        .as_array()
        .unwrap()
        .iter()
        .filter(|r| r["status"] == "ok")
        .count();
    assert_eq!(ok, 2, "unit 1's two models");
}

/// The identity of each unit's `unit.json` under `out` (inode and modification time), by
/// unit folder: a rewritten file gets a new one.
fn unit_stamps(out: &Path) -> Vec<(String, u64, std::time::SystemTime)> {
    let mut stamps = Vec::new();
    for e in std::fs::read_dir(out.join("units")).unwrap() {
        let dir = e.unwrap().path();
        if let Ok(meta) = std::fs::metadata(dir.join("unit.json")) {
            let name = dir.file_name().unwrap().to_string_lossy().into_owned();
            let ino = std::os::unix::fs::MetadataExt::ino(&meta);
            stamps.push((name, ino, meta.modified().unwrap()));
        }
    }
    stamps.sort();
    stamps
}

#[test]
fn arrays_split_within_max_array_size_and_a_cancelled_task_is_rerun_alone() {
    let Some(conf) = slurm() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("campaign");
    let file = small_campaign(&dir, false);
    // A fourth record (a copy of the first, repeated): four units. At most 3 tasks per array
    // and one unit per task: two arrays of 3 and 1 tasks. One task of an array at a time,
    // so the third task of the first array is still waiting when it is cancelled.
    std::fs::copy(
        dir.join("records/a1_c1.csv"),
        dir.join("records/a1_c1_again.csv"),
    )
    .unwrap();
    let body = std::fs::read_to_string(&file).unwrap();
    let (records, global) = body.split_once("\n[global]").unwrap();
    std::fs::write(
        &file,
        format!(
            "{records}\n[[records]]\nfile = \"records/a1_c1_again.csv\"\nF0 = 0.035\n\
             concentration = 0.36\n\n[global]{global}\n[slurm]\nmax_array_size = 3\n\
             units_per_task = 1\nthrottle = 1\n"
        ),
    )
    .unwrap();
    let out = tmp.path().join("out");
    let env = [("SLURM_CONF", conf.as_os_str())];
    let flags = ["--slurm", "--time", "00:10:00", "--mem", "500M"];
    let (said, units, collect) = submitted(&campaign(&file, &out, &flags, &env));
    assert_eq!(units.len(), 2, "{said}");
    assert!(
        said.contains("4 unit(s) in 4 task(s) of at most 1 unit(s) ([slurm] units_per_task), 2 array(s) of at most 3 task(s) ([slurm] max_array_size)"),
        "{said}"
    );
    // The scheduler kills task 2 of the first array (unit 3) before it runs.
    scancel(&format!("{}_2", units[0]), &conf);
    let log = collected(&collect, &out, &conf, "FAILED");
    // (squeue may no longer list a task cancelled while it waited.)
    let states = wait_for(&units[0], &out, &conf);
    assert!(
        ["CANCELLED,COMPLETED", "COMPLETED"].contains(&states.as_str()),
        "{states}"
    );
    assert_eq!(wait_for(&units[1], &out, &conf), "COMPLETED");
    assert!(
        log.contains("1 of 4 unit(s) failed")
            && log.contains("unit 3 (records/a3_c3.csv): it did not finish: no unit.json in"),
        "{log}"
    );
    for n in [1, 2, 4] {
        let unit_log = std::fs::read_to_string(out.join(format!("slurm/unit-{n}.log"))).unwrap();
        assert!(
            unit_log.starts_with("[stf-lab campaign] run by Slurm task "),
            "{unit_log}"
        );
    }
    let finished = unit_stamps(&out);
    assert_eq!(finished.len(), 3, "{finished:?}");

    // Submitted again: only unit 3 goes to Slurm; the finished units are not touched.
    let (said, units, collect) = submitted(&campaign(&file, &out, &flags, &env));
    assert!(said.contains("1 unit(s) in 1 task(s)"), "{said}");
    assert_eq!(units.len(), 1, "{said}");
    collected(&collect, &out, &conf, "COMPLETED");
    let now = unit_stamps(&out);
    assert_eq!(now.len(), 4, "{now:?}");
    for stamp in &finished {
        assert!(now.contains(stamp), "{stamp:?} was rewritten: {now:?}");
    }
    let rows = read_json(&out.join("campaign.json"));
    assert_eq!(rows["failed"], 0);
    assert_eq!(rows["units"], 4);
}

#[test]
fn three_thousand_units_one_per_task_go_to_three_arrays_below_slurm_s_default_limit() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path().join("campaign");
    small_campaign(&dir, false);
    let mut table = String::from("file,F0,concentration\n");
    for i in 0..3000 {
        table.push_str(&format!(
            "records/a1_c1.csv,0.035,{}\n",
            0.30 + 0.001 * (i % 100) as f64
        ));
    }
    std::fs::write(dir.join("records.csv"), table).unwrap();
    let file = dir.join("big.toml");
    std::fs::write(
        &file,
        "[campaign]\nexperiment = \"power_law.toml\"\ncommand = \"fit\"\n\
         conditions = [\"F0\", \"concentration\"]\nrecords = \"records.csv\"\n\n\
         [slurm]\nunits_per_task = 1\nthrottle = 100\n",
    )
    .unwrap();
    let bin = tmp.path().join("bin");
    std::fs::create_dir_all(&bin).unwrap();
    fake_scontrol(&bin, 1001);
    let path = path_with(&bin);
    let out = tmp.path().join("out");
    let run = campaign(
        &file,
        &out,
        &["--slurm", "--dry-run"],
        &[("PATH", path.as_os_str())],
    );
    let said = text(&run.stdout);
    assert!(run.status.success(), "{}", text(&run.stderr));
    assert!(
        said.contains("3000 unit(s) in 3000 task(s) of at most 1 unit(s) ([slurm] units_per_task), 3 array(s) of at most 1001 task(s) (the cluster's MaxArraySize (scontrol show config))"),
        "{}",
        &said[..said.len().min(2000)]
    );
    // Indices 0 to 1000 (below 1001), twice, then the 998 left; each unit once, in order.
    let arrays: Vec<&str> = said
        .lines()
        .filter_map(|l| l.strip_prefix("#SBATCH --array="))
        .collect();
    assert_eq!(arrays, ["0-1000%100", "0-1000%100", "0-997%100"]);
    let units: Vec<usize> = said
        .lines()
        .filter_map(|l| l.trim().split_once(") units=\""))
        .map(|(_, u)| u.trim_end_matches("\" ;;").parse().unwrap())
        .collect();
    assert_eq!(units, (1..=3000).collect::<Vec<_>>());
    assert!(
        said.contains("--dependency=afterany:<units job 1 id>:<units job 2 id>:<units job 3 id> ")
    );
}

#[test]
fn a_running_task_killed_by_the_scheduler_is_named_with_slurm_s_reason() {
    let Some(conf) = slurm() else { return };
    let tmp = tempfile::tempdir().unwrap();
    let file = small_campaign(&tmp.path().join("campaign"), false);
    // The three units in one task, one after another: a few seconds at least.
    with_slurm_settings(&file, "units_per_task = 3\n");
    let out = tmp.path().join("out");
    let env = [("SLURM_CONF", conf.as_os_str())];
    let flags = ["--slurm", "--time", "00:10:00", "--mem", "500M"];
    let (_, units, collect) = submitted(&campaign(&file, &out, &flags, &env));
    // The task writes unit 1's log as it starts the unit: then it is running, with three
    // units (each a process of its own) ahead of it.
    let started = Instant::now();
    while !out.join("slurm/unit-1.log").exists() {
        assert!(
            started.elapsed() < common::slurm::JOB_TIMEOUT,
            "the task never started:\n{}",
            logs(&out, &conf)
        );
        std::thread::sleep(Duration::from_millis(20));
    }
    scancel(&format!("{}_0", units[0]), &conf);
    let log = collected(&collect, &out, &conf, "FAILED");
    assert!(
        log.contains("it did not finish: no unit.json in")
            && log.contains("Slurm stopped its task: \"JOB ")
            && log.contains(" CANCELLED AT "),
        "{log}"
    );
    let finished = unit_stamps(&out);
    assert!(finished.len() < 3, "{finished:?}");

    // Submitted again: the units the kill stopped run; a unit that had finished stays as it was.
    let (said, _, collect) = submitted(&campaign(&file, &out, &flags, &env));
    assert!(
        said.contains(&format!("{} unit(s) in 1 task(s)", 3 - finished.len())),
        "{said}"
    );
    collected(&collect, &out, &conf, "COMPLETED");
    let now = unit_stamps(&out);
    assert_eq!(now.len(), 3, "{now:?}");
    for stamp in &finished {
        assert!(now.contains(stamp), "{stamp:?} was rewritten: {now:?}");
    }
}
