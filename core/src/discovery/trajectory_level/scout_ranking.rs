//! Which scouted candidates are tried on the whole record ([`crate::discovery::scout`]): each ranked by
//! the gain of its scout fit ([`TrajectoryLevel::scout_ranks`]), the best [`SCOUT_KEEP`] kept unless
//! their gain is a small share of the best one's ([`left_out`]); and where a scouted fit
//! continues on the whole record ([`scouted`]).

use super::TrajectoryLevel;
use crate::discovery::choice::Trial;
use crate::discovery::holdout::rms_over;
use crate::discovery::scout::Scout;
use crate::discovery::search_model::SearchModel;
use crate::discovery::settings::DiscoverySettings;
use crate::discovery::trajectory_setup::TrajectorySetup;
use crate::discovery::trajectory_subset_fit::{Rig, Track};

/// Candidates fitted on the whole record in a scouted step, at most: the others are ranked
/// out by their fits on the scout (see [`TrajectoryLevel::scores`]).
pub(in crate::discovery) const SCOUT_KEEP: usize = 3;

/// The least share of the best candidate's gain on the scout for a candidate to be tried on
/// the whole record in a scouted step (see [`TrajectoryLevel::scores`]). A candidate that lowers the
/// scout's mean square by a fraction of what the best one does cannot win the step unless
/// the best one fails on the whole record; on Silverbox's 100 000 samples `jamming_on_off`
/// (5 % of the excess explained) cost more than the two cubic springs' trials together. The
/// rule holds however few candidates were searched: on the paper's sweep with an added mass
/// hidden the force screen kept three, and the whole-record trials of `maxwell` and `yield`
/// (gains under 1 % of `added_mass`'s on the scout) took 3.4 s of the first step's 3.9 s.
pub(in crate::discovery) const SCOUT_SHARE: f64 = 0.2;

/// Why a scouted candidate is not fitted on the whole record, if it is not: its scout rank
/// (`rank` of `of`, gain in m²) is past [`SCOUT_KEEP`], its gain is under [`SCOUT_SHARE`] of
/// the best candidate's `best`, or its scout fit (`start_rms`, m) is no better than the
/// current model's training RMS `current` on the whole record — where the search failed, and
/// a short polish does not climb out. Said in `unit` (`mm`, or `mV` for a record whose x is
/// a voltage: thousandths of the record's unit either way).
pub(in crate::discovery) fn left_out(
    scout_rank: Option<(usize, usize, f64)>,
    best: f64,
    (start_rms, current): (f64, f64),
    unit: &str,
) -> Option<String> {
    if let Some((r, of, gain)) = scout_rank {
        if r >= SCOUT_KEEP {
            return Some(format!(
                "not fitted on the whole record: the scout ranks it {} of {of} (it lowers the \
                 scout's mean square by {:.3e} {unit}²)",
                r + 1,
                gain * 1e6
            ));
        }
        if best > 0.0 && gain < SCOUT_SHARE * best {
            return Some(format!(
                "not fitted on the whole record: on the scout it lowers the mean square by \
                 {:.3e} {unit}², less than {:.0} % of the best candidate's {:.3e} {unit}²",
                gain * 1e6,
                SCOUT_SHARE * 100.0,
                best * 1e6
            ));
        }
    }
    (start_rms >= current).then(|| {
        format!(
            "not fitted on the whole record: its scout fit leaves the training RMS at {:.4} \
             {unit}, not below the current model's {:.4} {unit}",
            start_rms * 1e3,
            current * 1e3
        )
    })
}

impl Scout<'_> {
    /// The mean square of `stage`'s residual over the scout's training samples (`None` when
    /// it cannot be simulated).
    fn mean_square(&self, stage: &SearchModel) -> Option<f64> {
        let r = self.residual(&stage.model().ok()?, &stage.values).ok()?;
        Some(rms_over(&r, &self.train).powi(2))
    }
}

impl TrajectoryLevel<'_> {
    /// Each searched candidate's rank among them by the gain of its scout fit over the
    /// current model on the scout, their number and the gain (mean square, m²); all `None`
    /// without a scout, or when fewer than two were searched. (With no more than
    /// [`SCOUT_KEEP`] searched no rank leaves one out, but the share rule of [`left_out`]
    /// still does.)
    pub(in crate::discovery) fn scout_ranks(
        &self,
        searched: &[Option<(SearchModel, f64, f64)>],
        current: &Trial,
    ) -> Vec<Option<(usize, usize, f64)>> {
        let mut out = vec![None; searched.len()];
        let of = searched.iter().flatten().count();
        let Some(scout) = self.scout.as_ref().filter(|_| of > 1) else {
            return out;
        };
        let Some(reference) = scout.mean_square(&current.stage) else {
            return out;
        };
        let mut order: Vec<(usize, f64)> = searched
            .iter()
            .enumerate()
            .filter_map(|(i, s)| s.as_ref().map(|(_, ms, _)| (i, reference - ms)))
            .collect();
        order.sort_by(|a, b| b.1.total_cmp(&a.1));
        for (r, (i, gain)) in order.into_iter().enumerate() {
            out[i] = Some((r, of, gain));
        }
        out
    }
}

/// Where a fit scouted on `scout` continues on the whole record: `stage` fitted on the scout
/// if that lowers the whole record's RMS at the samples `train`, else `stage` (one
/// simulation of each); with its mean square on the scout's training samples (m²) and its RMS
/// at `train` (m). The simulation of `stage` runs beside the scout fit.
pub(in crate::discovery) fn scouted(
    stage: SearchModel,
    scout: &Scout,
    (rig, setup, train): (&Rig, &TrajectorySetup, &[usize]),
    settings: &DiscoverySettings,
) -> (SearchModel, f64, f64) {
    let train_rms = |s: &SearchModel| training_rms(s, rig, train);
    // Only the scout fit's RMS and values are used: no standard errors.
    let quick = DiscoverySettings {
        fit: settings.fit.clone().errors(false),
        ..settings.clone()
    };
    let (before, fitted) = rayon::join(
        || train_rms(&stage),
        || stage.fit_simulated(scout, setup, &scout.train, &quick),
    );
    if let Ok((fitted, fit)) = fitted {
        let after = train_rms(&fitted);
        if after < before {
            return (fitted, fit.rms * fit.rms, after);
        }
    }
    let ms = scout.mean_square(&stage).unwrap_or(f64::INFINITY);
    (stage, ms, before)
}

/// `stage` as it is, as [`scouted`] gives it back when its fit does not lower the whole
/// record's RMS: its mean square on the scout's training samples and its RMS at `train` on
/// `rig` (one simulation of each, side by side).
pub(in crate::discovery) fn unfitted(
    stage: SearchModel,
    scout: &Scout,
    (rig, _, train): (&Rig, &TrajectorySetup, &[usize]),
) -> (SearchModel, f64, f64) {
    let (ms, rms) = rayon::join(
        || scout.mean_square(&stage).unwrap_or(f64::INFINITY),
        || training_rms(&stage, rig, train),
    );
    (stage, ms, rms)
}

/// `stage`'s RMS at the samples `train` of the whole record `rig` (m); infinite when its
/// simulation fails.
fn training_rms(stage: &SearchModel, rig: &Rig, train: &[usize]) -> f64 {
    stage
        .residual(rig)
        .map_or(f64::INFINITY, |r| rms_over(&r, train))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_scouted_candidate_is_left_out_by_rank_by_share_or_by_a_failed_search() {
        let best = 4e-8;
        let rms = (1e-3, 2e-3);
        let kept = left_out(Some((1, 5, 0.5 * best)), best, rms, "mm");
        assert_eq!(kept, None);
        let ranked = left_out(Some((SCOUT_KEEP, 5, 0.9 * best)), best, rms, "mm").unwrap();
        assert!(ranked.contains("ranks it 4 of 5"), "{ranked}");
        assert!(ranked.ends_with("3.600e-2 mm²)"), "{ranked}");
        let share = left_out(Some((2, 5, 0.1 * best)), best, rms, "mm").unwrap();
        assert!(share.contains("less than 20 % of the best"), "{share}");
        // Three searched: no rank leaves one out, the share still does.
        let few = left_out(Some((2, 3, 0.1 * best)), best, rms, "mm").unwrap();
        assert!(few.contains("less than 20 % of the best"), "{few}");
        // No positive gain anywhere: the share rule has nothing to measure against.
        assert_eq!(left_out(Some((2, 5, -1e-9)), -1e-10, rms, "mm"), None);
        let failed = left_out(None, best, (2e-3, 2e-3), "mm").unwrap();
        assert!(
            failed.contains("not below the current model's 2.0000 mm"),
            "{failed}"
        );
        // A record whose x is a voltage is said in mV.
        let volts = left_out(Some((2, 5, 0.1 * best)), best, rms, "mV").unwrap();
        assert!(volts.contains("4.000e-3 mV², less than"), "{volts}");
        assert!(!volts.contains("mm"), "{volts}");
    }
}
