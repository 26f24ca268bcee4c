//! Output safety end to end: special files and colliding outputs are refused, an output folder
//! is replaced as a whole and locked for its run, what a killed run left is repaired, text from
//! files never reaches the terminal raw nor report.md as HTML, and a closed pipe ends printing
//! quietly.

mod common;

use std::os::unix::fs::FileTypeExt;
use std::path::{Path, PathBuf};
use std::process::{Output, Stdio};

use common::{root, stf_lab};

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn mkfifo(path: &Path) {
    let made = std::process::Command::new("mkfifo")
        .arg(path)
        .status()
        .unwrap();
    assert!(made.success(), "mkfifo {}", path.display());
}

/// A one-model fit experiment on the bundled power-law record, with or without its report.
fn fit_experiment(dir: &Path, name: &str, report: bool) -> PathBuf {
    let record = root().join("experiments/records/power_law_sweep.csv");
    let exp = dir.join(name);
    std::fs::write(
        &exp,
        format!(
            "[data]\nfile = {:?}\n\n[output]\nreport = {report}\n\n[[models]]\nname = \"viscous\"\n",
            record.display().to_string()
        ),
    )
    .unwrap();
    exp
}

fn fit(exp: &Path, out: &Path, force: bool) -> Output {
    let mut c = stf_lab();
    c.args(["fit", "-q", "-o"]).arg(out).arg(exp);
    if force {
        c.arg("-f");
    }
    c.output().unwrap()
}

/// The entries of `dir`, sorted.
fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

#[test]
fn a_fifo_or_a_link_to_one_is_never_replaced_by_an_output() {
    let tmp = tempfile::tempdir().unwrap();
    let fifo = tmp.path().join("pipe");
    mkfifo(&fifo);
    let link = tmp.path().join("link.csv");
    std::os::unix::fs::symlink(&fifo, &link).unwrap();
    for out in [&fifo, &link] {
        let run = stf_lab()
            .args(["simulate", "--force", "--out"])
            .arg(out)
            .arg(root().join("experiments/paper_sweep.toml"))
            .output()
            .unwrap();
        assert!(!run.status.success());
        assert!(
            stderr(&run).contains("is not a regular file"),
            "{}",
            stderr(&run)
        );
    }
    let exp = fit_experiment(tmp.path(), "exp.toml", false);
    let run = fit(&exp, &fifo, true);
    assert!(!run.status.success());
    assert!(stderr(&run).contains("is not a folder"), "{}", stderr(&run));
    assert!(std::fs::metadata(&fifo).unwrap().file_type().is_fifo());
    assert!(std::fs::symlink_metadata(&link)
        .unwrap()
        .file_type()
        .is_symlink());
    assert_eq!(entries(tmp.path()), ["exp.toml", "link.csv", "pipe"]);
}

#[test]
fn a_record_that_would_be_its_own_sidecar_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("rec.json");
    let run = stf_lab()
        .args(["simulate", "--out"])
        .arg(&out)
        .arg(root().join("experiments/paper_sweep.toml"))
        .output()
        .unwrap();
    assert!(!run.status.success());
    assert!(
        stderr(&run).contains("which is the record itself"),
        "{}",
        stderr(&run)
    );
    assert!(!out.exists());
}

#[test]
fn a_forced_rerun_replaces_the_whole_folder_and_says_only_what_it_wrote() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("fit");
    let with_report = fit_experiment(tmp.path(), "a.toml", true);
    let first = fit(&with_report, &out, false);
    assert!(first.status.success(), "{}", stderr(&first));
    assert!(out.join("report.html").exists() && out.join("figures").is_dir());

    let without = fit_experiment(tmp.path(), "b.toml", false);
    let again = fit(&without, &out, true);
    assert!(again.status.success(), "{}", stderr(&again));
    assert_eq!(entries(&out), ["fit.json", "fitted.csv", "params.csv"]);
    let wrote = stdout(&again);
    let wrote = wrote.lines().last().unwrap();
    assert!(
        wrote.starts_with("wrote ") && !wrote.contains("report"),
        "{wrote}"
    );
    let doc = common::read_json(&out.join("fit.json"));
    assert!(doc["experiment"].as_str().unwrap().ends_with("b.toml"));
    // Nothing is left beside the folder, not even its lock file.
    assert_eq!(entries(tmp.path()), ["a.toml", "b.toml", "fit"]);
}

#[test]
fn a_folder_being_written_by_another_run_is_refused() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("fit");
    let exp = fit_experiment(tmp.path(), "exp.toml", false);
    assert!(fit(&exp, &out, false).status.success());
    let before = std::fs::read(out.join("fit.json")).unwrap();
    let held = stf_lab::writing::lock::OutputLock::acquire(&out).unwrap();
    let second = fit(&exp, &out, true);
    assert!(!second.status.success());
    let msg = stderr(&second);
    assert!(
        msg.contains("is being written by another stf-lab run")
            && msg.contains(&format!("process {}", std::process::id())),
        "{msg}"
    );
    assert_eq!(std::fs::read(out.join("fit.json")).unwrap(), before);
    drop(held);
    assert!(fit(&exp, &out, true).status.success());
}

#[test]
fn what_a_killed_run_left_is_repaired_and_strangers_are_kept() {
    let tmp = tempfile::tempdir().unwrap();
    let out = tmp.path().join("fit");
    let exp = fit_experiment(tmp.path(), "exp.toml", false);
    // Killed between the swap's renames: the folder is aside, the new one half built.
    let old = tmp.path().join(".fit.old-999999");
    std::fs::create_dir(&old).unwrap();
    std::fs::write(old.join("fit.json"), "{\"old\": true}").unwrap();
    let half = tmp.path().join(".fit.new-999999");
    std::fs::create_dir(&half).unwrap();
    std::fs::write(half.join("fit.json"), "{").unwrap();
    let run = fit(&exp, &out, false);
    let msg = stderr(&run);
    assert!(msg.contains("the previous results were put back"), "{msg}");
    assert!(
        msg.contains("removed") && msg.contains(".fit.new-999999"),
        "{msg}"
    );
    // Put back, the old results are there to be replaced only with --force.
    assert!(
        !run.status.success() && msg.contains("pass --force"),
        "{msg}"
    );
    assert_eq!(
        std::fs::read_to_string(out.join("fit.json")).unwrap(),
        "{\"old\": true}"
    );
    assert_eq!(entries(tmp.path()), ["exp.toml", "fit"]);

    // A stray temporary of an older version's killed write does not count as results.
    std::fs::remove_file(out.join("fit.json")).unwrap();
    std::fs::write(out.join(".fitted.4242-0.tmp.csv"), "t,f").unwrap();
    let run = fit(&exp, &out, false);
    assert!(run.status.success(), "{}", stderr(&run));
    assert_eq!(entries(&out), ["fit.json", "fitted.csv", "params.csv"]);

    // A file stf-lab does not write is never swept away with the old results.
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    let run = fit(&exp, &out, true);
    assert!(!run.status.success());
    assert!(stderr(&run).contains("holds notes.txt"), "{}", stderr(&run));
    assert!(out.join("notes.txt").exists());
}

#[test]
fn control_characters_from_files_reach_the_terminal_escaped() {
    let tmp = tempfile::tempdir().unwrap();
    let record = tmp.path().join("rec\u{1b}]0;pwned\u{7}.csv");
    std::fs::write(&record, "t,phi,x,f_stf\n0,0,0,0\n0.01,0,\u{1b}[2Jboom,0\n").unwrap();
    let exp = tmp.path().join("exp.toml");
    // The name as a TOML basic string, its control characters as TOML escapes.
    let name = "rec\\u001B]0;pwned\\u0007.csv";
    std::fs::write(
        &exp,
        format!("[data]\nfile = \"{name}\"\n\n[[models]]\nname = \"viscous\"\n"),
    )
    .unwrap();
    let run = fit(&exp, &tmp.path().join("fit"), false);
    assert!(!run.status.success());
    let msg = stderr(&run);
    assert!(
        !run.stderr.contains(&0x1b) && !run.stderr.contains(&0x07),
        "{msg:?}"
    );
    assert!(msg.contains("rec\\u{1b}]0;pwned\\u{7}.csv"), "{msg}");
    assert!(msg.contains("not a number: `\\u{1b}[2Jboom`"), "{msg}");
}

#[test]
fn report_md_escapes_html_from_file_names() {
    let tmp = tempfile::tempdir().unwrap();
    let exp = fit_experiment(tmp.path(), "<img src=x onerror=alert(1)>.toml", true);
    let out = tmp.path().join("fit");
    let run = fit(&exp, &out, false);
    assert!(run.status.success(), "{}", stderr(&run));
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(!md.contains("<img"), "{md}");
    assert!(
        md.contains("&lt;img src=x onerror=alert(1)&gt;.toml"),
        "{md}"
    );
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    assert!(!html.contains("<img src=x"));
}

#[test]
fn a_closed_pipe_ends_the_listing_quietly() {
    let mut child = stf_lab()
        .arg("models")
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    // Close the reading end before the program writes: its first line meets a closed pipe.
    drop(child.stdout.take());
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", stderr(&out));
    assert!(out.stderr.is_empty(), "{}", stderr(&out));
}

#[test]
fn every_command_takes_quiet_and_the_short_flags() {
    let tmp = tempfile::tempdir().unwrap();
    let rec = tmp.path().join("rec.csv");
    let sim = |extra: &[&str]| {
        stf_lab()
            .arg("simulate")
            .args(extra)
            .arg(root().join("experiments/paper_sweep.toml"))
            .arg("-o")
            .arg(&rec)
            .output()
            .unwrap()
    };
    let first = sim(&["--quiet"]);
    assert!(first.status.success(), "{}", stderr(&first));
    assert!(!sim(&["-q"]).status.success(), "no -f: refused");
    let forced = sim(&["-q", "-f"]);
    assert!(forced.status.success(), "{}", stderr(&forced));
    let models = stf_lab().args(["models", "--quiet"]).output().unwrap();
    assert!(models.status.success(), "{}", stderr(&models));
    let global = stf_lab().args(["-q", "models"]).output().unwrap();
    assert!(global.status.success(), "{}", stderr(&global));
}

#[test]
fn script_text_in_the_model_list_reaches_the_terminal_escaped() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(
        tmp.path().join("evil.rhai"),
        "//! Evil \u{1b}[31mred\u{1b}[0m model.\nfn params() {\n    #{\n        \
         /// doc \u{1b}]0;title\u{7} here\n        K: [5.0, 0.0, 1e3, \"N\u{1b}[2J\"],\n    }\n}\n\
         fn force(p, t, x, v, z) { p.K * v }\n",
    )
    .unwrap();
    let run = stf_lab()
        .args(["models", "--scripts"])
        .arg(tmp.path())
        .output()
        .unwrap();
    assert!(run.status.success(), "{}", stderr(&run));
    let text = stdout(&run);
    assert!(
        !run.stdout.contains(&0x1b) && !run.stdout.contains(&0x07),
        "{text:?}"
    );
    assert!(
        text.contains("Evil \\u{1b}[31mred\\u{1b}[0m model."),
        "{text}"
    );
    assert!(text.contains("doc \\u{1b}]0;title\\u{7} here"), "{text}");
}

/// `stf-lab fit -q -f -o OUT EXP` with `STF_LAB_FAILPOINT` set to `failpoint`.
fn fit_with_failpoint(exp: &Path, out: &Path, failpoint: &str) -> Output {
    stf_lab()
        .args(["fit", "-q", "-f", "-o"])
        .arg(out)
        .arg(exp)
        .env("STF_LAB_FAILPOINT", failpoint)
        .output()
        .unwrap()
}

#[test]
fn force_keeps_and_names_user_files_one_level_down() {
    let tmp = tempfile::tempdir().unwrap();
    let exp = fit_experiment(tmp.path(), "exp.toml", true);
    // Results with figures, and a user's files among the figures.
    let s2 = tmp.path().join("S2");
    assert!(fit(&exp, &s2, false).status.success());
    let before = std::fs::read(s2.join("fit.json")).unwrap();
    std::fs::write(s2.join("figures/mynotes.txt"), "notes").unwrap();
    std::fs::create_dir(s2.join("figures/sub")).unwrap();
    std::fs::write(s2.join("figures/sub/data.bin"), "x").unwrap();
    // A folder holding only a draft among figures, and one whose folder is named like a result.
    let draft = tmp.path().join("draft");
    std::fs::create_dir_all(draft.join("figures")).unwrap();
    std::fs::write(draft.join("figures/paper_draft.docx"), "draft").unwrap();
    let thesis = tmp.path().join("thesis");
    std::fs::create_dir_all(thesis.join("fit.json")).unwrap();
    std::fs::write(thesis.join("fit.json/thesis.tex"), "tex").unwrap();
    for (out, kept) in [
        (&s2, vec!["figures/mynotes.txt", "figures/sub/data.bin"]),
        (&draft, vec!["figures/paper_draft.docx"]),
        (&thesis, vec!["fit.json/thesis.tex"]),
    ] {
        let run = fit(&exp, out, true);
        assert!(!run.status.success(), "{}", out.display());
        let msg = stderr(&run);
        for file in kept {
            assert!(msg.contains(file), "{file} not named: {msg}");
            assert!(out.join(file).is_file(), "{file} was lost");
        }
        assert!(msg.contains("which stf-lab does not write"), "{msg}");
    }
    assert_eq!(std::fs::read(s2.join("fit.json")).unwrap(), before);
    // Nothing is left beside the folders: no staging, no lock file.
    assert_eq!(entries(tmp.path()), ["S2", "draft", "exp.toml", "thesis"]);
}

#[test]
fn lock_files_never_stay_beside_or_above_the_output() {
    let tmp = tempfile::tempdir().unwrap();
    let exp = fit_experiment(tmp.path(), "exp.toml", true);
    let pl = tmp.path().join("pl");
    assert!(fit(&exp, &pl, false).status.success());
    // A refused run into a folder inside the results leaves no lock file in them …
    let refused = fit(&exp, &pl.join("figures"), false);
    assert!(!refused.status.success());
    assert!(!pl.join(".figures.lock").exists(), "{:?}", entries(&pl));
    // … so a forced rerun into the results is not refused for holding one.
    let again = fit(&exp, &pl, true);
    assert!(again.status.success(), "{}", stderr(&again));
    // A refused `--out DIR --force` (DIR holds a stranger, as /tmp does) leaves nothing
    // beside DIR, in the folder above it.
    let busy = tmp.path().join("busy");
    std::fs::create_dir(&busy).unwrap();
    std::fs::write(busy.join("other.txt"), "x").unwrap();
    let refused = fit(&exp, &busy, true);
    assert!(
        stderr(&refused).contains("holds other.txt"),
        "{}",
        stderr(&refused)
    );
    assert_eq!(entries(tmp.path()), ["busy", "exp.toml", "pl"]);
}

/// A short simulation experiment of `seconds` seconds at 100 samples a second.
fn short_simulation(dir: &Path, name: &str, seconds: f64) -> PathBuf {
    let exp = dir.join(name);
    std::fs::write(
        &exp,
        format!(
            "[system]\npreset = \"forced\"\n\n[simulate]\nconstant = {{ omega = 6.0, t1 = {seconds} }}\n\
             rate = 100.0\nnoise = false\n"
        ),
    )
    .unwrap();
    exp
}

/// The record's data rows and the sample count its sidecar states.
fn rows_and_sidecar_samples(record: &Path) -> (usize, u64) {
    let rows = std::fs::read_to_string(record).unwrap().lines().count() - 1;
    let sidecar = common::read_json(&record.with_extension("json"));
    (rows, sidecar["summary"]["samples"].as_u64().unwrap())
}

#[test]
fn a_record_and_its_sidecar_from_a_killed_commit_are_put_right_by_the_next_run() {
    let tmp = tempfile::tempdir().unwrap();
    let short = short_simulation(tmp.path(), "short.toml", 1.0);
    let long = short_simulation(tmp.path(), "long.toml", 2.0);
    let rec = tmp.path().join("sw.csv");
    common::simulate_ok(&short, &rec);
    // Killed between the two renames of the commit: the new record is in place, the
    // sidecar not yet.
    let killed = stf_lab()
        .args(["simulate", "--force", "--out"])
        .arg(&rec)
        .arg(&long)
        .env("STF_LAB_FAILPOINT", "commit:sw.csv=kill")
        .output()
        .unwrap();
    assert_eq!(
        std::os::unix::process::ExitStatusExt::signal(&killed.status),
        Some(9),
        "{}",
        stderr(&killed)
    );
    // The next run into the same record notices and finishes the commit before anything else
    // (here it then refuses to replace the record without --force).
    let next = common::simulate(&long, &rec, &[]);
    let msg = stderr(&next);
    assert!(
        msg.contains("was stopped while putting its files in place") && msg.contains("sw.json"),
        "{msg}"
    );
    assert!(msg.contains("pass --force"), "{msg}");
    let (rows, samples) = rows_and_sidecar_samples(&rec);
    assert_eq!(rows as u64, samples, "record and sidecar are from one run");
    assert_eq!(rows, 201);
    assert_eq!(
        entries(tmp.path()),
        ["long.toml", "short.toml", "sw.csv", "sw.json"]
    );
}

#[test]
fn records_that_share_a_sidecar_are_not_written_at_once() {
    let tmp = tempfile::tempdir().unwrap();
    let exp = short_simulation(tmp.path(), "exp.toml", 1.0);
    // Another run writing `q.csv` holds its sidecar `q.json`: `--out q.CSV` (a different record
    // on a case-sensitive disk, the same sidecar) must wait its turn.
    let held = stf_lab::writing::lock::OutputLock::acquire(&tmp.path().join("q.json")).unwrap();
    let run = common::simulate(&exp, &tmp.path().join("q.CSV"), &[]);
    assert!(!run.status.success());
    let msg = stderr(&run);
    assert!(
        msg.contains("q.json is being written by another stf-lab run"),
        "{msg}"
    );
    assert!(!tmp.path().join("q.CSV").exists() && !tmp.path().join("q.json").exists());
    drop(held);
    common::simulate_ok(&exp, &tmp.path().join("q.CSV"));
    assert_eq!(entries(tmp.path()), ["exp.toml", "q.CSV", "q.json"]);
}

#[test]
fn output_lost_to_a_full_disk_is_a_failure() {
    let Ok(full) = std::fs::OpenOptions::new().write(true).open("/dev/full") else {
        return; // no /dev/full here
    };
    let run = stf_lab()
        .arg("models")
        .stdout(Stdio::from(full))
        .output()
        .unwrap();
    assert!(!run.status.success(), "exit 0 with the listing lost");
    assert!(
        stderr(&run).contains("cannot write to standard output"),
        "{}",
        stderr(&run)
    );
}

#[test]
fn ctrl_c_while_report_md_is_written_leaves_no_staging_folder() {
    let tmp = tempfile::tempdir().unwrap();
    let exp = fit_experiment(tmp.path(), "exp.toml", true);
    let out = tmp.path().join("fit");
    assert!(fit(&exp, &out, false).status.success());
    let before = std::fs::read(out.join("fit.json")).unwrap();
    // Ctrl-C arrives as report.md starts being written; the write goes on meanwhile.
    let run = fit_with_failpoint(&exp, &out, "write:report.md=int");
    assert_eq!(run.status.code(), Some(130), "{}", stderr(&run));
    assert!(
        stderr(&run).contains("no results were written"),
        "{}",
        stderr(&run)
    );
    assert_eq!(std::fs::read(out.join("fit.json")).unwrap(), before);
    assert_eq!(entries(tmp.path()), ["exp.toml", "fit"]);
}
