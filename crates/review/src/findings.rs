//! Which lint findings a change brings: a finding's fingerprint is its
//! rule code, its file (head's path, so that a rename changes nothing), the
//! node it is about and its message with line and column numbers removed,
//! so that a finding whose node only moved to other lines is the same
//! finding in both revisions (as GitHub code scanning matches alerts by
//! `partialFingerprints` rather than by line). A finding is new when head
//! has more findings of its fingerprint than base; fixed likewise.

use btfsm_lint::Finding;
use std::collections::BTreeMap;

/// A finding as the review reports it.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct NewFinding {
    pub code: &'static str,
    pub level: &'static str,
    pub file: String,
    pub line: Option<usize>,
    pub column: Option<usize>,
    /// The node or state it is about.
    pub at: String,
    pub message: String,
    pub fingerprint: String,
}

/// `s` with every number that follows `line `, `column `, `col ` or `:`
/// replaced by `#`.
fn without_positions(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    let mut rest = s;
    while let Some(c) = rest.chars().next() {
        let after_mark = out.ends_with("line ")
            || out.ends_with("column ")
            || out.ends_with("col ")
            || out.ends_with(':');
        if c.is_ascii_digit() && after_mark {
            let n = rest.bytes().take_while(u8::is_ascii_digit).count();
            out.push('#');
            rest = &rest[n..];
        } else {
            out.push(c);
            rest = &rest[c.len_utf8()..];
        }
    }
    out
}

/// The fingerprint of `f`, told as in `file`.
pub fn fingerprint(f: &Finding, file: &str) -> String {
    let text = format!(
        "{}\n{}\n{}\n{}",
        f.code,
        file,
        without_positions(&f.at),
        without_positions(&f.message)
    );
    // FNV-1a, 64 bits: stable across runs and versions (not `Hash`).
    let mut h: u64 = 0xcbf2_9ce4_8422_2325;
    for b in text.bytes() {
        h ^= u64::from(b);
        h = h.wrapping_mul(0x0000_0100_0000_01b3);
    }
    format!("{h:016x}")
}

/// The findings of `head` new over `base` (each counted by fingerprint,
/// base's told as in head's `file`), and how many of base's are gone.
pub fn new_in_head(base: &[Finding], head: &[Finding], file: &str) -> (Vec<NewFinding>, usize) {
    let mut count: BTreeMap<String, i64> = BTreeMap::new();
    for f in base {
        *count.entry(fingerprint(f, file)).or_default() += 1;
    }
    let mut new = Vec::new();
    for f in head {
        let fp = fingerprint(f, file);
        let c = count.entry(fp.clone()).or_default();
        *c -= 1;
        if *c < 0 {
            new.push(NewFinding {
                code: f.code,
                level: f.level.as_str(),
                file: f.file.clone(),
                line: f.line,
                column: f.column,
                at: f.at.clone(),
                message: f.message.clone(),
                fingerprint: fp,
            });
        }
    }
    let fixed = count
        .values()
        .filter(|&&c| c > 0)
        .map(|&c| c as usize)
        .sum();
    (new, fixed)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn finding(file: &str, line: usize, message: &str) -> Finding {
        Finding {
            code: "unknown-node-type",
            level: btfsm_lint::Level::Warning,
            file: file.into(),
            line: Some(line),
            column: Some(3),
            at: "Root/Seq".into(),
            message: message.into(),
            help: String::new(),
            source: None,
        }
    }

    #[test]
    fn a_finding_that_only_moved_lines_is_not_new() {
        let base = [finding("old.xml", 10, "`Foo` at line 10 is unknown")];
        let head = [
            finding("new.xml", 42, "`Foo` at line 42 is unknown"),
            finding("new.xml", 50, "`Bar` is unknown"),
        ];
        let (new, fixed) = new_in_head(&base, &head, "new.xml");
        assert_eq!(new.len(), 1);
        assert_eq!(new[0].message, "`Bar` is unknown");
        assert_eq!(fixed, 0);
        let (new, fixed) = new_in_head(&head, &base, "new.xml");
        assert!(new.is_empty());
        assert_eq!(fixed, 1);
    }

    #[test]
    fn positions_are_removed_and_nothing_else() {
        assert_eq!(
            without_positions("a.xml:12:5 line 7 has 3 kids"),
            "a.xml:#:# line # has 3 kids"
        );
    }
}
