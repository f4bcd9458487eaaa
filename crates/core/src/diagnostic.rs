//! Positioned messages about input files, rendered the way `just` and `rustc` do:
//! `error: what is wrong`, ` --> file:line:col`, the source line with a caret,
//! and a hint saying what would be valid.

use std::fmt;
use std::ops::Range;
use std::sync::Arc;

/// A source file held in memory so that messages can quote it.
#[derive(Debug)]
pub struct SourceFile {
    /// The path as the user gave it (or as an include resolved it).
    pub path: String,
    pub text: String,
    /// Byte offset of each line's start, computed on first use, so that
    /// positioning many messages in a large file stays linear.
    line_starts: std::sync::OnceLock<Vec<usize>>,
    /// Characters before every [`CHAR_STEP`]-th byte, computed on first
    /// use, so that a column on a very long line (a one-line XML file with
    /// thousands of findings) is counted from the nearest step, not from
    /// the line's start.
    char_steps: std::sync::OnceLock<Vec<usize>>,
}

/// Bytes between two entries of `SourceFile::char_steps`.
const CHAR_STEP: usize = 4096;

impl SourceFile {
    pub fn new(path: impl Into<String>, text: impl Into<String>) -> Arc<Self> {
        Arc::new(SourceFile {
            path: path.into(),
            text: text.into(),
            line_starts: std::sync::OnceLock::new(),
            char_steps: std::sync::OnceLock::new(),
        })
    }

    fn line_starts(&self) -> &[usize] {
        self.line_starts.get_or_init(|| {
            std::iter::once(0)
                .chain(self.text.match_indices('\n').map(|(i, _)| i + 1))
                .collect()
        })
    }

    /// Characters in `text[..offset]` (`offset` on a char boundary), from
    /// the nearest step below it: at most [`CHAR_STEP`] bytes counted.
    fn chars_before(&self, offset: usize) -> usize {
        let steps = self.char_steps.get_or_init(|| {
            let mut v = vec![0];
            for (n, (i, _)) in self.text.char_indices().enumerate() {
                while i >= v.len() * CHAR_STEP {
                    v.push(n);
                }
            }
            v
        });
        let k = (offset / CHAR_STEP).min(steps.len() - 1);
        // The step's byte may fall inside a character: the step counts the
        // characters before the first boundary at or after it.
        let mut from = k * CHAR_STEP;
        while from < self.text.len() && !self.text.is_char_boundary(from) {
            from += 1;
        }
        let from = from.min(offset);
        steps[k] + self.text[from..offset].chars().count()
    }

    /// 1-based line and column (in characters) of a byte offset.
    pub fn line_col(&self, offset: usize) -> (usize, usize) {
        let offset = floor_char_boundary(&self.text, offset.min(self.text.len()));
        let starts = self.line_starts();
        let line = starts.partition_point(|&s| s <= offset);
        let line_start = starts[line - 1];
        let col = if offset - line_start <= CHAR_STEP {
            self.text[line_start..offset].chars().count() + 1
        } else {
            self.chars_before(offset) - self.chars_before(line_start) + 1
        };
        (line, col)
    }

    /// Characters of a 1-based line (without its newline), counted from
    /// the nearest steps on a long line.
    pub fn line_chars(&self, line: usize) -> usize {
        let text = self.line_text(line);
        if text.len() <= 2 * CHAR_STEP {
            return text.chars().count();
        }
        let start = self.line_starts()[line - 1];
        self.chars_before(start + text.len()) - self.chars_before(start)
    }

    /// The text of a 1-based line, without its newline.
    pub fn line_text(&self, line: usize) -> &str {
        let starts = self.line_starts();
        let Some(&start) = starts.get(line.saturating_sub(1)) else {
            return "";
        };
        let end = starts.get(line).map_or(self.text.len(), |&e| e - 1);
        let text = &self.text[start..end];
        text.strip_suffix('\r').unwrap_or(text)
    }
}

fn floor_char_boundary(s: &str, mut i: usize) -> usize {
    while i > 0 && !s.is_char_boundary(i) {
        i -= 1;
    }
    i
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    Error,
    Warning,
}

/// One problem found in one file.
#[derive(Debug, Clone)]
pub struct Diagnostic {
    pub severity: Severity,
    pub message: String,
    pub file: Option<Arc<SourceFile>>,
    pub span: Option<Range<usize>>,
    pub hint: Option<String>,
    /// The lint rule this load error is (`empty-composite`, ...): `lint`
    /// reports a coded load error as a finding of that rule (docs/lint.md).
    pub code: Option<&'static str>,
}

impl Diagnostic {
    pub fn error(message: impl Into<String>) -> Self {
        Diagnostic {
            severity: Severity::Error,
            message: message.into(),
            file: None,
            span: None,
            hint: None,
            code: None,
        }
    }

    pub fn warning(message: impl Into<String>) -> Self {
        Diagnostic {
            severity: Severity::Warning,
            ..Diagnostic::error(message)
        }
    }

    pub fn at(mut self, file: &Arc<SourceFile>, span: Range<usize>) -> Self {
        self.file = Some(file.clone());
        self.span = Some(span);
        self
    }

    pub fn in_file(mut self, file: &Arc<SourceFile>) -> Self {
        self.file = Some(file.clone());
        self
    }

    pub fn hint(mut self, hint: impl Into<String>) -> Self {
        self.hint = Some(hint.into());
        self
    }

    pub fn with_code(mut self, code: &'static str) -> Self {
        self.code = Some(code);
        self
    }

    /// [`Diagnostic::with_code`] on a diagnostic already pushed.
    pub fn set_code(&mut self, code: &'static str) -> &mut Self {
        self.code = Some(code);
        self
    }

    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }

    /// `(path, line, column)` of the message, when it has a position.
    pub fn location(&self) -> Option<(String, usize, usize)> {
        let file = self.file.as_ref()?;
        match &self.span {
            Some(span) => {
                let (l, c) = file.line_col(span.start);
                Some((file.path.clone(), l, c))
            }
            None => Some((file.path.clone(), 0, 0)),
        }
    }
}

/// Longest message or hint shown, in characters (a message quotes names
/// from the input; readers cut those, this is the last bound).
pub const MESSAGE_CHARS: usize = 1000;
/// Characters of a source line shown in a snippet.
pub const SNIPPET_CHARS: usize = 160;

impl fmt::Display for Diagnostic {
    /// Every part that comes from input (message, path, source line, hint)
    /// goes through [`crate::sanitize`]: one line each, control characters
    /// escaped, cut with a count.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use crate::sanitize::{shown, shown_max};
        let sev = match self.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
        };
        writeln!(f, "{sev}: {}", shown_max(&self.message, MESSAGE_CHARS))?;
        if let Some(file) = &self.file {
            let path = shown_max(&file.path, 400);
            match &self.span {
                Some(span) => {
                    let (line, col) = file.line_col(span.start);
                    let num = line.to_string();
                    let pad = " ".repeat(num.len());
                    writeln!(f, "{pad}--> {path}:{line}:{col}")?;
                    let text = file.line_text(line);
                    // Underline the span, clipped to this line.
                    let line_chars = file.line_chars(line);
                    let span_chars =
                        file.text[floor_char_boundary(&file.text, span.start.min(file.text.len()))
                            ..floor_char_boundary(&file.text, span.end.min(file.text.len()))]
                            .chars()
                            .take_while(|&c| c != '\n')
                            .count();
                    let width = span_chars.clamp(1, (line_chars + 1).saturating_sub(col).max(1));
                    // The line as shown (escaped, cut), and where the caret
                    // falls in it: each character takes the width of its
                    // escaped form.
                    let mut shown_line = String::new();
                    let (mut caret_at, mut caret_len) = (None, 0usize);
                    for (i, c) in text.chars().enumerate().take(SNIPPET_CHARS) {
                        let mut buf = [0u8; 4];
                        let piece = shown(c.encode_utf8(&mut buf));
                        if i + 1 == col {
                            caret_at = Some(shown_line.chars().count());
                        }
                        if i + 1 >= col && i + 1 < col + width {
                            caret_len += piece.chars().count();
                        }
                        shown_line.push_str(&piece);
                    }
                    if line_chars > SNIPPET_CHARS {
                        shown_line.push('…');
                    }
                    let caret_at = caret_at.unwrap_or(shown_line.chars().count());
                    writeln!(f, "{pad} |")?;
                    writeln!(f, "{num} | {shown_line}")?;
                    writeln!(
                        f,
                        "{pad} | {}{}",
                        " ".repeat(caret_at),
                        "^".repeat(caret_len.clamp(1, 200))
                    )?;
                }
                None => writeln!(f, " --> {path}")?,
            }
        }
        if let Some(hint) = &self.hint {
            writeln!(f, "  = hint: {}", shown_max(hint, MESSAGE_CHARS))?;
        }
        Ok(())
    }
}

/// Levenshtein distance, for "did you mean" hints.
pub fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut prev: Vec<usize> = (0..=b.len()).collect();
    let mut cur = vec![0; b.len() + 1];
    for (i, ca) in a.chars().enumerate() {
        cur[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let sub = prev[j] + usize::from(ca != cb);
            cur[j + 1] = sub.min(prev[j + 1] + 1).min(cur[j] + 1);
        }
        std::mem::swap(&mut prev, &mut cur);
    }
    prev[b.len()]
}

/// Candidates [`suggest`] compares at most.
pub const SUGGEST_SCAN: usize = 5_000;
/// Longest name (in characters) [`suggest`] computes an edit distance for.
pub const SUGGEST_MAX_CHARS: usize = 128;

/// The candidate closest to `wrong` when it is close enough to be what was
/// meant (an edit distance of at most a third of its length, at least 2),
/// as [`suggest`] finds it; bounded the same way.
pub fn closest<'a>(wrong: &str, candidates: impl IntoIterator<Item = &'a str>) -> Option<&'a str> {
    let cands: Vec<&str> = candidates.into_iter().take(SUGGEST_SCAN).collect();
    closest_of(wrong, &cands)
}

fn closest_of<'a>(wrong: &str, cands: &[&'a str]) -> Option<&'a str> {
    let wrong_chars = wrong.chars().count();
    if wrong_chars > SUGGEST_MAX_CHARS {
        return None;
    }
    let lower = wrong.to_lowercase();
    cands
        .iter()
        .filter(|c| {
            c.len() <= 4 * SUGGEST_MAX_CHARS
                && c.chars().count().abs_diff(wrong_chars) <= (wrong_chars / 3).max(2)
        })
        .map(|c| (edit_distance(&lower, &c.to_lowercase()), *c))
        .min()
        .filter(|(d, _)| *d <= (wrong_chars / 3).max(2))
        .map(|(_, c)| c)
}

/// A hint naming the closest candidate, or listing the valid ones.
///
/// Bounded work whatever the input: only the first [`SUGGEST_SCAN`]
/// candidates are compared, and only names of at most [`SUGGEST_MAX_CHARS`]
/// characters (longer ones are not typos of each other).
pub fn suggest<'a>(wrong: &str, candidates: impl IntoIterator<Item = &'a str>) -> String {
    let mut cands: Vec<&str> = candidates.into_iter().take(SUGGEST_SCAN + 1).collect();
    let more_than_scanned = cands.len() > SUGGEST_SCAN;
    cands.truncate(SUGGEST_SCAN);
    match closest_of(wrong, &cands) {
        Some(c) => format!("did you mean `{c}`?"),
        _ if cands.is_empty() => "nothing is defined here".to_string(),
        _ => {
            let shown: Vec<String> = cands
                .iter()
                .take(12)
                .map(|c| match c.char_indices().nth(40) {
                    Some((cut, _)) => format!("`{}…`", &c[..cut]),
                    None => format!("`{c}`"),
                })
                .collect();
            let more = if more_than_scanned {
                " (and more)".to_string()
            } else if cands.len() > 12 {
                format!(" (and {} more)", cands.len() - 12)
            } else {
                String::new()
            };
            format!("expected one of {}{more}", shown.join(", "))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_on_long_lines_count_characters_from_the_line_start() {
        // Mixed 1- to 4-byte characters on lines longer than CHAR_STEP,
        // every offset checked against counting from the line's start.
        let unit = "ab\u{e9}\u{20ac}\u{1f600}<x y=\"{k}\"/>";
        let text = format!("{}\n{}\n\u{e9}", unit.repeat(900), unit.repeat(1200));
        let f = SourceFile::new("long.xml", text.clone());
        let naive = |o: usize| {
            let start = text[..o].rfind('\n').map_or(0, |i| i + 1);
            (
                text[..o].matches('\n').count() + 1,
                text[start..o].chars().count() + 1,
            )
        };
        for (o, _) in text.char_indices().step_by(7).chain([(text.len(), ' ')]) {
            assert_eq!(f.line_col(o), naive(o), "offset {o}");
        }
        for (l, t) in text.split('\n').enumerate() {
            assert_eq!(f.line_chars(l + 1), t.chars().count());
        }
    }

    #[test]
    fn line_and_column() {
        let f = SourceFile::new("x.toml", "a = 1\nbé = 2\n");
        assert_eq!(f.line_col(0), (1, 1));
        assert_eq!(f.line_col(6), (2, 1));
        assert_eq!(f.line_col(10), (2, 4));
    }

    #[test]
    fn renders_snippet_with_caret() {
        let f = SourceFile::new("p.toml", "kind = \"bt\"\nroot = \"nope\"\n");
        let d = Diagnostic::error("unknown node `nope`")
            .at(&f, 19..25)
            .hint("did you mean `none`?");
        let s = d.to_string();
        assert!(s.starts_with("error: unknown node `nope`\n"), "{s}");
        assert!(s.contains("--> p.toml:2:8"), "{s}");
        assert!(s.contains("2 | root = \"nope\""), "{s}");
        assert!(s.contains("  |        ^^^^^^"), "{s}");
        assert!(s.contains("= hint: did you mean `none`?"), "{s}");
    }

    #[test]
    fn snippets_and_messages_are_escaped_and_cut() {
        let f = SourceFile::new(
            "p\u{1b}[2J.toml",
            "a = \"x\u{1b}]0;t\u{7}\" # \u{202e}\nb = 2\n",
        );
        let d = Diagnostic::error("bad name `x\nerror: forged`")
            .at(&f, 4..12)
            .hint("h\r");
        let s = d.to_string();
        assert!(!crate::sanitize::has_raw_control(&s), "{s}");
        assert_eq!(s.lines().count(), 6, "{s}");
        assert!(s.contains("1 | a = \"x\\u{1b}]0;t\\u{7}\""), "{s}");
        // The caret still starts under the opening quote.
        assert!(s.contains("  |     ^"), "{s}");
        let long = SourceFile::new("l.toml", "x".repeat(100_000));
        let d = Diagnostic::error("m".repeat(100_000)).at(&long, 5..6);
        assert!(
            d.to_string().len() < 3 * (MESSAGE_CHARS + SNIPPET_CHARS),
            "bounded"
        );
    }

    #[test]
    fn suggestions() {
        assert_eq!(edit_distance("Pik", "Pick"), 1);
        assert_eq!(
            suggest("fallbak", ["fallback", "sequence"]),
            "did you mean `fallback`?"
        );
        assert!(suggest("zzzzzz", ["fallback", "sequence"]).starts_with("expected one of"));
    }
}
