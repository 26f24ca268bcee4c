//! The hysteretic element and the linear spring recovered from records made by `simulate`
//! with the rig's default sensors (noise, encoder steps): `bouc_wen`, fitted from its
//! defaults, within 5 % of the truth at force and trajectory level, on two sweeps (200 Hz and
//! 1 kHz) and more than one seed; and `bouc_wen + linear_spring` (an accumulator beside the
//! hysteresis) with both parts recovered at both levels.

mod common;

use std::path::Path;

use common::{read_json, run_ok, simulate_ok};

/// A sweep `(w0, alpha, t1)` sampled at `rate` with the rig's sensors and `seed`.
struct Sweep {
    w0: f64,
    alpha: f64,
    t1: f64,
    rate: f64,
    seed: u64,
}

/// Simulate `truth` (`[[simulate.truth]]` entries) over `sweep` into `NAME.csv`, fit
/// `models` (`[[models]]` entries, from their defaults) at `level` and return fit.json.
fn simulate_and_fit(
    dir: &Path,
    name: &str,
    sweep: &Sweep,
    (truth, models): (&str, &str),
    level: &str,
) -> serde_json::Value {
    let exp = dir.join(format!("{name}_{level}.toml"));
    let Sweep {
        w0,
        alpha,
        t1,
        rate,
        seed,
    } = sweep;
    std::fs::write(
        &exp,
        format!(
            "[data]\nfile = \"{name}.csv\"\n\n[fit]\nlevel = \"{level}\"\n\n[simulate]\n\
             sweep = {{ w0 = {w0:?}, alpha = {alpha:?}, t0 = 0.0, t1 = {t1:?} }}\n\
             rate = {rate:?}\nnoise = true\nseed = {seed}\n\n{truth}\n\n{models}\n"
        ),
    )
    .unwrap();
    let record = dir.join(format!("{name}.csv"));
    if !record.exists() {
        simulate_ok(&exp, &record);
    }
    let out = dir.join(format!("{name}_{level}_fit"));
    run_ok("fit", &exp, &out);
    read_json(&out.join("fit.json"))
}

/// Every `(name, truth)` of `expected` within 5 % in the params of `model` (fit.json).
fn within_five_percent(model: &serde_json::Value, expected: &[(&str, f64)], what: &str) {
    for (name, truth) in expected {
        let got = model["params"][name].as_f64().unwrap();
        let err = (got - truth).abs() / truth;
        eprintln!(
            "{what}: {name} = {got:.5} (truth {truth}, {:.2} %)",
            100.0 * err
        );
        assert!(err < 0.05, "{what}: {name} = {got} against {truth}");
    }
}

fn bouc_wen_truth(f_bw: f64, x_bw: f64, beta: f64) -> String {
    format!(
        "[[simulate.truth]]\nname = \"bouc_wen\"\n\
         params = {{ F_bw = {f_bw:?}, x_bw = {x_bw:?}, beta = {beta:?} }}"
    )
}

#[test]
fn bouc_wen_is_recovered_within_five_percent_at_both_levels_from_its_defaults() {
    let dir = tempfile::tempdir().unwrap();
    let cases = [
        // Through resonance at 200 Hz, two seeds: a 1 N loop over 3 mm.
        (
            Sweep {
                w0: 4.0,
                alpha: 0.2,
                t1: 20.0,
                rate: 200.0,
                seed: 1,
            },
            (1.0, 3e-3, 0.7),
        ),
        (
            Sweep {
                w0: 4.0,
                alpha: 0.2,
                t1: 20.0,
                rate: 200.0,
                seed: 2,
            },
            (1.0, 3e-3, 0.7),
        ),
        // A wider sweep at 1 kHz: a 0.4 N loop over 1 mm, softer unloading.
        (
            Sweep {
                w0: 3.0,
                alpha: 0.35,
                t1: 18.0,
                rate: 1000.0,
                seed: 3,
            },
            (0.4, 1e-3, 0.4),
        ),
    ];
    for (i, (sweep, (f_bw, x_bw, beta))) in cases.iter().enumerate() {
        let truth = bouc_wen_truth(*f_bw, *x_bw, *beta);
        let expected = [("F_bw", *f_bw), ("x_bw", *x_bw), ("beta", *beta)];
        for level in ["force", "trajectory"] {
            let fit = simulate_and_fit(
                dir.path(),
                &format!("bw{i}"),
                sweep,
                (&truth, "[[models]]\nname = \"bouc_wen\""),
                level,
            );
            let model = &fit["models"][0];
            let what = format!("seed {} at {} Hz, {level}", sweep.seed, sweep.rate);
            within_five_percent(model, &expected, &what);
            let kinds: Vec<&str> = model["warnings"]
                .as_array()
                .unwrap()
                .iter()
                .map(|w| w["kind"].as_str().unwrap())
                .collect();
            assert!(
                !kinds.contains(&"on_bound") && !kinds.contains(&"above_noise_floor"),
                "{what}: {kinds:?}"
            );
        }
    }
}

#[test]
fn a_linear_spring_beside_the_hysteresis_is_recovered_at_both_levels() {
    let dir = tempfile::tempdir().unwrap();
    let sweep = Sweep {
        w0: 4.0,
        alpha: 0.2,
        t1: 20.0,
        rate: 200.0,
        seed: 5,
    };
    let truth = format!(
        "{}\n\n[[simulate.truth]]\nname = \"linear_spring\"\nparams = {{ k_s = 20.0 }}",
        bouc_wen_truth(1.0, 3e-3, 0.7)
    );
    let models = "[[models]]\nname = \"bouc_wen\"\nplus = [\"linear_spring\"]\n\n\
                  [[models]]\nname = \"linear_spring\"";
    for level in ["force", "trajectory"] {
        let fit = simulate_and_fit(dir.path(), "spring", &sweep, (&truth, models), level);
        let both = &fit["models"][0];
        within_five_percent(
            both,
            &[("F_bw", 1.0), ("x_bw", 3e-3), ("beta", 0.7), ("k_s", 20.0)],
            &format!("bouc_wen + linear_spring, {level}"),
        );
        // The spring alone misses the loop by far.
        let alone = fit["models"][1]["rms"].as_f64().unwrap();
        assert!(
            alone > 10.0 * both["rms"].as_f64().unwrap(),
            "{level}: {alone}"
        );
    }
}
