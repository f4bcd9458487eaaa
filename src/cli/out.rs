//! Writing to the terminal without panicking and without raw control
//! characters: everything `cli` prints on stderr goes through [`stderr`]
//! (the `eprintln!` of this module tree), and every text output through
//! [`text`] before [`super::commands::emit`].

use std::io::Write;

/// Writes `s` to stderr with control characters but newline and tab
/// escaped; a failed write (closed or full stderr) is ignored.
pub fn stderr(s: &str) {
    let s = crate::sanitize::stream(s);
    let _ = std::io::stderr().lock().write_all(s.as_bytes());
}

/// A text output as written: control characters but newline and tab
/// escaped (JSON is already escaped by `sanitize::json`, DOT by its
/// renderer; this is the last line of defence).
pub fn text(s: &str) -> std::borrow::Cow<'_, str> {
    crate::sanitize::stream(s)
}

#[cfg(test)]
mod tests {
    /// ARCHITECTURE.md: the library never prints; only `src/cli/` writes to
    /// stdout or stderr (test code excepted: a file's `#[cfg(test)]` part
    /// and `tests.rs` files).
    #[test]
    fn only_cli_prints() {
        let src = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
        let mut stack = vec![src.clone()];
        let mut offenders = Vec::new();
        while let Some(d) = stack.pop() {
            for e in std::fs::read_dir(&d).expect("src").flatten() {
                let p = e.path();
                if p.is_dir() {
                    if p != src.join("cli") {
                        stack.push(p);
                    }
                    continue;
                }
                if p.extension().is_none_or(|x| x != "rs")
                    || p.file_name()
                        .is_some_and(|n| n == "tests.rs" || n == "main.rs")
                {
                    continue;
                }
                let text = std::fs::read_to_string(&p).expect("read");
                let code = text.split("#[cfg(test)]").next().unwrap_or("");
                for needle in ["println!", "print!(", "stdout()", "stderr()", "dbg!("] {
                    // Asking what stdout is (its file descriptor) is not
                    // writing to it.
                    let writes = code
                        .match_indices(needle)
                        .any(|(i, _)| !code[i + needle.len()..].starts_with(".as_fd()"));
                    if writes {
                        offenders.push(format!("{}: {needle}", p.display()));
                    }
                }
            }
        }
        assert!(offenders.is_empty(), "{offenders:?}");
    }
}
