//! Trajectory-level fits from default starts find the truth on records with the rig's own
//! sensors (x noise 0.05 mm quantised to 0.01 mm, a 2048-count encoder), made by
//! `stf-lab simulate`: power_law K and n within 3 %, added mass within 5 %, and the x residual
//! at the record's noise. Two sweep rates and two seeds; the records are 500 Hz.

mod common;

use common::{read_json, run_ok, simulate_ok};

/// Simulate a sweep at `alpha` rad/s² (ω 3 → 9.4 rad/s) with `truth`, then fit `model` at
/// trajectory level from its default starts; fit.json's model.
fn fit_from_defaults(alpha: f64, seed: u64, truth: &str, model: &str) -> serde_json::Value {
    let dir = tempfile::tempdir().unwrap();
    let t1 = (9.4 - 3.0) / alpha;
    let exp = dir.path().join("e.toml");
    std::fs::write(
        &exp,
        format!(
            "[data]\nfile = \"r.csv\"\n\n[fit]\nlevel = \"trajectory\"\n\n[simulate]\n\
             sweep = {{ w0 = 3.0, alpha = {alpha}, t0 = 0.0, t1 = {t1} }}\nrate = 500.0\n\
             noise = true\nseed = {seed}\n\n[[simulate.truth]]\n{truth}\n\n[[models]]\n{model}\n"
        ),
    )
    .unwrap();
    simulate_ok(&exp, &dir.path().join("r.csv"));
    let out = dir.path().join("fit");
    run_ok("fit", &exp, &out);
    let fit = read_json(&out.join("fit.json"));
    let drive = &fit["drive"];
    assert_eq!(drive["method"], "auto", "{drive}");
    assert!((drive["counts_per_rev"].as_f64().unwrap() - 2048.0).abs() < 1e-6);
    fit["models"][0].clone()
}

fn assert_near(model: &serde_json::Value, name: &str, truth: f64, within: f64) {
    let got = model["params"][name].as_f64().unwrap();
    assert!(
        (got / truth - 1.0).abs() < within,
        "{name} = {got}, truth {truth} (±{} %)\n{model}",
        within * 100.0
    );
}

/// The record's x noise: 0.05 mm of Gaussian noise quantised to 0.01 mm.
const X_NOISE_MM: f64 = 0.0501;

#[test]
fn power_law_is_found_from_default_starts() {
    for (alpha, seed) in [(0.2, 1), (0.08, 2)] {
        let m = fit_from_defaults(
            alpha,
            seed,
            "name = \"power_law\"\nparams = { K = 20.0, n = 1.5 }",
            "name = \"power_law\"",
        );
        assert_near(&m, "K", 20.0, 0.03);
        assert_near(&m, "n", 1.5, 0.03);
        let rms_mm = m["rms"].as_f64().unwrap() * 1e3;
        assert!(rms_mm < 1.1 * X_NOISE_MM, "x residual {rms_mm} mm");
    }
}

#[test]
fn power_law_with_added_mass_is_found_from_default_starts() {
    for (alpha, seed) in [(0.2, 3), (0.08, 4)] {
        let m = fit_from_defaults(
            alpha,
            seed,
            "name = \"power_law\"\nplus = [\"added_mass\"]\nparams = { K = 8.0, n = 1.8, m_a = 0.3 }",
            "name = \"power_law\"\nplus = [\"added_mass\"]",
        );
        assert_near(&m, "K", 8.0, 0.03);
        assert_near(&m, "n", 1.8, 0.03);
        assert_near(&m, "m_a", 0.3, 0.05);
        let rms_mm = m["rms"].as_f64().unwrap() * 1e3;
        assert!(rms_mm < 1.1 * X_NOISE_MM, "x residual {rms_mm} mm");
    }
}
