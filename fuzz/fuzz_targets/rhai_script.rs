//! Any text as a script model: loads and evaluates at its defaults, or fails with a clear
//! error; never a panic or a hang (the sandbox bounds operations, depth and sizes).
#![no_main]
use libfuzzer_sys::fuzz_target;
use stf_core::physics::force_model::{ForceModel, ModelState};
use stf_plugins::ScriptModel;

fuzz_target!(|data: &[u8]| {
    let Ok(source) = std::str::from_utf8(data) else {
        return;
    };
    if let Ok(model) = ScriptModel::from_source("fuzz", source) {
        let p: Vec<f64> = model.params().iter().map(|s| s.default).collect();
        let z = vec![0.0; model.n_internal()];
        let mut dz = vec![0.0; model.n_internal()];
        let s = ModelState { t: 0.1, x: 0.01, v: -0.2, z: &z };
        let _ = model.force(&p, &s, &mut dz);
        let _ = model.added_mass(&p, &s);
    }
});
