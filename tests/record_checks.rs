//! Implausible records are refused (or flagged) before anything is fitted: time in the wrong
//! unit, x in mm read as m, a `[data] rate` at odds with the record's `t` column; records of
//! other rigs in volts are left alone, and `[data] plausibility = false` turns it all off.

use std::path::{Path, PathBuf};

use stf_lab::experiment::Experiment;
use stf_lab::fitting::load_data;

/// A rotor record: 60 s at 100 Hz, ω 6 rad/s, x of 20 mm; times scaled by `t_scale`, x by
/// `x_scale`.
fn rotor_csv(dir: &Path, t_scale: f64, x_scale: f64) -> PathBuf {
    let mut text = String::from("t,phi,x\n");
    for i in 0..6000 {
        let t = i as f64 / 100.0;
        let phi = 6.0 * t;
        let x = 0.02 * (phi - 0.3).sin();
        text.push_str(&format!("{},{phi},{}\n", t * t_scale, x * x_scale));
    }
    let path = dir.join("rec.csv");
    std::fs::write(&path, text).unwrap();
    path
}

/// A shaker record of another rig in volts, as its lab writes it: x of 0.9 V (read as m),
/// u in V, 1 kHz, the steady response at 60 Hz of the `[system]` [`VOLTS_SYSTEM`].
fn volts_csv(dir: &Path) -> PathBuf {
    let (m, k, c, gain) = (1.0, 1e5, 20.0, 1e5);
    let w = 2.0 * std::f64::consts::PI * 60.0;
    let (re, im) = (k - m * w * w, c * w);
    let x_amp = 0.9;
    let u_amp = x_amp * (re * re + im * im).sqrt() / gain;
    let lag = im.atan2(re);
    let mut text = String::from("t,x,u\n");
    for i in 0..6000 {
        let t = i as f64 / 1000.0;
        let u = u_amp * (w * t).sin();
        let x = x_amp * (w * t - lag).sin();
        text.push_str(&format!("{t},{x},{u}\n"));
    }
    let path = dir.join("volts.csv");
    std::fs::write(&path, text).unwrap();
    path
}

/// The oscillator of [`volts_csv`] in volt units, and its force sensor's gain.
const VOLTS_SYSTEM: &str = "[system]\nm = 1.0\nk = 1e5\nc = 20.0\nT = 0.0\ndelta_T = 0.0\n";

/// `load_data` of an experiment with `[data]` keys `data` on `file`: the error, if any, and
/// the warnings.
fn load(dir: &Path, file: &Path, data: &str, rest: &str) -> Result<Vec<String>, String> {
    let exp_path = dir.join("exp.toml");
    let text = format!(
        "[data]\nfile = {:?}\n{data}\n{rest}\n[fit]\nlevel = \"trajectory\"\n",
        file.display().to_string()
    );
    std::fs::write(&exp_path, &text).unwrap();
    let mut exp = Experiment::load(&exp_path).map_err(|e| format!("{e:#}"))?;
    load_data(&mut exp)
        .map(|d| d.record_warnings)
        .map_err(|e| format!("{e:#}"))
}

#[test]
fn a_plausible_record_loads_without_a_word() {
    let dir = tempfile::tempdir().unwrap();
    let rec = rotor_csv(dir.path(), 1.0, 1.0);
    assert_eq!(load(dir.path(), &rec, "", ""), Ok(vec![]));
}

#[test]
fn time_a_trillion_times_too_long_is_refused_naming_the_units_key() {
    let dir = tempfile::tempdir().unwrap();
    let rec = rotor_csv(dir.path(), 1e12, 1.0);
    let msg = load(dir.path(), &rec, "", "").unwrap_err();
    assert!(
        msg.contains("exp.toml:1") && msg.contains("rec.csv") && msg.contains("days"),
        "{msg}"
    );
    assert!(
        msg.contains("units = { t = \"ms\" }") && msg.contains("plausibility = false"),
        "{msg}"
    );
}

#[test]
fn time_in_ms_read_as_s_is_refused_by_the_sample_rate() {
    // 60 s at 100 Hz read as 60 000 s at 0.1 Hz: below twice the trolley's 0.95 Hz.
    let dir = tempfile::tempdir().unwrap();
    let rec = rotor_csv(dir.path(), 1000.0, 1.0);
    let msg = load(dir.path(), &rec, "", "").unwrap_err();
    assert!(
        msg.contains("below twice") && msg.contains("units = { t = \"ms\" }"),
        "{msg}"
    );
}

#[test]
fn x_in_mm_read_as_m_is_refused_and_a_large_one_flagged() {
    let dir = tempfile::tempdir().unwrap();
    let rec = rotor_csv(dir.path(), 1.0, 1000.0);
    let msg = load(dir.path(), &rec, "", "").unwrap_err();
    assert!(
        msg.contains("x moves 20") && msg.contains("units = { x = \"mm\" }"),
        "{msg}"
    );
    // With the unit declared it is a 20 mm motion again.
    assert_eq!(
        load(dir.path(), &rec, "units = { x = \"mm\" }", ""),
        Ok(vec![])
    );
    // 0.4 m is possible, but suspicious.
    let rec = rotor_csv(dir.path(), 1.0, 20.0);
    let warnings = load(dir.path(), &rec, "", "").unwrap();
    assert!(
        warnings.len() == 1 && warnings[0].contains("mm read as m"),
        "{warnings:?}"
    );
}

#[test]
fn every_check_is_switched_off_by_the_plausibility_key() {
    let dir = tempfile::tempdir().unwrap();
    let rec = rotor_csv(dir.path(), 1.0, 1000.0);
    assert_eq!(
        load(dir.path(), &rec, "plausibility = false", ""),
        Ok(vec![])
    );
}

#[test]
fn a_record_of_another_rig_in_volts_is_not_judged_by_the_trolley() {
    let dir = tempfile::tempdir().unwrap();
    let rec = volts_csv(dir.path());
    let units = "units = { u = { unit = \"V\", gain = 1e5 } }";
    assert_eq!(load(dir.path(), &rec, units, VOLTS_SYSTEM), Ok(vec![]));
}

#[test]
fn a_rate_at_odds_with_the_t_column_is_flagged() {
    let dir = tempfile::tempdir().unwrap();
    let rec = rotor_csv(dir.path(), 1.0, 1.0);
    let warnings = load(dir.path(), &rec, "rate = 1000.0", "").unwrap();
    assert!(
        warnings.len() == 1
            && warnings[0].contains("`[data] rate` is 1000 Hz")
            && warnings[0].contains("0.100×"),
        "{warnings:?}"
    );
    assert_eq!(load(dir.path(), &rec, "rate = 100.0", ""), Ok(vec![]));
}

#[test]
fn a_validation_record_is_checked_as_the_estimation_record_is() {
    // The validation record's time is in ms read as s; the estimation record is plausible.
    let dir = tempfile::tempdir().unwrap();
    let other = dir.path().join("other.csv");
    std::fs::rename(rotor_csv(dir.path(), 1000.0, 1.0), &other).unwrap();
    let rec = rotor_csv(dir.path(), 1.0, 1.0);
    let exp_path = dir.path().join("exp.toml");
    std::fs::write(
        &exp_path,
        format!(
            "[data]\nfile = {:?}\n\n[validate]\nfile = {:?}\n\n[fit]\nlevel = \"trajectory\"\n",
            rec.display().to_string(),
            other.display().to_string()
        ),
    )
    .unwrap();
    let mut exp = Experiment::load(&exp_path).unwrap();
    let data = load_data(&mut exp).unwrap();
    let Err(e) = stf_lab::validation::load(&exp, &data) else {
        panic!("the validation record's time in ms was not caught");
    };
    let msg = format!("{e:#}");
    assert!(
        msg.contains("exp.toml:5") && msg.contains("validate.file") && msg.contains("other.csv"),
        "{msg}"
    );
    assert!(msg.contains("below twice"), "{msg}");
}
