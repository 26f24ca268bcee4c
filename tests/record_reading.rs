//! End to end: records as other rigs write them are read without friction. Each record is
//! made by `simulate` (the rig's sensors on) and then rewritten as a lab would have it:
//! columns dropped (a damper rig records t, x and the force only), other units, time stamps
//! rounded, a measured velocity beside x, a unit declared wrongly.

mod common;

use std::path::{Path, PathBuf};

use common::{read_json, run, run_ok, simulate_ok};

/// A force-level record through resonance: 2 s at rest, a spin-up, then a sweep to `w1`
/// rad/s; the STF force is a power law, K = 4, n = 1.5.
fn simulate_record(dir: &Path, w1: f64, seed: u64) -> String {
    simulate_at(dir, w1, seed, 200.0)
}

/// [`simulate_record`] at `rate` samples per second.
fn simulate_at(dir: &Path, w1: f64, seed: u64, rate: f64) -> String {
    simulate_with(dir, w1, seed, rate, true)
}

/// [`simulate_at`] with the sensors on or off (`noise`): the same run either way.
fn simulate_with(dir: &Path, w1: f64, seed: u64, rate: f64, noise: bool) -> String {
    let sim = dir.join(format!("sim_{seed}_{noise}.toml"));
    let text = format!(
        "[simulate]\nprofile = {{ t = [0.0, 2.0, 2.5, 22.5], omega = [0.0, 0.0, 4.0, {w1}] }}\n\
         rate = {rate}\nnoise = {noise}\nseed = {seed}\n\n[[simulate.truth]]\nname = \"power_law\"\n\
         params = {{ K = 4.0, n = 1.5 }}\n"
    );
    std::fs::write(&sim, text).unwrap();
    let csv = dir.join(format!("sim_{seed}_{noise}.csv"));
    simulate_ok(&sim, &csv);
    std::fs::read_to_string(&csv).unwrap()
}

/// The simulator's first columns (t, phi, x, f_stf) as numbers, one row a sample.
fn rows(si_csv: &str) -> Vec<[f64; 4]> {
    let mut lines = si_csv.lines();
    // (An exact run adds the rotor's ω.)
    assert!(lines.next().unwrap().starts_with("t,phi,x,f_stf"));
    lines
        .map(|l| {
            let v: Vec<f64> = l.split(',').map(|c| c.parse().unwrap()).collect();
            [v[0], v[1], v[2], v[3]]
        })
        .collect()
}

/// Write `header` and one line per row made by `line`.
fn write_csv(
    dir: &Path,
    name: &str,
    header: &str,
    rows: &[[f64; 4]],
    line: impl Fn(&[f64; 4]) -> String,
) -> PathBuf {
    let mut text = format!("{header}\n");
    for r in rows {
        text += &line(r);
        text.push('\n');
    }
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// A force-level experiment on `file` with `[data]` keys `data` (and the window of the
/// sweep, 2 – 22.5 s, unless they give one), fitting a power law.
fn experiment(dir: &Path, file: &str, data: &str) -> PathBuf {
    let window = if data.contains("window") {
        ""
    } else {
        "window = [2.0, 22.5]\n"
    };
    let text = format!(
        "[data]\nfile = \"{file}\"\n{window}{data}\n\n[output]\nreport = false\n\n\
         [[models]]\nname = \"power_law\"\n"
    );
    let path = dir.join(format!("{file}.toml"));
    std::fs::write(&path, text).unwrap();
    path
}

/// The fitted power law's (K, n) and their standard errors.
fn power_law(out: &Path) -> ([f64; 2], [f64; 2]) {
    let fit = read_json(&out.join("fit.json"));
    let m = &fit["models"][0];
    let value = |p: &str| m["params"][p].as_f64().unwrap();
    let se = |p: &str| m["std_errors"][p].as_f64().unwrap();
    ([value("K"), value("n")], [se("K"), se("n")])
}

#[test]
fn a_force_record_of_t_x_and_the_force_alone_fits_to_the_truth() {
    // A damper rig records no rotor angle or drive: t, x and the force are enough at force
    // level. Two sweep rates, two seeds.
    for (w1, seed) in [(8.0, 5), (10.0, 6)] {
        let dir = tempfile::tempdir().unwrap();
        let rows = rows(&simulate_record(dir.path(), w1, seed));
        write_csv(dir.path(), "damper.csv", "t,x,f_stf", &rows, |r| {
            format!("{},{},{}", r[0], r[2], r[3])
        });
        let exp = experiment(dir.path(), "damper.csv", "");
        let out = dir.path().join("fit");
        run_ok("fit", &exp, &out);
        let ([k, n], [se_k, se_n]) = power_law(&out);
        eprintln!("w1 {w1}, seed {seed}: K = {k} ± {se_k}, n = {n} ± {se_n}");
        assert!(
            (k - 4.0).abs() < 3.0 * se_k && (k / 4.0 - 1.0).abs() < 0.05,
            "K = {k}"
        );
        assert!(
            (n - 1.5).abs() < 3.0 * se_n && (n / 1.5 - 1.0).abs() < 0.05,
            "n = {n}"
        );
        // compare and discover read it too.
        for command in ["compare", "discover"] {
            let text = std::fs::read_to_string(&exp).unwrap()
                + "\n[[models]]\nname = \"viscous\"\n\n[discover]\nbase = \"viscous\"\n\
                   candidates = [\"power_law\"]\n";
            let both = dir.path().join("both.toml");
            std::fs::write(&both, text).unwrap();
            run_ok(command, &both, &dir.path().join(command));
        }
    }
}

#[test]
fn the_common_lab_units_are_known() {
    // The same record in SI, then in two labs' units (the rotor angle in turns, time in
    // minutes or ms, x in cm or inches, the force in kN or pounds-force): the same fit.
    let dir = tempfile::tempdir().unwrap();
    let rows = rows(&simulate_record(dir.path(), 8.0, 5));
    let si = dir.path().join("si");
    write_csv(dir.path(), "si.csv", "t,phi,x,f_stf", &rows, |r| {
        format!("{},{},{},{}", r[0], r[1], r[2], r[3])
    });
    run_ok("fit", &experiment(dir.path(), "si.csv", ""), &si);
    let (truth, _) = power_law(&si);
    let tau = std::f64::consts::TAU;
    let labs: [(&str, &str, [f64; 4]); 2] = [
        (
            "metric.csv",
            "units = { t = \"min\", phi = \"rev\", x = \"cm\", f_stf = \"kN\" }",
            [1.0 / 60.0, 1.0 / tau, 100.0, 1e-3],
        ),
        (
            "imperial.csv",
            "units = { t = \"ms\", phi = \"deg\", x = \"in\", f_stf = \"lbf\" }",
            [1e3, 360.0 / tau, 1.0 / 0.0254, 1.0 / 4.448_221_615_260_5],
        ),
    ];
    for (name, units, k) in labs {
        write_csv(dir.path(), name, "t,phi,x,f_stf", &rows, |r| {
            format!(
                "{},{},{},{}",
                r[0] * k[0],
                r[1] * k[1],
                r[2] * k[2],
                r[3] * k[3]
            )
        });
        let out = dir.path().join(name.replace(".csv", ""));
        // The window is in s whatever the file's time unit: only the units differ.
        run_ok("fit", &experiment(dir.path(), name, units), &out);
        let (fitted, _) = power_law(&out);
        eprintln!("{name}: K, n = {fitted:?} (SI: {truth:?})");
        for (a, b) in fitted.iter().zip(truth) {
            assert!(
                (a / b - 1.0).abs() < 1e-6,
                "{name}: {fitted:?} against {truth:?}"
            );
        }
    }
}

#[test]
fn time_stamps_rounded_to_a_tenth_of_a_ms_are_read_as_uniform() {
    // 610.35 Hz (a step of 1.6384 ms) written to 0.1 ms: steps of 1.6 and 1.7 ms. Force
    // only (t, x, f_stf), two seeds.
    for seed in [5, 6] {
        let dir = tempfile::tempdir().unwrap();
        let rows = rows(&simulate_at(dir.path(), 8.0, seed, 610.35));
        write_csv(dir.path(), "exact.csv", "t,x,f_stf", &rows, |r| {
            format!("{},{},{}", r[0], r[2], r[3])
        });
        write_csv(dir.path(), "rounded.csv", "t,x,f_stf", &rows, |r| {
            format!("{:.4},{},{}", r[0], r[2], r[3])
        });
        let exact = dir.path().join("exact");
        run_ok("fit", &experiment(dir.path(), "exact.csv", ""), &exact);
        let rounded = dir.path().join("rounded");
        run_ok("fit", &experiment(dir.path(), "rounded.csv", ""), &rounded);
        let ((a, se), (b, _)) = (power_law(&exact), power_law(&rounded));
        eprintln!("seed {seed}: exact time {a:?} ± {se:?}, rounded {b:?}");
        for i in 0..2 {
            assert!((a[i] - b[i]).abs() < 0.05 * se[i], "{a:?} against {b:?}");
        }
        assert!((a[0] / 4.0 - 1.0).abs() < 0.05 && (a[1] / 1.5 - 1.0).abs() < 0.05);

        // Stamps that are not uniform, rounded or not (a clock with 3 % of jitter), are
        // refused, and the message names the fix: the sample rate.
        write_csv(dir.path(), "jitter.csv", "t,x,f_stf", &rows, |r| {
            let i = (r[0] * 610.35).round() as u64;
            let hash = i.wrapping_mul(2_654_435_761) >> 7;
            let jitter = 0.03 / 610.35 * ((hash % 1000) as f64 / 1000.0 - 0.5);
            format!("{},{},{}", r[0] + jitter, r[2], r[3])
        });
        let failed = run(
            "fit",
            &experiment(dir.path(), "jitter.csv", ""),
            &dir.path().join("j"),
        );
        assert!(!failed.status.success());
        let msg = String::from_utf8_lossy(&failed.stderr);
        assert!(
            msg.contains("not uniform") && msg.contains("`rate = 610."),
            "{msg}"
        );
    }
}

#[test]
fn a_record_without_drive_at_trajectory_level_is_a_free_vibration_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let rows = rows(&simulate_record(dir.path(), 8.0, 5));
    write_csv(dir.path(), "damper.csv", "t,x,f_stf", &rows, |r| {
        format!("{},{},{}", r[0], r[2], r[3])
    });
    let exp = experiment(dir.path(), "damper.csv", "");
    let text = std::fs::read_to_string(&exp).unwrap() + "\n[fit]\nlevel = \"trajectory\"\n";
    std::fs::write(&exp, text).unwrap();
    let out = common::stf_lab()
        .args(["fit", "--out"])
        .arg(dir.path().join("traj"))
        .arg(&exp)
        .output()
        .unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        format!("{stdout}{stderr}").contains("no drive column"),
        "{stdout}\n{stderr}"
    );
}

/// The warnings of reading `file` with `[data]` keys `data` (the library's `load_data`).
fn warnings(dir: &Path, file: &str, data: &str) -> Vec<String> {
    let exp = experiment(dir, file, data);
    let mut exp = stf_lab::experiment::Experiment::load(&exp).unwrap();
    stf_lab::fitting::load_data(&mut exp)
        .map(|d| d.record_warnings)
        .unwrap_or_else(|e| panic!("{e:#}"))
}

#[test]
fn implausible_scales_warn_and_name_the_likely_unit_mistake() {
    for (w1, seed) in [(8.0, 5), (10.0, 6)] {
        let dir = tempfile::tempdir().unwrap();
        let rows = rows(&simulate_record(dir.path(), w1, seed));
        let si = |r: &[f64; 4]| format!("{},{},{},{}", r[0], r[1], r[2], r[3]);
        write_csv(dir.path(), "rotor.csv", "t,phi,x,f_stf", &rows, si);
        write_csv(dir.path(), "damper.csv", "t,x,f_stf", &rows, |r| {
            format!("{},{},{}", r[0], r[2], r[3])
        });
        // Read as recorded: not a word (the window is in s, so none when t is read as ms).
        assert_eq!(warnings(dir.path(), "rotor.csv", ""), Vec::<String>::new());
        assert_eq!(warnings(dir.path(), "damper.csv", ""), Vec::<String>::new());
        // A record in s read as ms: a rotor at thousands of rad/s, cycles of x at ~1 kHz.
        let ms = "units = { t = \"ms\" }\nwindow = [0.002, 0.0225]";
        for file in ["rotor.csv", "damper.csv"] {
            let w = warnings(dir.path(), file, ms);
            eprintln!("{file}, t read as ms: {w:?}");
            assert!(
                w.iter().any(|w| w.contains("is `t` in s read as ms?")),
                "{file}: {w:?}"
            );
        }
        // A record in m read as mm: a stroke of hundredths of a mm.
        for file in ["rotor.csv", "damper.csv"] {
            let w = warnings(dir.path(), file, "units = { x = \"mm\" }");
            eprintln!("{file}, x read as mm: {w:?}");
            assert!(
                w.iter().any(|w| w.contains("in m (or cm) read as mm?")),
                "{file}: {w:?}"
            );
        }
        // The same record written in mm and read as mm: not a word.
        write_csv(dir.path(), "mm.csv", "t,x,f_stf", &rows, |r| {
            format!("{},{},{}", r[0], r[2] * 1e3, r[3])
        });
        assert_eq!(
            warnings(dir.path(), "mm.csv", "units = { x = \"mm\" }"),
            Vec::<String>::new()
        );
    }
}

#[test]
fn a_force_record_without_rotor_is_reported_without_regimes() {
    // A damper's record (t, x, f_stf): its report speaks of thirds of the record and periods
    // of the motion, not of a rotor's regimes, in fit's and discover's reports alike.
    let dir = tempfile::tempdir().unwrap();
    let rows = rows(&simulate_record(dir.path(), 8.0, 5));
    write_csv(dir.path(), "damper.csv", "t,x,f_stf", &rows, |r| {
        format!("{},{},{}", r[0], r[2], r[3])
    });
    let exp = experiment(dir.path(), "damper.csv", "");
    let text = std::fs::read_to_string(&exp)
        .unwrap()
        .replace("report = false", "report = true")
        + "\n[[models]]\nname = \"viscous\"\n\n[discover]\nbase = \"viscous\"\n\
           candidates = [\"power_law\", \"yield\"]\n";
    std::fs::write(&exp, text).unwrap();
    for command in ["fit", "discover"] {
        let out = dir.path().join(command);
        run_ok(command, &exp, &out);
        let report = std::fs::read_to_string(out.join("report.md")).unwrap();
        assert!(report.contains("Start, middle and end"), "{command}");
        for word in ["regime", "resonance"] {
            let hit = report.lines().find(|l| l.to_lowercase().contains(word));
            assert!(hit.is_none(), "{command}: `{word}` in {hit:?}");
        }
    }
    // The rotor's record, the same otherwise, keeps its regimes.
    write_csv(dir.path(), "rotor.csv", "t,phi,x,f_stf", &rows, |r| {
        format!("{},{},{},{}", r[0], r[1], r[2], r[3])
    });
    let rotor = dir.path().join("rotor.toml");
    let text = std::fs::read_to_string(&exp)
        .unwrap()
        .replace("damper.csv", "rotor.csv");
    std::fs::write(&rotor, text).unwrap();
    let out = dir.path().join("rotor");
    run_ok("fit", &rotor, &out);
    let report = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(report.contains("Regime by regime"), "{report}");
}

#[test]
fn a_measured_velocity_is_used_when_it_agrees_with_x_and_flagged_when_not() {
    // The rig's sensors on x and the force; a velocity sensor beside them: the exact run's
    // velocity (central differences of its x) with 1 mm/s of noise. Two seeds, two sweeps.
    for (w1, seed) in [(8.0, 5), (10.0, 6)] {
        let dir = tempfile::tempdir().unwrap();
        let noisy = rows(&simulate_with(dir.path(), w1, seed, 200.0, true));
        let exact = rows(&simulate_with(dir.path(), w1, seed, 200.0, false));
        let n = exact.len();
        let v: Vec<f64> = (0..n)
            .map(|i| {
                let (a, b) = (i.saturating_sub(1), (i + 1).min(n - 1));
                let hash = (i as u64 + 7 * seed).wrapping_mul(2_654_435_761) >> 7;
                let noise = 1e-3 * 1.7 * ((hash % 1000) as f64 / 1000.0 - 0.5);
                (exact[b][2] - exact[a][2]) / (exact[b][0] - exact[a][0]) + noise
            })
            .collect();
        for (name, k) in [("v.csv", 1.0), ("v_mm.csv", 1e3), ("v_sign.csv", -1.0)] {
            let mut text = String::from("t,x,v,f_stf\n");
            for (r, v) in noisy.iter().zip(&v) {
                text += &format!("{},{},{},{}\n", r[0], r[2], v * k, r[3]);
            }
            std::fs::write(dir.path().join(name), text).unwrap();
        }
        // Agreeing: used, not a word, and the fit finds the truth.
        assert_eq!(warnings(dir.path(), "v.csv", ""), Vec::<String>::new());
        let out = dir.path().join("v");
        run_ok("fit", &experiment(dir.path(), "v.csv", ""), &out);
        let ([k, n_exp], [se_k, se_n]) = power_law(&out);
        eprintln!("w1 {w1}, seed {seed}, measured v: K = {k} ± {se_k}, n = {n_exp} ± {se_n}");
        assert!((k / 4.0 - 1.0).abs() < 0.05 && (n_exp / 1.5 - 1.0).abs() < 0.05);
        // In mm/s, or of the other sign: flagged with the likely mistake, and not used.
        let w = warnings(dir.path(), "v_mm.csv", "");
        assert!(w.iter().any(|w| w.contains("in mm/s")), "{w:?}");
        let w = warnings(dir.path(), "v_sign.csv", "");
        assert!(w.iter().any(|w| w.contains("sign")), "{w:?}");
        let out = dir.path().join("v_mm");
        run_ok("fit", &experiment(dir.path(), "v_mm.csv", ""), &out);
        let ([k_mm, _], _) = power_law(&out);
        assert!((k_mm / 4.0 - 1.0).abs() < 0.05, "K = {k_mm} with v flagged");
    }
}
