//! The XML that BehaviorTree.CPP reads although it is not well-formed:
//! tinyxml2 (BehaviorTree.CPP's parser) accepts a bare `&` or `<` in an
//! attribute value (`_if="a && b"`, `code="x < 3"`), a bare `&` in text,
//! `--` inside a comment or a comment ending in `--->`, attributes without a space between them
//! (`ID="A"name="x"`), and stray text before the document element. When a
//! file is not well-formed, [`repair`] rewrites exactly these places (`&amp;`,
//! `&lt;`, `- -` kept at the same length as `~~`, spaces), and the file is
//! read from the repair with every position mapped back to the original text,
//! a warning at each place. Anything else stays an error, at the original
//! position.

use btfsm_core::diagnostic::{Diagnostic, SourceFile};
use std::ops::Range;
use std::sync::Arc;

/// A text rewritten by [`repair`]: where its offsets came from.
#[derive(Debug, Default)]
pub struct OffsetMap {
    /// (offset in the repaired text, offset in the original) at the end of
    /// each insertion, in order: between two entries the texts agree.
    marks: Vec<(usize, usize)>,
}

impl OffsetMap {
    /// The original offset of an offset in the repaired text (a position
    /// inside an inserted escape maps to the character it escapes).
    pub fn original(&self, at: usize) -> usize {
        let i = self.marks.partition_point(|&(new, _)| new <= at);
        if i == 0 {
            return at;
        }
        let (new, orig) = self.marks[i - 1];
        orig + (at - new)
    }

    pub fn range(&self, r: Range<usize>) -> Range<usize> {
        let (a, b) = (self.original(r.start), self.original(r.end));
        a..b.max(a)
    }
}

/// What was repaired, and where (in the original text).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Repair {
    pub span: Range<usize>,
    pub what: &'static str,
}

/// The repaired text, its offset map and the repairs made; `None` when there
/// is nothing to repair.
pub fn repair(text: &str) -> Option<(String, OffsetMap, Vec<Repair>)> {
    let b = text.as_bytes();
    let mut r = Repairer {
        text,
        i: 0,
        out: String::with_capacity(text.len() + 64),
        map: OffsetMap::default(),
        fixes: Vec::new(),
    };
    let mut seen_root = false;
    while r.i < b.len() {
        let i = r.i;
        let rest = &text[i..];
        if rest.starts_with("<!--") {
            r.comment();
        } else if rest.starts_with("<![CDATA[") {
            r.copy_to(rest.find("]]>").map_or(b.len(), |e| i + e + 3));
        } else if rest.starts_with("<?") || rest.starts_with("<!") {
            r.copy_to(rest.find('>').map_or(b.len(), |e| i + e + 1));
        } else if b[i] == b'<' {
            if b.get(i + 1).is_some_and(|c| *c != b'/') {
                seen_root = true;
            }
            r.tag();
        } else if b[i] == b'&' && !entity_at(rest) {
            r.fixes.push(Repair {
                span: i..i + 1,
                what: "a bare `&` in text",
            });
            r.escape("&amp;");
        } else if !seen_root && !b[i].is_ascii_whitespace() {
            r.stray_text();
        } else {
            r.copy_char();
        }
    }
    let Repairer {
        out, map, fixes, ..
    } = r;
    (!fixes.is_empty()).then_some((out, map, fixes))
}

/// A repair under way: the text, how far it is read (`i`), the repaired
/// text written so far, its offset map and the repairs made.
struct Repairer<'a> {
    text: &'a str,
    i: usize,
    out: String,
    map: OffsetMap,
    fixes: Vec<Repair>,
}

impl Repairer<'_> {
    /// Copies the text up to `end` unchanged.
    fn copy_to(&mut self, end: usize) {
        self.out.push_str(&self.text[self.i..end]);
        self.i = end;
    }

    /// Copies one character (UTF-8 aware).
    fn copy_char(&mut self) {
        let b = self.text.as_bytes();
        let len = utf8_len(b[self.i]);
        self.out
            .push_str(&self.text[self.i..(self.i + len).min(b.len())]);
        self.i += len;
    }

    /// Writes `escape` for the one character at `i`.
    fn escape(&mut self, escape: &str) {
        self.out.push_str(escape);
        self.i += 1;
        self.map.marks.push((self.out.len(), self.i));
    }

    /// A comment, with `--` inside it written `~~`.
    fn comment(&mut self) {
        let (text, i) = (self.text, self.i);
        // The comment's content ends at `-->` (or at the end of an
        // unterminated comment, which stays an error): ASCII boundaries.
        let close = text[i + 4..].find("-->").map(|e| i + 4 + e);
        let inner_end = close.unwrap_or(text.len());
        let end = close.map_or(text.len(), |c| c + 3);
        let inner = &text[i + 4..inner_end];
        // `--->` (BehaviorTree.CPP 3.8's tutorial t05 ends a comment so):
        // the comment's text ends in `-`, which XML forbids.
        let dash_end = close.is_some() && inner.ends_with('-');
        if inner.contains("--") || dash_end {
            self.fixes.push(Repair {
                span: i..i + 4,
                what: if inner.contains("--") {
                    "`--` inside a comment"
                } else {
                    "a comment ending in `--->`"
                },
            });
            self.out.push_str("<!--");
            let mut fixed = inner.replace("--", "~~");
            if fixed.ends_with('-') {
                fixed.pop();
                fixed.push('~');
            }
            self.out.push_str(&fixed);
            self.out.push_str(&text[inner_end..end]);
            self.i = end;
        } else {
            self.copy_to(end);
        }
    }

    /// A tag: copied up to its end, escaping `&` and `<` inside quoted
    /// attribute values (one repair per tag) and putting a space between
    /// attributes written together.
    fn tag(&mut self) {
        let b = self.text.as_bytes();
        self.out.push('<');
        self.i += 1;
        let mut quote: Option<u8> = None;
        let mut fixed_here = false;
        while self.i < b.len() {
            let (c, i) = (b[self.i], self.i);
            match quote {
                None if c == b'>' => {
                    self.out.push('>');
                    self.i += 1;
                    break;
                }
                None if c == b'"' || c == b'\'' => quote = Some(c),
                Some(q) if c == q => {
                    quote = None;
                    self.out.push(c as char);
                    self.i += 1;
                    // `a="1"b="2"`: a space where the next attribute starts.
                    if b.get(self.i)
                        .is_some_and(|n| n.is_ascii_alphabetic() || *n == b'_')
                    {
                        self.fixes.push(Repair {
                            span: self.i..self.i + 1,
                            what: "no space between two attributes",
                        });
                        self.out.push(' ');
                        self.map.marks.push((self.out.len(), self.i));
                    }
                    continue;
                }
                Some(_) if c == b'<' || (c == b'&' && !entity_at(&self.text[i..])) => {
                    let (what, escape) = if c == b'<' {
                        ("a bare `<` in an attribute value", "&lt;")
                    } else {
                        ("a bare `&` in an attribute value", "&amp;")
                    };
                    if !fixed_here {
                        self.fixes.push(Repair {
                            span: i..i + 1,
                            what,
                        });
                        fixed_here = true;
                    }
                    self.escape(escape);
                    continue;
                }
                _ => {}
            }
            self.copy_char();
        }
    }

    /// Stray text before the document element: blanked, same length.
    fn stray_text(&mut self) {
        let (text, i) = (self.text, self.i);
        let end = text[i..].find('<').map_or(text.len(), |e| i + e);
        let shown_end = text[i..end].find('\n').map_or(end, |e| i + e);
        self.fixes.push(Repair {
            span: i..shown_end,
            what: "text before the document element",
        });
        for ch in text[i..end].chars() {
            if ch == '\n' || ch == '\r' {
                self.out.push(ch);
            } else {
                for _ in 0..ch.len_utf8() {
                    self.out.push(' ');
                }
            }
        }
        self.i = end;
    }
}

fn utf8_len(first: u8) -> usize {
    match first {
        0x00..=0x7f => 1,
        0xc0..=0xdf => 2,
        0xe0..=0xef => 3,
        _ => 4,
    }
}

/// Does `s` (starting at `&`) start an entity or character reference?
fn entity_at(s: &str) -> bool {
    let rest = &s[1..];
    let Some(end) = rest.find(';').filter(|&e| e <= 32) else {
        return false;
    };
    let name = &rest[..end];
    if let Some(num) = name.strip_prefix('#') {
        return match num.strip_prefix('x') {
            Some(hex) => !hex.is_empty() && hex.chars().all(|c| c.is_ascii_hexdigit()),
            None => !num.is_empty() && num.chars().all(|c| c.is_ascii_digit()),
        };
    }
    name.chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '_' | '-' | '.'))
}

/// The warnings of the repairs made to `file` (one per place).
pub fn warnings(file: &Arc<SourceFile>, fixes: &[Repair]) -> Vec<Diagnostic> {
    fixes
        .iter()
        .map(|r| {
            Diagnostic::warning(format!(
                "not well-formed XML: {}; read as BehaviorTree.CPP (tinyxml2) reads it",
                r.what
            ))
            .at(file, r.span.clone())
            .hint(match r.what {
                "`--` inside a comment" => "write `- -` or end the comment before it",
                "a comment ending in `--->`" => "end the comment with ` -->`",
                "text before the document element" => "remove the text before `<root>`",
                "a bare `<` in an attribute value" => "write `&lt;`",
                "no space between two attributes" => "separate attributes with a space",
                _ => "write `&amp;`",
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn what_tinyxml2_accepts_is_repaired_and_mapped_back() {
        let text =
            "junk\n<root>\n<!-- a -- b -->\n<S _if=\"a && b < 3\" x=\"&amp;\">k & l</S></root>";
        let (fixed, map, fixes) = repair(text).unwrap();
        assert_eq!(
            fixed,
            "    \n<root>\n<!-- a ~~ b -->\n<S _if=\"a &amp;&amp; b &lt; 3\" x=\"&amp;\">k &amp; l</S></root>"
        );
        let whats: Vec<&str> = fixes.iter().map(|f| f.what).collect();
        assert_eq!(
            whats,
            [
                "text before the document element",
                "`--` inside a comment",
                "a bare `&` in an attribute value",
                "a bare `&` in text"
            ]
        );
        // Offsets after the escapes map back to the original.
        let close = fixed.find("</S>").unwrap();
        assert_eq!(map.original(close), text.find("</S>").unwrap());
        assert_eq!(&text[fixes[2].span.clone()], "&");
        assert!(repair("<root a=\"&lt;\"><!-- ok --></root>").is_none());
        let (fixed, map, _) = repair("<A ID=\"A\"name=\"x\"/>").unwrap();
        assert_eq!(fixed, "<A ID=\"A\" name=\"x\"/>");
        assert_eq!(map.original(fixed.find("name").unwrap()), 9);
    }

    /// BehaviorTree.CPP 3.8's tutorial t05 ends a comment with `--->`,
    /// which tinyxml2 reads (and BehaviorTree.CPP 4 loads).
    #[test]
    fn a_comment_ending_in_three_dashes_is_read() {
        let text = "<root>\n  <!-- Simple tree --->\n  <B/>\n</root>";
        let (fixed, _, fixes) = repair(text).unwrap();
        assert_eq!(fixed, "<root>\n  <!-- Simple tree ~-->\n  <B/>\n</root>");
        assert_eq!(fixes[0].what, "a comment ending in `--->`");
        assert_eq!(fixes[0].span, 9..13);
    }
}
