//! The `[output]` section of an experiment file: what the commands write besides their JSON
//! (`report = false`: no figures, report.html or report.md).

use serde::Deserialize;

/// What the commands write besides their JSON: `[output]` as written, the defaults where it
/// or a key is absent.
#[derive(Clone, Debug, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct OutputSpec {
    /// Figures (SVG, PNG, CSV), report.html and report.md.
    pub report: bool,
}

impl Default for OutputSpec {
    fn default() -> OutputSpec {
        OutputSpec { report: true }
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
