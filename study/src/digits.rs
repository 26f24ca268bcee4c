//! Numbers written with the digits they carry. A double holds 15 significant decimal digits
//! faithfully; the 16th and 17th that Rust's shortest round-trip form can add are the residue
//! of arithmetic (ω = w0 + 0.047·(t − t0) gave 3.7933700000000004 where 3.79337 was meant),
//! not information. Outputs round every number to 15 significant digits, which changes a value
//! by less than 1e-15 of itself and never cuts a measured digit (records carry far fewer).
//! Numbers for a person (a value rounded to its error, no negative zero) are
//! [`stf_core::digits`]'s, re-exported here.
//!
//! ```
//! use stf_study::digits::carried;
//! assert_eq!(carried(2.35 + 0.047 * 82.0).to_string(), "6.204");
//! assert_eq!(carried(0.1 + 0.2).to_string(), "0.3");
//! assert_eq!(stf_study::digits::fixed(-0.04, 1), "0.0");
//! assert_eq!(stf_study::digits::fixed(-0.06, 1), "-0.1");
//! assert_eq!(stf_study::digits::with_error(1.0004e4, 8.1), "10 004 ± 8");
//! assert_eq!(stf_study::digits::with_error(3.02331, 0.313), "3.02 ± 0.31");
//! ```

use serde_json::Value;

pub use stf_core::digits::{carried, cell, fixed, grouped, rounded, signed, with_error};

/// `x` in a message: at most 15 significant digits ([`carried`]), plain between 10⁻³ and
/// 10⁶ and in exponent form outside (`1e300`, not a number of 301 digits; `2.5e-7`).
pub fn shown(x: f64) -> String {
    let x = carried(x);
    if x == 0.0 {
        "0".into()
    } else if !x.is_finite() || (1e-3..1e6).contains(&x.abs()) {
        x.to_string()
    } else {
        format!("{x:e}")
    }
}

/// `x` to six significant digits for a message (`0.0054` for 0.005399999999999849), as
/// [`shown`].
pub fn brief(x: f64) -> String {
    shown(format!("{x:.5e}").parse().unwrap_or(x))
}

/// The times `t` run over, for a message: `from 0 to 70 s` (`none`, for no samples).
pub fn time_span(t: &[f64]) -> String {
    match (t.first(), t.last()) {
        (Some(&a), Some(&b)) => format!("from {} to {} s", shown(a), shown(b)),
        _ => "none".into(),
    }
}

/// `name = value ± error` of a fitted parameter ([`with_error`]).
pub fn param_with_error(p: &stf_core::fit::FittedParam) -> String {
    format!("{} = {}", p.name, with_error(p.value, p.std_error))
}

/// A CSV cell of `x`: [`carried`] in Rust's shortest form (`1`, `0.000155`, never
/// `0.00015500000000000003`), a negative zero as `0`. For `#[serde(serialize_with)]`.
pub fn csv_number<S: serde::Serializer>(x: &f64, s: S) -> Result<S::Ok, S::Error> {
    s.collect_str(&cell(*x))
}

/// [`csv_number`] of an optional value (an empty cell for none).
pub fn csv_optional<S: serde::Serializer>(x: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
    match x {
        Some(x) => csv_number(x, s),
        None => s.serialize_none(),
    }
}

/// Every floating-point number of `value`, recursively, rounded by [`carried`] (a negative
/// zero written `0.0`); integers untouched.
pub fn tidy_json(value: &mut Value) {
    match value {
        Value::Number(n) if n.is_f64() => {
            if let Some(x) = n
                .as_f64()
                .and_then(|x| serde_json::Number::from_f64(if x == 0.0 { 0.0 } else { carried(x) }))
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
    fn a_number_in_a_message_is_short() {
        assert_eq!(shown(1e300), "1e300");
        assert_eq!(shown(1e301), "1e301");
        assert_eq!(shown(2.5e-7), "2.5e-7");
        assert_eq!(shown(70.0), "70");
        assert_eq!(shown(0.1 + 0.2), "0.3");
        assert_eq!(shown(-0.0), "0");
        assert_eq!(shown(-1234567.0), "-1.234567e6");
        assert_eq!(brief(0.005399999999999849), "0.0054");
        assert_eq!(brief(1.0 / 0.005), "200");
    }

    #[test]
    fn csv_cells_carry_15_digits_and_no_negative_zero() {
        #[derive(serde::Serialize)]
        struct Row {
            #[serde(serialize_with = "csv_number")]
            a: f64,
            #[serde(serialize_with = "csv_number")]
            b: f64,
            #[serde(serialize_with = "csv_optional")]
            c: Option<f64>,
            #[serde(serialize_with = "csv_optional")]
            d: Option<f64>,
        }
        let mut w = csv::Writer::from_writer(Vec::new());
        w.serialize(Row {
            a: 0.000155 + 1e-20,
            b: -0.0,
            c: Some(0.1 + 0.2),
            d: None,
        })
        .unwrap();
        let text = String::from_utf8(w.into_inner().unwrap()).unwrap();
        assert_eq!(text, "a,b,c,d\n0.000155,0,0.3,\n");
    }

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
