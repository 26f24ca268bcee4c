//! The one temporary-name pattern. Everything this program puts beside an output before it
//! is in place — a file being written, a staged file or folder, old results moved aside in a
//! swap, the list of a commit's renames — is named `.<name>.<role>-<pid>-<n>`: the target's
//! name, the [`Role`], the writing process's id and a counter unique within the process. A
//! later run into the same output recognises these names (and only these) as left by a run
//! that was killed, and repairs or removes them under the output's lock.
//!
//! Earlier versions of the program used other names for their temporaries
//! (`.<stem>.<pid>-<n>.tmp.<ext>`, `.<name>.<pid>.tmp`, `.<name>.<random>.log.tmp`, and the
//! role names without `-<n>`); [`is_temporary_name`] still recognises them so that what an
//! older run left is cleaned too. Nothing is written under those names any more.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

static COUNTER: AtomicU64 = AtomicU64::new(0);

/// What a temporary is for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// New content being written or staged, not yet in place.
    New,
    /// Old results moved aside while new ones are swapped in.
    Old,
    /// The list of renames of a commit under way ([`super::staged_files`]).
    Commit,
}

impl Role {
    fn tag(self) -> &'static str {
        match self {
            Role::New => "new",
            Role::Old => "old",
            Role::Commit => "commit",
        }
    }
}

/// A temporary's name, read back: whose it is, its role and the process that made it.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Temporary {
    /// The name of the output it belongs to.
    pub of: String,
    /// What it is for.
    pub role: Role,
    /// The process that made it.
    pub pid: u32,
}

/// The file name of `target` (`output` if it has none).
pub fn file_name(target: &Path) -> String {
    target
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "output".into())
}

/// A fresh temporary path beside `target` for `role`: `.<name>.<role>-<pid>-<n>`.
pub fn temporary(target: &Path, role: Role) -> PathBuf {
    let n = COUNTER.fetch_add(1, Ordering::Relaxed);
    let name = file_name(target);
    target.with_file_name(format!(".{name}.{}-{}-{n}", role.tag(), std::process::id()))
}

/// A path beside `target` named `.<name>.<tag>` (its lock file).
pub fn sibling(target: &Path, tag: &str) -> PathBuf {
    target.with_file_name(format!(".{}.{tag}", file_name(target)))
}

fn digits(s: &str) -> bool {
    !s.is_empty() && s.bytes().all(|b| b.is_ascii_digit())
}

/// Read `entry` (a file name) as a temporary of this program's pattern
/// (`.<name>.<role>-<pid>-<n>`, or an older version's `.<name>.<role>-<pid>`).
pub fn parse(entry: &str) -> Option<Temporary> {
    let rest = entry.strip_prefix('.')?;
    let (of, tail) = rest.rsplit_once('.')?;
    let (tag, ids) = tail.split_once('-')?;
    let role = [Role::New, Role::Old, Role::Commit]
        .into_iter()
        .find(|r| r.tag() == tag)?;
    let (pid, n) = ids.split_once('-').unwrap_or((ids, "0"));
    if of.is_empty() || !digits(pid) || !digits(n) {
        return None;
    }
    Some(Temporary {
        of: of.to_string(),
        role,
        pid: pid.parse().ok()?,
    })
}

/// Whether `entry` is a temporary of output `target_name` (any role).
pub fn is_temporary_of(entry: &str, target_name: &str) -> bool {
    // A temporary of a staged file (`..<name>.new-…`) is one of the target's too.
    parse(entry).is_some_and(|t| t.of == target_name || is_temporary_of(&t.of, target_name))
        || older_temporary_of(entry).is_some_and(|of| of == target_name)
}

/// Whether `entry` is one of this program's temporaries, of this version's pattern or an
/// older version's: left only by a run that was killed.
pub fn is_temporary_name(entry: &str) -> bool {
    parse(entry).is_some() || older_temporary_of(entry).is_some()
}

/// The target name of an older version's per-file temporary: `.<stem>.<pid>-<n>.tmp[.ext]`
/// (its target `<stem>[.ext]`), `.<name>.<pid>.tmp` (the record writer's) or
/// `.<name>.<six characters>.log.tmp` (a campaign log's).
fn older_temporary_of(entry: &str) -> Option<String> {
    let rest = entry.strip_prefix('.')?;
    if let Some(base) = rest.strip_suffix(".log.tmp") {
        let (unit, random) = base.rsplit_once('.')?;
        let ok = random.len() == 6 && random.bytes().all(|b| b.is_ascii_alphanumeric());
        return (ok && !unit.is_empty()).then(|| format!("{unit}.log"));
    }
    let (base, ext) = rest.rsplit_once(".tmp")?;
    let one_ext = ext.is_empty() || ext.strip_prefix('.').is_some_and(|e| !e.contains('.'));
    let (stem, id) = base.rsplit_once('.')?;
    let id_ok = match id.split_once('-') {
        Some((pid, n)) => digits(pid) && digits(n),
        None => digits(id),
    };
    (one_ext && id_ok && !stem.is_empty()).then(|| format!("{stem}{ext}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_temporary_reads_back_as_what_it_is() {
        let t = temporary(Path::new("out/rec.csv"), Role::New);
        assert_eq!(t.parent(), Some(Path::new("out")));
        let name = t.file_name().unwrap().to_string_lossy().into_owned();
        assert!(name.starts_with(".rec.csv.new-"), "{name}");
        let parsed = parse(&name).unwrap();
        assert_eq!(
            (parsed.of.as_str(), parsed.role, parsed.pid),
            ("rec.csv", Role::New, std::process::id())
        );
        assert_ne!(t, temporary(Path::new("out/rec.csv"), Role::New));
        let old = temporary(Path::new("fit"), Role::Old);
        assert_eq!(
            parse(&old.to_string_lossy()).unwrap().role,
            Role::Old,
            "{old:?}"
        );
    }

    #[test]
    fn recognises_its_own_and_older_temporaries_only() {
        for (ours, of) in [
            (".fit.new-12-3", "fit"),
            (".fit.old-999999", "fit"),
            (".rec.csv.commit-4-0", "rec.csv"),
            (".fitted.123-4.tmp.csv", "fitted.csv"),
            (".fit.9-0.tmp.json", "fit.json"),
            (".rec.csv.77.tmp", "rec.csv"),
            (".001-a1_c1.Ab3xYz.log.tmp", "001-a1_c1.log"),
        ] {
            assert!(is_temporary_name(ours), "{ours}");
            assert!(is_temporary_of(ours, of), "{ours} of {of}");
        }
        for not_ours in [
            "fitted.csv",
            ".fitted.tmp.csv",
            ".x.12-a.tmp.csv",
            ".notes.tmp",
            ".a.1.tmp.b.c",
            ".fit.new-x",
            ".fit.older-1",
            "fit.new-1",
            ".fit.lock",
            ".notes.log.tmp",
        ] {
            assert!(!is_temporary_name(not_ours), "{not_ours}");
        }
        assert!(!is_temporary_of(".fits.new-1-0", "fit"));
        assert!(is_temporary_of("..rec.csv.new-1-0.new-1-1", "rec.csv"));
        assert!(!is_temporary_of(".rec.json.new-1-0", "rec.csv"));
    }
}
