//! How a measured force is held between samples decides what a model must explain. A shaker
//! record whose amplifier held each sample (a DAC's zero-order hold), at 20 samples per period
//! of resonance, with a viscous fluid only: read with linear interpolation between samples the
//! drive leads the true one by half a sample, and trajectory-level discovery "finds" a force
//! with memory (`maxwell`, measured: held-out x RMS 2.15 → 1.04 mm on seed 3); read with
//! `drive = "zoh"` it finds nothing and the base sits at the x noise (S 0.0026 mm²).

mod common;

use common::{read_json, run_ok, simulate_ok};

fn experiment(seed: u64, drive: &str) -> String {
    format!(
        "[data]\nfile = \"r.csv\"\ndrive = \"{drive}\"\n\n[system]\npreset = \"forced\"\nT = 0.0\n\
         delta_T = 0.0\n\n[simulate]\nchirp = {{ f0 = 0.5, f1 = 1.5, amplitude = 2.0, t1 = 40.0, \
         hold = \"zoh\" }}\nrate = 20.0\nnoise = true\nseed = {seed}\n\n[[simulate.truth]]\n\
         name = \"viscous\"\nparams = {{ c_s = 1.0 }}\n\n[discover]\nbase = \"viscous\"\n\
         candidates = [\"maxwell\", \"added_mass\", \"cubic_stiffness\", \"power_law\"]\n\
         level = \"trajectory\"\n"
    )
}

#[test]
fn the_wrong_hold_makes_a_memory_effect_win_and_the_right_one_does_not() {
    for seed in [3, 4] {
        let dir = tempfile::tempdir().unwrap();
        let mut effects = Vec::new();
        for drive in ["samples", "zoh"] {
            let exp = dir.path().join(format!("{drive}.toml"));
            std::fs::write(&exp, experiment(seed, drive)).unwrap();
            if drive == "samples" {
                simulate_ok(&exp, &dir.path().join("r.csv"));
            }
            let out = dir.path().join(drive);
            run_ok("discover", &exp, &out);
            let found = read_json(&out.join("discovery.json"));
            effects.push(found["effects"].clone());
        }
        assert_eq!(
            effects[0],
            serde_json::json!(["maxwell"]),
            "seed {seed}, linear"
        );
        assert_eq!(effects[1], serde_json::json!([]), "seed {seed}, zoh");
    }
}
