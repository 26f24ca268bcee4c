//! The digits of a bundled example's tables: every number of `compare.csv` and `cycles.csv`
//! carries at most 15 significant digits (the promise of docs/commands.md: no
//! `0.00015500000000000003`), and none is written `-0`, `-0.0` or with an exponent `e0`.

mod common;

use common::{root, run_ok};

/// Why `cell` is not a number as the outputs promise to write it, if it is not.
fn bad_number(cell: &str) -> Option<&'static str> {
    let is_number = !cell.is_empty()
        && cell
            .chars()
            .all(|c| c.is_ascii_digit() || "-+.e".contains(c))
        && cell.parse::<f64>().is_ok();
    if !is_number {
        return None;
    }
    let mantissa = cell.split('e').next().unwrap_or_default();
    let digits: String = mantissa.chars().filter(char::is_ascii_digit).collect();
    let significant = digits.trim_start_matches('0').len();
    if significant > 15 {
        Some("more than 15 significant digits")
    } else if cell.parse::<f64>().unwrap() == 0.0 && cell.starts_with('-') {
        Some("a negative zero")
    } else if cell.ends_with("e0") || cell.contains("e-0") || cell.contains("e+") {
        Some("a padded exponent")
    } else {
        None
    }
}

#[test]
fn the_scanner_finds_what_it_looks_for() {
    assert_eq!(
        bad_number("0.00015500000000000003"),
        Some("more than 15 significant digits")
    );
    assert_eq!(bad_number("-0.0"), Some("a negative zero"));
    assert_eq!(bad_number("1.5e0"), Some("a padded exponent"));
    for fine in [
        "0.000155",
        "6.204",
        "-41.69",
        "1e300",
        "2.5e-7",
        "power_law",
        "",
    ] {
        assert_eq!(bad_number(fine), None, "{fine}");
    }
}

#[test]
fn compare_s_tables_carry_the_digits_the_readme_promises() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("out");
    run_ok(
        "compare",
        &root().join("experiments/jamming_compare.toml"),
        &out,
    );
    for table in ["compare.csv", "cycles.csv"] {
        let text = std::fs::read_to_string(out.join(table)).unwrap();
        let mut cells = 0;
        for (i, line) in text.lines().enumerate() {
            for cell in line.split(',') {
                cells += 1;
                if let Some(why) = bad_number(cell) {
                    panic!("{table}:{}: `{cell}` has {why}", i + 1);
                }
            }
        }
        assert!(cells > 20, "{table}: {cells} cells");
    }
}
