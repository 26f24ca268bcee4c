//! The layout of a lab's record file: which column holds which signal, in which unit, with
//! which offset, how the text is separated, and where the time comes from.
//!
//! A [`ReadOptions`] describes the layout; the CSV and `.mat` readers find the columns it
//! names and then apply it, turning the recorded values into the SI values of a
//! [`Record`](super::Record): the time from its column (or `t0 + i/rate`), and for every other
//! signal `scale · (recorded − offset)` — the offset is in the file's units, given or estimated
//! as the mean over a rest stretch — followed, for `f_stf`, by a calibration `a·F + b`.
//! Settings that cannot work together are a [`LayoutError`] from [`ReadOptions::check`].

use std::f64::consts::{PI, TAU};
use std::fmt;

use derive_setters::Setters;
use serde::Deserialize;
use thiserror::Error;

use super::{ColumnNames, RecordError};

/// A signal of the data contract.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Signal {
    /// Time, s.
    T,
    /// Displacement, m.
    X,
    /// Rotor angle, rad.
    Phi,
    /// STF force, N.
    FStf,
    /// Rotor speed, rad/s.
    Omega,
    /// Drive force of a shaker rig, N.
    U,
}

impl Signal {
    /// Every signal, in the order of the data contract.
    pub const ALL: [Signal; 6] = [
        Signal::T,
        Signal::X,
        Signal::Phi,
        Signal::FStf,
        Signal::Omega,
        Signal::U,
    ];

    /// The name of the data contract (`t`, `x`, `phi`, `f_stf`, `omega`, `u`).
    pub fn name(self) -> &'static str {
        match self {
            Signal::T => "t",
            Signal::X => "x",
            Signal::Phi => "phi",
            Signal::FStf => "f_stf",
            Signal::Omega => "omega",
            Signal::U => "u",
        }
    }

    /// The signal called `name`, if any.
    pub fn from_name(name: &str) -> Option<Signal> {
        Signal::ALL.into_iter().find(|s| s.name() == name)
    }

    /// The names of all signals, comma-separated (for messages).
    pub fn names() -> String {
        Signal::ALL.map(Signal::name).join(", ")
    }

    /// The units this signal may be recorded in, as a user writes them (for messages).
    pub fn unit_list(self) -> &'static str {
        match self {
            Signal::T => "s, ms, us (or µs), min",
            Signal::X => {
                "m, cm, mm, um (or µm), in, V (with `gain`, metres per volt; alone, a voltage kept \
                 in volts)"
            }
            Signal::Phi => "rad, deg, rev, counts (with `per_rev`, encoder counts per revolution)",
            Signal::Omega => "rad/s, rpm, Hz",
            Signal::FStf | Signal::U => "N, kN, mN, lbf, V (with `gain`, newtons per volt)",
        }
    }

    pub(crate) fn index(self) -> usize {
        self as usize
    }
}

impl fmt::Display for Signal {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A unit a signal is recorded in; [`Unit::scale`] brings a value to SI.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Unit {
    /// s.
    Second,
    /// ms.
    Millisecond,
    /// µs.
    Microsecond,
    /// Minutes.
    Minute,
    /// m.
    Metre,
    /// cm.
    Centimetre,
    /// mm.
    Millimetre,
    /// µm.
    Micrometre,
    /// Inches (25.4 mm).
    Inch,
    /// rad.
    Radian,
    /// Degrees.
    Degree,
    /// Revolutions (turns).
    Revolution,
    /// Encoder counts, `per_rev` counts a revolution.
    Counts {
        /// Counts per revolution.
        per_rev: f64,
    },
    /// rad/s.
    RadianPerSecond,
    /// Revolutions per minute.
    Rpm,
    /// Revolutions per second.
    Hertz,
    /// N.
    Newton,
    /// kN.
    Kilonewton,
    /// mN.
    Millinewton,
    /// Pounds-force (4.448 221 615 260 5 N).
    PoundForce,
    /// Volts of a sensor with `gain` SI units per volt: newtons for a force, metres for a
    /// displacement.
    Volt {
        /// N per V, or m per V.
        gain: f64,
    },
}

impl Unit {
    /// The SI unit of `signal`.
    pub fn si(signal: Signal) -> Unit {
        match signal {
            Signal::T => Unit::Second,
            Signal::X => Unit::Metre,
            Signal::Phi => Unit::Radian,
            Signal::Omega => Unit::RadianPerSecond,
            Signal::FStf | Signal::U => Unit::Newton,
        }
    }

    /// The unit called `name` for `signal`. `counts` needs `per_rev` (counts per revolution)
    /// and `V` needs `gain` (N or m per V), except for `x`, where `V` alone is a voltage kept
    /// in volts (gain 1: an electronic oscillator's output); neither is taken by another unit.
    pub fn parse(
        signal: Signal,
        name: &str,
        gain: Option<f64>,
        per_rev: Option<f64>,
    ) -> Result<Unit, LayoutError> {
        use Signal as S;
        let unit = match (signal, name) {
            (S::T, "s") => Unit::Second,
            (S::T, "ms") => Unit::Millisecond,
            (S::T, "us" | "µs" | "μs") => Unit::Microsecond,
            (S::T, "min") => Unit::Minute,
            (S::X, "m") => Unit::Metre,
            (S::X, "cm") => Unit::Centimetre,
            (S::X, "mm") => Unit::Millimetre,
            (S::X, "um" | "µm" | "μm") => Unit::Micrometre,
            (S::X, "in") => Unit::Inch,
            (S::Phi, "rad") => Unit::Radian,
            (S::Phi, "deg") => Unit::Degree,
            (S::Phi, "rev") => Unit::Revolution,
            (S::Phi, "counts") => Unit::Counts {
                per_rev: parameter(name, "per_rev", per_rev)?,
            },
            (S::Omega, "rad/s") => Unit::RadianPerSecond,
            (S::Omega, "rpm") => Unit::Rpm,
            (S::Omega, "Hz") => Unit::Hertz,
            (S::FStf | S::U, "N") => Unit::Newton,
            (S::FStf | S::U, "kN") => Unit::Kilonewton,
            (S::FStf | S::U, "mN") => Unit::Millinewton,
            (S::FStf | S::U, "lbf") => Unit::PoundForce,
            // x in volts with no gain: a voltage kept as it is (an electronic oscillator).
            (S::X, "V") if gain.is_none() => Unit::Volt { gain: 1.0 },
            (S::X | S::FStf | S::U, "V") => Unit::Volt {
                gain: parameter(name, "gain", gain)?,
            },
            _ => {
                return Err(LayoutError::UnknownUnit {
                    signal,
                    unit: name.to_string(),
                })
            }
        };
        for (param, value, owner) in [("gain", gain, "V"), ("per_rev", per_rev, "counts")] {
            if value.is_some() && name != owner {
                return Err(LayoutError::StrayParameter {
                    param,
                    owner,
                    unit: name.to_string(),
                });
            }
        }
        Ok(unit)
    }

    /// Whether `signal` may be recorded in this unit, with a valid `per_rev` or `gain`.
    pub fn fits(self, signal: Signal) -> bool {
        use Signal as S;
        match self {
            Unit::Second | Unit::Millisecond | Unit::Microsecond | Unit::Minute => signal == S::T,
            Unit::Metre | Unit::Centimetre | Unit::Millimetre | Unit::Micrometre | Unit::Inch => {
                signal == S::X
            }
            Unit::Radian | Unit::Degree | Unit::Revolution => signal == S::Phi,
            Unit::Counts { per_rev } => signal == S::Phi && per_rev.is_finite() && per_rev > 0.0,
            Unit::RadianPerSecond | Unit::Rpm | Unit::Hertz => signal == S::Omega,
            Unit::Newton | Unit::Kilonewton | Unit::Millinewton | Unit::PoundForce => {
                matches!(signal, S::FStf | S::U)
            }
            Unit::Volt { gain } => {
                matches!(signal, S::X | S::FStf | S::U) && gain.is_finite() && gain != 0.0
            }
        }
    }

    /// The factor that brings a value in this unit to SI.
    pub fn scale(self) -> f64 {
        match self {
            Unit::Second | Unit::Metre | Unit::Radian | Unit::RadianPerSecond | Unit::Newton => 1.0,
            Unit::Millisecond | Unit::Millimetre | Unit::Millinewton => 1e-3,
            Unit::Microsecond | Unit::Micrometre => 1e-6,
            Unit::Minute => 60.0,
            Unit::Centimetre => 1e-2,
            Unit::Inch => 0.0254,
            Unit::Kilonewton => 1e3,
            Unit::PoundForce => 4.448_221_615_260_5,
            Unit::Degree => PI / 180.0,
            Unit::Revolution => TAU,
            Unit::Counts { per_rev } => TAU / per_rev,
            Unit::Rpm => TAU / 60.0,
            Unit::Hertz => TAU,
            Unit::Volt { gain } => gain,
        }
    }
}

/// `counts`'s `per_rev` or `V`'s `gain`: present, finite and non-zero (positive for counts).
fn parameter(unit: &str, param: &'static str, value: Option<f64>) -> Result<f64, LayoutError> {
    let value = value.ok_or(LayoutError::MissingParameter {
        unit: unit.to_string(),
        param,
    })?;
    let positive = param == "per_rev";
    if !value.is_finite() || value == 0.0 || (positive && value < 0.0) {
        return invalid(
            "units",
            format!("`{param}` = {value} must be a finite, non-zero number"),
        );
    }
    Ok(value)
}

/// Where a signal sits in the file.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Column {
    /// A CSV header name or `.mat` variable name.
    Name(String),
    /// A CSV column number, counted from 1 (the first column is 1, as in a spreadsheet).
    Number(usize),
}

/// A channel's offset, subtracted from the recorded value before it is brought to SI.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Offset {
    /// A value in the file's units (the unit the column is recorded in).
    Value(f64),
    /// The mean of the channel over the rest stretch ([`ReadOptions::rest`]).
    Rest,
}

/// How the cells of a CSV row are separated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Separator {
    /// Told from the header line (the first data line without a header): a tab if it has
    /// one, else a semicolon if it has one, else a comma.
    #[default]
    Auto,
    /// `,`.
    Comma,
    /// `;`.
    Semicolon,
    /// A tab.
    Tab,
}

/// The decimal mark of the numbers in a CSV file.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DecimalMark {
    /// `1.5`.
    #[default]
    Point,
    /// `1,5` (a cell holding a `.` is then an error).
    Comma,
}

/// Where the time of each sample comes from.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub enum TimeBase {
    /// The `t` column.
    #[default]
    Column,
    /// A constant sample rate: sample `i` (from 0) is at `t0 + i/rate` s.
    Rate {
        /// Samples per second, Hz.
        rate: f64,
        /// Time of the first sample, s.
        t0: f64,
    },
}

/// A force sensor's calibration `F = a·signal + b`, applied to `f_stf` after its unit.
#[derive(Clone, Copy, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Calibration {
    /// Slope.
    pub a: f64,
    /// Intercept, N.
    pub b: f64,
}

/// One signal's place in the file, its unit and its offset.
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    /// The column (CSV) or variable (`.mat`).
    pub column: Column,
    /// Whether the layout names it, so the file must have it (`x`, and `t` unless a rate
    /// gives the time, must anyway; see [`ReadOptions::needs`]).
    pub required: bool,
    /// The unit it is recorded in.
    pub unit: Unit,
    /// Subtracted from the recorded value, if any.
    pub offset: Option<Offset>,
}

/// The layout settings cannot work together, or a unit is unknown.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum LayoutError {
    /// A unit this signal is not recorded in.
    #[error("unknown unit `{unit}` for `{signal}`; known: {}", signal.unit_list())]
    UnknownUnit {
        /// The signal.
        signal: Signal,
        /// The unit as written.
        unit: String,
    },
    /// `counts` without `per_rev`, or `V` without `gain`.
    #[error("the unit `{unit}` needs `{param}`: write {{ unit = \"{unit}\", {param} = … }}")]
    MissingParameter {
        /// The unit.
        unit: String,
        /// The missing parameter.
        param: &'static str,
    },
    /// `gain` or `per_rev` given with a unit that takes none.
    #[error("`{param}` belongs to the unit `{owner}`, not `{unit}`")]
    StrayParameter {
        /// The parameter.
        param: &'static str,
        /// The unit it belongs to.
        owner: &'static str,
        /// The unit given.
        unit: String,
    },
    /// A setting that is out of range or conflicts with another.
    #[error("{message}")]
    Invalid {
        /// The setting at fault: `columns`, `units`, `offsets`, `rest`, `rate`, `t0`,
        /// `separator`, `decimal`, `skip`, `header` or `calibration`.
        setting: &'static str,
        /// What is wrong.
        message: String,
    },
}

impl LayoutError {
    /// The setting at fault (`units` for a unit error).
    pub fn setting(&self) -> &'static str {
        match self {
            LayoutError::Invalid { setting, .. } => setting,
            _ => "units",
        }
    }
}

/// How to read a record: the layout of the file.
///
/// The default is the data contract: columns named `t`, `x`, `phi`, `f_stf`, `omega`, `u`
/// in SI units, no offsets, separator told from the header line, decimal points, the header
/// on line 1, time from the `t` column.
///
/// ```
/// use stf_core::data::record::{Column, DecimalMark, Offset, ReadOptions, Signal, Unit};
/// let text = "rig 7\nexported 2024-05-02\ntime_ms;disp_mm;drive_V\n\
///             0;0,5;1\n1;0,5;1,5\n2;1,5;2\n";
/// let opts = ReadOptions::default()
///     .skip(2)
///     .decimal(DecimalMark::Comma)
///     .column(Signal::T, Column::Name("time_ms".into()))
///     .column(Signal::X, Column::Name("disp_mm".into()))
///     .column(Signal::U, Column::Number(3))
///     .unit(Signal::T, Unit::Millisecond)
///     .unit(Signal::X, Unit::Millimetre)
///     .unit(Signal::U, Unit::Volt { gain: 2.5 })
///     .offset(Signal::X, Offset::Rest)
///     .rest(0.0, 0.0015);
/// let rec = opts.read_csv_from(text.as_bytes(), "rig.csv").unwrap();
/// assert_eq!(rec.t, [0.0, 0.001, 0.002]);
/// assert_eq!(rec.x, [0.0, 0.0, 1e-3]);
/// assert_eq!(rec.u.unwrap(), [2.5, 3.75, 5.0]);
/// ```
#[derive(Clone, Debug, PartialEq, Setters)]
pub struct ReadOptions {
    #[setters(skip)]
    channels: [Channel; 6],
    /// Cell separator (CSV).
    pub separator: Separator,
    /// Decimal mark (CSV).
    pub decimal: DecimalMark,
    /// Lines before the header row (CSV), whatever they hold.
    pub skip: usize,
    /// Whether a header row names the columns (CSV); without one, columns go by number.
    pub header: bool,
    /// Where the time comes from.
    #[setters(skip)]
    pub time: TimeBase,
    /// The rest stretch `[t0, t1]`, s, over which `Offset::Rest` channels are averaged.
    #[setters(skip)]
    pub rest: Option<(f64, f64)>,
    /// Calibration of `f_stf`.
    #[setters(skip)]
    pub calibration: Option<Calibration>,
    /// The most bytes read from a record file, and the most a `.mat` file's compressed
    /// variables may inflate to ([`DEFAULT_MAX_BYTES`] unless set).
    pub max_bytes: u64,
}

/// The default cap on a record's bytes, 1 GiB: a CSV record of about 2·10⁷ rows of four
/// columns (a 10⁷-row one is 0.4–0.7 GB), or 1.3·10⁸ doubles in a `.mat` file, while a
/// wrong path (`/dev/zero`) or a `.mat` file that inflates without end stops there instead of
/// at the machine's memory.
pub const DEFAULT_MAX_BYTES: u64 = 1 << 30;

impl Default for ReadOptions {
    fn default() -> Self {
        let channel = |s: Signal| Channel {
            column: Column::Name(s.name().to_string()),
            required: false,
            unit: Unit::si(s),
            offset: None,
        };
        ReadOptions {
            channels: Signal::ALL.map(channel),
            separator: Separator::Auto,
            decimal: DecimalMark::Point,
            skip: 0,
            header: true,
            time: TimeBase::Column,
            rest: None,
            calibration: None,
            max_bytes: DEFAULT_MAX_BYTES,
        }
    }
}

impl ReadOptions {
    /// Read with these column names (each signal may still be absent, as by default).
    pub fn columns(mut self, n: ColumnNames) -> Self {
        // The channels are in the order of `Signal::ALL`.
        let names = [n.t, n.x, n.phi, n.f_stf, n.omega, n.u];
        for (channel, name) in self.channels.iter_mut().zip(names) {
            channel.column = Column::Name(name);
        }
        self
    }

    /// `signal` is in `column`, which the file must have.
    pub fn column(mut self, signal: Signal, column: Column) -> Self {
        let channel = &mut self.channels[signal.index()];
        channel.column = column;
        channel.required = true;
        self
    }

    /// `signal` is recorded in `unit`.
    pub fn unit(mut self, signal: Signal, unit: Unit) -> Self {
        self.channels[signal.index()].unit = unit;
        self
    }

    /// Subtract `offset` from `signal`.
    pub fn offset(mut self, signal: Signal, offset: Offset) -> Self {
        self.channels[signal.index()].offset = Some(offset);
        self
    }

    /// Time from a sample rate (Hz), the first sample at `t0` s; no `t` column is read.
    pub fn rate(mut self, rate: f64, t0: f64) -> Self {
        self.time = TimeBase::Rate { rate, t0 };
        self
    }

    /// The rest stretch `[t0, t1]`, s, for `Offset::Rest`.
    pub fn rest(mut self, t0: f64, t1: f64) -> Self {
        self.rest = Some((t0, t1));
        self
    }

    /// Calibrate `f_stf`: `F = a·signal + b`.
    pub fn calibration(mut self, a: f64, b: f64) -> Self {
        self.calibration = Some(Calibration { a, b });
        self
    }

    /// How `signal` is read.
    pub fn channel(&self, signal: Signal) -> &Channel {
        &self.channels[signal.index()]
    }

    /// The signals to look for in the file, with their channels (not `t` when a rate gives
    /// the time).
    pub(crate) fn wanted(&self) -> impl Iterator<Item = (Signal, &Channel)> {
        let from_rate = matches!(self.time, TimeBase::Rate { .. });
        Signal::ALL
            .into_iter()
            .filter(move |s| !(from_rate && *s == Signal::T))
            .map(|s| (s, self.channel(s)))
    }

    /// Whether the file must hold `signal`: `x` always, `t` unless a rate gives the time,
    /// any other once the layout names its column.
    pub fn needs(&self, signal: Signal) -> bool {
        match signal {
            Signal::X => true,
            Signal::T => matches!(self.time, TimeBase::Column),
            _ => self.channel(signal).required,
        }
    }

    /// Check that the settings can work together.
    pub fn check(&self) -> Result<(), LayoutError> {
        for (signal, ch) in Signal::ALL.map(|s| (s, self.channel(s))) {
            match &ch.column {
                Column::Number(0) => {
                    return invalid("columns", format!("`{signal}` = 0: columns count from 1"))
                }
                Column::Name(name) if self.needs(signal) && !self.header => {
                    return invalid(
                        "columns",
                        format!(
                            "`{signal}` is by name (\"{name}\"), but a file without a header \
                             row takes columns by number, from 1: e.g. columns = {{ t = 1, x = 2, phi = 3 }}"
                        ),
                    )
                }
                _ => {}
            }
            if !ch.unit.fits(signal) {
                return invalid(
                    "units",
                    format!(
                        "`{signal}` cannot be in {:?}; known: {}",
                        ch.unit,
                        signal.unit_list()
                    ),
                );
            }
            match ch.offset {
                Some(_) if signal == Signal::T => {
                    return invalid("offsets", "`t` takes no offset (set `t0`)")
                }
                Some(Offset::Value(v)) if !v.is_finite() => {
                    return invalid(
                        "offsets",
                        format!("`{signal}` = {v} is not a finite number"),
                    )
                }
                Some(Offset::Rest) if self.rest.is_none() => {
                    return invalid(
                        "offsets",
                        format!("`{signal}` = \"rest\" needs a rest stretch: rest = [t0, t1], s"),
                    )
                }
                _ => {}
            }
        }
        self.check_time()?;
        self.check_rest()?;
        self.check_text()?;
        if let Some(Calibration { a, b }) = self.calibration {
            if !(a.is_finite() && b.is_finite()) {
                return invalid("calibration", format!("a = {a}, b = {b} must be finite"));
            }
        }
        Ok(())
    }

    fn check_time(&self) -> Result<(), LayoutError> {
        let TimeBase::Rate { rate, t0 } = self.time else {
            return Ok(());
        };
        if !(rate.is_finite() && rate > 0.0) {
            return invalid("rate", format!("{rate} must be a positive sample rate, Hz"));
        }
        if !t0.is_finite() {
            return invalid("t0", format!("{t0} is not a finite time"));
        }
        let t = self.channel(Signal::T);
        if t.required {
            return invalid(
                "rate",
                "give either a `t` column or a sample `rate`, not both",
            );
        }
        if t.unit != Unit::Second {
            return invalid(
                "units",
                "`t` has no unit when a sample `rate` gives the time",
            );
        }
        Ok(())
    }

    fn check_rest(&self) -> Result<(), LayoutError> {
        let Some((a, b)) = self.rest else {
            return Ok(());
        };
        if !(a.is_finite() && b.is_finite() && b > a) {
            return invalid(
                "rest",
                format!("[{a}, {b}] is not a stretch of time: need t0 < t1, in s"),
            );
        }
        if !self.channels.iter().any(|c| c.offset == Some(Offset::Rest)) {
            return invalid(
                "rest",
                "no channel's offset is \"rest\": name them, e.g. offsets = { x = \"rest\" }",
            );
        }
        Ok(())
    }

    fn check_text(&self) -> Result<(), LayoutError> {
        if self.decimal == DecimalMark::Comma && self.separator == Separator::Comma {
            return invalid(
                "decimal",
                "decimal commas need another separator (`;` or tab)",
            );
        }
        Ok(())
    }
}

/// A [`LayoutError::Invalid`] of `setting`.
fn invalid<T>(setting: &'static str, message: impl Into<String>) -> Result<T, LayoutError> {
    Err(LayoutError::Invalid {
        setting,
        message: message.into(),
    })
}

/// The signals as recorded, by [`Signal`] index, before the layout is applied.
pub(crate) type Raw = [Option<Vec<f64>>; 6];

/// Bring recorded values to SI as `opts` says: the time from its column or the rate, each
/// other channel `scale · (value − offset)`, then `f_stf`'s calibration. `labels` name the
/// columns and `row_of` turns a sample index into a row, for errors.
pub(crate) fn apply(
    opts: &ReadOptions,
    mut raw: Raw,
    source: &str,
    labels: &[String; 6],
    row_of: &dyn Fn(usize) -> usize,
) -> Result<Raw, RecordError> {
    let n = raw[Signal::X.index()].as_ref().map_or(0, Vec::len);
    let t: Vec<f64> = match opts.time {
        TimeBase::Rate { rate, t0 } => (0..n).map(|i| t0 + i as f64 / rate).collect(),
        TimeBase::Column => {
            let k = opts.channel(Signal::T).unit.scale();
            let t: Vec<f64> = raw[Signal::T.index()].take().unwrap_or_default();
            t.into_iter().map(|v| k * v).collect()
        }
    };
    for signal in Signal::ALL.into_iter().skip(1) {
        let ch = opts.channel(signal);
        let label = &labels[signal.index()];
        let Some(values) = raw[signal.index()].as_mut() else {
            if ch.offset.is_some() {
                return Err(RecordError::new(
                    source,
                    format!("an offset is set for `{signal}`, but the record has no such column"),
                )
                .in_column(label.as_str()));
            }
            continue;
        };
        let offset = match ch.offset {
            None => 0.0,
            Some(Offset::Value(v)) => v,
            Some(Offset::Rest) => rest_mean(opts, &t, values, source, label, row_of)?,
        };
        let k = ch.unit.scale();
        let cal = match (signal, opts.calibration) {
            (Signal::FStf, Some(c)) => c,
            _ => Calibration { a: 1.0, b: 0.0 },
        };
        // SI values with no offset or calibration are kept as read: `+ 0.0` would turn a
        // recorded `-0` into `0`, and a record must read back to the very numbers written.
        if (offset, k, cal.a, cal.b) != (0.0, 1.0, 1.0, 0.0) {
            values
                .iter_mut()
                .for_each(|v| *v = cal.a * (k * (*v - offset)) + cal.b);
        }
    }
    raw[Signal::T.index()] = Some(t);
    Ok(raw)
}

/// The mean of `values` over the samples with `t` in the rest stretch.
fn rest_mean(
    opts: &ReadOptions,
    t: &[f64],
    values: &[f64],
    source: &str,
    label: &str,
    row_of: &dyn Fn(usize) -> usize,
) -> Result<f64, RecordError> {
    let (a, b) = opts.rest.unwrap_or((f64::NAN, f64::NAN));
    let err = |message: String| RecordError::new(source, message).in_column(label);
    let (mut sum, mut count) = (0.0, 0usize);
    for (i, (&ti, &v)) in t.iter().zip(values).enumerate() {
        if (a..=b).contains(&ti) {
            if !v.is_finite() {
                return Err(err(format!("not a finite number: `{v}`")).at_row(row_of(i)));
            }
            sum += v;
            count += 1;
        }
    }
    if count == 0 {
        let span = match (t.first(), t.last()) {
            (Some(first), Some(last)) => format!("the record runs from {first} s to {last} s"),
            _ => "the record is empty".to_string(),
        };
        return Err(err(format!(
            "the rest stretch [{a}, {b}] s holds no samples: {span}"
        )));
    }
    Ok(sum / count as f64)
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests may unwrap
mod tests {
    use super::*;

    #[test]
    fn units_parse_for_their_signals_and_scale_to_si() {
        let cases = [
            (Signal::T, "ms", 1e-3),
            (Signal::T, "µs", 1e-6),
            (Signal::T, "us", 1e-6),
            (Signal::X, "mm", 1e-3),
            (Signal::X, "um", 1e-6),
            (Signal::Phi, "deg", PI / 180.0),
            (Signal::Omega, "rpm", TAU / 60.0),
            (Signal::Omega, "Hz", TAU),
            (Signal::FStf, "mN", 1e-3),
            (Signal::U, "N", 1.0),
            (Signal::T, "min", 60.0),
            (Signal::X, "cm", 1e-2),
            (Signal::X, "in", 0.0254),
            (Signal::Phi, "rev", TAU),
            (Signal::FStf, "kN", 1e3),
            (Signal::U, "lbf", 4.448_221_615_260_5),
        ];
        for (signal, name, k) in cases {
            let unit = Unit::parse(signal, name, None, None).unwrap();
            assert!((unit.scale() / k - 1.0).abs() < 1e-15, "{signal} {name}");
        }
        let counts = Unit::parse(Signal::Phi, "counts", None, Some(2048.0)).unwrap();
        assert!((counts.scale() * 2048.0 - TAU).abs() < 1e-12);
        let volts = Unit::parse(Signal::U, "V", Some(2.5), None).unwrap();
        assert_eq!(volts, Unit::Volt { gain: 2.5 });
        assert_eq!(volts.scale(), 2.5);
        // A displacement sensor in volts: 2 mm per V.
        let lvdt = Unit::parse(Signal::X, "V", Some(0.002), None).unwrap();
        assert!(lvdt.fits(Signal::X) && !lvdt.fits(Signal::Phi));
        assert_eq!(lvdt.scale(), 0.002);
    }

    #[test]
    fn a_unit_error_lists_the_known_units() {
        let e = Unit::parse(Signal::X, "furlong", None, None).unwrap_err();
        assert_eq!(
            e.to_string(),
            "unknown unit `furlong` for `x`; known: m, cm, mm, um (or µm), in, V (with `gain`, \
             metres per volt; alone, a voltage kept in volts)"
        );
        let e = Unit::parse(Signal::T, "mm", None, None).unwrap_err();
        assert!(e.to_string().contains("known: s, ms, us"), "{e}");
        let e = Unit::parse(Signal::U, "V", None, None).unwrap_err();
        assert!(e.to_string().contains("needs `gain`"), "{e}");
        let volts = Unit::parse(Signal::X, "V", None, None).unwrap();
        assert_eq!(volts, Unit::Volt { gain: 1.0 });
        let e = Unit::parse(Signal::Phi, "counts", None, None).unwrap_err();
        assert!(e.to_string().contains("needs `per_rev`"), "{e}");
        let e = Unit::parse(Signal::Phi, "deg", Some(1.0), None).unwrap_err();
        assert!(
            e.to_string().contains("`gain` belongs to the unit `V`"),
            "{e}"
        );
        let e = Unit::parse(Signal::Phi, "counts", None, Some(-5.0)).unwrap_err();
        assert_eq!(e.setting(), "units");
        assert!(Unit::parse(Signal::T, "V", Some(2.0), None).is_err());
        assert!(Unit::parse(Signal::Phi, "V", Some(2.0), None).is_err());
    }

    #[test]
    fn check_names_the_setting_at_fault() {
        let d = ReadOptions::default;
        let setting = |o: ReadOptions| o.check().unwrap_err().setting();
        assert!(d().check().is_ok());
        assert_eq!(setting(d().column(Signal::U, Column::Number(0))), "columns");
        assert_eq!(
            setting(
                d().header(false)
                    .column(Signal::X, Column::Name("a".into()))
            ),
            "columns"
        );
        assert_eq!(setting(d().header(false)), "columns");
        let by_number = d()
            .header(false)
            .column(Signal::T, Column::Number(1))
            .column(Signal::X, Column::Number(2));
        assert!(by_number.check().is_ok());
        assert!(d()
            .header(false)
            .rate(10.0, 0.0)
            .column(Signal::X, Column::Number(1))
            .check()
            .is_ok());
        assert_eq!(
            setting(d().offset(Signal::T, Offset::Value(1.0))),
            "offsets"
        );
        assert_eq!(setting(d().offset(Signal::X, Offset::Rest)), "offsets");
        assert_eq!(setting(d().rest(0.0, 1.0)), "rest");
        assert_eq!(
            setting(d().offset(Signal::X, Offset::Rest).rest(1.0, 1.0)),
            "rest"
        );
        assert_eq!(setting(d().rate(0.0, 0.0)), "rate");
        assert_eq!(setting(d().rate(100.0, f64::NAN)), "t0");
        assert_eq!(
            setting(d().rate(100.0, 0.0).column(Signal::T, Column::Number(1))),
            "rate"
        );
        assert_eq!(
            setting(d().rate(100.0, 0.0).unit(Signal::T, Unit::Millisecond)),
            "units"
        );
        assert_eq!(
            setting(d().decimal(DecimalMark::Comma).separator(Separator::Comma)),
            "decimal"
        );
        assert_eq!(setting(d().calibration(f64::INFINITY, 0.0)), "calibration");
        assert_eq!(setting(d().unit(Signal::X, Unit::Degree)), "units");
        assert_eq!(
            setting(d().unit(Signal::U, Unit::Volt { gain: f64::NAN })),
            "units"
        );
    }

    fn raw(t: &[f64], x: &[f64], f: Option<&[f64]>) -> Raw {
        [
            Some(t.to_vec()),
            Some(x.to_vec()),
            None,
            f.map(<[f64]>::to_vec),
            None,
            None,
        ]
    }

    fn labels() -> [String; 6] {
        Signal::ALL.map(|s| s.name().to_string())
    }

    #[test]
    fn apply_scales_offsets_and_calibrates() {
        let opts = ReadOptions::default()
            .unit(Signal::T, Unit::Millisecond)
            .unit(Signal::X, Unit::Millimetre)
            .offset(Signal::X, Offset::Value(0.5))
            .unit(Signal::FStf, Unit::Volt { gain: 2.0 })
            .offset(Signal::FStf, Offset::Rest)
            .rest(0.0, 0.0015)
            .calibration(3.0, 0.25);
        let r = raw(&[0.0, 1.0, 2.0], &[0.5, 1.5, 2.5], Some(&[1.0, 3.0, 5.0]));
        let out = apply(&opts, r, "r.csv", &labels(), &|i| i + 1).unwrap();
        assert_eq!(out[0].as_deref(), Some(&[0.0, 0.001, 0.002][..]));
        assert_eq!(out[1].as_deref(), Some(&[0.0, 1e-3, 2e-3][..]));
        // Rest mean of the volts over t ≤ 1.5 ms: 2 V; F = 3·(2·(v − 2)) + 0.25.
        assert_eq!(out[3].as_deref(), Some(&[-5.75, 6.25, 18.25][..]));
    }

    #[test]
    fn apply_makes_time_from_a_rate() {
        let opts = ReadOptions::default().rate(200.0, 1.0);
        let out = apply(
            &opts,
            raw(&[], &[1.0, 2.0, 3.0], None),
            "r",
            &labels(),
            &|i| i,
        )
        .unwrap();
        assert_eq!(out[0].as_deref(), Some(&[1.0, 1.005, 1.01][..]));
    }

    #[test]
    fn apply_errors_name_the_column() {
        let opts = ReadOptions::default()
            .offset(Signal::X, Offset::Rest)
            .rest(5.0, 6.0);
        let e = apply(
            &opts,
            raw(&[0.0, 1.0], &[1.0, 2.0], None),
            "r.csv",
            &labels(),
            &|i| i,
        )
        .unwrap_err();
        assert_eq!(e.column.as_deref(), Some("x"));
        assert!(e
            .message
            .contains("holds no samples: the record runs from 0 s to 1 s"));
        let opts = ReadOptions::default().offset(Signal::FStf, Offset::Value(1.0));
        let e = apply(&opts, raw(&[0.0], &[1.0], None), "r.csv", &labels(), &|i| i).unwrap_err();
        assert_eq!(e.column.as_deref(), Some("f_stf"));
        let opts = ReadOptions::default()
            .offset(Signal::X, Offset::Rest)
            .rest(0.0, 6.0);
        let e = apply(
            &opts,
            raw(&[0.0, 1.0], &[1.0, f64::NAN], None),
            "r",
            &labels(),
            &|i| i + 1,
        )
        .unwrap_err();
        assert_eq!((e.row, e.column.as_deref()), (Some(2), Some("x")));
    }
}
