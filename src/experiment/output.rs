//! The `[output]` section of an experiment file: what the commands write besides their JSON
//! (`report = false`: no figures, report.html or report.md).

use serde::Deserialize;

/// `[output]` as written.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawOutput {
    report: Option<bool>,
}

/// What the commands write besides their JSON.
#[derive(Clone, Debug)]
pub struct OutputSpec {
    /// Figures (SVG, PNG, CSV), report.html and report.md.
    pub report: bool,
}

impl From<Option<&RawOutput>> for OutputSpec {
    fn from(raw: Option<&RawOutput>) -> OutputSpec {
        OutputSpec {
            report: raw.and_then(|o| o.report).unwrap_or(true),
        }
    }
}

#[cfg(test)]
mod tests {

    #[test]
    fn reports_are_written_unless_turned_off() {
        let parse = |text: &str| crate::experiment::parse_exp(text).unwrap();
        assert!(parse("").output.report);
        assert!(parse("[output]\n").output.report);
        assert!(!parse("[output]\nreport = false\n").output.report);
    }
}
