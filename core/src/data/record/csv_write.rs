//! Writing a record as CSV to any `impl Write`: every number in the shortest text that reads
//! back to the same `f64`. Where the bytes go — and writing a file atomically (a temporary
//! file beside it, synced, then renamed into place) — is the caller's: the program does it
//! in `stf_lab::writing`.
//!
//! Numbers come from `ryu` (shortest round-trip digits, without `fmt`'s machinery or an
//! allocation per number) and keep the layout the writer has always had — plain notation for
//! 1e-4 ≤ |v| < 1e15 (`0.1`, `-0`, `123456.789`), exponent notation outside (`1e-7`,
//! `5e-324`, `1e300`). Where two shortest texts are equally near the number, ryu takes the
//! even last digit and `fmt` (the writer before it) the upper one: both read back exactly.

use super::{Record, RecordError};
use std::io::Write;

/// Rows are gathered into a buffer this big before each write.
const CHUNK: usize = 1 << 20;

/// Append the shortest text that parses back to exactly `v` (finite) to `out`: plain
/// notation for ordinary magnitudes, exponent notation for very small or large ones (Rust's
/// `{}` and `{:e}` forms).
pub(super) fn push_f64(out: &mut Vec<u8>, v: f64, digits: &mut ryu::Buffer) {
    let a = v.abs();
    let plain = a == 0.0 || (1e-4..1e15).contains(&a);
    if !v.is_finite() || (!plain && (1e-5..1e16).contains(&a)) {
        // ryu writes 1e-5 ≤ |v| < 1e-4 and 1e15 ≤ |v| < 1e16 plainly: `fmt` says those.
        let text = if plain {
            format!("{v}")
        } else {
            format!("{v:e}")
        };
        out.extend_from_slice(text.as_bytes());
        return;
    }
    let text = digits.format_finite(v).as_bytes();
    // ryu ends whole numbers in `.0`, which Rust's `{}` leaves out.
    let text = match text.strip_suffix(b".0") {
        Some(whole) if plain => whole,
        _ => text,
    };
    out.extend_from_slice(text);
}

/// [`push_f64`] as a string.
#[cfg(test)]
pub(super) fn format_f64(v: f64) -> String {
    let mut out = Vec::new();
    push_f64(&mut out, v, &mut ryu::Buffer::new());
    String::from_utf8(out).unwrap_or_default()
}

/// The columns a record writes, in order: `t, phi, x, f_stf, omega, u` (those present).
fn columns(record: &Record) -> Vec<(&'static str, &[f64])> {
    let mut columns: Vec<(&str, &[f64])> = vec![("t", &record.t)];
    if let Some(phi) = &record.phi {
        columns.push(("phi", phi));
    }
    columns.push(("x", &record.x));
    for (label, values) in [
        ("f_stf", &record.f_stf),
        ("omega", &record.omega),
        ("u", &record.u),
    ] {
        if let Some(v) = values {
            columns.push((label, v));
        }
    }
    columns
}

/// Write a (validated) record to `out`, a chunk at a time.
pub(super) fn write(record: &Record, out: &mut impl Write) -> Result<(), RecordError> {
    write_rows(out, &columns(record)).map_err(|e| {
        RecordError::new(
            &record.source,
            format!("cannot write the record as CSV: {e}"),
        )
    })
}

/// The header and the rows, gathered a chunk at a time.
fn write_rows(file: &mut impl Write, columns: &[(&str, &[f64])]) -> std::io::Result<()> {
    let mut chunk = Vec::with_capacity(CHUNK + 4096);
    let header: Vec<&str> = columns.iter().map(|(label, _)| *label).collect();
    chunk.extend_from_slice(header.join(",").as_bytes());
    chunk.push(b'\n');
    let mut digits = ryu::Buffer::new();
    let rows = columns.first().map_or(0, |(_, values)| values.len());
    for i in 0..rows {
        for (k, (_, values)) in columns.iter().enumerate() {
            if k > 0 {
                chunk.push(b',');
            }
            push_f64(
                &mut chunk,
                values.get(i).copied().unwrap_or(f64::NAN),
                &mut digits,
            );
        }
        chunk.push(b'\n');
        if chunk.len() >= CHUNK {
            file.write_all(&chunk)?;
            chunk.clear();
        }
    }
    file.write_all(&chunk)?;
    file.flush()
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests may unwrap
mod tests {
    use super::*;
    use rand::{rngs::StdRng, Rng, SeedableRng};

    /// The writer's text before `ryu`: `{}` for ordinary magnitudes, `{:e}` outside.
    fn fmt_reference(v: f64) -> String {
        let a = v.abs();
        if a == 0.0 || (1e-4..1e15).contains(&a) {
            format!("{v}")
        } else {
            format!("{v:e}")
        }
    }

    #[test]
    fn awkward_floats_are_shortest_and_read_back_exactly() {
        let awkward = [
            0.1,
            -0.0,
            0.0,
            1e300,
            -1e300,
            5e-324,
            -5e-324,
            2.2250738585072014e-308,
            2.225073858507201e-308, // largest subnormal
            1e-5,
            9.99e-5,
            1e-4,
            123456.789,
            1e15,
            1.5e15,
            9.999999999999998e15,
            1e16,
            f64::MAX,
            f64::MIN_POSITIVE,
            1.0 / 3.0,
            2.0,
            -7.0,
            0.30000000000000004,
        ];
        for v in awkward {
            let s = format_f64(v);
            check_against_fmt(v, &s);
            assert!(s.len() < 26, "{s}");
        }
        assert_eq!(format_f64(0.1), "0.1");
        assert_eq!(format_f64(-0.0), "-0");
        assert_eq!(format_f64(1e300), "1e300");
        assert_eq!(format_f64(5e-324), "5e-324");
    }

    /// As short as `fmt`'s shortest text, in the same notation, and reading back exactly. (The
    /// last digit may differ from `fmt`'s where two shortest texts are equally near: ryu rounds
    /// such a tie to even, `fmt` up.)
    fn check_against_fmt(v: f64, s: &str) {
        let reference = fmt_reference(v);
        assert_eq!(s.parse::<f64>().unwrap().to_bits(), v.to_bits(), "{s}");
        assert_eq!(s.len(), reference.len(), "{s} against {reference}");
        assert_eq!(
            s.contains('e'),
            reference.contains('e'),
            "{s} against {reference}"
        );
    }

    #[test]
    fn any_finite_double_is_shortest_in_the_same_notation_and_reads_back_exactly() {
        let mut rng = StdRng::seed_from_u64(11);
        let mut digits = ryu::Buffer::new();
        let mut out = Vec::new();
        let (mut checked, mut same) = (0, 0);
        while checked < 200_000 {
            // Random bit patterns cover every exponent, subnormals included; random
            // magnitudes near the notation's switch points cover those.
            let v = if checked % 2 == 0 {
                f64::from_bits(rng.random::<u64>())
            } else {
                let e = rng.random_range(-6.0..17.0);
                (rng.random::<f64>() - 0.5) * 10f64.powf(e)
            };
            if !v.is_finite() {
                continue;
            }
            out.clear();
            push_f64(&mut out, v, &mut digits);
            let s = std::str::from_utf8(&out).unwrap();
            check_against_fmt(v, s);
            same += usize::from(s == fmt_reference(v));
            checked += 1;
        }
        // Ties are rare: nearly every number is written as `fmt` wrote it.
        assert!(same > checked * 99 / 100, "{same} of {checked}");
    }

    #[test]
    fn a_tie_between_two_shortest_texts_goes_to_the_even_digit() {
        // −97135501438217.625 exactly: `.62` and `.63` are both 16 digits and equally near.
        let v = -(97_135_501_438_217.0 + 0.625); // exact: the sum is a double
        assert_eq!(format_f64(v), "-97135501438217.62");
        assert_eq!(fmt_reference(v), "-97135501438217.63");
        check_against_fmt(v, &format_f64(v));
    }
}
