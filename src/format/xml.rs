//! XML documents read into an owned arena of elements with byte positions, shared by
//! the BehaviorTree.CPP reader (`btcpp_xml.rs`) and the SCXML reader (`scxml.rs`).
//! Parsing is roxmltree's (W3C XML 1.0 with namespaces); a malformed document
//! becomes one [`Diagnostic`] at the line and column roxmltree reports. Elements
//! are copied out in document order with an iterator, never by recursion, so a
//! deeply nested file cannot overflow the stack.

use crate::diagnostic::{Diagnostic, SourceFile};
use std::collections::HashMap;
use std::ops::Range;
use std::sync::Arc;

/// The namespace of btfsm's own attributes in exported files (`btfsm:id`).
pub const BTFSM_NS: &str = "urn:btfsm";

/// One attribute as written.
#[derive(Debug, Clone)]
pub struct XAttr {
    /// Local name (without prefix).
    pub name: String,
    /// Namespace URI, `None` for unprefixed attributes.
    pub ns: Option<String>,
    pub value: String,
    /// Byte range of the whole `name="value"`.
    pub span: Range<usize>,
}

/// One element: its name, attributes and child elements (text and comments are
/// dropped).
#[derive(Debug, Clone)]
pub struct XElem {
    /// Local name (without prefix).
    pub name: String,
    pub ns: Option<String>,
    pub attrs: Vec<XAttr>,
    pub children: Vec<usize>,
    /// Byte range of the element's name in its start tag (`<Name`).
    pub span: Range<usize>,
}

impl XElem {
    /// Value of an unprefixed attribute.
    pub fn attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|a| a.ns.is_none() && a.name == name)
            .map(|a| a.value.as_str())
    }

    /// An unprefixed attribute with its position.
    pub fn attr_full(&self, name: &str) -> Option<&XAttr> {
        self.attrs.iter().find(|a| a.ns.is_none() && a.name == name)
    }

    /// Value of an attribute in btfsm's namespace.
    pub fn btfsm_attr(&self, name: &str) -> Option<&str> {
        self.attrs
            .iter()
            .find(|a| a.ns.as_deref() == Some(BTFSM_NS) && a.name == name)
            .map(|a| a.value.as_str())
    }
}

/// A parsed document; `elems[root]` is the document element.
#[derive(Debug, Clone)]
pub struct XDoc {
    pub file: Arc<SourceFile>,
    pub elems: Vec<XElem>,
    pub root: usize,
}

impl XDoc {
    /// Child elements of `e` in a given namespace (`None`: unprefixed or the
    /// default namespace `default_ns`).
    pub fn children<'a>(&'a self, e: usize) -> impl Iterator<Item = (usize, &'a XElem)> + 'a {
        self.elems[e]
            .children
            .iter()
            .map(move |&c| (c, &self.elems[c]))
    }
}

/// Parses a source file into an element arena.
pub fn parse(file: &Arc<SourceFile>) -> Result<XDoc, Diagnostic> {
    let opts = roxmltree::ParsingOptions {
        allow_dtd: false,
        ..Default::default()
    };
    let doc = roxmltree::Document::parse_with_options(&file.text, opts).map_err(|e| {
        let pos = e.pos();
        let off = offset_of(&file.text, pos.row as usize, pos.col as usize);
        let msg = e.to_string();
        // roxmltree appends " at ROW:COL"; the diagnostic shows the position.
        let msg = match msg.rfind(" at ") {
            Some(i) if msg[i + 4..].contains(':') => msg[..i].to_string(),
            _ => msg,
        };
        Diagnostic::error(format!("malformed XML: {}", lower_first(&msg)))
            .at(file, off..off + 1)
            .hint("the file must be well-formed XML (every attribute `name=\"value\"`, separated by spaces; tags closed in order)")
    })?;
    let mut elems: Vec<XElem> = Vec::new();
    let mut index: HashMap<roxmltree::NodeId, usize> = HashMap::new();
    for n in doc.descendants().filter(|n| n.is_element()) {
        let i = elems.len();
        index.insert(n.id(), i);
        let start = n.range().start;
        let tag = n.tag_name();
        elems.push(XElem {
            name: tag.name().to_string(),
            ns: tag.namespace().map(str::to_string),
            attrs: n
                .attributes()
                .map(|a| XAttr {
                    name: a.name().to_string(),
                    ns: a.namespace().map(str::to_string),
                    value: a.value().to_string(),
                    span: a.range(),
                })
                .collect(),
            children: Vec::new(),
            span: start..(start + 1 + qname_len(&file.text[start..])),
        });
        if let Some(p) = n.parent_element()
            && let Some(&pi) = index.get(&p.id())
        {
            elems[pi].children.push(i);
        }
    }
    Ok(XDoc {
        file: file.clone(),
        elems,
        root: 0,
    })
}

/// Length of the qualified name after `<` at the start of `s`.
fn qname_len(s: &str) -> usize {
    s.get(1..)
        .map(|rest| {
            rest.find(|c: char| c.is_whitespace() || c == '>' || c == '/')
                .unwrap_or(rest.len())
        })
        .unwrap_or(0)
}

/// Byte offset of a 1-based row and column (in characters).
pub fn offset_of(text: &str, row: usize, col: usize) -> usize {
    let mut off = 0;
    for (i, line) in text.split_inclusive('\n').enumerate() {
        if i + 1 == row {
            return off
                + line
                    .char_indices()
                    .nth(col.saturating_sub(1))
                    .map_or(line.len(), |(b, _)| b);
        }
        off += line.len();
    }
    text.len()
}

fn lower_first(s: &str) -> String {
    let mut c = s.chars();
    match c.next() {
        Some(f) => f.to_lowercase().chain(c).collect(),
        None => String::new(),
    }
}

/// Escapes text for an attribute value in double quotes.
pub fn escape_attr(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\n' => out.push_str("&#10;"),
            '\t' => out.push_str("&#9;"),
            '\r' => out.push_str("&#13;"),
            c => out.push(c),
        }
    }
    out
}

/// Escapes text for an XML comment (no `--`).
pub fn escape_comment(s: &str) -> String {
    s.replace("--", "- -")
}

/// Test helper: `seed` with each `(at, delete, insert)` edit applied (offsets
/// wrap around; edits that would split a character are skipped).
#[cfg(test)]
pub fn mutate(seed: &str, cuts: &[(usize, usize, String)]) -> String {
    let mut text = seed.to_string();
    for (at, del, ins) in cuts {
        let at = at % (text.len() + 1);
        let end = (at + del).min(text.len());
        if text.is_char_boundary(at) && text.is_char_boundary(end) {
            text.replace_range(at..end, ins);
        }
    }
    text
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn attribute_without_separating_space_is_positioned() {
        let f = SourceFile::new("t.xml", "<root>\n  <Action ID=\"A\"name=\"x\"/>\n</root>\n");
        let d = parse(&f).unwrap_err();
        let (_, line, col) = d.location().unwrap();
        assert_eq!(line, 2);
        assert!(col > 10, "column {col}");
        assert!(d.message.starts_with("malformed XML"), "{}", d.message);
    }

    #[test]
    fn elements_in_document_order_with_children() {
        let f = SourceFile::new("t.xml", "<a x=\"1\"><b/><c><d/></c></a>");
        let d = parse(&f).unwrap();
        let names: Vec<&str> = d.elems.iter().map(|e| e.name.as_str()).collect();
        assert_eq!(names, ["a", "b", "c", "d"]);
        assert_eq!(d.elems[0].children, vec![1, 2]);
        assert_eq!(d.elems[2].children, vec![3]);
        assert_eq!(d.elems[0].attr("x"), Some("1"));
        assert_eq!(&f.text[d.elems[2].span.clone()], "<c");
    }

    #[test]
    fn offsets_of_rows_and_columns() {
        assert_eq!(offset_of("ab\ncd", 2, 2), 4);
        assert_eq!(offset_of("ab\ncd", 1, 1), 0);
    }
}
