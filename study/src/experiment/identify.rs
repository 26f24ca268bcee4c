//! `[[identify]]` stages of an experiment file: an oscillator identification in steps, each
//! on its record (`data`, relative to the file), from a `preset` if given, with the listed
//! oscillator parameters `free` and others `set` (and held) before it.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use anyhow::Result;
use serde::Deserialize;
use stf_core::physics::oscillator_params::{OscParam, OscillatorParams};
use toml::Spanned;

use super::system::Preset;
use super::Ctx;

/// One `[[identify]]` stage as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawStage {
    data: String,
    preset: Option<Preset>,
    free: Vec<String>,
    #[serde(default)]
    set: BTreeMap<String, f64>,
}

/// One stage of an oscillator identification (`[[identify]]`).
#[derive(Clone, Debug)]
pub struct StageSpec {
    /// The record, resolved.
    pub data: PathBuf,
    /// Start values replaced by a preset before this stage.
    pub preset: Option<OscillatorParams>,
    /// Oscillator parameters fitted in this stage.
    pub free: Vec<OscParam>,
    /// Values set (and held) before this stage.
    pub set: Vec<(OscParam, f64)>,
    /// Line in the file.
    pub line: usize,
}

/// Check the stages: every name in `free` and `set` is an oscillator parameter; records are
/// resolved against `dir`.
pub(super) fn check(stages: &[Spanned<RawStage>], cx: &Ctx, dir: &Path) -> Result<Vec<StageSpec>> {
    stages
        .iter()
        .enumerate()
        .map(|(i, st)| {
            let (span, r) = (st.span(), st.get_ref());
            let bad = |e| cx.at(span.clone(), &format!("identify[{i}]"), e);
            let free = r.free.iter().map(|n| n.parse()).collect::<Result<_, _>>();
            let set = r.set.iter().map(|(n, v)| n.parse().map(|p| (p, *v)));
            Ok(StageSpec {
                data: dir.join(&r.data),
                preset: r.preset.map(Preset::params),
                free: free.map_err(bad)?,
                set: set.collect::<Result<_, _>>().map_err(bad)?,
                line: cx.line(span.start),
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::super::Experiment;
    use super::*;

    fn parse(text: &str) -> anyhow::Result<Experiment> {
        Experiment::parse(Path::new("dir/exp.toml"), text)
    }

    #[test]
    fn stages_parse_with_their_records_presets_and_lines() {
        let e = parse(
            "[[identify]]\ndata = \"free.csv\"\npreset = \"free\"\nfree = [\"k\", \"c\"]\n\n\
             [[identify]]\ndata = \"forced.csv\"\nfree = [\"F0\"]\nset = { T = 0.5 }\n",
        )
        .unwrap();
        let [a, b] = &e.identify[..] else {
            panic!("{:?}", e.identify)
        };
        assert_eq!(a.data, Path::new("dir/free.csv"));
        assert_eq!(a.preset, Some(OscillatorParams::FREE));
        assert_eq!(
            (a.free.as_slice(), a.line),
            (&[OscParam::K, OscParam::C][..], 1)
        );
        assert_eq!(b.preset, None);
        assert_eq!((b.set.as_slice(), b.line), (&[(OscParam::T, 0.5)][..], 6));
    }

    #[test]
    fn a_bad_name_or_preset_names_file_line_key_and_the_known_ones() {
        let stage = "[[identify]]\ndata = \"a.csv\"\nfree = [\"k\"]\n";
        let msg = format!(
            "{:#}",
            parse(&format!("{stage}{stage}set = {{ q = 1.0 }}\n")).unwrap_err()
        );
        assert!(
            msg.starts_with(
                "dir/exp.toml:4: `identify[1]`: `q` is not an oscillator parameter; known: m, k"
            ),
            "{msg}"
        );
        let msg = format!(
            "{:#}",
            parse(&format!("{stage}preset = \"forcd\"\n")).unwrap_err()
        );
        assert!(
            msg.starts_with("dir/exp.toml:4: `identify[0].preset`: unknown value `forcd`")
                && msg.contains("one of: forced, free"),
            "{msg}"
        );
    }
}
