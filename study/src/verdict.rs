//! The paragraph each report opens with: the judgement, not only the numbers. For `fit`,
//! which model fits best and by how much, and every reason not to trust it; for `compare`,
//! the ranking in each regime, the measure behind it and a paired test of the first two over
//! the regime's cycles; for `discover`, what was named and its share of the excess.

use stf_core::fit::FitWarning;
use stf_core::regimes::{Cycle, Ranking, Regime};

use crate::experiment::FitLevel;
use crate::fitting::ModelFit;

/// AIC differences below this say the data do not prefer one model over the other
/// (Burnham & Anderson's rule of thumb: ΔAIC < 2, substantial support for both).
const AIC_TIE: f64 = 2.0;

/// The best of fits given as `(AIC, free parameters)`: among those the data do not tell apart
/// from the lowest finite AIC (within ΔAIC 2), the simplest; its index, `None` if no AIC is
/// finite. The rule of [`fit_verdict`], shared with the campaign table.
pub fn best_by_aic(fits: &[(f64, usize)]) -> Option<usize> {
    let lowest = fits
        .iter()
        .map(|f| f.0)
        .filter(|a| a.is_finite())
        .min_by(f64::total_cmp)?;
    let mut near: Vec<usize> = (0..fits.len())
        .filter(|&i| fits[i].0.is_finite() && fits[i].0 - lowest < AIC_TIE)
        .collect();
    // The lowest AIC first among equally simple ones.
    near.sort_by(|&a, &b| fits[a].0.total_cmp(&fits[b].0));
    near.into_iter().min_by_key(|&i| fits[i].1)
}

/// The verdict of a set of fits: the best by AIC, how far the others are behind (ΔAIC and
/// RMS), and the warnings that stand against the best and the others.
pub fn fit_verdict(fits: &[ModelFit], level: FitLevel) -> String {
    let (unit, scale) = level.shown();
    let mut ranked: Vec<&ModelFit> = fits.iter().filter(|f| f.result.aic.is_finite()).collect();
    ranked.sort_by(|a, b| a.result.aic.total_cmp(&b.result.aic));
    let free = |f: &ModelFit| f.result.params.iter().filter(|p| !p.fixed).count();
    let scored: Vec<(f64, usize)> = fits.iter().map(|f| (f.result.aic, free(f))).collect();
    let Some(best) = best_by_aic(&scored).map(|i| &fits[i]) else {
        return "No model could be fitted: see the warnings below.".into();
    };
    let lowest = ranked[0].result.aic;
    let mut text = format!(
        "Best fit: `{}`, RMS residual {:.4} {unit}, AIC {:.1}{}.",
        best.label,
        best.result.rms * scale,
        best.result.aic,
        if best.result.aic > lowest {
            " (the simplest of the fits within ΔAIC 2 of the lowest)"
        } else {
            " (the lowest)"
        }
    );
    let others: Vec<String> = ranked
        .iter()
        .filter(|f| f.label != best.label)
        .map(|f| {
            let d = f.result.aic - best.result.aic;
            let rms = f.result.rms / best.result.rms - 1.0;
            let tie = if d.abs() < AIC_TIE {
                ", as good: the data do not prefer either"
            } else {
                ""
            };
            format!("`{}` ΔAIC {d:+.1}, RMS {:+.1} %{tie}", f.label, 100.0 * rms)
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

/// The verdict of a comparison: the models in order in each regime the record has, by the
/// relative force RMS error over the regime's cycles, and whether the first is ahead of the
/// second cycle by cycle: a paired z of their per-cycle mean squared errors (`models`' fitted
/// forces against `measured` over each `cycles[i]` labelled `labels[i]`), cycles being the
/// independent units.
pub fn compare_verdict(
    ranking: &Ranking,
    cycles: &[Cycle],
    labels: &[Regime],
    measured: &[f64],
    models: &[(&str, &[f64])],
) -> String {
    let mut parts = Vec::new();
    for r in Regime::ALL {
        let Some(scores) = ranking.per_regime.get(r) else {
            continue;
        };
        let order: Vec<String> = scores
            .iter()
            .map(|s| format!("`{}` {:.3}", s.model, s.score))
            .collect();
        let test = match scores.as_slice() {
            [first, second, ..] => {
                let in_regime: Vec<&Cycle> = cycles
                    .iter()
                    .zip(labels)
                    .filter(|(_, l)| **l == r)
                    .map(|(c, _)| c)
                    .collect();
                let errors = |name: &str| {
                    let f = models.iter().find(|(l, _)| *l == name)?.1;
                    Some(cycle_errors(&in_regime, measured, f))
                };
                match (errors(&first.model), errors(&second.model)) {
                    (Some(a), Some(b)) => paired_test(&a, &b, &first.model, &second.model),
                    _ => String::new(),
                }
            }
            _ => String::new(),
        };
        parts.push(format!(
            "{}: {}{test}",
            r.name().replace('_', "-"),
            order.join(" < ")
        ));
    }
    if parts.is_empty() {
        return "The record has no regime with cycles to rank the models on.".into();
    }
    let overall = ranking
        .overall
        .first()
        .map(|s| {
            format!(
                " Best overall (the mean over regimes, each weighing the same): `{}` ({:.3}).",
                s.model, s.score
            )
        })
        .unwrap_or_default();
    format!(
        "Models ranked in each regime by their relative force RMS error over the regime's cycles \
         (the RMS of model − measured force over the measured force's RMS; 0 is perfect, 1 is \
         no better than no force), the first two compared cycle by cycle: {}.{overall}",
        parts.join("; ")
    )
}

/// The mean squared error of `fitted` against `measured` over each cycle.
fn cycle_errors(cycles: &[&Cycle], measured: &[f64], fitted: &[f64]) -> Vec<f64> {
    cycles
        .iter()
        .filter(|c| c.end <= measured.len() && c.end <= fitted.len() && c.start < c.end)
        .map(|c| {
            let n = (c.end - c.start) as f64;
            (c.start..c.end)
                .map(|i| (fitted[i] - measured[i]).powi(2))
                .sum::<f64>()
                / n
        })
        .collect()
}

/// ` (paired over N cycles: z Z, ahead in K)` for the per-cycle errors `a` (the first) and `b`.
fn paired_test(a: &[f64], b: &[f64], first: &str, second: &str) -> String {
    let d: Vec<f64> = b
        .iter()
        .zip(a)
        .map(|(b, a)| b - a)
        .filter(|d| d.is_finite())
        .collect();
    let n = d.len();
    if n < 3 {
        return format!(" (too few cycles, {n}, to tell `{first}` from `{second}`)");
    }
    let mean = d.iter().sum::<f64>() / n as f64;
    let sd = (d.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1) as f64).sqrt();
    let ahead = d.iter().filter(|x| **x > 0.0).count();
    let z = if sd > 0.0 {
        mean / (sd / (n as f64).sqrt())
    } else {
        f64::INFINITY
    };
    let call = if z > 3.0 { "ahead" } else { "not told apart" };
    format!(" (`{first}` {call} of `{second}`: paired z {z:.1} over {n} cycles, smaller error in {ahead})")
}

/// The verdict of a discovery: the effects named and how much of the base's excess over the
/// noise floor they explain (RMS gaps `before` → `after` against `floor`, in `unit`).
pub fn discover_verdict(
    effects: &[String],
    before: f64,
    after: f64,
    floor: f64,
    unit: &str,
) -> String {
    let excess = |g: f64| (g * g - floor * floor).max(0.0);
    let share = if excess(before) > 0.0 {
        format!(
            ", which explains {:.0} % of the base's excess over the noise floor (in mean square)",
            100.0 * (1.0 - excess(after) / excess(before))
        )
    } else {
        String::new()
    };
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
    format!(
        "{named}. The gap (RMS of measured − modelled) went from {before:.4} to {after:.4} {unit} \
         against a noise floor of {floor:.4} {unit}{share}; {}",
        if after <= 1.2 * floor {
            "what is left is noise."
        } else {
            "what is left is above the noise: something is still missing, or the floor is \
             underestimated."
        }
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_paired_test_tells_a_consistent_lead_from_a_coin_toss() {
        let a = [1.0, 1.1, 0.9, 1.0, 1.05, 0.95];
        let better: Vec<f64> = a.iter().map(|x| x + 0.5).collect();
        let said = paired_test(&a, &better, "p", "q");
        assert!(
            said.contains("`p` ahead of `q`") && said.contains("smaller error in 6"),
            "{said}"
        );
        let mixed = [1.2, 0.8, 1.1, 0.9, 1.0, 1.0];
        let said = paired_test(&a, &mixed, "p", "q");
        assert!(said.contains("not told apart"), "{said}");
        assert!(paired_test(&a[..2], &mixed[..2], "p", "q").contains("too few cycles"));
    }

    #[test]
    fn a_discovery_verdict_says_what_was_named_and_its_share() {
        let v = discover_verdict(&["cubic_stiffness".into()], 0.1189, 0.0200, 0.0201, "N");
        assert!(v.starts_with("Named: `cubic_stiffness`."), "{v}");
        assert!(v.contains("100 % of the base's excess"), "{v}");
        assert!(v.ends_with("what is left is noise."), "{v}");
        let none = discover_verdict(&[], 0.05, 0.05, 0.02, "N");
        assert!(
            none.starts_with("Nothing named") && none.contains(" 0 % "),
            "{none}"
        );
        assert!(none.contains("above the noise"), "{none}");
    }
}
