//! The paragraph each report opens with: the judgement, not only the numbers. For `fit`,
//! which model fits best and by how much, and every reason not to trust it; for `compare`,
//! the ranking in each regime, the measure behind it and a paired test of the first two over
//! the regime's cycles; for `discover`, what was named and its share of the excess.

use serde::Serialize;
use stf_core::fit::FitWarning;
use stf_core::regimes::{LoopMetric, PairedTest, Regime};

use stf_core::physics::oscillator_params::{OscParam, OscillatorParams};

use crate::compare::Compared;
use crate::identify::StageOutcome;

use crate::fitting::ModelFit;
use crate::param_units::in_record_units;
use crate::rig_words::RigWords;
use crate::shown_units::ShownUnits;

/// AIC differences below this say the data do not prefer one model over the other
/// (Burnham & Anderson's rule of thumb: ΔAIC < 2, substantial support for both).
const AIC_TIE: f64 = 2.0;

/// The best of fits given as `(AIC, free parameters)`: among those the data do not tell apart
/// from the lowest finite AIC (within ΔAIC 2), the simplest; its index, `None` if no AIC is
/// finite. The rule of [`FitVerdict`], shared with the campaign table.
pub fn best_by_aic(fits: &[(f64, usize)]) -> Option<usize> {
    let lowest = fits
        .iter()
        .map(|f| f.0)
        .filter(|a| a.is_finite())
        .min_by(f64::total_cmp)?;
    let mut near: Vec<usize> = (0..fits.len())
        .filter(|&i| fits[i].0.is_finite() && fits[i].0 - lowest < AIC_TIE)
        .collect();
    // The lowest AIC first among equally simple ones, as the verdict shows it (to 0.1): fits
    // that differ below that (one model fitted from two starts) keep the order listed.
    let shown = |i: usize| (fits[i].0 * 10.0).round();
    near.sort_by(|&a, &b| shown(a).total_cmp(&shown(b)));
    near.into_iter().min_by_key(|&i| fits[i].1)
}

/// How one of the other fits stands against the best (fit.json's `verdict.others`).
#[derive(Clone, Debug, Serialize)]
pub struct Behind {
    /// The fit's label.
    pub label: String,
    /// Its AIC minus the best's.
    pub delta_aic: f64,
    /// Its RMS residual over the best's, minus 1, in %.
    pub rms_change_percent: f64,
    /// Whether the data do not prefer either (|ΔAIC| below `aic_tie`).
    pub as_good: bool,
}

/// The verdict of a set of fits (fit.json's `verdict`): the best by AIC, how far the others
/// are behind (ΔAIC and RMS), and the warnings that stand against the best and the others;
/// `text` is the paragraph the report opens with, written from these fields.
#[derive(Clone, Debug, Serialize)]
pub struct FitVerdict {
    /// The best fit's label (none when no model could be fitted).
    pub best: Option<String>,
    /// Whether the best has the lowest AIC (else it is the simplest within `aic_tie` of it).
    pub lowest_aic: bool,
    /// ΔAIC below which the data do not prefer one fit over another.
    pub aic_tie: f64,
    /// The other fits with a finite AIC, lowest AIC first.
    pub others: Vec<Behind>,
    /// The paragraph.
    pub text: String,
}

impl FitVerdict {
    /// The verdict of `fits`, their errors shown in `shown` (unit, factor from the record's
    /// values: [`crate::fitting::FitData::shown`]).
    pub fn new(fits: &[ModelFit], shown: (&str, f64)) -> Self {
        let mut ranked: Vec<&ModelFit> = fits.iter().filter(|f| f.result.aic.is_finite()).collect();
        ranked.sort_by(|a, b| a.result.aic.total_cmp(&b.result.aic));
        let free = |f: &ModelFit| f.result.params.iter().filter(|p| !p.fixed).count();
        let scored: Vec<(f64, usize)> = fits.iter().map(|f| (f.result.aic, free(f))).collect();
        let Some(best) = best_by_aic(&scored).map(|i| &fits[i]) else {
            return FitVerdict {
                best: None,
                lowest_aic: false,
                aic_tie: AIC_TIE,
                others: Vec::new(),
                text: "No model could be fitted: see the warnings below.".into(),
            };
        };
        let others: Vec<Behind> = ranked
            .iter()
            .filter(|f| f.label != best.label)
            .map(|f| {
                let delta_aic = f.result.aic - best.result.aic;
                Behind {
                    label: f.label.clone(),
                    delta_aic,
                    rms_change_percent: 100.0 * (f.result.rms / best.result.rms - 1.0),
                    as_good: delta_aic.abs() < AIC_TIE,
                }
            })
            .collect();
        let lowest_aic = best.result.aic <= ranked[0].result.aic;
        let text = fit_text(best, lowest_aic, &others, fits, shown);
        FitVerdict {
            best: Some(best.label.clone()),
            lowest_aic,
            aic_tie: AIC_TIE,
            others,
            text,
        }
    }
}

impl crate::fit::Fitted {
    /// The verdict: the best model, how far it is to be trusted, and why (fit.json's
    /// `verdict`; its `text` opens the report).
    pub fn verdict(&self) -> FitVerdict {
        FitVerdict::new(&self.fits, self.data.shown())
    }
}

/// The paragraph of a fit's verdict.
fn fit_text(
    best: &ModelFit,
    lowest_aic: bool,
    others: &[Behind],
    fits: &[ModelFit],
    (unit, scale): (&str, f64),
) -> String {
    let mut text = format!(
        "Best fit: `{}`, RMS residual {:.4} {unit}, AIC {:.1}{}.",
        best.label,
        best.result.rms * scale,
        best.result.aic,
        if lowest_aic {
            " (the lowest)"
        } else {
            " (the simplest of the fits within ΔAIC 2 of the lowest)"
        }
    );
    let others: Vec<String> = others
        .iter()
        .map(|o| {
            let tie = if o.as_good {
                ", as good: the data do not prefer either"
            } else {
                ""
            };
            format!(
                "`{}` ΔAIC {}, RMS {} %{tie}",
                o.label,
                crate::digits::signed(o.delta_aic, 1),
                crate::digits::signed(o.rms_change_percent, 1)
            )
        })
        .collect();
    if !others.is_empty() {
        text.push_str(&format!(" The others: {}.", others.join("; ")));
    }
    text.push(' ');
    text.push_str(&trust(best, fits));
    text
}

/// The warnings against the best fit, stated in full, and a count for the others.
fn trust(best: &ModelFit, fits: &[ModelFit]) -> String {
    let own = if best.warnings.is_empty() {
        format!(
            "`{}` carries no warning: converged, at its noise floor, every parameter determined, \
             none on a bound, none indistinguishable from another.",
            best.label
        )
    } else {
        let said: Vec<String> = best.warnings.iter().map(FitWarning::to_string).collect();
        format!(
            "⚠ Do not take `{}` as it stands: {}.",
            best.label,
            said.join("; ")
        )
    };
    let warned: Vec<String> = fits
        .iter()
        .filter(|f| f.label != best.label && !f.warnings.is_empty())
        .map(|f| format!("`{}` ({})", f.label, f.warnings.len()))
        .collect();
    if warned.is_empty() {
        own
    } else {
        format!(
            "{own} Warnings also stand against {}: see Fits.",
            warned.join(", ")
        )
    }
}

/// The verdict of a comparison (compare.json's `verdict`): the models in order in each
/// regime the record has, by their relative force RMS error over the regime's cycles
/// (compare.json's `ranking`), and whether the best by per-cycle force error is ahead of the
/// runner-up cycle by cycle (the paired test of `loop_rankings`' `force` metric, cycles
/// being the independent units).
pub fn compare_verdict(c: &Compared, words: RigWords) -> String {
    if !words.regimes {
        return whole_record_verdict(c);
    }
    let force = c
        .loop_rankings
        .iter()
        .find(|m| m.metric == LoopMetric::Force);
    let mut parts = Vec::new();
    for r in Regime::ALL {
        let Some(scores) = c.ranking.per_regime.get(r) else {
            continue;
        };
        let order: Vec<String> = scores
            .iter()
            .map(|s| format!("`{}` {:.3}", s.model, s.score))
            .collect();
        let test = force
            .and_then(|m| m.per_regime.get(r))
            .and_then(|rank| rank.test.as_ref())
            .map_or(String::new(), paired_text);
        parts.push(format!(
            "{}: {}{test}",
            r.name().replace('_', "-"),
            order.join(" < ")
        ));
    }
    if parts.is_empty() {
        return "The record has no regime with cycles to rank the models on.".into();
    }
    let overall = c
        .ranking
        .overall
        .first()
        .map(|s| {
            format!(
                " Best over the regimes (the mean of the per-regime errors, each regime weighing \
                 the same): `{}` ({:.3}).",
                s.model, s.score
            )
        })
        .unwrap_or_default();
    format!(
        "Models ranked in each regime by their relative force RMS error over the regime's cycles \
         (the RMS of model − measured force over the measured force's RMS; 0 is perfect, 1 is \
         no better than no force), with the best and the runner-up by per-cycle force error \
         compared cycle by cycle: {}.{overall}",
        parts.join("; ")
    )
}

/// The verdict of a comparison on a record without a rotor: no regimes, the models ranked by
/// their relative force RMS error over the whole record.
fn whole_record_verdict(c: &Compared) -> String {
    // The ranking's own order (over the whole record on such a record: compare.json's
    // `ranking.overall` and `best.overall`).
    let order: Vec<String> = c
        .ranking
        .overall
        .iter()
        .filter(|s| s.score.is_finite())
        .map(|s| format!("`{}` {:.3}", s.model, s.score))
        .collect();
    if order.is_empty() {
        return "No model could be scored on the record.".into();
    }
    format!(
        "Models ranked over the whole record (it has no rotor) by their relative force \
         RMS error (the RMS of model − measured force over the measured force's RMS; 0 is \
         perfect, 1 is no better than no force): {}.",
        order.join(" < ")
    )
}

/// Whether a paired test over `t`'s cycles says anything: at least 3 cycles and a finite z.
pub fn tested(t: &PairedTest) -> bool {
    t.cycles >= 3 && t.z.is_finite()
}

/// `not tested (1 cycle)`: what stands where a paired test had too few cycles to be made
/// (never a z of NaN, never a best declared on it).
pub fn not_tested(cycles: usize) -> String {
    let s = if cycles == 1 { "" } else { "s" };
    format!("not tested ({cycles} cycle{s})")
}

/// ` (`best` ahead of `runner-up`: paired z Z over N cycles)`, or ` (`best` against
/// `runner-up` cycle by cycle: not tested (1 cycle))`.
fn paired_text(t: &PairedTest) -> String {
    if !tested(t) {
        return format!(
            " (`{}` against `{}` cycle by cycle: {})",
            t.best,
            t.runner_up,
            not_tested(t.cycles)
        );
    }
    let call = if t.z > 3.0 { "ahead" } else { "not told apart" };
    format!(
        " (`{}` {call} of `{}`: paired z {:.1} over {} cycles)",
        t.best, t.runner_up, t.z, t.cycles
    )
}

/// The verdict of a discovery (discovery.json's `verdict`): the effects named, the gap
/// before and after against the noise floor (discovery.json's `gap_before`, `gap_after`,
/// `noise_floor`, shown in the level's unit), and the share of the base's excess over the
/// floor the effects explain; `text` is the report's opening paragraph, from these fields.
#[derive(Clone, Debug, Serialize)]
pub struct DiscoverVerdict {
    /// The share (0–1) of the base's excess over the noise floor, in mean square, that the
    /// effects explain (none when the base had no excess).
    pub excess_explained: Option<f64>,
    /// Whether what is left is noise (the final gap within 1.2 × the floor).
    pub left_is_noise: bool,
    /// The paragraph.
    pub text: String,
}

/// The verdict of a discovery: the effects named and how much of the base's excess over the
/// noise floor they explain (RMS gaps `before` → `after` against `floor`, in `unit`).
pub fn discover_verdict(
    effects: &[String],
    before: f64,
    after: f64,
    floor: f64,
    unit: &str,
) -> DiscoverVerdict {
    let excess = |g: f64| (g * g - floor * floor).max(0.0);
    let excess_explained = (excess(before) > 0.0).then(|| 1.0 - excess(after) / excess(before));
    let share = excess_explained.map_or(String::new(), |share| {
        format!(
            ", which explains {:.0} % of the base's excess over the noise floor (in mean square)",
            100.0 * share
        )
    });
    let named = if effects.is_empty() {
        "Nothing named: no effect of the vocabulary improved the held-out fit by the evidence \
         rule"
            .to_string()
    } else {
        format!(
            "Named: {}",
            effects
                .iter()
                .map(|e| format!("`{e}`"))
                .collect::<Vec<_>>()
                .join(", then ")
        )
    };
    let left_is_noise = after <= 1.2 * floor;
    let text = format!(
        "{named}. The gap (RMS of measured − modelled) went from {before:.4} to {after:.4} {unit} \
         against a noise floor of {floor:.4} {unit}{share}; {}",
        if left_is_noise {
            "what is left is noise."
        } else {
            "what is left is above the noise: something is still missing, or the floor is \
             underestimated."
        }
    );
    DiscoverVerdict {
        excess_explained,
        left_is_noise,
        text,
    }
}

/// The oscillator's parameters as a readable line: `m 7.65 kg, k 267.9 N/m, …`, units on a
/// record shown in `units`.
pub fn system_line(system: &OscillatorParams, units: &ShownUnits) -> String {
    OscParam::ALL
        .into_iter()
        .filter(|p| !p.is_offset() || system[*p] != 0.0)
        .map(|p| {
            let unit = in_record_units(p.unit(), units);
            format!("{p} {} {unit}", stf_core::digits::significant(system[p], 6))
                .trim_end()
                .to_string()
        })
        .collect::<Vec<_>>()
        .join(", ")
}

/// The verdict of an identification (its fit.json's `verdict`): what was identified, how
/// close each stage came to its noise floor (each stage's `floor_mm2` and `s_over_floor`),
/// and whether any warning stands; units on a record shown in `units`.
pub fn identify_verdict(
    stages: &[StageOutcome],
    system: &OscillatorParams,
    units: &ShownUnits,
) -> String {
    let fits: Vec<String> = stages
        .iter()
        .enumerate()
        .map(|(i, s)| {
            format!(
                "stage {} ({}) S(μ) = {:.4} {} against the position noise's {:.4} {} ({:.1}×)",
                i + 1,
                s.record,
                s.result.s_mm2.unwrap_or(f64::NAN),
                units.x_squared,
                s.floor_mm2(),
                units.x_squared,
                s.s_over_floor()
            )
        })
        .collect();
    let warned: usize = stages.iter().map(|s| s.warnings.len()).sum();
    format!(
        "Identified oscillator: {}. {}. {}",
        system_line(system, units),
        fits.join("; "),
        if warned == 0 {
            "No stage carries a warning: every stage converged, its free parameters determined, \
             none on a bound and none indistinguishable from another."
                .to_string()
        } else {
            format!("⚠ {warned} warning(s): see each stage's box below before using these values.")
        }
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One model fitted from two starts ends a rounding apart: the first listed stays best;
    /// a lower AIC as shown still wins among equally simple fits, and a simpler fit within
    /// ΔAIC 2 wins over both.
    #[test]
    fn fits_that_differ_below_the_shown_aic_keep_their_order() {
        assert_eq!(best_by_aic(&[(-100.0, 2), (-100.000_001, 2)]), Some(0));
        assert_eq!(best_by_aic(&[(-100.0, 2), (-100.3, 2)]), Some(1));
        assert_eq!(
            best_by_aic(&[(-100.0, 2), (-101.0, 3), (-90.0, 1)]),
            Some(0)
        );
    }

    #[test]
    fn the_paired_test_tells_a_lead_from_a_coin_toss_and_says_when_it_cannot_tell() {
        let test = |cycles, z| PairedTest {
            best: "p".into(),
            runner_up: "q".into(),
            cycles,
            mean_difference: 0.1,
            z,
        };
        let said = paired_text(&test(475, 111.36));
        assert_eq!(said, " (`p` ahead of `q`: paired z 111.4 over 475 cycles)");
        assert!(paired_text(&test(39, 0.08)).contains("not told apart"));
        let one = paired_text(&test(1, f64::NAN));
        assert!(
            one.contains("not tested (1 cycle)") && !one.contains("NaN"),
            "{one}"
        );
    }

    #[test]
    fn a_discovery_verdict_says_what_was_named_and_its_share() {
        let v = discover_verdict(&["cubic_stiffness".into()], 0.1189, 0.0200, 0.0201, "N").text;
        assert!(v.starts_with("Named: `cubic_stiffness`."), "{v}");
        assert!(v.contains("100 % of the base's excess"), "{v}");
        assert!(v.ends_with("what is left is noise."), "{v}");
        let none = discover_verdict(&[], 0.05, 0.05, 0.02, "N").text;
        assert!(
            none.starts_with("Nothing named") && none.contains(" 0 % "),
            "{none}"
        );
        assert!(none.contains("above the noise"), "{none}");
    }
}
