//! The `[regimes]` section of an experiment file: the regime classifier's thresholds, core's
//! [`RegimeThresholds`] (its keys and defaults are documented there), read from the section
//! as written and checked as a whole.

use anyhow::Result;
use stf_core::regimes::RegimeThresholds;
use toml::Spanned;

use super::Ctx;

/// The thresholds `[regimes]` gives (absent: the defaults); errors name the section's line.
pub(super) fn check(raw: Option<&Spanned<toml::Value>>, cx: &Ctx) -> Result<RegimeThresholds> {
    let Some(v) = raw else {
        return Ok(RegimeThresholds::default());
    };
    let th: RegimeThresholds = v
        .get_ref()
        .clone()
        .try_into()
        .map_err(|e: toml::de::Error| cx.at(v.span(), "regimes", e.message()))?;
    th.check().map_err(|e| cx.at(v.span(), "regimes", e))?;
    Ok(th)
}

#[cfg(test)]
mod tests {
    use crate::experiment::parse_exp as parse;
    use stf_core::regimes::RegimeThresholds;

    #[test]
    fn thresholds_parse_and_a_bad_one_names_the_section() {
        assert_eq!(parse("").unwrap().regimes, RegimeThresholds::default());
        let e = parse("[regimes]\non_k = 3.0\n").unwrap();
        assert_eq!(e.regimes.on_k, 3.0);
        let msg = format!("{:#}", parse("\n[regimes]\non_kk = 3.0\n").unwrap_err());
        assert!(
            msg.starts_with("exp.toml:2: `regimes`: ") && msg.contains("on_kk"),
            "{msg}"
        );
    }
}
