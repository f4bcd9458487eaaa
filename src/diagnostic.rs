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
}

impl SourceFile {
    pub fn new(path: impl Into<String>, text: impl Into<String>) -> Arc<Self> {
        Arc::new(SourceFile {
            path: path.into(),
            text: text.into(),
            line_starts: std::sync::OnceLock::new(),
        })
    }

    fn line_starts(&self) -> &[usize] {
        self.line_starts.get_or_init(|| {
            std::iter::once(0)
                .chain(self.text.match_indices('\n').map(|(i, _)| i + 1))
                .collect()
        })
    }

    /// 1-based line and column (in characters) of a byte offset.
    pub fn line_col(&self, offset: usize) -> (usize, usize) {
        let offset = floor_char_boundary(&self.text, offset.min(self.text.len()));
        let starts = self.line_starts();
        let line = starts.partition_point(|&s| s <= offset);
        let line_start = starts[line - 1];
        let col = self.text[line_start..offset].chars().count() + 1;
        (line, col)
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
}

impl Diagnostic {
    pub fn error(message: impl Into<String>) -> Self {
        Diagnostic {
            severity: Severity::Error,
            message: message.into(),
            file: None,
            span: None,
            hint: None,
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

impl fmt::Display for Diagnostic {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let sev = match self.severity {
            Severity::Error => "error",
            Severity::Warning => "warning",
        };
        writeln!(f, "{sev}: {}", self.message)?;
        if let Some(file) = &self.file {
            match &self.span {
                Some(span) => {
                    let (line, col) = file.line_col(span.start);
                    let num = line.to_string();
                    let pad = " ".repeat(num.len());
                    writeln!(f, "{pad}--> {}:{line}:{col}", file.path)?;
                    let text = file.line_text(line);
                    // Underline the span, clipped to this line.
                    let line_chars = text.chars().count();
                    let span_chars =
                        file.text[floor_char_boundary(&file.text, span.start.min(file.text.len()))
                            ..floor_char_boundary(&file.text, span.end.min(file.text.len()))]
                            .chars()
                            .take_while(|&c| c != '\n')
                            .count();
                    let width = span_chars.clamp(1, (line_chars + 1).saturating_sub(col).max(1));
                    let shown: String = text.chars().take(200).collect();
                    writeln!(f, "{pad} |")?;
                    writeln!(f, "{num} | {shown}")?;
                    writeln!(
                        f,
                        "{pad} | {}{}",
                        " ".repeat(col.saturating_sub(1).min(200)),
                        "^".repeat(width.min(200))
                    )?;
                }
                None => writeln!(f, " --> {}", file.path)?,
            }
        }
        if let Some(hint) = &self.hint {
            writeln!(f, "  = hint: {hint}")?;
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

/// A hint naming the closest candidate, or listing the valid ones.
///
/// Bounded work whatever the input: only the first [`SUGGEST_SCAN`]
/// candidates are compared, and only names of at most [`SUGGEST_MAX_CHARS`]
/// characters (longer ones are not typos of each other).
pub fn suggest<'a>(wrong: &str, candidates: impl IntoIterator<Item = &'a str>) -> String {
    let mut cands: Vec<&str> = candidates.into_iter().take(SUGGEST_SCAN + 1).collect();
    let more_than_scanned = cands.len() > SUGGEST_SCAN;
    cands.truncate(SUGGEST_SCAN);
    let wrong_chars = wrong.chars().count();
    let best = if wrong_chars <= SUGGEST_MAX_CHARS {
        let lower = wrong.to_lowercase();
        cands
            .iter()
            .filter(|c| {
                c.len() <= 4 * SUGGEST_MAX_CHARS
                    && c.chars().count().abs_diff(wrong_chars) <= (wrong_chars / 3).max(2)
            })
            .map(|c| (edit_distance(&lower, &c.to_lowercase()), *c))
            .min()
    } else {
        None
    };
    match best {
        Some((d, c)) if d <= (wrong.chars().count() / 3).max(2) => {
            format!("did you mean `{c}`?")
        }
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
    fn suggestions() {
        assert_eq!(edit_distance("Pik", "Pick"), 1);
        assert_eq!(
            suggest("fallbak", ["fallback", "sequence"]),
            "did you mean `fallback`?"
        );
        assert!(suggest("zzzzzz", ["fallback", "sequence"]).starts_with("expected one of"));
    }
}
