//! The `[simulate]` section of an experiment file: exactly one drive (`crate::experiment`'s
//! [`Drive`], see `drive.rs`), the sample `rate` and the most samples a run may make
//! (`max_samples`, checked before anything is allocated), sensor `noise` and its `seed`, the
//! initial state, the hidden models (`[[simulate.truth]]`), control `channels` written as
//! columns (a random switch between levels) and a sensor offset of the STF force.

use std::ops::Range;

use anyhow::Result;
use serde::Deserialize;
use std::collections::BTreeMap;

use stf_core::simulate::control::RandomLevels;
use stf_core::simulate::{count_text, sample_count, DEFAULT_MAX_SAMPLES};
use toml::Spanned;

use super::drive::{self, Chirp, Drive, RawConstant, RawFree, RawProfile, RawSweep};
use super::models::{self, ModelEntry, RawModel};
use super::Ctx;
use crate::digits::shown;

/// `[simulate]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawSimulate {
    sweep: Option<RawSweep>,
    constant: Option<RawConstant>,
    profile: Option<RawProfile>,
    free: Option<RawFree>,
    chirp: Option<Spanned<Chirp>>,
    #[serde(default = "default_rate")]
    rate: f64,
    #[serde(default = "yes")]
    noise: bool,
    #[serde(default = "one")]
    seed: u64,
    #[serde(default)]
    x0: f64,
    #[serde(default)]
    v0: f64,
    #[serde(default)]
    truth: Vec<Spanned<RawModel>>,
    /// The most samples the run may make (default `DEFAULT_MAX_SAMPLES`).
    max_samples: Option<Spanned<f64>>,
    /// Control channels written beside the signals, by name.
    #[serde(default)]
    channels: BTreeMap<String, Spanned<RawLevels>>,
    /// Sensor offsets added to the recorded signals (`f_stf`, N).
    #[serde(default)]
    offsets: BTreeMap<String, Spanned<f64>>,
}

/// A control channel as written: `{ levels = [0.0, 1.0], hold = 2.0, seed = 3 }`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawLevels {
    levels: Vec<f64>,
    hold: f64,
    seed: Option<u64>,
}

/// A control channel of the simulated record: its column's name, its signal and its seed.
#[derive(Clone, Debug, PartialEq)]
pub struct SimChannel {
    /// The column's name.
    pub name: String,
    /// The levels it switches between and their mean hold time.
    pub signal: RandomLevels,
    /// Its random seed (the channel's own, else the run's plus the channel's place).
    pub seed: u64,
}

fn default_rate() -> f64 {
    1000.0
}
fn yes() -> bool {
    true
}
fn one() -> u64 {
    1
}

/// A checked `[simulate]` section.
#[derive(Clone, Debug)]
pub struct SimulateSpec {
    /// The drive.
    pub drive: Drive,
    /// Start and end time, s.
    pub t0: f64,
    /// End time, s.
    pub t1: f64,
    /// Samples per second.
    pub rate: f64,
    /// The most samples the run may make (`max_samples`).
    pub max_samples: u64,
    /// Sensor noise on or off.
    pub noise: bool,
    /// Random seed.
    pub seed: u64,
    /// Initial displacement (m) and velocity (m/s).
    pub x0: f64,
    /// Initial velocity.
    pub v0: f64,
    /// The hidden models.
    pub truth: Vec<ModelEntry>,
    /// Control channels written as columns (`channels.u_ctrl = { levels, hold }`).
    pub channels: Vec<SimChannel>,
    /// Offset added to the recorded STF force, N (`offsets = { f_stf = … }`).
    pub f_stf_offset: f64,
    /// The section as written, for the sidecar.
    pub as_json: serde_json::Value,
}

/// Check `[simulate]` (absent: no simulation).
pub(super) fn check(raw: Option<&Spanned<RawSimulate>>, cx: &Ctx) -> Result<Option<SimulateSpec>> {
    let Some(s) = raw else {
        return Ok(None);
    };
    let (span, s) = (s.span(), s.get_ref());
    let checked = the_drive(s, cx, span.clone())?;
    let (t0, t1, mut as_json) = (checked.t0, checked.t1, checked.as_json);
    let order = format!("t1 = {} must exceed t0 = {}", shown(t1), shown(t0));
    cx.ensure(t1 > t0, span.clone(), "simulate", order)?;
    cx.ensure(
        s.rate > 0.0,
        span.clone(),
        "simulate.rate",
        "must be a positive number",
    )?;
    let max_samples = sample_limit(cx, &span, s, t0, t1)?;
    as_json["rate"] = s.rate.into();
    as_json["noise"] = s.noise.into();
    as_json["seed"] = s.seed.into();
    as_json["x0"] = s.x0.into();
    as_json["v0"] = s.v0.into();
    let channels = channels(s, cx)?;
    let f_stf_offset = f_stf_offset(s, cx)?;
    for c in &channels {
        as_json["channels"][&c.name] = serde_json::json!({
            "levels": c.signal.levels, "hold": c.signal.hold, "seed": c.seed
        });
    }
    if f_stf_offset != 0.0 {
        as_json["offsets"]["f_stf"] = f_stf_offset.into();
    }
    Ok(Some(SimulateSpec {
        drive: checked.drive,
        t0,
        t1,
        rate: s.rate,
        max_samples,
        noise: s.noise,
        seed: s.seed,
        x0: s.x0,
        v0: s.v0,
        truth: models::check(&s.truth, "simulate.truth", cx)?,
        channels,
        f_stf_offset,
        as_json,
    }))
}

/// The record's own column names, which a channel may not take.
const SIGNALS: [&str; 7] = ["t", "x", "phi", "f_stf", "omega", "u", "v"];

/// `[simulate] channels`, checked: a new column name, two or more finite levels, a positive
/// hold time.
fn channels(s: &RawSimulate, cx: &Ctx) -> Result<Vec<SimChannel>> {
    s.channels
        .iter()
        .enumerate()
        .map(|(i, (name, raw))| {
            let key = format!("simulate.channels.{name}");
            let r = raw.get_ref();
            let bad = |msg: String| Err(cx.at(raw.span(), &key, msg));
            if SIGNALS.contains(&name.as_str()) {
                return bad(format!(
                    "`{name}` is one of the record's signals ({}): give the channel another name",
                    SIGNALS.join(", ")
                ));
            }
            if r.levels.len() < 2 || r.levels.iter().any(|v| !v.is_finite()) {
                return bad("`levels` needs two or more numbers to switch between".into());
            }
            if !(r.hold.is_finite() && r.hold > 0.0) {
                return bad(format!(
                    "`hold` = {} must be a positive time, s (the mean time a level is held)",
                    shown(r.hold)
                ));
            }
            Ok(SimChannel {
                name: name.clone(),
                signal: RandomLevels {
                    levels: r.levels.clone(),
                    hold: r.hold,
                },
                seed: r.seed.unwrap_or(s.seed.wrapping_add(1 + i as u64)),
            })
        })
        .collect()
}

/// `[simulate] offsets`: only `f_stf` (N), finite.
fn f_stf_offset(s: &RawSimulate, cx: &Ctx) -> Result<f64> {
    let mut out = 0.0;
    for (name, v) in &s.offsets {
        let key = format!("simulate.offsets.{name}");
        if name != "f_stf" {
            return Err(cx.at(
                v.span(),
                &key,
                "only the STF force takes a simulated sensor offset: `offsets = { f_stf = … }` (N)",
            ));
        }
        cx.ensure(
            v.get_ref().is_finite(),
            v.span(),
            &key,
            "must be a number, N",
        )?;
        out = *v.get_ref();
    }
    Ok(out)
}

/// The one drive the section gives, checked.
fn the_drive(s: &RawSimulate, cx: &Ctx, span: Range<usize>) -> Result<drive::Checked> {
    match (&s.sweep, &s.constant, &s.profile, &s.free, &s.chirp) {
        (Some(w), None, None, None, None) => Ok(w.check()),
        (None, Some(c), None, None, None) => Ok(c.check()),
        (None, None, Some(p), None, None) => p.check(cx, span),
        (None, None, None, Some(f), None) => Ok(f.check()),
        (None, None, None, None, Some(c)) => Chirp::check(c, cx),
        _ => Err(cx.at(
            span,
            "simulate",
            "give exactly one of `sweep`, `constant`, `profile`, `free` or `chirp`",
        )),
    }
}

/// `[simulate] max_samples` (default [`DEFAULT_MAX_SAMPLES`]), and the run's sample count
/// checked against it before anything is allocated.
fn sample_limit(cx: &Ctx, span: &Range<usize>, s: &RawSimulate, t0: f64, t1: f64) -> Result<u64> {
    let limit = match &s.max_samples {
        None => DEFAULT_MAX_SAMPLES,
        Some(m) => cx.count(m, "simulate.max_samples", 2, "sample count")?,
    };
    let count = sample_count(t0, t1, s.rate);
    let asked = format!(
        "{} samples/s from t0 = {} to t1 = {} s asks for {} samples, over the limit of \
         {limit} (`simulate.max_samples`; a run holds about 140 bytes a sample)",
        shown(s.rate),
        shown(t0),
        shown(t1),
        count_text(count)
    );
    cx.ensure(count <= limit as f64, span.clone(), "simulate.rate", asked)?;
    // The limit is a setting: raised past what this machine can hold, the run is refused
    // here, naming the key, instead of aborting when it allocates.
    // (The truth's internal states, not known here, add a little; the run checks them too.)
    let bytes = count * stf_core::simulate::bytes_per_sample(0);
    if let Err(why) = stf_core::data::memory::check(bytes, stf_core::data::memory::available()) {
        let key = if s.max_samples.is_some() {
            "simulate.max_samples"
        } else {
            "simulate.rate"
        };
        let span = s.max_samples.as_ref().map_or(span.clone(), |m| m.span());
        let msg = format!(
            "{} samples/s from t0 = {} to t1 = {} s is {} samples, which {why}; the limit \
             of {limit} samples (`simulate.max_samples`) does not make room for them: lower \
             `rate` or the drive's end time",
            shown(s.rate),
            shown(t0),
            shown(t1),
            count_text(count)
        );
        return Err(cx.at(span, key, msg));
    }
    Ok(limit)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::parse_exp as parse;

    #[test]
    fn a_run_too_long_for_memory_names_the_key_the_samples_and_the_limit() {
        // The case: 10⁹ s at 1 MHz, 10¹⁵ samples. Parsing allocates nothing.
        let msg = parse("[simulate]\nconstant = { omega = 6.0, t1 = 1e9 }\nrate = 1e6\n")
            .unwrap_err()
            .to_string();
        assert_eq!(
            msg,
            "exp.toml:1: `simulate.rate`: 1e6 samples/s from t0 = 0 to t1 = 1e9 s \
             asks for 1.00e15 samples, over the limit of 10000000 (`simulate.max_samples`; a \
             run holds about 140 bytes a sample)"
        );
        let msg = parse("[simulate]\nconstant = { omega = 6.0, t1 = 1.0 }\nrate = 1e300\n")
            .unwrap_err()
            .to_string();
        assert!(msg.contains("asks for 1.00e300 samples"), "{msg}");
        // The limit is a setting: raised, a run past the default parses (1.5·10⁷ samples,
        // 2.1 GB, within this machine's memory); lowered, a short one is refused.
        let e = parse(
            "[simulate]\nconstant = { omega = 6.0, t1 = 15.0 }\nrate = 1e6\nmax_samples = 2e7\n",
        )
        .unwrap();
        assert_eq!(e.simulate.unwrap().max_samples, 20_000_000);
        let msg = parse("[simulate]\nfree = { t1 = 1.0 }\nrate = 100.0\nmax_samples = 100\n")
            .unwrap_err()
            .to_string();
        assert!(msg.contains("101 samples, over the limit of 100"), "{msg}");
        let msg = parse("[simulate]\nfree = { t1 = 1.0 }\nmax_samples = -3\n")
            .unwrap_err()
            .to_string();
        assert!(
            msg.starts_with("exp.toml:3: `simulate.max_samples`: -3 is not"),
            "{msg}"
        );
    }

    #[test]
    fn a_raised_limit_past_the_machine_s_memory_is_refused_at_the_key() {
        // The case aborted with "memory allocation of 80000000000008 bytes failed".
        let msg = parse(
            "[simulate]\nconstant = { omega = 8.2, t1 = 1e4 }\nrate = 1e9\nmax_samples = 1e18\n",
        )
        .unwrap_err()
        .to_string();
        assert!(
            msg.starts_with(
                "exp.toml:4: `simulate.max_samples`: 1e9 samples/s from t0 = 0 \
                             to t1 = 10000 s is 1.00e13 samples, which needs about"
            ) && msg.contains("of memory this machine has available")
                && msg.contains("lower `rate`"),
            "{msg}"
        );
    }

    #[test]
    fn two_drives_or_none_are_an_error() {
        for text in [
            "[simulate]\nsweep = { w0 = 1.0, alpha = 0.1, t0 = 0.0, t1 = 5.0 }\nconstant = { omega = 2.0, t1 = 3.0 }\n",
            "[simulate]\nrate = 100.0\n",
        ] {
            let msg = format!("{:#}", parse(text).unwrap_err());
            assert!(
                msg.starts_with("exp.toml:1: `simulate`: ") && msg.contains("exactly one"),
                "{msg}"
            );
        }
    }

    #[test]
    fn each_drive_gives_its_span_and_the_sidecar_its_table() {
        let s = parse(
            "[simulate]\nprofile = { t = [1.0, 2.0, 4.0], omega = [1.0, 2.0, 3.0] }\nseed = 7\n",
        )
        .unwrap()
        .simulate
        .unwrap();
        assert_eq!((s.t0, s.t1, s.seed, s.rate), (1.0, 4.0, 7, 1000.0));
        assert!(matches!(s.drive, Drive::Rotor(_)));
        assert_eq!(s.as_json["profile"]["t"][2], 4.0);
        assert_eq!(s.as_json["seed"], 7);
        let s = parse("[simulate]\nfree = { t1 = 3.0 }\nnoise = false\n")
            .unwrap()
            .simulate
            .unwrap();
        assert!(matches!(s.drive, Drive::Free) && !s.noise);
        assert_eq!((s.t0, s.t1), (0.0, 3.0));
        for (profile, key, says) in [
            ("t = [1.0], omega = [1.0]", "simulate.profile", "at least 2"),
            (
                "t = [1.0, 2.0], omega = [1.0]",
                "simulate.profile",
                "same length",
            ),
            (
                "t = [2.0, 1.0], omega = [1.0, 1.0]",
                "simulate.profile.t",
                "increase",
            ),
        ] {
            let msg = format!(
                "{:#}",
                parse(&format!("[simulate]\nprofile = {{ {profile} }}\n")).unwrap_err()
            );
            assert!(
                msg.starts_with(&format!("exp.toml:1: `{key}`: ")) && msg.contains(says),
                "{msg}"
            );
        }
        let msg = format!(
            "{:#}",
            parse("[simulate]\nfree = { t1 = 1.0 }\nrate = -5.0\n").unwrap_err()
        );
        assert!(
            msg.starts_with("exp.toml:1: `simulate.rate`: must be"),
            "{msg}"
        );
    }

    #[test]
    fn a_chirp_drive_parses_and_a_bad_value_names_file_line_and_key() {
        let e = parse(
            "[simulate]\nrate = 200.0\nchirp = { f0 = 0.5, f1 = 1.5, amplitude = 2.0, t1 = 20.0 }\n",
        )
        .unwrap();
        let s = e.simulate.unwrap();
        assert_eq!((s.t0, s.t1), (0.0, 20.0));
        let Drive::Force(chirp) = s.drive else {
            panic!("not a force drive: {:?}", s.drive)
        };
        assert!(!chirp.held());
        // The frequency sweeps 0.5 → 1.5 Hz: the phase is 2π·(0.5·t + 0.025·t²).
        let t = 7.3;
        let expected = 2.0 * (std::f64::consts::TAU * (0.5 * t + 0.025 * t * t)).sin();
        assert!((chirp.at(t) - expected).abs() < 1e-12);
        assert_eq!(s.as_json["chirp"]["amplitude"], 2.0);
        assert!(s.as_json["chirp"].get("hold").is_none());

        for (bad, key) in [
            ("f0 = -0.5, f1 = 1.5, amplitude = 2.0", "simulate.chirp.f0"),
            ("f0 = 0.5, f1 = nan, amplitude = 2.0", "simulate.chirp.f1"),
            (
                "f0 = 0.5, f1 = 1.5, amplitude = 0.0",
                "simulate.chirp.amplitude",
            ),
            (
                "f0 = 0.5, f1 = 1.5, amplitude = inf",
                "simulate.chirp.amplitude",
            ),
        ] {
            let text = format!("[simulate]\nrate = 200.0\n\nchirp = {{ {bad}, t1 = 20.0 }}\n");
            let msg = format!("{:#}", parse(&text).unwrap_err());
            assert!(msg.contains("exp.toml:4") && msg.contains(key), "{msg}");
        }
        let msg = format!(
            "{:#}",
            parse(
                "[simulate]\nchirp = { f0 = 0.5, f1 = 1.5, amplitude = 2.0, t0 = 5.0, t1 = 5.0 }\n"
            )
            .unwrap_err()
        );
        assert!(msg.contains("t1 = 5 must exceed t0 = 5"), "{msg}");
        let msg = format!(
            "{:#}",
            parse("[simulate]\nchirp = { f0 = 0.5, f1 = 1.5, amplitud = 2.0, t1 = 5.0 }\n")
                .unwrap_err()
        );
        assert!(
            msg.contains("exp.toml:2") && msg.contains("amplitud"),
            "{msg}"
        );
    }

    #[test]
    fn a_chirp_s_hold_is_linear_or_zoh_and_an_unknown_one_lists_both() {
        let chirp = "chirp = { f0 = 0.5, f1 = 1.5, amplitude = 2.0, t1 = 5.0";
        for (hold, held) in [("linear", false), ("zoh", true)] {
            let s = parse(&format!("[simulate]\n{chirp}, hold = \"{hold}\" }}\n"))
                .unwrap()
                .simulate
                .unwrap();
            assert!(matches!(s.drive, Drive::Force(c) if c.held() == held));
            assert_eq!(s.as_json["chirp"]["hold"], hold);
        }
        let msg = format!(
            "{:#}",
            parse(&format!("[simulate]\n{chirp}, hold = \"step\" }}\n")).unwrap_err()
        );
        assert!(
            msg.starts_with("exp.toml:2: `simulate.chirp.hold`: unknown value `step`")
                && msg.contains("one of: linear, zoh"),
            "{msg}"
        );
    }
}
