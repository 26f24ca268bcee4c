//! End-to-end tests of `stf-lab campaign` on the bundled example (`experiments/campaign/`:
//! 9 records, 3 forcing amplitudes × 3 concentrations, K = 4·(c/0.40)^6): the table's rows,
//! the law recovered record by record, resuming, a unit run alone, a failed unit's row and
//! bad campaign input refused before any unit starts.

mod common;

use std::path::{Path, PathBuf};
use std::process::Output;

use common::{read_json, root, stf_lab};

/// The bundled campaign copied into a temporary folder (records are changed by the tests).
fn bundled_copy(dir: &Path) -> PathBuf {
    let from = root().join("experiments/campaign");
    let to = dir.join("campaign");
    std::fs::create_dir_all(to.join("records")).unwrap();
    for sub in ["", "records"] {
        for entry in std::fs::read_dir(from.join(sub)).unwrap() {
            let entry = entry.unwrap();
            if entry.file_type().unwrap().is_file() {
                std::fs::copy(entry.path(), to.join(sub).join(entry.file_name())).unwrap();
            }
        }
    }
    to.join("campaign.toml")
}

/// `stf-lab campaign CAMPAIGN --out OUT ARGS…`.
fn campaign(file: &Path, out: &Path, args: &[&str]) -> Output {
    stf_lab()
        .arg("campaign")
        .arg(file)
        .arg("--out")
        .arg(out)
        .args(args)
        .output()
        .unwrap()
}

fn stdout(o: &Output) -> String {
    String::from_utf8_lossy(&o.stdout).into_owned()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The law the bundled records were made with.
fn k_law(concentration: f64) -> f64 {
    4.0 * (concentration / 0.40).powi(6)
}

/// The rows of campaign.json.
fn rows(out: &Path) -> Vec<serde_json::Value> {
    read_json(&out.join("campaign.json"))["rows"]
        .as_array()
        .unwrap()
        .clone()
}

#[test]
fn the_bundled_campaign_tabulates_every_record_and_model_and_resumes() {
    let tmp = tempfile::tempdir().unwrap();
    let file = bundled_copy(tmp.path());
    let out = tmp.path().join("out");
    let first = campaign(&file, &out, &["--jobs", "2"]);
    assert!(first.status.success(), "{}", stderr(&first));
    assert_eq!(
        stdout(&first).matches(": ok, ").count(),
        10,
        "{}",
        stdout(&first)
    );

    // One row per record × model, with conditions, parameters and verdicts.
    let rows = rows(&out);
    assert_eq!(rows.len(), 20);
    let power: Vec<&serde_json::Value> =
        rows.iter().filter(|r| r["model"] == "power_law").collect();
    assert_eq!(power.len(), 10);
    let mut worst: f64 = 0.0;
    for r in &power {
        assert_eq!(r["status"], "ok");
        assert_eq!(r["converged"], true);
        let c = r["conditions"]["concentration"].as_f64().unwrap();
        let k = r["params"]["K"]["value"].as_f64().unwrap();
        let se = r["params"]["K"]["std_error"].as_f64().unwrap();
        let z = (k - k_law(c)) / se;
        worst = worst.max(z.abs());
        assert!(
            z.abs() < 3.0,
            "{}: K {k} ± {se} against {}",
            r["record"],
            k_law(c)
        );
    }
    println!("largest |K − law| over its standard error: {worst:.2}");
    // The verdict: one best model per unit.
    for unit in 1..=10 {
        let best = rows
            .iter()
            .filter(|r| r["unit"] == unit && r["best"] == true)
            .count();
        assert_eq!(best, 1, "unit {unit}");
    }
    let csv = std::fs::read_to_string(out.join("campaign.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert!(
        header.starts_with("unit,record,command,status,F0,concentration,model,")
            && header.contains(",K,K_std_error,n,n_std_error,"),
        "{header}"
    );
    assert_eq!(csv.lines().count(), 21);

    // A second run skips every unit and leaves their results as they were.
    let unit_json = out.join("units/001-a1_c1/unit.json");
    let before = std::fs::read(&unit_json).unwrap();
    let second = campaign(&file, &out, &["--jobs", "2"]);
    assert!(second.status.success(), "{}", stderr(&second));
    assert_eq!(
        stdout(&second).matches("skipped").count(),
        10,
        "{}",
        stdout(&second)
    );
    assert!(stdout(&second).contains("10 unit(s), 0 to run"));
    assert_eq!(std::fs::read(&unit_json).unwrap(), before);

    // A changed record reruns its unit alone; so does a unit whose unit.json is missing (a
    // unit killed midway writes none).
    let record = file.parent().unwrap().join("records/a1_c1.csv");
    let other = file.parent().unwrap().join("records/a1_c2.csv");
    std::fs::copy(&other, &record).unwrap();
    std::fs::remove_file(out.join("units/005-a2_c2/unit.json")).unwrap();
    let third = campaign(&file, &out, &["--jobs", "2"]);
    assert!(third.status.success(), "{}", stderr(&third));
    let said = stdout(&third);
    assert!(
        said.contains("unit 1 (records/a1_c1.csv): its inputs changed: rerun"),
        "{said}"
    );
    assert!(said.contains("10 unit(s), 2 to run"), "{said}");
    assert_eq!(said.matches("skipped").count(), 8, "{said}");
    assert!(said.contains("unit 5 records/a2_c2.csv: ok"), "{said}");
    let k1 = rows_k(&out, 1);
    let k2 = rows_k(&out, 2);
    assert_eq!(k1, k2, "unit 1 now fits unit 2's record");
}

/// The power law's K in unit `unit`'s row.
fn rows_k(out: &Path, unit: usize) -> f64 {
    rows(out)
        .iter()
        .find(|r| r["unit"] == unit && r["model"] == "power_law")
        .unwrap()["params"]["K"]["value"]
        .as_f64()
        .unwrap()
}

#[test]
fn a_unit_run_alone_writes_what_the_runner_writes() {
    let tmp = tempfile::tempdir().unwrap();
    let file = bundled_copy(tmp.path());
    let text = std::fs::read_to_string(&file).unwrap();
    // The first two records only.
    let cut: String = text
        .split("\n[[records]]")
        .take(3)
        .collect::<Vec<_>>()
        .join("\n[[records]]");
    std::fs::write(&file, cut).unwrap();
    let all = tmp.path().join("all");
    let run = campaign(&file, &all, &["--jobs", "1", "--quiet"]);
    assert!(run.status.success(), "{}", stderr(&run));
    let alone = tmp.path().join("alone");
    let run = campaign(&file, &alone, &["--unit", "2", "--quiet"]);
    assert!(run.status.success(), "{}", stderr(&run));
    for name in ["fit.json", "params.csv", "fitted.csv"] {
        assert_eq!(
            std::fs::read(all.join("units/002-a1_c2").join(name)).unwrap(),
            std::fs::read(alone.join("units/002-a1_c2").join(name)).unwrap(),
            "{name}"
        );
    }
    let a = read_json(&all.join("units/002-a1_c2/unit.json"));
    let b = read_json(&alone.join("units/002-a1_c2/unit.json"));
    assert_eq!(a["inputs_hash"], b["inputs_hash"]);
    let e = stderr(&campaign(&file, &alone, &["--unit", "3"]));
    assert!(
        e.contains("no unit 3: the campaign has units 1 to 2"),
        "{e}"
    );
}

#[test]
fn a_failed_unit_is_a_row_with_its_error_and_the_others_still_run() {
    let tmp = tempfile::tempdir().unwrap();
    let file = bundled_copy(tmp.path());
    let dir = file.parent().unwrap();
    std::fs::write(dir.join("records/broken.csv"), "t,phi,x\n0,0,0\n1,zero,0\n").unwrap();
    let text = std::fs::read_to_string(&file).unwrap();
    let cut: String = text
        .split("\n[[records]]")
        .take(2)
        .collect::<Vec<_>>()
        .join("\n[[records]]");
    let cut =
        format!("{cut}\n[[records]]\nfile = \"records/broken.csv\"\nF0 = 1\nconcentration = 0.5\n");
    std::fs::write(&file, cut).unwrap();
    let out = tmp.path().join("out");
    let run = campaign(&file, &out, &["--quiet"]);
    assert!(!run.status.success());
    assert!(
        stderr(&run).contains("1 of 2 unit(s) failed"),
        "{}",
        stderr(&run)
    );
    let rows = rows(&out);
    assert_eq!(rows.len(), 3);
    let failed = rows.iter().find(|r| r["unit"] == 2).unwrap();
    assert_eq!(failed["status"], "failed");
    assert!(
        failed["error"].as_str().unwrap().contains("broken.csv"),
        "{failed}"
    );
    assert_eq!(failed["conditions"]["F0"], 1.0);
    let unit = read_json(&out.join("units/002-broken/unit.json"));
    assert_eq!(unit["status"], "failed");
    // A failed unit is tried again on the next run.
    let again = campaign(&file, &out, &[]);
    assert!(stdout(&again).contains("unit 2 (records/broken.csv): it failed last time: rerun"));
}

#[test]
fn bad_campaign_input_is_refused_before_any_unit_starts() {
    let tmp = tempfile::tempdir().unwrap();
    let file = bundled_copy(tmp.path());
    let dir = file.parent().unwrap();
    let text = std::fs::read_to_string(&file).unwrap();
    let line_of = |needle: &str, t: &str| t[..t.find(needle).unwrap()].matches('\n').count() + 1;
    let cases: Vec<(String, String, String)> = vec![
        {
            let t = text.replacen("records/a2_c2.csv", "records/missing.csv", 1);
            let at = line_of("records/missing.csv", &t);
            (
                t,
                format!(":{at}: `records[4].file`: no such record"),
                "missing record".into(),
            )
        },
        {
            let t = text.replacen("concentration = 0.36", "concentration = \"high\"", 1);
            let at = line_of("\"high\"", &t);
            (
                t,
                format!(":{at}: `records[0].concentration`: a condition is a finite number, found the string \"high\""),
                "not a number".into(),
            )
        },
        {
            let t = text.replacen("command = \"fit\"", "command = \"fitt\"", 1);
            let at = line_of("\"fitt\"", &t);
            (
                t,
                format!(":{at}: `campaign.command`: unknown value `fitt`"),
                "unknown command".into(),
            )
        },
        {
            let t = text.replacen(
                "experiment = \"power_law.toml\"",
                "experiment = \"bad.toml\"",
                1,
            );
            std::fs::write(dir.join("bad.toml"), "[system]\nm = 7.65\nstifnes = 3\n").unwrap();
            (
                t,
                "bad.toml:3: `system`: unknown key `stifnes`".into(),
                "experiment that does not parse".into(),
            )
        },
    ];
    for (t, expected, what) in cases {
        assert_refused_before_any_unit(&file, tmp.path(), &t, &what, &expected);
    }
    // A folder holding anything a campaign does not write is refused.
    std::fs::write(&file, &text).unwrap();
    let out = tmp.path().join("notes");
    std::fs::create_dir(&out).unwrap();
    std::fs::write(out.join("notes.txt"), "mine").unwrap();
    let e = stderr(&campaign(&file, &out, &[]));
    assert!(
        e.contains("holds notes.txt, which a campaign does not write"),
        "{e}"
    );
    assert_eq!(std::fs::read(out.join("notes.txt")).unwrap(), b"mine");
}

#[test]
fn the_report_draws_each_parameter_against_each_condition() {
    let tmp = tempfile::tempdir().unwrap();
    let file = bundled_copy(tmp.path());
    let out = tmp.path().join("out");
    let run = campaign(&file, &out, &["--quiet"]);
    assert!(run.status.success(), "{}", stderr(&run));
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    for figure in [
        "power_law_K_vs_concentration",
        "power_law_n_vs_F0",
        "viscous_c_s_vs_F0",
    ] {
        assert!(md.contains(&format!("figures/{figure}.png")), "{figure}");
        assert!(
            out.join(format!("figures/{figure}.png")).is_file(),
            "{figure}"
        );
    }
    // The figure's data are the table's: the K of each record with its error, by F0; the
    // axes carry the units (K's from its ParamSpec, F0's from `campaign.units`, none given
    // for the concentration).
    let csv =
        std::fs::read_to_string(out.join("figures/power_law_K_vs_concentration.csv")).unwrap();
    let header = csv.lines().next().unwrap();
    assert!(
        header.starts_with(
            "F0 = 0.035 kg·m: concentration,F0 = 0.035 kg·m: K [N·(s/m)ⁿ],F0 = 0.035 kg·m: \
             standard error,"
        ),
        "{header}"
    );
    for (figure, axis) in [
        ("power_law_n_vs_F0", "n [–]"),
        ("power_law_n_vs_F0", "F0 [kg·m]"),
        ("viscous_c_s_vs_F0", "c_s [N·s/m]"),
        ("global_K_vs_concentration", "K [N·(s/m)ⁿ]"),
    ] {
        let svg = std::fs::read_to_string(out.join(format!("figures/{figure}.svg"))).unwrap();
        assert!(svg.contains(axis), "{figure}: no axis `{axis}`");
    }
    // The header and a row per concentration (four at F0 = 0.0462, three at the others).
    assert_eq!(csv.lines().count(), 5);
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    // The 6 parameter figures and the global fit's law.
    assert_eq!(html.matches("<svg class=\"figure").count(), 7);
}

#[test]
fn the_global_fit_recovers_the_law_and_beats_per_record_fits_on_the_held_out_record() {
    let tmp = tempfile::tempdir().unwrap();
    let file = bundled_copy(tmp.path());
    let out = tmp.path().join("out");
    let run = campaign(&file, &out, &["--quiet"]);
    assert!(run.status.success(), "{}", stderr(&run));
    let g = read_json(&out.join("global.json"));
    let param = |name: &str| {
        let p = g["params"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["name"] == name)
            .unwrap_or_else(|| panic!("no {name} in {g}"));
        (
            p["value"].as_f64().unwrap(),
            p["std_error"].as_f64().unwrap(),
        )
    };
    // K = 4·(c/0.40)^6, n = 1.5: the exponent within 5 % and within 3 standard errors.
    let (p, p_se) = param("K_p");
    assert!((p - 6.0).abs() < 0.05 * 6.0, "K_p = {p}");
    assert!((p - 6.0).abs() < 3.0 * p_se, "K_p = {p} ± {p_se}");
    let (k0, k0_se) = param("K0");
    assert!((k0 - 4.0).abs() < 3.0 * k0_se, "K0 = {k0} ± {k0_se}");
    let (n, n_se) = param("n");
    assert!((n - 1.5).abs() < 3.0 * n_se, "n = {n} ± {n_se}");
    assert_eq!(g["params"].as_array().unwrap().len(), 3, "{}", g["params"]);
    assert_eq!(g["laws"][0]["exponent"].as_f64().unwrap(), p);
    // Fitted on the 9 others; the global fit wins on BIC and on the held-out record, a
    // concentration (0.46) beyond those fitted: the law extrapolates, the nearest records
    // (0.44) do not.
    assert_eq!(g["records"].as_array().unwrap().len(), 9);
    let h = &g["holdout"];
    assert_eq!(h["record"], "records/a2_c4.csv");
    assert_eq!(
        h["per_record_from"],
        serde_json::json!([
            "records/a1_c3.csv",
            "records/a2_c3.csv",
            "records/a3_c3.csv"
        ])
    );
    let (global, alone) = (
        h["global_rms"].as_f64().unwrap(),
        h["per_record_rms"].as_f64().unwrap(),
    );
    assert!(
        global < 0.8 * alone,
        "held-out RMS {global} against {alone}"
    );
    // Close to the record's own fit: the law's K at 0.46 is right.
    let own = h["own_fit_rms"].as_f64().unwrap();
    assert!(
        global < 1.02 * own,
        "held-out RMS {global} against its own fit's {own}"
    );
    assert!(g["delta_bic"].as_f64().unwrap() < 0.0, "{}", g["delta_bic"]);
    assert_eq!(g["per_record"]["n_params"], 18);
    assert_eq!(g["supported"], true);
    assert!(
        g["caveats"].as_array().unwrap().is_empty(),
        "{}",
        g["caveats"]
    );
    println!(
        "K_p = {p} ± {p_se}, K0 = {k0} ± {k0_se}, n = {n} ± {n_se}; held-out RMS global \
         {global} N, per record {alone} N; ΔBIC {}",
        g["delta_bic"]
    );
    // The report opens with the global fit and its figure.
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    let global_at = md.find("## Global fit").expect("a Global fit section");
    assert!(global_at < md.find("## Parameters against").unwrap());
    assert!(md.contains("Sharing supported"), "{md}");
    assert!(out.join("figures/global_K_vs_concentration.png").is_file());
    let csv = std::fs::read_to_string(out.join("figures/global_K_vs_concentration.csv")).unwrap();
    assert!(csv.lines().next().unwrap().contains("global law"), "{csv}");
}

/// A campaign of 4 `simulate` records (the rig's sensors on, two sweep rates, four seeds) of
/// a yield force F_y = 0.1 + 0.1·voltage N at voltages 0–3 V, fitted with `yield` and a
/// `[global]` section whose `laws` line is `law`.
fn yield_campaign(dir: &Path, law: &str) -> PathBuf {
    let truth = YieldTruth {
        voltages: &[0.0, 1.0, 2.0, 3.0],
        f_y: &|v| 0.1 + 0.1 * v,
        seed: 300,
        rates: [0.3, 0.2],
        level: "force",
    };
    yield_campaign_of(dir, law, &truth)
}

/// The records of a yield campaign: one per voltage, F_y a function of it, seeds from `seed`
/// on, the sweep rates (rad/s², 3 → 9 rad/s) alternating from the first; the records fitted
/// (and the `[global]` fit run) at `level`.
struct YieldTruth<'a> {
    voltages: &'a [f64],
    f_y: &'a dyn Fn(f64) -> f64,
    seed: u64,
    rates: [f64; 2],
    level: &'a str,
}

/// [`yield_campaign`] of `truth`: 20 s records at 100 Hz of the forced rig (F0 0.0462 kg·m).
fn yield_campaign_of(dir: &Path, law: &str, truth: &YieldTruth) -> PathBuf {
    let mut records = String::new();
    for (i, &v) in truth.voltages.iter().enumerate() {
        let alpha = truth.rates[i % 2];
        let make = format!(
            "[system]\npreset = \"forced\"\nF0 = 0.0462\n\n[simulate]\n\
             sweep = {{ w0 = 3.0, alpha = {alpha}, t0 = 0.0, t1 = 20.0 }}\nrate = 100.0\n\
             noise = true\nseed = {}\n\n[[simulate.truth]]\nname = \"yield\"\n\
             params = {{ F_y = {} }}\n",
            truth.seed + i as u64,
            (truth.f_y)(v)
        );
        let sim = dir.join(format!("r{i}.toml"));
        std::fs::write(&sim, make).unwrap();
        let run = stf_lab()
            .arg("simulate")
            .arg(&sim)
            .arg("--out")
            .arg(dir.join(format!("r{i}.csv")))
            .output()
            .unwrap();
        assert!(run.status.success(), "{}", stderr(&run));
        records.push_str(&format!(
            "[[records]]\nfile = \"r{i}.csv\"\nvoltage = {v:?}\n\n"
        ));
    }
    // At trajectory level the records' own oscillator is simulated: the rig as it was set.
    let rig = match truth.level {
        "trajectory" => {
            "[system]\npreset = \"forced\"\nF0 = 0.0462\n\n[fit]\nlevel = \"trajectory\"\n\n"
        }
        _ => "",
    };
    std::fs::write(
        dir.join("yield.toml"),
        format!("{rig}[data]\nfile = \"r0.csv\"\n\n[[models]]\nname = \"yield\"\n"),
    )
    .unwrap();
    let file = dir.join("campaign.toml");
    std::fs::write(
        &file,
        format!(
            "[campaign]\nexperiment = \"yield.toml\"\ncommand = \"fit\"\n\
             conditions = [\"voltage\"]\nunits = {{ voltage = \"V\" }}\n\n{records}\
             [global]\nmodel = \"yield\"\nshared = [\"v_s\"]\n{law}\n"
        ),
    )
    .unwrap();
    file
}

/// Run the campaign `file` into `dir/out` and read its `global.json`.
fn global_of(file: &Path, dir: &Path) -> serde_json::Value {
    let out = dir.join("out");
    let run = campaign(file, &out, &["--quiet"]);
    assert!(run.status.success(), "{}", stderr(&run));
    read_json(&out.join("global.json"))
}

/// Each of `truth`'s coefficients of `g` within 3 standard errors; their z, printed.
fn within_3_se(g: &serde_json::Value, truth: &[(&str, f64)], case: &str) {
    for &(name, want) in truth {
        let (got, se) = global_param(g, name);
        let z = (got - want) / se;
        println!("{case}: {name} = {got} ± {se} (truth {want}), z {z:.2}");
        assert!(z.abs() < 3.0, "{case}: {name} = {got} ± {se}, truth {want}");
    }
}

#[test]
fn an_affine_global_law_with_an_offset_is_recovered_from_a_zero_condition_up() {
    let tmp = tempfile::tempdir().unwrap();
    let file = yield_campaign(
        tmp.path(),
        "laws = { F_y = { condition = \"voltage\", law = \"affine\" } }",
    );
    let out = tmp.path().join("out");
    let run = campaign(&file, &out, &[]);
    assert!(run.status.success(), "{}", stderr(&run));
    let g = read_json(&out.join("global.json"));
    // Every entry of θ with its unit, in global.json and on the terminal's line.
    let unit_of = |name: &str| {
        g["params"]
            .as_array()
            .unwrap()
            .iter()
            .find(|p| p["name"] == name)
            .map(|p| p["unit"].as_str().unwrap().to_string())
    };
    assert_eq!(unit_of("F_y_base").as_deref(), Some("N"));
    assert_eq!(unit_of("F_y_gain").as_deref(), Some("N/V"));
    assert_eq!(unit_of("v_s").as_deref(), Some("m/s"));
    let said = String::from_utf8_lossy(&run.stdout);
    let line = said
        .lines()
        .find(|l| l.contains("over the records:"))
        .unwrap_or_else(|| panic!("no line of θ in\n{said}"));
    assert!(
        line.contains(" N/V (law coefficient)") && line.contains(" m/s (shared)"),
        "{line}"
    );
    let (base, base_se) = global_param(&g, "F_y_base");
    let (gain, gain_se) = global_param(&g, "F_y_gain");
    println!("F_y_base = {base} ± {base_se} (0.1), F_y_gain = {gain} ± {gain_se} (0.1)");
    assert!(
        (base - 0.1).abs() < 3.0 * base_se,
        "F_y_base = {base} ± {base_se}"
    );
    assert!(
        (gain - 0.1).abs() < 3.0 * gain_se,
        "F_y_gain = {gain} ± {gain_se}"
    );
    assert!(base_se < 0.02 && gain_se < 0.01, "{base_se}, {gain_se}");
    let law = &g["laws"][0];
    assert_eq!(law["law"], "affine");
    assert_eq!(law["reference"], 1.0);
    assert!(law.get("exponent").is_none(), "{law}");
    let k = law["coefficients"].as_array().unwrap();
    assert_eq!(k.len(), 2);
    assert_eq!(
        (&k[0]["name"], &k[0]["unit"]),
        (&"F_y_base".into(), &"N".into())
    );
    assert_eq!(
        (&k[1]["name"], &k[1]["unit"]),
        (&"F_y_gain".into(), &"N/V".into())
    );
    assert_eq!(k[1]["value"].as_f64().unwrap(), gain);
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        md.contains("with F_y = F_y_base + F_y_gain·voltage"),
        "{md}"
    );
    assert!(out.join("figures/global_F_y_vs_voltage.png").is_file());
}

/// A power law with an offset, F_y = 0.1 + 0.1·V^1.5 N at V = 0, 0.5, 1, 1.5, 2, recovered
/// at force level on two sets of records (two seeds each, the two sweep rates swapped
/// between them), each coefficient within 3 standard errors.
#[test]
fn a_global_power_law_with_an_offset_is_recovered_on_records_with_the_rigs_sensors() {
    let law = "laws = { F_y = { condition = \"voltage\", law = \"power\", reference = 1.0 } }";
    for (seed, rates) in [(400, [0.3, 0.2]), (500, [0.2, 0.3])] {
        let tmp = tempfile::tempdir().unwrap();
        let truth = YieldTruth {
            voltages: &[0.0, 0.5, 1.0, 1.5, 2.0],
            f_y: &|v: f64| 0.1 + 0.1 * v.powf(1.5),
            seed,
            rates,
            level: "force",
        };
        let g = global_of(&yield_campaign_of(tmp.path(), law, &truth), tmp.path());
        assert_eq!(g["laws"][0]["law"], "power");
        let case = format!("seeds from {seed}, sweeps {rates:?} rad/s²");
        within_3_se(
            &g,
            &[("F_y_base", 0.1), ("F_y_gain", 0.1), ("F_y_exp", 1.5)],
            &case,
        );
    }
}

/// An affine `[global]` law at trajectory level: the records fitted from x alone (their
/// oscillator simulated), F_y = 0.1 + 0.1·V N at V = 0–3 on two seeds' records at two sweep
/// rates, each coefficient within 3 standard errors.
#[test]
fn an_affine_global_law_is_recovered_at_trajectory_level() {
    let law = "laws = { F_y = { condition = \"voltage\", law = \"affine\" } }";
    let tmp = tempfile::tempdir().unwrap();
    let truth = YieldTruth {
        voltages: &[0.0, 1.0, 2.0, 3.0],
        f_y: &|v| 0.1 + 0.1 * v,
        seed: 600,
        rates: [0.3, 0.2],
        level: "trajectory",
    };
    let g = global_of(&yield_campaign_of(tmp.path(), law, &truth), tmp.path());
    assert_eq!(
        (g["level"].as_str(), g["laws"][0]["law"].as_str()),
        (Some("trajectory"), Some("affine"))
    );
    within_3_se(
        &g,
        &[("F_y_base", 0.1), ("F_y_gain", 0.1)],
        "trajectory level",
    );
    let rms = g["global"]["rms"].as_f64().unwrap();
    assert!(
        rms < 0.07,
        "global RMS {rms} mm: near the x noise (0.05 mm)"
    );
}

/// The parameter `name` of global.json's θ: value and standard error.
fn global_param(g: &serde_json::Value, name: &str) -> (f64, f64) {
    let p = g["params"]
        .as_array()
        .unwrap()
        .iter()
        .find(|p| p["name"] == name)
        .unwrap_or_else(|| panic!("no {name} in {g}"));
    (
        p["value"].as_f64().unwrap(),
        p["std_error"].as_f64().unwrap(),
    )
}

#[test]
fn the_trajectory_level_global_fit_recovers_the_law_from_x_alone() {
    let tmp = tempfile::tempdir().unwrap();
    let file = bundled_copy(tmp.path()).with_file_name("trajectory_campaign.toml");
    let out = tmp.path().join("out");
    let run = campaign(&file, &out, &["--quiet"]);
    assert!(run.status.success(), "{}", stderr(&run));
    let g = read_json(&out.join("global.json"));
    assert_eq!(
        (g["level"].as_str(), g["rms_unit"].as_str()),
        (Some("trajectory"), Some("mm"))
    );
    // K = 4·(c/0.40)^6, n = 1.5: the exponent within 5 % and within 2 standard errors.
    let (p, p_se) = global_param(&g, "K_p");
    assert!((p - 6.0).abs() < 0.05 * 6.0, "K_p = {p}");
    assert!((p - 6.0).abs() < 2.0 * p_se, "K_p = {p} ± {p_se}");
    let (k0, k0_se) = global_param(&g, "K0");
    assert!((k0 - 4.0).abs() < 3.0 * k0_se, "K0 = {k0} ± {k0_se}");
    let (n, n_se) = global_param(&g, "n");
    assert!((n - 1.5).abs() < 0.01 * 1.5, "n = {n}");
    assert!((n - 1.5).abs() < 3.0 * n_se, "n = {n} ± {n_se}");
    // θ: K0, K_p, n and each training record's own initial state x0@N, v0@N.
    let names: Vec<&str> = g["params"]
        .as_array()
        .unwrap()
        .iter()
        .map(|p| p["name"].as_str().unwrap())
        .collect();
    assert_eq!(names.len(), 3 + 2 * 9, "{names:?}");
    assert!(names.contains(&"x0@1") && names.contains(&"v0@9") && !names.contains(&"x0@10"));
    // RMS in mm, near the records' x noise (0.05 mm); the held-out record (concentration
    // 0.46, beyond those fitted) is predicted by the law as well as by its own fit, far
    // better than by the nearest records' own values.
    let rms = g["global"]["rms"].as_f64().unwrap();
    assert!(rms > 0.04 && rms < 0.06, "global RMS {rms} mm");
    let h = &g["holdout"];
    let (global, alone, own) = (
        h["global_rms"].as_f64().unwrap(),
        h["per_record_rms"].as_f64().unwrap(),
        h["own_fit_rms"].as_f64().unwrap(),
    );
    assert!(
        global < 0.8 * alone,
        "held-out RMS {global} against {alone}"
    );
    assert!(
        global < 1.02 * own,
        "held-out RMS {global} against its own fit's {own}"
    );
    assert!(g["delta_bic"].as_f64().unwrap() < 0.0, "{}", g["delta_bic"]);
    assert_eq!(g["supported"], true);
    println!(
        "trajectory: K_p = {p} ± {p_se}, K0 = {k0} ± {k0_se}, n = {n} ± {n_se}; held-out RMS \
         global {global} mm, per record {alone} mm, own {own} mm; ΔBIC {}; global step {} s, \
         joint fit {} s",
        g["delta_bic"], g["wall_seconds"], g["joint_fit_seconds"]
    );
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(md.contains("displacement (trajectory level)"), "{md}");
    assert!(md.contains(" mm"), "{md}");
}

#[test]
fn a_rerun_removes_stale_figures_and_lists_stale_unit_folders() {
    let tmp = tempfile::tempdir().unwrap();
    let file = bundled_copy(tmp.path());
    let out = tmp.path().join("out");
    let run = campaign(&file, &out, &["--quiet"]);
    assert!(run.status.success(), "{}", stderr(&run));
    assert!(out.join("figures/global_K_vs_concentration.png").is_file());
    assert_eq!(rows(&out).len(), 20);
    // The held-out record and [global] removed from the campaign: its figure goes, its unit
    // folder stays (the user's results) and is named.
    let text = std::fs::read_to_string(&file).unwrap();
    let last = text.find("# A denser suspension").unwrap();
    std::fs::write(&file, &text[..last]).unwrap();
    let run = campaign(&file, &out, &["--quiet"]);
    assert!(run.status.success(), "{}", stderr(&run));
    assert!(!out.join("figures/global_K_vs_concentration.png").exists());
    assert!(!out.join("figures/global_K_vs_concentration.csv").exists());
    assert!(out
        .join("figures/power_law_K_vs_concentration.png")
        .is_file());
    assert!(out.join("units/010-a2_c4/unit.json").is_file());
    let json = read_json(&out.join("campaign.json"));
    assert_eq!(json["stale_units"], serde_json::json!(["010-a2_c4"]));
    assert_eq!(rows(&out).len(), 18);
    let md = std::fs::read_to_string(out.join("report.md")).unwrap();
    assert!(
        md.contains("units/ holds 1 folder(s) that no unit of this campaign writes"),
        "{md}"
    );
    assert!(md.contains("010-a2_c4"), "{md}");
}

#[test]
fn bad_global_input_is_refused_before_any_unit_starts() {
    let tmp = tempfile::tempdir().unwrap();
    let file = bundled_copy(tmp.path());
    let text = std::fs::read_to_string(&file).unwrap();
    let line_of = |needle: &str, t: &str| t[..t.rfind(needle).unwrap()].matches('\n').count() + 1;
    let cases: Vec<(String, &str, String)> = vec![
        (
            "shared = [\"n\"]",
            "shared = [\"m\"]",
            "`global.shared[0]`: `power_law` has no parameter `m` (it has: K, n)",
        ),
        (
            "condition = \"concentration\"",
            "condition = \"fill\"",
            "`global.laws.K.condition`: `fill` is not a condition",
        ),
        (
            "holdout = \"records/a2_c4.csv\"",
            "holdout = \"records/a9.csv\"",
            "`global.holdout`: `records/a9.csv` is not a record of this campaign",
        ),
        (
            "model = \"power_law\"",
            "model = \"bingham\"",
            "`global.model`: `bingham` is not a [[models]] entry",
        ),
        (
            "laws = { K =",
            "laws = { c =",
            "`global.laws.c`: `power_law` has no parameter `c`",
        ),
        (
            "reference = 0.40 }",
            "law = \"cubic\" }",
            "`global.laws.K.law`: unknown law `cubic`: one of linear, affine, power",
        ),
        (
            "reference = 0.40 }",
            "law = \"power\" }",
            "`global.laws.K.reference`: missing: a `power` law divides the condition",
        ),
    ]
    .into_iter()
    .map(|(from, to, msg)| {
        let t = text.replacen(from, to, 1);
        let at = line_of(to, &t);
        (t, to, format!(":{at}: {msg}"))
    })
    .collect();
    for (t, what, expected) in cases {
        assert_refused_before_any_unit(&file, tmp.path(), &t, what, &expected);
    }
}

/// Write campaign text `t` to `file` and run it into `dir/out`: it must fail, naming the
/// campaign file and `expected`, before any unit starts (no `out` folder). `what` names the case.
fn assert_refused_before_any_unit(file: &Path, dir: &Path, t: &str, what: &str, expected: &str) {
    std::fs::write(file, t).unwrap();
    let out = dir.join("out");
    let run = campaign(file, &out, &[]);
    assert!(!run.status.success(), "{what}");
    let e = stderr(&run);
    assert!(
        e.contains("campaign.toml") && e.contains(expected),
        "{what}: {e}\nexpected {expected}"
    );
    assert!(!out.exists(), "{what}: a unit started");
}

/// The bundled campaign cut to its first `n` records (the `[global]` section dropped).
fn first_records(dir: &Path, n: usize) -> PathBuf {
    let file = bundled_copy(dir);
    let text = std::fs::read_to_string(&file).unwrap();
    let cut: String = text
        .split("\n[[records]]")
        .take(n + 1)
        .collect::<Vec<_>>()
        .join("\n[[records]]");
    let cut = match cut.find("\n[global]") {
        Some(at) => cut[..at].to_string(),
        None => cut,
    };
    std::fs::write(&file, cut).unwrap();
    file
}

/// Processes still running whose command line names `out` (the units of a campaign into it).
fn live_units(out: &Path) -> Vec<String> {
    let needle = out.as_os_str().as_encoded_bytes().to_vec();
    let Ok(procs) = std::fs::read_dir("/proc") else {
        return Vec::new();
    };
    procs
        .filter_map(|e| e.ok())
        .filter_map(|e| {
            let cmdline = std::fs::read(e.path().join("cmdline")).ok()?;
            let named = cmdline
                .windows(needle.len())
                .any(|w| w == needle.as_slice());
            named.then(|| String::from_utf8_lossy(&cmdline).replace('\0', " "))
        })
        .collect()
}

/// Hidden names (this program's temporaries) directly in `dir`.
fn hidden(dir: &Path) -> Vec<String> {
    std::fs::read_dir(dir)
        .map(|d| {
            d.filter_map(|e| e.ok())
                .map(|e| e.file_name().to_string_lossy().into_owned())
                .filter(|n| n.starts_with('.'))
                .collect()
        })
        .unwrap_or_default()
}

/// Start `stf-lab campaign FILE --out OUT ARGS…`, wait for its first finished unit, then send
/// `signal`: its exit status, stdout and stderr.
fn signalled_after_first_unit(
    file: &Path,
    out: &Path,
    args: &[&str],
    signal: &str,
) -> (std::process::ExitStatus, String, String) {
    use std::io::{BufRead, Read};
    let mut child = stf_lab()
        .arg("campaign")
        .arg(file)
        .arg("--out")
        .arg(out)
        .args(args)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let mut lines = std::io::BufReader::new(child.stdout.take().unwrap()).lines();
    let mut said = String::new();
    for line in lines.by_ref() {
        let line = line.unwrap();
        said.push_str(&line);
        said.push('\n');
        if line.contains(": ok, ") {
            break;
        }
    }
    let sent = std::process::Command::new("kill")
        .args([signal, &child.id().to_string()])
        .status()
        .unwrap();
    assert!(sent.success());
    for line in lines {
        said.push_str(&line.unwrap());
        said.push('\n');
    }
    let mut err = String::new();
    child
        .stderr
        .take()
        .unwrap()
        .read_to_string(&mut err)
        .unwrap();
    (child.wait().unwrap(), said, err)
}

/// The units whose unit.json says ok.
fn ok_units(out: &Path) -> usize {
    std::fs::read_dir(out.join("units"))
        .map(|d| {
            d.filter_map(|e| e.ok())
                .filter(|e| {
                    std::fs::read(e.path().join("unit.json"))
                        .ok()
                        .and_then(|b| serde_json::from_slice::<serde_json::Value>(&b).ok())
                        .is_some_and(|u| u["status"] == "ok")
                })
                .count()
        })
        .unwrap_or(0)
}

#[test]
fn sigterm_stops_the_units_and_counts_what_finished() {
    let tmp = tempfile::tempdir().unwrap();
    let file = first_records(tmp.path(), 6);
    let out = tmp.path().join("out");
    let (status, said, err) = signalled_after_first_unit(&file, &out, &["--jobs", "1"], "-TERM");
    assert_eq!(status.code(), Some(130), "{said}\n{err}");
    // When the campaign has exited its units have too: none goes on writing.
    assert_eq!(live_units(&out), Vec::<String>::new());
    let finished = ok_units(&out);
    assert!(finished >= 1, "{said}");
    assert!(
        err.contains(&format!(
            "interrupted: {finished} of 6 unit(s) to run had finished"
        )),
        "{finished} finished: {err}"
    );
    assert!(
        err.contains("the campaign's table and report were not written"),
        "{err}"
    );
    assert!(!out.join("campaign.json").exists());
    // Every log is in place, none left staged.
    assert_eq!(hidden(&out.join("logs")), Vec::<String>::new());
    assert_eq!(hidden(&out.join("units")), Vec::<String>::new());
    assert_eq!(hidden(&out), Vec::<String>::new());
}

#[test]
fn a_killed_campaign_leaves_no_unit_running_and_a_rerun_finishes_it() {
    let tmp = tempfile::tempdir().unwrap();
    let file = first_records(tmp.path(), 6);
    let out = tmp.path().join("out");
    let (status, said, _) = signalled_after_first_unit(&file, &out, &["--jobs", "2"], "-KILL");
    assert_eq!(
        std::os::unix::process::ExitStatusExt::signal(&status),
        Some(9),
        "{said}"
    );
    // A rerun at once: units of the killed run still ending are waited for, not failed.
    let rerun = campaign(&file, &out, &["--jobs", "2"]);
    assert!(
        rerun.status.success(),
        "{}\n{}",
        stdout(&rerun),
        stderr(&rerun)
    );
    assert_eq!(ok_units(&out), 6);
    assert_eq!(rows(&out).len(), 12);
    assert!(rows(&out).iter().all(|r| r["status"] == "ok"));
    assert_eq!(live_units(&out), Vec::<String>::new());
    assert_eq!(hidden(&out.join("logs")), Vec::<String>::new());
    assert_eq!(hidden(&out.join("units")), Vec::<String>::new());
    assert_eq!(hidden(&out), Vec::<String>::new());
}

#[test]
fn a_forced_unit_that_refuses_is_failed_not_reported_with_stale_results() {
    let tmp = tempfile::tempdir().unwrap();
    let file = first_records(tmp.path(), 2);
    let out = tmp.path().join("out");
    let first = campaign(&file, &out, &["--quiet"]);
    assert!(first.status.success(), "{}", stderr(&first));
    let unit2 = out.join("units/002-a1_c2");
    let before = std::fs::read(unit2.join("unit.json")).unwrap();
    std::fs::write(unit2.join("notes.txt"), "mine").unwrap();
    let forced = campaign(&file, &out, &["--force"]);
    assert!(!forced.status.success(), "{}", stdout(&forced));
    let said = stdout(&forced);
    assert!(said.contains("unit 2 records/a1_c2.csv: failed"), "{said}");
    assert!(said.contains("unit 1 records/a1_c1.csv: ok"), "{said}");
    let row = rows(&out).into_iter().find(|r| r["unit"] == 2).unwrap();
    assert_eq!(row["status"], "failed");
    assert!(
        row["error"].as_str().unwrap().contains("holds notes.txt"),
        "{row}"
    );
    assert!(
        stderr(&forced).contains("1 of 2 unit(s) failed"),
        "{}",
        stderr(&forced)
    );
    // The user's file is kept; the unit's folder as it was.
    assert_eq!(std::fs::read(unit2.join("notes.txt")).unwrap(), b"mine");
    assert_eq!(std::fs::read(unit2.join("unit.json")).unwrap(), before);
}

#[test]
fn the_tables_go_in_as_one_unit_and_a_cut_commit_is_finished() {
    let tmp = tempfile::tempdir().unwrap();
    let file = first_records(tmp.path(), 2);
    let out = tmp.path().join("out");
    assert!(campaign(&file, &out, &["--quiet"]).status.success());
    // Killed between the renames of the tables: campaign.json in place, the rest staged.
    let killed = stf_lab()
        .arg("campaign")
        .arg(&file)
        .arg("--out")
        .arg(&out)
        .args(["--quiet", "--force"])
        .env("STF_LAB_FAILPOINT", "commit:campaign.json=kill")
        .output()
        .unwrap();
    assert_eq!(
        std::os::unix::process::ExitStatusExt::signal(&killed.status),
        Some(9),
        "{}",
        stderr(&killed)
    );
    let rerun = campaign(&file, &out, &[]);
    assert!(rerun.status.success(), "{}", stderr(&rerun));
    let msg = stderr(&rerun);
    for name in ["campaign.csv", "report.md", "report.html"] {
        assert!(
            msg.contains("was stopped while putting its files in place") && msg.contains(name),
            "{name}: {msg}"
        );
    }
    assert_eq!(hidden(&out), Vec::<String>::new());
    let csv = std::fs::read_to_string(out.join("campaign.csv")).unwrap();
    assert_eq!(csv.lines().count() - 1, rows(&out).len());
}

#[test]
fn user_files_among_the_campaign_figures_are_named_and_kept() {
    let tmp = tempfile::tempdir().unwrap();
    let file = first_records(tmp.path(), 2);
    let out = tmp.path().join("out");
    assert!(campaign(&file, &out, &["--quiet"]).status.success());
    std::fs::create_dir_all(out.join("figures")).unwrap();
    std::fs::write(out.join("figures/mynotes.txt"), "mine").unwrap();
    let run = campaign(&file, &out, &["--force"]);
    assert!(!run.status.success());
    assert!(
        stderr(&run).contains("holds figures/mynotes.txt"),
        "{}",
        stderr(&run)
    );
    assert_eq!(
        std::fs::read(out.join("figures/mynotes.txt")).unwrap(),
        b"mine"
    );
}

#[test]
fn a_condition_named_as_a_column_of_the_table_is_refused() {
    // `model`, `rms`, `status` are columns campaign.csv always has; `n` is power_law's.
    let tmp = tempfile::tempdir().unwrap();
    let file = first_records(tmp.path(), 1);
    let text = std::fs::read_to_string(&file).unwrap();
    let at = text[..text.find("conditions = ").unwrap()]
        .matches('\n')
        .count()
        + 1;
    for (name, says) in [
        ("model", "`model` is a column campaign.csv always has"),
        ("rms", "`rms` is a column campaign.csv always has"),
        ("status", "`status` is a column campaign.csv always has"),
        ("K_std_error", "`K_std_error` ends in `_std_error`"),
        ("n", "`n` is a parameter of power_law in"),
    ] {
        let t = text
            .replace("\"concentration\"", &format!("\"{name}\""))
            .replace("concentration = ", &format!("{name} = "));
        let expected = format!(":{at}: `campaign.conditions[1]`: {says}");
        assert_refused_before_any_unit(&file, tmp.path(), &t, name, &expected);
        let e = stderr(&campaign(&file, &tmp.path().join("out"), &[]));
        assert!(e.contains("choose another name"), "{e}");
    }
}

#[test]
fn a_unit_whose_results_file_was_deleted_runs_again() {
    let tmp = tempfile::tempdir().unwrap();
    let file = first_records(tmp.path(), 1);
    let out = tmp.path().join("out");
    assert!(campaign(&file, &out, &[]).status.success());
    let unit = out.join("units/001-a1_c1");
    std::fs::remove_file(unit.join("fit.json")).unwrap();
    // It failed on every rerun ("cannot read …/fit.json"), skipped as unchanged.
    let run = campaign(&file, &out, &[]);
    assert!(run.status.success(), "{}", stderr(&run));
    assert!(
        stdout(&run).contains("its fit.json is missing from")
            || stderr(&run).contains("its fit.json is missing from"),
        "{}{}",
        stdout(&run),
        stderr(&run)
    );
    assert!(unit.join("fit.json").is_file());
    assert_eq!(rows(&out).iter().filter(|r| r["status"] == "ok").count(), 2);
}
