//! Errors of loading and checking script models; each names the script and, where known, the
//! line.

use std::fmt;

use thiserror::Error;

/// Where in a script something went wrong: its path and, when known, the line (1-based).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ScriptLocation {
    /// The script's path as given (or the name given to [`crate::ScriptModel::from_source`]).
    pub path: String,
    /// Line, 1-based, when known.
    pub line: Option<usize>,
}

impl ScriptLocation {
    /// `line` (when known) of the script at `path`.
    pub fn new(path: &str, line: Option<usize>) -> Self {
        ScriptLocation {
            path: path.to_string(),
            line,
        }
    }
}

impl fmt::Display for ScriptLocation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.path)?;
        self.line.map_or(Ok(()), |line| write!(f, ":{line}"))
    }
}

/// A script could not be loaded as a force model.
#[derive(Debug, Error)]
pub enum ScriptError {
    /// The file could not be read.
    #[error("{path}: cannot read the script: {error}{did_you_mean}")]
    Read {
        /// The script's path.
        path: String,
        /// ` (did you mean `m.rhai`?)` for a missing script with a file of a close name
        /// beside it, else empty.
        did_you_mean: String,
        /// The I/O error (shown in the message, so not also a `source` that an error chain
        /// would print a second time).
        error: std::io::Error,
    },
    /// The script exceeds a size limit ([`crate::ScriptLimits`]); checked before it is compiled.
    #[error("{path}: the script is too large to load: {message}")]
    TooLarge {
        /// The script's path.
        path: String,
        /// Which limit, with the script's size and the limit.
        message: String,
    },
    /// rhai could not parse the script (syntax, undefined variable, disabled `import`, …).
    #[error("{at}: syntax error: {message}")]
    Syntax {
        /// Where.
        at: ScriptLocation,
        /// rhai's message.
        message: String,
    },
    /// A required function is missing, or a function has the wrong number of arguments.
    #[error("{at}: {message}")]
    Contract {
        /// Where (the function's line when it exists).
        at: ScriptLocation,
        /// What is wrong.
        message: String,
    },
    /// The map returned by `params()` is ill-formed.
    #[error("{at}: bad params(): {message}")]
    Params {
        /// Where (the line of `fn params`).
        at: ScriptLocation,
        /// What is wrong.
        message: String,
    },
    /// A script function failed when the host called it at load time.
    #[error("{at}: {message}")]
    Runtime {
        /// Where.
        at: ScriptLocation,
        /// What went wrong.
        message: String,
    },
    /// A run would take a script longer than its time budget
    /// ([`crate::ScriptLimits::run_seconds`]).
    #[error("{path}: {message}")]
    Budget {
        /// The script's path.
        path: String,
        /// The cost of a call, the calls the run needs and the limit.
        message: String,
    },
    /// A file given as a script (`script = "…"`) that is not one: a folder, or a file whose
    /// name does not end in `.rhai`.
    #[error("{path}: {why}")]
    NotAScript {
        /// The path as given, resolved.
        path: String,
        /// What it is instead, and what to give.
        why: String,
    },
    /// A name is neither a built-in model nor a script path.
    #[error(
        "unknown model `{name}`{did_you_mean}; built-in models: {known}; or give a script path \
         ending in .rhai"
    )]
    UnknownModel {
        /// The name asked for.
        name: String,
        /// ` (did you mean `power_law`?)` when a built-in's name is a typo away, else empty.
        did_you_mean: String,
        /// The known names, comma separated.
        known: String,
    },
}
