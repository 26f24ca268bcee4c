//! Settings of a discovery run, with named setters and the documented acceptance thresholds.

use derive_setters::Setters;
use serde::{Deserialize, Serialize};

use super::error::DiscoveryError;
use super::progress::Observer;
use crate::data::kinematics::Kinematics;
use crate::data::kinematics::MotionNoise;
use crate::fit::{FitSettings, Solver};

/// How discovery fits, holds out data and decides that an effect is significant.
///
/// ```
/// use stf_core::discovery::DiscoverySettings;
/// let s = DiscoverySettings::default().max_effects(2).holdout_every(5);
/// assert!(s.check().is_ok());
/// assert!(DiscoverySettings::default().holdout_every(1).check().is_err());
/// ```
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, Setters)]
#[serde(default)]
pub struct DiscoverySettings {
    /// Most effects added (default 3).
    pub max_effects: usize,
    /// Every k-th whole cycle is held out of the fits and used to score them (default 4,
    /// ≥ 2).
    pub holdout_every: usize,
    /// The paired z of a candidate's held-out gain must exceed this for it to count;
    /// candidates the winner does not beat by this z are ties (default 3; see
    /// [`super::acceptance`]).
    pub min_gain_sigma: f64,
    /// The BIC (on the training samples) must fall by more than this (default 10: "very
    /// strong" evidence on Kass and Raftery's scale).
    pub min_bic_drop: f64,
    /// A significant candidate must also remove at least this share of the current model's
    /// held-out excess over the noise floor, `(MSE_current − MSE_candidate) / (MSE_current −
    /// σ²)` (default 0.1; see [`super::acceptance`]): a real but small gain — a flexible
    /// candidate bending to follow the derivative filter's bias — is not the missing physics.
    pub min_explained: f64,
    /// How far the kinematics' part of the force floor may be from its estimate, as a factor
    /// (default 2, ≥ 1): the excess a candidate must explain a share of is counted as at least
    /// the floor's width between the estimate and the estimate with that part this many times
    /// larger. The estimate propagates the derivative filter's noise through the model; the
    /// filter also smears ẍ where it jumps (where the trolley sticks and slips), which no noise
    /// estimate sees: with an added mass of 1.5 kg on a power law (rig sensors) the true
    /// model's residual put the kinematics' part at 1.11× the estimate at 200 Hz and 1.85× at
    /// 1 kHz, and an on–off jamming candidate explained 21 % of that unseen part at z 3.4.
    pub kinematics_uncertainty: f64,
    /// Settings of every fit (default: [`FitSettings::default`] with at most 200 iterations
    /// per stage, to bound the time of a candidate whose fit wanders, and a relative cost
    /// tolerance of 1e-6: a candidate whose scale parameter creeps to zero along its bound map
    /// otherwise ran for hundreds of steps each gaining 1e-8 of the cost, while a gain of
    /// 1e-6 changes the BIC of 9000 training samples by 0.01, far below `min_bic_drop`). The
    /// final fit on the whole record uses at most 1e-9.
    pub fit: FitSettings,
    /// σ of the force noise, N; `None`: estimated from the measured force
    /// ([`crate::regimes::noise_floor`]).
    pub noise_sigma: Option<f64>,
    /// Fit a constant force offset `f_off` with every model (default false).
    pub fit_offset: bool,
    /// Noise of the kinematics the force-level models are evaluated along (x as measured, v
    /// and a as filtered): propagated through the current model into the force noise floor
    /// ([`crate::fit::ForceFit::noise_floor`]). `None`: the floor is the force sensor's alone,
    /// and the verdict says the kinematics' part is missing. Set from the record by
    /// [`DiscoverySettings::kinematics`]; not read from a file.
    #[serde(skip)]
    #[setters(skip)]
    pub motion_noise: Option<MotionNoise>,
    /// Window of the derivative filter that made v and a, samples: the filtered noise is
    /// correlated over it, so the force-level paired test's blocks are at least twice as long
    /// (see [`super::blocks`]). `None`: the block length is estimated from the residual's
    /// autocorrelation alone. Set by [`DiscoverySettings::kinematics`]; not read from a file.
    #[serde(skip)]
    #[setters(skip)]
    pub filter_window: Option<usize>,
    /// Starts of a candidate's trial besides its defaults: the best points of a coarse grid
    /// over its nonlinear parameters, scored by variable projection on the current residual;
    /// the trial with the lowest training RMS is kept (default 1; 0: the defaults only).
    pub extra_starts: usize,
    /// Records of at least this many samples are scouted at trajectory level: a candidate's
    /// values are searched on a few short pieces of the record (one sample in eight) and its
    /// trial on the whole record starts from there (default
    /// [`super::scout::SCOUT_FROM`]; 0: never). Scores and verdicts are the whole record's.
    pub scout_from: usize,
    /// Re-check the earlier effects after each acceptance ([`super::reconsider`]): each
    /// replaced in turn by every candidate not in the model. `None`: the level's default (on
    /// at force level, off at trajectory level).
    pub recheck: Option<bool>,
    /// Polish an accepted model at the final fit's tolerance before the next step
    /// ([`super::search`]). `None`: the level's default (off at force level, on at trajectory
    /// level).
    pub polish: Option<bool>,
    /// Whether the record's cycles are a rotor's, whose regimes (pre-resonance, resonance,
    /// post-resonance) the gap is broken down by (default true); a record without a rotor
    /// (a damper, a shaker) has no regimes, and its gap is said by ω and states alone. Set
    /// from the record; not read from a file.
    #[serde(skip)]
    #[setters(skip)]
    pub regimes: bool,
    /// The unit a displacement is said in at trajectory level: `mm` (default), or `mV` for a
    /// record whose x is a voltage (the numbers are thousandths of the record's unit either
    /// way). Set from the record; not read from a file.
    #[serde(skip)]
    #[setters(skip)]
    pub x_unit: &'static str,
    /// What the held-out pieces of a record are called: a rotor's `cycles` (default), or the
    /// `periods` of the motion of a record without a rotor. Set from the record; not read from
    /// a file.
    #[serde(skip)]
    #[setters(skip)]
    pub pieces: &'static str,
    /// Called as the run goes (step, candidate, score): for a live display.
    #[serde(skip)]
    #[setters(skip)]
    pub observer: Observer,
}

impl Default for DiscoverySettings {
    fn default() -> Self {
        DiscoverySettings {
            max_effects: 3,
            holdout_every: 4,
            min_gain_sigma: 3.0,
            min_bic_drop: 10.0,
            min_explained: 0.1,
            kinematics_uncertainty: 2.0,
            fit: FitSettings::default().max_iters(200).tol(1e-7),
            noise_sigma: None,
            fit_offset: false,
            motion_noise: None,
            filter_window: None,
            extra_starts: 1,
            scout_from: super::scout::SCOUT_FROM,
            recheck: None,
            polish: None,
            regimes: true,
            x_unit: "mm",
            pieces: "cycles",
            observer: Observer::default(),
        }
    }
}

impl DiscoverySettings {
    /// The width in mean square (N²) of the uncertainty of a force floor whose kinematics'
    /// part is `propagated` (N).
    pub(super) fn floor_band(&self, propagated: f64) -> f64 {
        (self.kinematics_uncertainty.powi(2) - 1.0) * propagated * propagated
    }
    /// These settings with every fit run by Levenberg–Marquardt alone, which never leaves its
    /// start for a worse point, its iterations at most `max_iters` (`None`: as set).
    pub(super) fn levenberg_marquardt(&self, max_iters: Option<u64>) -> Self {
        let fit = self.fit.clone().solver(Solver::LevenbergMarquardt);
        let iters = max_iters.map_or(fit.max_iters, |n| fit.max_iters.min(n));
        DiscoverySettings {
            fit: fit.max_iters(iters),
            ..self.clone()
        }
    }
    /// [`DiscoverySettings::levenberg_marquardt`] at a tolerance of at most 1e-9: for a fit
    /// from near the optimum that must end there (the final refit, a polish).
    pub(super) fn refined(&self) -> Self {
        let mut s = self.levenberg_marquardt(None);
        s.fit = s.fit.tol(self.fit.tol.min(1e-9));
        s
    }
    /// The noise and the derivative filter of the kinematics `k` the force data were derived
    /// with: their noise enters the floor, the filter's window the length of the test's blocks.
    pub fn kinematics(mut self, k: &Kinematics) -> Self {
        self.motion_noise = Some(k.motion_noise());
        self.filter_window = Some(k.motion_filter.window());
        self
    }

    /// Check the settings.
    pub fn check(&self) -> Result<(), DiscoveryError> {
        self.fit
            .check()
            .map_err(|e| DiscoveryError::BadSettings(e.to_string()))?;
        let sigma_ok = self.noise_sigma.is_none_or(|s| s > 0.0 && s.is_finite());
        let ok = self.holdout_every >= 2
            && self.min_gain_sigma >= 0.0
            && self.min_gain_sigma.is_finite()
            && self.min_bic_drop >= 0.0
            && self.min_bic_drop.is_finite()
            && (0.0..=1.0).contains(&self.min_explained)
            && self.kinematics_uncertainty >= 1.0
            && self.kinematics_uncertainty.is_finite()
            && sigma_ok;
        if !ok {
            return Err(DiscoveryError::BadSettings(format!(
                "need holdout_every ≥ 2, finite min_gain_sigma ≥ 0 and min_bic_drop ≥ 0, \
                 min_explained in [0, 1], a finite kinematics_uncertainty ≥ 1, a positive finite \
                 noise_sigma (got holdout_every {}, min_gain_sigma {}, min_bic_drop {}, \
                 min_explained {}, kinematics_uncertainty {}, noise_sigma {:?})",
                self.holdout_every,
                self.min_gain_sigma,
                self.min_bic_drop,
                self.min_explained,
                self.kinematics_uncertainty,
                self.noise_sigma
            )));
        }
        Ok(())
    }

    /// The noise floor σ of the search: `noise_sigma`, or else that of the measured `signal`
    /// ([`crate::regimes::noise_floor`]); an error unless positive and finite. `what` names
    /// the measured quantity and `unit` its unit, for the error.
    pub(super) fn floor_of(
        &self,
        signal: &[f64],
        what: &str,
        unit: &str,
    ) -> Result<f64, DiscoveryError> {
        let estimated = || crate::regimes::noise_floor(signal);
        let floor = self.noise_sigma.map_or_else(estimated, Ok)?;
        if !(floor > 0.0 && floor.is_finite()) {
            return Err(DiscoveryError::BadData(format!(
                "the noise floor of the measured {what} is {floor} {unit}; give `noise_sigma`"
            )));
        }
        Ok(floor)
    }
}
