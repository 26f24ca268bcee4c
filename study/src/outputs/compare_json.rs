//! `compare.json` of `stf-lab compare`: the measured record's regimes and resonance, each
//! model's fit and its errors regime by regime, the rankings and the best model per regime.

use serde::Serialize;
use stf_core::regimes::{
    Boundaries, BoundaryErrors, MetricRanking, PerRegime, Ranking, Regime, RegimeMetrics,
    RegimeThresholds, ZeroLevelSpread,
};

use super::fit_json::ModelFitJson;
use crate::compare::{BoundaryNote, CompareResult, Compared};
use crate::experiment::Experiment;
use crate::fitting::FitData;
use crate::param_units::in_record_units;
use crate::shown_units::ShownUnits;

/// The whole of `compare.json`.
#[derive(Serialize)]
pub struct CompareJson<'a> {
    /// The experiment file, as given.
    pub experiment: String,
    /// The record compared on (its path).
    pub record: &'a str,
    /// What the record itself shows.
    pub measured: MeasuredJson<'a>,
    /// The regime thresholds used (`[regimes]`).
    pub thresholds: &'a RegimeThresholds,
    /// Each model, in the experiment's order.
    pub models: Vec<ModelComparisonJson<'a>>,
    /// The models in order of relative force RMS error, per regime and overall (the mean
    /// over the regimes; on a record with no sweep, the error over the whole record): the
    /// order the verdict, the terminal and the report give.
    pub ranking: &'a Ranking,
    /// The models in order on each loop metric, with the paired test behind each place.
    pub loop_rankings: &'a [MetricRanking],
    /// The best model's label per regime and overall (null where none was scored).
    pub best: Best<'a>,
    /// The per-cycle table beside this file.
    pub cycles_csv: &'static str,
    /// The record's units of the values here and in `cycles.csv` (whose `_m`, `_j`, `_ns_m`
    /// and `_n` columns hold them).
    pub units: CompareUnits,
    /// The report's opening paragraph, written from `ranking` and `loop_rankings`.
    pub verdict: String,
}

/// The measured record's regimes and resonance.
#[derive(Serialize)]
pub struct MeasuredJson<'a> {
    /// Noise σ of the STF force, N.
    pub noise_sigma: f64,
    /// |F_STF| above which the force counts as on, N.
    pub on_threshold: f64,
    /// The STF force is negligible everywhere (no regimes).
    pub no_stf: bool,
    /// Rotor cycles in the record.
    pub cycles: usize,
    /// Cycles labelled with each regime.
    pub cycles_per_regime: PerRegime<usize>,
    /// The regime boundaries, ω in rad/s.
    pub boundaries: &'a Boundaries,
    /// Each boundary with the rule that placed it, in words.
    pub boundary_notes: Vec<BoundaryNote>,
    /// The zero-force level used (N, and where it comes from), the boundaries recomputed at
    /// half and twice it, and the ω range each boundary spans over them (null without STF
    /// force).
    pub zero_level: Option<&'a ZeroLevelSpread>,
    /// The record's resonance peak.
    pub resonance: PeakJson,
}

/// A resonance peak.
#[derive(Serialize)]
pub struct PeakJson {
    /// Largest |x|, m.
    pub peak_x_m: f64,
    /// ω at the peak, rad/s; null without a rotor speed.
    pub peak_omega_rad_s: f64,
}

/// One model compared with the record.
#[derive(Serialize)]
pub struct ModelComparisonJson<'a> {
    /// The model's name.
    pub name: String,
    /// Its label, unique in the experiment.
    pub label: &'a str,
    /// The fit, as in fit.json.
    pub fit: ModelFitJson<'a>,
    /// Force errors, energies, duty and loop metrics per regime (null: no cycle there).
    pub regimes: &'a PerRegime<RegimeMetrics>,
    /// The same over every cycle.
    pub overall: &'a RegimeMetrics,
    /// How far the boundaries the model's force gives lie from the measured ones, rad/s.
    pub boundary_errors: &'a BoundaryErrors,
    /// The boundaries the model's force gives, ω in rad/s.
    pub model_boundaries: &'a Boundaries,
    /// The oscillator with the model, simulated: its peak (null if the simulation failed).
    pub resonance: Option<ModelPeak>,
}

/// A model's simulated resonance peak against the record's.
#[derive(Serialize)]
pub struct ModelPeak {
    /// Largest |x|, m.
    pub peak_x_m: f64,
    /// ω at the peak, rad/s; null if not finite.
    pub peak_omega_rad_s: f64,
    /// Simulated minus measured peak |x|, m.
    pub peak_x_error_m: f64,
    /// Simulated minus measured peak ω, rad/s; null if not finite.
    pub peak_omega_error_rad_s: f64,
}

/// The best model's label in each regime and overall.
#[derive(Serialize)]
pub struct Best<'a> {
    /// Pre-resonance.
    pub pre_resonance: Option<&'a str>,
    /// Resonance.
    pub resonance: Option<&'a str>,
    /// Post-resonance.
    pub post_resonance: Option<&'a str>,
    /// First in `ranking.overall`: the best by the mean over the regimes, or over the whole
    /// record on a record with no sweep; the model the verdict names first.
    pub overall: Option<&'a str>,
}

impl<'a> CompareJson<'a> {
    /// `compare.json` of the comparison `c` of `exp` on `data`.
    pub fn new(exp: &'a Experiment, data: &'a FitData, c: &'a Compared) -> Self {
        let measured = &c.measured;
        let mut cycles_per_regime = PerRegime::default();
        for r in Regime::ALL {
            let n = measured.labels.iter().filter(|l| **l == r).count();
            cycles_per_regime.set(r, Some(n));
        }
        let peak = &c.measured_peak;
        CompareJson {
            experiment: exp.path.display().to_string(),
            record: &data.record.source,
            measured: MeasuredJson {
                noise_sigma: measured.noise_sigma,
                on_threshold: measured.on_threshold,
                no_stf: measured.no_stf,
                cycles: measured.labels.len(),
                cycles_per_regime,
                boundaries: &measured.boundaries,
                boundary_notes: crate::compare::boundary_notes(measured),
                zero_level: c.zero_level.as_ref(),
                resonance: PeakJson {
                    peak_x_m: peak.amplitude,
                    peak_omega_rad_s: peak.omega,
                },
            },
            thresholds: &exp.regimes,
            models: models(data, c),
            ranking: &c.ranking,
            loop_rankings: &c.loop_rankings,
            best: Best {
                pre_resonance: c.ranking.best_in(Regime::PreResonance),
                resonance: c.ranking.best_in(Regime::Resonance),
                post_resonance: c.ranking.best_in(Regime::PostResonance),
                overall: c.ranking.best_overall(),
            },
            cycles_csv: "cycles.csv",
            units: CompareUnits::of(&data.units),
            verdict: crate::verdict::compare_verdict(c, data.words()),
        }
    }
}

/// The units a comparison's values are in: the record's own. On a record of the trolley x in
/// m, forces in N, energies in J and c_eq in N·s/m; on a record whose x is a voltage kept in
/// volts, x in V, energies in N·V and c_eq in N·s/V (forces in V too when the STF force is a
/// voltage read with a gain of 1).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CompareUnits {
    /// Displacements (`peak_x_m`, `amplitude_m`).
    pub x: &'static str,
    /// Forces (noise floor, peak forces, force errors).
    pub force: &'static str,
    /// Energy per cycle ∮F dx (`energy_j`).
    pub energy: String,
    /// Equivalent viscous damping (`c_eq_ns_m`).
    pub c_eq: String,
}

impl CompareUnits {
    /// The units of a record shown in `units`.
    pub fn of(units: &ShownUnits) -> CompareUnits {
        let energy = match in_record_units("N·m", units).as_str() {
            "N·m" => "J".to_string(),
            other => other.to_string(),
        };
        CompareUnits {
            x: units.x_si,
            force: units.force_si,
            energy,
            c_eq: in_record_units("N·s/m", units),
        }
    }
}

/// Each model's entry.
fn models<'a>(data: &'a FitData, c: &'a Compared) -> Vec<ModelComparisonJson<'a>> {
    let measured = &c.measured_peak;
    c.fits
        .iter()
        .zip(&c.comparisons)
        .zip(&c.responses)
        .map(|((f, cmp), response)| ModelComparisonJson {
            name: f.name(),
            label: &f.label,
            fit: ModelFitJson::new(f, data),
            regimes: &cmp.per_regime,
            overall: &cmp.overall,
            boundary_errors: &cmp.boundary_errors,
            model_boundaries: &cmp.model_boundaries,
            resonance: response.as_ref().map(|r| {
                let (x, w) = r.1;
                ModelPeak {
                    peak_x_m: x,
                    peak_omega_rad_s: w,
                    peak_x_error_m: x - measured.amplitude,
                    peak_omega_error_rad_s: w - measured.omega,
                }
            }),
        })
        .collect()
}

impl CompareResult {
    /// `compare.json` of the experiment `exp`.
    pub fn json<'a>(&'a self, exp: &'a Experiment) -> CompareJson<'a> {
        CompareJson::new(exp, &self.data, &self.compared)
    }
}
