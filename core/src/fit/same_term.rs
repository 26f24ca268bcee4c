//! Parameters that are the same term of the equation, which a fit must not free together.
//!
//! The oscillator `m·ẍ + c·ẋ + k·x + F_R + F_STF + f_off = drive` shares terms with some force
//! models: a fluid's linear damping `viscous.c_s` adds to `c`, an added mass `m_a` to `m`
//! ([`crate::physics::param_spec::ParamSpec::same_as`] says which). On a shaker rig the drive offset `u_off`
//! and the force offset `f_off` enter as one constant. Freeing both of such a pair leaves the
//! fit a valley of equal residuals: the optimiser wanders along it and the standard errors
//! blow up (±43 on c = 20.5 and on c_s = 0.98 on a measured record). So a fit refuses the
//! pair and says which one to fix. An offset that the record's drive does not carry
//! (`phi_off` without a rotor, `u_off` without a measured force) is refused too: it has no
//! effect and could not be determined.

use super::error::FitError;
use crate::physics::excitation::Excitation;
use crate::physics::param_spec::ParamSpec;

/// Refuse free parameters that duplicate each other or do nothing: `model` are the model's
/// parameter specs with whether each is free, `oscillator` the freed oscillator parameters.
pub fn check_same_terms(
    model: &[(&ParamSpec, bool)],
    oscillator: &[&str],
    excitation: &Excitation,
) -> Result<(), FitError> {
    for (spec, free) in model {
        if let Some(osc) = spec.same_as {
            if *free && oscillator.contains(&osc) {
                return Err(FitError::SameTerm(format!(
                    "the model's `{}` and the oscillator's `{osc}` are the same term of the \
                     equation; free one of them and fix the other",
                    spec.name
                )));
            }
        }
    }
    let rotor = matches!(excitation, Excitation::Rotor(_));
    let shaker = matches!(excitation, Excitation::Force(_));
    if shaker && oscillator.contains(&"u_off") && oscillator.contains(&"f_off") {
        return Err(FitError::SameTerm(
            "`u_off` and `f_off` are the same constant force on a rig driven by a measured \
             force `u`; free one of them"
                .into(),
        ));
    }
    for (name, applies, what) in [
        ("phi_off", rotor, "a rotor angle φ"),
        ("u_off", shaker, "a measured force u"),
    ] {
        if oscillator.contains(&name) && !applies {
            return Err(FitError::SameTerm(format!(
                "`{name}` is an offset of {what}, which does not drive this record; it has no \
                 effect and cannot be fitted"
            )));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numerics::interpolate::Linear;

    fn shaker() -> Excitation {
        Excitation::Force(Linear::new(vec![0.0, 1.0], vec![0.0, 1.0]))
    }

    #[test]
    fn a_model_term_and_its_oscillator_twin_are_not_freed_together() {
        let c_s = ParamSpec::new("c_s", "N·s/m", 1.0, 0.0, 10.0, "").same_as("c");
        let err = check_same_terms(&[(&c_s, true)], &["k", "c"], &shaker()).unwrap_err();
        assert!(err.to_string().contains("`c_s`") && err.to_string().contains("`c`"));
        assert!(check_same_terms(&[(&c_s, false)], &["k", "c"], &shaker()).is_ok());
        assert!(check_same_terms(&[(&c_s, true)], &["k"], &shaker()).is_ok());
    }

    #[test]
    fn offsets_must_apply_to_the_drive_and_not_repeat_each_other() {
        assert!(check_same_terms(&[], &["u_off", "f_off"], &shaker()).is_err());
        assert!(check_same_terms(&[], &["u_off"], &shaker()).is_ok());
        assert!(check_same_terms(&[], &["phi_off"], &shaker()).is_err());
        assert!(check_same_terms(&[], &["u_off"], &Excitation::None).is_err());
        assert!(check_same_terms(&[], &["f_off"], &Excitation::None).is_ok());
    }
}
