//! Where the report's regime windows sit, and why: a few cycles where each regime is by the
//! study's definitions (`stf_core::regimes`), each named with the reason it was chosen.
//!
//! - **resonance**: around the amplitude peak when the peak's cycle is resonance (the force on
//!   for most of the cycle there); otherwise around the resonance cycle of largest amplitude.
//! - **pre-resonance**: the middle of the longest run of pre-resonance cycles (force
//!   negligible) below the amplitude peak's ω — never the peak itself.
//! - **post-resonance**: the middle of the longest run of post-resonance cycles, above the
//!   resonance → post-resonance boundary.
//! - **amplitude peak**: when the peak's own force stays negligible (the definitions call it
//!   pre-resonance, though the motion is at its largest), a window at the peak named so, with
//!   the reason it is no resonance by the force — the peak is never shown as pre-resonance.

use stf_core::regimes::{Classification, Regime};

/// A window of `count` cycles from `first`, named (short, for the figure) and explained (a
/// sentence, for the text).
#[derive(Clone, Debug, PartialEq)]
pub struct Placement {
    /// The regime shown, or `amplitude peak`.
    pub regime: String,
    /// The figure's heading: the regime, why, the ω span.
    pub name: String,
    /// Why the window sits where it does, with the definitions' numbers.
    pub why: String,
    /// First cycle.
    pub first: usize,
    /// Number of cycles.
    pub count: usize,
}

/// `count` cycles centred on `centre`, kept inside `lo..hi`.
fn around(centre: usize, count: usize, (lo, hi): (usize, usize)) -> (usize, usize) {
    let count = count.min(hi - lo);
    let first = centre.saturating_sub(count / 2).max(lo).min(hi - count);
    (first, count)
}

/// The longest run of consecutive cycles for which `keep` holds: `(first, length)`.
fn longest_run(n: usize, keep: impl Fn(usize) -> bool) -> Option<(usize, usize)> {
    let mut best: Option<(usize, usize)> = None;
    let mut i = 0;
    while i < n {
        if !keep(i) {
            i += 1;
            continue;
        }
        let start = i;
        while i < n && keep(i) {
            i += 1;
        }
        if best.is_none_or(|(_, len)| i - start > len) {
            best = Some((start, i - start));
        }
    }
    best
}

/// The run of consecutive cycles around `i` with its label, as `(first, one past the last)`.
fn run_of(labels: &[Regime], i: usize) -> (usize, usize) {
    let same = |j: usize| labels[j] == labels[i];
    let lo = (0..=i).rev().take_while(|&j| same(j)).last().unwrap_or(i);
    let hi = (i..labels.len())
        .take_while(|&j| same(j))
        .last()
        .unwrap_or(i)
        + 1;
    (lo, hi)
}

/// The cycle of largest amplitude among those for which `keep` holds.
fn largest(c: &Classification, keep: impl Fn(usize) -> bool) -> Option<usize> {
    (0..c.features.len())
        .filter(|&i| keep(i) && c.features[i].amplitude.is_finite())
        .max_by(|&a, &b| c.features[a].amplitude.total_cmp(&c.features[b].amplitude))
}

/// The windows of `per_window` cycles each, in the order pre-resonance,
/// resonance (or amplitude peak), post-resonance; see the [module doc](self). Amplitudes are
/// said in `x_unit` (thousandths of the record's unit of x: `mm`, or `mV` for x in volts),
/// forces in `force_unit` (the record's: N, or V for a force read in volts).
pub fn place_windows(
    c: &Classification,
    per_window: usize,
    (x_unit, force_unit): (&str, &str),
) -> Vec<Placement> {
    let n = c.features.len().min(c.labels.len()).min(c.cycles.len());
    let Some(peak) = largest(c, |i| i < n) else {
        return Vec::new();
    };
    let omega = |i: usize| c.features[i].omega;
    let milli = |i: usize| c.features[i].amplitude * 1e3;
    let label = |i: usize| c.labels[i];
    let span = |(first, count): (usize, usize)| {
        format!(
            "ω {:.2}–{:.2} rad/s",
            omega(first),
            omega(first + count - 1)
        )
    };
    let placed = |regime: &str, short: &str, why: String, (first, count)| Placement {
        regime: regime.to_string(),
        name: format!("{regime}: {short}, {}", span((first, count))),
        why: format!("{regime} ({}): {why}", span((first, count))),
        first,
        count,
    };
    let mut out = Vec::new();
    let below_peak = |i: usize| label(i) == Regime::PreResonance && omega(i) < omega(peak);
    if let Some((first, len)) = longest_run(n, below_peak) {
        let why = format!(
            "the force negligible (its peak ≤ {:.2} {force_unit}), in the middle of the longest \
             such run below the amplitude peak at ω {:.2} rad/s",
            c.negligible_level,
            omega(peak)
        );
        let w = around(first + len / 2, per_window, (first, first + len));
        out.push(placed("pre-resonance", "force negligible", why, w));
    }
    let labels = &c.labels[..n];
    let w = around(peak, per_window, run_of(labels, peak));
    match label(peak) {
        Regime::Resonance => {
            let why = format!(
                "around the amplitude peak ({:.1} {x_unit} at ω {:.2} rad/s), where the force is on \
                 for most of the cycle",
                milli(peak),
                omega(peak)
            );
            out.push(placed("resonance", "amplitude peak", why, w));
        }
        Regime::PreResonance => {
            let why = format!(
                "the largest amplitude ({:.1} {x_unit} at ω {:.2} rad/s), where the force stays \
                 negligible (its peak ≤ {:.2} {force_unit}): no resonance by the force \
                 definition, and not pre-resonance either, since the motion is at its largest",
                milli(peak),
                omega(peak),
                c.negligible_level
            );
            out.push(placed("amplitude peak", "force negligible", why, w));
        }
        Regime::PostResonance => {}
    }
    if label(peak) != Regime::Resonance {
        if let Some(r) = largest(c, |i| i < n && label(i) == Regime::Resonance) {
            let why = format!(
                "around the largest amplitude among the cycles whose force is on for most of \
                 the cycle ({:.1} {x_unit} at ω {:.2} rad/s; the record's peak, at ω {:.2} rad/s, is \
                 not resonance)",
                milli(r),
                omega(r),
                omega(peak)
            );
            let w = around(r, per_window, run_of(labels, r));
            out.push(placed("resonance", "its largest amplitude", why, w));
        }
    }
    if let Some((first, len)) = longest_run(n, |i| label(i) == Regime::PostResonance) {
        let after = c.boundaries.resonance_post.map_or(String::new(), |b| {
            format!(
                ", past the resonance → post-resonance boundary at ω {:.2} rad/s ({})",
                b.omega,
                b.rule.describe()
            )
        });
        let why = format!(
            "the force on–off or back to negligible, in the middle of the longest run of such \
             cycles{after}"
        );
        let w = around(first + len / 2, per_window, (first, first + len));
        out.push(placed("post-resonance", "force on–off", why, w));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use stf_core::regimes::{Boundaries, Cycle, CycleFeatures};
    use Regime::{PostResonance as Post, PreResonance as Pre, Resonance as Res};

    /// A classification of cycles at ω 3, 3.25, … with `amplitude` (mm) and `labels`.
    fn classified(amplitude_mm: &[f64], labels: &[Regime]) -> Classification {
        let n = labels.len();
        let features = (0..n)
            .map(|i| CycleFeatures {
                t_mid: i as f64,
                omega: 3.0 + 0.25 * i as f64,
                amplitude: amplitude_mm[i] * 1e-3,
                f_peak: 1.0,
                f_rms: 0.5,
                duty: 0.8,
                energy: 0.0,
                energy_ratio: 0.0,
                corr_x: 0.0,
                corr_v: 0.0,
                corr_a: 0.0,
                f_peak_smooth: 1.0,
                c_eq: 0.0,
                phase_x: f64::NAN,
                phase_v: f64::NAN,
            })
            .collect();
        let cycles = (0..n)
            .map(|i| Cycle {
                start: 100 * i,
                end: 100 * (i + 1),
                t_mid: i as f64,
                omega: 3.0 + 0.25 * i as f64,
            })
            .collect();
        Classification {
            noise_sigma: 0.01,
            on_threshold: 0.05,
            negligible_level: 0.2,
            no_stf: false,
            peak_omega: f64::NAN,
            cycles,
            features,
            raw_labels: labels.to_vec(),
            labels: labels.to_vec(),
            boundaries: Boundaries::default(),
        }
    }

    /// A resonance peak at cycle 12 of 40 (ω 6.0) and `labels`.
    fn peaked(labels: &[Regime]) -> Classification {
        let a: Vec<f64> = (0..labels.len())
            .map(|i| 30.0 / (1.0 + (i as f64 - 12.0).powi(2) / 9.0))
            .collect();
        classified(&a, labels)
    }

    #[test]
    fn resonance_lasting_to_the_end_is_shown_at_the_amplitude_peak() {
        // No post-resonance: the resonance run is cycles 8..40, its middle at cycle 24.
        let labels: Vec<Regime> = (0..40).map(|i| if i < 8 { Pre } else { Res }).collect();
        let w = place_windows(&peaked(&labels), 3, ("mm", "N"));
        let names: Vec<&str> = w.iter().map(|p| p.regime.as_str()).collect();
        assert_eq!(names, ["pre-resonance", "resonance"]);
        assert_eq!((w[1].first, w[1].count), (11, 3), "{w:?}");
        assert!(
            w[1].name
                .starts_with("resonance: amplitude peak, ω 5.75–6.25"),
            "{w:?}"
        );
        assert!(w[1].why.contains("30.0 mm at ω 6.00 rad/s"), "{}", w[1].why);
        assert!(w[0].first + w[0].count <= 8);
    }

    #[test]
    fn a_peak_with_negligible_force_is_never_called_pre_resonance() {
        // The force passes the negligible level only at cycle 20, after the peak (cycle 12).
        let labels: Vec<Regime> = (0..40)
            .map(|i| match i {
                0..20 => Pre,
                20..30 => Res,
                _ => Post,
            })
            .collect();
        let w = place_windows(&peaked(&labels), 3, ("mm", "N"));
        let names: Vec<&str> = w.iter().map(|p| p.regime.as_str()).collect();
        assert_eq!(
            names,
            [
                "pre-resonance",
                "amplitude peak",
                "resonance",
                "post-resonance"
            ]
        );
        let pre = &w[0];
        assert!(
            pre.first + pre.count <= 12,
            "pre-resonance below the peak: {pre:?}"
        );
        assert_eq!(w[1].first, 11);
        assert!(w[1]
            .why
            .contains("force stays negligible (its peak ≤ 0.20 N)"));
        // A record whose force is read in volts says its level in volts.
        let volts = place_windows(&peaked(&labels), 3, ("mV", "V"));
        assert!(
            volts[0].why.contains("(its peak ≤ 0.20 V)"),
            "{:?}",
            volts[0]
        );
        assert!(
            volts[1].why.contains("(its peak ≤ 0.20 V)"),
            "{:?}",
            volts[1]
        );
        assert!(!volts[1].why.contains(" N)"), "{:?}", volts[1]);
        assert_eq!(
            w[2].first, 20,
            "the largest resonant amplitude, in its run: {w:?}"
        );
        assert!(w[3].first >= 30);
    }

    #[test]
    fn a_short_record_gets_the_cycles_it_has() {
        let w = place_windows(&peaked(&[Res, Res]), 3, ("mm", "N"));
        assert_eq!((w[0].first, w[0].count), (0, 2));
        assert!(place_windows(&peaked(&[]), 3, ("mm", "N")).is_empty());
    }
}
