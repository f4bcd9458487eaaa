//! py_trees DOT renders (what `py_trees.display.dot_tree(root)` and
//! `py-trees-render` write, through pydot) read back as Behavior Trees.
//!
//! The mapping is py_trees 2.x's own (`py_trees/display.py`,
//! `dot_tree`: `get_node_attributes` and `get_node_label`; checked against
//! py_trees 2.6.0):
//!
//! - the graph is `digraph pastafarianism` (py_trees' fixed name) with
//!   `ordering=out`; each behaviour is a node statement, added parent first,
//!   and each child an edge `parent -> child` in child order; the first
//!   node is the root;
//! - `shape=octagon` is a Selector (fallback), `box` a Sequence,
//!   `parallelogram` a Parallel, `ellipse` a decorator when it has a child
//!   (py_trees fills it `ghostwhite`) and a behaviour (a leaf) otherwise;
//! - a composite's label is `PREFIX NAME` where `PREFIX` holds `Ⓜ` (or
//!   `M` without unicode) for `memory=True` and `⚡` (`s`) for a
//!   synchronised Parallel, and a Parallel's second label line is its
//!   policy: `SuccessOnAll` (success when all children succeed),
//!   `SuccessOnOne` (one, failing at the first failure), or
//!   `SuccessOnSelected(0, 2)` (only over all of its children);
//! - a leaf whose name ends in `?` is a condition, any other an action
//!   (the first rule of the Python module's `default_leaf_kind`: the class
//!   is not in the render); a decorator's class is not in the render either:
//!   it is a decorator of type `Decorator`;
//! - node names are py_trees names made unique with `*` suffixes (py_trees'
//!   rule); they are the node ids, and the labels.
//!
//! Nodes of the `Blackboard` subgraph (`with_blackboard_variables=True`)
//! and the edges touching them are not part of the tree and are skipped.
//! Everything else that is not of this shape (another graph, a node without
//! a known shape, a node with two parents, a cycle, a node the root does not
//! reach) is an error at its position. The text is tokenised in one pass and
//! the tree built with explicit stacks.

use super::{Limits, Loaded};
use btfsm_core::diagnostic::{Diagnostic, SourceFile};
use btfsm_core::sanitize::shown;
use btfsm_model::{Bt, BtNode, BtNodeKind, Policy, PolicyBody};
use std::collections::{BTreeMap, HashMap};
use std::ops::Range;
use std::sync::Arc;

/// Does a text look like a py_trees render (its graph is
/// `digraph pastafarianism`)?
pub fn looks_like_py_trees_dot(text: &str) -> bool {
    super::head(text).contains("digraph pastafarianism")
}

/// One token of DOT: an identifier or a quoted string (unquoted), or
/// punctuation.
#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Id(String),
    Punct(&'static str),
}

/// The tokens of a DOT text with their spans (comments skipped).
fn tokens(file: &Arc<SourceFile>) -> Result<Vec<(Tok, Range<usize>)>, Diagnostic> {
    let text = &file.text;
    let b = text.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        let start = i;
        if c.is_ascii_whitespace() {
            i += 1;
        } else if text[i..].starts_with("//") || (c == b'#' && (i == 0 || b[i - 1] == b'\n')) {
            i = text[i..].find('\n').map_or(b.len(), |n| i + n);
        } else if text[i..].starts_with("/*") {
            i = text[i + 2..].find("*/").map_or(b.len(), |n| i + 2 + n + 2);
        } else if c == b'"' {
            let mut s = String::new();
            i += 1;
            loop {
                match b.get(i) {
                    None => {
                        return Err(Diagnostic::error("unterminated string")
                            .at(file, start..start + 1)
                            .hint("close the string with `\"`"));
                    }
                    Some(b'"') => break,
                    Some(b'\\') if b.get(i + 1) == Some(&b'"') => {
                        s.push('"');
                        i += 2;
                    }
                    Some(_) => {
                        let ch = text[i..].chars().next().unwrap_or('\u{fffd}');
                        s.push(ch);
                        i += ch.len_utf8();
                    }
                }
            }
            i += 1;
            out.push((Tok::Id(s), start..i));
        } else if c.is_ascii_alphanumeric() || c == b'_' || c == b'.' || c >= 0x80 {
            while i < b.len()
                && (b[i].is_ascii_alphanumeric() || b[i] == b'_' || b[i] == b'.' || b[i] >= 0x80)
            {
                i += 1;
            }
            out.push((Tok::Id(text[start..i].to_string()), start..i));
        } else {
            let p = ["->", "--", "{", "}", "[", "]", ";", ",", "="]
                .into_iter()
                .find(|p| text[i..].starts_with(p));
            let Some(p) = p else {
                let end = i + text[i..].chars().next().map_or(1, char::len_utf8);
                return Err(Diagnostic::error(format!(
                    "unexpected `{}` in DOT",
                    shown(&text[i..end])
                ))
                .at(file, i..end)
                .hint("a py_trees render holds node statements `name [label=..., shape=...];` and edges `parent -> child;`"));
            };
            i += p.len();
            out.push((Tok::Punct(p), start..i));
        }
    }
    Ok(out)
}

/// A node statement: its attributes and where it is.
struct DotNode {
    name: String,
    attrs: HashMap<String, String>,
    span: Range<usize>,
    blackboard: bool,
}

/// The statements of the graph: nodes in order, edges in order.
struct DotGraph {
    nodes: Vec<DotNode>,
    edges: Vec<(String, String, Range<usize>)>,
}

struct Parser<'a> {
    file: &'a Arc<SourceFile>,
    toks: Vec<(Tok, Range<usize>)>,
    at: usize,
}

impl Parser<'_> {
    fn peek(&self) -> Option<&Tok> {
        self.toks.get(self.at).map(|t| &t.0)
    }

    fn span(&self) -> Range<usize> {
        self.toks
            .get(self.at)
            .map_or(self.file.text.len()..self.file.text.len(), |t| t.1.clone())
    }

    fn err(&self, msg: &str, hint: &str) -> Diagnostic {
        Diagnostic::error(msg.to_string())
            .at(self.file, self.span())
            .hint(hint.to_string())
    }

    fn id(&mut self) -> Option<String> {
        match self.peek() {
            Some(Tok::Id(s)) => {
                let s = s.clone();
                self.at += 1;
                Some(s)
            }
            _ => None,
        }
    }

    fn eat(&mut self, p: &str) -> bool {
        if matches!(self.peek(), Some(Tok::Punct(q)) if *q == p) {
            self.at += 1;
            true
        } else {
            false
        }
    }

    /// `[a=b, c=d]` (several lists allowed), or nothing.
    fn attrs(&mut self) -> Result<HashMap<String, String>, Diagnostic> {
        let mut out = HashMap::new();
        while self.eat("[") {
            while !self.eat("]") {
                let (Some(k), true) = (self.id(), self.eat("=")) else {
                    return Err(self.err(
                        "expected `name=value` in an attribute list",
                        "write `[label=\"x\", shape=box]`",
                    ));
                };
                let Some(v) = self.id() else {
                    return Err(self.err(
                        "expected a value after `=`",
                        "write `[label=\"x\", shape=box]`",
                    ));
                };
                out.insert(k, v);
                let _ = self.eat(",") || self.eat(";");
            }
        }
        Ok(out)
    }

    /// The graph: `digraph pastafarianism { statements }`.
    fn graph(&mut self) -> Result<DotGraph, Diagnostic> {
        let hint = "btfsm reads DOT as py_trees draws a tree: `digraph pastafarianism { ... }` (py_trees.display.dot_tree)";
        if self.id().as_deref() != Some("digraph") {
            return Err(self.err("expected `digraph`", hint));
        }
        if self.id().as_deref() != Some("pastafarianism") {
            self.at -= 1;
            return Err(self.err(
                "not a py_trees render: its graph is not named `pastafarianism`",
                hint,
            ));
        }
        if !self.eat("{") {
            return Err(self.err("expected `{`", hint));
        }
        let mut g = DotGraph {
            nodes: Vec::new(),
            edges: Vec::new(),
        };
        // Depth of `subgraph { }` blocks, and whether one is the blackboard's.
        let mut blocks: Vec<bool> = Vec::new();
        loop {
            if self.eat("}") {
                match blocks.pop() {
                    Some(_) => continue,
                    None => break,
                }
            }
            if self.eat(";") {
                continue;
            }
            let start = self.span();
            let Some(first) = self.id() else {
                return Err(self.err("expected a statement", hint));
            };
            if first == "subgraph" {
                let name = if matches!(self.peek(), Some(Tok::Id(_))) {
                    self.id()
                } else {
                    None
                };
                if !self.eat("{") {
                    return Err(self.err("expected `{` after `subgraph`", hint));
                }
                if blocks.len() >= 64 {
                    return Err(self.err("subgraphs nested more than 64 deep", hint));
                }
                let bb = blocks.last().copied().unwrap_or(false)
                    || name.as_deref() == Some("Blackboard");
                blocks.push(bb);
                continue;
            }
            if self.eat("=") {
                self.id();
                continue;
            }
            if self.eat("->") {
                let Some(to) = self.id() else {
                    return Err(self.err("expected a node after `->`", hint));
                };
                if matches!(self.peek(), Some(Tok::Punct("->"))) {
                    return Err(self.err(
                        "unsupported construct: an edge chain `a -> b -> c`",
                        "py_trees writes one edge a statement: `a -> b;`",
                    ));
                }
                self.attrs()?;
                g.edges.push((first, to, start.start..self.span().start));
                continue;
            }
            let attrs = self.attrs()?;
            if !matches!(first.as_str(), "graph" | "node" | "edge") {
                let blackboard = blocks.last().copied().unwrap_or(false);
                g.nodes.push(DotNode {
                    name: first,
                    attrs,
                    span: start,
                    blackboard,
                });
            }
        }
        Ok(g)
    }
}

/// Reads a py_trees DOT render already read.
pub fn load_read(file: Arc<SourceFile>, limits: &Limits) -> Result<Loaded, Vec<Diagnostic>> {
    let toks = tokens(&file).map_err(|d| vec![d])?;
    let mut p = Parser {
        file: &file,
        toks,
        at: 0,
    };
    let g = p.graph().map_err(|d| vec![d])?;
    let mut diags = Vec::new();
    let bt = build(&file, g, limits, &mut diags);
    let policy = bt.map(|bt| Policy {
        name: bt.nodes[bt.root].id.clone(),
        description: None,
        body: PolicyBody::Bt(bt),
    });
    super::finish(&file, policy, diags, "py_trees render")
}

/// Reads a py_trees DOT render from text (tests, fuzzing).
pub fn parse_str(name: &str, text: &str, limits: &Limits) -> Result<Loaded, Vec<Diagnostic>> {
    load_read(SourceFile::new(name, text), limits)
}

/// The tree of a render's nodes and edges.
fn build(
    file: &Arc<SourceFile>,
    g: DotGraph,
    limits: &Limits,
    diags: &mut Vec<Diagnostic>,
) -> Option<Bt> {
    let mut err = |at: Range<usize>, msg: String, hint: &str| {
        diags.push(Diagnostic::error(msg).at(file, at).hint(hint.to_string()));
    };
    let blackboard: std::collections::HashSet<String> = g
        .nodes
        .iter()
        .filter(|n| n.blackboard)
        .map(|n| n.name.clone())
        .collect();
    let nodes: Vec<DotNode> = g.nodes.into_iter().filter(|n| !n.blackboard).collect();
    if nodes.len() > limits.max_nodes {
        err(
            0..0,
            format!("more than {} nodes", limits.max_nodes),
            "raise the limit with --max-nodes",
        );
        return None;
    }
    let mut index: HashMap<&str, usize> = HashMap::new();
    for (i, n) in nodes.iter().enumerate() {
        if index.insert(&n.name, i).is_some() {
            err(
                n.span.clone(),
                format!("node `{}` is declared twice", shown(&n.name)),
                "py_trees makes names unique with `*` suffixes",
            );
            return None;
        }
    }
    if nodes.is_empty() {
        err(
            0..0,
            "this render has no nodes".into(),
            "render a tree with py_trees.display.dot_tree(root)",
        );
        return None;
    }
    let mut children: Vec<Vec<usize>> = vec![Vec::new(); nodes.len()];
    let mut parent: Vec<Option<usize>> = vec![None; nodes.len()];
    for (from, to, at) in &g.edges {
        if blackboard.contains(from) || blackboard.contains(to) {
            continue; // a blackboard key read or written: not the tree
        }
        let (Some(&a), Some(&b)) = (index.get(from.as_str()), index.get(to.as_str())) else {
            let missing = if index.contains_key(from.as_str()) {
                to
            } else {
                from
            };
            err(
                at.clone(),
                format!(
                    "edge to or from `{}`, a node this render does not declare",
                    shown(missing)
                ),
                "py_trees declares every node (`name [label=..., shape=...];`) before its edge",
            );
            return None;
        };
        if parent[b].is_some() || b == 0 {
            err(
                at.clone(),
                format!("node `{}` has two parents", shown(to)),
                "a py_trees render is a tree: each node has one parent",
            );
            return None;
        }
        parent[b] = Some(a);
        children[a].push(b);
    }
    if let Some(n) = unreachable(&children) {
        err(
            nodes[n].span.clone(),
            format!(
                "node `{}` is not below the root `{}`",
                shown(&nodes[n].name),
                shown(&nodes[0].name)
            ),
            "the first node of a py_trees render is the root; every other node is one of its descendants",
        );
        return None;
    }
    let mut out = Vec::with_capacity(nodes.len());
    for (i, n) in nodes.iter().enumerate() {
        let kind = node_kind(n, &children[i], &mut err)?;
        let mut node = BtNode::bare(n.name.clone(), n.name.clone(), kind, children[i].clone());
        node.span = Some(n.span.clone());
        if kind == BtNodeKind::Decorator {
            node.type_name = Some("Decorator".into());
        }
        if matches!(kind, BtNodeKind::Parallel { success: 1 }) && children[i].len() > 1 {
            node.ports = BTreeMap::from([("failure_count".to_string(), "1".to_string())]);
        }
        out.push(node);
    }
    Some(Bt {
        nodes: out,
        root: 0,
    })
}

/// The first node the root (node 0) does not reach, walking `children`
/// with an explicit stack.
fn unreachable(children: &[Vec<usize>]) -> Option<usize> {
    let mut seen = vec![false; children.len()];
    let mut stack = vec![0usize];
    while let Some(n) = stack.pop() {
        if !std::mem::replace(&mut seen[n], true) {
            stack.extend(children[n].iter().copied());
        }
    }
    seen.iter().position(|s| !s)
}

/// A node's type from its shape, label and children.
fn node_kind(
    n: &DotNode,
    kids: &[usize],
    err: &mut impl FnMut(Range<usize>, String, &str),
) -> Option<BtNodeKind> {
    let label = n.attrs.get("label").map_or(n.name.as_str(), String::as_str);
    let mut lines = label.split("\\n");
    let first = lines.next().unwrap_or("");
    let policy = lines.next();
    let prefix = first
        .strip_suffix(n.name.as_str())
        .map(str::trim_end)
        .unwrap_or("");
    let memory = prefix.contains('Ⓜ') || prefix.contains('M');
    let shape = n.attrs.get("shape").map_or("", String::as_str);
    let need_kids = |err: &mut dyn FnMut(Range<usize>, String, &str)| {
        if kids.is_empty() {
            err(
                n.span.clone(),
                format!("composite `{}` has no children", shown(&n.name)),
                "a collapsed render (visibility_level, blackbox) hides children: render with visibility_level=ALL",
            );
            return false;
        }
        true
    };
    Some(match shape {
        "octagon" | "box" => {
            if !need_kids(err) {
                return None;
            }
            match (shape, memory) {
                ("octagon", false) => BtNodeKind::Fallback,
                ("octagon", true) => BtNodeKind::FallbackMemory,
                (_, false) => BtNodeKind::Sequence,
                (_, true) => BtNodeKind::SequenceMemory,
            }
        }
        "parallelogram" => {
            if !need_kids(err) {
                return None;
            }
            let all = BtNodeKind::Parallel {
                success: kids.len(),
            };
            match policy.unwrap_or("") {
                "SuccessOnAll" => all,
                "SuccessOnOne" => BtNodeKind::Parallel { success: 1 },
                p if p.starts_with("SuccessOnSelected(") => {
                    let picked = p
                        .trim_start_matches("SuccessOnSelected(")
                        .trim_end_matches(')');
                    let picked: Vec<&str> = picked
                        .split(',')
                        .map(str::trim)
                        .filter(|s| !s.is_empty())
                        .collect();
                    if picked.len() != kids.len() {
                        err(
                            n.span.clone(),
                            format!(
                                "unsupported construct: Parallel `{}` with SuccessOnSelected over some of its children",
                                shown(&n.name)
                            ),
                            "valid: SuccessOnAll, SuccessOnOne, or SuccessOnSelected over all children (btfsm's parallel counts successes, not which children)",
                        );
                        return None;
                    }
                    all
                }
                other => {
                    err(
                        n.span.clone(),
                        format!("unsupported construct: Parallel policy `{}`", shown(other)),
                        "valid: SuccessOnAll, SuccessOnOne, SuccessOnSelected(...) on the label's second line",
                    );
                    return None;
                }
            }
        }
        "ellipse" => match kids.len() {
            0 if n.name.ends_with('?') => BtNodeKind::Condition,
            0 => BtNodeKind::Action,
            1 => BtNodeKind::Decorator,
            _ => {
                err(
                    n.span.clone(),
                    format!("decorator `{}` has {} children", shown(&n.name), kids.len()),
                    "a py_trees decorator has one child",
                );
                return None;
            }
        },
        other => {
            err(
                n.span.clone(),
                format!("unsupported construct: node shape `{}`", shown(other)),
                "valid: the shapes py_trees draws: octagon (Selector), box (Sequence), parallelogram (Parallel), ellipse (decorator or behaviour)",
            );
            return None;
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use btfsm_model::PolicyBody;

    fn bt(text: &str) -> Bt {
        match parse_str("t.dot", text, &Limits::default()) {
            Ok(l) => match l.policy.body {
                PolicyBody::Bt(bt) => bt,
                PolicyBody::Machine(_) => panic!("a render is a BT"),
            },
            Err(d) => panic!("{d:?}"),
        }
    }

    fn error(text: &str) -> String {
        match parse_str("t.dot", text, &Limits::default()) {
            Ok(_) => panic!("expected an error"),
            Err(d) => d[0].message.clone(),
        }
    }

    /// As py_trees 2.6.0 renders without unicode (`M` for memory) a
    /// Parallel with SuccessOnSelected over all its children, a Selector
    /// with memory, a decorator and leaves, in child order.
    const ASCII: &str = r#"digraph pastafarianism {
ordering=out;
graph [fontname="times-roman"];
par [label="s par\nSuccessOnSelected(0, 1)", shape=parallelogram, style=filled, fillcolor=gold];
sel [label="M sel", shape=octagon, style=filled, fillcolor=cyan];
par -> sel;
"Ok?" [label="Ok?", shape=ellipse, style=filled, fillcolor=gray];
sel -> "Ok?";
"Go!" [label="Go!", shape=ellipse, style=filled, fillcolor=gray];
sel -> "Go!";
inv [label=inv, shape=ellipse, style=filled, fillcolor=ghostwhite];
par -> inv;
"Go!*" [label="Go!*", shape=ellipse, style=filled, fillcolor=gray];
inv -> "Go!*";
}
"#;

    #[test]
    fn shapes_labels_and_edges_make_the_tree() {
        let t = bt(ASCII);
        let kinds: Vec<(&str, BtNodeKind)> =
            t.nodes.iter().map(|n| (n.id.as_str(), n.kind)).collect();
        assert_eq!(
            kinds,
            [
                ("par", BtNodeKind::Parallel { success: 2 }),
                ("sel", BtNodeKind::FallbackMemory),
                ("Ok?", BtNodeKind::Condition),
                ("Go!", BtNodeKind::Action),
                ("inv", BtNodeKind::Decorator),
                ("Go!*", BtNodeKind::Action),
            ]
        );
        assert_eq!(t.nodes[0].children, [1, 4]);
        assert_eq!(t.nodes[1].children, [2, 3]);
        assert_eq!(t.nodes[4].type_name.as_deref(), Some("Decorator"));
    }

    #[test]
    fn what_py_trees_does_not_draw_is_an_error_at_its_position() {
        assert!(error("digraph G { a [shape=box]; }").starts_with("not a py_trees render"));
        let two = ASCII.replace("inv -> \"Go!*\";", "inv -> \"Go!*\";\nsel -> \"Go!*\";");
        assert_eq!(error(&two), "node `Go!*` has two parents");
        let shape = ASCII.replace("shape=octagon", "shape=diamond");
        assert_eq!(error(&shape), "unsupported construct: node shape `diamond`");
        let some = ASCII.replace("SuccessOnSelected(0, 1)", "SuccessOnSelected(1)");
        assert!(error(&some).contains("SuccessOnSelected over some of its children"));
        let lost = ASCII.replace("par -> inv;", "");
        assert_eq!(error(&lost), "node `inv` is not below the root `par`");
        let typo = ASCII.replace("par -> inv;", "par -> inw;");
        assert!(error(&typo).starts_with("edge to or from `inw`"));
        let d = parse_str(
            "t.dot",
            &ASCII.replace("shape=octagon", "shape=diamond"),
            &Limits::default(),
        )
        .unwrap_err();
        let (line, _) = d[0]
            .file
            .as_ref()
            .unwrap()
            .line_col(d[0].span.clone().unwrap().start);
        assert_eq!(line, 5);
    }
}
