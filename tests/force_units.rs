//! A force-level record whose force is a voltage read with a gain of 1 (x and `f_stf` both in
//! V: an electronic rig, or a force sensor left uncalibrated) carries its force in V in every
//! figure: the axes and CSV columns of the time history, the hysteresis loops, the measured
//! and fitted force and discovery's residuals say `F_STF, V`, never `F_STF, N`; discovery's
//! `gap_unit` is `V`; discover's gap lines and compare's noise floor and on-threshold, in the
//! terminal and in compare.md, say V. The same record with its force in N keeps `F_STF, N`.

mod common;

use std::path::Path;

use common::{damper_record, read_json, run_ok, terminal, write_file};

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

/// The value and unit of the number after `key` in `line` (`rms 68.6186 V` → ("68.6186", "V")).
fn number_after(line: &str, key: &str) -> Option<(String, String)> {
    let rest = &line[line.find(key)? + key.len()..];
    let mut words = rest.split_whitespace();
    let value = words.next()?.to_string();
    let unit = words.next()?.trim_end_matches([')', ':', ',']).to_string();
    Some((value, unit))
}

/// A fit's warning above the noise floor is written in the unit and scale of the terminal's
/// summary line above it and of `fit.json`'s `rms_unit`: V for a force read in volts, N for a
/// force read in kN (shown in SI N, as the summary shows it) or in N; the message stored in
/// `fit.json` is the sentence the terminal prints.
#[test]
fn a_fit_warning_speaks_the_summary_s_unit() {
    let tmp = tempfile::tempdir().unwrap();
    damper_record(tmp.path(), 7, 3.0);
    let cases = [
        ("{ x = \"V\", f_stf = { unit = \"V\", gain = 1.0 } }", "V"),
        ("{ f_stf = \"kN\" }", "N"),
        ("{ x = \"V\" }", "N"),
    ];
    for (i, (units, unit)) in cases.into_iter().enumerate() {
        let exp = write_file(
            tmp.path(),
            &format!("w{i}.toml"),
            &format!(
                "[data]\nfile = \"r.csv\"\nunits = {units}\n\n[fit]\nlevel = \"force\"\n\n\
                 [[models]]\nname = \"viscous\"\n"
            ),
        );
        let out = tmp.path().join(format!("w{i}"));
        let run = run_ok("fit", &exp, &out);
        let said = String::from_utf8_lossy(&run.stdout).to_string();
        let summary = said
            .lines()
            .find_map(|l| {
                l.trim_start()
                    .starts_with("viscous ")
                    .then(|| number_after(l, " rms "))
            })
            .flatten()
            .unwrap_or_else(|| panic!("{units}: no summary line in\n{said}"));
        let warning = said
            .lines()
            .find(|l| l.contains("warning: the residual is"))
            .unwrap_or_else(|| panic!("{units}: viscous alone leaves no warning in\n{said}"));
        let quoted = number_after(warning, "(RMS ").unwrap();
        let floor = number_after(warning, " against ").unwrap();
        assert_eq!(summary.1, unit, "{units}: {said}");
        assert_eq!(quoted, summary, "{units}: {warning}");
        assert_eq!(floor.1, unit, "{units}: {warning}");
        let doc = read_json(&out.join("fit.json"));
        let model = &doc["models"][0];
        let si = model["rms_unit"].as_str().unwrap();
        assert_eq!(si, unit, "{units}");
        let message = model["warnings"][0]["message"].as_str().unwrap();
        assert!(
            warning.trim_start().ends_with(message),
            "{units}: {message} against {warning}"
        );
    }
}

/// The force numbers a run says, with their unit: the discovery's gaps and floor, the
/// comparison's noise floor and on-threshold, in the terminal and in compare.md.
fn force_words(dir: &Path, units: &str) -> Vec<String> {
    let exp = experiment(dir, units);
    let disc = terminal(&run_ok("discover", &exp, &dir.join("disc")));
    let cmp_out = dir.join("cmp");
    let cmp = terminal(&run_ok("compare", &exp, &cmp_out));
    let md = std::fs::read_to_string(cmp_out.join("compare.md")).unwrap();
    let mut out = Vec::new();
    for (text, key) in [
        (&disc, "`: gap "),
        (&disc, "(noise floor "),
        (&cmp, "noise floor σ = "),
        (&md, "noise floor σ = "),
        (&md, "|F_STF| above "),
    ] {
        let line = text.lines().find(|l| l.contains(key));
        let line = line.unwrap_or_else(|| panic!("no `{key}` in\n{text}"));
        let (_, unit) = number_after(line, key).unwrap_or_else(|| panic!("{key}: {line}"));
        out.push(format!("{key}{}", unit.trim_end_matches(['.', ';', ')'])));
    }
    out
}

#[test]
fn a_force_read_in_volts_is_said_in_volts_by_discover_and_compare() {
    let tmp = tempfile::tempdir().unwrap();
    let volts = force_words(
        tmp.path(),
        "{ x = \"V\", f_stf = { unit = \"V\", gain = 1.0 } }",
    );
    for w in &volts {
        assert!(w.ends_with('V'), "{volts:?}");
    }
    let tmp = tempfile::tempdir().unwrap();
    let newtons = force_words(tmp.path(), "{ x = \"m\" }");
    for w in &newtons {
        assert!(w.ends_with('N'), "{newtons:?}");
    }
}
