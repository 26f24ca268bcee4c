//! The `[system]` section of an experiment file: the oscillator's parameters, a `preset`
//! (`forced`, `free`) and single values over it. Absent, the forced rig
//! ([`OscillatorParams::FORCED`]).

use anyhow::Result;
use serde::Deserialize;
use stf_core::physics::oscillator_params::{OscParam, OscillatorParams};
use toml::Spanned;

use super::Ctx;

/// A named set of oscillator parameters (`preset = "free"`), in `[system]` and in
/// `[[identify]]` stages.
#[derive(Clone, Copy, Debug, Deserialize, PartialEq, Eq)]
#[serde(rename_all = "snake_case")]
pub(super) enum Preset {
    /// [`OscillatorParams::FORCED`], the source study's forced identification.
    Forced,
    /// [`OscillatorParams::FREE`], its free-vibration identification.
    Free,
}

impl Preset {
    /// The preset's parameters.
    pub(super) fn params(self) -> OscillatorParams {
        match self {
            Preset::Forced => OscillatorParams::FORCED,
            Preset::Free => OscillatorParams::FREE,
        }
    }
}

/// `[system]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
#[allow(non_snake_case)]
pub(super) struct RawSystem {
    preset: Option<Preset>,
    m: Option<f64>,
    k: Option<f64>,
    c: Option<f64>,
    #[serde(rename = "T")]
    t_friction: Option<f64>,
    delta_T: Option<f64>,
    F0: Option<f64>,
    eta: Option<f64>,
    f_off: Option<f64>,
    phi_off: Option<f64>,
    u_off: Option<f64>,
}

/// The oscillator `[system]` gives: its preset (default forced) with the values given set;
/// masses, stiffness and `eta` must be positive, the other values not negative but offsets.
pub(super) fn check(raw: Option<&Spanned<RawSystem>>, cx: &Ctx) -> Result<OscillatorParams> {
    let Some(s) = raw else {
        return Ok(OscillatorParams::FORCED);
    };
    let (span, s) = (s.span(), s.get_ref());
    let mut system = s.preset.unwrap_or(Preset::Forced).params();
    let given = [
        s.m,
        s.k,
        s.c,
        s.t_friction,
        s.delta_T,
        s.F0,
        s.eta,
        s.f_off,
        s.phi_off,
        s.u_off,
    ];
    for (param, value) in OscParam::ALL.into_iter().zip(given) {
        let Some(v) = value else { continue };
        let must_be_positive = matches!(param, OscParam::M | OscParam::K | OscParam::Eta);
        let valid = (v >= 0.0 || param.is_offset()) && !(must_be_positive && v == 0.0);
        let key = format!("system.{param}");
        cx.ensure(
            valid,
            span.clone(),
            &key,
            format!("{v} is not a valid value"),
        )?;
        system[param] = v;
    }
    Ok(system)
}

#[cfg(test)]
mod tests {
    use crate::experiment::parse_exp as parse;
    use stf_core::physics::oscillator_params::OscillatorParams;

    #[test]
    fn a_preset_with_values_over_it_is_the_system() {
        let e = parse("[system]\npreset = \"free\"\nk = 250.0\nf_off = -0.1\n").unwrap();
        let mut expected = OscillatorParams::FREE;
        expected.k = 250.0;
        expected.f_off = -0.1;
        assert_eq!(e.system, expected);
        assert!(e.system_given);
        let e = parse("").unwrap();
        assert_eq!(e.system, OscillatorParams::FORCED);
        assert!(!e.system_given);
    }

    #[test]
    fn an_unknown_preset_or_a_bad_value_names_file_line_key_and_what_is_accepted() {
        let msg = format!("{:#}", parse("[system]\npreset = \"forcd\"\n").unwrap_err());
        assert!(
            msg.starts_with("exp.toml:2: `system.preset`:") && msg.contains("one of: forced, free"),
            "{msg}"
        );
        for (text, key) in [
            ("m = 0.0", "system.m"),
            ("c = -1.0", "system.c"),
            ("eta = 0.0", "system.eta"),
        ] {
            let msg = format!("{:#}", parse(&format!("\n[system]\n{text}\n")).unwrap_err());
            assert!(
                msg.starts_with(&format!("exp.toml:2: `{key}`: ")) && msg.contains("not a valid"),
                "{msg}"
            );
        }
    }
}
