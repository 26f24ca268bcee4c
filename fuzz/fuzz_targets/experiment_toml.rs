//! Any bytes as an experiment file: an experiment or a clear error naming the file and line,
//! never a panic or a hang. Parsing and validation touch no file (the data file and scripts
//! are only joined to the experiment's folder, read later by the commands).
#![no_main]
use std::path::Path;

use libfuzzer_sys::fuzz_target;
use stf_lab::experiment::Experiment;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        let _ = Experiment::parse(Path::new("/nonexistent/fuzz/experiment.toml"), text);
    }
});
