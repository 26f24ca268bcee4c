//! Record I/O speed: writes and reads a CSV record of 10⁶ rows (t, phi, x, f_stf, u) and
//! prints MB/s. Run with `cargo bench -p stf-core --bench record_io` (release profile).
//!
//! Given a file path (`record_io FILE.csv`), it only reads that file and prints the rate:
//! with `/usr/bin/time -v` this measures a big record's peak memory.
//!
//! A plain `harness = false` target: one write and one read of a realistic record tell the
//! rate well enough, and it needs no benchmarking crate beyond what the tests use.

use std::time::Instant;
use stf_core::data::record::{Record, MEMORY_SOURCE};

/// A record that looks like a simulated sweep: 1 kHz, smooth signals with noise-like digits.
fn record(rows: usize) -> Record {
    let t: Vec<f64> = (0..rows).map(|i| i as f64 * 1e-3).collect();
    let wave = |k: f64, a: f64| -> Vec<f64> {
        t.iter()
            .map(|&t| a * (k * t).sin() + 1e-9 * (t * 7919.0).cos())
            .collect()
    };
    Record {
        source: MEMORY_SOURCE.into(),
        phi: Some(t.iter().map(|&t| 0.0235 * t * t + 2.35 * t).collect()),
        x: wave(6.2, 0.04),
        f_stf: Some(wave(12.4, 1.5)),
        omega: None,
        u: Some(wave(3.1, 0.3)),
        t,
    }
}

fn main() {
    // `cargo bench` passes `--bench`; anything else is a record to read.
    if let Some(file) = std::env::args().skip(1).find(|a| !a.starts_with("--")) {
        let start = Instant::now();
        let rec = Record::read_csv(std::path::Path::new(&file)).expect("the record reads");
        let seconds = start.elapsed().as_secs_f64();
        let mb = std::fs::metadata(&file).map_or(0.0, |m| m.len() as f64 / 1e6);
        println!(
            "read {file}: {} rows, {mb:.1} MB in {seconds:.2} s, {:.0} MB/s",
            rec.len(),
            mb / seconds
        );
        return;
    }
    let rows = 1_000_000;
    let rec = record(rows);
    let dir = tempfile::tempdir().expect("a temporary folder");
    let path = dir.path().join("bench.csv");

    let start = Instant::now();
    let file = std::fs::File::create(&path).expect("the file is created");
    rec.write_csv(std::io::BufWriter::new(file))
        .expect("the record is written");
    let write_s = start.elapsed().as_secs_f64();
    let bytes = std::fs::metadata(&path).expect("the file exists").len() as f64;

    let start = Instant::now();
    let back = Record::read_csv(&path).expect("the record reads back");
    let read_s = start.elapsed().as_secs_f64();
    assert_eq!(back.x, rec.x, "the record reads back exactly");

    let mb = bytes / 1e6;
    println!(
        "record_io: {rows} rows × 5 columns, {mb:.1} MB: write {:.0} MB/s ({:.3} s, synced), read {:.0} MB/s ({:.3} s)",
        mb / write_s,
        write_s,
        mb / read_s,
        read_s
    );
}
