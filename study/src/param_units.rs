//! A parameter's unit on a record: its SI unit (as a model's spec or the oscillator gives it,
//! in metres and newtons) with lengths and forces in the record's own units. On a record of
//! the trolley nothing changes; on one whose x is a voltage kept in volts lengths are V, and
//! forces are the drive's unit (V when it too is a voltage read with a gain of 1, else N). A
//! unit written in whole powers of N, m, s, kg and rad is rewritten and simplified (`N/m` on a
//! record whose x and drive are both in volts is a plain gain, shown as no unit; `kg` is
//! `N·s²/m` first); one with a symbolic power (`N·(s/m)ⁿ`) has its N and m replaced as written.

use crate::shown_units::ShownUnits;

/// The unit `si` (an SI unit in metres and newtons) on a record shown in `units`.
pub fn in_record_units(si: &str, units: &ShownUnits) -> String {
    let (length, force) = (units.x_si, units.force_si);
    if length == "m" && force == "N" {
        return si.to_string();
    }
    match powers(si) {
        Some(powers) => render(&substituted(&powers, length, force)),
        None => replaced(si, length, force),
    }
}

/// `(symbol, power)` factors of a unit written as `A·B²/C` (at most one `/`; factors joined
/// by `·`, `*` or a space; powers as superscripts or `^k`, whole numbers only); `None` for
/// anything else (a symbolic power, brackets, an unknown symbol).
fn powers(si: &str) -> Option<Vec<(&'static str, i32)>> {
    let mut sides = si.split('/');
    let (num, den) = (sides.next()?, sides.next());
    if sides.next().is_some() {
        return None;
    }
    let mut out = factors(num, 1)?;
    if let Some(den) = den {
        out.extend(factors(den, -1)?);
    }
    Some(out)
}

/// The factors of one side of a `/`, their powers times `sign`; `1` or nothing is none.
fn factors(side: &str, sign: i32) -> Option<Vec<(&'static str, i32)>> {
    let side = side.trim();
    if side.is_empty() || side == "1" {
        return Some(Vec::new());
    }
    side.split(['·', '*', ' '])
        .filter(|f| !f.is_empty())
        .map(|f| {
            let split = f
                .find(|c: char| !c.is_ascii_alphabetic())
                .unwrap_or(f.len());
            let (symbol, power) = f.split_at(split);
            let symbol = ["N", "m", "s", "kg", "rad"]
                .into_iter()
                .find(|s| *s == symbol)?;
            Some((symbol, sign * power_of(power)?))
        })
        .collect()
}

/// A whole power written as superscripts (`²`, `⁻¹`) or `^k`; empty is 1.
fn power_of(text: &str) -> Option<i32> {
    if text.is_empty() {
        return Some(1);
    }
    if let Some(k) = text.strip_prefix('^') {
        return k.parse().ok();
    }
    let plain: String = text
        .chars()
        .map(|c| match c {
            '⁻' => Some('-'),
            _ => "⁰¹²³⁴⁵⁶⁷⁸⁹"
                .chars()
                .position(|d| d == c)
                .and_then(|d| char::from_digit(d as u32, 10)),
        })
        .collect::<Option<_>>()?;
    plain.parse().ok()
}

/// `powers` with kg written as N·s²/m, then m as `length` and N as `force`, like symbols
/// merged (in order of first appearance) and zero powers dropped.
fn substituted(
    powers: &[(&'static str, i32)],
    length: &'static str,
    force: &'static str,
) -> Vec<(&'static str, i32)> {
    let mut out: Vec<(&'static str, i32)> = Vec::new();
    let mut add = |symbol: &'static str, power: i32| {
        let symbol = match symbol {
            "m" => length,
            "N" => force,
            s => s,
        };
        match out.iter_mut().find(|(s, _)| *s == symbol) {
            Some((_, p)) => *p += power,
            None => out.push((symbol, power)),
        }
    };
    for &(symbol, power) in powers {
        if symbol == "kg" {
            add("N", power);
            add("s", 2 * power);
            add("m", -power);
        } else {
            add(symbol, power);
        }
    }
    out.retain(|(_, p)| *p != 0);
    out
}

/// `A·B²/C`, `1/C²`, `A/(B·C)`; empty for no factor (a plain number).
fn render(powers: &[(&str, i32)]) -> String {
    let side = |sign: i32| -> Vec<String> {
        powers
            .iter()
            .filter(|(_, p)| p.signum() == sign)
            .map(|&(s, p)| format!("{s}{}", superscript(p.abs())))
            .collect()
    };
    let (num, den) = (side(1), side(-1));
    let num = if num.is_empty() && !den.is_empty() {
        "1".to_string()
    } else {
        num.join("·")
    };
    match den.len() {
        0 => num,
        1 => format!("{num}/{}", den[0]),
        _ => format!("{num}/({})", den.join("·")),
    }
}

/// A power as superscript digits; nothing for 1.
fn superscript(p: i32) -> String {
    if p == 1 {
        return String::new();
    }
    p.to_string()
        .chars()
        .map(|d| {
            d.to_digit(10)
                .and_then(|d| "⁰¹²³⁴⁵⁶⁷⁸⁹".chars().nth(d as usize))
                .unwrap_or(d)
        })
        .collect()
}

/// `si` with each whole symbol `m` written `length`, `N` written `force` and `kg` written
/// `(force·s²/length)`, the rest as it is.
fn replaced(si: &str, length: &str, force: &str) -> String {
    let mut out = String::new();
    let mut word = String::new();
    let flush = |word: &mut String, out: &mut String| {
        let shown = match word.as_str() {
            "m" => length.to_string(),
            "N" => force.to_string(),
            "kg" => format!("({force}·s²/{length})"),
            w => w.to_string(),
        };
        out.push_str(&shown);
        word.clear();
    };
    for c in si.chars() {
        if c.is_alphanumeric() || c == '_' {
            word.push(c);
        } else {
            flush(&mut word, &mut out);
            out.push(c);
        }
    }
    flush(&mut word, &mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn volts(force: &'static str) -> ShownUnits {
        ShownUnits {
            force_si: force,
            ..ShownUnits::VOLTAGE
        }
    }

    #[test]
    fn a_record_in_metres_keeps_every_unit_as_written() {
        for si in ["kg", "N/m", "N·(s/m)ⁿ", "kg·m", "", "m/s"] {
            assert_eq!(in_record_units(si, &ShownUnits::LENGTH), si);
        }
    }

    #[test]
    fn lengths_in_volts_and_forces_in_newtons() {
        let u = volts("N");
        let cases = [
            ("m", "V"),
            ("m/s", "V/s"),
            ("N/m", "N/V"),
            ("N·s/m", "N·s/V"),
            ("N/m³", "N/V³"),
            ("kg", "N·s²/V"),
            ("kg·m", "N·s²"),
            ("s/m", "s/V"),
            ("N", "N"),
            ("rad", "rad"),
            ("", ""),
            ("N·(s/m)ⁿ", "N·(s/V)ⁿ"),
            ("N/m^p", "N/V^p"),
        ];
        for (si, shown) in cases {
            assert_eq!(in_record_units(si, &u), shown, "{si}");
        }
    }

    #[test]
    fn lengths_and_forces_both_in_volts_simplify() {
        let u = volts("V");
        let cases = [
            ("N/m", ""),
            ("N·s/m", "s"),
            ("N/m³", "1/V²"),
            ("kg", "s²"),
            ("m/s", "V/s"),
            ("N", "V"),
            ("N·(s/m)^n", "V·(s/V)^n"),
            ("N·(s/m)^n_j", "V·(s/V)^n_j"),
        ];
        for (si, shown) in cases {
            assert_eq!(in_record_units(si, &u), shown, "{si}");
        }
    }
}
