//! The study API gives the command line's numbers: the prelude's walk-through (its rustdoc
//! example, `study/src/prelude.rs`) run in this process on the bundled experiments, and the
//! same experiments through `stf-lab`; every fitted value, RMS, AIC, ranking and discovered
//! effect agrees with the command's JSON (which carries 15 significant digits): the whole
//! document, key by key.

mod common;

use serde_json::Value;
use stf_study::digits::carried;
use stf_study::prelude::*;

/// `a` and the JSON number `b` agree to the JSON's digits (`null` for a non-finite value).
fn same(a: f64, b: &Value, what: &str) {
    match b.as_f64() {
        Some(b) => assert_eq!(carried(a), b, "{what}: library {a} vs JSON {b}"),
        None => assert!(
            !a.is_finite() && b.is_null(),
            "{what}: library {a} vs JSON {b}"
        ),
    }
}

/// A result as its JSON file holds it (digits tidied as the writer tidies them).
fn library_json(doc: impl serde::Serialize) -> Value {
    let mut v = serde_json::to_value(doc).unwrap();
    stf_study::digits::tidy_json(&mut v);
    v
}

/// The library's document equals the command's, key by key, timings (`…seconds`) aside; a
/// difference is named by its path.
fn assert_same_json(lib: &Value, cli: &Value, path: &str) {
    match (lib, cli) {
        (Value::Object(a), Value::Object(b)) => {
            let keys: std::collections::BTreeSet<_> = a.keys().chain(b.keys()).collect();
            for k in keys.into_iter().filter(|k| !k.contains("seconds")) {
                let (x, y) = (&a.get(k), &b.get(k));
                let (x, y) = (x.unwrap_or(&Value::Null), y.unwrap_or(&Value::Null));
                assert!(
                    a.contains_key(k) == b.contains_key(k),
                    "{path}.{k}: only in one"
                );
                assert_same_json(x, y, &format!("{path}.{k}"));
            }
        }
        (Value::Array(a), Value::Array(b)) => {
            assert_eq!(a.len(), b.len(), "{path}: lengths");
            for (i, (x, y)) in a.iter().zip(b).enumerate() {
                assert_same_json(x, y, &format!("{path}[{i}]"));
            }
        }
        (Value::Number(a), Value::Number(b)) => {
            let (a, b) = (a.as_f64().unwrap(), b.as_f64().unwrap());
            // Sums over threads may round a value that is zero in exact arithmetic
            // differently (a phase of 1e-15°): equal to 1e-12 relative, or 1e-12 absolute.
            let close = (a - b).abs() <= 1e-12 * a.abs().max(b.abs()).max(1.0);
            assert!(close, "{path}: library {a} against command line {b}");
        }
        _ => assert_eq!(lib, cli, "{path}: library against command line"),
    }
}

fn experiment(name: &str) -> Experiment {
    read_experiment(common::root().join("experiments").join(name)).expect("bundled experiment")
}

#[test]
fn fitting_from_the_library_gives_the_command_lines_numbers() {
    let mut exp = experiment("power_law_fit.toml");
    let fitted = fit(&mut exp, &Silent).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("pl");
    common::run_ok("fit", &exp.path, &out);
    let json = common::read_json(&out.join("fit.json"));
    assert_same_json(&library_json(fitted.json(&exp)), &json, "fit.json");
    let models = json["models"].as_array().unwrap();
    assert_eq!(models.len(), fitted.fits.len());
    for (f, m) in fitted.fits.iter().zip(models) {
        same(f.result.rms, &m["rms"], &format!("{} rms", f.label));
        same(f.result.aic, &m["aic"], &format!("{} aic", f.label));
        for p in &f.result.params {
            same(
                p.value,
                &m["params"][&p.name],
                &format!("{}.{}", f.label, p.name),
            );
            let se = &m["std_errors"][&p.name];
            same(
                p.std_error,
                se,
                &format!("{}.{} std error", f.label, p.name),
            );
        }
        assert_eq!(f.warnings.len(), m["warnings"].as_array().unwrap().len());
    }
}

#[test]
fn comparing_from_the_library_gives_the_command_lines_ranking() {
    let mut exp = experiment("jamming_compare.toml");
    let result = compare(&mut exp, &Silent).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("cmp");
    common::run_ok("compare", &exp.path, &out);
    let json = common::read_json(&out.join("compare.json"));
    let text = library_json(result.json(&exp));
    assert_same_json(&text, &json, "compare.json");
    assert_eq!(text["models"].as_array().unwrap().len(), 4);
    for (m, j) in text["models"]
        .as_array()
        .unwrap()
        .iter()
        .zip(json["models"].as_array().unwrap())
    {
        let (a, b) = (&m["fit"]["rms"], &j["fit"]["rms"]);
        same(a.as_f64().unwrap(), b, "compare rms");
    }
}

#[test]
fn discovering_from_the_library_names_what_the_command_line_names() {
    let mut exp = experiment("discovery.toml");
    let found = discover(&mut exp, &Silent).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("disc");
    common::run_ok("discover", &exp.path, &out);
    let json = common::read_json(&out.join("discovery.json"));
    let effects: Vec<&str> = json["effects"]
        .as_array()
        .unwrap()
        .iter()
        .map(|e| e.as_str().unwrap())
        .collect();
    assert_eq!(found.found.effects, effects);
    assert!(
        !effects.is_empty(),
        "the bundled discovery finds its hidden effect"
    );
    same(found.found.gap_before, &json["gap_before"], "gap_before");
    same(found.found.gap_after, &json["gap_after"], "gap_after");
    same(found.found.noise_floor, &json["noise_floor"], "noise_floor");
    let (doc, _) = found.json(&exp).unwrap();
    assert_same_json(&library_json(doc), &json, "discovery.json");
}

#[test]
fn a_bad_experiment_is_an_error_of_its_kind_naming_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("exp.toml");
    std::fs::write(
        &path,
        "[data]\nfile = \"missing.csv\"\n[[models]]\nname = \"power_law\"\n",
    )
    .unwrap();
    let mut exp = read_experiment(&path).unwrap();
    let err = fit(&mut exp, &Silent).err().expect("no record");
    assert_eq!(err.kind, ErrorKind::Experiment);
    assert!(err.message.contains("data.file"), "{}", err.message);
    std::fs::write(&path, "[data]\nfile = 3\n").unwrap();
    let err = read_experiment(&path).expect_err("a number is no file name");
    assert!(err.message.contains("exp.toml:2"), "{}", err.message);
}

#[test]
fn settings_built_in_code_fit_as_the_same_experiment_file_does() {
    let record = common::root().join("experiments/records/power_law_sweep.csv");
    let mut built = Experiment::for_record(&record)
        .unwrap()
        .with_model("power_law")
        .with_model("viscous");
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("exp.toml");
    let text = format!(
        "[data]\nfile = {:?}\n[[models]]\nname = \"power_law\"\n[[models]]\nname = \"viscous\"\n",
        record.display().to_string()
    );
    std::fs::write(&path, text).unwrap();
    let mut read = read_experiment(&path).unwrap();
    let (a, b) = (
        fit(&mut built, &Silent).unwrap(),
        fit(&mut read, &Silent).unwrap(),
    );
    assert_eq!(a.fits.len(), 2);
    for (x, y) in a.fits.iter().zip(&b.fits) {
        assert_eq!(x.label, y.label);
        assert_eq!(x.result.rms, y.result.rms, "{}", x.label);
        assert_eq!(x.model_values(), y.model_values(), "{}", x.label);
    }
}
