//! DOT statements and attributes: quoting and escaping of ids and labels
//! (Graphviz's "DOT language" and "HTML-like labels" grammars), the
//! attribute lists of nodes and edges.

use super::*;
use graphviz_rust::dot_structures::{
    Attribute, Edge, EdgeTy, Id, Node, NodeId, Stmt, Subgraph, Vertex,
};

/// `s` as a DOT double-quoted string: `"` and `\` escaped, line breaks as `\n`
/// (a centred line break in labels), other control characters and
/// bidirectional controls as spaces.
pub(super) fn quote(s: &str) -> String {
    let mut out = String::with_capacity(s.len() + 2);
    out.push('"');
    for c in s.chars() {
        match c {
            '"' => out.push_str("\\\""),
            '\\' => out.push_str("\\\\"),
            '\n' => out.push_str("\\n"),
            '\r' => {}
            c if c.is_control() || btfsm_core::sanitize::is_unsafe(c, false) => out.push(' '),
            c => out.push(c),
        }
    }
    out.push('"');
    out
}

/// `s` as text of a Graphviz HTML-like label: `&`, `<`, `>` and `"` as
/// entities, line breaks as `<BR/>`, other control characters and
/// bidirectional controls as spaces.
pub(super) fn html(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        if let Some(e) = btfsm_core::sanitize::entity(c) {
            out.push_str(e);
            continue;
        }
        match c {
            '\n' => out.push_str("<BR/>"),
            '\r' => {}
            c if c.is_control() || btfsm_core::sanitize::is_unsafe(c, false) => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

/// A DOT id: bare when it is a plain identifier or number, else quoted.
pub(super) fn dot_id(s: &str) -> Id {
    let ident = s
        .chars()
        .next()
        .is_some_and(|c| c.is_ascii_alphabetic() || c == '_')
        && s.chars().all(|c| c.is_ascii_alphanumeric() || c == '_')
        && !["node", "edge", "graph", "digraph", "subgraph", "strict"]
            .iter()
            .any(|k| k.eq_ignore_ascii_case(s));
    let number = !s.is_empty()
        && s.chars().all(|c| c.is_ascii_digit() || c == '.')
        && s.chars().filter(|&c| c == '.').count() <= 1
        && s != ".";
    if ident || number {
        Id::Plain(s.to_string())
    } else {
        Id::Escaped(quote(s))
    }
}

pub(super) fn node_id(s: &str) -> NodeId {
    NodeId(dot_id(s), None)
}

/// An ordered attribute list; `set` replaces a previous value in place.
#[derive(Default)]
pub(super) struct Attrs {
    list: Vec<(&'static str, String)>,
    styles: Vec<&'static str>,
    /// Lines drawn under the label in a smaller grey font (a BT node's type
    /// under its custom name, its ports): the label becomes HTML-like.
    sub: Vec<String>,
    /// A line over the label in a larger font (a control node's symbol over
    /// its name): the label becomes HTML-like.
    head: Option<String>,
}

impl Attrs {
    pub(super) fn set(&mut self, key: &'static str, value: &str) -> &mut Self {
        match self.list.iter_mut().find(|(k, _)| *k == key) {
            Some(slot) => slot.1 = value.to_string(),
            None => self.list.push((key, value.to_string())),
        }
        self
    }

    /// Sets a line over the label, larger.
    pub(super) fn head(&mut self, line: String) -> &mut Self {
        self.head = Some(line);
        self
    }

    /// Adds a line under the label, smaller and grey.
    pub(super) fn sub(&mut self, line: String) -> &mut Self {
        self.sub.push(line);
        self
    }

    pub(super) fn style(&mut self, s: &'static str) -> &mut Self {
        if !self.styles.contains(&s) {
            self.styles.push(s);
        }
        self
    }

    /// Marks a kept element that changed: [`CHANGED`] outline and text,
    /// `note` (the old values) under its label.
    pub(super) fn changed(&mut self, note: Option<&String>) {
        let Some(note) = note else { return };
        let label = self
            .list
            .iter()
            .find(|(k, _)| *k == "label")
            .map(|(_, v)| v.clone())
            .unwrap_or_default();
        self.set("label", &format!("{label}\n{note}"))
            .set("color", CHANGED)
            .set("fontcolor", CHANGED)
            .set("penwidth", "2.5");
    }

    pub(super) fn unstyle(&mut self, s: &'static str) -> &mut Self {
        self.styles.retain(|x| *x != s);
        self
    }

    /// Applies a highlight to a node's attributes.
    pub(super) fn node_highlight(&mut self, h: Option<&Highlight>) {
        match h {
            None => {}
            Some(Highlight::Added) => {
                self.set("color", ADDED)
                    .set("fontcolor", ADDED)
                    .set("penwidth", "2.5");
            }
            Some(Highlight::Removed) => {
                self.unstyle("filled").unstyle("bold").style("dashed");
                self.set("color", REMOVED).set("fontcolor", REMOVED);
            }
            Some(Highlight::Status(s)) => {
                self.style("filled").set("fillcolor", s.fill_color());
            }
        }
    }

    /// Applies a highlight to an edge's attributes.
    pub(super) fn edge_highlight(&mut self, h: Option<&Highlight>) {
        match h {
            None => {}
            Some(Highlight::Added) => {
                self.set("color", ADDED)
                    .set("fontcolor", ADDED)
                    .set("penwidth", "2");
            }
            Some(Highlight::Removed) => {
                self.style("dashed")
                    .set("color", REMOVED)
                    .set("fontcolor", REMOVED);
            }
            Some(Highlight::Status(s)) => {
                self.set("color", s.line_color())
                    .set("fontcolor", s.line_color())
                    .set("penwidth", "3");
            }
        }
    }

    pub(super) fn into_vec(self) -> Vec<Attribute> {
        let (sub, head) = (self.sub, self.head);
        let mut v: Vec<Attribute> = self
            .list
            .into_iter()
            .map(|(k, val)| {
                let value = if k == "label" && (!sub.is_empty() || head.is_some()) {
                    let mut text = String::from("<");
                    if let Some(h) = &head {
                        text.push_str(&format!(
                            "<FONT POINT-SIZE=\"{HEAD_FONT_SIZE}\">{}</FONT><BR/>",
                            html(h)
                        ));
                    }
                    if sub.is_empty() {
                        // Ends as `</FONT>>`, as HTML-like labels usually
                        // do (some DOT readers look for `>>`).
                        text.push_str(&format!("<FONT>{}</FONT>", html(&val)));
                    } else {
                        text.push_str(&html(&val));
                    }
                    if !sub.is_empty() {
                        let lines: Vec<String> = sub.iter().map(|l| html(l)).collect();
                        text.push_str(&format!(
                            "<BR/><FONT POINT-SIZE=\"{SUB_FONT_SIZE}\" COLOR=\"{SUB_COLOR}\">{}</FONT>",
                            lines.join("<BR/>")
                        ));
                    }
                    text.push('>');
                    Id::Html(text)
                } else {
                    dot_id(&val)
                };
                Attribute(Id::Plain(k.to_string()), value)
            })
            .collect();
        if !self.styles.is_empty() {
            v.push(Attribute(
                Id::Plain("style".into()),
                dot_id(&self.styles.join(",")),
            ));
        }
        v
    }
}

/// A node statement; its SVG element's `id` is its DOT node id (the vertex
/// key for vertices), so that a page can find it.
pub(super) fn node_stmt(id: &str, mut attrs: Attrs) -> Stmt {
    attrs.set("id", id);
    Stmt::Node(Node::new(node_id(id), attrs.into_vec()))
}

pub(super) fn edge_stmt(from: &str, to: &str, attrs: Attrs) -> Stmt {
    Stmt::Edge(Edge {
        ty: EdgeTy::Pair(Vertex::N(node_id(from)), Vertex::N(node_id(to))),
        attributes: attrs.into_vec(),
    })
}

/// `{rank=same; a; b}` (or another rank) as an anonymous subgraph.
pub(super) fn rank_group(rank: &str, ids: &[String]) -> Stmt {
    let mut stmts = vec![Stmt::Attribute(Attribute(
        Id::Plain("rank".into()),
        Id::Plain(rank.into()),
    ))];
    stmts.extend(
        ids.iter()
            .map(|i| Stmt::Node(Node::new(node_id(i), vec![]))),
    );
    Stmt::Subgraph(Subgraph {
        id: Id::Anonymous(String::new()),
        stmts,
    })
}

// ---------------------------------------------------------------------------
// Ids of the SVG elements (`btfsm view`)

/// `prefix` and the bytes of `s`: ASCII letters and digits kept, every other
/// byte as `-` and two hex digits; one-to-one, and a valid HTML/SVG id.
fn encoded_id(prefix: &str, s: &str) -> String {
    let mut out = String::with_capacity(prefix.len() + s.len());
    out.push_str(prefix);
    for b in s.bytes() {
        if b.is_ascii_alphanumeric() {
            out.push(b as char);
        } else {
            out.push_str(&format!("-{b:02x}"));
        }
    }
    out
}

/// The text of a DOT id as printed (quoted when it is not plain).
fn id_text(id: &Id) -> &str {
    match id {
        Id::Plain(s) | Id::Escaped(s) | Id::Html(s) | Id::Anonymous(s) => s,
    }
}

/// The SVG element id of the DOT node of a vertex key (with
/// [`DotOptions::svg_ids`]): distinct keys give distinct ids.
pub fn svg_id(key: &str) -> String {
    encoded_id("v_", id_text(&dot_id(key)))
}

/// The SVG element id of an HFSM container's cluster, by its key.
pub fn svg_cluster_id(key: &str) -> String {
    encoded_id("c_", id_text(&dot_id(key)))
}

/// Sets `id` on every DOT node below `stmts` (clusters included, walked
/// with a stack).
pub(super) fn set_svg_ids(stmts: &mut [Stmt]) {
    let mut stack: Vec<&mut [Stmt]> = vec![stmts];
    while let Some(list) = stack.pop() {
        for s in list {
            match s {
                Stmt::Node(n) => {
                    // Replaces the plain `id` every node has (the key).
                    let id = encoded_id("v_", id_text(&n.id.0));
                    n.attributes.retain(|Attribute(k, _)| id_text(k) != "id");
                    n.attributes
                        .push(Attribute(Id::Plain("id".into()), dot_id(&id)));
                }
                Stmt::Subgraph(sg) => stack.push(&mut sg.stmts),
                _ => {}
            }
        }
    }
}
