//! Any bytes as a MATLAB .mat record: a record or a clear error, never a panic or a hang.
#![no_main]
use libfuzzer_sys::fuzz_target;
use stf_core::record::ReadOptions;

fuzz_target!(|data: &[u8]| {
    let _ = ReadOptions::default().read_mat_bytes(data, "fuzz.mat");
});
