//! What a person reads when an experiment file is wrong: every mistake of the file in one
//! run, each with its file, line and key; the file's words, never serde's ("variant",
//! "untagged enum RawParam", "invalid type … expected f64"); a did-you-mean for keys, values,
//! models, parameters and files; the fix where there is one (widen the bounds, `**` for
//! powers, `[data] rate` for uneven times); and each command's `--help` with an example.

mod common;

use std::path::{Path, PathBuf};

use common::{root, stf_lab};

/// The bundled power-law sweep.
fn sweep() -> String {
    root()
        .join("experiments/records/power_law_sweep.csv")
        .display()
        .to_string()
}

/// `text` written as `exp.toml` in `dir`.
fn experiment(dir: &Path, text: &str) -> PathBuf {
    let path = dir.join("exp.toml");
    std::fs::write(&path, text).unwrap();
    path
}

/// `stf-lab COMMAND EXP --out DIR/out`: its failure message (exit status 1, nothing written).
fn fails(command: &str, exp: &Path) -> String {
    let out = exp.parent().unwrap().join("out");
    let run = stf_lab()
        .arg(command)
        .arg(exp)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert_eq!(run.status.code(), Some(1), "{run:?}");
    assert!(!out.exists());
    String::from_utf8_lossy(&run.stderr).into_owned()
}

/// serde's words, which no message may hold.
const SERDE_WORDS: [&str; 8] = [
    "variant",
    "untagged",
    "invalid type",
    "invalid value",
    "expected f64",
    "expected usize",
    "unknown field",
    "struct ",
];

fn assert_plain(msg: &str) {
    for word in SERDE_WORDS {
        assert!(!msg.contains(word), "`{word}` in: {msg}");
    }
}

#[test]
fn five_mistakes_are_reported_in_one_run() {
    let dir = tempfile::tempdir().unwrap();
    let exp = experiment(
        dir.path(),
        &format!(
            "[data]\nfile = {:?}\nwindow = [0.0, 1.0, 2.0]\n\n[system]\nm = 7.65\nstifnes = 270.0\n\n\
             [[models]]\nname = \"power_law\"\nparams = {{ K = \"big\", n = 1.5 }}\n\n\
             [fit]\nlevel = \"forc\"\n\n[discover]\nbase = \"viscous\"\nholdout_every = 0\n",
            sweep()
        ),
    );
    let msg = fails("fit", &exp);
    assert!(msg.contains("5 mistakes in "), "{msg}");
    let file = exp.display().to_string();
    for (line, key, says) in [
        (3, "data.window", "give two times"),
        (7, "system", "unknown key `stifnes`"),
        (
            11,
            "models[0].params.K",
            "expected a number or a table { value, min, max, fixed }, found the string \"big\"",
        ),
        (
            14,
            "fit.level",
            "unknown value `forc` (did you mean `force`?)",
        ),
        (18, "discover.holdout_every", "0 is not a count of cycles"),
    ] {
        let want = format!("{file}:{line}: `{key}`: {says}");
        assert!(msg.contains(&want), "{want}\nin: {msg}");
    }
    assert_plain(&msg);
    // In the file's order.
    let at = |s: &str| msg.find(s).unwrap();
    assert!(at("data.window") < at("`system`") && at("`system`") < at("fit.level"));
}

#[test]
fn no_message_speaks_serde() {
    let dir = tempfile::tempdir().unwrap();
    let data = format!("[data]\nfile = {:?}\n", sweep());
    for (text, says) in [
        (
            "[system]\nk = \"stiff\"\n",
            "`system.k`: expected a number, found the string \"stiff\"",
        ),
        (
            "[system]\nk = [1, 2]\n",
            "`system.k`: expected a number, found a list",
        ),
        (
            "[[models]]\nname = \"power_law\"\nparams = { K = [1] }\n",
            "`models[0].params.K`: expected a number or a table",
        ),
        (
            "[[models]]\nname = \"power_law\"\nparams = { K = { value = \"x\" } }\n",
            "expected a number, found the string \"x\"",
        ),
        (
            "[fit]\nmax_iters = \"many\"\n",
            "`fit.max_iters`: expected a number",
        ),
        (
            "[discover]\nbase = \"viscous\"\npolish = 1\n",
            "expected true or false, found the number 1",
        ),
        (
            "[discover]\nbsae = \"viscous\"\n",
            "unknown key `bsae` (did you mean `base`?)",
        ),
        ("[discover]\nmax_effects = 2\n", "missing key `base`"),
        ("[filter]\nboundary = \"edge\"\n", "unknown value `edge`"),
        (
            "[integrator]\nmethod = \"euler\"\n",
            "unknown value `euler`",
        ),
        ("[data]\nwindow = { a = 1 }\n", "`data.window`"),
        (
            "[sytem]\nk = 3.0\n",
            "unknown key `sytem` (did you mean `system`?)",
        ),
        (
            "[[models]]\nname = \"power_law\"\nparms = { K = 1.0 }\n",
            "unknown key `parms` (did you mean `params`?)",
        ),
    ] {
        // Each file has the record so that only its own mistake is reported.
        let text = if text.starts_with("[data]") {
            text.replace("[data]\n", &data)
        } else {
            format!("{data}\n{text}")
        };
        let exp = experiment(dir.path(), &text);
        let msg = fails("fit", &exp);
        assert!(
            msg.contains("exp.toml:") && msg.contains(says),
            "{says}\nin: {msg}"
        );
        assert_plain(&msg);
    }
}

#[test]
fn models_parameters_and_files_get_a_did_you_mean_and_bounds_the_fix() {
    let dir = tempfile::tempdir().unwrap();
    let exp = experiment(
        dir.path(),
        &format!(
            "[data]\nfile = {:?}\n\n[[models]]\nname = \"power_lw\"\n\n[[models]]\n\
             name = \"power_law\"\nparams = {{ k = 2.0 }}\n\n[[models]]\nname = \"power_law\"\n\
             params = {{ n = 9.0 }}\n",
            sweep()
        ),
    );
    let msg = fails("fit", &exp);
    for says in [
        "exp.toml:4: `models[0]`: unknown model `power_lw` (did you mean `power_law`?)",
        "exp.toml:9: `models[1].params.k`: `power_law` has no parameter `k` (did you mean `K`?)",
        "exp.toml:13: `models[2].params.n`: 9 lies outside its bounds [",
        "widen them in this entry: `n = { value = 9, max = 18 }`",
    ] {
        assert!(msg.contains(says), "{says}\nin: {msg}");
    }
    let missing = sweep().replace("power_law_sweep.csv", "power_law_swep.csv");
    let exp = experiment(
        dir.path(),
        &format!("[data]\nfile = {missing:?}\n\n[[models]]\nname = \"viscous\"\n"),
    );
    let msg = fails("fit", &exp);
    assert!(
        msg.contains("no such record: ")
            && msg.contains("(did you mean `")
            && msg.contains("power_law_sweep.csv`?)"),
        "{msg}"
    );
    std::fs::write(dir.path().join("drag.rhai"), "").unwrap();
    let exp = experiment(
        dir.path(),
        &format!(
            "[data]\nfile = {:?}\n\n[[models]]\nscript = \"darg.rhai\"\n",
            sweep()
        ),
    );
    let msg = fails("fit", &exp);
    assert!(msg.contains("drag.rhai`?)"), "{msg}");
}

/// The bundled power-law script with `force`'s body replaced by `body`.
fn script(dir: &Path, body: &str) -> PathBuf {
    let source = std::fs::read_to_string(root().join("models/scripts/power_law.rhai")).unwrap();
    let changed = source.replace("p.K * v.abs() ** p.n * v.sign()", body);
    assert_ne!(changed, source);
    let path = dir.join("m.rhai");
    std::fs::write(&path, changed).unwrap();
    path
}

#[test]
fn a_script_s_unknown_parameter_and_pow_are_named_with_the_fix() {
    let dir = tempfile::tempdir().unwrap();
    for (body, says) in [
        // It said "Function not found: ** (f64, ())".
        (
            "p.K * v.abs() ** p.nn * v.sign()",
            "`nn` is not a parameter of this script (did you mean `n`?): its parameters (from fn params) are K, n",
        ),
        (
            "p.K * pow(v.abs(), p.n) * v.sign()",
            "rhai has no `pow`; `**` is the power operator",
        ),
    ] {
        let path = script(dir.path(), body);
        let run = stf_lab().arg("models").arg("--check").arg(&path).output().unwrap();
        assert_eq!(run.status.code(), Some(1));
        let msg = String::from_utf8_lossy(&run.stderr);
        assert!(msg.contains("m.rhai:24: ") && msg.contains(says), "{says}\nin: {msg}");
    }
}

#[test]
fn uneven_times_name_the_rate_that_would_replace_them() {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(sweep()).unwrap();
    // One time moved by 0.4 ms in a record of 5 ms steps.
    let mut lines: Vec<String> = text.lines().map(String::from).collect();
    let mut cells: Vec<String> = lines[501].split(',').map(String::from).collect();
    cells[0] = format!("{}", cells[0].parse::<f64>().unwrap() + 0.0004);
    lines[501] = cells.join(",");
    std::fs::write(dir.path().join("r.csv"), lines.join("\n") + "\n").unwrap();
    let exp = experiment(
        dir.path(),
        "[data]\nfile = \"r.csv\"\n\n[[models]]\nname = \"viscous\"\n",
    );
    let msg = fails("fit", &exp);
    assert!(
        msg.contains("exp.toml:1: `[data]`: the times of ")
            && msg.contains("are not uniform")
            && msg.contains("give it in [data]: `rate = 200`"),
        "{msg}"
    );
    assert!(!msg.contains("0000000"), "{msg}");
}

#[test]
fn every_command_s_help_shows_an_example_and_where_the_keys_are() {
    for command in [
        "models", "simulate", "fit", "compare", "discover", "campaign",
    ] {
        let run = stf_lab().args([command, "--help"]).output().unwrap();
        assert!(run.status.success());
        let help = String::from_utf8_lossy(&run.stdout);
        assert!(
            help.contains("Example") && help.contains(&format!("stf-lab {command} ")),
            "{command}: {help}"
        );
        assert!(help.contains("docs/"), "{command}: {help}");
        // The page it names is there.
        let page = help
            .split_whitespace()
            .find(|w| w.starts_with("docs/"))
            .unwrap()
            .trim_end_matches(['.', ';', ',']);
        assert!(root().join(page).is_file(), "{command}: {page}");
    }
}
