//! A fit's values as the terminal shows them: each free parameter `name = value ± error unit`
//! (the value rounded to its error, [`stf_study::digits::with_error`]), held ones counted,
//! from the rows `params.csv` is written from — so the terminal's numbers are the file's.

use stf_study::digits::with_error;
use stf_study::param_table::ParamRow;

/// `K = 4.074 ± 0.047 N·(s/m)ⁿ, n = 1.5083 ± 0.0054; 2 held` for one model's `rows`.
pub fn values_line(rows: &[ParamRow]) -> String {
    let free: Vec<String> = rows.iter().filter(|r| !r.fixed).map(value_of).collect();
    let held = rows.iter().filter(|r| r.fixed).count();
    let mut line = free.join(", ");
    if held > 0 {
        line.push_str(&format!(
            "{}{held} held",
            if line.is_empty() { "" } else { "; " }
        ));
    }
    line
}

/// One parameter: `name = value ± error unit`, `(on a bound)` when it ended there.
fn value_of(r: &ParamRow) -> String {
    let unit = if r.unit.is_empty() {
        String::new()
    } else {
        format!(" {}", r.unit)
    };
    let bound = if r.at_bound { " (on a bound)" } else { "" };
    let value = with_error(r.value, r.std_error.unwrap_or(f64::NAN));
    format!("{} = {value}{unit}{bound}", r.parameter)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(name: &str, value: f64, se: Option<f64>, unit: &str, fixed: bool) -> ParamRow {
        ParamRow {
            model: "m".into(),
            parameter: name.into(),
            value,
            std_error: se,
            unit: unit.into(),
            fixed,
            at_bound: false,
        }
    }

    #[test]
    fn free_values_with_errors_and_units_then_the_held_count() {
        let rows = [
            row("K", 4.0741, Some(0.0468), "N·(s/m)ⁿ", false),
            row("n", 1.50834, Some(0.00541), "", false),
            row("m", 1.2, None, "kg", true),
        ];
        assert_eq!(
            values_line(&rows),
            "K = 4.07 ± 0.05 N·(s/m)ⁿ, n = 1.508 ± 0.005; 1 held"
        );
    }
}
