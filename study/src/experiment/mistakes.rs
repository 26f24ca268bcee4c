//! Every mistake of an experiment file in one run, as rustc and cargo report them: the file is
//! read, and each value serde refuses is reported and its lines blanked (newlines kept, so
//! that every later line number stays true), until the rest reads; then each section is
//! checked and every section's error is kept. [`Mistakes`] is the error that holds them all.
//!
//! A syntax error stops the reading (what follows it cannot be trusted to mean what it
//! says); so does a mistake whose lines cannot be blanked without changing the meaning of
//! others, and the [`MOST_REPORTED`]-th.

use std::ops::Range;

use serde::de::DeserializeOwned;

use super::context::{line_of, Ctx};
use super::finite;

/// The most mistakes reported at once: beyond it, the file is likely not an experiment.
pub const MOST_REPORTED: usize = 20;

/// An experiment file's mistakes, each a message `FILE:LINE: `KEY`: …`.
#[derive(Debug, thiserror::Error)]
pub struct Mistakes {
    /// The file.
    pub file: String,
    /// Each mistake's message, in the order found.
    pub messages: Vec<String>,
}

impl std::fmt::Display for Mistakes {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.messages.as_slice() {
            [one] => write!(f, "{one}"),
            all => {
                write!(f, "{} mistakes in {}:", all.len(), self.file)?;
                for m in all {
                    write!(f, "\n  {}", m.replace('\n', "\n    "))?;
                }
                if all.len() >= MOST_REPORTED {
                    write!(f, "\n  (reading stopped after {MOST_REPORTED})")?;
                }
                Ok(())
            }
        }
    }
}

impl Mistakes {
    /// The mistakes `errors` (each shown with its context chain) of `file`, as one error.
    pub fn of(file: &std::path::Path, errors: Vec<anyhow::Error>) -> anyhow::Error {
        let mut messages: Vec<String> = errors.iter().map(|e| format!("{e:#}")).collect();
        // In the file's order, as a reader goes through it.
        let prefix = format!("{}:", file.display());
        messages.sort_by_key(|m| line_in(m, &prefix));
        if messages.len() == 1 {
            // One mistake keeps its own error (and its kind) as it is.
            if let Some(e) = errors.into_iter().next() {
                return e;
            }
        }
        anyhow::Error::new(Mistakes {
            file: file.display().to_string(),
            messages,
        })
    }
}

/// The line a message `FILE:LINE: …` names (0 for none).
fn line_in(message: &str, prefix: &str) -> usize {
    message
        .strip_prefix(prefix)
        .and_then(|rest| rest.split(':').next())
        .and_then(|n| n.parse().ok())
        .unwrap_or(0)
}

/// `text` deserialised as `T`, each value serde or the finite check refuses reported and its
/// lines blanked until the rest reads: the value read (none if reading had to stop), the
/// text it was read from (same lines as `text`) and the mistakes.
pub fn read_all<T: DeserializeOwned>(cx: &Ctx, text: &str) -> Read<T> {
    let mut now = text.to_string();
    let mut errors = Vec::new();
    let mut blanked_keys = Vec::new();
    // A syntax error: nothing after it can be trusted; toml's own message names the place.
    if let Err(e) = toml::de::DeTable::parse(text) {
        errors.push(Ctx::new(cx.file, text).deserialize_error(&e));
        return Read::stopped(now, errors, blanked_keys);
    }
    while errors.len() < MOST_REPORTED {
        if let Some((key, at)) = finite::first_non_finite(&now) {
            errors.push(super::error_at(
                cx.file,
                line_of(&now, at),
                &key,
                "NaN, infinity and numbers beyond a double's range (±1.8e308) are not \
                 accepted: give a finite number",
            ));
            blanked_keys.push(key);
            match blanked(&now, at..at + 1) {
                Some(next) => now = next,
                None => return Read::stopped(now, errors, blanked_keys),
            }
            continue;
        }
        match toml::from_str::<T>(&now) {
            Ok(raw) => {
                return Read {
                    raw: Some(raw),
                    text: now,
                    errors,
                    blanked_keys,
                }
            }
            Err(e) => {
                let error = Ctx::new(cx.file, &now).deserialize_error(&e);
                let key = key_of(&format!("{error:#}"));
                // A key missing because an earlier mistake's line was blanked is no mistake.
                let follows = e.message().starts_with("missing field")
                    && key.as_deref().is_some_and(|k| within(k, &blanked_keys));
                if !follows {
                    errors.push(error);
                }
                blanked_keys.extend(key.map(|k| match typed_key(e.message()) {
                    Some(typed) => format!("{k}.{typed}"),
                    None => k,
                }));
                match e.span().and_then(|span| blanked(&now, span)) {
                    Some(next) => now = next,
                    None => return Read::stopped(now, errors, blanked_keys),
                }
            }
        }
    }
    Read::stopped(now, errors, blanked_keys)
}

/// What [`read_all`] read.
pub struct Read<T> {
    /// The value read; none if reading had to stop.
    pub raw: Option<T>,
    /// The text it was read from: the file's, its mistakes' lines blanked.
    pub text: String,
    /// The mistakes found.
    pub errors: Vec<anyhow::Error>,
    /// The key paths whose lines were blanked.
    pub blanked_keys: Vec<String>,
}

impl<T> Read<T> {
    fn stopped(text: String, errors: Vec<anyhow::Error>, blanked_keys: Vec<String>) -> Self {
        Read {
            raw: None,
            text,
            errors,
            blanked_keys,
        }
    }

    /// Whether `error`, found when the sections were checked, only follows from a blanked
    /// line: it is about a table that held a blanked key (`simulate` once
    /// `simulate.sweep.w0` was taken out).
    pub fn follows(&self, error: &anyhow::Error) -> bool {
        key_of(&format!("{error:#}")).is_some_and(|k| within(&k, &self.blanked_keys))
    }
}

/// Whether the table `key` holds (or is) one of `blanked`.
fn within(key: &str, blanked: &[String]) -> bool {
    blanked.iter().any(|b| {
        b == key
            || b.strip_prefix(key)
                .is_some_and(|rest| rest.starts_with(['.', '[']))
    })
}

/// The key of a message `FILE:LINE: `KEY`: …`.
fn key_of(message: &str) -> Option<String> {
    let (_, rest) = message.split_once(": `")?;
    Some(rest.split_once("`:")?.0.to_string())
}

/// The key an "unknown field `x`" message is about.
fn typed_key(message: &str) -> Option<&str> {
    message
        .strip_prefix("unknown field `")
        .and_then(|rest| rest.split('`').next())
}

/// `text` with the lines of `span` blanked (a table header: its whole table, up to the next
/// header), newlines kept; `None` if that changes nothing or leaves no valid TOML.
fn blanked(text: &str, span: Range<usize>) -> Option<String> {
    let start = text[..span.start.min(text.len())]
        .rfind('\n')
        .map_or(0, |i| i + 1);
    let last = span.end.max(span.start + 1).min(text.len());
    let mut end = text[last.saturating_sub(1)..]
        .find('\n')
        .map_or(text.len(), |i| last.saturating_sub(1) + i);
    if text[start..].trim_start().starts_with('[') {
        // A header: its table goes with it, or its keys would land in the table before.
        let mut at = end;
        while at < text.len() {
            let next = text[at + 1..].find('\n').map_or(text.len(), |i| at + 1 + i);
            if text[(at + 1).min(next)..next].trim_start().starts_with('[') {
                break;
            }
            at = next;
        }
        end = at;
    }
    let blank: String = text[start..end]
        .chars()
        .map(|c| if c == '\n' { '\n' } else { ' ' })
        .collect();
    if blank == text[start..end] {
        return None;
    }
    let next = format!("{}{blank}{}", &text[..start], &text[end..]);
    toml::de::DeTable::parse(&next).is_ok().then_some(next)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_value_s_lines_or_a_table_are_blanked_and_lines_kept() {
        let text = "[system]\nm = 7.65\nk = \"x\"\n\n[sytem]\nc = 1\n[fit]\nlevel = \"force\"\n";
        let at = text.find("\"x\"").unwrap();
        let b = blanked(text, at..at + 3).unwrap();
        assert_eq!(b.lines().count(), text.lines().count());
        assert!(!b.contains("\"x\"") && b.contains("m = 7.65"));
        let at = text.find("[sytem]").unwrap();
        let b = blanked(text, at..at + 7).unwrap();
        assert!(!b.contains("sytem") && !b.contains("c = 1") && b.contains("[fit]"));
        assert_eq!(b.lines().count(), text.lines().count());
    }
}
