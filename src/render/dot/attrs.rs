//! DOT statements and attributes: quoting and escaping of ids and labels,
//! the attribute lists of nodes and edges, and a BT node's look.

use super::*;
use crate::model::BtNodeKind;
use crate::model::bt::BtNode;
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
            c if c.is_control() || crate::sanitize::is_unsafe(c, false) => out.push(' '),
            c => out.push(c),
        }
    }
    out.push('"');
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
}

impl Attrs {
    pub(super) fn set(&mut self, key: &'static str, value: &str) -> &mut Self {
        match self.list.iter_mut().find(|(k, _)| *k == key) {
            Some(slot) => slot.1 = value.to_string(),
            None => self.list.push((key, value.to_string())),
        }
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
        let mut v: Vec<Attribute> = self
            .list
            .into_iter()
            .map(|(k, val)| Attribute(Id::Plain(k.to_string()), dot_id(&val)))
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

pub(super) fn node_stmt(id: &str, attrs: Attrs) -> Stmt {
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
// Building the diagram

/// Shape and label of a BT node.
pub(super) fn bt_node_attrs(n: &BtNode) -> Attrs {
    let mut a = Attrs::default();
    let custom = n.label != n.kind.default_label() && Some(&n.label) != n.type_name.as_ref();
    // Ports of imported nodes (BehaviorTree.CPP), one `name=value` line each.
    let ports: String = n.ports.iter().map(|(k, v)| format!("\n{k}={v}")).collect();
    let control = |a: &mut Attrs, symbol: String| {
        let label = if custom {
            format!("{symbol}\n{}{ports}", n.label)
        } else {
            format!("{symbol}{ports}")
        };
        a.set("label", &label)
            .set("shape", "box")
            .set("fontsize", if custom { "11" } else { "15" })
            .set("width", "0.45")
            .set("height", "0.4")
            .set("margin", "0.06,0.03");
    };
    match n.kind {
        BtNodeKind::Sequence => control(&mut a, "→".into()),
        BtNodeKind::Fallback => control(&mut a, "?".into()),
        BtNodeKind::SequenceMemory => control(&mut a, "→*".into()),
        BtNodeKind::FallbackMemory => control(&mut a, "?*".into()),
        BtNodeKind::Parallel { success } => {
            control(&mut a, format!("⇉ {success}/{}", n.children.len()))
        }
        BtNodeKind::Control => control(
            &mut a,
            n.type_name.clone().unwrap_or_else(|| n.label.clone()),
        ),
        BtNodeKind::Inverter
        | BtNodeKind::ForceSuccess
        | BtNodeKind::ForceFailure
        | BtNodeKind::Repeat { .. }
        | BtNodeKind::Retry { .. }
        | BtNodeKind::Timeout { .. }
        | BtNodeKind::Decorator => {
            let param = match n.kind {
                BtNodeKind::Repeat { times: Some(t) } | BtNodeKind::Retry { times: t } => {
                    format!("\n×{t}")
                }
                BtNodeKind::Repeat { times: None } => "\n×∞".to_string(),
                BtNodeKind::Timeout { ms } => format!("\n{ms} ms"),
                _ => String::new(),
            };
            a.set("label", &format!("{}{param}{ports}", n.label))
                .set("shape", "diamond")
                .set("fillcolor", DECISION_FILL)
                .set("fontsize", "9")
                .set("margin", "0.02,0.02")
                .style("filled");
        }
        BtNodeKind::Action => {
            a.set("label", &format!("{}{ports}", n.label))
                .set("shape", "ellipse")
                .set("fillcolor", ACTION_FILL)
                .style("filled");
        }
        BtNodeKind::Condition => {
            a.set("label", &format!("{}{ports}", n.label))
                .set("shape", "ellipse")
                .set("fillcolor", "white")
                .set("fontname", "Helvetica-Oblique")
                .style("filled");
        }
    }
    let tip = match &n.skill {
        Some(c) => format!("{}: {c}", n.id),
        None => n.id.clone(),
    };
    a.set("tooltip", &tip);
    a
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
                    let id = encoded_id("v_", id_text(&n.id.0));
                    n.attributes
                        .push(Attribute(Id::Plain("id".into()), dot_id(&id)));
                }
                Stmt::Subgraph(sg) => stack.push(&mut sg.stmts),
                _ => {}
            }
        }
    }
}
