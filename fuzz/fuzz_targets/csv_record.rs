//! Any bytes as a CSV record: a record or a clear error, never a panic or a hang.
#![no_main]
use libfuzzer_sys::fuzz_target;
use stf_core::data::record::Record;

fuzz_target!(|data: &[u8]| {
    let _ = Record::read_csv_from(data, "fuzz.csv");
});
