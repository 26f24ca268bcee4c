//! Where an experiment file's errors point: [`Ctx`] holds the file and its text, and every
//! error about a value reads `FILE:LINE: `KEY`: MSG` ([`error_at`]). Errors from serde (an
//! unknown key, a wrong type, an unknown value of a serde enum, which lists the accepted
//! ones) take the same form through [`Ctx::deserialize_error`], with the key path `toml` records
//! (each array of tables' index added) and serde's words in the file's ([`super::plain_words`]).

use std::ops::Range;
use std::path::Path;

/// 1-based line of a byte offset.
pub fn line_of(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].matches('\n').count() + 1
}

/// `FILE:LINE: `KEY`: MSG`, the form of every error about a value in an experiment file.
pub fn error_at(file: &Path, line: usize, key: &str, msg: impl std::fmt::Display) -> anyhow::Error {
    let (key, msg) = (shorten(key), shorten(&msg.to_string()));
    anyhow::anyhow!("{}:{}: `{}`: {}", file.display(), line, key, msg)
}

/// Where [`error_at`] says an error is (`file:line: \`key\``), for a cause kept as it is under
/// it (`anyhow`'s context: the message reads the same, the cause's type is kept).
pub fn place(file: &Path, line: usize, key: &str) -> String {
    format!("{}:{}: `{}`", file.display(), line, shorten(key))
}

/// Longest run of text from a file shown whole in a message (a key, a value, a name).
const SHOWN_WHOLE: usize = 200;

/// `text` with every word longer than `SHOWN_WHOLE` bytes cut to its start and end and its
/// size, so that a 5 MB key is not echoed whole.
pub fn shorten(text: &str) -> String {
    if text.len() <= SHOWN_WHOLE {
        return text.to_string();
    }
    let mut out = String::new();
    let mut rest = text;
    while let Some(start) = rest.find(|c: char| !c.is_whitespace()) {
        out.push_str(&rest[..start]);
        rest = &rest[start..];
        let end = rest.find(char::is_whitespace).unwrap_or(rest.len());
        let word = &rest[..end];
        if word.len() > SHOWN_WHOLE {
            let head = floor_char(word, 40);
            let tail = &word[ceil_char(word, word.len() - 20)..];
            out.push_str(&format!("{head}…({} bytes)…{tail}", word.len()));
        } else {
            out.push_str(word);
        }
        rest = &rest[end..];
    }
    out.push_str(rest);
    out
}

/// The largest char boundary of `s` at or below `i`.
fn floor_char(s: &str, i: usize) -> &str {
    let mut i = i.min(s.len());
    while !s.is_char_boundary(i) {
        i -= 1;
    }
    &s[..i]
}

/// The smallest char boundary of `s` at or above `i`.
fn ceil_char(s: &str, i: usize) -> usize {
    let mut i = i.min(s.len());
    while !s.is_char_boundary(i) {
        i += 1;
    }
    i
}

/// Where errors point: the experiment file and its text.
pub struct Ctx<'a> {
    pub(super) file: &'a Path,
    pub(super) text: &'a str,
}

impl<'a> Ctx<'a> {
    /// Errors about `text`, the contents of `file` (another TOML file read the same way, such
    /// as a campaign file).
    pub fn new(file: &'a Path, text: &'a str) -> Self {
        Ctx { file, text }
    }

    /// The 1-based line of a byte offset.
    pub fn line(&self, offset: usize) -> usize {
        line_of(self.text, offset)
    }

    /// An error at `span`'s line, about `key`.
    pub fn at(&self, span: Range<usize>, key: &str, msg: impl std::fmt::Display) -> anyhow::Error {
        error_at(self.file, line_of(self.text, span.start), key, msg)
    }

    /// Nothing when `holds`, else the error [`Ctx::at`] gives: the shape of every range check.
    pub fn ensure(
        &self,
        holds: bool,
        span: Range<usize>,
        key: &str,
        msg: impl std::fmt::Display,
    ) -> anyhow::Result<()> {
        if holds {
            Ok(())
        } else {
            Err(self.at(span, key, msg))
        }
    }

    /// A whole count read from a number: at least `least` and within `u64`, else the error
    /// [`Ctx::at`] gives, "V is not a WHAT (at least LEAST)".
    pub fn count(
        &self,
        value: &toml::Spanned<f64>,
        key: &str,
        least: u64,
        what: &str,
    ) -> anyhow::Result<u64> {
        let v = *value.get_ref();
        let msg = format!(
            "{} is not a {what} (at least {least})",
            crate::digits::shown(v)
        );
        self.ensure(
            v >= least as f64 && v <= u64::MAX as f64,
            value.span(),
            key,
            msg,
        )?;
        Ok(v as u64)
    }

    /// A deserialisation error of the file's text: its line, the key path of the value it is
    /// about (none for a key unknown at the top level) and serde's message.
    pub fn deserialize_error(&self, e: &toml::de::Error) -> anyhow::Error {
        let msg = e.message().trim_end();
        // toml gives no place for some errors (nesting too deep): then no line is named.
        let Some(span) = e.span() else {
            let hint = if msg.contains("recursion") {
                " (keys or tables nested too deeply)"
            } else {
                ""
            };
            return anyhow::anyhow!("{}: {}{hint}", self.file.display(), shorten(msg));
        };
        let line = line_of(self.text, span.start);
        let written = self.text.get(span.clone()).unwrap_or_default();
        let msg = &super::plain_words::plain(msg, written);
        match key_path(e) {
            Some(key) => error_at(self.file, line, &indexed(self.text, &key, span.start), msg),
            None => anyhow::anyhow!("{}:{}: {}", self.file.display(), line, shorten(msg)),
        }
    }
}

/// `path` with the index of each array of tables it passes through (`models[1].params.K`
/// for toml's `models.params.K`): the item of the array that starts last before `offset`.
fn indexed(text: &str, path: &str, offset: usize) -> String {
    use toml::de::{DeTable, DeValue};
    let Ok(doc) = DeTable::parse(text) else {
        return path.to_string();
    };
    let mut table = doc.get_ref();
    let mut out = Vec::new();
    let mut parts = path.split('.');
    while let Some(part) = parts.next() {
        let found = table.iter().find(|(k, _)| k.get_ref() == part);
        let Some((_, value)) = found else {
            out.push(part.to_string());
            out.extend(parts.map(str::to_string));
            break;
        };
        match value.get_ref() {
            DeValue::Array(items) => {
                let at = items
                    .iter()
                    .enumerate()
                    .rfind(|(_, v)| v.span().start <= offset);
                match at {
                    Some((i, v)) if v.get_ref().is_table() => {
                        out.push(format!("{part}[{i}]"));
                        if let DeValue::Table(t) = v.get_ref() {
                            table = t;
                        }
                    }
                    _ => {
                        out.push(part.to_string());
                        out.extend(parts.map(str::to_string));
                        break;
                    }
                }
            }
            DeValue::Table(t) => {
                out.push(part.to_string());
                table = t;
            }
            _ => {
                out.push(part.to_string());
                out.extend(parts.map(str::to_string));
                break;
            }
        }
    }
    out.join(".")
}

/// The dotted key path `toml` records on a deserialisation error (`fit.level`; a table's
/// path for a key unknown in it). `toml` shows it, and has no getter for it, only in its
/// message without the input's excerpt: `MESSAGE\nin `PATH``.
fn key_path(e: &toml::de::Error) -> Option<String> {
    let mut bare = e.clone();
    bare.set_input(None);
    let shown = bare.to_string();
    let rest = shown.strip_prefix(e.message())?.trim();
    let path = rest.strip_prefix("in `")?.strip_suffix('`')?;
    (!path.is_empty()).then(|| path.to_string())
}

#[cfg(test)]
mod tests {

    fn message(text: &str) -> String {
        format!("{:#}", crate::experiment::parse_exp(text).unwrap_err())
    }

    #[test]
    fn a_huge_key_or_value_is_shown_cut_with_its_size() {
        let key = "k".repeat(5_000_000);
        let msg = message(&format!("[system]\n{key} = 1.0\n"));
        assert!(msg.len() < 2_000, "{} bytes", msg.len());
        assert!(msg.starts_with("exp.toml:2: `system`: "), "{}", &msg[..200]);
        // The word shown cut is the key with its quotes.
        assert!(
            msg.contains("unknown key `kkkk") && msg.contains("…(5000002 bytes)…"),
            "{msg}"
        );
        // Short text is shown whole; multibyte text is cut on a character boundary.
        assert_eq!(super::shorten("a `b` c"), "a `b` c");
        let wide = "é".repeat(300);
        assert!(super::shorten(&wide).contains("…(600 bytes)…"));
    }

    #[test]
    fn an_error_without_a_place_names_no_line() {
        // A table header or a dotted key nested too deeply: toml says "recursion limit" with
        // no place, once shown as line 0.
        for deep in [
            format!("[{}a]\n", "a.".repeat(3000)),
            format!("{}a = 1\n", "a.".repeat(3000)),
        ] {
            let msg = message(&deep);
            assert_eq!(
                msg, "exp.toml: recursion limit (keys or tables nested too deeply)",
                "{msg}"
            );
        }
    }

    #[test]
    fn a_serde_error_names_the_line_and_the_key_path() {
        assert_eq!(
            message("[fit]\n\nlevel = \"forc\"\n"),
            "exp.toml:3: `fit.level`: unknown value `forc` (did you mean `force`?) (one of: force, trajectory)"
        );
        assert_eq!(
            message("[system]\nm = 7.65\nk = \"stiff\"\n"),
            "exp.toml:3: `system.k`: expected a number, found the string \"stiff\""
        );
        // A key unknown in a table names the table; at the top level, no key.
        let msg = message("[system]\nm = 7.65\nstifnes = 3.0\n");
        assert!(
            msg.starts_with(
                "exp.toml:3: `system`: unknown key `stifnes` (keys here: preset, m, k,"
            ),
            "{msg}"
        );
        let msg = message("\nsystm = 3.0\n");
        assert!(
            msg.starts_with(
                "exp.toml:2: unknown key `systm` (did you mean `system`?) (keys here: data,"
            ),
            "{msg}"
        );
    }
}
