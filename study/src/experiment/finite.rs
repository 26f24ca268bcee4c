//! Every number in an experiment file is finite: TOML accepts `nan`, `inf` and `-inf` (and
//! `1e400` overflows to infinity), which no key of an experiment means, and which would fail
//! later, far from the file (a simulation that cannot start, a fit that never moves), without
//! naming the key. One walk over the parsed document, before its sections are read, refuses
//! the first such value with the file, its line and its key path (`simulate.sweep.w0`,
//! `simulate.profile.omega[3]`, `models[0].params.K.value`).

use toml::de::{DeTable, DeValue};
use toml::Spanned;

/// The key path and byte offset of the first number in `text` that is NaN or infinite;
/// `None` if there is none (or if the text is not TOML: its parser reports that).
pub(super) fn first_non_finite(text: &str) -> Option<(String, usize)> {
    let doc = DeTable::parse(text).ok()?;
    table(doc.get_ref(), "")
}

fn table(t: &DeTable<'_>, prefix: &str) -> Option<(String, usize)> {
    t.iter().find_map(|(key, value)| {
        let path = if prefix.is_empty() {
            key.get_ref().to_string()
        } else {
            format!("{prefix}.{}", key.get_ref())
        };
        self::value(value, &path)
    })
}

fn value(v: &Spanned<DeValue<'_>>, path: &str) -> Option<(String, usize)> {
    match v.get_ref() {
        DeValue::Float(f) => {
            let text = f.as_str();
            let finite = !text.contains("nan")
                && !text.contains("inf")
                && text.parse::<f64>().is_ok_and(f64::is_finite);
            (!finite).then(|| (path.to_string(), v.span().start))
        }
        DeValue::Table(t) => table(t, path),
        DeValue::Array(items) => items
            .iter()
            .enumerate()
            .find_map(|(i, item)| value(item, &format!("{path}[{i}]"))),
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_nan_and_inf_with_their_key_path() {
        let text = "[simulate]\nprofile = { t = [0.0, 1.0], omega = [1.0, -inf] }\n";
        assert_eq!(
            first_non_finite(text).map(|(k, _)| k).as_deref(),
            Some("simulate.profile.omega[1]")
        );
        let text = "[[models]]\nname = \"a\"\n[[models]]\nparams = { K = { value = nan } }\n";
        assert_eq!(
            first_non_finite(text).map(|(k, _)| k).as_deref(),
            Some("models[1].params.K.value")
        );
        assert_eq!(
            first_non_finite("x = 1e400\n").map(|(k, _)| k).as_deref(),
            Some("x")
        );
        assert_eq!(
            first_non_finite("x = 1.5\ny = [1, 2.0]\ns = \"inf\"\n"),
            None
        );
    }
}

#[cfg(test)]
mod refused_at_parse {

    /// The parse error of `text` (it must fail).
    fn error(text: &str) -> String {
        format!("{:#}", crate::experiment::parse_exp(text).unwrap_err())
    }

    #[test]
    fn nan_or_inf_in_any_number_is_refused_with_line_and_key() {
        let cases = [
            ("[simulate]\nrate = 100.0\n\nsweep = { w0 = nan, alpha = 0.047, t0 = 0.0, t1 = 9.0 }\n", 4, "simulate.sweep.w0"),
            ("[simulate]\nrate = 100.0\n\nsweep = { w0 = 2.0, alpha = inf, t0 = 0.0, t1 = 9.0 }\n", 4, "simulate.sweep.alpha"),
            ("[simulate]\n\nconstant = { omega = -inf, t1 = 3.0 }\n", 3, "simulate.constant.omega"),
            ("[simulate]\nprofile = { t = [0.0, 1.0, 2.0], omega = [1.0, nan, 2.0] }\n", 2, "simulate.profile.omega[1]"),
            ("[simulate]\nconstant = { omega = 6.0, t1 = 3.0 }\n\nx0 = nan\n", 4, "simulate.x0"),
            ("[simulate]\nconstant = { omega = 6.0, t1 = 3.0 }\nv0 = 1e999\n", 3, "simulate.v0"),
            ("[system]\n\nk = inf\n", 3, "system.k"),
            ("[[models]]\nname = \"power_law\"\nparams = { K = { value = 2.0, max = inf } }\n", 3, "models[0].params.K.max"),
            ("[data]\nfile = \"r.csv\"\nrate = nan\n", 3, "data.rate"),
            ("[data]\nfile = \"r.csv\"\nwindow = [0.0, inf]\n", 3, "data.window[1]"),
            ("[regimes]\nnoise_sigma = nan\n", 2, "regimes.noise_sigma"),
        ];
        for (text, line, key) in cases {
            let msg = error(text);
            assert!(
                msg.starts_with(&format!("exp.toml:{line}: `{key}`:")) && msg.contains("NaN"),
                "{key}: {msg}"
            );
        }
    }
}
