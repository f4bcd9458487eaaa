//! The one output-sanitising layer (issue 12): every string a policy,
//! scenario, baseline or trace controls passes through here before it
//! reaches a terminal, a CI log, a file or a pull-request comment.
//!
//! - [`shown`]: one user string inside a message or a table cell: control
//!   characters escaped (newlines too), long strings cut with a count.
//! - [`stream`]: a whole text output: every control character but newline
//!   and tab escaped, the last line of defence for what [`shown`] missed.
//! - [`json`]: a serialised JSON document, with the characters JSON leaves
//!   raw (DEL, C1, bidirectional controls, line separators) written as
//!   `\uXXXX`: the same data, no raw control byte.
//! - [`markdown_cell`], [`code_fence`]: markdown that cannot open HTML nor
//!   close the code block it sits in.
//! - [`csv_cell`]: a CSV cell a spreadsheet does not run as a formula
//!   (OWASP, "CSV Injection").
//!
//! Escapes are Rust's (`\n`, `\u{1b}`), so an escaped string reads back
//! unambiguously.

use std::borrow::Cow;
use std::fmt::Write;

/// Characters of a user string shown in a message or table cell; the rest
/// is cut and counted.
pub const SHOWN_CHARS: usize = 120;

/// Whether `c` must not reach an output raw: C0 controls (tab and, where
/// `keep_newline`, newline excepted), DEL, C1, the Unicode bidirectional
/// overrides, embeddings, isolates and marks ("Trojan Source",
/// CVE-2021-42574), the line and paragraph separators, and the characters
/// that show nothing but change what a reader sees or a program compares
/// (issue 33): zero-width spaces and joiners, the word joiner and invisible
/// operators, the byte-order mark, the soft hyphen, the combining grapheme
/// joiner, the Hangul fillers, variation selectors, interlinear
/// annotations and the tag characters (which can spell hidden text).
pub fn is_unsafe(c: char, keep_newline: bool) -> bool {
    match c {
        '\t' => false,
        '\n' => !keep_newline,
        '\u{0}'..='\u{1f}' | '\u{7f}'..='\u{9f}' => true,
        '\u{61c}' | '\u{200e}' | '\u{200f}' | '\u{202a}'..='\u{202e}' | '\u{2066}'..='\u{2069}' => {
            true
        }
        '\u{2028}' | '\u{2029}' => true,
        '\u{ad}'
        | '\u{34f}'
        | '\u{115f}'
        | '\u{1160}'
        | '\u{17b4}'
        | '\u{17b5}'
        | '\u{180b}'..='\u{180f}' => true,
        '\u{200b}'..='\u{200d}'
        | '\u{2060}'..='\u{2064}'
        | '\u{3164}'
        | '\u{feff}'
        | '\u{ffa0}' => true,
        '\u{fe00}'..='\u{fe0f}' | '\u{fff9}'..='\u{fffb}' => true,
        '\u{e0000}'..='\u{e007f}' | '\u{e0100}'..='\u{e01ef}' => true,
        _ => false,
    }
}

fn escape_into(out: &mut String, c: char) {
    match c {
        '\n' => out.push_str("\\n"),
        '\r' => out.push_str("\\r"),
        c => {
            let _ = write!(out, "\\u{{{:x}}}", c as u32);
        }
    }
}

fn escaped(s: &str, keep_newline: bool) -> Cow<'_, str> {
    if !s.chars().any(|c| is_unsafe(c, keep_newline)) {
        return Cow::Borrowed(s);
    }
    let mut out = String::with_capacity(s.len() + 8);
    for c in s.chars() {
        if is_unsafe(c, keep_newline) {
            escape_into(&mut out, c);
        } else {
            out.push(c);
        }
    }
    Cow::Owned(out)
}

/// A user string for a message or a cell: on one line, control characters
/// escaped, at most [`SHOWN_CHARS`] characters, the rest counted as
/// `…(N more bytes)`.
pub fn shown(s: &str) -> Cow<'_, str> {
    shown_max(s, SHOWN_CHARS)
}

/// [`shown`] with another length.
pub fn shown_max(s: &str, max_chars: usize) -> Cow<'_, str> {
    let cut = s.char_indices().nth(max_chars).map(|(i, _)| i);
    match cut {
        None => escaped(s, false),
        Some(i) => {
            let mut out = escaped(&s[..i], false).into_owned();
            let _ = write!(out, "…({} more bytes)", s.len() - i);
            Cow::Owned(out)
        }
    }
}

/// A whole text output (report, message, DOT): every control character but
/// newline and tab escaped.
pub fn stream(s: &str) -> Cow<'_, str> {
    escaped(s, true)
}

/// A serialised JSON document with DEL, C1, bidirectional controls and line
/// separators as `\uXXXX` escapes (serde_json escapes only C0): the same
/// data. Outside strings JSON holds only ASCII, so every such character is
/// inside a string.
pub fn json(s: String) -> String {
    if !s.chars().any(|c| is_unsafe(c, true)) {
        return s;
    }
    let mut out = String::with_capacity(s.len() + 16);
    for c in s.chars() {
        if is_unsafe(c, true) && c != '\n' {
            let mut buf = [0u16; 2];
            for u in c.encode_utf16(&mut buf) {
                let _ = write!(out, "\\u{:04x}", u);
            }
        } else {
            out.push(c);
        }
    }
    out
}

/// A user string in a markdown table cell, list item or paragraph, inert
/// on GitHub (issue 33): [`shown`] (one line, no control or invisible
/// character), then
///
/// - a string holding `@` (a mention, a team, an e-mail address) or a link
///   GitHub would make of bare text (`://`, `www.`, `mailto:`, `xmpp:`) is
///   the code span of [`markdown_code`], where GitHub links and mentions
///   nothing;
/// - otherwise HTML (`<`, `>`, `&`) as entities, markdown's inline
///   characters (`|`, `` ` ``, `*`, `_`, `[`, `]`, `\`, `#`, `~`) escaped,
///   leading blanks as entities, and a first `-`, `+`, `=` or the `.`/`)`
///   after leading digits escaped,
///   so that it can open no tag, link, code span, emphasis, heading, list or
///   rule, nor end the table cell.
pub fn markdown_cell(s: &str) -> String {
    if would_link(s) {
        return markdown_code(s);
    }
    let s = shown(s);
    let lead = s.len() - s.trim_start().len();
    let digits = s[lead..].bytes().take_while(u8::is_ascii_digit).count();
    let mut out = String::with_capacity(s.len() + 8);
    for (i, c) in s.char_indices() {
        match c {
            // Leading blanks would indent a code block or a list.
            ' ' if i < lead => out.push_str("&#32;"),
            '\t' if i < lead => out.push_str("&#9;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '&' => out.push_str("&amp;"),
            '|' | '`' | '*' | '_' | '[' | ']' | '\\' | '#' | '~' => {
                out.push('\\');
                out.push(c);
            }
            '-' | '+' | '=' if i == lead => {
                out.push('\\');
                out.push(c);
            }
            '.' | ')' if digits > 0 && i == lead + digits => {
                out.push('\\');
                out.push(c);
            }
            c => out.push(c),
        }
    }
    out
}

/// Whether GitHub would make a mention or a link of some of `s`'s bare text.
fn would_link(s: &str) -> bool {
    if s.contains('@') {
        return true;
    }
    let lower = s.to_ascii_lowercase();
    ["://", "www.", "mailto:", "xmpp:"]
        .iter()
        .any(|p| lower.contains(p))
}

/// A user string as an inline code span, the one form in which GitHub shows
/// any text inert (no HTML, link, autolink, mention nor emoji): [`shown`]
/// (one line, no control or invisible character), `|` escaped (GitHub
/// reads `\|` inside a code span in a table as `|`), and delimited by one
/// more backtick than its longest run (CommonMark 0.31, 6.1), so it can
/// neither end the span nor the cell.
pub fn markdown_code(s: &str) -> String {
    let s = shown(s).replace('|', "\\|");
    let fence = "`".repeat(longest_backtick_run(&s) + 1);
    let pad = if s.starts_with('`') || s.ends_with('`') || s.is_empty() {
        " "
    } else {
        ""
    };
    format!("{fence}{pad}{s}{pad}{fence}")
}

fn longest_backtick_run(s: &str) -> usize {
    let (mut run, mut longest) = (0usize, 0usize);
    for c in s.chars() {
        if c == '`' {
            run += 1;
            longest = longest.max(run);
        } else {
            run = 0;
        }
    }
    longest
}

/// The fence for a code block holding `body`: backticks, one more than the
/// longest run of backticks in it (at least three), so the body cannot
/// close it (CommonMark 0.31, 4.5).
pub fn code_fence(body: &str) -> String {
    "`".repeat((longest_backtick_run(body) + 1).max(3))
}

/// The entity of one of XML's four characters that text or a double-quoted
/// attribute value must not hold as they are (`&`, `<`, `>`, `"`).
pub fn entity(c: char) -> Option<&'static str> {
    match c {
        '&' => Some("&amp;"),
        '<' => Some("&lt;"),
        '>' => Some("&gt;"),
        '"' => Some("&quot;"),
        _ => None,
    }
}

/// A user string as XML, SVG or HTML text or attribute value: control
/// characters escaped and the length cut at `max_chars` ([`shown_max`]),
/// then `&`, `<`, `>`, `"` and `'` as entities.
pub fn markup(s: &str, max_chars: usize) -> String {
    let s = shown_max(s, max_chars);
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match (entity(c), c) {
            (Some(e), _) => out.push_str(e),
            (None, '\'') => out.push_str("&#39;"),
            (None, c) => out.push(c),
        }
    }
    out
}

/// A CSV cell: control characters escaped, quoted when it holds a comma, a
/// quote or a newline, and prefixed with `'` when it starts with `=`, `+`,
/// `-`, `@` (or a tab or carriage return), which spreadsheets would run as
/// a formula. For strings from input only; numbers are written as they are.
pub fn csv_cell(s: &str) -> String {
    let s = escaped(s, false);
    let s = if s.starts_with(['=', '+', '-', '@', '\t', '\r']) {
        Cow::Owned(format!("'{s}"))
    } else {
        s
    };
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.into_owned()
    }
}

/// Whether an output holds a character [`stream`] would escape (tests).
pub fn has_raw_control(s: &str) -> bool {
    s.chars().any(|c| is_unsafe(c, true))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn control_characters_are_escaped() {
        assert_eq!(shown("a\u{1b}]0;pwned\u{7}b"), "a\\u{1b}]0;pwned\\u{7}b");
        assert_eq!(shown("x\nerror: fake"), "x\\nerror: fake");
        assert_eq!(shown("tab\tok"), "tab\tok");
        assert_eq!(shown("\u{202e}gnp.exe"), "\\u{202e}gnp.exe");
        assert_eq!(shown("c1\u{9b}31m"), "c1\\u{9b}31m");
        assert_eq!(shown("plain"), "plain");
        assert!(matches!(shown("plain"), Cow::Borrowed(_)));
        assert_eq!(stream("l1\nl2\u{1b}[2J"), "l1\nl2\\u{1b}[2J");
        assert!(!has_raw_control(&stream("\u{0}\u{7f}\u{85}\u{2028}\r")));
    }

    #[test]
    fn long_strings_are_cut_with_a_count() {
        let long = "é".repeat(1000);
        let s = shown(&long);
        assert!(s.starts_with(&"é".repeat(SHOWN_CHARS)));
        assert!(s.ends_with(&format!("…({} more bytes)", 2 * (1000 - SHOWN_CHARS))));
        assert_eq!(shown(&"a".repeat(SHOWN_CHARS)).len(), SHOWN_CHARS);
    }

    #[test]
    fn json_keeps_the_data_and_no_raw_control() {
        let v = serde_json::json!({"name": "a\u{7f}b\u{85}c\u{202e}d\u{1b}e\u{1F600}"});
        let text = json(serde_json::to_string_pretty(&v).unwrap());
        assert!(!has_raw_control(&text), "{text}");
        let back: serde_json::Value = serde_json::from_str(&text).unwrap();
        assert_eq!(back, v);
    }

    #[test]
    fn markdown_cannot_break_out() {
        let cell = markdown_cell("<img src=x onerror=alert(1)>|`x`\n# h");
        assert!(!cell.contains('<') && !cell.contains('\n'), "{cell}");
        assert!(cell.contains("\\|") && cell.contains("\\`"), "{cell}");
        assert_eq!(code_fence("a ``` b"), "````");
        assert_eq!(code_fence("plain"), "```");
        assert_eq!(markdown_code("a|b"), "`a\\|b`");
        assert_eq!(markdown_code("x``y"), "```x``y```");
        assert_eq!(markdown_code("`x"), "`` `x ``");
    }

    #[test]
    fn invisible_characters_are_escaped() {
        for c in [
            '\u{200b}',
            '\u{200d}',
            '\u{2060}',
            '\u{feff}',
            '\u{ad}',
            '\u{115f}',
            '\u{1160}',
            '\u{3164}',
            '\u{ffa0}',
            '\u{fe0f}',
            '\u{e0041}',
            '\u{e0100}',
            '\u{180e}',
        ] {
            let s = format!("a{c}b");
            assert_eq!(shown(&s), format!("a\\u{{{:x}}}b", c as u32));
            assert!(has_raw_control(&s), "{:x}", c as u32);
        }
        assert_eq!(shown("plain é ü ✓"), "plain é ü ✓");
    }

    #[test]
    fn markdown_cells_make_no_link_mention_list_or_heading() {
        assert_eq!(markdown_cell("@octocat"), "`@octocat`");
        assert_eq!(markdown_cell("see https://x.io"), "`see https://x.io`");
        assert_eq!(markdown_cell("WWW.x.io"), "`WWW.x.io`");
        assert_eq!(markdown_cell("a@b.co"), "`a@b.co`");
        assert_eq!(markdown_cell("- item"), "\\- item");
        assert_eq!(markdown_cell("==="), "\\===");
        assert_eq!(markdown_cell("  + x"), "&#32;&#32;\\+ x");
        assert_eq!(markdown_cell("12. x"), "12\\. x");
        assert_eq!(markdown_cell("3) x"), "3\\) x");
        assert_eq!(markdown_cell("a-b 1.5"), "a-b 1.5");
        assert_eq!(markdown_code(""), "`  `");
    }

    #[test]
    fn csv_cells_are_not_formulas() {
        assert_eq!(csv_cell("=HYPERLINK(\"x\")"), "\"'=HYPERLINK(\"\"x\"\")\"");
        assert_eq!(csv_cell("+1"), "'+1");
        assert_eq!(csv_cell("-x"), "'-x");
        assert_eq!(csv_cell("@SUM(A1)"), "'@SUM(A1)");
        assert_eq!(csv_cell("a,b"), "\"a,b\"");
        assert_eq!(csv_cell("plain"), "plain");
        assert_eq!(csv_cell("line\nbreak"), "line\\nbreak");
    }
}
