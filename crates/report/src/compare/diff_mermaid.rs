//! The diff drawing as a Mermaid flowchart, for `compare --format
//! markdown` (GitHub renders it in a pull-request comment; syntax:
//! mermaid.js.org, "Flowcharts"): the same picture as the DOT diff
//! (`diff_dot.rs`, from the same [`DotOptions`]): b's graph (SPEC §2: one
//! node per vertex, one link per arc), added elements magenta, a's removed
//! ones dashed grey (a removed BT child in its old place among its
//! siblings), kept elements that changed in orange with their old value,
//! transitions coloured by outcome as in the paper's Fig. 4, a title naming
//! both files and a legend.
//!
//! Node ids are generated (`v3` for b's vertex 3, `g0` for a ghost, `l0`
//! for the legend), never taken from input; every label goes through
//! `render::mermaid::label` (quotes, `#`, `<`, `>`, `:` and `;` as entity
//! codes, control characters removed). Drawn only up to
//! [`MAX_NODES`] nodes and [`MAX_LINKS`] links: past them a diagram is
//! unreadable, and Mermaid refuses more than 500 links by default.

use super::Pair;
use btfsm_model::PolicyBody;
use btfsm_model::bt::{Bt, BtNode, BtNodeKind};
use btfsm_model::graph::{ArcKind, PolicyGraph, VertexType};
use btfsm_render::dot::{DotOptions, Highlight};
use btfsm_render::mermaid::{front_matter, label};
use std::collections::HashMap;
use std::fmt::Write;

/// Most nodes (b's vertices and ghosts) of an embedded diff diagram.
pub(super) const MAX_NODES: usize = 150;
/// Most links (b's arcs and ghost arcs) of an embedded diff diagram.
pub(super) const MAX_LINKS: usize = 400;

const ADDED: &str = "stroke:#ff00ff,stroke-width:3px,color:#c000c0";
const REMOVED: &str = "stroke:#999999,stroke-width:1.5px,stroke-dasharray:5 5,color:#999999";
const CHANGED: &str = "stroke:#cd6600,stroke-width:3px,color:#cd6600";

/// Links grouped by style, for `linkStyle` lines.
#[derive(Default)]
struct Links {
    text: String,
    count: usize,
    styles: Vec<(&'static str, Vec<usize>)>,
}

impl Links {
    fn push(
        &mut self,
        from: &str,
        to: &str,
        lbl: &str,
        dashed: bool,
        bt: bool,
        style: Option<&'static str>,
    ) {
        let arrow = match (dashed, bt) {
            (false, false) => "-->",
            (false, true) => "---",
            (true, false) => "-.->",
            (true, true) => "-.-",
        };
        let lbl = label(lbl);
        if lbl.trim().is_empty() {
            let _ = writeln!(self.text, "    {from} {arrow} {to}");
        } else {
            let _ = writeln!(self.text, "    {from} {arrow}|\"{lbl}\"| {to}");
        }
        if let Some(s) = style {
            match self.styles.iter_mut().find(|x| x.0 == s) {
                Some(x) => x.1.push(self.count),
                None => self.styles.push((s, vec![self.count])),
            }
        }
        self.count += 1;
    }
}

/// The stroke of an arc's label as the DOT drawing colours it.
fn arc_style(l: &str, guard: bool) -> Option<&'static str> {
    match l {
        "SUCCESS" => Some("stroke:green,color:green"),
        "FAILURE" => Some("stroke:#cd0000,color:#cd0000"),
        "RUNNING" => Some("stroke:goldenrod,color:goldenrod"),
        _ if guard => Some("stroke:blue,color:blue"),
        _ => None,
    }
}

impl Pair<'_> {
    /// The Mermaid diff of `script`, or the numbers of nodes and links
    /// that make it too large (counted before anything is built).
    pub(super) fn diagram(&self, script: &super::Script) -> Result<String, (usize, usize)> {
        let nodes = self.gb.vertex_count() + script.vertices_removed.len();
        let links = self.gb.arc_count()
            + script
                .arcs_removed
                .iter()
                .map(|a| a.count as usize)
                .sum::<usize>();
        if nodes > MAX_NODES || links > MAX_LINKS {
            return Err((nodes, links));
        }
        self.diff_mermaid(&self.dot_options(script))
            .ok_or((nodes, links))
    }

    /// The Mermaid text of the diff drawn by `opts` (from
    /// [`Pair::dot_options`]), or `None` when it would pass `MAX_NODES`
    /// or `MAX_LINKS`.
    pub fn diff_mermaid(&self, opts: &DotOptions) -> Option<String> {
        let nodes = self.gb.vertex_count() + opts.ghost_vertices.len();
        let links = self.gb.arc_count() + opts.ghost_arcs.len();
        if nodes > MAX_NODES || links > MAX_LINKS {
            return None;
        }
        let bt = match &self.b.policy.body {
            PolicyBody::Bt(bt) => Some(bt),
            PolicyBody::Machine(_) => None,
        };
        let mut chart = Chart {
            out: front_matter(opts.title.as_deref().unwrap_or(&self.b.policy.name)),
            class: Vec::new(),
            id_of: HashMap::new(),
            links: Links::default(),
        };
        chart.out.push_str("flowchart TD\n");
        chart.vertices(&self.gb, bt, opts);
        let ends = chart.ghosts(opts);
        let mut done = vec![false; opts.ghost_arcs.len()];
        match bt {
            Some(b) => chart.bt_links(b, opts, &ends, &mut done),
            None => chart.machine_links(&self.gb, opts),
        }
        for (g, _) in done.iter().enumerate().filter(|x| !*x.1) {
            chart.ghost_link(opts, &ends, g, bt.is_some());
        }
        Some(chart.finish(opts.legend))
    }
}

/// A Mermaid diff being written: the text so far, the nodes of each class
/// (`added`, `removed`, `changed`), the node id of each vertex key, and the
/// links.
struct Chart<'a> {
    out: String,
    class: Vec<(&'static str, String)>,
    id_of: HashMap<&'a str, String>,
    links: Links,
}

impl<'a> Chart<'a> {
    /// b's vertices as nodes `v{i}`: BT nodes with the paper's symbols, a
    /// changed vertex with its old values, each shaped by its type.
    fn vertices(&mut self, gb: &'a PolicyGraph, bt: Option<&Bt>, opts: &DotOptions) {
        for (i, v) in gb.g.raw_nodes().iter().enumerate() {
            let v = &v.weight;
            let mut text = match bt.and_then(|b| b.nodes.get(i)) {
                Some(n) => bt_node_text(n),
                None => label(&v.label),
            };
            if let Some(note) = opts.changed.get(&v.key) {
                for l in note.lines() {
                    let _ = write!(text, "<br/>{}", label(l));
                }
                self.class.push(("changed", format!("v{i}")));
            }
            let (open, close) = shape(v.vtype);
            let _ = writeln!(self.out, "    v{i}{open}{text}{close}");
            if opts.highlight.get(&v.key) == Some(&Highlight::Added) {
                self.class.push(("added", format!("v{i}")));
            }
            self.id_of.insert(v.key.as_str(), format!("v{i}"));
        }
    }

    /// a's removed vertices as nodes `g{k}`, then the ends of the ghost arcs
    /// that are neither theirs nor b's (as DOT draws them: `x{k}`); returns
    /// the node ids of each ghost arc's ends.
    fn ghosts(&mut self, opts: &'a DotOptions) -> Vec<(String, String)> {
        for (k, (key, name)) in opts.ghost_vertices.iter().enumerate() {
            let _ = writeln!(self.out, "    g{k}[\"{}\"]", label(name));
            self.class.push(("removed", format!("g{k}")));
            self.id_of.entry(key.as_str()).or_insert(format!("g{k}"));
        }
        let mut extra = 0usize;
        let mut ends: Vec<(String, String)> = Vec::with_capacity(opts.ghost_arcs.len());
        for (from, to, _) in &opts.ghost_arcs {
            let mut pair = Vec::with_capacity(2);
            for k in [from, to] {
                let id = match self.id_of.get(k.as_str()) {
                    Some(id) => id.clone(),
                    None => {
                        let id = format!("x{extra}");
                        extra += 1;
                        let _ = writeln!(self.out, "    {id}[\"{}\"]", label(k));
                        self.class.push(("removed", id.clone()));
                        self.id_of.insert(k.as_str(), id.clone());
                        id
                    }
                };
                pair.push(id);
            }
            ends.push((pair[0].clone(), pair[1].clone()));
        }
        ends
    }

    /// Ghost arc `g` (its ends' ids in `ends`), dashed grey.
    fn ghost_link(&mut self, opts: &DotOptions, ends: &[(String, String)], g: usize, bt: bool) {
        let (f, t) = &ends[g];
        self.links
            .push(f, t, &opts.ghost_arcs[g].2, true, bt, Some(REMOVED));
    }

    /// A BT's links in preorder, each node's children in order, with the
    /// ghost arcs that have a slot among them in their old place (marked
    /// in `done`).
    fn bt_links(
        &mut self,
        b: &Bt,
        opts: &DotOptions,
        ends: &[(String, String)],
        done: &mut [bool],
    ) {
        let mut slotted: HashMap<&str, Vec<(usize, usize)>> = HashMap::new();
        for (&g, &slot) in &opts.ghost_slot {
            if let Some((from, _, _)) = opts.ghost_arcs.get(g) {
                slotted.entry(from.as_str()).or_default().push((slot, g));
            }
        }
        for u in b.preorder() {
            let mut mine = slotted.remove(b.nodes[u].id.as_str()).unwrap_or_default();
            mine.sort_unstable();
            let mut mine = mine.into_iter().peekable();
            for (k, &c) in b.nodes[u].children.iter().enumerate() {
                while let Some((_, g)) = mine.next_if(|x| x.0 <= k) {
                    self.ghost_link(opts, ends, g, true);
                    done[g] = true;
                }
                let key = (b.nodes[u].id.clone(), b.nodes[c].id.clone(), String::new());
                let style = (opts.arc_label_highlight.get(&key) == Some(&Highlight::Added))
                    .then_some(ADDED);
                self.links
                    .push(&format!("v{u}"), &format!("v{c}"), "", false, true, style);
            }
            for (_, g) in mine {
                self.ghost_link(opts, ends, g, true);
                done[g] = true;
            }
        }
    }

    /// A machine's links, one per arc of b's graph, coloured by outcome or
    /// guard, a changed one with its old label.
    fn machine_links(&mut self, gb: &PolicyGraph, opts: &DotOptions) {
        let verts = gb.g.raw_nodes();
        for e in gb.g.raw_edges() {
            let (t, h) = (e.source().index(), e.target().index());
            let l = e.weight.label();
            let key = (
                verts[t].weight.key.clone(),
                verts[h].weight.key.clone(),
                l.to_string(),
            );
            let mut style = arc_style(l, matches!(e.weight, ArcKind::Guard(_)));
            let mut text = l.to_string();
            if let Some(old) = opts.changed_arcs.get(&key) {
                text = format!("{l} (was {old})");
                style = Some(CHANGED);
            }
            if opts.arc_label_highlight.get(&key) == Some(&Highlight::Added) {
                style = Some(ADDED);
            }
            self.links.push(
                &format!("v{t}"),
                &format!("v{h}"),
                &text,
                false,
                false,
                style,
            );
        }
    }

    /// The text: nodes, links, the legend (if asked for), the links'
    /// styles and the classes.
    fn finish(mut self, legend: bool) -> String {
        let out = &mut self.out;
        out.push_str(&self.links.text);
        if legend {
            out.push_str("    subgraph legend [\"legend\"]\n        direction LR\n");
            out.push_str("        l0[\"added\"]\n        l1[\"removed\"]\n        l2[\"changed<br/>(was#58; old value)\"]\n    end\n");
            self.class.extend([
                ("added", "l0".into()),
                ("removed", "l1".into()),
                ("changed", "l2".into()),
            ]);
        }
        for (style, list) in &self.links.styles {
            let ids: Vec<String> = list.iter().map(ToString::to_string).collect();
            let _ = writeln!(out, "    linkStyle {} {style}", ids.join(","));
        }
        for (name, style) in [("added", ADDED), ("removed", REMOVED), ("changed", CHANGED)] {
            let _ = writeln!(out, "    classDef {name} {style}");
            let ids: Vec<&str> = self
                .class
                .iter()
                .filter(|c| c.0 == name)
                .map(|c| c.1.as_str())
                .collect();
            if !ids.is_empty() {
                let _ = writeln!(out, "    class {} {name}", ids.join(","));
            }
        }
        self.out
    }
}

/// A BT node's text: its label, after the paper's symbol for a control
/// node (with its id when the label is the default one).
fn bt_node_text(n: &BtNode) -> String {
    let symbol = match n.kind {
        BtNodeKind::Sequence => "→",
        BtNodeKind::Fallback => "?",
        BtNodeKind::SequenceMemory => "→*",
        BtNodeKind::FallbackMemory => "?*",
        BtNodeKind::Parallel { .. } => "⇉",
        _ => "",
    };
    match (symbol, n.label == n.kind.default_label()) {
        ("", _) => label(&n.label),
        (s, true) => format!("{s} {}", label(&n.id)),
        (s, false) => format!("{s} {}", label(&n.label)),
    }
}

/// The opening and closing brackets of a node of this vertex type.
fn shape(t: VertexType) -> (&'static str, &'static str) {
    match t {
        VertexType::Action | VertexType::State => ("(\"", "\")"),
        VertexType::Condition | VertexType::ConditionState => ("([\"", "\"])"),
        VertexType::Decorator => ("{{\"", "\"}}"),
        VertexType::Decision => ("{\"", "\"}"),
        VertexType::Container => ("[[\"", "\"]]"),
        VertexType::Outcome => ("(((\"", "\")))"),
        _ => ("[\"", "\"]"),
    }
}

/// The markdown report's diagram section: the Mermaid block, open when the
/// diagram is small, or a line saying why it was left out.
pub(super) fn markdown_section(r: &super::CompareReport) -> String {
    match &r.diagram {
        None => String::new(),
        Some(Ok(text)) => {
            let fence = btfsm_core::sanitize::code_fence(text);
            let open = if text.lines().count() <= 80 {
                " open"
            } else {
                ""
            };
            format!(
                "\n<details{open}><summary>diff diagram: added magenta, removed dashed grey, changed orange</summary>\n\n{fence}mermaid\n{text}{fence}\n\n</details>\n"
            )
        }
        Some(Err((nodes, links))) => format!(
            "\nThe diff diagram is left out: {nodes} nodes and {links} links (at most {MAX_NODES} and {MAX_LINKS} are drawn); `--dot FILE` draws it.\n"
        ),
    }
}
