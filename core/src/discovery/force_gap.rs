//! Where a model and the measurement disagree: the residual broken down by regime, by ω band
//! and by region of state, against the noise floor, and said in words.
//!
//! Each breakdown splits the samples into groups (regimes of the sweep; equal-width bands of
//! the cycles' ω; |x|, |v|, |a| below or above their medians; direction of motion) and gives
//! the RMS residual of each group. A breakdown whose groups differ a lot (the largest RMS at
//! least 1.5 times the smallest) localises the gap; the summary names the group with the
//! largest RMS of the most contrasted breakdowns.

use serde::Serialize;

use super::holdout::{rms, rms_of};
use crate::data::force_data::ForceData;
use crate::regimes::{classify, Cycle, RegimeThresholds};

/// Number of ω bands of the breakdown.
pub const OMEGA_BANDS: usize = 4;

/// A breakdown is reported in the summary when its largest group RMS is at least this many
/// times its smallest.
pub const CONTRAST: f64 = 1.5;

/// One group of samples and its residual.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GapGroup {
    /// What the group is (`large |v|`, `5.2–6.9 rad/s`, `post_resonance`).
    pub label: String,
    /// Samples in the group.
    pub n: usize,
    /// RMS residual over the group, N.
    pub rms: f64,
    /// `rms` over the noise floor.
    pub over_floor: f64,
}

/// The residual along one way of splitting the samples.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GapBreakdown {
    /// The quantity split on (`regime`, `omega`, `|x|`, `|v|`, `|a|`, `direction`).
    pub by: String,
    /// Its groups (empty groups left out).
    pub groups: Vec<GapGroup>,
    /// Largest group RMS over the smallest (1 with fewer than two groups).
    pub contrast: f64,
}

/// Where the residual of a model lives.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct GapLocation {
    /// RMS residual over the whole record, N.
    pub rms: f64,
    /// The noise floor σ, N.
    pub noise_floor: f64,
    /// The breakdowns.
    pub breakdowns: Vec<GapBreakdown>,
    /// One line saying where the gap lives.
    pub summary: String,
}

impl GapLocation {
    /// The breakdown by `by`.
    pub fn breakdown(&self, by: &str) -> Option<&GapBreakdown> {
        self.breakdowns.iter().find(|b| b.by == by)
    }
}

/// Locate the residual `r` (measured − modelled, N) of a model along `data`, cut into
/// `cycles`, with noise floor `floor` (N, > 0). The regimes are those of the measured force
/// ([`classify()`] with default thresholds and this floor); if they cannot be classified, the
/// breakdown by regime is left out.
pub fn locate_gap(r: &[f64], data: &ForceData, cycles: &[Cycle], floor: f64) -> GapLocation {
    let n = r.len();
    let total = rms(r);
    let group = |label: String, idx: &mut dyn Iterator<Item = usize>| {
        let (rms, count) = rms_of(idx.filter(|&i| i < n).map(|i| r[i]));
        GapGroup {
            label,
            n: count,
            rms,
            over_floor: rms / floor,
        }
    };
    let mut breakdowns = Vec::new();

    // Regimes of the measured force.
    let th = RegimeThresholds {
        noise_sigma: Some(floor),
        ..RegimeThresholds::default()
    };
    if let Ok(class) = classify(data, cycles.to_vec(), &th) {
        let mut groups = Vec::new();
        for regime in crate::regimes::Regime::ALL {
            let mut idx = class
                .cycles
                .iter()
                .zip(&class.labels)
                .filter(|(_, &l)| l == regime)
                .flat_map(|(c, _)| c.start..c.end);
            groups.push(group(regime.name().to_string(), &mut idx));
        }
        breakdowns.push(finish("regime", groups));
    }

    // ω bands of the cycles.
    let (lo, hi) = cycles.iter().fold((f64::INFINITY, 0.0f64), |(lo, hi), c| {
        (lo.min(c.omega), hi.max(c.omega))
    });
    if hi > lo {
        let width = (hi - lo) / OMEGA_BANDS as f64;
        let mut groups = Vec::new();
        for b in 0..OMEGA_BANDS {
            let (w0, w1) = (lo + b as f64 * width, lo + (b + 1) as f64 * width);
            let last = b + 1 == OMEGA_BANDS;
            let mut idx = cycles
                .iter()
                .filter(|c| c.omega >= w0 && (c.omega < w1 || last))
                .flat_map(|c| c.start..c.end);
            groups.push(group(format!("ω {w0:.2}–{w1:.2} rad/s"), &mut idx));
        }
        breakdowns.push(finish("omega", groups));
    }

    // Regions of state.
    for (name, col) in [("|x|", data.x), ("|v|", data.v), ("|a|", data.a)] {
        let mut mags: Vec<f64> = col.iter().map(|v| v.abs()).collect();
        let med = crate::regimes::noise::median(&mut mags);
        let mut small = (0..col.len()).filter(|&i| col[i].abs() <= med);
        let mut large = (0..col.len()).filter(|&i| col[i].abs() > med);
        let groups = vec![
            group(format!("small {name}"), &mut small),
            group(format!("large {name}"), &mut large),
        ];
        breakdowns.push(finish(name, groups));
    }
    let mut up = (0..data.v.len()).filter(|&i| data.v[i] > 0.0);
    let mut down = (0..data.v.len()).filter(|&i| data.v[i] <= 0.0);
    let groups = vec![
        group("moving towards +x".into(), &mut up),
        group("moving towards −x".into(), &mut down),
    ];
    breakdowns.push(finish("direction", groups));

    let summary = summarise(total, floor, &breakdowns);
    GapLocation {
        rms: total,
        noise_floor: floor,
        breakdowns,
        summary,
    }
}

/// `g` without its breakdown by regime, said again: for a record without a rotor, which has
/// no regimes.
pub(super) fn without_regimes(mut g: GapLocation) -> GapLocation {
    g.breakdowns.retain(|b| b.by != "regime");
    let head = head_of(g.rms, g.noise_floor);
    g.summary = summary(
        head,
        g.rms,
        g.noise_floor,
        &g.breakdowns,
        "ω and states",
        |v| format!("{v:.3} N"),
    );
    g
}

fn finish(by: &str, groups: Vec<GapGroup>) -> GapBreakdown {
    let groups: Vec<GapGroup> = groups.into_iter().filter(|g| g.n > 0).collect();
    let max = groups.iter().map(|g| g.rms).fold(0.0, f64::max);
    let min = groups.iter().map(|g| g.rms).fold(f64::INFINITY, f64::min);
    let contrast = if groups.len() < 2 || !(min > 0.0) {
        1.0
    } else {
        max / min
    };
    GapBreakdown {
        by: by.to_string(),
        groups,
        contrast,
    }
}

/// The residual `total` against the noise floor `floor`, in words.
fn head_of(total: f64, floor: f64) -> String {
    format!(
        "residual {total:.3} N RMS against a noise floor of {floor:.3} N ({:.1}×)",
        total / floor
    )
}

/// The one-line description of where the gap lives.
fn summarise(total: f64, floor: f64, breakdowns: &[GapBreakdown]) -> String {
    let head = head_of(total, floor);
    summary(
        head,
        total,
        floor,
        breakdowns,
        "regimes, ω and states",
        |v| format!("{v:.3} N"),
    )
}

/// The one-line description of where a residual of RMS `total` lives, after `head` (the
/// residual against the noise floor `floor`, in words): at the floor, spread evenly over
/// what the `breakdowns` split on (`evenly_over`, in words), or the groups with the largest
/// RMS of the three most contrasted breakdowns, each RMS said by `say` (with its unit).
pub(super) fn summary(
    head: String,
    total: f64,
    floor: f64,
    breakdowns: &[GapBreakdown],
    evenly_over: &str,
    say: impl Fn(f64) -> String,
) -> String {
    if total <= 1.2 * floor {
        return format!("{head}: at the noise floor, no gap to locate");
    }
    let mut contrasted: Vec<&GapBreakdown> = breakdowns
        .iter()
        .filter(|b| b.contrast >= CONTRAST)
        .collect();
    contrasted.sort_by(|a, b| b.contrast.total_cmp(&a.contrast));
    if contrasted.is_empty() {
        return format!("{head}: spread evenly over {evenly_over}");
    }
    let parts: Vec<String> = contrasted
        .iter()
        .take(3)
        .filter_map(|b| {
            let top = b.groups.iter().max_by(|x, y| x.rms.total_cmp(&y.rms))?;
            let low = b.groups.iter().min_by(|x, y| x.rms.total_cmp(&y.rms))?;
            Some(format!(
                "{} ({} vs {} at {})",
                top.label,
                say(top.rms),
                say(low.rms),
                low.label
            ))
        })
        .collect();
    format!("{head}: largest at {}", parts.join("; at "))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_gap_at_large_speed_is_located_there() {
        // 40 cycles of x = sin, v = cos; a residual only where |v| > 0.9.
        let n = 4000;
        let t: Vec<f64> = (0..n).map(|i| i as f64 * 0.01).collect();
        let phase: Vec<f64> = t.iter().map(|t| std::f64::consts::TAU * t).collect();
        let x: Vec<f64> = phase.iter().map(|p| p.sin()).collect();
        let v: Vec<f64> = phase.iter().map(|p| p.cos()).collect();
        let a = x.iter().map(|x| -x).collect::<Vec<_>>();
        let f = vec![0.0; n];
        let r: Vec<f64> = v
            .iter()
            .map(|v| if v.abs() > 0.9 { 1.0 } else { 0.01 })
            .collect();
        let cycles: Vec<Cycle> = (0..39)
            .map(|k| Cycle {
                start: 100 * k,
                end: 100 * (k + 1),
                t_mid: k as f64 + 0.5,
                omega: std::f64::consts::TAU,
            })
            .collect();
        let data = ForceData::new(&t, &x, &v, &a, &f);
        let g = locate_gap(&r, &data, &cycles, 0.01);
        let by_v = g.breakdown("|v|").unwrap();
        assert!(by_v.contrast > 10.0, "{by_v:?}");
        assert!(g.breakdown("|x|").unwrap().contrast > 10.0);
        assert!(g.breakdown("direction").unwrap().contrast < 1.2);
        assert!(g.summary.contains("large |v|"), "{}", g.summary);
        // At the floor: nothing to locate.
        let quiet = vec![0.01; n];
        let g = locate_gap(&quiet, &data, &cycles, 0.01);
        assert!(g.summary.contains("no gap"), "{}", g.summary);
    }
}
