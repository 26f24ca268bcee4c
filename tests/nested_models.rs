//! A model that contains another (a sum with one more term) never ends worse than the smaller
//! one's optimum: `fit` fits the smaller sum first and starts the larger from its optimum with
//! the added term neutral, keeping the better of that and the fit from the defaults. On
//! damper-like shaker records (viscous + yield, a force of hundreds of N, the rig's sensors)
//! `viscous + yield + maxwell` ends at or below `viscous + yield`'s RMS (it ended at 32.4
//! against 26.5 N on a damper record from its defaults alone).

mod common;

use common::{damper_only_record, damper_record, run_json};

/// The damper record of `seed` on a chirp 0.5 → `f1` Hz, and the experiment fitting both
/// sums to it at force level.
fn damper(dir: &std::path::Path, seed: u64, f1: f64) -> std::path::PathBuf {
    damper_record(dir, seed, f1);
    let fit = "[data]\nfile = \"r.csv\"\n\n[system]\npreset = \"forced\"\nT = 0.0\n\
               delta_T = 0.0\n\n[fit]\nlevel = \"force\"\n\n[[models]]\nname = \"viscous\"\n\
               plus = [\"yield\"]\n\n[[models]]\nname = \"viscous\"\n\
               plus = [\"yield\", \"maxwell\"]\n";
    let fit_path = dir.join("fit.toml");
    std::fs::write(&fit_path, fit).unwrap();
    fit_path
}

/// "Never worse" to within the neutral term's own contribution (a millionth of its default
/// amplitude's: 8e-9 of the RMS was seen) and the fit's tolerance.
#[test]
fn a_sum_with_one_more_term_never_ends_worse_than_the_sum_it_contains() {
    for (seed, f1) in [(1, 3.0), (2, 2.0)] {
        let dir = tempfile::tempdir().unwrap();
        let fit_path = damper(dir.path(), seed, f1);
        let out = dir.path().join("fit");
        let models = run_json("fit", &fit_path, &out, "fit.json")["models"].clone();
        let rms = |i: usize| models[i]["rms"].as_f64().unwrap();
        assert!(
            rms(1) <= rms(0) * (1.0 + 1e-6),
            "seed {seed}: viscous + yield + maxwell rms {} > viscous + yield {}",
            rms(1),
            rms(0)
        );
    }
}

/// The same rule through `compare` on a damper's own record (t, x and the force only, no
/// rotor, no drive, no `[system]`): the richer sum's training RMS is its base's or lower, to
/// the same tolerance, on a record where maxwell helps (seed 6, to 4 Hz: 26.707 against
/// 26.724 N) and on one where it adds nothing (seed 7, to 3 Hz: higher by 4e-8 of itself,
/// within the fit's tolerance).
#[test]
fn compare_on_a_damper_s_own_record_never_ranks_the_richer_sum_worse_in_training() {
    for (seed, f1) in [(6, 4.0), (7, 3.0)] {
        let dir = tempfile::tempdir().unwrap();
        damper_only_record(dir.path(), (seed, f1), "d.csv", |_, force| force);
        let exp = dir.path().join("c.toml");
        std::fs::write(
            &exp,
            "[data]\nfile = \"d.csv\"\ncolumns = { f_stf = \"F\" }\n\n[[models]]\n\
             name = \"viscous\"\nplus = [\"yield\"]\n\n[[models]]\nname = \"viscous\"\n\
             plus = [\"yield\", \"maxwell\"]\n",
        )
        .unwrap();
        let doc = run_json("compare", &exp, &dir.path().join("cmp"), "compare.json");
        let rms = |i: usize| doc["models"][i]["fit"]["rms"].as_f64().unwrap();
        eprintln!("seed {seed}, f1 {f1}: {} against {}", rms(1), rms(0));
        assert!(
            rms(1) <= rms(0) * (1.0 + 1e-6),
            "seed {seed}: viscous + yield + maxwell rms {} > viscous + yield {}",
            rms(1),
            rms(0)
        );
    }
}
