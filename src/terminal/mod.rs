//! What reaches the terminal. Messages quote text from outside — a record's column names and
//! cells, a script's source and names, file names — and a terminal obeys the control
//! characters in what it prints (ESC sequences move the cursor, recolour, retitle, or write
//! over a line with CR). Every line the program prints therefore goes through
//! [`escape_controls`]: control characters other than line feed and tab, and the bidirectional
//! overrides that reorder a line as displayed, are shown as escapes (`\u{1b}`, `\r`).
//!
//! `println!` panics when standard output is a closed pipe (`stf-lab models | head -1`), so the
//! program prints through [`say!`](crate::say) and [`tell!`](crate::tell): a closed pipe ends
//! printing to it quietly while the run goes on (its results are still written). Any other
//! failure to write (a full disk: `> /dev/full`) ends printing too, and is kept
//! ([`output_failure`]) so that the program does not exit 0 with its output lost.

pub mod interrupt;
pub mod progress;

use std::borrow::Cow;
use std::fmt;
use std::io::Write;
use std::sync::atomic::{AtomicBool, Ordering};

static STDOUT_CLOSED: AtomicBool = AtomicBool::new(false);
static STDERR_CLOSED: AtomicBool = AtomicBool::new(false);
static FAILURE: std::sync::Mutex<Option<String>> = std::sync::Mutex::new(None);
static SILENT: AtomicBool = AtomicBool::new(false);

/// Print nothing from now on: for a front end that shows results its own way (the Python
/// package, which calls the campaign in process and reads its table), not on the terminal.
pub fn silence() {
    SILENT.store(true, Ordering::Relaxed);
}

/// Whether `c` must not reach a terminal raw: a control character other than `\n` and `\t`
/// (C0, DEL, C1), or a bidirectional embedding, override or isolate.
fn unsafe_char(c: char) -> bool {
    (c.is_control() && c != '\n' && c != '\t')
        || matches!(c, '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}')
}

/// `text` with its unsafe characters written as escapes: `\r`, `\u{1b}` … (a backslash is
/// kept as it is). Text without any is returned as it is.
pub fn escape_controls(text: &str) -> Cow<'_, str> {
    if !text.chars().any(unsafe_char) {
        return Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 8);
    for c in text.chars() {
        match c {
            '\r' => out.push_str("\\r"),
            c if unsafe_char(c) => out.push_str(&format!("\\u{{{:x}}}", c as u32)),
            c => out.push(c),
        }
    }
    Cow::Owned(out)
}

/// Write one line to `stream` (`name`: what it is, for a failure), escaped, unless it is
/// known closed; a failed write marks it closed, and one that is not a closed pipe is kept.
fn line(mut stream: impl Write, name: &str, closed: &AtomicBool, args: fmt::Arguments) {
    if closed.load(Ordering::Relaxed) || SILENT.load(Ordering::Relaxed) {
        return;
    }
    let text = args.to_string();
    let written = writeln!(stream, "{}", escape_controls(&text)).and_then(|()| stream.flush());
    if let Err(e) = written {
        closed.store(true, Ordering::Relaxed);
        if e.kind() != std::io::ErrorKind::BrokenPipe {
            if let Ok(mut failure) = FAILURE.lock() {
                failure.get_or_insert_with(|| format!("cannot write to {name}: {e}"));
            }
        }
    }
}

/// One line on standard output (use [`say!`](crate::say)).
pub fn say_line(args: fmt::Arguments) {
    line(
        std::io::stdout().lock(),
        "standard output",
        &STDOUT_CLOSED,
        args,
    );
}

/// One line on standard error (use [`tell!`](crate::tell)).
pub fn tell_line(args: fmt::Arguments) {
    line(
        std::io::stderr().lock(),
        "standard error",
        &STDERR_CLOSED,
        args,
    );
}

/// The first failure to print that was not a closed pipe (a full disk, an I/O error): what
/// was printed is incomplete, and the program must not exit 0.
pub fn output_failure() -> Option<String> {
    FAILURE.lock().ok().and_then(|f| f.clone())
}

/// `println!` for the program: escaped, and quiet on a closed pipe.
#[macro_export]
macro_rules! say {
    ($($arg:tt)*) => { $crate::terminal::say_line(format_args!($($arg)*)) };
}

/// `eprintln!` for the program: escaped, and quiet on a closed pipe.
#[macro_export]
macro_rules! tell {
    ($($arg:tt)*) => { $crate::terminal::tell_line(format_args!($($arg)*)) };
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_controls_and_keeps_plain_text() {
        assert!(matches!(escape_controls("t,x,f_stf"), Cow::Borrowed(_)));
        assert_eq!(escape_controls("a\tb\nc"), "a\tb\nc");
        assert_eq!(escape_controls("x\u{1b}[2J"), "x\\u{1b}[2J");
        assert_eq!(escape_controls("ok\rfake"), "ok\\rfake");
        assert_eq!(escape_controls("\u{7}\u{7f}\u{9b}"), "\\u{7}\\u{7f}\\u{9b}");
        assert_eq!(escape_controls("a\u{202e}b"), "a\\u{202e}b");
    }

    #[test]
    fn a_failed_stream_is_marked_closed_and_skipped() {
        struct Broken;
        impl Write for Broken {
            fn write(&mut self, _: &[u8]) -> std::io::Result<usize> {
                Err(std::io::ErrorKind::BrokenPipe.into())
            }
            fn flush(&mut self) -> std::io::Result<()> {
                Ok(())
            }
        }
        let closed = AtomicBool::new(false);
        line(Broken, "a pipe", &closed, format_args!("one"));
        assert!(closed.load(Ordering::Relaxed));
        let mut sink = Vec::new();
        line(&mut sink, "a pipe", &closed, format_args!("two"));
        assert!(sink.is_empty());
        // A closed pipe is no failure of the run.
        assert!(output_failure().is_none_or(|f| !f.contains("a pipe")));
    }
}
