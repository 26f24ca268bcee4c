//! serde's messages about an experiment or campaign file, said in the file's own words: a
//! "key" and a "value" where serde says "field" and "variant", "a number" where it says
//! `f64`, "a table { … }" where it says "struct" or "map", and no Rust type names ("untagged
//! enum RawParam"). Each message names what was expected, then what was found, and suggests
//! the closest known key or value when one is a typo away
//! ([`stf_core::names::did_you_mean`]).

use stf_core::names::did_you_mean;

/// `msg`, a serde message about the value written as `written` in the file (the text of the
/// error's span), in plain words.
pub fn plain(msg: &str, written: &str) -> String {
    if let Some(rest) = msg.strip_prefix("unknown field ") {
        let (typed, known) = typed_and_known(rest);
        return format!(
            "unknown key `{typed}`{}{}",
            did_you_mean(&typed, known.iter().map(String::as_str)),
            listed("keys here", &known)
        );
    }
    if let Some(rest) = msg.strip_prefix("unknown variant ") {
        let (typed, known) = typed_and_known(rest);
        return format!(
            "unknown value `{typed}`{}{}",
            did_you_mean(&typed, known.iter().map(String::as_str)),
            listed("one of", &known)
        );
    }
    if let Some(rest) = msg.strip_prefix("missing field ") {
        return format!("missing key {rest}");
    }
    if let Some(rest) = msg.strip_prefix("duplicate field ") {
        return format!("the key {rest} is given twice");
    }
    for prefix in ["invalid type: ", "invalid value: "] {
        if let Some(rest) = msg.strip_prefix(prefix) {
            if let Some((found, expected)) = rest.split_once(", expected ") {
                return format!(
                    "expected {}, found {}",
                    expected_words(expected),
                    found_words(found)
                );
            }
        }
    }
    if let Some(rest) = msg.strip_prefix("invalid length ") {
        if let Some((n, expected)) = rest.split_once(", expected ") {
            return format!("expected {}, found {n} values", expected_words(expected));
        }
    }
    if let Some(name) = msg.strip_prefix("data did not match any variant of untagged enum ") {
        return format!(
            "expected {}, found {}",
            untagged_expected(name.trim()),
            written_kind(written)
        );
    }
    msg.to_string()
}

/// The typed name and the known names of "`x`, expected one of `a`, `b`" (or "`a` or `b`",
/// or "there are no fields").
fn typed_and_known(rest: &str) -> (String, Vec<String>) {
    let mut ticks = rest.split('`').skip(1).step_by(2).map(str::to_string);
    let typed = ticks.next().unwrap_or_default();
    (typed, ticks.collect())
}

/// ` (WHAT: a, b, c)`, or nothing for no names.
fn listed(what: &str, names: &[String]) -> String {
    if names.is_empty() {
        " (this table takes no keys)".into()
    } else {
        format!(" ({what}: {})", names.join(", "))
    }
}

/// What serde says it expected, in the file's words.
fn expected_words(expected: &str) -> String {
    let e = expected.trim();
    match e {
        "f64" | "f32" | "a float" | "a floating point number" => "a number".into(),
        "u8" | "u16" | "u32" | "u64" | "usize" | "i8" | "i16" | "i32" | "i64" | "isize"
        | "an integer" => "a whole number".into(),
        "a boolean" | "bool" => "true or false".into(),
        "a string" | "a borrowed string" | "a character" | "char" => "a string (in quotes)".into(),
        "a sequence" => "a list [ … ]".into(),
        "a map" | "map" => "a table { … }".into(),
        _ if e.starts_with("struct ") => "a table { … }".into(),
        _ if e.starts_with("tuple of ") || e.starts_with("an array of length") => {
            format!(
                "a list of {}",
                e.trim_start_matches("tuple of ")
                    .trim_start_matches("an array of length ")
            )
        }
        _ if e.starts_with("enum ") => "one of its names, in quotes".into(),
        _ => e.to_string(),
    }
}

/// What serde says it found, in the file's words.
fn found_words(found: &str) -> String {
    let f = found.trim();
    let quoted = |s: &str| s.trim_matches('`').to_string();
    if let Some(s) = f.strip_prefix("string ") {
        format!("the string {s}")
    } else if let Some(s) = f.strip_prefix("floating point ") {
        format!("the number {}", quoted(s))
    } else if let Some(s) = f.strip_prefix("integer ") {
        format!("the number {}", quoted(s))
    } else if let Some(s) = f.strip_prefix("boolean ") {
        quoted(s)
    } else {
        match f {
            "map" => "a table".into(),
            "sequence" => "a list".into(),
            "unit value" => "nothing".into(),
            _ => f.to_string(),
        }
    }
}

/// What an untagged enum of the experiment's raw types accepts, by its name.
fn untagged_expected(name: &str) -> &'static str {
    match name {
        "RawParam" => "a number or a table { value, min, max, fixed }",
        "RawDrive" => {
            "a filter's name in quotes (\"auto\", \"none\", …) or a table { order, window }"
        }
        _ => "a value of another shape",
    }
}

/// What a value written as `written` is: a string, a table, a list, true or false, a number.
fn written_kind(written: &str) -> String {
    let w = written.trim_start();
    match w.chars().next() {
        Some('"') | Some('\'') => format!("the string {}", first_line(w)),
        Some('{') => "a table".into(),
        Some('[') => "a list".into(),
        _ if w.starts_with("true") || w.starts_with("false") => "true or false".into(),
        Some(_) => format!("`{}`", first_line(w)),
        None => "nothing".into(),
    }
}

/// The first line of `text`, at most 60 characters.
fn first_line(text: &str) -> String {
    let line = text.lines().next().unwrap_or_default();
    line.chars().take(60).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn serde_s_words_become_the_file_s() {
        assert_eq!(
            plain("invalid type: string \"stiff\", expected f64", "\"stiff\""),
            "expected a number, found the string \"stiff\""
        );
        assert_eq!(
            plain("invalid type: floating point `1.5`, expected usize", "1.5"),
            "expected a whole number, found the number 1.5"
        );
        assert_eq!(
            plain(
                "data did not match any variant of untagged enum RawParam",
                "\"big\""
            ),
            "expected a number or a table { value, min, max, fixed }, found the string \"big\""
        );
        assert_eq!(
            plain(
                "unknown variant `forc`, expected `force` or `trajectory`",
                "\"forc\""
            ),
            "unknown value `forc` (did you mean `force`?) (one of: force, trajectory)"
        );
        assert_eq!(
            plain(
                "unknown field `stifnes`, expected one of `preset`, `m`, `k`, `stiffness_k`",
                "stifnes"
            ),
            "unknown key `stifnes` (keys here: preset, m, k, stiffness_k)"
        );
        assert_eq!(
            plain(
                "unknown field `prams`, expected `name` or `params`",
                "prams"
            ),
            "unknown key `prams` (did you mean `params`?) (keys here: name, params)"
        );
        assert_eq!(plain("missing field `base`", ""), "missing key `base`");
        assert_eq!(
            plain("invalid type: map, expected a sequence", "{"),
            "expected a list [ … ], found a table"
        );
    }
}
