//! The force a fit or a discovery ends with, written as an equation, as a sparse-regression
//! tool prints its model: `F_STF = 4.01·|v|^1.501·sgn v + 19 987·x³`. Each value is rounded to
//! its standard error ([`FittedParam::shown_value`]: the digits the results table shows), a held
//! value or one without an error to six significant digits; each model writes its own term
//! ([`ForceModel::equation`]), a script or a model with internal state as a named term,
//! `F_maxwell(c_m = 5.2, tau = 0.050)`.

use stf_core::fit::FittedParam;
use stf_core::physics::force_model::ForceModel;

/// `F_STF = …` of `model` with the fitted `params` (found by the model's parameter names;
/// others, such as an offset, are left out). `None` when a parameter of the model has no
/// fitted value or the model cannot write its term.
pub fn force_equation(model: &dyn ForceModel, params: &[FittedParam]) -> Option<String> {
    let values: Option<Vec<String>> = model
        .params()
        .iter()
        .map(|spec| {
            let p = params.iter().find(|p| p.name == spec.name)?;
            Some(p.shown_value())
        })
        .collect();
    Some(format!("F_STF = {}", model.equation(&values?)?))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;
    use stf_core::physics::model_sum::ModelSum;

    fn model(names: &[&str]) -> Arc<dyn ForceModel> {
        let parts: Vec<Arc<dyn ForceModel>> = names
            .iter()
            .map(|n| stf_models::find(n).expect("a built-in model"))
            .collect();
        Arc::new(ModelSum::new(parts).expect("a sum"))
    }

    #[test]
    fn a_sum_is_written_term_by_term_with_values_rounded_to_their_errors() {
        let params = [
            FittedParam::free("K", 4.0108, 0.060),
            FittedParam::free("n", 1.50138, 0.0074),
            FittedParam::free("k3", 19986.76, 11.3),
            FittedParam::free("f_off", 0.001, 0.0001),
        ];
        let eq = force_equation(&*model(&["power_law", "cubic_stiffness"]), &params);
        assert_eq!(
            eq.as_deref(),
            Some("F_STF = 4.01·|v|^1.501·sgn v + 19 987·x³")
        );
    }

    #[test]
    fn a_negative_term_is_subtracted_and_a_model_with_state_is_named() {
        let params = [
            FittedParam::free("c_s", 1.0005, 3.0e-4),
            FittedParam::free("k_s", -12.3, 0.4),
        ];
        let eq = force_equation(&*model(&["viscous", "linear_spring"]), &params);
        assert_eq!(eq.as_deref(), Some("F_STF = 1.00050·v − 12.3·x"));
        let maxwell = model(&["maxwell"]);
        let params: Vec<FittedParam> = maxwell
            .params()
            .iter()
            .map(|s| FittedParam::free(&s.name, s.default, 0.1 * s.default))
            .collect();
        let eq = force_equation(&*maxwell, &params).unwrap_or_default();
        assert!(
            eq.starts_with("F_STF = F_maxwell(") && eq.contains("c_m = "),
            "{eq}"
        );
        assert_eq!(force_equation(&*maxwell, &params[1..]), None);
    }
}
