//! Names a person typed (a key, a model, a column, a file) matched against the names that
//! exist, for a "did you mean" in the error that refuses them: the closest known name by
//! edit distance (a swapped pair of letters counts once), if it is close enough to be a typo.
//!
//! ```
//! use stf_core::names::{closest, did_you_mean};
//! assert_eq!(closest("power_lw", ["viscous", "power_law"]), Some("power_law"));
//! assert_eq!(did_you_mean("stifnes", ["m", "k", "stiffness"]), " (did you mean `stiffness`?)");
//! assert_eq!(did_you_mean("zzz", ["m", "k"]), "");
//! ```

/// The known name closest to `typed`, if it is within a typo of it: the same but for case,
/// or at most one edit in three letters (at least one edit).
pub fn closest<'a>(typed: &str, known: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let lower = typed.to_lowercase();
    let most = (typed.chars().count() / 3).max(1);
    let mut best: Option<(usize, &str)> = None;
    for name in known {
        if name == typed {
            continue;
        }
        let d = if name.to_lowercase() == lower {
            0
        } else {
            strsim::damerau_levenshtein(&lower, &name.to_lowercase())
        };
        if d <= most && best.is_none_or(|(b, _)| d < b) {
            best = Some((d, name));
        }
    }
    best.map(|(_, name)| name)
}

/// ` (did you mean `NAME`?)` for the [`closest`] known name, or nothing.
pub fn did_you_mean<'a>(typed: &str, known: impl IntoIterator<Item = &'a str>) -> String {
    closest(typed, known).map_or_else(String::new, |n| format!(" (did you mean `{n}`?)"))
}

/// ` (did you mean `DIR/NAME`?)` for a file of `path`'s folder whose name is a typo away
/// from `path`'s, or nothing (also when the folder cannot be read). At most 10 000 entries
/// of the folder are looked at.
pub fn nearby_file(path: &std::path::Path) -> String {
    let (Some(name), dir) = (path.file_name().and_then(|n| n.to_str()), path.parent()) else {
        return String::new();
    };
    let dir = match dir {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => std::path::Path::new("."),
    };
    let Ok(entries) = std::fs::read_dir(dir) else {
        return String::new();
    };
    let names: Vec<String> = entries
        .take(10_000)
        .filter_map(|e| e.ok()?.file_name().into_string().ok())
        .collect();
    closest(name, names.iter().map(String::as_str)).map_or_else(String::new, |n| {
        format!(" (did you mean `{}`?)", path.with_file_name(n).display())
    })
}

#[cfg(test)]
#[allow(clippy::unwrap_used)] // tests may unwrap
mod tests {
    use super::*;

    #[test]
    fn typos_are_matched_and_strangers_are_not() {
        let keys = ["m", "k", "c", "T", "delta_T", "F0", "eta"];
        assert_eq!(closest("f0", keys), Some("F0"));
        assert_eq!(closest("delta_t", keys), Some("delta_T"));
        assert_eq!(closest("detla_T", keys), Some("delta_T"));
        assert_eq!(closest("stiffness", keys), None);
        assert_eq!(
            closest("trajectroy", ["force", "trajectory"]),
            Some("trajectory")
        );
        assert_eq!(closest("x", ["x"]), None);
    }

    #[test]
    fn a_file_a_typo_away_is_suggested() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("sweep_a1.csv"), "").unwrap();
        let hint = nearby_file(&dir.path().join("swep_a1.csv"));
        assert_eq!(
            hint,
            format!(
                " (did you mean `{}`?)",
                dir.path().join("sweep_a1.csv").display()
            )
        );
        assert_eq!(nearby_file(&dir.path().join("other.csv")), "");
        assert_eq!(nearby_file(&dir.path().join("no/such/dir.csv")), "");
    }
}
