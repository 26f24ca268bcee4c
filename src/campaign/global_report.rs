//! The "Global fit" section at the top of the campaign report, from `global.json`
//! ([`GlobalJson`]): the verdict and its caveats, the joint fit's parameters ± standard
//! errors, the comparison table (RSS, parameters, AIC, BIC; held-out RMS both ways), and per
//! law its fitted formula and a figure of the records' own fitted values (± one standard error, one colour per value
//! of the other conditions, the held-out record apart) with the fitted law drawn over them.

use std::path::Path;

use anyhow::Result;

use super::global::{Criteria, GlobalJson, LawJson};
use super::global_file::Form;
use crate::digits::{carried, with_error};
use crate::report::{self, Curve, ErrorSeries, FigureRef, Section, Table};

/// Points along a law's curve in its figure.
const CURVE_POINTS: usize = 200;

/// The section, its figures written to `figures`.
pub fn section(g: &GlobalJson, figures: &Path) -> Result<Section> {
    let mut s = Section::new("Global fit");
    s.paragraphs.push(format!(
        "`{}` fitted jointly to the {} of {} record(s){}{}{}. {}",
        g.model,
        if g.level == "trajectory" {
            "displacement (trajectory level)"
        } else {
            "force"
        },
        g.records.len(),
        if g.shared.is_empty() {
            String::new()
        } else {
            format!(", sharing {}", g.shared.join(", "))
        },
        g.laws
            .iter()
            .map(|l| format!(", with {}", formula(l, |name, _, _| name.to_string())))
            .collect::<String>(),
        g.holdout
            .as_ref()
            .map_or(String::new(), |h| format!(", {} held out", h.record)),
        capitalised(&g.verdict)
    ));
    for law in &g.laws {
        s.paragraphs.push(format!(
            "{} (± one block-robust standard error).",
            formula(law, |_, v, e| format!("({})", with_error(v, e)))
        ));
    }
    s.warnings = g.caveats.iter().map(|c| capitalised(c) + ".").collect();
    s.tables.push(comparison(g));
    s.tables.push(params_table(g));
    for law in &g.laws {
        s.figures.push(law_figure(g, law, figures)?);
    }
    Ok(s)
}

/// "sharing …" → "Sharing …".
fn capitalised(text: &str) -> String {
    let mut c = text.chars();
    c.next()
        .map_or(String::new(), |f| f.to_uppercase().chain(c).collect())
}

/// Global against per-record: RSS, parameters, AIC, BIC, held-out RMS.
fn comparison(g: &GlobalJson) -> Table {
    let unit = &g.rms_unit;
    let row = |name: &str, c: &Criteria, held: Option<f64>| {
        vec![
            name.to_string(),
            crate::digits::brief(c.rss),
            c.n_params.to_string(),
            format!("{:.1}", c.aic),
            format!("{:.1}", c.bic),
            held.map_or("—".into(), |h| format!("{h:.5} {unit}")),
        ]
    };
    // The RSS stays in the records' SI units: those of the shown RMS without its milli.
    let rss_unit = match unit.as_str() {
        "mm" => "m²".to_string(),
        "mV" => "V²".to_string(),
        u => format!("{u}²"),
    };
    let h = g.holdout.as_ref();
    Table {
        caption: format!(
            "Over the {} training record(s) ({} samples). {}",
            g.records.len(),
            g.global.n_points,
            h.map_or(String::new(), |h| format!(
                "On the held-out record the per-record alternative takes the mean of the own \
                 fits' parameters of {}; the record's own fit reaches {:.5} {unit}.",
                h.per_record_from.join(", "),
                h.own_fit_rms
            ))
        ),
        columns: [
            "fit",
            &format!("RSS, {rss_unit}"),
            "parameters",
            "AIC",
            "BIC",
            "held-out RMS",
        ]
        .map(String::from)
        .to_vec(),
        rows: vec![
            row("global", &g.global, h.map(|h| h.global_rms)),
            row("per record", &g.per_record, h.map(|h| h.per_record_rms)),
        ],
    }
}

/// θ with standard errors.
fn params_table(g: &GlobalJson) -> Table {
    Table {
        caption: "The joint fit's parameters (`P@N`: unit N's own).".into(),
        columns: ["parameter", "role", "value ± standard error"]
            .map(String::from)
            .to_vec(),
        rows: g
            .params
            .iter()
            .map(|p| {
                vec![
                    p.name.clone(),
                    p.role.clone(),
                    with_error(p.value, p.std_error),
                ]
            })
            .collect(),
    }
}

/// A law's coefficients in order: (name, value, standard error); the form (none: the power law
/// without offset).
fn coefficients(law: &LawJson) -> (Option<Form>, Vec<(String, f64, f64)>) {
    let form = law.law.as_deref().and_then(Form::named);
    let list = match (&law.coefficients, form) {
        (Some(c), Some(_)) => c
            .iter()
            .map(|c| (c.name.clone(), c.value, c.std_error))
            .collect(),
        _ => vec![
            (
                format!("{}0", law.param),
                law.coefficient.unwrap_or(f64::NAN),
                law.coefficient_std_error.unwrap_or(f64::NAN),
            ),
            (
                format!("{}_p", law.param),
                law.exponent.unwrap_or(f64::NAN),
                law.exponent_std_error.unwrap_or(f64::NAN),
            ),
        ],
    };
    (form, list)
}

/// The law written out, each coefficient shown by `shown(name, value, error)`:
/// `K = K0·(c/0.4)^K_p`, `F_y = F_y_base + F_y_gain·voltage`.
fn formula(law: &LawJson, shown: impl Fn(&str, f64, f64) -> String) -> String {
    let (form, k) = coefficients(law);
    let k: Vec<String> = k.iter().map(|(n, v, e)| shown(n, *v, *e)).collect();
    let ratio = format!("({}/{})", law.condition, carried(law.reference));
    let x = if law.reference == 1.0 {
        law.condition.clone()
    } else {
        ratio.clone()
    };
    let rhs = match form {
        None => format!("{}·{ratio}^{}", k[0], k[1]),
        Some(Form::Linear) => format!("{}·{x}", k[0]),
        Some(Form::Affine) => format!("{} + {}·{x}", k[0], k[1]),
        Some(Form::Power) => format!("{} + {}·|{x}|^{}", k[0], k[1], k[2]),
    };
    format!("{} = {rhs}", law.param)
}

/// The fitted law's value at condition `c`, clamped into the parameter's bounds as the fit
/// clamps it; and whether it was.
fn law_at(law: &LawJson, c: f64) -> (f64, bool) {
    let (form, k) = coefficients(law);
    let values: Vec<f64> = k.iter().map(|(_, v, _)| *v).collect();
    let x = c / law.reference;
    let v = match form {
        None => values[0] * x.powf(values[1]),
        Some(form) => form.value(&values, x),
    };
    let (lo, hi) = (
        law.min.unwrap_or(f64::NEG_INFINITY),
        law.max.unwrap_or(f64::INFINITY),
    );
    let held = v.clamp(lo, hi);
    (held, held != v)
}

/// The curve's legend: the law's formula, and where its value was clamped into the
/// parameter's bounds along the figure, which bound.
fn curve_label(law: &LawJson, clamped: bool) -> String {
    let text = format!("global law: {}", formula(law, |_, v, _| format!("{v:.4}")));
    if !clamped {
        return text;
    }
    let bound = |b: Option<f64>| b.map_or_else(|| "∞".to_string(), |v| format!("{v}"));
    let unit = if law.unit.is_empty() {
        String::new()
    } else {
        format!(" {}", law.unit)
    };
    format!(
        "{text}, clamped into [{}, {}]{unit} as in the fit",
        bound(law.min),
        bound(law.max)
    )
}

/// The records' own values of `law.param` against its condition, with the law over them.
fn law_figure(g: &GlobalJson, law: &LawJson, dir: &Path) -> Result<FigureRef> {
    let mut series: Vec<ErrorSeries> = Vec::new();
    let mut xs = Vec::new();
    for r in &g.each_record {
        let (Some(&x), Some(&(v, e))) =
            (r.conditions.get(&law.condition), r.params.get(&law.param))
        else {
            continue;
        };
        xs.push(x);
        let label = if r.held_out {
            "held out".to_string()
        } else {
            let others: Vec<String> = r
                .conditions
                .iter()
                .filter(|(c, _)| **c != law.condition)
                .map(|(c, v)| super::labels::value_label(c, *v, g.condition_units.get(c)))
                .collect();
            if others.is_empty() {
                "records".into()
            } else {
                others.join(", ")
            }
        };
        match series.iter_mut().find(|s| s.label == label) {
            Some(s) => s.points.push((x, v, e)),
            None => series.push(ErrorSeries {
                label,
                points: vec![(x, v, e)],
            }),
        }
    }
    // The held-out record last, so the colours of the others follow their order.
    series.sort_by_key(|s| s.label == "held out");
    let lo = xs.iter().copied().fold(f64::INFINITY, f64::min);
    let hi = xs.iter().copied().fold(f64::NEG_INFINITY, f64::max);
    let along: Vec<(f64, (f64, bool))> = (0..CURVE_POINTS)
        .map(|i| {
            let x = lo + (hi - lo) * i as f64 / (CURVE_POINTS - 1) as f64;
            (x, law_at(law, x))
        })
        .collect();
    let clamped = along.iter().any(|(_, (_, held))| *held);
    let curve = Curve {
        label: curve_label(law, clamped),
        points: along.into_iter().map(|(x, (y, _))| (x, y)).collect(),
    };
    let name = format!("global_{}_vs_{}", law.param, law.condition)
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '_' })
        .collect::<String>();
    let title = format!("{}: {} against {}", g.model, law.param, law.condition);
    let files = report::error_bars_with_curve(
        dir,
        &name,
        &title,
        (
            &super::labels::axis_label(&law.condition, law.condition_unit.as_deref()),
            &super::labels::axis_label(&law.param, Some(&law.unit)),
        ),
        &series,
        Some(&curve),
    )?;
    Ok(FigureRef::new(
        files,
        format!(
            "Each record's own fitted {} (± one standard error) against {}, and the law the \
             global fit found (black){}.",
            law.param,
            law.condition,
            if clamped {
                ", held within the parameter's bounds where it leaves them, as in the fit"
            } else {
                ""
            }
        ),
    ))
}

#[cfg(test)]
mod tests {
    use super::*;
    use stf_study::joint::LawCoefficient;

    fn affine(base: f64, gain: f64) -> LawJson {
        let k = |name: &str, value: f64| LawCoefficient {
            name: name.into(),
            value,
            std_error: 0.01,
            unit: "N".into(),
        };
        LawJson {
            param: "F_y".into(),
            condition: "voltage".into(),
            reference: 1.0,
            unit: "N".into(),
            condition_unit: Some("V".into()),
            coefficient: None,
            coefficient_std_error: None,
            exponent: None,
            exponent_std_error: None,
            law: Some("affine".into()),
            coefficients: Some(vec![k("F_y_base", base), k("F_y_gain", gain)]),
            min: Some(0.0),
            max: Some(50.0),
        }
    }

    #[test]
    fn the_curve_is_clamped_into_the_bounds_as_the_fit_clamps_it_and_says_so() {
        let law = affine(-1.0, 2.0);
        assert_eq!(law_at(&law, 0.0), (0.0, true));
        assert_eq!(law_at(&law, 1.0), (1.0, false));
        let label = curve_label(&law, true);
        assert!(
            label.ends_with("clamped into [0, 50] N as in the fit"),
            "{label}"
        );
        assert!(!curve_label(&affine(0.5, 2.0), false).contains("clamped"));
    }

    /// The plain law `K0·(c/ref)^K_p` is held within the parameter's bounds too: K0 = 40 at
    /// reference 1 with exponent 2 passes the upper bound 50 at c = 2 and is held there.
    #[test]
    fn the_plain_power_law_is_clamped_into_the_bounds_too() {
        let law = LawJson {
            law: None,
            coefficients: None,
            coefficient: Some(40.0),
            coefficient_std_error: Some(0.1),
            exponent: Some(2.0),
            exponent_std_error: Some(0.01),
            ..affine(0.0, 0.0)
        };
        assert_eq!(law_at(&law, 1.0), (40.0, false));
        assert_eq!(law_at(&law, 2.0), (50.0, true));
        assert!(curve_label(&law, true).ends_with("clamped into [0, 50] N as in the fit"));
    }
}
