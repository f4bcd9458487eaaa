//! Writing to the terminal without panicking and without raw control
//! characters: everything `cli` prints on stderr goes through [`stderr`]
//! (the `eprintln!` of this module tree), and every text output through
//! [`text`] before [`super::io::emit`].

use std::io::Write;

/// Writes `s` to stderr with control characters but newline and tab
/// escaped; a failed write (closed or full stderr) is ignored.
pub(crate) fn stderr(s: &str) {
    let s = btfsm_core::sanitize::stream(s);
    let _ = std::io::stderr().lock().write_all(s.as_bytes());
}

/// A text output as written: control characters but newline and tab
/// escaped (JSON is already escaped by `sanitize::json`, DOT by its
/// renderer; this is the last line of defence).
pub(crate) fn text(s: &str) -> std::borrow::Cow<'_, str> {
    btfsm_core::sanitize::stream(s)
}
