//! Comparing fitted models with a record regime by regime: the record is cut into rotor
//! cycles and each labelled pre-resonance, resonance or post-resonance (`stf_core::regimes`);
//! each fitted model's force, on the same kinematics, is scored per regime (force RMS error,
//! energy per cycle, on–off duty, peak force, label agreement, boundary error), and the
//! oscillator with the model plugged in is simulated against the record for the resonance
//! peak ([`compare_fits`]). The result, [`Compared`], is what `compare.json`, `compare.md`,
//! `compare.csv`, `cycles.csv` and the report are rendered from.

use anyhow::{Context, Result};
use serde::Serialize;
use stf_core::data::response::{local_maxima, peak, Peak};
use stf_core::physics::oscillator::Oscillator;
use stf_core::regimes::{
    classify, compare as compare_with, rank_models, rank_on_loops, zero_level_spread, Boundary,
    Classification, Comparison, MetricRanking, OverallScore, Ranking, ZeroLevelSpread,
};
use stf_core::simulate::Simulation;

use crate::experiment::{Experiment, FitLevel};
use crate::fit::FitInputs;
use crate::fitting::{fit_all, FitData, ModelFit};
use crate::observer::Observer;
use crate::validation::ValidationRecord;

/// A comparison with the records it was made on: what `compare.json`, `compare.md`,
/// `compare.csv`, `cycles.csv`, the terminal and the report are rendered from.
pub struct CompareResult {
    /// The record the models were fitted to and compared on.
    pub data: FitData,
    /// The `[validate]` record the fits were scored on.
    pub validation: Option<ValidationRecord>,
    /// The comparison.
    pub compared: Compared,
}

/// Fit every model of `exp` to its record, then compare them regime by regime.
pub fn compare(exp: &mut Experiment, observer: &dyn Observer) -> Result<CompareResult> {
    load(exp, observer)?.compare(exp, observer)
}

/// Read and check the records of a comparison: the record needs the measured force.
pub fn load(exp: &mut Experiment, observer: &dyn Observer) -> Result<FitInputs> {
    let inputs = crate::fit::load(exp, observer)?;
    if inputs.data.level != FitLevel::Force {
        anyhow::bail!(
            "{}: compare scores models on the measured STF force; the record needs `f_stf`",
            exp.path.display()
        );
    }
    Ok(inputs)
}

impl FitInputs {
    /// The measured regimes, the fits (scored on the second record) and their comparison.
    pub fn compare(self, exp: &Experiment, observer: &dyn Observer) -> Result<CompareResult> {
        let measured = measured_regimes(exp, &self.data)?;
        let mut fits = fit_all(exp, &self.data, observer)?;
        if let Some(rec) = &self.validation {
            crate::validation::score_fits(&mut fits, rec);
        }
        let compared = compare_fits(exp, &self.data, measured, fits)?;
        Ok(CompareResult {
            data: self.data,
            validation: self.validation,
            compared,
        })
    }
}

/// The local maxima of a displacement against the rotor speed: a frequency response as a
/// sweep shows it.
#[derive(Clone, Debug)]
pub struct Response {
    /// What it is: `measured`, `without STF` or a model's label.
    pub label: String,
    /// Rotor speed at each local maximum, rad/s.
    pub omega: Vec<f64>,
    /// The local maxima of the displacement, m.
    pub x_peak: Vec<f64>,
}

/// The measured record's regimes.
pub fn measured_regimes(exp: &Experiment, data: &FitData) -> Result<Classification> {
    let f = data
        .record
        .f_stf
        .as_deref()
        .context("comparing models needs the record's `f_stf` column")?;
    let sig = data.force_data().with_force(f);
    let cycles = crate::fitting::cycles_of(data)?;
    Ok(classify(&sig, cycles, &exp.regimes)?)
}

/// The oscillator with the fitted model (or none), driven as in the record: its local maxima
/// of x against ω and its resonance peak (|x|, ω).
pub fn simulated_response(
    exp: &Experiment,
    data: &FitData,
    fit: Option<&ModelFit>,
) -> Result<(Response, (f64, f64))> {
    let k = &data.kinematics;
    let system = fit.map_or(exp.system, |f| f.system);
    let mut osc = Oscillator::new(system, k.excitation());
    if let Some(f) = fit {
        if let Some(c) = &f.configured {
            osc = osc.with_model(c.model.clone(), f.model_values())?;
        }
    }
    let (x0, v0) = k.initial_state();
    let run = Simulation::new(&osc)
        .settings(exp.integrator.clone())
        .initial(x0, v0)
        .run_at(&k.t)?;
    let p = peak(&run.t, &run.x, k.omega.as_deref()).context("empty simulation")?;
    Ok((
        response(
            fit.map_or("without STF", |f| f.label.as_str()),
            &run.t,
            &run.x,
            k.omega.as_deref(),
        ),
        (p.amplitude, p.omega),
    ))
}

/// The frequency response of `x` (times `t`, rotor speed `omega`) called `label`.
pub fn response(label: &str, t: &[f64], x: &[f64], omega: Option<&[f64]>) -> Response {
    let zeros = vec![0.0; t.len()];
    let maxima = local_maxima(t, x, omega.unwrap_or(&zeros));
    Response {
        label: label.to_string(),
        omega: maxima.iter().map(|m| m.omega).collect(),
        x_peak: maxima.iter().map(|m| m.x).collect(),
    }
}

/// Everything a comparison found: the measured record's regimes and peak, each model's fit,
/// its comparison and its simulated response, and the rankings.
pub struct Compared {
    /// The measured record's cycles, labels and boundaries.
    pub measured: Classification,
    /// Each model's fit, in the experiment's order.
    pub fits: Vec<ModelFit>,
    /// Each model's comparison with the record, in the same order.
    pub comparisons: Vec<Comparison>,
    /// The record's resonance peak.
    pub measured_peak: Peak,
    /// Each model's simulated response and its peak (|x| m, ω rad/s); none if it failed.
    pub responses: Vec<Option<(Response, (f64, f64))>>,
    /// The models in order of relative force RMS error: per regime, and overall by the mean
    /// over the regimes (by the whole record on a record with no sweep); the verdict's order.
    pub ranking: Ranking,
    /// The models in order on each loop metric.
    pub loop_rankings: Vec<MetricRanking>,
    /// How the measured boundaries move with the zero-force level (none without STF force).
    pub zero_level: Option<ZeroLevelSpread>,
}

impl Compared {
    /// The models' labels, in order.
    pub fn labels(&self) -> Vec<&str> {
        self.fits.iter().map(|f| f.label.as_str()).collect()
    }

    /// The score the models are ranked by overall (compare.json's `ranking.overall`: the
    /// mean of the per-regime relative force RMS errors, or on a record with no sweep the
    /// error over the whole record) of the model labelled `label`; the one overall score a
    /// report or the terminal shows.
    pub fn mean_error(&self, label: &str) -> Option<f64> {
        let overall = &self.ranking.overall;
        overall.iter().find(|s| s.model == label).map(|s| s.score)
    }

    /// Each model's simulated peak (|x| m, ω rad/s), none where the simulation failed.
    pub fn peaks(&self) -> Vec<Option<(f64, f64)>> {
        self.responses
            .iter()
            .map(|r| r.as_ref().map(|r| r.1))
            .collect()
    }
}

/// Compare every fit in `fits` with the record `data` regime by regime.
pub fn compare_fits(
    exp: &Experiment,
    data: &FitData,
    measured: Classification,
    fits: Vec<ModelFit>,
) -> Result<Compared> {
    let sig = data.force_data();
    let comparisons: Vec<Comparison> = fits
        .iter()
        .map(|f| compare_with(&measured, &sig, &f.fitted, &exp.regimes))
        .collect::<std::result::Result<_, _>>()?;
    let measured_peak = peak(
        &data.record.t,
        &data.record.x,
        data.kinematics.omega.as_deref(),
    )
    .context("empty record")?;
    let responses = fits
        .iter()
        .map(|f| simulated_response(exp, data, Some(f)).ok())
        .collect();
    let labels: Vec<&str> = fits.iter().map(|f| f.label.as_str()).collect();
    let pairs: Vec<(&str, &Comparison)> = labels.iter().copied().zip(comparisons.iter()).collect();
    // A record with no sweep is ranked over the whole record, as its verdict says.
    let over = if data.words().regimes {
        OverallScore::MeanOverRegimes
    } else {
        OverallScore::WholeRecord
    };
    let ranking = rank_models(&pairs, over);
    let loop_rankings = rank_on_loops(&measured, &pairs);
    let zero_level = match data.record.f_stf.as_deref() {
        Some(f) if !measured.no_stf => {
            let force = data.force_data().with_force(f);
            Some(zero_level_spread(
                &force,
                &measured.cycles,
                &exp.regimes,
                &measured,
            )?)
        }
        _ => None,
    };
    Ok(Compared {
        measured,
        fits,
        comparisons,
        measured_peak,
        responses,
        ranking,
        loop_rankings,
        zero_level,
    })
}

/// A boundary as reports show it.
#[derive(Clone, Debug, Serialize)]
pub struct BoundaryNote {
    /// `pre_resonance` (pre → resonance) or `resonance_post`.
    pub boundary: &'static str,
    /// ω, rad/s.
    pub omega: f64,
    /// Half-width of its uncertainty, rad/s.
    pub uncertainty: f64,
    /// The rule that placed it (`force_onset`, `on_off`, `force_gone`, `on_off_from_onset`,
    /// `amplitude`).
    pub rule: stf_core::regimes::BoundaryRule,
    /// The rule in words.
    pub explanation: &'static str,
}

/// The measured boundaries, with the rule that placed each.
pub fn boundary_notes(c: &Classification) -> Vec<BoundaryNote> {
    let note = |name, b: Option<Boundary>| {
        b.map(|b| BoundaryNote {
            boundary: name,
            omega: b.omega,
            uncertainty: b.uncertainty,
            rule: b.rule,
            explanation: b.rule.describe(),
        })
    };
    [
        note("pre_resonance", c.boundaries.pre_resonance),
        note("resonance_post", c.boundaries.resonance_post),
    ]
    .into_iter()
    .flatten()
    .collect()
}
