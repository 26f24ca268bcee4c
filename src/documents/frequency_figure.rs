//! The frequency response (local maxima of x against ω, the regimes shaded) in the report of
//! every swept record: the measured record's, the oscillator's without STF, and each model's
//! where the command has one. A record without a rotor speed (a shaker, free vibration) has
//! none. The regimes are the measured record's own, classified on its STF force as `compare`
//! does; a record without STF force shows its response unshaded.

use std::path::Path;

use anyhow::Result;
use stf_core::regimes::Boundaries;
use stf_study::compare::{measured_regimes, response, simulated_response, Response};

use crate::documents::standard_report::frequency_section;
use crate::experiment::Experiment;
use crate::fitting::FitData;
use crate::report::{FrfCurve, FrfRole, RegimeChange, Section};

/// A frequency response as the figure draws it: the measured record's, the oscillator's
/// without STF (dashed) or a model's.
pub fn frf_curve(r: Response) -> FrfCurve {
    let role = match r.label.as_str() {
        "measured" => FrfRole::Measured,
        "without STF" => FrfRole::Reference,
        _ => FrfRole::Model,
    };
    FrfCurve {
        label: r.label,
        omega: r.omega,
        x_peak: r.x_peak,
        role,
    }
}

/// The two changes of regime of `b`, as the figure shades them.
pub fn regime_changes(b: &Boundaries) -> [Option<RegimeChange>; 2] {
    let change = |b: Option<stf_core::regimes::Boundary>| {
        b.map(|b| RegimeChange {
            omega: b.omega,
            uncertainty: b.uncertainty,
        })
    };
    [change(b.pre_resonance), change(b.resonance_post)]
}

/// The response of displacement `x` (m) of `data`'s record, named `label`; `None` when the
/// record has no rotor speed.
pub fn response_of(data: &FitData, label: &str, x: &[f64]) -> Option<Response> {
    let omega = data.kinematics.omega.as_deref()?;
    (x.len() == omega.len()).then(|| response(label, &data.record.t, x, Some(omega)))
}

/// The frequency response section of a swept record (`None` without a rotor speed): the
/// measured response, the oscillator's without STF (when it simulates) and `models`'.
pub fn swept_section(
    exp: &Experiment,
    data: &FitData,
    models: Vec<Response>,
    out: &Path,
) -> Result<Option<Section>> {
    let Some(measured) = response_of(data, "measured", &data.record.x) else {
        return Ok(None);
    };
    let mut curves = vec![measured];
    if let Ok((without, _)) = simulated_response(exp, data, None) {
        curves.push(without);
    }
    curves.extend(models);
    let changes = match data.record.f_stf {
        Some(_) => measured_regimes(exp, data)
            .ok()
            .filter(|c| !c.no_stf)
            .map_or([None, None], |c| regime_changes(&c.boundaries)),
        None => [None, None],
    };
    let curves: Vec<FrfCurve> = curves.into_iter().map(frf_curve).collect();
    Ok(Some(frequency_section(
        "frequency_response",
        &curves,
        changes,
        data.units.x,
        out,
    )?))
}
