//! Any bytes as a MATLAB .mat record: a record or a clear error, never a panic or a hang.
#![no_main]
use libfuzzer_sys::fuzz_target;
use stf_core::data::record::ReadOptions;

fuzz_target!(|data: &[u8]| {
    // A cap well under the fuzzer's memory limit: a small input may inflate to it.
    let _ = ReadOptions::default()
        .max_bytes(64 << 20)
        .read_mat_bytes(data, "fuzz.mat");
});
