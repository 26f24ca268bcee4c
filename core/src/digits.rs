//! Numbers for a person to read, written in one place: a value rounded to its standard error
//! (`10 004 ± 8`, `4.01 ± 0.06`), a fixed number of decimals without a negative zero, a signed
//! difference (`+0.0`, never `-0.0`). Reports, the terminal and the study's verdicts all call
//! these, and the tables' cells ([`cell`]: 15 significant digits, no negative zero).
//!
//! The error keeps one significant digit, or two when its first digits are 10–35 (the
//! Particle Data Group's rule: `± 8`, `± 0.06`, `± 11`, `± 0.31`), and the value is rounded to
//! the error's last digit. Numbers are plain between 10⁻³ and 10⁶ (integer parts of five digits
//! or more grouped by threes with a space, `19 987`) and in exponent form outside it
//! (`5.34e-6 ± 2.6e-8`), never with an exponent `e0`.
//!
//! ```
//! use stf_core::digits::{fixed, signed, with_error};
//! assert_eq!(with_error(1.0004e4, 8.1), "10 004 ± 8");
//! assert_eq!(with_error(4.0108, 0.060), "4.01 ± 0.06");
//! assert_eq!(with_error(3.02331, 0.313), "3.02 ± 0.31");
//! assert_eq!(fixed(-0.04, 1), "0.0");
//! assert_eq!(signed(-0.04, 1), "+0.0");
//! ```

/// `x` rounded to 15 significant digits (non-finite values and zero as they are): what a
/// double holds faithfully; the 16th and 17th digits of Rust's shortest form are the residue
/// of arithmetic (`0.1 + 0.2` is `0.30000000000000004`), not information.
pub fn carried(x: f64) -> f64 {
    if !x.is_finite() || x == 0.0 {
        return x;
    }
    format!("{x:.14e}").parse().unwrap_or(x)
}

/// A number as a CSV cell or table file writes it: [`carried`] in Rust's shortest form
/// (`0.000155`, never `0.00015500000000000003`), a negative zero as `0`.
pub fn cell(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else {
        carried(x).to_string()
    }
}

/// `x` to `n` significant digits (at least 1) for a person to read, plain between 10⁻³ and
/// 10⁶ (`0.001017`, `12 345.7`: [`grouped`]) and in exponent form outside (`8.78e-4`),
/// trailing zeros dropped.
pub fn significant(x: f64, n: usize) -> String {
    let digits = n.max(1) - 1;
    let x: f64 = format!("{x:.digits$e}").parse().unwrap_or(x);
    if !x.is_finite() || plain(x) {
        let lead = if x == 0.0 || !x.is_finite() {
            0
        } else {
            x.abs().log10().floor() as i32
        };
        let s = fixed(x, (digits as i32 - lead).clamp(0, 12) as usize);
        match s.contains('.') {
            true => grouped(s.trim_end_matches('0').trim_end_matches('.')),
            false => grouped(&s),
        }
    } else {
        format!("{x:e}")
    }
}

/// A number in Rust's shortest form that reads back exactly, a negative zero as `0`: a
/// figure's data, which must be the samples drawn (not rounded to [`cell`]'s 15 digits).
pub fn exact(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else {
        x.to_string()
    }
}

/// `x` with `decimals` decimals for a person to read, never as a negative zero ("-0.0" for
/// -0.04 at one decimal reads as a sign the value does not have).
pub fn fixed(x: f64, decimals: usize) -> String {
    let s = format!("{x:.decimals$}");
    if s.starts_with('-') && s[1..].chars().all(|c| c == '0' || c == '.') {
        return s[1..].to_string();
    }
    s
}

/// A difference with its sign and `decimals` decimals (`+7151.3`, `-2.0`); one that rounds
/// to zero is `+0.0`, never `-0.0`.
pub fn signed(x: f64, decimals: usize) -> String {
    let s = fixed(x, decimals);
    if s.starts_with('-') || !x.is_finite() {
        s
    } else {
        format!("+{s}")
    }
}

/// Whether `x` is written plainly (zero, or between 10⁻³ and 10⁶) rather than with an exponent.
fn plain(x: f64) -> bool {
    x == 0.0 || (1e-3..1e6).contains(&x.abs())
}

/// The integer part of a plain number grouped by threes when it has five digits or more
/// (`19 987.3`, `-123 456`; `2048` stays as it is).
pub fn grouped(s: &str) -> String {
    let (sign, rest) = match s.strip_prefix('-') {
        Some(r) => ("-", r),
        None => ("", s),
    };
    let (int, frac) = rest.split_at(rest.find('.').unwrap_or(rest.len()));
    if int.len() < 5 || !int.chars().all(|c| c.is_ascii_digit()) {
        return s.to_string();
    }
    let mut out = String::new();
    for (i, c) in int.chars().enumerate() {
        if i > 0 && (int.len() - i) % 3 == 0 {
            out.push(' ');
        }
        out.push(c);
    }
    format!("{sign}{out}{frac}")
}

/// `x` with its last digit at the decimal place `10^last`: plain ([`grouped`]) or in exponent
/// form. A nonzero value that would round to zero there keeps one significant digit (`0.1`
/// beside an error of 30 is not `0`).
fn to_digit(x: f64, last: i32) -> String {
    to_digit_as(x, last, plain(x))
}

/// [`to_digit`], plain or in exponent form as `plainly` says (an error beside a value in
/// exponent form is in exponent form too: `2.50e7 ± 4e5`).
fn to_digit_as(x: f64, last: i32, plainly: bool) -> String {
    if !x.is_finite() {
        return x.to_string();
    }
    let lead = if x == 0.0 {
        last
    } else {
        x.abs().log10().floor() as i32
    };
    let last = if x != 0.0 && lead < last { lead } else { last };
    if plainly || x == 0.0 {
        grouped(&fixed(x, (-last).clamp(0, 12) as usize))
    } else {
        let digits = (lead - last).clamp(0, 12) as usize;
        format!("{x:.digits$e}")
    }
}

/// The decimal place of the last digit an error shows: one significant digit, two when its
/// first three digits are 100–354 (an error of 0.0099 is shown as 0.010).
fn last_digit(error: f64) -> i32 {
    let lead = error.log10().floor() as i32;
    let three = (error / 10f64.powi(lead - 2)).round();
    if three >= 999.5 {
        return lead; // 0.0999… rounds to 0.10: two digits of the next decade
    }
    if three < 355.0 {
        lead - 1
    } else {
        lead
    }
}

/// `value` as [`with_error`] shows it beside `error` (the value alone: what an equation
/// writes).
pub fn rounded(value: f64, error: f64) -> String {
    if !(error.is_finite() && error > 0.0) {
        let lead = if value == 0.0 || !value.is_finite() {
            0
        } else {
            value.abs().log10().floor() as i32
        };
        return to_digit(value, lead - 5);
    }
    to_digit(value, last_digit(error))
}

/// `value ± error` for a person to read: the error to one significant digit (two when they
/// start 10–35), the value to the error's last digit, each plain between 10⁻³ and 10⁶ and in
/// exponent form outside it (`5.34e-6 ± 2.6e-8`, not `0.00001 ± 2.57e-8`). Without a usable
/// error (zero, NaN, infinite) the value gets six significant digits and the error is shown
/// as it is.
pub fn with_error(value: f64, error: f64) -> String {
    let (value, error) = value_and_error(value, error);
    format!("{value} ± {error}")
}

/// `value` and `error` as [`with_error`] writes them on either side of its `±`
/// (`("4.01", "0.06")`), for a sentence that names them apart.
pub fn value_and_error(value: f64, error: f64) -> (String, String) {
    if !(error.is_finite() && error > 0.0) {
        return (rounded(value, error), error.to_string());
    }
    let last = last_digit(error);
    // Beside a value of a million or more (in exponent form) the error is in exponent form.
    let plainly = plain(error) && value.abs() < 1e6;
    (to_digit(value, last), to_digit_as(error, last, plainly))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_value_shows_the_digits_its_error_allows() {
        assert_eq!(with_error(5.3362e-6, 2.57e-8), "5.336e-6 ± 2.6e-8");
        assert_eq!(with_error(-51.13313, 8.44), "-51 ± 8");
        assert_eq!(with_error(0.97819, 9.92e-3), "0.978 ± 0.010");
        assert_eq!(with_error(1.0000432e4, 0.45), "10 000.4 ± 0.5");
        assert_eq!(with_error(1.0004e4, 8.1), "10 004 ± 8");
        assert_eq!(with_error(19986.76, 11.3), "19 987 ± 11");
        assert_eq!(with_error(2.0012e4, 23.0), "20 012 ± 23");
        assert_eq!(with_error(4.0108, 0.060), "4.01 ± 0.06");
        assert_eq!(with_error(1.50138, 0.0074), "1.501 ± 0.007");
        // A value far below its error keeps one digit; no error: six significant digits.
        assert_eq!(with_error(2e-5, 5e-3), "2e-5 ± 0.005");
        assert_eq!(with_error(0.1, 30.0), "0.1 ± 30");
        assert_eq!(with_error(1234.5678, 0.0), "1234.57 ± 0");
        assert_eq!(with_error(1234.5678, f64::NAN), "1234.57 ± NaN");
        assert_eq!(with_error(-0.0001, 1e-9), "-1.000000e-4 ± 1.0e-9");
        assert_eq!(with_error(-4.5e-6, 3.3e-6), "-4.5e-6 ± 3.3e-6");
        assert_eq!(with_error(2.5e7, 4.0e5), "2.50e7 ± 4e5");
        assert_eq!(
            value_and_error(1.5184e-4, 5.60e-4),
            ("2e-4".into(), "6e-4".into())
        );
    }

    #[test]
    fn no_shown_number_has_an_exponent_zero_or_a_negative_zero() {
        for (v, e) in [
            (1.0004e4, 8.1),
            (5.0, 0.3),
            (-0.0004, 0.3),
            (9.97, 0.5),
            (0.0, 1.0),
        ] {
            let s = with_error(v, e);
            assert!(!s.contains("e0") && !s.starts_with("-0 "), "{s}");
        }
        assert_eq!(fixed(-0.04, 1), "0.0");
        assert_eq!(fixed(-0.06, 1), "-0.1");
        assert_eq!(signed(-0.0, 1), "+0.0");
        assert_eq!(signed(7151.34, 1), "+7151.3");
        assert_eq!(signed(-2.04, 1), "-2.0");
    }

    #[test]
    fn cells_carry_15_digits_and_no_negative_zero() {
        assert_eq!(cell(0.1 + 0.2), "0.3");
        assert_eq!(cell(-0.0), "0");
        assert_eq!(cell(0.000155 + 1e-20), "0.000155");
        assert_eq!(cell(-1.6389436157238029), "-1.6389436157238");
    }

    #[test]
    fn significant_digits_are_plain_in_the_plain_range() {
        assert_eq!(significant(1.0171e-3, 4), "0.001017");
        assert_eq!(significant(8.7801e-4, 4), "8.78e-4");
        assert_eq!(significant(1234.5678, 6), "1234.57");
        assert_eq!(significant(-0.0, 3), "0");
        assert_eq!(significant(2.5e7, 2), "2.5e7");
        assert_eq!(significant(12345.678, 6), "12 345.7");
        assert_eq!(significant(20000.0, 3), "20 000");
        assert_eq!(significant(0.1 + 0.2, 6), "0.3");
    }

    #[test]
    fn long_integer_parts_are_grouped_by_threes() {
        assert_eq!(grouped("19987"), "19 987");
        assert_eq!(grouped("-123456.5"), "-123 456.5");
        assert_eq!(grouped("2048"), "2048");
        assert_eq!(grouped("1000000"), "1 000 000");
    }
}
