//! The `[data]` section of an experiment file: the record's file and time window, and the
//! layout a lab wrote it in — `columns` (by name or by number from 1), `units` (with a
//! `gain` for volts and `per_rev` for encoder counts), `offsets` (a number in the column's
//! own units, or `"rest"`: the mean over the `rest` stretch), a sample `rate` (and `t0`)
//! instead of a time column, `separator`, `decimal`, `skip`, `header`, the force
//! `calibration` and `max_bytes`, the cap on what is read. The keys become the core's typed
//! [`ReadOptions`], which the readers apply; every error names the file, the line and the key,
//! and lists what is accepted.

use std::collections::BTreeMap;
use std::ops::Range;
use std::path::{Path, PathBuf};

use anyhow::Result;
use serde::Deserialize;
use stf_core::data::record::{
    Calibration, Column, DecimalMark, Offset, ReadOptions, Separator, Signal, Unit,
};
use toml::{Spanned, Value};

use crate::experiment::context::Ctx;
use crate::experiment::raw_drive::RawDrive;

/// `[data]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RawData {
    /// The record; absent, `[data]` gives only the layout (of the `[[identify]]` records).
    file: Option<String>,
    /// Time window to use, s: `[start, end]` (read as a list, so that a third value is an
    /// error rather than dropped).
    window: Option<Spanned<Vec<f64>>>,
    /// Where each signal is: a column (variable) name or a CSV column number from 1.
    #[serde(default)]
    columns: BTreeMap<String, Spanned<Value>>,
    /// Units: a name (`"mm"`) or a table (`{ unit = "V", gain = 2.5 }`).
    #[serde(default)]
    units: BTreeMap<String, Spanned<Value>>,
    /// Offsets: a number in the column's units, or `"rest"`.
    #[serde(default)]
    offsets: BTreeMap<String, Spanned<Value>>,
    rest: Option<Spanned<[f64; 2]>>,
    rate: Option<Spanned<f64>>,
    t0: Option<Spanned<f64>>,
    separator: Option<Spanned<String>>,
    decimal: Option<Spanned<String>>,
    skip: Option<Spanned<usize>>,
    header: Option<Spanned<bool>>,
    /// The most bytes the record file may hold (a `.mat` file: inflate to).
    max_bytes: Option<Spanned<f64>>,
    /// Strain-gauge calibration of a force column recorded as a signal: F = a·signal + b.
    calibration: Option<Spanned<Calibration>>,
    /// How the measured drive (φ or u) is reconstructed: `"auto"`, `"samples"` or a filter.
    pub drive: Option<RawDrive>,
    /// Refuse or flag implausible records (`crate::plausibility`); default true.
    plausibility: Option<bool>,
    /// Measured channels kept beside the signals (columns that laws follow, or that
    /// discovery tries laws of): `["u_ctrl"]`.
    #[serde(default)]
    channels: Vec<String>,
}

/// A checked `[data]` section.
#[derive(Clone, Debug, Default)]
pub struct DataSection {
    /// The record, resolved against the experiment's folder.
    pub file: Option<PathBuf>,
    /// Line of `[data]` in the file.
    pub line: usize,
    /// Time window, s.
    pub window: Option<(f64, f64)>,
    /// How to read the record.
    pub layout: ReadOptions,
    /// Whether records are checked for plausibility (`[data] plausibility`, default true).
    pub plausibility: bool,
    /// Measured channels the record carries (`[data] channels`), besides those laws name.
    pub channels: Vec<String>,
}

/// Validate `[data]` (absent: no record, the default layout).
pub fn parse(cx: &Ctx, data: Option<&Spanned<RawData>>, dir: &Path) -> Result<DataSection> {
    let Some(d) = data else {
        return Ok(DataSection {
            plausibility: true,
            ..DataSection::default()
        });
    };
    let (span, raw) = (d.span(), d.get_ref());
    let window = match &raw.window {
        None => None,
        Some(w) => match w.get_ref()[..] {
            [a, b] if b > a => Some((a, b)),
            [a, b] => return Err(cx.at(w.span(), "data.window", format!("[{a}, {b}] is empty"))),
            ref other => {
                let msg = format!(
                    "give two times, [start, end] in s, not {} value(s)",
                    other.len()
                );
                return Err(cx.at(w.span(), "data.window", msg));
            }
        },
    };
    let layout = layout(cx, &span, raw)?;
    Ok(DataSection {
        file: raw.file.as_ref().map(|f| dir.join(f)),
        line: cx.line(span.start),
        window,
        layout,
        plausibility: raw.plausibility.unwrap_or(true),
        channels: raw.channels.clone(),
    })
}

/// The record's layout from the `[data]` keys.
fn layout(cx: &Ctx, span: &Range<usize>, raw: &RawData) -> Result<ReadOptions> {
    let mut opts = text_settings(cx, raw)?;
    for (signal, value, at) in entries(cx, "columns", &raw.columns)? {
        opts = opts.column(signal, column(cx, signal, value, at)?);
    }
    for (signal, value, at) in entries(cx, "units", &raw.units)? {
        opts = opts.unit(signal, unit(cx, signal, value, at)?);
    }
    for (signal, value, at) in entries(cx, "offsets", &raw.offsets)? {
        opts = opts.offset(signal, offset(cx, signal, value, at)?);
    }
    match (&raw.rate, &raw.t0) {
        (Some(rate), t0) => {
            opts = opts.rate(*rate.get_ref(), t0.as_ref().map_or(0.0, |t| *t.get_ref()));
        }
        (None, Some(t0)) => {
            return Err(cx.at(t0.span(), "data.t0", "`t0` goes with a sample `rate`"));
        }
        (None, None) => {}
    }
    opts.rest = raw.rest.as_ref().map(|r| (r.get_ref()[0], r.get_ref()[1]));
    opts.calibration = raw.calibration.as_ref().map(|c| *c.get_ref());
    if let Some(m) = &raw.max_bytes {
        opts = opts.max_bytes(cx.count(m, "data.max_bytes", 1, "size in bytes")?);
    }
    opts.check().map_err(|e| {
        let setting = e.setting();
        cx.at(
            span_of(raw, setting).unwrap_or_else(|| span.clone()),
            &format!("data.{setting}"),
            e,
        )
    })?;
    Ok(opts)
}

/// `separator`, `decimal`, `skip` and `header` (CSV only).
fn text_settings(cx: &Ctx, raw: &RawData) -> Result<ReadOptions> {
    let mut opts = ReadOptions::default();
    let is_mat = raw.file.as_ref().is_some_and(|f| {
        Path::new(f)
            .extension()
            .is_some_and(|e| e.eq_ignore_ascii_case("mat"))
    });
    for key in ["separator", "decimal", "skip", "header"] {
        if let (true, Some(at)) = (is_mat, span_of(raw, key)) {
            return Err(cx.at(
                at,
                &format!("data.{key}"),
                "applies to CSV files; a .mat file's variables have names and numbers",
            ));
        }
    }
    if let Some(s) = &raw.separator {
        opts = opts.separator(match s.get_ref().as_str() {
            "," | "comma" => Separator::Comma,
            ";" | "semicolon" => Separator::Semicolon,
            "\t" | "tab" => Separator::Tab,
            "auto" => Separator::Auto,
            other => {
                return Err(cx.at(
                    s.span(),
                    "data.separator",
                    format!(
                        "unknown separator `{other}`; known: \",\", \";\", \"tab\" (or \"\\t\"), \
                         \"auto\" (told from the header line, the default)"
                    ),
                ))
            }
        });
    }
    if let Some(d) = &raw.decimal {
        opts = opts.decimal(match d.get_ref().as_str() {
            "." => DecimalMark::Point,
            "," => DecimalMark::Comma,
            other => {
                return Err(cx.at(
                    d.span(),
                    "data.decimal",
                    format!("unknown decimal mark `{other}`; known: \".\" (the default), \",\""),
                ))
            }
        });
    }
    if let Some(n) = &raw.skip {
        opts = opts.skip(*n.get_ref());
    }
    if let Some(h) = &raw.header {
        opts = opts.header(*h.get_ref());
    }
    Ok(opts)
}

/// The entries of a `columns`, `units` or `offsets` table, by signal.
fn entries<'a>(
    cx: &Ctx,
    table: &str,
    map: &'a BTreeMap<String, Spanned<Value>>,
) -> Result<Vec<(Signal, &'a Value, Range<usize>)>> {
    map.iter()
        .map(|(name, value)| {
            let signal = Signal::from_name(name).ok_or_else(|| {
                cx.at(
                    value.span(),
                    &format!("data.{table}.{name}"),
                    format!("unknown signal `{name}`; known: {}", Signal::names()),
                )
            })?;
            Ok((signal, value.get_ref(), value.span()))
        })
        .collect()
}

/// A `columns` value: a name, or a number from 1.
fn column(cx: &Ctx, signal: Signal, value: &Value, at: Range<usize>) -> Result<Column> {
    let key = format!("data.columns.{signal}");
    match value {
        Value::String(name) => Ok(Column::Name(name.clone())),
        Value::Integer(k) if *k >= 1 => Ok(Column::Number(usize::try_from(*k).unwrap_or(0))),
        Value::Integer(k) => Err(cx.at(
            at,
            &key,
            format!("column {k}: columns count from 1 (the first column is 1)"),
        )),
        other => Err(cx.at(
            at,
            &key,
            format!("`{other}` is not a column: give its name (a string) or its number, from 1"),
        )),
    }
}

/// How a unit is written (for messages).
const UNIT_FORMS: &str = "a unit is a name (\"mm\") or a table: { unit = \"V\", gain = 2.5 } \
                          (N or m per V) or { unit = \"counts\", per_rev = 2048 }";

/// A `units` value: `"mm"`, or `{ unit = "V", gain = 2.5 }`, `{ unit = "counts",
/// per_rev = 2048 }`.
fn unit(cx: &Ctx, signal: Signal, value: &Value, at: Range<usize>) -> Result<Unit> {
    let key = format!("data.units.{signal}");
    let fail = |msg: String| cx.at(at.clone(), &key, msg);
    let (name, gain, per_rev) = match value {
        Value::String(s) => (Some(s.as_str()), None, None),
        Value::Table(table) => unit_table(table).map_err(fail)?,
        other => return Err(fail(format!("`{other}`: {UNIT_FORMS}"))),
    };
    let name = name.ok_or_else(|| fail(format!("the table has no `unit`; {UNIT_FORMS}")))?;
    Unit::parse(signal, name, gain, per_rev).map_err(|e| fail(e.to_string()))
}

/// The `unit`, `gain` and `per_rev` of a unit table.
#[allow(clippy::type_complexity)]
fn unit_table(table: &toml::Table) -> Result<(Option<&str>, Option<f64>, Option<f64>), String> {
    let (mut name, mut gain, mut per_rev) = (None, None, None);
    for (key, v) in table {
        match key.as_str() {
            "unit" => {
                name = Some(
                    v.as_str()
                        .ok_or(format!("`unit` = {v} is not a unit name"))?,
                )
            }
            "gain" => {
                gain = Some(number(v).ok_or(format!("`gain` = {v} is not a number, N or m per V"))?)
            }
            "per_rev" => {
                per_rev =
                    Some(number(v).ok_or(format!("`per_rev` = {v} is not a number of counts"))?)
            }
            other => return Err(format!("unknown key `{other}`; {UNIT_FORMS}")),
        }
    }
    Ok((name, gain, per_rev))
}

/// An `offsets` value: a number in the column's own units, or `"rest"`.
fn offset(cx: &Ctx, signal: Signal, value: &Value, at: Range<usize>) -> Result<Offset> {
    match value {
        Value::String(s) if s == "rest" => Ok(Offset::Rest),
        v => number(v).map(Offset::Value).ok_or_else(|| {
            cx.at(
                at,
                &format!("data.offsets.{signal}"),
                format!(
                    "`{v}`: an offset is a number, in the column's own units (as recorded), \
                     or \"rest\" (the mean over the `rest` stretch)"
                ),
            )
        }),
    }
}

/// A TOML number (integer or float) as `f64`.
fn number(value: &Value) -> Option<f64> {
    value.as_float().or(value.as_integer().map(|v| v as f64))
}

/// Where a layout setting is written, if it is (`columns` without columns: `header`).
fn span_of(raw: &RawData, setting: &str) -> Option<Range<usize>> {
    let first = |map: &BTreeMap<String, Spanned<Value>>| map.values().next().map(Spanned::span);
    match setting {
        "columns" => first(&raw.columns).or_else(|| raw.header.as_ref().map(Spanned::span)),
        "units" => first(&raw.units),
        "offsets" => first(&raw.offsets),
        "rest" => raw.rest.as_ref().map(Spanned::span),
        "rate" => raw.rate.as_ref().map(Spanned::span),
        "t0" => raw.t0.as_ref().map(Spanned::span),
        "separator" => raw.separator.as_ref().map(Spanned::span),
        "decimal" => raw.decimal.as_ref().map(Spanned::span),
        "skip" => raw.skip.as_ref().map(Spanned::span),
        "header" => raw.header.as_ref().map(Spanned::span),
        "calibration" => raw.calibration.as_ref().map(Spanned::span),
        _ => None,
    }
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests may unwrap
mod tests {
    use super::*;
    use crate::experiment::Experiment;
    use stf_core::data::record::{Calibration, TimeBase};

    fn parse(data: &str) -> Result<Experiment> {
        Experiment::parse(
            Path::new("exp.toml"),
            &format!("# lab rig\n[data]\nfile = \"rig.csv\"\n{data}"),
        )
    }

    /// The error names `exp.toml:line`, the key, and contains `words`.
    fn expect(data: &str, line: usize, key: &str, words: &str) {
        let msg = format!("{:#}", parse(data).unwrap_err());
        assert!(
            msg.starts_with(&format!("exp.toml:{line}: `{key}`")),
            "{msg}"
        );
        assert!(msg.contains(words), "{msg}");
    }

    #[test]
    fn a_window_is_two_increasing_times_and_a_third_value_is_refused() {
        assert_eq!(
            parse("window = [1.0, 2.5]\n").unwrap().data_window,
            Some((1.0, 2.5))
        );
        // It was read as its first two values, the third dropped without a word.
        expect(
            "\nwindow = [0.0, 1.0, 2.0]\n",
            5,
            "data.window",
            "give two times, [start, end] in s, not 3 value(s)",
        );
        expect("window = [3.0]\n", 4, "data.window", "not 1 value(s)");
        expect("window = [2.0, 1.0]\n", 4, "data.window", "[2, 1] is empty");
    }

    #[test]
    fn max_bytes_caps_the_record_and_names_its_line_when_bad() {
        let e = parse("max_bytes = 1e9\n").unwrap();
        assert_eq!(e.data_layout.max_bytes, 1_000_000_000);
        assert_eq!(
            parse("").unwrap().data_layout.max_bytes,
            stf_core::data::record::DEFAULT_MAX_BYTES
        );
        let msg = parse("\nmax_bytes = 0\n").unwrap_err().to_string();
        assert_eq!(
            msg,
            "exp.toml:5: `data.max_bytes`: 0 is not a size in bytes (at least 1)"
        );
    }

    #[test]
    fn a_lab_layout_parses_into_read_options() {
        let e = parse(
            r#"separator = ";"
decimal = ","
skip = 2
columns = { t = "time_ms", x = "disp_mm", u = 3, phi = "enc" }
units = { t = "ms", x = "mm", u = { unit = "V", gain = 2.5 }, phi = { unit = "counts", per_rev = 2048 } }
offsets = { x = "rest", u = 0.12 }
rest = [0.0, 2.0]
calibration = { a = 0.5, b = 0.1 }
"#,
        )
        .unwrap();
        let o = &e.data_layout;
        assert_eq!(
            (o.separator, o.decimal, o.skip),
            (Separator::Semicolon, DecimalMark::Comma, 2)
        );
        assert_eq!(o.channel(Signal::T).column, Column::Name("time_ms".into()));
        assert_eq!(o.channel(Signal::U).column, Column::Number(3));
        assert!(o.channel(Signal::U).required);
        assert_eq!(o.channel(Signal::U).unit, Unit::Volt { gain: 2.5 });
        assert_eq!(
            o.channel(Signal::Phi).unit,
            Unit::Counts { per_rev: 2048.0 }
        );
        assert_eq!(o.channel(Signal::X).offset, Some(Offset::Rest));
        assert_eq!(o.channel(Signal::U).offset, Some(Offset::Value(0.12)));
        assert_eq!(o.rest, Some((0.0, 2.0)));
        assert_eq!(o.calibration, Some(Calibration { a: 0.5, b: 0.1 }));
        assert_eq!(e.data_line, 2);
    }

    #[test]
    fn a_rate_header_and_tab_parse() {
        let e = parse("separator = \"tab\"\nheader = false\nrate = 1000\nt0 = 5.0\ncolumns = { x = 1, phi = 2 }\n")
            .unwrap();
        let o = &e.data_layout;
        assert_eq!(o.separator, Separator::Tab);
        assert!(!o.header);
        assert_eq!(
            o.time,
            TimeBase::Rate {
                rate: 1000.0,
                t0: 5.0
            }
        );
        assert_eq!(
            parse("separator = \"\\t\"\n")
                .unwrap()
                .data_layout
                .separator,
            Separator::Tab
        );
    }

    #[test]
    fn a_logger_file_without_header_or_time_is_read() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("logger.csv"), "20.5,0,100\n22.5,512,-50\n").unwrap();
        let e = Experiment::parse(
            &dir.path().join("exp.toml"),
            r#"[data]
file = "logger.csv"
header = false
rate = 1000.0
columns = { x = 1, phi = 2, u = 3 }
units = { x = "um", phi = { unit = "counts", per_rev = 2048 }, u = "mN" }
offsets = { x = 12.5 }
"#,
        )
        .unwrap();
        let r = crate::fitting::read_record(&e, e.data_file.as_ref().unwrap()).unwrap();
        assert_eq!(r.t, [0.0, 0.001]);
        assert!((r.x[0] - 8e-6).abs() < 1e-18 && (r.x[1] - 10e-6).abs() < 1e-18);
        let phi = r.phi.unwrap();
        assert!((phi[1] - std::f64::consts::FRAC_PI_2).abs() < 1e-12);
        assert_eq!(r.u.unwrap(), [0.1, -0.05]);
    }

    #[test]
    fn unknown_values_list_the_accepted_ones_at_their_line() {
        expect(
            "units = { x = \"furlong\" }\n",
            4,
            "data.units.x",
            "known: m, cm, mm, um (or µm)",
        );
        expect(
            "\nunits = { t = \"s\",\n  omega = \"rps\" }\n",
            6,
            "data.units.omega",
            "known: rad/s, rpm, Hz",
        );
        expect("units = { u = \"V\" }\n", 4, "data.units.u", "needs `gain`");
        expect(
            "units = { phi = { unit = \"counts\" } }\n",
            4,
            "data.units.phi",
            "needs `per_rev`",
        );
        expect(
            "units = { u = { unit = \"V\", gian = 2 } }\n",
            4,
            "data.units.u",
            "unknown key `gian`",
        );
        expect(
            "units = { f_stf = \"kg\" }\n",
            4,
            "data.units.f_stf",
            "known: N, kN, mN, lbf, V (with `gain`",
        );
        expect(
            "units = { y = \"m\" }\n",
            4,
            "data.units.y",
            "known: t, x, phi, f_stf, omega, u",
        );
        expect("columns = { x = 0 }\n", 4, "data.columns.x", "count from 1");
        expect(
            "columns = { x = 1.5 }\n",
            4,
            "data.columns.x",
            "its name (a string) or its number",
        );
        expect(
            "offsets = { x = \"mean\" }\n",
            4,
            "data.offsets.x",
            "or \"rest\"",
        );
        expect(
            "separator = \"|\"\n",
            4,
            "data.separator",
            "known: \",\", \";\", \"tab\"",
        );
        expect(
            "decimal = \"'\"\n",
            4,
            "data.decimal",
            "known: \".\" (the default), \",\"",
        );
    }

    #[test]
    fn settings_that_cannot_work_together_name_their_key() {
        expect(
            "offsets = { x = \"rest\" }\n",
            4,
            "data.offsets",
            "needs a rest stretch",
        );
        expect(
            "\nrest = [0.0, 1.0]\n",
            5,
            "data.rest",
            "no channel's offset is \"rest\"",
        );
        expect(
            "offsets = { x = \"rest\" }\nrest = [2.0, 1.0]\n",
            5,
            "data.rest",
            "t0 < t1",
        );
        expect("rate = 0.0\n", 4, "data.rate", "positive sample rate");
        expect("t0 = 1.0\n", 4, "data.t0", "goes with a sample `rate`");
        expect(
            "rate = 100.0\ncolumns = { t = 1 }\n",
            4,
            "data.rate",
            "not both",
        );
        expect(
            "decimal = \",\"\nseparator = \",\"\n",
            4,
            "data.decimal",
            "another separator",
        );
        expect(
            "header = false\n",
            4,
            "data.columns",
            "takes columns by number",
        );
        expect(
            "header = false\ncolumns = { t = 1, x = \"d\" }\n",
            5,
            "data.columns",
            "by name",
        );
        expect(
            "offsets = { t = 1.0 }\n",
            4,
            "data.offsets",
            "`t` takes no offset",
        );
        let msg = format!(
            "{:#}",
            Experiment::parse(
                Path::new("exp.toml"),
                "[data]\nfile = \"r.mat\"\nskip = 2\n"
            )
            .unwrap_err()
        );
        assert!(
            msg.starts_with("exp.toml:3: `data.skip`: applies to CSV files"),
            "{msg}"
        );
    }
}
