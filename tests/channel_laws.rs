//! A model parameter that follows a measured channel of the record, end to end: `simulate`
//! makes a damper-like record — the rotor rig swept 3 → 9 rad/s through resonance (in 60 s or
//! 30 s at 200 Hz, the rig's sensors), its STF force `viscous + yield` with the yield force
//! F_y = 0.5 + 1.5·u N following a random two-level control channel `u_ctrl` (each level held
//! 3 s on average), a force sensor offset of 50 N (a hundred times the yield force at u = 0) —
//! and writes `u_ctrl` as a column; `fit` reads it back through the law's syntax
//! (`F_y = { law = "affine", channel = "u_ctrl" }`) and recovers the law's coefficients within
//! 3 standard errors, with the offset fitted (`[fit] offset = true`), where a constant yield
//! force leaves a residual well above; at trajectory level too, with standard errors that
//! match those at a thousand times tighter integration. Bad input names the file, line and
//! key.

mod common;

use std::path::Path;

use common::{read_json, run, run_ok, simulate_ok};

/// The sweep rates the laws are checked at, rad/s²: the rotor swept 3 → 9 rad/s in 60 s or
/// in 30 s.
const RATES: [f64; 2] = [0.1, 0.2];

/// The experiment that makes the record (`seed`, swept at `alpha` rad/s² from 3 to 9 rad/s)
/// and fits it at `level` with the law.
fn experiment(seed: u64, level: &str, alpha: f64) -> String {
    let fit = match level {
        "force" => "offset = true",
        _ => "level = \"trajectory\"",
    };
    let t1 = 6.0 / alpha;
    format!(
        r#"[data]
file = "r.csv"

[simulate]
sweep = {{ w0 = 3.0, alpha = {alpha}, t0 = 0.0, t1 = {t1} }}
rate = 200.0
noise = true
seed = {seed}
channels.u_ctrl = {{ levels = [0.0, 1.0], hold = 3.0 }}
offsets = {{ f_stf = 50.0 }}

[[simulate.truth]]
name = "viscous"
plus = ["yield"]
params = {{ c_s = 5.0, F_y = {{ law = "affine", channel = "u_ctrl", base = 0.5, gain = 1.5 }} }}

[fit]
{fit}

[[models]]
name = "viscous"
plus = ["yield"]
params.F_y = {{ law = "affine", channel = "u_ctrl" }}
"#
    )
}

/// Write `text` as `exp.toml` in `dir`, simulate its record, and fit it.
fn simulated_and_fitted(dir: &Path, text: &str) -> serde_json::Value {
    let exp = dir.join("exp.toml");
    std::fs::write(&exp, text).unwrap();
    simulate_ok(&exp, &dir.join("r.csv"));
    let out = dir.join("fit");
    run_ok("fit", &exp, &out);
    read_json(&out.join("fit.json"))
}

/// `name`'s fitted value within 3 standard errors of `truth`.
fn within_3_se(model: &serde_json::Value, name: &str, truth: f64, seed: u64) {
    let got = model["params"][name].as_f64().unwrap();
    let se = model["std_errors"][name].as_f64().unwrap();
    assert!(
        (got - truth).abs() < 3.0 * se,
        "seed {seed}: {name} = {got} ± {se}, truth {truth}\n{model}"
    );
}

#[test]
fn simulate_writes_the_control_channel_beside_the_signals() {
    let dir = tempfile::tempdir().unwrap();
    let exp = dir.path().join("exp.toml");
    std::fs::write(&exp, experiment(1, "force", 0.1)).unwrap();
    simulate_ok(&exp, &dir.path().join("r.csv"));
    let u = common::csv_column(&dir.path().join("r.csv"), "u_ctrl");
    assert!(u.iter().all(|&v| v == 0.0 || v == 1.0));
    let switches = u.windows(2).filter(|w| w[0] != w[1]).count();
    // 60 s at a mean hold of 3 s: about 20 switches.
    assert!((8..40).contains(&switches), "{switches} switches");
    let f = common::csv_column(&dir.path().join("r.csv"), "f_stf");
    let mean = f.iter().sum::<f64>() / f.len() as f64;
    assert!(
        (mean - 50.0).abs() < 1.0,
        "mean f_stf {mean}: the offset is 50 N"
    );
}

#[test]
fn a_yield_force_following_a_control_channel_is_recovered_at_force_level() {
    for (seed, alpha) in [(1, RATES[0]), (2, RATES[1])] {
        let dir = tempfile::tempdir().unwrap();
        let text = experiment(seed, "force", alpha);
        let constant = format!("{text}\n[[models]]\nname = \"viscous\"\nplus = [\"yield\"]\n");
        let json = simulated_and_fitted(dir.path(), &constant);
        let (law, flat) = (&json["models"][0], &json["models"][1]);
        within_3_se(law, "F_y_base", 0.5, seed);
        within_3_se(law, "F_y_gain", 1.5, seed);
        within_3_se(law, "f_off", 50.0, seed);
        assert!(flat["params"]["F_y"].is_number(), "{flat}");
        // The RMS and AIC are those of the filter-noise-corrected values (not the least-squares
        // optimum on the noisy v), so the law's lead is read from AIC, not from an RMS ratio.
        let (aic_law, aic_flat) = (law["aic"].as_f64().unwrap(), flat["aic"].as_f64().unwrap());
        let gain_z = law["params"]["F_y_gain"].as_f64().unwrap()
            / law["std_errors"]["F_y_gain"].as_f64().unwrap();
        assert!(
            aic_flat - aic_law > 100.0 && gain_z > 5.0,
            "seed {seed}: constant F_y AIC {aic_flat} against the law's {aic_law}, gain z {gain_z}"
        );
    }
}

/// The law's coefficients at trajectory level, with standard errors that hold: in every case
/// the fit reaches the noise floor and the truth lies within 3.5 standard errors of each
/// coefficient (measured z at the default `rtol` 1e-7 — c_s, F_y_base, F_y_gain: seed 1 at
/// 0.1 rad/s² +1.95, −2.59, +2.18; seed 2 +0.04, −0.13, +0.41; seed 1 at 0.2 rad/s² +0.80,
/// −0.87, −0.75; seed 2 −0.65, +1.47, −1.75: all within 3), the RMS of all z within a factor 3
/// of 1 (measured 1.4). The difference steps of the errors once had the size of the yield
/// force's neutral start (2e-7 N), below the integrator's noise: F_y_base was 0.49936 ± 8.6e-7,
/// 750 errors off. Seed 2 at the faster sweep is the hard case: its initial velocity hardly
/// moves the residuals (the trolley sticks at the start), its Gauss–Newton component is
/// thousands of scales, and the step cap shortens every step by it, so the refinement creeps
/// (about 4 000 evaluations against 300–700 for the others); it once stopped that way in a
/// valley off the truth (0.66 mm RMS, c_s 12.7).
#[test]
fn a_yield_force_following_a_control_channel_is_recovered_at_trajectory_level() {
    let mut z2 = Vec::new();
    for (seed, alpha) in [(1, RATES[0]), (2, RATES[0]), (1, RATES[1]), (2, RATES[1])] {
        let dir = tempfile::tempdir().unwrap();
        let json = simulated_and_fitted(dir.path(), &experiment(seed, "trajectory", alpha));
        let law = &json["models"][0];
        let kinds: Vec<&str> = law["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .filter_map(|w| w["kind"].as_str())
            .collect();
        assert!(
            law["rms"].as_f64().unwrap() < 0.06e-3 && !kinds.contains(&"above_noise_floor"),
            "seed {seed}, {alpha} rad/s²: the fit ends off the truth\n{law}"
        );
        for (name, truth) in [("F_y_base", 0.5), ("F_y_gain", 1.5), ("c_s", 5.0)] {
            let got = law["params"][name].as_f64().unwrap();
            let se = law["std_errors"][name].as_f64().unwrap();
            let z = (got - truth) / se;
            assert!(
                z.abs() < 3.5,
                "seed {seed}, {alpha} rad/s²: {name} = {got} ± {se}, truth {truth}\n{law}"
            );
            z2.push(z * z);
        }
        assert!(!kinds.contains(&"noisy_error"), "{law}");
    }
    let rms_z = (z2.iter().sum::<f64>() / z2.len() as f64).sqrt();
    assert!((1.0 / 3.0..3.0).contains(&rms_z), "RMS of z {rms_z}");
}

/// The standard errors at the default `rtol` 1e-7 within a factor 3 of those at 1e-10, where
/// the integrator's noise is a thousand times smaller (measured, seed 1 at 0.1 rad/s²:
/// F_y_base 2.2e-4 at both, F_y_gain 5.2e-4 against 5.4e-4, c_s 0.0065 against 0.0062).
#[test]
fn trajectory_standard_errors_do_not_depend_on_the_integrators_noise() {
    let fitted = |rtol: Option<f64>| {
        let dir = tempfile::tempdir().unwrap();
        let mut text = experiment(1, "trajectory", RATES[0]);
        if let Some(r) = rtol {
            text = text.replace("[fit]\n", &format!("[integrator]\nrtol = {r}\n\n[fit]\n"));
        }
        simulated_and_fitted(dir.path(), &text)["models"][0].clone()
    };
    let (loose, tight) = (fitted(None), fitted(Some(1e-10)));
    for name in ["F_y_base", "F_y_gain", "c_s"] {
        let (a, b) = (
            loose["std_errors"][name].as_f64().unwrap(),
            tight["std_errors"][name].as_f64().unwrap(),
        );
        assert!(
            (a / b) > 1.0 / 3.0 && (a / b) < 3.0,
            "{name}: ± {a} at rtol 1e-7, ± {b} at 1e-10"
        );
    }
}

/// The discovery experiment of the record `r.csv`, its channel declared, the force offset
/// fitted.
const DISCOVER: &str = "[data]\nfile = \"r.csv\"\nchannels = [\"u_ctrl\"]\n\n[fit]\noffset = true\n\n\
                        [discover]\nbase = \"viscous + yield\"\ncandidates = [\"cubic_stiffness\"]\n";

/// Damper-like records with a large force offset (50 or 150 N, a hundred times the yield
/// force) fitted with `[fit] offset = true`, two seeds at two sweep rates: where F_y follows
/// the control channel the law is named; where it is constant nothing is. (The offset started
/// at 0, unbounded, at a scale of 0.1 N, once left the base's fit far from its optimum —
/// held-out RMS 0.91 N against 0.28 N — and the law or `cubic_stiffness` was then named for
/// the base's misfit.)
#[test]
fn discovery_names_the_channel_law_only_where_the_parameter_follows_the_channel() {
    let cases = [
        (1, RATES[0], 50.0),
        (2, RATES[0], 150.0),
        (1, RATES[1], 150.0),
        (2, RATES[1], 50.0),
    ];
    for (seed, alpha, offset) in cases {
        for follows in [true, false] {
            let dir = tempfile::tempdir().unwrap();
            let mut make = experiment(seed, "force", alpha)
                .replace("f_stf = 50.0", &format!("f_stf = {offset}"));
            if !follows {
                make = make.replace(
                    "F_y = { law = \"affine\", channel = \"u_ctrl\", base = 0.5, gain = 1.5 }",
                    "F_y = 1.25",
                );
            }
            let (make_path, exp) = (dir.path().join("make.toml"), dir.path().join("exp.toml"));
            std::fs::write(&make_path, make).unwrap();
            simulate_ok(&make_path, &dir.path().join("r.csv"));
            std::fs::write(&exp, DISCOVER).unwrap();
            let out = dir.path().join("out");
            let printed = run_ok("discover", &exp, &out);
            let json = read_json(&out.join("discovery.json"));
            let case =
                format!("seed {seed}, sweep {alpha} rad/s², offset {offset} N, follows {follows}");
            let named = json["effects"].as_array().unwrap();
            let expected = if follows {
                vec!["yield.F_y~u_ctrl"]
            } else {
                vec![]
            };
            assert_eq!(named, &expected, "{case}: effects {}", json["effects"]);
            if follows {
                pasted_back_fits(dir.path(), &printed.stdout, &json, &case);
            }
        }
    }
}

/// The entry `discover` printed for a law effect (on the terminal and in `discovery.json`),
/// pasted as it is into an experiment on the same record, loads and fits: the effect
/// `yield.F_y~u_ctrl` is printed as the law it adds up to, `F_y = { law = "affine", channel =
/// "u_ctrl", base = …, gain = … }`, and the refit recovers the truth's gain.
fn pasted_back_fits(dir: &Path, stdout: &[u8], json: &serde_json::Value, case: &str) {
    let entry = json["final_model"]["experiment_entry"].as_str().unwrap();
    assert!(
        entry.contains("F_y = { law = \"affine\", channel = \"u_ctrl\", base = ")
            && !entry.contains('~'),
        "{case}: {entry}"
    );
    let stdout = String::from_utf8_lossy(stdout);
    let shown = stdout
        .split("final model, as an experiment entry:\n")
        .nth(1)
        .unwrap_or_else(|| panic!("no entry printed: {stdout}"));
    assert!(shown.starts_with(entry), "{shown}");
    let refit = dir.join("refit.toml");
    std::fs::write(
        &refit,
        format!("[data]\nfile = \"r.csv\"\n\n[fit]\noffset = true\n\n{entry}"),
    )
    .unwrap();
    run_ok("fit", &refit, &dir.join("refit"));
    let fitted = &read_json(&dir.join("refit/fit.json"))["models"][0];
    let gain = fitted["params"]["F_y_gain"].as_f64().unwrap();
    assert!(
        (gain / 1.5 - 1.0).abs() < 0.15,
        "{case}: F_y_gain {gain}\n{fitted}"
    );
}

/// `exp.toml` in a fresh folder with `text`, and the message of `command` on it.
fn error_of(command: &str, text: &str, record: Option<&str>) -> String {
    let dir = tempfile::tempdir().unwrap();
    let exp = dir.path().join("exp.toml");
    std::fs::write(&exp, text).unwrap();
    if let Some(csv) = record {
        std::fs::write(dir.path().join("r.csv"), csv).unwrap();
    }
    let out = run(command, &exp, &dir.path().join("out"));
    assert!(!out.status.success(), "{command} should fail on\n{text}");
    String::from_utf8_lossy(&out.stderr).into_owned()
}

#[test]
fn bad_laws_and_missing_channels_are_named_with_file_line_and_key() {
    let rows = |u: bool| -> String {
        let head = if u {
            "t,x,f_stf,u_ctrl\n"
        } else {
            "t,x,f_stf\n"
        };
        let body: String = (0..40)
            .map(|i| {
                let t = i as f64 * 0.01;
                let tail = if u {
                    format!(",{}", i % 2)
                } else {
                    String::new()
                };
                format!(
                    "{t},{},{}{tail}\n",
                    1e-3 * (6.0 * t).sin(),
                    0.1 * (6.0 * t).cos()
                )
            })
            .collect();
        format!("{head}{body}")
    };
    let record = rows(false);
    let record = record.as_str();
    let models = |law: &str| {
        format!(
            "[data]\nfile = \"r.csv\"\n\n[[models]]\nname = \"viscous\"\nplus = [\"yield\"]\n\
             params.F_y = {law}\n"
        )
    };
    let cases = [
        (
            models(r#"{ law = "afine", channel = "u_ctrl" }"#),
            vec![
                "exp.toml:7",
                "models[0].params.F_y",
                "unknown law `afine`",
                "did you mean `affine`",
            ],
        ),
        (
            models(r#"{ law = "affine" }"#),
            vec!["exp.toml:7", "needs the `channel`"],
        ),
        (
            models(r#"{ law = "linear", channel = "u_ctrl", base = 1.0 }"#),
            vec!["the linear law has no `base`"],
        ),
        (
            models(r#"{ law = "affine", channel = "u_ctrl", value = 1.0 }"#),
            vec!["`value` does not go with a law", "F_y_gain"],
        ),
        (
            models(r#"{ law = "affine", channel = "u_ctrl" }"#),
            vec!["channel `u_ctrl`", "r.csv"],
        ),
    ];
    for (text, says) in cases {
        let msg = error_of("fit", &text, Some(record));
        for s in says {
            assert!(msg.contains(s), "`{s}` not in: {msg}");
        }
    }
    // A parameter the models lack.
    let text = models(r#"{ law = "affine", channel = "u_ctrl" }"#).replace("F_y =", "F_z =");
    let msg = error_of("fit", &text, Some(&rows(true)));
    assert!(
        msg.contains("models[0].params.F_z") && msg.contains("did you mean `F_y`"),
        "{msg}"
    );
    // A simulated truth following a channel `[simulate]` does not make.
    let text = "[simulate]\nconstant = { omega = 6.0, t1 = 1.0 }\n\n[[simulate.truth]]\n\
                name = \"yield\"\nparams.F_y = { law = \"affine\", channel = \"u\" }\n";
    let dir = tempfile::tempdir().unwrap();
    let exp = dir.path().join("exp.toml");
    std::fs::write(&exp, text).unwrap();
    let out = common::simulate(&exp, &dir.path().join("r.csv"), &[]);
    let msg = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success()
            && msg.contains("simulate.truth[0].params.F_y")
            && msg.contains("channels.u = { levels"),
        "{msg}"
    );
}
