//! The figures of a record regime by regime: a window of a few cycles in each regime
//! (pre-resonance, resonance, post-resonance) over time, x, v and F_STF measured and modelled
//! ([`crate::report::regime_time_windows`]), with the loops F–x, F–v, F–a of every model over
//! the measured ones ([`crate::report::regime_windows`]), and measured against fitted with the
//! residual's distribution per regime ([`crate::report::parity`]). The regimes are the
//! record's own (classified on its STF force, as `compare` does), and each window sits where
//! its regime is, with the reason it was chosen ([`super::window_placement`]: the resonance at
//! the amplitude peak, which is never shown as pre-resonance); a record without them (no
//! rotor, no STF force to speak of) gets windows at its start, middle and end instead, said in
//! words that fit it (periods of the motion, thirds of the record: a damper has no regimes).

use std::path::Path;

use anyhow::Result;
use stf_core::regimes::{classify, Classification, Cycle, Regime};

use super::window_placement::place_windows;
use crate::experiment::Experiment;
use crate::fitting::FitData;
use crate::report::{
    milli, parity, regime_time_windows, regime_windows, FigureRef, MotionLabels, ParityQuantity,
    RegimeWindow, SampleGroup, Section, TimeRow, WindowSeries,
};

/// How many whole cycles a window shows.
const CYCLES_PER_WINDOW: usize = 3;

/// A named stretch of consecutive cycles `cycles[first..first + count]`.
struct Stretch {
    name: String,
    first: usize,
    count: usize,
}

/// The longest run of consecutive cycles labelled with each regime the record has; or, with
/// no regimes, the whole record's start, middle and end thirds.
fn stretches(cycles: &[Cycle], labels: Option<&[Regime]>) -> Vec<Stretch> {
    let Some(labels) = labels else {
        let third = cycles.len() / 3;
        return ["start", "middle", "end"]
            .iter()
            .enumerate()
            .filter(|_| third > 0)
            .map(|(k, name)| Stretch {
                name: name.to_string(),
                first: k * third,
                count: third,
            })
            .collect();
    };
    Regime::ALL
        .iter()
        .filter_map(|&r| {
            let (mut best, mut start): (Option<(usize, usize)>, usize) = (None, 0);
            for run in labels.chunk_by(|a, b| a == b) {
                if run[0] == r && best.is_none_or(|(_, n)| run.len() > n) {
                    best = Some((start, run.len()));
                }
                start += run.len();
            }
            best.map(|(first, count)| Stretch {
                name: r.name().replace('_', "-"),
                first,
                count,
            })
        })
        .collect()
}

/// The record's cycles and, when it has an STF force and a rotor, their classification.
fn labelled_cycles(
    exp: &Experiment,
    data: &FitData,
) -> Result<(Vec<Cycle>, Option<Classification>)> {
    let k = &data.kinematics;
    let cycles = crate::fitting::cycles_of(data)?;
    let rotor = k.phi.is_some() || k.omega.is_some();
    let labels = match (data.record.f_stf.as_deref(), rotor) {
        (Some(f), true) => {
            let sig = data.force_data().with_force(f);
            classify(&sig, cycles.clone(), &exp.regimes)
                .ok()
                .filter(|c| !c.no_stf)
        }
        _ => None,
    };
    Ok((cycles, labels))
}

/// The words of the section: a rotor's regimes and cycles, a rotor's record too quiet to
/// classify, or — without a rotor — thirds of the record and periods of its motion.
struct Words {
    title: &'static str,
    figure: &'static str,
    cycles: &'static str,
    stretch: &'static str,
    group: &'static str,
}

impl Words {
    fn of(regimes: bool, rotor: bool) -> Words {
        match (regimes, rotor) {
            (true, _) => Words {
                title: "Regime by regime",
                figure: "regime_windows",
                cycles: "cycles",
                stretch: "regime of the record (classified on its STF force, as `compare` does)",
                group: "regime",
            },
            (false, true) => Words {
                title: "Start, middle and end",
                figure: "regime_windows",
                cycles: "cycles",
                stretch: "third of the record (its STF force is too small to tell regimes apart)",
                group: "third of the record",
            },
            (false, false) => Words {
                title: "Start, middle and end",
                figure: "windows",
                cycles: "periods of the motion",
                stretch: "third of the record",
                group: "third of the record",
            },
        }
    }
}

/// The windows and the sentence saying why each sits where it does: by the regimes
/// ([`place_windows`]), or [`CYCLES_PER_WINDOW`] cycles from the middle of each stretch,
/// named by the rotor's speed over them (`t`: none, a record without a rotor) or else by
/// their time.
fn windows_of(
    found: &[Stretch],
    cycles: &[Cycle],
    classified: Option<&Classification>,
    (units, t): ((&str, &str), Option<&[f64]>),
) -> (Vec<RegimeWindow>, Vec<String>) {
    let window = |name: String, first: usize, count: usize| RegimeWindow {
        name,
        start: cycles[first].start,
        end: cycles[first + count - 1].end,
    };
    if let Some(c) = classified {
        let placed = place_windows(c, CYCLES_PER_WINDOW, units);
        let why = placed.iter().map(|p| format!("{}.", p.why)).collect();
        let windows = placed
            .into_iter()
            .map(|p| window(p.name, p.first, p.count))
            .collect();
        return (windows, why);
    }
    let windows = found
        .iter()
        .map(|s| {
            let n = CYCLES_PER_WINDOW.min(s.count);
            let first = s.first + (s.count - n) / 2;
            let (a, b) = (&cycles[first], &cycles[first + n - 1]);
            let name = match t {
                None => format!("{}, ω {:.2}–{:.2} rad/s", s.name, a.omega, b.omega),
                Some(t) => format!(
                    "{}, t {:.2}–{:.2} s",
                    s.name,
                    t[a.start],
                    t[(b.end - 1).min(t.len() - 1)]
                ),
            };
            window(name, first, n)
        })
        .collect();
    (windows, Vec::new())
}

/// Every sample of each stretch's cycles.
fn groups_of(found: &[Stretch], cycles: &[Cycle]) -> Vec<SampleGroup> {
    found
        .iter()
        .map(|s| SampleGroup {
            name: s.name.clone(),
            samples: cycles[s.first..s.first + s.count]
                .iter()
                .flat_map(|c| c.start..c.end)
                .collect(),
        })
        .collect()
}

/// The section of regime windows and parity plots for `models` (`(label, fitted STF force)`,
/// N; none: the measured force alone) and `simulated` (`(label, simulated displacement)`, m:
/// trajectory-level fits), or `None` when the record has no STF force or too few cycles.
pub fn regime_section(
    exp: &Experiment,
    data: &FitData,
    models: &[(&str, &[f64])],
    simulated: &[(&str, &[f64])],
    out: &Path,
) -> Result<Option<Section>> {
    let Some(f) = data.record.f_stf.as_deref() else {
        return Ok(None);
    };
    let (cycles, classified) = labelled_cycles(exp, data)?;
    let labels = classified.as_ref().map(|c| c.labels.as_slice());
    let found = stretches(&cycles, labels);
    if found.is_empty() {
        return Ok(None);
    }
    let dir = out.join("figures");
    let k = &data.kinematics;
    let (x_mm, v_mm) = (milli(&k.x), milli(&k.v));
    let rotor = k.phi.is_some() || k.omega.is_some();
    let units = (data.units.x, data.units.force_si);
    let named_by = (units, (!rotor).then_some(k.t.as_slice()));
    let (windows, why) = windows_of(&found, &cycles, classified.as_ref(), named_by);
    let words = Words::of(labels.is_some(), rotor);
    let motion = MotionLabels::of(&data.units);
    let title = format!(
        "A few {} of each {}: the STF force over time and against x, v, a",
        words.cycles, words.group
    );
    let series = WindowSeries {
        t: &k.t,
        x_mm: &x_mm,
        v_mm: &v_mm,
        a: &k.a,
        f,
        models,
        labels: motion,
        title: &title,
    };
    let mut s = Section::new(words.title);
    if why.is_empty() {
        s.paragraphs.push(format!(
            "{} whole {} from the middle of the longest stretch of each {}, and every sample of \
             it for measured against fitted.",
            CYCLES_PER_WINDOW, words.cycles, words.stretch
        ));
    } else {
        s.paragraphs.push(format!(
            "{CYCLES_PER_WINDOW} whole cycles where each regime is by the study's definitions \
             (classified on the STF force, as `compare` does), and every sample of the longest \
             stretch of each regime for measured against fitted. The windows:"
        ));
        s.paragraphs.extend(why);
    }
    let simulated_mm: Vec<(&str, Vec<f64>)> =
        simulated.iter().map(|(l, x)| (*l, milli(x))).collect();
    let rows = [
        TimeRow {
            label: motion.x_column,
            measured: &x_mm,
            models: simulated_mm
                .iter()
                .map(|(l, x)| (*l, x.as_slice()))
                .collect(),
        },
        TimeRow {
            label: motion.v_column,
            measured: &v_mm,
            models: Vec::new(),
        },
        TimeRow {
            label: motion.force,
            measured: f,
            models: models.to_vec(),
        },
    ];
    let name = format!("{}_over_time", words.figure);
    let title = format!(
        "A few {} of each {} over time: measured and modelled",
        words.cycles, words.group
    );
    // The three figures are independent files: drawn in parallel, kept in this order.
    let over_time = || regime_time_windows(&dir, &name, &title, &k.t, &rows, &windows);
    let loops = || regime_windows(&dir, words.figure, &series, &windows);
    let parity_of = || -> Result<Option<_>, crate::report::ReportError> {
        if models.is_empty() {
            return Ok(None);
        }
        let groups = groups_of(&found, &cycles);
        let quantity = ParityQuantity {
            label: motion.force.into(),
            group: words.group,
            noise_sigma: Some(stf_core::numerics::derivative::noise_estimate(f).sigma),
        };
        parity(&dir, "parity", &quantity, f, models, &groups).map(Some)
    };
    let ((over_time, loops), parity_fig) = rayon::join(|| rayon::join(over_time, loops), parity_of);
    s.figures.push(FigureRef::new(
        over_time?,
        format!(
            "A few {} of each {} over time: displacement, velocity and STF force, measured \
             (grey) and {}.",
            words.cycles,
            words.group,
            match (models.is_empty(), simulated.is_empty()) {
                (true, true) => "no model",
                (false, true) => "each model's fitted force over it",
                (true, false) => "each model's simulated displacement over it",
                (false, false) => "each model's over it",
            }
        ),
    ));
    s.figures.push(FigureRef::new(
        loops?,
        format!(
            "A few {} of each {}: the STF force over time, and its loops against x, v and a; \
             each model's force over the measured one (grey).",
            words.cycles, words.group
        ),
    ));
    if let Some(fig) = parity_fig? {
        s.figures.push(FigureRef::new(
            fig,
            format!(
                "Measured against fitted STF force in each {} (on y = x where they agree), and \
                 the residual's (measured − fitted) distribution against the normal curve of \
                 the force noise; residuals beyond the axis's ends are left off.",
                words.group
            ),
        ));
    }
    Ok(Some(s))
}
