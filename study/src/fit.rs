//! The fit workflow: read the experiment's record, check its `[validate]` record, fit every
//! model at the record's level ([`crate::fitting::fit_all`]) and score the fits on the second
//! record. [`Fitted`] is what `fit.json`, `params.csv`, `fitted.csv`, the terminal summary and
//! the fit report are all rendered from.

use anyhow::Result;

use crate::experiment::Experiment;
use crate::fitting::{fit_all, load_data, FitData, ModelFit};
use crate::observer::Observer;
use crate::outputs::columns_csv::Columns;
use crate::param_table::{rows_of_fits, ParamRow};
use crate::validation::ValidationRecord;

/// A fit of every model of an experiment to its record.
pub struct Fitted {
    /// The record the models were fitted to, with its kinematics and level.
    pub data: FitData,
    /// Each model's fit, in the experiment's order.
    pub fits: Vec<ModelFit>,
    /// The `[validate]` record the fits were scored on.
    pub validation: Option<ValidationRecord>,
}

/// The inputs of a fit: the record and the `[validate]` record, read and checked.
pub struct FitInputs {
    /// The record the models are fitted to, with its kinematics and level.
    pub data: FitData,
    /// The second record the fits are scored on.
    pub validation: Option<ValidationRecord>,
}

/// Fit every model of `exp` to its record (the oscillator `exp.system` may be taken from the
/// record: [`crate::fitting::load_data`]), then score the fits on the `[validate]` record.
pub fn fit(exp: &mut Experiment, observer: &dyn Observer) -> Result<Fitted> {
    load(exp, observer)?.fit(exp, observer)
}

/// Read and check the records of `exp` (a front end may stop here, before it prepares its
/// outputs, so that a bad record is said before anything else).
pub fn load(exp: &mut Experiment, observer: &dyn Observer) -> Result<FitInputs> {
    let data = load_data(exp)?;
    warn_about(&data, observer);
    let validation = crate::validation::load(exp, &data)?;
    if let Some(rec) = &validation {
        warn_about(&rec.data, observer);
    }
    Ok(FitInputs { data, validation })
}

impl FitInputs {
    /// Fit every model of `exp` and score the fits on the second record.
    pub fn fit(self, exp: &Experiment, observer: &dyn Observer) -> Result<Fitted> {
        let mut fits = fit_all(exp, &self.data, observer)?;
        if let Some(rec) = &self.validation {
            crate::validation::score_fits(&mut fits, rec);
        }
        Ok(Fitted {
            data: self.data,
            fits,
            validation: self.validation,
        })
    }
}

/// Say what looks suspicious about a record read.
pub fn warn_about(data: &FitData, observer: &dyn Observer) {
    for w in &data.record_warnings {
        observer.warning(w);
    }
}

impl Fitted {
    /// The rows of `params.csv`.
    pub fn param_rows(&self) -> Vec<ParamRow> {
        rows_of_fits(&self.fits, &self.data.units)
    }

    /// `fitted.csv`: t, the measured signal (`f_stf` or `x`) and each model's fit of it
    /// (`f_stf_<label>` or `x_<label>`).
    pub fn fitted_columns(&self) -> Columns<'_> {
        let measured = self.data.level.signal().column;
        let columns = Columns::new()
            .with("t", &self.data.record.t)
            .with(measured, self.data.target());
        self.fits.iter().fold(columns, |c, f| {
            c.with(format!("{measured}_{}", f.label), &f.fitted)
        })
    }
}
