//! The Python package (`python/`): built once by maturin into an abi3 wheel, installed into a
//! fresh folder (`pip install --target`), and its pytest suite run — records, models, every workflow on
//! the bundled examples, errors, notebook display, interrupt, the parity of its numbers with
//! this program's JSON, and `examples/python_walkthrough.py`.
//!
//! It needs `python3` (3.9 or later; or the Python `STF_LAB_PYTHON` names) able to import pip,
//! maturin, pytest, numpy and pandas. `.ci/run` installs them and sets `STF_LAB_REQUIRE_PYTHON=1`, so in CI a missing
//! piece fails the test; elsewhere, without them, the test is skipped and says so on the
//! terminal, so the README's test command passes on a fresh machine.
//!
//! The wheel is built with its own cargo target folder (`target/python-package/cargo`: the
//! running `cargo test` holds the workspace's), unless `STF_LAB_PYTHON_WHEELS` names a folder
//! holding one already built (`.ci/run` builds it before the tests, in the workspace's target
//! folder, so CI compiles the workspace once).

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const NEEDS: &str =
    "import sys, pip, maturin, pytest, numpy, pandas; assert sys.version_info >= (3, 9)";

fn repo() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// What is missing for the Python package's tests, if anything.
fn missing(python: &str) -> Option<String> {
    match Command::new(python).args(["-c", NEEDS]).output() {
        Err(e) => Some(format!("`{python}` cannot be run ({e})")),
        Ok(o) if !o.status.success() => Some(format!(
            "`{python}` lacks one of pip, maturin, pytest, numpy, pandas (or is older than 3.9): {}",
            String::from_utf8_lossy(&o.stderr).lines().last().unwrap_or("")
        )),
        Ok(_) => None,
    }
}

/// `python3` (or `STF_LAB_PYTHON`) when it has what the tests need; `None` (the test skipped,
/// and said on stderr) otherwise — a failure instead when `STF_LAB_REQUIRE_PYTHON=1` (CI).
fn python_or_skip() -> Option<String> {
    let python = std::env::var("STF_LAB_PYTHON").unwrap_or_else(|_| "python3".to_string());
    let Some(why) = missing(&python) else {
        return Some(python);
    };
    let how = "pip install maturin pytest numpy pandas, as .ci/run does in a venv it names in \
               STF_LAB_PYTHON";
    if std::env::var("STF_LAB_REQUIRE_PYTHON").as_deref() == Ok("1") {
        panic!("{why}; STF_LAB_REQUIRE_PYTHON=1 makes this a failure: {how}");
    }
    // Straight to stderr, past the test harness's capture, so `cargo test` shows it.
    let _ = writeln!(
        std::io::stderr(),
        "{why}: the Python package's tests are SKIPPED ({how}; STF_LAB_REQUIRE_PYTHON=1 makes \
         a skip a failure)"
    );
    None
}

/// Run `cmd`, failing the test with its output if it fails.
fn run(cmd: &mut Command, what: &str) -> Output {
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("cannot run {what}: {e}"));
    assert!(
        out.status.success(),
        "{what} failed ({}):\n{}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    out
}

/// The folder holding the package's wheel: `STF_LAB_PYTHON_WHEELS`, or one built here.
fn wheels(python: &str, work: &Path) -> PathBuf {
    if let Some(dir) = std::env::var_os("STF_LAB_PYTHON_WHEELS") {
        return PathBuf::from(dir);
    }
    let dir = work.join("wheels");
    let _ = std::fs::remove_dir_all(&dir);
    run(
        Command::new(python)
            .args(["-m", "maturin", "build", "--release", "--quiet", "-m"])
            .arg(repo().join("python/Cargo.toml"))
            .arg("--out")
            .arg(&dir)
            .env("CARGO_TARGET_DIR", work.join("cargo")),
        "maturin build",
    );
    dir
}

/// The one wheel in `dir`, named for the stable ABI.
fn the_wheel(dir: &Path) -> PathBuf {
    let found: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|e| e == "whl"))
        .collect();
    assert_eq!(
        found.len(),
        1,
        "one wheel expected in {}: {found:?}",
        dir.display()
    );
    let name = found[0].file_name().unwrap().to_string_lossy().into_owned();
    assert!(name.contains("-cp39-abi3-"), "not an abi3 wheel: {name}");
    found[0].clone()
}

#[test]
fn the_python_package_passes_its_tests() {
    let Some(python) = python_or_skip() else {
        return;
    };
    let work = repo().join("target/python-package");
    std::fs::create_dir_all(&work).unwrap();
    let wheel = the_wheel(&wheels(&python, &work));
    let site = work.join("site");
    let _ = std::fs::remove_dir_all(&site);
    // The package is the wheel, alone in its folder; numpy, pandas and pytest are the Python's.
    run(
        Command::new(&python)
            .args([
                "-m",
                "pip",
                "install",
                "--quiet",
                "--no-deps",
                "--no-index",
                "--target",
            ])
            .arg(&site)
            .arg(&wheel),
        "pip install --target (the wheel)",
    );
    let out = run(
        Command::new(&python)
            .args([
                "-m",
                "pytest",
                "-q",
                "-p",
                "no:cacheprovider",
                "python/tests",
            ])
            .current_dir(repo())
            .env("PYTHONPATH", &site)
            .env("STF_LAB_BIN", env!("CARGO_BIN_EXE_stf-lab"))
            .env("STF_LAB_REQUIRE_PYTHON", "1"),
        "pytest python/tests",
    );
    let summary = String::from_utf8_lossy(&out.stdout);
    let last = summary.lines().last().unwrap_or("");
    let _ = writeln!(std::io::stderr(), "python package: {last}");
    assert!(
        last.contains("passed") && !last.contains("skipped"),
        "{summary}"
    );
}
