//! Where a simulated displacement and the measured one disagree: the x residual broken down
//! by ω band of the cycles, by |x|, |v|, |a| of the model's motion and by direction, against
//! the displacement noise floor, said in millimetres.
//!
//! The breakdowns are those of [`locate_gap`] applied to the x residual along the model's
//! simulated motion. The breakdown by regime is left out: the regimes are defined on the
//! measured STF force, which a trajectory-level record does not have (ω bands stand in for
//! them on a sweep).

use super::force_gap::{locate_gap, summary, GapLocation};
use super::trajectory_subset_fit::Run;
use crate::data::force_data::ForceData;
use crate::regimes::Cycle;

/// Locate the x residual of `run` (m) over `cycles`, with displacement noise floor `floor`
/// (m, > 0), said in thousandths of the record's unit, `unit` (`mm`, or `mV` for x in volts).
pub(super) fn locate_x_gap(run: &Run, cycles: &[Cycle], floor: f64, unit: &str) -> GapLocation {
    let s = &run.sim;
    let data = ForceData::new(&s.t, &s.x, &s.v, &s.a, &s.f_stf);
    let mut g = locate_gap(&run.residual, &data, cycles, floor);
    g.breakdowns.retain(|b| b.by != "regime");
    // The summary in thousandths of the record's unit.
    let mm = |v: f64| v * 1e3;
    let head = format!(
        "x residual {:.4} {unit} RMS (S = {:.4} {unit}²) against a noise floor of {:.4} {unit} \
         ({:.1}×)",
        mm(g.rms),
        mm(g.rms) * mm(g.rms),
        mm(floor),
        g.rms / floor
    );
    let say = |v: f64| format!("{:.4} {unit}", mm(v));
    g.summary = summary(head, g.rms, floor, &g.breakdowns, "ω and states", say);
    g
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::simulate::Trajectory;

    #[test]
    fn a_gap_at_large_amplitude_is_said_in_mm_without_regimes() {
        let n = 4000;
        let t: Vec<f64> = (0..n).map(|i| i as f64 * 0.01).collect();
        let phase: Vec<f64> = t.iter().map(|t| std::f64::consts::TAU * t).collect();
        let x: Vec<f64> = phase.iter().map(|p| 0.01 * p.sin()).collect();
        let v: Vec<f64> = phase.iter().map(|p| 0.0628 * p.cos()).collect();
        let a: Vec<f64> = x.iter().map(|x| -39.5 * x).collect();
        let residual: Vec<f64> = x
            .iter()
            .map(|x| if x.abs() > 0.009 { 1e-3 } else { 1e-5 })
            .collect();
        let run = Run {
            sim: Trajectory {
                t: t.clone(),
                x,
                v,
                a,
                f_stf: vec![0.0; n],
                ..Trajectory::default()
            },
            residual,
        };
        let cycles: Vec<Cycle> = (0..39)
            .map(|k| Cycle {
                start: 100 * k,
                end: 100 * (k + 1),
                t_mid: k as f64 + 0.5,
                omega: std::f64::consts::TAU,
            })
            .collect();
        let g = locate_x_gap(&run, &cycles, 1e-5, "mm");
        assert!(g.breakdown("regime").is_none());
        assert!(g.breakdown("|x|").unwrap().contrast > 10.0);
        assert!(g.summary.contains("large |x|"), "{}", g.summary);
        assert!(g.summary.contains("mm") && !g.summary.contains(" N"));
    }
}
