//! Numbers written with the digits they carry. A double holds 15 significant decimal digits
//! faithfully; the 16th and 17th that Rust's shortest round-trip form can add are the residue
//! of arithmetic (ω = w0 + 0.047·(t − t0) gave 3.7933700000000004 where 3.79337 was meant),
//! not information. Outputs round every number to 15 significant digits, which changes a value
//! by less than 1e-15 of itself and never cuts a measured digit (records carry far fewer).
//!
//! ```
//! use stf_lab::digits::carried;
//! assert_eq!(carried(2.35 + 0.047 * 82.0).to_string(), "6.204");
//! assert_eq!(carried(0.1 + 0.2).to_string(), "0.3");
//! assert_eq!(stf_lab::digits::fixed(-0.04, 1), "0.0");
//! assert_eq!(stf_lab::digits::fixed(-0.06, 1), "-0.1");
//! ```

use serde_json::Value;

/// `x` rounded to 15 significant digits (non-finite values and zero as they are).
pub fn carried(x: f64) -> f64 {
    if !x.is_finite() || x == 0.0 {
        return x;
    }
    format!("{x:.14e}").parse().unwrap_or(x)
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

/// Every floating-point number of `value`, recursively, rounded by [`carried`]; integers
/// untouched.
pub fn tidy_json(value: &mut Value) {
    match value {
        Value::Number(n) if n.is_f64() => {
            if let Some(x) = n
                .as_f64()
                .and_then(|x| serde_json::Number::from_f64(carried(x)))
            {
                *n = x;
            }
        }
        Value::Array(items) => items.iter_mut().for_each(tidy_json),
        Value::Object(map) => map.values_mut().for_each(tidy_json),
        _ => {}
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn arithmetic_residue_goes_and_measured_digits_stay() {
        assert_eq!(carried(3.7933700000000004), 3.79337);
        assert_eq!(carried(6.2227060000000005).to_string(), "6.222706");
        assert_eq!(carried(0.015090000000000001).to_string(), "0.01509");
        // Values with 15 or fewer digits are untouched, however small or large.
        for x in [
            0.01509,
            1.234567890123e-9,
            269.9346,
            2048.0,
            -41.69,
            1e300,
            5e-324,
        ] {
            assert_eq!(carried(x), x, "{x}");
        }
        // Rounding moves a value by less than 1e-15 of itself.
        let x = 1.0 / 3.0;
        assert!((carried(x) - x).abs() <= 1e-15 * x);
        assert!(carried(f64::NAN).is_nan());
    }

    #[test]
    fn json_floats_are_tidied_and_integers_kept() {
        let mut v = serde_json::json!({"a": [0.1 + 0.2, 3], "b": {"c": 2.35 + 0.047 * 82.0}, "d": u64::MAX});
        tidy_json(&mut v);
        assert_eq!(
            v.to_string(),
            format!("{{\"a\":[0.3,3],\"b\":{{\"c\":6.204}},\"d\":{}}}", u64::MAX)
        );
    }
}
