//! DOT diagrams of policies in the paper's visual language, and rendering them
//! with Graphviz.
//!
//! What is drawn is the policy's graph of SPEC §2, one DOT node per vertex and one
//! DOT edge per arc, so that a picture can be counted like the paper counts:
//!
//! - BT (Fig. 1): control nodes are boxes labelled `→` (Sequence), `?` (Fallback),
//!   `→*` / `?*` (with memory) and `⇉ k/N` (Parallel with its success threshold),
//!   other control types boxes with their type; decorators are hexagons with
//!   their name and parameter; actions are filled rounded boxes, conditions
//!   white ellipses in italics (Groot's convention). A node with a name of
//!   its own shows its type in small grey under it; ports are in the
//!   tooltip (under the label with [`DotOptions::ports`]). Subtrees can be
//!   folded into one double-bordered node with their size (see `bt.rs`).
//!   The tree is drawn with children in order (`ordering=out`), top-down, or
//!   left-to-right when top-down would be too wide ([`RankDir`]).
//! - FSM (Fig. 4): states are ovals, decision states (SELECTOR) diamonds, the
//!   initial state has a bold border and, as in UML, an arrow from a filled
//!   dot (the start dot, DOT node [`START`], neither a vertex nor an arc:
//!   its edge has `class=start`); terminal outcomes are double circles.
//!   Arcs carry their outcome or guard label and are coloured like the
//!   paper's Fig. 4: RUNNING goldenrod, SUCCESS green, FAILURE red, guards
//!   blue (the label says what the colour means, so no legend is drawn; a
//!   drawing with status fills, `dot --trace`, has a status legend). A
//!   decision state's self-loop hangs below it, clear of its guard arcs.
//! - HFSM (Fig. 6): every container is a cluster holding its states. The
//!   container's own vertex is the small dot at the top of its cluster (arcs into
//!   the container end at the cluster's border; the dot's arc goes to the initial
//!   child, so every level marks its initial state as UML does). The regions
//!   of a parallel state are dashed clusters inside it. The container's
//!   outcomes are small boxes at the bottom of the cluster: a transition to
//!   a container outcome points at that box, and the container's own
//!   transitions leave from it. These outcome boxes and the start dot are
//!   the only DOT nodes that are not graph vertices.
//!
//! DOT node ids are the graph's vertex keys (BT node id, state path
//! `Container/Child`, outcome name), quoted and escaped, so that a diagram can be
//! matched with `compare`'s edit scripts ([`DotOptions`] highlights vertices
//! and arcs by key and draws removed ones as dashed grey ghosts). Every node
//! also has the DOT attribute `id` set to its node id, so that in Graphviz's
//! SVG the node's `<g>` element has `id` = the vertex key (control
//! characters and bidirectional controls replaced by spaces, as every
//! string is; a page colours nodes by `getElementById(key)`). Output is
//! deterministic: everything is emitted in model order. HFSM clusters nested
//! deeper than 48 levels are drawn beside their parent's cluster, so that
//! neither the printer nor Graphviz recurse without bound.

mod attrs;
mod bt;
mod builder;
mod graphviz;
#[cfg(test)]
mod tests;

use attrs::*;
pub use attrs::{svg_cluster_id, svg_id};
pub use bt::{FoldError, MAX_ASPECT, RankDir, check_fold};
use builder::*;
pub use graphviz::*;

use btfsm_model::{Policy, PolicyBody, StateBody};
use graphviz_rust::dot_structures::{Graph, GraphAttributes, Stmt};
use graphviz_rust::printer::{DotPrinter, PrinterContext};
use std::collections::BTreeMap;

/// A return status, as the paper colours it (Fig. 4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Status {
    Running,
    Success,
    Failure,
}

impl Status {
    /// The status an outcome name stands for (`SUCCESS`, `FAILURE`, `RUNNING`).
    pub fn from_outcome(name: &str) -> Option<Status> {
        match name {
            "RUNNING" => Some(Status::Running),
            "SUCCESS" => Some(Status::Success),
            "FAILURE" => Some(Status::Failure),
            _ => None,
        }
    }

    /// Colour of arcs and outlines with this status.
    fn line_color(self) -> &'static str {
        match self {
            Status::Running => "goldenrod",
            Status::Success => "green4",
            Status::Failure => "red3",
        }
    }

    /// Fill of a node highlighted with this status (an SVG/CSS colour name
    /// too: `btfsm view` paints with it).
    pub fn fill_color(self) -> &'static str {
        match self {
            Status::Running => "gold",
            Status::Success => "palegreen",
            Status::Failure => "tomato",
        }
    }
}

/// How one element is emphasised (by `compare` and by the simulator).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Highlight {
    /// An element the edit added: drawn magenta (as the paper's Fig. 8), a
    /// colour no transition label uses.
    Added,
    /// An element the edit removed: drawn dashed grey.
    Removed,
    /// The element's current status: RUNNING yellow, SUCCESS green, FAILURE red
    /// fill (arcs in the status colour, thick).
    Status(Status),
}

/// What to emphasise in a diagram; the default draws the plain policy.
#[derive(Debug, Clone, Default)]
pub struct DotOptions {
    /// Per-vertex highlight, by vertex key (BT node id, state path, outcome).
    pub highlight: BTreeMap<String, Highlight>,
    /// Per-arc highlight, by `(from key, to key)` of the graph arc (every
    /// parallel arc between the two is highlighted). An HFSM arc to a container's
    /// outcome has the container's key as `to`.
    pub arc_highlight: BTreeMap<(String, String), Highlight>,
    /// Per-arc highlight of the arcs with one label, by `(from key, to key,
    /// label)`: the outcome or guard label, `"initial"` for an HFSM container's
    /// arc to its initial child, `""` for a BT edge. Wins over `arc_highlight`
    /// (the simulator highlights the one transition taken).
    pub arc_label_highlight: BTreeMap<(String, String, String), Highlight>,
    /// Removed vertices, drawn dashed grey: `(key, label)`. In an HFSM a ghost
    /// whose key starts with a container's key and `/` is drawn in its cluster.
    pub ghost_vertices: Vec<(String, String)>,
    /// Removed arcs, drawn dashed grey: `(from key, to key, label)`.
    pub ghost_arcs: Vec<(String, String, String)>,
    /// Where ghost arcs of a BT go among their tail's children: index in
    /// `ghost_arcs` -> how many of the tail's children come before it (the
    /// removed child's place among its siblings). Others come after all.
    pub ghost_slot: BTreeMap<usize, usize>,
    /// Kept vertices that changed (type, binding, arguments, order), by key:
    /// drawn in [`CHANGED`] with these lines (`was: fallback`) under their
    /// label.
    pub changed: BTreeMap<String, String>,
    /// Kept arcs whose label changed, by `(from key, to key, label)`: the
    /// old label, drawn as `(was ...)` in [`CHANGED`].
    pub changed_arcs: BTreeMap<(String, String, String), String>,
    /// The diagram's title instead of the policy's name.
    pub title: Option<String>,
    /// Adds a legend of the diff colours (added, removed, changed).
    pub legend: bool,
    /// Gives every DOT node the attribute `id` = [`svg_id`] of its DOT node
    /// id, and every HFSM container's cluster [`svg_cluster_id`] of its key,
    /// so that the SVG Graphviz renders can be scripted (`btfsm view`).
    pub svg_ids: bool,
    /// BT: draws each node's ports under its label (they are always in its
    /// tooltip).
    pub ports: bool,
    /// BT: nodes drawn folded, by id: one node standing for the subtree.
    pub collapse: std::collections::BTreeSet<String>,
    /// BT: folds every node at this depth (the root is at depth 0).
    pub depth: Option<usize>,
    /// BT: folds the root of every SubTree (BehaviorTree.CPP `<SubTree>`,
    /// TOML `subtree` include).
    pub fold_subtrees: bool,
    /// BT: the direction of the layout.
    pub rankdir: RankDir,
}

const FONT: &str = "Helvetica";
/// The DOT node id of an FSM's start dot (made unique if a state has it).
pub const START: &str = "__start";
/// The font of the lines under a label (a node's type, ports, a folded
/// subtree's size).
const SUB_FONT_SIZE: &str = "8";
const SUB_COLOR: &str = "#555555";
/// The font of a control node's symbol over its name.
const HEAD_FONT_SIZE: &str = "15";
const ACTION_FILL: &str = "#dce8f7";
const DECISION_FILL: &str = "#eeeeee";
const ADDED: &str = "magenta";
/// Kept elements an edit changed (relabels, reorders): no status, guard or
/// diff colour uses it.
pub const CHANGED: &str = "darkorange3";
const REMOVED: &str = "grey55";
const GUARD: &str = "blue";
/// Clusters nested deeper than this are drawn beside their parent's cluster
/// instead of inside it (Graphviz and the printer recurse on nesting).
const MAX_CLUSTER_NESTING: usize = 48;

/// The legend of a drawing coloured by status: one sample node per status,
/// side by side in a cluster of their own. The fills are written in hex
/// (the same colours), so that a count of `fillcolor=gold` counts nodes.
fn status_legend(b: &mut Builder) -> Stmt {
    let mut ca = Attrs::default();
    ca.set("label", "status at this step")
        .set("fontname", FONT)
        .set("fontsize", "9")
        .set("color", "grey70")
        .style("rounded");
    let mut stmts: Vec<Stmt> = ca.into_vec().into_iter().map(Stmt::Attribute).collect();
    let mut ids = Vec::new();
    for (name, fill) in [
        ("RUNNING", "#ffd700"),
        ("SUCCESS", "#98fb98"),
        ("FAILURE", "#ff6347"),
    ] {
        let id = b.fresh(&format!("legend: {name}"));
        let mut a = Attrs::default();
        a.set("label", name)
            .set("shape", "box")
            .set("fontsize", "9")
            .set("height", "0.3")
            .set("fillcolor", fill)
            .style("rounded")
            .style("filled");
        stmts.push(node_stmt(&id, a));
        ids.push(id);
    }
    stmts.push(rank_group("same", &ids));
    Stmt::Subgraph(graphviz_rust::dot_structures::Subgraph {
        id: dot_id("cluster legend"),
        stmts,
    })
}

/// DOT text of a policy in the paper's visual language.
pub fn policy_dot(policy: &Policy, opts: &DotOptions) -> String {
    let mut b = Builder::new(opts);
    let mut graph_attrs = Attrs::default();
    graph_attrs.set("label", opts.title.as_deref().unwrap_or(&policy.name));
    graph_attrs.set("labelloc", "t");
    graph_attrs.set("fontname", FONT);
    graph_attrs.set("fontsize", "14");
    match &policy.body {
        PolicyBody::Bt(bt) => {
            let view = bt::View::new(bt, opts);
            graph_attrs.set("ordering", "out");
            let rankdir = view.rankdir(bt, opts);
            if rankdir != "TB" {
                graph_attrs.set("rankdir", rankdir);
            }
            graph_attrs.set("nodesep", "0.25");
            graph_attrs.set("ranksep", "0.45");
            b.bt(bt, &view);
        }
        PolicyBody::Machine(m) => {
            // Room between states for the arcs' labels of dense machines
            // (the paper's Fig. 8e, 16b), looked at in PNG.
            graph_attrs.set("nodesep", "0.6");
            graph_attrs.set("ranksep", "0.5");
            if m.states
                .iter()
                .any(|s| matches!(s.body, StateBody::Container(_)))
            {
                graph_attrs.set("compound", "true");
            }
            b.machine(m);
        }
    }
    b.ghosts();
    b.assemble();
    if opts.svg_ids {
        set_svg_ids(&mut b.root);
    }
    if opts.legend {
        let legend = b.legend();
        b.root.push(legend);
    } else if opts
        .highlight
        .values()
        .any(|h| matches!(h, Highlight::Status(_)))
    {
        // Fills say a status no label writes (`dot --trace`): say which.
        let legend = status_legend(&mut b);
        b.root.push(legend);
    }

    let mut node_defaults = Attrs::default();
    node_defaults.set("fontname", FONT);
    node_defaults.set("fontsize", "11");
    let mut edge_defaults = Attrs::default();
    edge_defaults.set("fontname", FONT);
    edge_defaults.set("fontsize", "9");
    edge_defaults.set("arrowsize", "0.7");
    if matches!(policy.body, PolicyBody::Bt(_)) {
        edge_defaults.set("arrowhead", "none");
    }

    let mut stmts = vec![
        Stmt::GAttribute(GraphAttributes::Graph(graph_attrs.into_vec())),
        Stmt::GAttribute(GraphAttributes::Node(node_defaults.into_vec())),
        Stmt::GAttribute(GraphAttributes::Edge(edge_defaults.into_vec())),
    ];
    stmts.append(&mut b.root);
    stmts.append(&mut b.edges);
    let graph = Graph::DiGraph {
        id: dot_id(&policy.name),
        strict: false,
        stmts,
    };
    let mut text = graph.print(&mut PrinterContext::default());
    text.push('\n');
    text
}
