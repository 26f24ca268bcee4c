//! A force-level record whose force is a voltage read with a gain of 1 (x and `f_stf` both in
//! V: an electronic rig, or a force sensor left uncalibrated) carries its force in V in every
//! figure: the axes and CSV columns of the time history, the hysteresis loops, the measured
//! and fitted force and discovery's residuals say `F_STF, V`, never `F_STF, N`; discovery's
//! `gap_unit` is `V`. The same record with its force in N keeps `F_STF, N`.

mod common;

use std::path::Path;

use common::{damper_record, read_json, run_ok, write_file};

/// The damper record of `common::damper_record` read with `units`, fitted at force level by
/// `viscous` and `viscous + yield`, discovered from `viscous`, with a report.
fn experiment(dir: &Path, units: &str) -> std::path::PathBuf {
    damper_record(dir, 7, 3.0);
    write_file(
        dir,
        "exp.toml",
        &format!(
            "[data]\nfile = \"r.csv\"\nunits = {units}\n\n[fit]\nlevel = \"force\"\n\n\
             [[models]]\nname = \"viscous\"\n\n[[models]]\nname = \"viscous\"\n\
             plus = [\"yield\"]\n\n[discover]\nbase = \"viscous\"\n\n[output]\nreport = true\n"
        ),
    )
}

/// Every figure's CSV header and SVG text under `dir/figures`, by file name.
fn figure_texts(dir: &Path) -> Vec<(String, String)> {
    let figures = dir.join("figures");
    let mut out = Vec::new();
    for entry in std::fs::read_dir(&figures).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        if name.ends_with(".csv") || name.ends_with(".svg") {
            let text = std::fs::read_to_string(&path).unwrap();
            let text = if name.ends_with(".csv") {
                text.lines().next().unwrap_or("").to_string()
            } else {
                text
            };
            out.push((name, text));
        }
    }
    assert!(!out.is_empty(), "no figure in {}", figures.display());
    out
}

/// The figures that label the STF force, and those that label it in newtons.
fn force_labels(texts: &[(String, String)]) -> (Vec<&str>, Vec<&str>) {
    let labelled = texts
        .iter()
        .filter(|(_, t)| t.contains("F_STF,") || t.contains("F_STF measured,"))
        .map(|(n, _)| n.as_str())
        .collect();
    let newtons = texts
        .iter()
        .filter(|(_, t)| {
            t.contains("F_STF, N")
                || t.contains("F_STF measured, N")
                || t.contains("F_STF residual, N")
                || t.contains("F_STF extremum, N")
        })
        .map(|(n, _)| n.as_str())
        .collect();
    (labelled, newtons)
}

#[test]
fn a_force_read_in_volts_is_labelled_in_volts_in_every_figure() {
    let tmp = tempfile::tempdir().unwrap();
    let exp = experiment(
        tmp.path(),
        "{ x = \"V\", f_stf = { unit = \"V\", gain = 1.0 } }",
    );
    let fit = tmp.path().join("fit");
    run_ok("fit", &exp, &fit);
    let texts = figure_texts(&fit);
    let (labelled, newtons) = force_labels(&texts);
    assert!(newtons.is_empty(), "F_STF in N in {newtons:?}");
    for name in [
        "time_history.csv",
        "hysteresis_x.csv",
        "measured_vs_fitted.csv",
    ] {
        assert!(
            labelled.contains(&name),
            "{name} not labelled: {labelled:?}"
        );
    }
    let header = &texts
        .iter()
        .find(|(n, _)| n == "hysteresis_v.csv")
        .unwrap()
        .1;
    assert!(header.contains("F_STF, V"), "{header}");
    assert_eq!(
        read_json(&fit.join("fit.json"))["models"][0]["rms_unit"],
        "V"
    );

    let disc = tmp.path().join("disc");
    run_ok("discover", &exp, &disc);
    assert_eq!(read_json(&disc.join("discovery.json"))["gap_unit"], "V");
    let texts = figure_texts(&disc);
    let (labelled, newtons) = force_labels(&texts);
    assert!(newtons.is_empty(), "F_STF in N in {newtons:?}");
    assert!(
        !labelled.is_empty(),
        "no force figure in discovery's report"
    );
}

#[test]
fn a_force_in_newtons_keeps_newtons() {
    let tmp = tempfile::tempdir().unwrap();
    let exp = experiment(tmp.path(), "{ x = \"m\" }");
    let disc = tmp.path().join("disc");
    run_ok("discover", &exp, &disc);
    assert_eq!(read_json(&disc.join("discovery.json"))["gap_unit"], "N");
    let texts = figure_texts(&disc);
    let (_, newtons) = force_labels(&texts);
    assert!(!newtons.is_empty(), "no figure labels the force in N");
}
