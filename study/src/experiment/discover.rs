//! The `[discover]` section of an experiment file: the base model, the candidate effects,
//! how many may be added, the held-out cycles, the scouting threshold, the fit level and
//! whether earlier effects are re-checked and accepted models polished.
//! Every key's shape is its serde type, so the section is read as it is checked; the
//! base `a + b` is split into its terms as it is read ([`base_terms`]), once.

use serde::{Deserialize, Deserializer};

use super::FitLevel;

/// A checked `[discover]` section: every key's shape is its serde type.
#[derive(Clone, Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DiscoverSpec {
    /// The base model's terms, in order: names or script paths (`base = "a + b"` as written;
    /// `none` is the zero force).
    #[serde(deserialize_with = "base_terms")]
    pub base: Vec<String>,
    /// Candidate effects (default: the vocabulary of docs/ARCHITECTURE.md §5).
    pub candidates: Option<Vec<String>>,
    /// At most this many effects are added.
    pub max_effects: Option<usize>,
    /// Every k-th cycle is held out for scoring (k ≥ 2).
    #[serde(default, deserialize_with = "super::counts::holdout")]
    pub holdout_every: Option<usize>,
    /// `force` or `trajectory`; `None`: as `[fit] level`, else force when the record has
    /// `f_stf`.
    pub level: Option<FitLevel>,
    /// Records of at least this many samples are scouted at trajectory level (0: never).
    pub scout_from: Option<usize>,
    /// Re-check earlier effects after each acceptance; `None`: the level's default (on at
    /// force level, off at trajectory level).
    pub recheck: Option<bool>,
    /// Polish an accepted model before the next step; `None`: the level's default (off at
    /// force level, on at trajectory level).
    pub polish: Option<bool>,
    /// Line of `[discover]` in the file (1-based; 0 for settings built in code).
    #[serde(skip)]
    pub line: usize,
}

/// `base = "a + b + …"` as its terms, trimmed; an empty term is an error.
fn base_terms<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<String>, D::Error> {
    let text = String::deserialize(d)?;
    let terms: Vec<String> = text.split('+').map(|t| t.trim().to_string()).collect();
    if terms.iter().any(String::is_empty) {
        return Err(serde::de::Error::custom(format!(
            "`{text}` has an empty term: write model names or script paths joined by ` + `"
        )));
    }
    Ok(terms)
}

impl DiscoverSpec {
    /// The base as shown: its terms joined by ` + `.
    pub fn base_text(&self) -> String {
        self.base.join(" + ")
    }
}

#[cfg(test)]
mod tests {
    use super::super::Experiment;
    use super::*;
    use std::path::Path;

    fn parse(text: &str) -> anyhow::Result<Experiment> {
        Experiment::parse(Path::new("exp.toml"), text)
    }

    #[test]
    fn zero_iterations_or_a_holdout_of_every_cycle_name_the_key() {
        // Both printed a settings struct with no key when the run started.
        let msg = format!("{:#}", parse("[fit]\nmax_iters = 0\n").unwrap_err());
        assert_eq!(
            msg,
            "exp.toml:2: `fit.max_iters`: 0 is not a count of iterations (a whole number, at \
             least 1)"
        );
        let msg = format!(
            "{:#}",
            parse("[discover]\nbase = \"viscous\"\nholdout_every = 0\n").unwrap_err()
        );
        assert_eq!(
            msg,
            "exp.toml:3: `discover.holdout_every`: 0 is not a count of cycles (a whole number, \
             at least 2)"
        );
        let e =
            parse("[fit]\nmax_iters = 1e3\n[discover]\nbase = \"viscous\"\nholdout_every = 4\n")
                .unwrap();
        assert_eq!(e.fit.settings.max_iters, 1000);
        assert_eq!(e.discover.unwrap().holdout_every, Some(4));
    }

    #[test]
    fn the_section_parses_and_an_unknown_level_lists_the_levels() {
        let d = parse(
            "[discover]\nbase = \"viscous\"\ncandidates = [\"yield\"]\nmax_effects = 2\n\
             holdout_every = 4\nlevel = \"trajectory\"\nscout_from = 0\n",
        )
        .unwrap()
        .discover
        .unwrap();
        assert_eq!(d.base, ["viscous"]);
        assert_eq!(d.candidates, Some(vec!["yield".to_string()]));
        assert_eq!(
            (d.max_effects, d.holdout_every, d.scout_from),
            (Some(2), Some(4), Some(0))
        );
        assert_eq!(d.level, Some(FitLevel::Trajectory));
        assert!(parse("").unwrap().discover.is_none());
        let msg = format!(
            "{:#}",
            parse("\n[discover]\nbase = \"viscous\"\nlevel = \"forces\"\n").unwrap_err()
        );
        assert!(
            msg.starts_with("exp.toml:4: `discover.level`: unknown value `forces`")
                && msg.contains("one of: force, trajectory"),
            "{msg}"
        );
    }

    #[test]
    fn recheck_and_polish_are_read_and_default_to_the_level_s_own() {
        let d = parse("[discover]\nbase = \"viscous\"\nrecheck = false\npolish = true\n")
            .unwrap()
            .discover
            .unwrap();
        assert_eq!((d.recheck, d.polish), (Some(false), Some(true)));
        let d = parse("[discover]\nbase = \"viscous\"\n")
            .unwrap()
            .discover
            .unwrap();
        assert_eq!((d.recheck, d.polish), (None, None));
        let msg = format!(
            "{:#}",
            parse("\n[discover]\nbase = \"viscous\"\npolish = \"yes\"\n").unwrap_err()
        );
        assert!(
            msg.starts_with("exp.toml:4: `discover.polish`: expected true or false"),
            "{msg}"
        );
    }

    #[test]
    fn the_base_is_read_as_its_terms_and_an_empty_term_is_an_error() {
        let d = parse("[discover]\nbase = \" power_law +cubic_stiffness \"\n")
            .unwrap()
            .discover
            .unwrap();
        assert_eq!(d.base, ["power_law", "cubic_stiffness"]);
        assert_eq!(d.base_text(), "power_law + cubic_stiffness");
        for bad in ["power_law + ", "", "+ viscous"] {
            let text = format!("\n[discover]\nbase = \"{bad}\"\n");
            let msg = format!("{:#}", parse(&text).unwrap_err());
            assert!(
                msg.starts_with("exp.toml:3: `discover.base`: ") && msg.contains("empty term"),
                "{msg}"
            );
        }
    }
}
