//! The `[filter]` section of an experiment file and `[data] drive`, which together make the
//! kinematics settings: the sliding polynomial filters of the motion (`motion`) and of the
//! measured drive (`omega`, or `[data] drive`, the same setting), what they do at the
//! record's ends (`boundary`), and the source study's filters (`paper = true`).
//!
//! `[data] drive` is a name or a filter table; serde's message for a value matching neither
//! form of an untagged enum lists nothing, so the name is read as a string and checked here,
//! listing the accepted ones.

use anyhow::Result;
use serde::Deserialize;
use stf_core::data::kinematics::KinematicsSettings;
use stf_core::numerics::derivative::{Boundary, PolyFilter};
use stf_core::numerics::reconstruct::DriveSmoothing;
use toml::Spanned;

use super::raw_drive::{RawDrive, RawFilterSpec};
use super::Ctx;
use crate::data_layout::RawData;

/// `boundary` as written: core's [`Boundary`] by name.
#[derive(Clone, Copy, Debug, Deserialize)]
#[serde(rename_all = "snake_case")]
enum BoundaryName {
    Shifted,
    Zero,
}

impl From<BoundaryName> for Boundary {
    fn from(b: BoundaryName) -> Boundary {
        match b {
            BoundaryName::Shifted => Boundary::Shifted,
            BoundaryName::Zero => Boundary::Zero,
        }
    }
}

/// `[filter]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawFilter {
    motion: Option<RawFilterSpec>,
    omega: Option<RawFilterSpec>,
    boundary: Option<BoundaryName>,
    #[serde(default)]
    paper: bool,
}

/// `kinematics` with the drive reconstruction `[data] drive` asks for, if it does; `[filter]
/// omega`, the same setting, must then be absent.
pub(super) fn with_drive(
    mut kinematics: KinematicsSettings,
    filter: Option<&Spanned<RawFilter>>,
    data: Option<&Spanned<RawData>>,
    cx: &Ctx,
) -> Result<KinematicsSettings> {
    let Some((d, drive)) = data.and_then(|d| Some((d, d.get_ref().drive.as_ref()?))) else {
        return Ok(kinematics);
    };
    if filter.is_some_and(|f| f.get_ref().omega.is_some()) {
        return Err(cx.at(
            d.span(),
            "data.drive",
            "set either `[data] drive` or `[filter] omega`, not both (they are the same \
             setting)",
        ));
    }
    kinematics.drive = drive_smoothing(drive).map_err(|e| cx.at(d.span(), "data.drive", e))?;
    Ok(kinematics)
}

/// The kinematics settings of `[filter]` (absent: the defaults): the defaults (or the
/// paper's), its filters, and the boundary on every filter.
pub(super) fn check(filter: Option<&Spanned<RawFilter>>, cx: &Ctx) -> Result<KinematicsSettings> {
    let Some(raw) = filter else {
        return Ok(KinematicsSettings::default());
    };
    let (span, f) = (raw.span(), raw.get_ref());
    let mut kinematics = if f.paper {
        KinematicsSettings::paper()
    } else {
        KinematicsSettings::default()
    };
    if let Some(b) = f.boundary {
        kinematics.boundary = b.into();
    }
    let boundary = kinematics.boundary;
    let make = |key: &str, spec: &RawFilterSpec| {
        PolyFilter::new(spec.order, spec.window)
            .map(|f| f.boundary(boundary))
            .map_err(|e| cx.at(span.clone(), key, e))
    };
    if let Some(m) = &f.motion {
        kinematics.motion = Some(make("filter.motion", m)?);
    } else if let Some(m) = kinematics.motion.as_mut() {
        *m = m.boundary(boundary);
    }
    if let Some(o) = &f.omega {
        kinematics.drive = DriveSmoothing::Filter(make("filter.omega", o)?);
    } else if let DriveSmoothing::Samples(f) = &mut kinematics.drive {
        *f = f.boundary(boundary);
    }
    Ok(kinematics)
}

/// The drive reconstruction a `[data] drive` value asks for.
fn drive_smoothing(raw: &RawDrive) -> Result<DriveSmoothing, String> {
    match raw {
        RawDrive::Named(name) => match name.as_str() {
            "auto" => Ok(DriveSmoothing::Auto),
            "samples" => Ok(DriveSmoothing::Samples(PolyFilter::paper_omega())),
            "zoh" => Ok(DriveSmoothing::Held),
            other => Err(format!(
                "unknown drive reconstruction `{other}`; known: auto, samples, zoh, or {{ order, window }}"
            )),
        },
        RawDrive::Filter(spec) => PolyFilter::new(spec.order, spec.window)
            .map(DriveSmoothing::Filter)
            .map_err(|e| e.to_string()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::experiment::parse_exp as parse;

    #[test]
    fn the_drive_reconstruction_is_a_setting() {
        let e = parse("[data]\nfile = \"r.csv\"\ndrive = \"samples\"\n").unwrap();
        assert!(matches!(e.kinematics.drive, DriveSmoothing::Samples(_)));
        let e = parse("[data]\nfile = \"r.csv\"\ndrive = \"zoh\"\n").unwrap();
        assert_eq!(e.kinematics.drive, DriveSmoothing::Held);
        let e = parse("[data]\nfile = \"r.csv\"\ndrive = { order = 2, window = 101 }\n").unwrap();
        assert!(matches!(e.kinematics.drive, DriveSmoothing::Filter(f) if f.window() == 101));
        let e = parse("[data]\nfile = \"r.csv\"\n").unwrap();
        assert_eq!(e.kinematics.drive, DriveSmoothing::Auto);
        for (text, says) in [
            (
                "[data]\nfile = \"r.csv\"\ndrive = \"smooth\"\n",
                "known: auto, samples, zoh, or { order, window }",
            ),
            (
                "[data]\nfile = \"r.csv\"\ndrive = \"auto\"\n[filter]\nomega = { order = 2, window = 9 }\n",
                "not both",
            ),
        ] {
            let msg = format!("{:#}", parse(text).unwrap_err());
            assert!(
                msg.starts_with("exp.toml:1: `data.drive`: ") && msg.contains(says),
                "{msg}"
            );
        }
    }

    #[test]
    fn the_boundary_applies_to_every_filter_and_an_unknown_one_lists_both() {
        let e =
            parse("[filter]\nboundary = \"zero\"\nmotion = { order = 3, window = 21 }\n").unwrap();
        assert_eq!(e.kinematics.boundary, Boundary::Zero);
        let motion = e.kinematics.motion.unwrap();
        assert_eq!(motion.boundary_handling(), Boundary::Zero);
        assert_eq!(motion.window(), 21);
        let e = parse("[filter]\npaper = true\nboundary = \"zero\"\n").unwrap();
        if let DriveSmoothing::Samples(f) = e.kinematics.drive {
            assert_eq!(f.boundary_handling(), Boundary::Zero);
        }
        let msg = format!(
            "{:#}",
            parse("[filter]\nboundary = \"edge\"\n").unwrap_err()
        );
        assert!(
            msg.starts_with("exp.toml:2: `filter.boundary`: unknown value `edge`")
                && msg.contains("one of: shifted, zero"),
            "{msg}"
        );
        let msg = format!(
            "{:#}",
            parse("[filter]\nmotion = { order = 3, window = 3 }\n").unwrap_err()
        );
        assert!(msg.starts_with("exp.toml:1: `filter.motion`: "), "{msg}");
    }
}
