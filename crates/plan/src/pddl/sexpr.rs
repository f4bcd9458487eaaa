//! A small S-expression reader for PDDL (McDermott et al. 1998, "PDDL —
//! the Planning Domain Definition Language", sec. 2: the syntax is Lisp
//! lists of names; `;` starts a comment to the end of the line), keeping
//! the byte span of every atom and list so that each error points at its
//! line and column.
//!
//! Why not a crate: `pddl` (crates.io, sunsided) parses PDDL 3.1 with
//! nom but its syntax tree keeps no positions, so an undeclared predicate
//! or a refused requirement could not be reported at its place (the
//! project's one rule for errors: file:line:col, snippet, caret); the
//! subset `btfsm plan` reads (docs/guide/plan.md, "PDDL domains") is small
//! enough to read from plain lists.
//!
//! Bounded: at most [`MAX_DEPTH`] nested lists and [`MAX_NODES`] atoms and
//! lists, read without recursion; names are ASCII-lowercased (PDDL names are
//! case-insensitive).

use btfsm_core::diagnostic::{Diagnostic, SourceFile};
use std::ops::Range;
use std::sync::Arc;

/// Deepest nesting of lists read.
pub const MAX_DEPTH: usize = 64;
/// Most atoms and lists in one file.
pub const MAX_NODES: usize = 200_000;
/// Longest atom, in bytes.
pub const MAX_ATOM: usize = 256;

/// An atom (a name, variable, keyword or number) or a list, with its span.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Sexp {
    Atom(String, Range<usize>),
    List(Vec<Sexp>, Range<usize>),
}

impl Sexp {
    pub fn span(&self) -> Range<usize> {
        match self {
            Sexp::Atom(_, s) | Sexp::List(_, s) => s.clone(),
        }
    }

    /// The atom's text, `None` for a list.
    pub fn atom(&self) -> Option<&str> {
        match self {
            Sexp::Atom(a, _) => Some(a),
            Sexp::List(..) => None,
        }
    }

    /// The list's items, `None` for an atom.
    pub fn list(&self) -> Option<&[Sexp]> {
        match self {
            Sexp::List(items, _) => Some(items),
            Sexp::Atom(..) => None,
        }
    }

    /// The first item of a list when it is an atom (`and` of `(and ...)`).
    pub fn head(&self) -> Option<&str> {
        self.list()?.first()?.atom()
    }
}

/// Reads every top-level expression of `file`.
pub fn read(file: &Arc<SourceFile>) -> Result<Vec<Sexp>, Diagnostic> {
    let text = file.text.as_bytes();
    let err = |span: Range<usize>, msg: &str, hint: &str| {
        Diagnostic::error(msg.to_string())
            .at(file, span)
            .hint(hint.to_string())
    };
    // Open lists: (start offset, items so far).
    let mut stack: Vec<(usize, Vec<Sexp>)> = Vec::new();
    let mut top: Vec<Sexp> = Vec::new();
    let mut nodes = 0usize;
    let mut i = 0;
    while i < text.len() {
        let c = text[i];
        match c {
            b';' => {
                while i < text.len() && text[i] != b'\n' {
                    i += 1;
                }
                continue;
            }
            b'(' => {
                if stack.len() >= MAX_DEPTH {
                    return Err(err(
                        i..i + 1,
                        &format!("lists nested deeper than {MAX_DEPTH}"),
                        "a PDDL domain or problem nests a few levels",
                    ));
                }
                stack.push((i, Vec::new()));
                i += 1;
                continue;
            }
            b')' => {
                let Some((start, items)) = stack.pop() else {
                    return Err(err(
                        i..i + 1,
                        "`)` closes no list",
                        "remove it, or open its list with `(`",
                    ));
                };
                let list = Sexp::List(items, start..i + 1);
                match stack.last_mut() {
                    Some((_, up)) => up.push(list),
                    None => top.push(list),
                }
                i += 1;
            }
            c if c.is_ascii_whitespace() => {
                i += 1;
                continue;
            }
            _ => {
                let start = i;
                while i < text.len()
                    && !text[i].is_ascii_whitespace()
                    && !matches!(text[i], b'(' | b')' | b';')
                {
                    i += 1;
                }
                let span = start..i;
                if i - start > MAX_ATOM {
                    return Err(err(
                        span,
                        &format!("a name longer than {MAX_ATOM} bytes"),
                        "PDDL names are short words",
                    ));
                }
                let atom = Sexp::Atom(file.text[span.clone()].to_ascii_lowercase(), span);
                match stack.last_mut() {
                    Some((_, up)) => up.push(atom),
                    None => top.push(atom),
                }
            }
        }
        nodes += 1;
        if nodes > MAX_NODES {
            return Err(err(
                i.saturating_sub(1)..i,
                &format!("more than {MAX_NODES} names and lists"),
                "split the file",
            ));
        }
    }
    if let Some((start, _)) = stack.last() {
        return Err(err(
            *start..start + 1,
            "this `(` is never closed",
            "close it with `)`",
        ));
    }
    Ok(top)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse(text: &str) -> Result<Vec<Sexp>, Diagnostic> {
        read(&SourceFile::new("t.pddl", text))
    }

    #[test]
    fn atoms_and_lists_keep_their_spans_and_comments_are_skipped() {
        let t = "; comment (\n(define (Domain X) ; more\n  (:types a b - c))";
        let top = parse(t).unwrap();
        assert_eq!(top.len(), 1);
        let items = top[0].list().unwrap();
        assert_eq!(items[0].atom(), Some("define"));
        assert_eq!(items[1].head(), Some("domain"));
        // Names are lowercased; spans point into the original text.
        let x = &items[1].list().unwrap()[1];
        assert_eq!(x.atom(), Some("x"));
        assert_eq!(&t[x.span()], "X");
        assert_eq!(top[0].span(), 12..t.len());
        // `(at start(not(p)))`: no space needed before `(`.
        let top = parse("(at start(not(p ?x)))").unwrap();
        let l = top[0].list().unwrap();
        assert_eq!(l.len(), 3);
        assert_eq!(l[2].head(), Some("not"));
    }

    #[test]
    fn unbalanced_and_too_deep_input_is_an_error_with_its_position() {
        let f = SourceFile::new("t.pddl", "(a\n  (b)");
        let e = read(&f).unwrap_err();
        assert_eq!(e.message, "this `(` is never closed");
        assert_eq!(e.location(), Some(("t.pddl".into(), 1, 1)));
        let f = SourceFile::new("t.pddl", "(a))");
        let e = read(&f).unwrap_err();
        assert_eq!(e.message, "`)` closes no list");
        assert_eq!(e.location(), Some(("t.pddl".into(), 1, 4)));
        let deep = "(".repeat(MAX_DEPTH + 1) + &")".repeat(MAX_DEPTH + 1);
        let e = parse(&deep).unwrap_err();
        assert!(e.message.contains("nested deeper than 64"), "{}", e.message);
        let long = "x".repeat(MAX_ATOM + 1);
        assert!(parse(&long).unwrap_err().message.contains("longer than"));
        // A huge flat list stops at the node cap, whatever the depth.
        let many = format!("({})", "a ".repeat(MAX_NODES + 1));
        assert!(parse(&many).unwrap_err().message.contains("more than"));
    }
}
