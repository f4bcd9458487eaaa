//! XML documents read into an owned arena of elements with byte positions, shared by
//! the BehaviorTree.CPP reader (`btcpp_xml.rs`) and the SCXML reader (`scxml.rs`).
//! Parsing is roxmltree's (W3C XML 1.0 with namespaces); a malformed document
//! becomes one [`Diagnostic`] at the line and column roxmltree reports. Elements
//! are copied out in document order with an iterator, never by recursion, so a
//! deeply nested file cannot overflow the stack.

use btfsm_core::diagnostic::{Diagnostic, SourceFile};
use std::collections::HashMap;
use std::ops::Range;
use std::sync::Arc;

/// The namespace of btfsm's own attributes (`btfsm:id`, read in files
/// older exports wrote; exports now write the comment of [`ID_COMMENT`]).
pub const BTFSM_NS: &str = "urn:btfsm";

/// What opens the comment that gives the next element its node id in an
/// export (`<!-- btfsm:id deliver -->`): BehaviorTree.CPP 4 refuses the
/// attribute `btfsm:id` ("a port with name \[btfsm:id\] is found in the XML
/// but not in the providedPorts()") and skips comments.
pub const ID_COMMENT: &str = "btfsm:id ";

/// An id as written in a comment: XML comments hold no `--` and do not end
/// in `-`, so `%` is written `%25` always and every `-` `%2D` when the id
/// would break the comment ([`id_from_comment`] reads it back).
pub fn id_to_comment(id: &str) -> String {
    let dashes = id.contains("--") || id.ends_with('-');
    let mut out = String::with_capacity(id.len());
    for c in id.chars() {
        match c {
            '%' => out.push_str("%25"),
            '-' if dashes => out.push_str("%2D"),
            c => out.push(c),
        }
    }
    out
}

/// The id a comment's text gives (see [`id_to_comment`]), if it is one.
pub fn id_from_comment(text: &str) -> Option<String> {
    let raw = text.trim().strip_prefix(ID_COMMENT)?.trim();
    if raw.is_empty() {
        return None;
    }
    Some(raw.replace("%2D", "-").replace("%25", "%"))
}

/// One attribute as written.
#[derive(Debug, Clone)]
pub struct XAttr {
    /// Local name (without prefix).
    pub name: String,
    /// Namespace URI, `None` for unprefixed attributes (shared: one
    /// allocation per namespace, not per attribute).
    pub ns: Option<Arc<str>>,
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
    /// Namespace URI (shared, as [`XAttr::ns`]).
    pub ns: Option<Arc<str>>,
    pub attrs: Vec<XAttr>,
    pub children: Vec<usize>,
    /// Byte range of the element's name in its start tag (`<Name`).
    pub span: Range<usize>,
    /// The node id given by the comment just before the element
    /// (`<!-- btfsm:id deliver -->`, only whitespace between), if any.
    pub id_comment: Option<String>,
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

/// At most this many bytes of a name are quoted in a message.
pub const SHOWN_NAME_BYTES: usize = 64;

/// A name as quoted in a message: whole when short, else its first
/// [`SHOWN_NAME_BYTES`] bytes (on a character boundary) and how long it is,
/// so that a 10 MB name gives a message of a hundred bytes.
pub fn shown(s: &str) -> std::borrow::Cow<'_, str> {
    if s.len() <= SHOWN_NAME_BYTES {
        return std::borrow::Cow::Borrowed(s);
    }
    let mut end = SHOWN_NAME_BYTES;
    while !s.is_char_boundary(end) {
        end -= 1;
    }
    std::borrow::Cow::Owned(format!("{}…({} bytes)", &s[..end], s.len()))
}

/// Byte offset of the start tag of the `(n + 1)`-th element (`<name`, in
/// document order; comments, CDATA, processing instructions and end tags
/// skipped), or `None` when the text has at most `n` start tags. One linear
/// pass before parsing, so that a file of millions of elements is refused
/// with a position before any of them is built.
pub fn nth_start_tag(text: &str, n: usize) -> Option<usize> {
    let b = text.as_bytes();
    let mut count = 0usize;
    let mut i = 0usize;
    while let Some(k) = memchr_lt(&b[i..]) {
        let at = i + k;
        let rest = &b[at + 1..];
        let skip_to = |end: &str| text[at..].find(end).map_or(b.len(), |e| at + e + end.len());
        if rest.starts_with(b"!--") {
            i = skip_to("-->");
        } else if rest.starts_with(b"![CDATA[") {
            i = skip_to("]]>");
        } else if rest.starts_with(b"?") {
            i = skip_to("?>");
        } else if rest.starts_with(b"/") || rest.starts_with(b"!") {
            i = at + 1;
        } else {
            if count == n {
                return Some(at);
            }
            count += 1;
            i = at + 1;
        }
    }
    None
}

fn memchr_lt(b: &[u8]) -> Option<usize> {
    b.iter().position(|&c| c == b'<')
}

/// The messages of one reading, at most [`MAX_DIAGNOSTICS`] errors and as
/// many warnings kept, the rest only counted (one message says how many), so
/// that a file of a million bad elements holds a bounded number of messages
/// in memory while it is read, not only when it is reported.
///
/// [`MAX_DIAGNOSTICS`]: super::toml::MAX_DIAGNOSTICS
#[derive(Debug, Default)]
pub struct Sink {
    kept: Vec<Diagnostic>,
    errors: usize,
    warnings: usize,
    dropped_errors: usize,
    dropped_warnings: usize,
    /// Where a dropped message is built (and its hint set) before it is
    /// forgotten.
    scratch: Option<Diagnostic>,
}

impl Sink {
    /// Keeps `d` if there is room for its kind; returns it (or a scratch
    /// copy) so that the caller may add a hint.
    pub fn push(&mut self, d: Diagnostic) -> &mut Diagnostic {
        let cap = super::toml::MAX_DIAGNOSTICS;
        let (kept, dropped) = if d.is_error() {
            (&mut self.errors, &mut self.dropped_errors)
        } else {
            (&mut self.warnings, &mut self.dropped_warnings)
        };
        if *kept >= cap {
            *dropped += 1;
            return self.scratch.insert(d);
        }
        *kept += 1;
        self.kept.push(d);
        self.kept.last_mut().expect("just pushed")
    }

    pub fn extend(&mut self, ds: impl IntoIterator<Item = Diagnostic>) {
        for d in ds {
            self.push(d);
        }
    }

    /// Messages kept.
    pub fn len(&self) -> usize {
        self.kept.len()
    }

    pub fn is_empty(&self) -> bool {
        self.kept.is_empty()
    }

    pub fn has_errors(&self) -> bool {
        self.errors > 0
    }

    /// A mark to [`Sink::demote_since`] from: the messages kept and errors
    /// dropped so far.
    pub fn mark(&self) -> (usize, usize) {
        (self.kept.len(), self.dropped_errors)
    }

    /// Makes the errors pushed since `mark` warnings (problems of a file
    /// nobody asked to read, such as a node model `lint` found).
    pub fn demote_since(&mut self, mark: (usize, usize)) {
        for d in &mut self.kept[mark.0..] {
            if d.is_error() {
                d.severity = btfsm_core::diagnostic::Severity::Warning;
                self.errors -= 1;
                self.warnings += 1;
            }
        }
        let dropped = self.dropped_errors - mark.1;
        self.dropped_errors -= dropped;
        self.dropped_warnings += dropped;
    }

    /// Is there still room for an error (worth a did-you-mean search)?
    pub fn room_for_errors(&self) -> bool {
        self.errors < super::toml::MAX_DIAGNOSTICS
    }

    /// The messages kept, then one per kind saying how many were not kept
    /// (at the end of `file`).
    pub fn into_vec(self, file: &Arc<SourceFile>) -> Vec<Diagnostic> {
        let mut all = self.kept;
        let end = file.text.len()..file.text.len();
        let cap = super::toml::MAX_DIAGNOSTICS;
        if self.dropped_errors > 0 {
            all.push(
                Diagnostic::error(format!(
                    "{} more errors not shown (the first {cap} messages are)",
                    self.dropped_errors
                ))
                .at(file, end.clone()),
            );
        }
        if self.dropped_warnings > 0 {
            all.push(
                Diagnostic::warning(format!("{} more warnings not shown", self.dropped_warnings))
                    .at(file, end),
            );
        }
        all
    }
}

/// Parses a source file into an element arena of at most `left` elements:
/// more is an error at the first element beyond, saying that the files read
/// hold more than `limit` elements (`--max-nodes`; `left` is what remains of
/// it after the files read before).
pub fn parse(file: &Arc<SourceFile>, left: usize, limit: usize) -> Result<XDoc, Diagnostic> {
    parse_text(file, &file.text, None, left, limit)
}

/// [`parse`], reading what BehaviorTree.CPP's tinyxml2 reads although it is
/// not well-formed ([`super::xml_lenient`]): the document, and a warning per
/// place repaired. Anything else is the strict parser's error.
pub fn parse_lenient(
    file: &Arc<SourceFile>,
    left: usize,
    limit: usize,
) -> Result<(XDoc, Vec<Diagnostic>), Diagnostic> {
    match parse(file, left, limit) {
        Ok(d) => Ok((d, Vec::new())),
        Err(strict) if strict.message.starts_with("malformed XML") => {
            let Some((text, map, fixes)) = super::xml_lenient::repair(&file.text) else {
                return Err(strict);
            };
            match parse_text(file, &text, Some(&map), left, limit) {
                Ok(d) => Ok((d, super::xml_lenient::warnings(file, &fixes))),
                Err(_) => Err(strict),
            }
        }
        Err(e) => Err(e),
    }
}

/// Parses `text` (the file's text, or a repair of it whose offsets `map`
/// takes back to the file's).
fn parse_text(
    file: &Arc<SourceFile>,
    text: &str,
    map: Option<&super::xml_lenient::OffsetMap>,
    left: usize,
    limit: usize,
) -> Result<XDoc, Diagnostic> {
    let back = |r: std::ops::Range<usize>| match map {
        Some(m) => m.range(r),
        None => r,
    };
    let max_elems = left;
    if let Some(at) = nth_start_tag(&file.text, max_elems) {
        let end = at + 1 + qname_len(&file.text[at..]);
        return Err(Diagnostic::error(format!(
            "more than {limit} elements (every element of every file read counts, in used and unused trees alike)"
        ))
        .at(file, at..end)
        .hint("raise the limit with --max-nodes"));
    }
    // Elements are bounded above; text, comments and processing
    // instructions between them are nodes too (a backstop on memory).
    let nodes_limit =
        u32::try_from(max_elems.saturating_mul(4).saturating_add(1024)).unwrap_or(u32::MAX);
    let opts = roxmltree::ParsingOptions {
        allow_dtd: false,
        nodes_limit,
        ..Default::default()
    };
    let doc = roxmltree::Document::parse_with_options(text, opts).map_err(|e| {
        if matches!(e, roxmltree::Error::NodesLimitReached) {
            return Diagnostic::error(format!(
                "more than {nodes_limit} XML nodes (elements, text, comments) in this file"
            ))
            .at(file, 0..1)
            .hint("raise the limit with --max-nodes");
        }
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
    // Arena index of each roxmltree node (by its id; usize::MAX: no element).
    let mut index: Vec<usize> = vec![usize::MAX; doc.descendants().len()];
    let mut namespaces: HashMap<String, Arc<str>> = HashMap::new();
    let mut intern = |ns: Option<&str>| -> Option<Arc<str>> {
        let u = ns?;
        if let Some(a) = namespaces.get(u) {
            return Some(a.clone());
        }
        let a: Arc<str> = Arc::from(u);
        namespaces.insert(u.to_string(), a.clone());
        Some(a)
    };
    for n in doc.descendants().filter(|n| n.is_element()) {
        let i = elems.len();
        if let Some(slot) = index.get_mut(n.id().get_usize()) {
            *slot = i;
        }
        let start = n.range().start;
        let tag = n.tag_name();
        elems.push(XElem {
            name: tag.name().to_string(),
            ns: intern(tag.namespace()),
            attrs: n
                .attributes()
                .map(|a| XAttr {
                    name: a.name().to_string(),
                    ns: intern(a.namespace()),
                    value: a.value().to_string(),
                    span: back(a.range()),
                })
                .collect(),
            children: Vec::new(),
            span: back(start..(start + 1 + qname_len(&text[start..]))),
            id_comment: id_comment_before(n),
        });
        if let Some(p) = n.parent_element()
            && let Some(&pi) = index.get(p.id().get_usize())
            && pi != usize::MAX
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

/// The id of an [`ID_COMMENT`] comment before element `n`, only
/// whitespace between them.
fn id_comment_before(n: roxmltree::Node<'_, '_>) -> Option<String> {
    let mut p = n.prev_sibling();
    while let Some(x) = p {
        if x.is_comment() {
            return x.text().and_then(id_from_comment);
        }
        if !(x.is_text() && x.text().is_some_and(|t| t.trim().is_empty())) {
            return None;
        }
        p = x.prev_sibling();
    }
    None
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
        if let Some(e) = btfsm_core::sanitize::entity(c) {
            out.push_str(e);
            continue;
        }
        match c {
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

/// Test helper (the readers' and `btfsm-fuzzing`'s mutation tests): `seed`
/// with each `(at, delete, insert)` edit applied (offsets wrap around; edits
/// that would split a character are skipped).
#[doc(hidden)]
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
        let d = parse(&f, 100, 100).unwrap_err();
        let (_, line, col) = d.location().unwrap();
        assert_eq!(line, 2);
        assert!(col > 10, "column {col}");
        assert!(d.message.starts_with("malformed XML"), "{}", d.message);
    }

    #[test]
    fn elements_in_document_order_with_children() {
        let f = SourceFile::new("t.xml", "<a x=\"1\"><b/><c><d/></c></a>");
        let d = parse(&f, 100, 100).unwrap();
        let names: Vec<&str> = d.elems.iter().map(|e| e.name.as_str()).collect();
        assert_eq!(names, ["a", "b", "c", "d"]);
        assert_eq!(d.elems[0].children, vec![1, 2]);
        assert_eq!(d.elems[2].children, vec![3]);
        assert_eq!(d.elems[0].attr("x"), Some("1"));
        assert_eq!(&f.text[d.elems[2].span.clone()], "<c");
    }

    #[test]
    fn elements_beyond_the_limit_are_refused_at_the_first_one_beyond() {
        let text = "<a>\n<!-- <x/> --><![CDATA[<y/>]]><?pi <z/>?>\n  <b/><c/>\n  <d/>\n</a>";
        let f = SourceFile::new("t.xml", text);
        assert!(parse(&f, 4, 4).is_ok());
        let d = parse(&f, 3, 10).unwrap_err();
        assert_eq!(d.location().unwrap().1, 4, "{d}");
        assert_eq!(&f.text[d.span.clone().unwrap()], "<d");
        assert!(
            d.message.starts_with("more than 10 elements"),
            "{}",
            d.message
        );
        assert_eq!(nth_start_tag(text, 0), Some(0));
        assert_eq!(nth_start_tag(text, 4), None);
    }

    #[test]
    fn the_sink_keeps_a_bounded_number_of_messages() {
        let f = SourceFile::new("t.xml", "<a/>");
        let cap = crate::toml::MAX_DIAGNOSTICS;
        let mut sink = Sink::default();
        for i in 0..100_000 {
            sink.push(Diagnostic::error(format!("e{i}")).at(&f, 0..1))
                .hint = Some("h".into());
            sink.push(Diagnostic::warning(format!("w{i}")));
        }
        assert_eq!(sink.len(), 2 * cap);
        assert!(sink.has_errors() && !sink.room_for_errors());
        let all = sink.into_vec(&f);
        assert_eq!(all.len(), 2 * cap + 2);
        assert_eq!(
            all[2 * cap].message,
            format!(
                "{} more errors not shown (the first {cap} messages are)",
                100_000 - cap
            )
        );
        assert_eq!(
            all[2 * cap + 1].message,
            format!("{} more warnings not shown", 100_000 - cap)
        );
    }

    #[test]
    fn long_names_are_shown_truncated() {
        assert_eq!(shown("short"), "short");
        let long = "é".repeat(1000);
        let s = shown(&long);
        assert!(s.len() < 100, "{s}");
        assert!(s.ends_with("…(2000 bytes)"), "{s}");
    }

    #[test]
    fn offsets_of_rows_and_columns() {
        assert_eq!(offset_of("ab\ncd", 2, 2), 4);
        assert_eq!(offset_of("ab\ncd", 1, 1), 0);
    }
}
