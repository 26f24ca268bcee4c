//! How a campaign's figures label their axes and legends: a name with its unit.

use stf_study::digits::carried;

/// An axis's label: the name and its unit in brackets (`K [N·(s/m)ⁿ]`, `n [–]` for a
/// dimensionless one), the name alone when the unit is not known.
pub fn axis_label(name: &str, unit: Option<&str>) -> String {
    match unit.map(str::trim) {
        None => name.to_string(),
        Some("") => format!("{name} [–]"),
        Some(u) => format!("{name} [{u}]"),
    }
}

/// `name = value unit` (the unit where the campaign gives one) for a legend.
pub fn value_label(name: &str, value: f64, unit: Option<&String>) -> String {
    match unit {
        Some(u) => format!("{name} = {} {u}", carried(value)),
        None => format!("{name} = {}", carried(value)),
    }
}
