//! End to end: a record written in a lab's own layout — two lines before the header,
//! semicolons, decimal commas, time in ms, displacement in mm, angle in degrees, the force
//! as a voltage with a gain, sensor offsets — is read as it is through `[data]` and fits to
//! the truth it was made with, and scores at the sensor noise on a second record in the same
//! layout (`[validate]`).

mod common;

use common::{read_json, run_ok, simulate_ok};

/// A force-level record: 2 s at rest, a quick spin-up, then a sweep through resonance; the
/// STF force is a power law, K = 4, n = 1.5.
const SIMULATE: &str = r#"
[simulate]
profile = { t = [0.0, 2.0, 2.5, 22.5], omega = [0.0, 0.0, 4.0, 8.0] }
rate = 200.0
noise = true
seed = 5

[[simulate.truth]]
name = "power_law"
params = { K = 4.0, n = 1.5 }
"#;

/// The lab's sensor offsets (in the file's units) and the force sensor's gain, N per V.
const X_OFFSET_MM: f64 = 0.37;
const F_OFFSET_V: f64 = -0.08;
const GAIN: f64 = 2.5;

/// The experiment that reads the lab file as it is.
const FIT: &str = r#"
[data]
file = "lab.csv"
skip = 2
decimal = ","
columns = { t = "Zeit [ms]", x = "Weg [mm]", phi = "Winkel [deg]", f_stf = 4 }
units = { t = "ms", x = "mm", phi = "deg", f_stf = { unit = "V", gain = 2.5 } }
offsets = { x = "rest", f_stf = "rest" }
rest = [0.0, 1.95]
window = [2.0, 22.5]

[output]
report = false

[[models]]
name = "power_law"
params = { K = 2.0, n = { value = 1.2, min = 1.0, max = 4.0 } }
"#;

/// A number with a decimal comma.
fn comma(v: f64, decimals: usize) -> String {
    format!("{v:.decimals$}").replace('.', ",")
}

/// Rewrite the simulator's CSV (t, phi, x, f_stf in SI) in the lab's layout.
fn to_lab_layout(si_csv: &str) -> String {
    let mut lines = si_csv.lines();
    assert_eq!(lines.next(), Some("t,phi,x,f_stf"));
    let mut out = String::from(
        "Prüfstand 3; STF-Dämpfer; Lauf 12\nexportiert 2024-05-02 10:41;;;\n\
         Zeit [ms];Weg [mm];Winkel [deg];Kraft [V]\n",
    );
    for line in lines {
        let v: Vec<f64> = line.split(',').map(|c| c.parse().unwrap()).collect();
        let (t, phi, x, f) = (v[0], v[1], v[2], v[3]);
        out += &format!(
            "{};{};{};{}\n",
            comma(t * 1e3, 3),
            comma(x * 1e3 + X_OFFSET_MM, 5),
            comma(phi.to_degrees(), 6),
            comma(f / GAIN + F_OFFSET_V, 7),
        );
    }
    out
}

#[test]
fn a_lab_layout_record_fits_to_the_truth() {
    let dir = tempfile::tempdir().unwrap();
    let sim = dir.path().join("sim.toml");
    std::fs::write(&sim, SIMULATE).unwrap();
    let si = dir.path().join("si.csv");
    simulate_ok(&sim, &si);
    let lab = to_lab_layout(&std::fs::read_to_string(&si).unwrap());
    std::fs::write(dir.path().join("lab.csv"), &lab).unwrap();
    // A separate measurement in the same layout: another run of the rig (seed 6).
    std::fs::write(&sim, SIMULATE.replace("seed = 5", "seed = 6")).unwrap();
    let si_val = dir.path().join("si_val.csv");
    simulate_ok(&sim, &si_val);
    let lab_val = to_lab_layout(&std::fs::read_to_string(&si_val).unwrap());
    std::fs::write(dir.path().join("lab_val.csv"), &lab_val).unwrap();
    let exp = dir.path().join("fit.toml");
    let validated = format!("{FIT}\n[validate]\nfile = \"lab_val.csv\"\nwindow = [2.0, 22.5]\n");
    std::fs::write(&exp, &validated).unwrap();

    let out = dir.path().join("fit");
    let _ = run_ok("fit", &exp, &out);
    let fit = read_json(&out.join("fit.json"));
    let power = &fit["models"][0];
    // Scored on the second measurement, read with the same layout and offsets: the noise.
    let validation = power["validation_rms"].as_f64().unwrap();
    eprintln!("validation rms {validation} N");
    assert!(validation < 0.03, "validation rms {validation}");
    let k = power["params"]["K"].as_f64().unwrap();
    let n = power["params"]["n"].as_f64().unwrap();
    assert!((k / 4.0 - 1.0).abs() < 0.03, "K = {k}");
    assert!((n / 1.5 - 1.0).abs() < 0.03, "n = {n}");
    // The residual is the sensor noise (σ 0.02 N), not a left-over offset of 0.2 N.
    let rms = power["rms"].as_f64().unwrap();
    assert!(rms < 0.03, "rms {rms}");

    // Read without the offsets, the same file leaves the force 0.2 N off.
    let no_offsets = FIT
        .replace("offsets = { x = \"rest\", f_stf = \"rest\" }\n", "")
        .replace("rest = [0.0, 1.95]\n", "");
    std::fs::write(&exp, no_offsets).unwrap();
    let _ = run_ok("fit", &exp, &dir.path().join("raw"));
    let raw = read_json(&dir.path().join("raw/fit.json"));
    let raw_rms = raw["models"][0]["rms"].as_f64().unwrap();
    eprintln!("K = {k}, n = {n}, rms = {rms} N; without the offsets rms = {raw_rms} N");
    assert!(raw_rms > 0.15, "rms without offsets {raw_rms}");
    std::fs::write(&exp, FIT).unwrap();

    // A bad cell is reported at its editor line (the two skipped lines and the header count).
    let mut bad: Vec<&str> = lab.lines().collect();
    bad[9] = "45;0,1.5;0;0";
    std::fs::write(dir.path().join("lab.csv"), bad.join("\n")).unwrap();
    let failed = common::run("fit", &exp, &dir.path().join("bad"));
    assert!(!failed.status.success());
    let stderr = String::from_utf8_lossy(&failed.stderr);
    assert!(
        stderr.contains("lab.csv:row 10, column `Weg [mm]`: not a number: `0,1.5`"),
        "{stderr}"
    );
}

/// Identification stages of the free-vibration record, read with `[data]`'s layout (`{layout}`).
fn identification(record: &str, layout: &str) -> String {
    format!(
        "[data]\n{layout}\n[output]\nreport = false\n\n[system]\nm = 7.65\nk = 294.7\nc = 4.81\n\
         T = 0.461\ndelta_T = 0.0\nF0 = 0.0\neta = 1000.0\n\n[[identify]]\ndata = {record:?}\n\
         free = [\"k\", \"c\", \"T\"]\n"
    )
}

#[test]
fn identification_stages_read_their_records_with_the_data_layout() {
    let dir = tempfile::tempdir().unwrap();
    let si = common::root().join("experiments/records/free_vibration.csv");
    let text = std::fs::read_to_string(&si).unwrap();
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some("t,x,f_stf,u"));
    let mut lab = String::from("Zeit [ms];Weg [mm];Antrieb [mN]\n");
    for line in lines {
        let v: Vec<f64> = line.split(',').map(|c| c.parse().unwrap()).collect();
        let (t, x, u) = (v[0] * 1e3, v[1] * 1e3, v[3] * 1e3);
        lab += &format!("{};{};{}\n", comma(t, 3), comma(x, 6), comma(u, 3));
    }
    std::fs::write(dir.path().join("lab.csv"), lab).unwrap();

    let stage_values = |name: &str, record: &str, layout: &str| {
        let exp = dir.path().join(format!("{name}.toml"));
        std::fs::write(&exp, identification(record, layout)).unwrap();
        let out = dir.path().join(name);
        let _ = run_ok("fit", &exp, &out);
        let fit = read_json(&out.join("fit.json"));
        ["k", "c", "T"].map(|p| fit["stages"][0]["params"][p].as_f64().unwrap())
    };
    let layout = "decimal = \",\"\n\
                  columns = { t = \"Zeit [ms]\", x = \"Weg [mm]\", u = \"Antrieb [mN]\" }\n\
                  units = { t = \"ms\", x = \"mm\", u = \"mN\" }\n";
    let from_lab = stage_values("lab", "lab.csv", layout);
    let from_si = stage_values("si", si.to_str().unwrap(), "");
    eprintln!("k, c, T: lab layout {from_lab:?}, SI {from_si:?}");
    for (a, b) in from_lab.iter().zip(&from_si) {
        assert!(
            (a / b - 1.0).abs() < 1e-4,
            "lab {from_lab:?} vs SI {from_si:?}"
        );
    }

    // Without the layout the same file is not read as a record at all.
    let exp = dir.path().join("plain.toml");
    std::fs::write(&exp, identification("lab.csv", "")).unwrap();
    let failed = common::run("fit", &exp, &dir.path().join("plain"));
    assert!(!failed.status.success());
}
