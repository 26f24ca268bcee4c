//! The single-node Slurm of `tests/slurm/start.sh` for the campaign tests: bring it up once
//! per test binary (or say why this machine cannot), wait for jobs with a time limit, and
//! gather the jobs' and daemons' logs for a failure's message.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::sync::OnceLock;
use std::time::{Duration, Instant};

use super::root;

/// The folder of the test cluster's files (`tests/slurm/start.sh`'s default).
pub const SLURM_DIR: &str = "/tmp/stf-lab-slurm";

/// The longest wait for a submitted campaign's collect job to end.
pub const JOB_TIMEOUT: Duration = Duration::from_secs(600);

pub fn text(bytes: &[u8]) -> String {
    String::from_utf8_lossy(bytes).into_owned()
}

/// Whether `name` is an executable file in a folder of PATH.
pub fn on_path(name: &str) -> bool {
    std::env::var_os("PATH")
        .is_some_and(|p| std::env::split_paths(&p).any(|d| d.join(name).is_file()))
}

/// The test cluster's `SLURM_CONF`, Slurm brought up once for this test binary; `None` (the
/// test is skipped) when this machine cannot run it, unless `STF_LAB_REQUIRE_SLURM=1`.
pub fn slurm() -> Option<PathBuf> {
    static STARTED: OnceLock<Result<PathBuf, String>> = OnceLock::new();
    let started = STARTED.get_or_init(|| {
        let missing: Vec<&str> = ["sbatch", "squeue", "slurmctld", "slurmd", "munged"]
            .into_iter()
            .filter(|n| !on_path(n))
            .collect();
        if !missing.is_empty() {
            return Err(format!(
                "not on PATH: {} (apt-get install -y slurm-wlm munge)",
                missing.join(", ")
            ));
        }
        let uid = Command::new("id")
            .arg("-u")
            .output()
            .map(|o| text(&o.stdout));
        if uid.ok().as_deref().map(str::trim) != Some("0") {
            return Err("tests/slurm/start.sh runs slurmd, which needs root".into());
        }
        let start = Command::new(root().join("tests/slurm/start.sh"))
            .env("STF_LAB_SLURM_DIR", SLURM_DIR)
            .output()
            .unwrap();
        assert!(
            start.status.success(),
            "tests/slurm/start.sh failed:\n{}{}",
            text(&start.stdout),
            text(&start.stderr)
        );
        println!("{}", text(&start.stdout).trim());
        Ok(Path::new(SLURM_DIR).join("slurm.conf"))
    });
    match started {
        Ok(conf) => Some(conf.clone()),
        Err(why) if std::env::var("STF_LAB_REQUIRE_SLURM").as_deref() == Ok("1") => {
            panic!("STF_LAB_REQUIRE_SLURM=1 but Slurm cannot run here: {why}")
        }
        Err(why) => {
            println!("skipped: no single-node Slurm on this machine: {why}");
            None
        }
    }
}

/// The job ids `--slurm` printed: (units jobs, one per array; collect job).
pub fn job_ids(stdout: &str) -> (Vec<String>, String) {
    let first_word = |l: &str| l.split_whitespace().next().unwrap().to_string();
    let units: Vec<String> = stdout
        .lines()
        .filter_map(|l| l.strip_prefix("units job: "))
        .map(first_word)
        .collect();
    assert!(!units.is_empty(), "no \"units job: \" line in:\n{stdout}");
    let collect = stdout
        .lines()
        .find_map(|l| l.strip_prefix("collect job: "))
        .unwrap_or_else(|| panic!("no \"collect job: \" line in:\n{stdout}"));
    (units, first_word(collect))
}

/// What a submitting run printed, asserting it succeeded, with its job ids ([`job_ids`]):
/// `(stdout, units jobs, collect job)`.
pub fn submitted(run: &std::process::Output) -> (String, Vec<String>, String) {
    let said = text(&run.stdout);
    assert!(run.status.success(), "{said}{}", text(&run.stderr));
    let (units, collect) = job_ids(&said);
    (said, units, collect)
}

/// Wait for the collect job `collect` of the campaign in `out` to end in `state` (the logs
/// if it does not); the collect job's log (empty if it wrote none).
pub fn collected(collect: &str, out: &Path, conf: &Path, state: &str) -> String {
    assert_eq!(wait_for(collect, out, conf), state, "{}", logs(out, conf));
    std::fs::read_to_string(out.join("slurm/collect.log")).unwrap_or_default()
}

/// Cancel the Slurm job or array task `id` (`123_2`), as the scheduler would.
pub fn scancel(id: &str, conf: &Path) {
    let cancel = Command::new("scancel")
        .arg(id)
        .env("SLURM_CONF", conf)
        .output()
        .unwrap();
    assert!(cancel.status.success(), "{}", text(&cancel.stderr));
}

/// What a campaign's Slurm jobs and the test cluster logged, for a failure's message.
pub fn logs(out: &Path, conf: &Path) -> String {
    let mut said = String::new();
    let squeue = Command::new("squeue")
        .args(["--states=all", "-o", "%i %j %T %r"])
        .env("SLURM_CONF", conf)
        .output();
    if let Ok(o) = squeue {
        said.push_str(&format!(
            "---- squeue\n{}{}",
            text(&o.stdout),
            text(&o.stderr)
        ));
    }
    let mut files: Vec<PathBuf> = std::fs::read_dir(out.join("slurm"))
        .map(|d| d.filter_map(|e| e.ok()).map(|e| e.path()).collect())
        .unwrap_or_default();
    files.sort();
    files.push(Path::new(SLURM_DIR).join("slurmctld.log"));
    files.push(Path::new(SLURM_DIR).join("slurmd.log"));
    for f in files
        .iter()
        .filter(|f| f.extension().is_some_and(|e| e == "log"))
    {
        let body = std::fs::read_to_string(f).unwrap_or_default();
        let tail: Vec<&str> = body.lines().rev().take(30).collect();
        let tail: Vec<&str> = tail.into_iter().rev().collect();
        said.push_str(&format!("---- {}\n{}\n", f.display(), tail.join("\n")));
    }
    said
}

/// Wait until job `id` (each task of an array) has ended; its final states, distinct and
/// sorted (`COMPLETED`, `FAILED`, …, joined by `,`). Panics with the logs after
/// [`JOB_TIMEOUT`].
pub fn wait_for(id: &str, out: &Path, conf: &Path) -> String {
    wait_up_to(id, out, conf, JOB_TIMEOUT)
}

/// [`wait_for`] with a time limit of `limit`.
pub fn wait_up_to(id: &str, out: &Path, conf: &Path, limit: Duration) -> String {
    let started = Instant::now();
    let ended = [
        "COMPLETED",
        "FAILED",
        "CANCELLED",
        "TIMEOUT",
        "NODE_FAIL",
        "OUT_OF_MEMORY",
        "BOOT_FAIL",
        "DEADLINE",
        "PREEMPTED",
    ];
    loop {
        let o = Command::new("squeue")
            .args(["-h", "--states=all", "-j", id, "-o", "%T"])
            .env("SLURM_CONF", conf)
            .output()
            .unwrap();
        let said = text(&o.stdout);
        let mut states: Vec<&str> = said.split_whitespace().collect();
        states.sort();
        states.dedup();
        if !states.is_empty()
            && states
                .iter()
                .all(|s| ended.iter().any(|e| s.starts_with(e)))
        {
            return states.join(",");
        }
        assert!(
            started.elapsed() < limit,
            "job {id} has not ended after {limit:?} (states {states:?}):\n{}",
            logs(out, conf)
        );
        std::thread::sleep(Duration::from_millis(500));
    }
}
