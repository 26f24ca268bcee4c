//! The `[integrator]` section of an experiment file: the integration `method` (a serde enum
//! of core's, [`Method`]) and the tolerances `rtol`, `atol`, `h_max`, each within a range
//! beyond which a run takes minutes to hours or means nothing ([`TOLERANCE_RANGES`]).

use anyhow::Result;
use serde::Deserialize;
use stf_core::numerics::integrate::{Method, Settings};
use toml::Spanned;

use super::Ctx;

/// `[integrator]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawIntegrator {
    method: Option<Method>,
    rtol: Option<f64>,
    atol: Option<f64>,
    h_max: Option<f64>,
}

/// Accepted `[integrator]` tolerances: key, least, most, and what else is accepted. Beyond
/// them a run takes minutes to hours (`rtol = 1e-300` asks for more digits than a double
/// holds; `h_max = 1e-300` for more steps than the integrator's limit) or means nothing.
const TOLERANCE_RANGES: [(&str, f64, f64, &str); 3] = [
    ("rtol", 1e-13, 0.1, ""),
    ("atol", 1e-15, 1e-2, ""),
    ("h_max", 1e-5, 1e3, " s, or 0 (no limit)"),
];

/// The integrator settings: the defaults with the keys given, each tolerance in its range
/// (`h_max = 0`: no limit).
pub(super) fn check(raw: Option<&Spanned<RawIntegrator>>, cx: &Ctx) -> Result<Settings> {
    let mut integrator = Settings::default();
    let Some(i) = raw else {
        return Ok(integrator);
    };
    let (span, i) = (i.span(), i.get_ref());
    if let Some(m) = i.method {
        integrator.method = m;
    }
    let given = [i.rtol, i.atol, i.h_max];
    let slots = [
        &mut integrator.rtol,
        &mut integrator.atol,
        &mut integrator.h_max,
    ];
    for ((value, slot), (name, lo, hi, what)) in given.into_iter().zip(slots).zip(TOLERANCE_RANGES)
    {
        let Some(v) = value else { continue };
        let off = name == "h_max" && v == 0.0;
        let range = format!("{v} is outside the accepted range [{lo:e}, {hi:e}]{what}");
        let key = format!("integrator.{name}");
        cx.ensure(off || (lo..=hi).contains(&v), span.clone(), &key, range)?;
        *slot = v;
    }
    Ok(integrator)
}

#[cfg(test)]
mod tests {
    use crate::experiment::parse_exp as parse;
    use stf_core::numerics::integrate::Method;

    #[test]
    fn tolerances_that_would_run_for_minutes_are_refused_with_the_range() {
        for (text, key, range) in [
            ("rtol = 1e-300", "integrator.rtol", "[1e-13, 1e-1]"),
            ("atol = 1e-300", "integrator.atol", "[1e-15, 1e-2]"),
            (
                "h_max = 1e-300",
                "integrator.h_max",
                "[1e-5, 1e3] s, or 0 (no limit)",
            ),
            ("rtol = 0.5", "integrator.rtol", "[1e-13, 1e-1]"),
            ("h_max = -1.0", "integrator.h_max", "or 0"),
        ] {
            let msg = format!(
                "{:#}",
                parse(&format!("[integrator]\n{text}\n")).unwrap_err()
            );
            assert!(
                msg.starts_with(&format!("exp.toml:1: `{key}`:"))
                    && msg.contains("outside the accepted range")
                    && msg.contains(range),
                "{msg}"
            );
        }
        let e = parse("[integrator]\nrtol = 1e-11\natol = 1e-12\nh_max = 0.0\n").unwrap();
        assert_eq!(
            (e.integrator.rtol, e.integrator.atol, e.integrator.h_max),
            (1e-11, 1e-12, 0.0)
        );
    }

    #[test]
    fn an_unknown_method_lists_the_methods() {
        let msg = format!(
            "{:#}",
            parse("[integrator]\nmethod = \"euler\"\n").unwrap_err()
        );
        assert!(
            msg.starts_with("exp.toml:2: `integrator.method`: unknown value `euler`"),
            "{msg}"
        );
        let e = parse("[integrator]\nmethod = \"auto\"\n").unwrap();
        assert_eq!(e.integrator.method, Method::Auto);
    }
}
