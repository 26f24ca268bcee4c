//! Inputs a careless or hostile user gives where a file belongs — a folder, a FIFO, a device —
//! and limits raised past what the machine can hold: each is named as what it is, at once,
//! with exit status 1 (never a hang, an abort or "no such record").

mod common;

use std::path::{Path, PathBuf};
use std::process::{Child, Command, Output, Stdio};
use std::time::{Duration, Instant};

use common::{root, stf_lab};

/// The output of `cmd`, which must end by itself: a run still going after a minute is a hang
/// (a FIFO opened for reading waits for a writer forever), killed and reported.
fn ends(mut cmd: Command) -> Output {
    let mut child: Child = cmd
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let start = Instant::now();
    while child.try_wait().unwrap().is_none() {
        if start.elapsed() > Duration::from_secs(60) {
            child.kill().unwrap();
            panic!("hung: {cmd:?}");
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    child.wait_with_output().unwrap()
}

fn fifo(dir: &Path, name: &str) -> PathBuf {
    let path = dir.join(name);
    assert!(Command::new("mkfifo")
        .arg(&path)
        .status()
        .unwrap()
        .success());
    path
}

/// `stf-lab ARGS…`: its failure message, exit status 1.
fn fails(args: &[&std::ffi::OsStr]) -> String {
    let mut cmd = stf_lab();
    cmd.args(args);
    let out = ends(cmd);
    assert_eq!(out.status.code(), Some(1), "{out:?}");
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn experiment(dir: &Path, text: &str) -> PathBuf {
    let path = dir.join("exp.toml");
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn a_folder_fifo_or_device_as_the_record_is_named_as_such() {
    let dir = tempfile::tempdir().unwrap();
    let pipe = fifo(dir.path(), "rec.csv");
    let folder = dir.path().join("folder.csv");
    std::fs::create_dir(&folder).unwrap();
    for (record, what) in [
        (Path::new("/dev/zero"), "is a device, not a record file"),
        (pipe.as_path(), "is a FIFO (named pipe), not a record file"),
        (folder.as_path(), "is a folder, not a record file"),
    ] {
        let exp = experiment(
            dir.path(),
            &format!(
                "[data]\nfile = {:?}\n\n[[models]]\nname = \"viscous\"\n",
                record.display().to_string()
            ),
        );
        let out = dir.path().join("out");
        let msg = fails(&[
            "fit".as_ref(),
            exp.as_os_str(),
            "--out".as_ref(),
            out.as_os_str(),
        ]);
        assert!(
            msg.contains("exp.toml:1: `data.file`: ") && msg.contains(what),
            "{record:?}: {msg}"
        );
        assert!(!out.exists());
    }
}

#[test]
fn a_fifo_as_the_experiment_or_the_script_fails_at_once() {
    let dir = tempfile::tempdir().unwrap();
    let pipe = fifo(dir.path(), "exp.toml");
    let out = dir.path().join("out");
    let msg = fails(&[
        "fit".as_ref(),
        pipe.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    assert!(msg.contains("FIFO (named pipe)"), "{msg}");
    let script = fifo(dir.path(), "model.rhai");
    let msg = fails(&["models".as_ref(), "--check".as_ref(), script.as_os_str()]);
    assert!(
        msg.contains("model.rhai") && msg.contains("FIFO (named pipe)"),
        "{msg}"
    );
    let record = root().join("experiments/records/power_law_sweep.csv");
    let exp = dir.path().join("with_script.toml");
    std::fs::write(
        &exp,
        format!(
            "[data]\nfile = {:?}\n\n[[models]]\nscript = \"model.rhai\"\n",
            record.display().to_string()
        ),
    )
    .unwrap();
    let msg = fails(&[
        "fit".as_ref(),
        exp.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    assert!(
        msg.contains("model.rhai") && msg.contains("FIFO (named pipe)"),
        "{msg}"
    );
}

#[test]
fn a_sample_limit_raised_past_memory_is_refused_at_its_key_not_aborted() {
    // The run: 10¹³ samples; it aborted (status 134) allocating 80 TB.
    let dir = tempfile::tempdir().unwrap();
    let exp = experiment(
        dir.path(),
        "[simulate]\nconstant = { omega = 8.2, t1 = 1e4 }\nrate = 1e9\nmax_samples = 1e18\n",
    );
    let rec = dir.path().join("rec.csv");
    let msg = fails(&[
        "simulate".as_ref(),
        exp.as_os_str(),
        "--out".as_ref(),
        rec.as_os_str(),
    ]);
    assert!(
        msg.contains("exp.toml:4: `simulate.max_samples`: ")
            && msg.contains("1.00e13 samples, which needs about")
            && msg.contains("of memory this machine has available"),
        "{msg}"
    );
    assert!(!rec.exists());
}

#[test]
fn a_window_of_three_values_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let record = root().join("experiments/records/power_law_sweep.csv");
    let exp = experiment(
        dir.path(),
        &format!(
            "[data]\nfile = {:?}\nwindow = [0.0, 1.0, 2.0]\n\n[[models]]\nname = \"viscous\"\n",
            record.display().to_string()
        ),
    );
    let out = dir.path().join("out");
    let msg = fails(&[
        "fit".as_ref(),
        exp.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ]);
    assert!(
        msg.contains("exp.toml:3: `data.window`: give two times"),
        "{msg}"
    );
}

/// `[data] file` = the bundled power-law sweep, then `rest`.
fn on_the_sweep(dir: &Path, rest: &str) -> PathBuf {
    let record = root().join("experiments/records/power_law_sweep.csv");
    experiment(
        dir,
        &format!("[data]\nfile = {:?}\n{rest}", record.display().to_string()),
    )
}

/// `stf-lab COMMAND EXP --out DIR/out`: its failure message.
fn fails_on(command: &str, exp: &Path) -> String {
    let out = exp.parent().unwrap().join("out");
    fails(&[
        command.as_ref(),
        exp.as_os_str(),
        "--out".as_ref(),
        out.as_os_str(),
    ])
}

#[test]
fn a_window_beyond_the_record_is_shown_with_short_numbers_and_the_record_s_times() {
    // It printed 1e300 as a number of 301 digits.
    let dir = tempfile::tempdir().unwrap();
    let exp = on_the_sweep(
        dir.path(),
        "window = [1e300, 1e301]\n\n[[models]]\nname = \"viscous\"\n",
    );
    let msg = fails_on("fit", &exp);
    assert!(
        msg.contains("exp.toml:1: `data.window` [1e300, 1e301] keeps 0 samples of")
            && msg.contains("whose times run from 0 to 60 s"),
        "{msg}"
    );
    assert!(!msg.contains("0000000000"), "{msg}");
}

#[test]
fn a_holdout_longer_than_the_record_names_its_key() {
    // It said "bad discovery data: 56 whole cycles hold out none at one in 1000000000".
    let dir = tempfile::tempdir().unwrap();
    let exp = on_the_sweep(
        dir.path(),
        "\n[discover]\nbase = \"viscous\"\ncandidates = [\"power_law\"]\nholdout_every = 1e9\n",
    );
    let msg = fails_on("discover", &exp);
    assert!(
        msg.contains("exp.toml:4: `discover.holdout_every`: holdout_every = 1000000000 holds out none of the record's")
            && msg.contains("give holdout_every at most"),
        "{msg}"
    );
    assert!(!msg.contains("bad discovery data"), "{msg}");
}

#[test]
fn a_script_that_is_a_folder_or_not_a_rhai_file_is_named_as_such() {
    // Both said "unknown model `dir.csv`; built-in models: …".
    let dir = tempfile::tempdir().unwrap();
    std::fs::create_dir(dir.path().join("dir.csv")).unwrap();
    std::fs::write(dir.path().join("notes.toml"), "x = 1\n").unwrap();
    for (script, says) in [
        ("dir.csv", "dir.csv: is a folder, not a script"),
        (
            "notes.toml",
            "notes.toml: is not a rhai script (its name does not end in .rhai)",
        ),
        (
            "nowhere.txt",
            "nowhere.txt: no such file, and not a rhai script's name",
        ),
    ] {
        let exp = on_the_sweep(
            dir.path(),
            &format!("\n[[models]]\nscript = \"{script}\"\n"),
        );
        let msg = fails_on("fit", &exp);
        assert!(
            msg.contains("exp.toml:4: `models[0]`: ") && msg.contains(says),
            "{script}: {msg}"
        );
        assert!(!msg.contains("unknown model"), "{msg}");
    }
}
