//! Reading a script's `params()` map into [`ParamSpec`]s.
//!
//! A script declares its parameters as an object map `name => [default, min, max, unit]`,
//! optionally with a fifth element, a one-line doc string, or a `/// doc` line just above the
//! entry. The parameter order is the map's key order as rhai gives it: **sorted by key**
//! (byte order, so upper case before lower case: `K`, `n`, `tau`).

use std::collections::HashMap;

use rhai::Dynamic;
use stf_core::physics::param_spec::ParamSpec;

/// Convert a script number (float or integer) to `f64`.
pub(crate) fn to_f64(value: &Dynamic) -> Option<f64> {
    value
        .as_float()
        .ok()
        .or_else(|| value.as_int().ok().map(|i| i as f64))
}

/// Parse the value returned by `params()`; `docs` holds `/// doc` lines found in the source.
pub(crate) fn parse_params(
    value: Dynamic,
    docs: &HashMap<String, String>,
) -> Result<Vec<ParamSpec>, String> {
    let type_name = value.type_name();
    let Some(map) = value.try_cast::<rhai::Map>() else {
        return Err(format!(
            "must return an object map #{{ name: [default, min, max, unit] }}, not {type_name}"
        ));
    };
    map.into_iter()
        .map(|(name, entry)| parse_entry(&name, entry, docs))
        .collect()
}

fn parse_entry(
    name: &str,
    entry: Dynamic,
    docs: &HashMap<String, String>,
) -> Result<ParamSpec, String> {
    let shape = "must be [default, min, max, unit] or [default, min, max, unit, doc]";
    let Some(items) = entry.try_cast::<rhai::Array>() else {
        return Err(format!("`{name}` {shape}"));
    };
    if !(4..=5).contains(&items.len()) {
        return Err(format!("`{name}` has {} elements; {shape}", items.len()));
    }
    // `items` has four or five elements (checked above).
    let number = |i: usize, what: &str| {
        let item = &items[i];
        to_f64(item).filter(|v| !v.is_nan()).ok_or_else(|| {
            format!(
                "`{name}`: {what} must be a number, not {}",
                item.type_name()
            )
        })
    };
    let (default, min, max) = (number(0, "default")?, number(1, "min")?, number(2, "max")?);
    if !(min <= default && default <= max) {
        return Err(format!(
            "`{name}`: need min <= default <= max, got default {default}, min {min}, max {max}"
        ));
    }
    let text = |i: usize, what: &str| -> Result<String, String> {
        match items.get(i) {
            None => Ok(String::new()),
            Some(item) => item
                .clone()
                .into_string()
                .map_err(|t| format!("`{name}`: {what} must be a string, not {t}")),
        }
    };
    let unit = text(3, "unit")?;
    let mut doc = text(4, "doc")?;
    if doc.is_empty() {
        doc = docs.get(name).cloned().unwrap_or_default();
    }
    Ok(ParamSpec::new(name, &unit, default, min, max, &doc))
}

/// `/// doc` lines written just above an entry `name: [...]` inside `fn params`.
pub(crate) fn param_docs(source: &str, params_line: Option<usize>) -> HashMap<String, String> {
    let mut docs = HashMap::new();
    let Some(start) = params_line else {
        return docs;
    };
    let mut pending: Option<String> = None;
    for line in source.lines().skip(start) {
        let line = line.trim();
        if line.starts_with("fn ") {
            break;
        }
        if let Some(doc) = line.strip_prefix("///") {
            pending = Some(doc.trim().to_string());
            continue;
        }
        let key: String = line
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect();
        if let (Some(doc), false) = (pending.take(), key.is_empty()) {
            if line[key.len()..].trim_start().starts_with(':') {
                docs.insert(key, doc);
            }
        }
    }
    docs
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;

    fn parse(src: &str) -> Result<Vec<ParamSpec>, String> {
        let engine = rhai::Engine::new();
        let value: Dynamic = engine.eval(src).unwrap();
        parse_params(value, &HashMap::new())
    }

    #[test]
    fn entries_are_sorted_by_key_and_integers_accepted() {
        let specs =
            parse(r#"#{ n: [2, 1, 4, ""], K: [5.0, 0.0, 1e3, "N", "consistency"] }"#).unwrap();
        assert_eq!(specs[0].name, "K");
        assert_eq!(specs[0].doc, "consistency");
        assert_eq!(specs[1].name, "n");
        assert_eq!(
            (specs[1].default, specs[1].min, specs[1].max),
            (2.0, 1.0, 4.0)
        );
    }

    #[test]
    fn ill_formed_entries_are_rejected() {
        assert!(parse(r#"#{ K: [5.0, 6.0, 1e3, "N"] }"#)
            .unwrap_err()
            .contains("min <= default"));
        assert!(parse(r#"#{ K: ["a", 0.0, 1e3, "N"] }"#)
            .unwrap_err()
            .contains("default must be a number"));
        assert!(parse(r#"#{ K: [5.0, 0.0, 1e3] }"#)
            .unwrap_err()
            .contains("3 elements"));
        assert!(parse(r#"#{ K: [5.0, 0.0, 1e3, 4] }"#)
            .unwrap_err()
            .contains("unit must be a string"));
        assert!(parse("[1, 2]").unwrap_err().contains("object map"));
    }

    #[test]
    fn doc_lines_above_entries_are_found() {
        let src = "fn params() { #{\n  /// consistency\n  K: [1.0, 0.0, 2.0, \"\"],\n  n: [1.0, 0.0, 2.0, \"\"] } }\nfn force(p, t, x, v, z) { 0.0 }";
        let docs = param_docs(src, Some(1));
        assert_eq!(docs.get("K").map(String::as_str), Some("consistency"));
        assert!(!docs.contains_key("n"));
    }
}
