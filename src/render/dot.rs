//! DOT diagrams of policies in the paper's visual language, and rendering them
//! with Graphviz.
//!
//! What is drawn is the policy's graph of SPEC §2, one DOT node per vertex and one
//! DOT edge per arc, so that a picture can be counted like the paper counts:
//!
//! - BT (Fig. 1): control nodes are boxes labelled `→` (Sequence), `?` (Fallback),
//!   `→*` / `?*` (with memory) and `⇉ k/N` (Parallel with its success threshold);
//!   decorators are diamonds with their name and parameter; actions are filled
//!   ovals, conditions white ovals in italics. The tree is drawn top-down with
//!   children in order (`ordering=out`).
//! - FSM (Fig. 4): states are ovals, decision states (SELECTOR) diamonds, the
//!   initial state has a bold border, terminal outcomes are double circles. Arcs
//!   carry their outcome or guard label and are coloured like the paper's Fig. 4:
//!   RUNNING goldenrod, SUCCESS green, FAILURE red, guards blue. A decision
//!   state's self-loop hangs below it, clear of its guard arcs.
//! - HFSM (Fig. 6): every container is a cluster holding its states. The
//!   container's own vertex is the small dot at the top of its cluster (arcs into
//!   the container end at the cluster's border; the dot's arc goes to the initial
//!   child). The container's outcomes are small boxes at the bottom of the
//!   cluster: a transition to a container outcome points at that box, and the
//!   container's own transitions leave from it. These outcome boxes are the only
//!   DOT nodes that are not graph vertices.
//!
//! DOT node ids are the graph's vertex keys (BT node id, state path
//! `Container/Child`, outcome name), quoted and escaped, so that a diagram can be
//! matched with `compare`'s edit scripts ([`DotOptions`] highlights vertices
//! and arcs by key and draws removed ones as dashed grey ghosts). Output is
//! deterministic: everything is emitted in model order. HFSM clusters nested
//! deeper than 48 levels are drawn beside their parent's cluster, so that
//! neither the printer nor Graphviz recurse without bound.

use crate::model::bt::BtNode;
use crate::model::{Bt, BtNodeKind, Policy, PolicyBody, StateBody, StateMachine, Target, Trigger};
use graphviz_rust::dot_structures::{
    Attribute, Edge, EdgeTy, Graph, GraphAttributes, Id, Node, NodeId, Stmt, Subgraph, Vertex,
};
use graphviz_rust::printer::{DotPrinter, PrinterContext};
use std::collections::{BTreeMap, HashMap, HashSet};
use std::io::Write;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

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

    /// Fill of a node highlighted with this status.
    fn fill_color(self) -> &'static str {
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
}

const FONT: &str = "Helvetica";
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
            graph_attrs.set("ordering", "out");
            graph_attrs.set("nodesep", "0.25");
            graph_attrs.set("ranksep", "0.45");
            b.bt(bt);
        }
        PolicyBody::Machine(m) => {
            graph_attrs.set("nodesep", "0.4");
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
    if opts.legend {
        let legend = b.legend();
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

/// An output format of [`render`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, clap::ValueEnum)]
pub enum RenderFormat {
    Svg,
    Png,
    Pdf,
}

impl RenderFormat {
    /// The file extension (and Graphviz `-T` name).
    pub fn extension(self) -> &'static str {
        match self {
            RenderFormat::Svg => "svg",
            RenderFormat::Png => "png",
            RenderFormat::Pdf => "pdf",
        }
    }

    /// The format an output file's extension asks for (`x.svg`, `x.PNG`,
    /// `x.pdf`); `None` for anything else (`x.dot`, `x.gv`, no extension),
    /// which gets DOT text.
    pub fn from_path(path: &std::path::Path) -> Option<RenderFormat> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        [RenderFormat::Svg, RenderFormat::Png, RenderFormat::Pdf]
            .into_iter()
            .find(|f| f.extension() == ext)
    }
}

impl std::fmt::Display for RenderFormat {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.extension())
    }
}

/// Why Graphviz could not render a diagram.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error("graphviz `{program}` is not installed (apt-get install graphviz)")]
    NotInstalled { program: String },
    #[error("graphviz `{program}` failed ({status}): {stderr}")]
    Failed {
        program: String,
        status: String,
        stderr: String,
    },
    #[error(
        "graphviz `{program}` did not finish within {ms} ms and was stopped (give it more time with --timeout-ms)"
    )]
    Timeout { program: String, ms: u128 },
    #[error("graphviz `{program}` wrote more than {limit} bytes and was stopped")]
    TooLarge { program: String, limit: u64 },
    #[error("cannot run graphviz `{program}`: {source}")]
    Io {
        program: String,
        #[source]
        source: std::io::Error,
    },
}

/// Graphviz's time budget where the command has no `--timeout-ms` of its
/// own meaning (`dot --render`'s default).
pub const DEFAULT_RENDER_TIMEOUT_MS: u64 = 60_000;

/// Most bytes of a rendered diagram read from Graphviz: past them the child
/// is killed and the run fails.
pub const MAX_RENDER_BYTES: u64 = 256 << 20;

/// Most bytes of Graphviz's stderr kept for the message (the rest is read
/// and dropped, so that the child never blocks on it).
pub const MAX_RENDER_STDERR_BYTES: u64 = 64 << 10;

/// What a Graphviz run may take.
#[derive(Debug, Clone, Copy)]
struct Budget {
    timeout: Duration,
    max_output: u64,
    max_stderr: u64,
}

impl Budget {
    fn new(timeout: Duration) -> Budget {
        Budget {
            timeout,
            max_output: MAX_RENDER_BYTES,
            max_stderr: MAX_RENDER_STDERR_BYTES,
        }
    }
}

/// Renders DOT to svg/png/pdf by running Graphviz's `dot` as a child killed
/// after `timeout` or [`MAX_RENDER_BYTES`] of output; a clear error when
/// `dot` is not installed.
pub fn render(dot: &str, format: RenderFormat, timeout: Duration) -> Result<Vec<u8>, RenderError> {
    render_with("dot", dot, format, timeout)
}

/// [`render`] with another Graphviz program (a full path, or `neato`, ...).
pub fn render_with(
    program: &str,
    dot: &str,
    format: RenderFormat,
    timeout: Duration,
) -> Result<Vec<u8>, RenderError> {
    run_graphviz(program, dot, format, Budget::new(timeout)).map(|(out, _warnings)| out)
}

/// What the threads around a Graphviz child report.
enum Piped {
    /// Its input written (or not).
    Stdin(std::io::Result<()>),
    /// Its output, at most `max_output + 1` bytes.
    Stdout(std::io::Result<Vec<u8>>),
    /// Its first `max_stderr` bytes of stderr.
    Stderr(std::io::Result<Vec<u8>>),
}

/// Runs a Graphviz program on `dot`: its output and its warnings (stderr).
/// Input is fed and output read by threads, so that a child that does not
/// read, or writes a lot, cannot dead-lock us; the child is killed past the
/// budget's deadline or output size, without waiting for its pipes.
fn run_graphviz(
    program: &str,
    dot: &str,
    format: RenderFormat,
    budget: Budget,
) -> Result<(Vec<u8>, String), RenderError> {
    use std::io::Read;
    use std::sync::mpsc;
    let io = |source: std::io::Error| RenderError::Io {
        program: program.to_string(),
        source,
    };
    let start = Instant::now();
    // No deadline when the budget passes the clock's range.
    let deadline = start.checked_add(budget.timeout);
    let mut child = Command::new(program)
        .arg(format!("-T{}", format.extension()))
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .map_err(|e| match e.kind() {
            std::io::ErrorKind::NotFound => RenderError::NotInstalled {
                program: program.to_string(),
            },
            _ => io(e),
        })?;
    let (tx, rx) = mpsc::channel();
    let (mut stdin, stdout, stderr) = (
        child.stdin.take().expect("stdin is piped"),
        child.stdout.take().expect("stdout is piped"),
        child.stderr.take().expect("stderr is piped"),
    );
    let input = dot.as_bytes().to_vec();
    let t = tx.clone();
    std::thread::spawn(move || {
        let r = stdin.write_all(&input);
        drop(stdin);
        let _ = t.send(Piped::Stdin(r));
    });
    let t = tx.clone();
    std::thread::spawn(move || {
        let mut v = Vec::new();
        let r = stdout
            .take(budget.max_output.saturating_add(1))
            .read_to_end(&mut v);
        let _ = t.send(Piped::Stdout(r.map(|_| v)));
    });
    std::thread::spawn(move || {
        let mut v = Vec::new();
        let mut err = stderr;
        let r = (&mut err).take(budget.max_stderr).read_to_end(&mut v);
        // Drained, not kept.
        let _ = std::io::copy(&mut err, &mut std::io::sink());
        let _ = tx.send(Piped::Stderr(r.map(|_| v)));
    });
    let stop = |child: &mut std::process::Child| {
        let _ = child.kill();
        let _ = child.wait();
    };
    let (mut written, mut out, mut err, mut status) = (None, None, None, None);
    while written.is_none() || out.is_none() || err.is_none() || status.is_none() {
        let now = Instant::now();
        if deadline.is_some_and(|d| now >= d) {
            stop(&mut child);
            return Err(RenderError::Timeout {
                program: program.to_string(),
                ms: budget.timeout.as_millis(),
            });
        }
        let wait = deadline.map_or(Duration::from_millis(20), |d| {
            (d - now).min(Duration::from_millis(20))
        });
        match rx.recv_timeout(wait) {
            Ok(Piped::Stdin(r)) => written = Some(r),
            Ok(Piped::Stdout(r)) => {
                if r.as_ref().is_ok_and(|v| v.len() as u64 > budget.max_output) {
                    stop(&mut child);
                    return Err(RenderError::TooLarge {
                        program: program.to_string(),
                        limit: budget.max_output,
                    });
                }
                out = Some(r);
            }
            Ok(Piped::Stderr(r)) => err = Some(r),
            Err(mpsc::RecvTimeoutError::Timeout) => {}
            // Every thread has reported: only the exit is awaited.
            Err(mpsc::RecvTimeoutError::Disconnected) => std::thread::sleep(wait),
        }
        if status.is_none() {
            status = child.try_wait().map_err(io)?;
        }
    }
    let (Some(status), Some(written), Some(out), Some(err)) = (status, written, out, err) else {
        unreachable!("the loop ends when all are known");
    };
    let stderr = String::from_utf8_lossy(&err.map_err(io)?)
        .trim()
        .to_string();
    if !status.success() {
        return Err(RenderError::Failed {
            program: program.to_string(),
            status: status.to_string(),
            stderr,
        });
    }
    written.map_err(io)?;
    Ok((out.map_err(io)?, stderr))
}

// ---------------------------------------------------------------------------
// DOT syntax helpers

/// `s` as a DOT double-quoted string: `"` and `\` escaped, line breaks as `\n`
/// (a centred line break in labels), other control characters and
/// bidirectional controls as spaces.
fn quote(s: &str) -> String {
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
fn dot_id(s: &str) -> Id {
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

fn node_id(s: &str) -> NodeId {
    NodeId(dot_id(s), None)
}

/// An ordered attribute list; `set` replaces a previous value in place.
#[derive(Default)]
struct Attrs {
    list: Vec<(&'static str, String)>,
    styles: Vec<&'static str>,
}

impl Attrs {
    fn set(&mut self, key: &'static str, value: &str) -> &mut Self {
        match self.list.iter_mut().find(|(k, _)| *k == key) {
            Some(slot) => slot.1 = value.to_string(),
            None => self.list.push((key, value.to_string())),
        }
        self
    }

    fn style(&mut self, s: &'static str) -> &mut Self {
        if !self.styles.contains(&s) {
            self.styles.push(s);
        }
        self
    }

    /// Marks a kept element that changed: [`CHANGED`] outline and text,
    /// `note` (the old values) under its label.
    fn changed(&mut self, note: Option<&String>) {
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

    fn unstyle(&mut self, s: &'static str) -> &mut Self {
        self.styles.retain(|x| *x != s);
        self
    }

    /// Applies a highlight to a node's attributes.
    fn node_highlight(&mut self, h: Option<&Highlight>) {
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
    fn edge_highlight(&mut self, h: Option<&Highlight>) {
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

    fn into_vec(self) -> Vec<Attribute> {
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

fn node_stmt(id: &str, attrs: Attrs) -> Stmt {
    Stmt::Node(Node::new(node_id(id), attrs.into_vec()))
}

fn edge_stmt(from: &str, to: &str, attrs: Attrs) -> Stmt {
    Stmt::Edge(Edge {
        ty: EdgeTy::Pair(Vertex::N(node_id(from)), Vertex::N(node_id(to))),
        attributes: attrs.into_vec(),
    })
}

/// `{rank=same; a; b}` (or another rank) as an anonymous subgraph.
fn rank_group(rank: &str, ids: &[String]) -> Stmt {
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

struct Builder<'o> {
    opts: &'o DotOptions,
    /// Top-level statements (nodes, clusters), before the edges.
    root: Vec<Stmt>,
    edges: Vec<Stmt>,
    /// DOT node ids in use.
    used: HashSet<String>,
    /// Vertex key -> DOT node id, for arcs given by key (ghost arcs).
    by_key: HashMap<String, String>,
    /// Container key -> container, for placing ghost vertices.
    container_of_key: HashMap<String, usize>,
    /// Statements added to a cluster (`Some(container)`) or to the top level
    /// (`None`) besides its states: ghosts, clusters nested too deep.
    extra: HashMap<Option<usize>, Vec<Stmt>>,
    /// Per state: its node, or for a container its cluster once assembled.
    state_stmt: Vec<Option<Stmt>>,
    /// Per container: cluster attributes and entry node; outcome boxes.
    header: Vec<Vec<Stmt>>,
    footer: Vec<Vec<Stmt>>,
    /// Clusters to assemble, deepest first.
    clusters: Vec<ClusterPlan>,
    /// Top-level states in order, and what follows them (outcomes).
    top_states: Vec<usize>,
    top_tail: Vec<Stmt>,
    /// `(position in edges, ghost arc)`: ghost arcs of a BT drawn among
    /// their tail's children, in edge order.
    bt_ghost_slots: Vec<(usize, usize)>,
}

/// How one container's cluster is put together.
struct ClusterPlan {
    container: usize,
    name: String,
    /// The states of its region, in file order.
    children: Vec<usize>,
    /// Where the cluster goes: inside its parent's cluster (`true`), or, when
    /// nested too deep, beside it in the cluster `slot`.
    in_parent: bool,
    slot: Option<usize>,
}

impl<'o> Builder<'o> {
    fn new(opts: &'o DotOptions) -> Self {
        Builder {
            opts,
            root: Vec::new(),
            edges: Vec::new(),
            used: HashSet::new(),
            by_key: HashMap::new(),
            container_of_key: HashMap::new(),
            extra: HashMap::new(),
            state_stmt: Vec::new(),
            header: Vec::new(),
            footer: Vec::new(),
            clusters: Vec::new(),
            top_states: Vec::new(),
            top_tail: Vec::new(),
            bt_ghost_slots: Vec::new(),
        }
    }

    /// Puts the clusters together, deepest first, then the top level.
    fn assemble(&mut self) {
        for plan in std::mem::take(&mut self.clusters) {
            let c = plan.container;
            let mut stmts = std::mem::take(&mut self.header[c]);
            for j in plan.children {
                stmts.extend(self.state_stmt[j].take());
            }
            stmts.extend(self.extra.remove(&Some(c)).unwrap_or_default());
            stmts.append(&mut self.footer[c]);
            let sub = Stmt::Subgraph(Subgraph {
                id: dot_id(&plan.name),
                stmts,
            });
            if plan.in_parent {
                self.state_stmt[c] = Some(sub);
            } else {
                self.extra.entry(plan.slot).or_default().push(sub);
            }
        }
        for j in std::mem::take(&mut self.top_states) {
            self.root.extend(self.state_stmt[j].take());
        }
        // States no region lists (none in a valid machine) are still drawn.
        for s in std::mem::take(&mut self.state_stmt) {
            self.root.extend(s);
        }
        self.root
            .extend(self.extra.remove(&None).unwrap_or_default());
        self.root.append(&mut self.top_tail);
    }

    /// A DOT node id not used yet, `base` if possible.
    fn fresh(&mut self, base: &str) -> String {
        let mut id = base.to_string();
        while self.used.contains(&id) {
            id.push('\'');
        }
        self.used.insert(id.clone());
        id
    }

    /// Registers a vertex and returns its DOT node id.
    fn vertex(&mut self, key: &str) -> String {
        let id = self.fresh(key);
        self.by_key.entry(key.to_string()).or_insert(id.clone());
        id
    }

    fn vhl(&self, key: &str) -> Option<&'o Highlight> {
        self.opts.highlight.get(key)
    }

    fn ahl(&self, from: &str, to: &str, label: &str) -> Option<&'o Highlight> {
        let (from, to) = (from.to_string(), to.to_string());
        if !self.opts.arc_label_highlight.is_empty() {
            let key = (from, to, label.to_string());
            if let Some(h) = self.opts.arc_label_highlight.get(&key) {
                return Some(h);
            }
            return self.opts.arc_highlight.get(&(key.0, key.1));
        }
        self.opts.arc_highlight.get(&(from, to))
    }

    // --- Behavior Trees -----------------------------------------------------

    fn bt(&mut self, bt: &Bt) {
        let ids: Vec<String> = bt.nodes.iter().map(|n| self.vertex(&n.id)).collect();
        for (n, id) in bt.nodes.iter().zip(&ids) {
            let mut a = bt_node_attrs(n);
            a.node_highlight(self.vhl(&n.id));
            a.changed(self.opts.changed.get(&n.id));
            self.root.push(node_stmt(id, a));
        }
        // Ghost arcs with a slot among a drawn node's children, by tail.
        let mut slotted: HashMap<&str, Vec<(usize, usize)>> = HashMap::new();
        for (&g, &slot) in &self.opts.ghost_slot {
            if let Some((from, _, _)) = self.opts.ghost_arcs.get(g) {
                slotted.entry(from.as_str()).or_default().push((slot, g));
            }
        }
        for (n, id) in bt.nodes.iter().zip(&ids) {
            let mut ghosts = slotted.remove(n.id.as_str()).unwrap_or_default();
            ghosts.sort_unstable();
            let mut ghosts = ghosts.into_iter().peekable();
            for (k, &c) in n.children.iter().enumerate() {
                while let Some((_, g)) = ghosts.next_if(|&(slot, _)| slot <= k) {
                    self.bt_ghost_slots.push((self.edges.len(), g));
                }
                let mut a = Attrs::default();
                a.edge_highlight(self.ahl(&n.id, &bt.nodes[c].id, ""));
                self.edges.push(edge_stmt(id, &ids[c], a));
            }
            for (_, g) in ghosts {
                self.bt_ghost_slots.push((self.edges.len(), g));
            }
        }
    }

    // --- FSMs and HFSMs -----------------------------------------------------

    fn machine(&mut self, m: &StateMachine) {
        let n = m.states.len();
        // Nesting levels, parents before children, without recursion.
        let mut level = vec![0usize; n];
        for c in m.parents_first() {
            level[c] = m.states[c].parent.map_or(0, |p| level[p] + 1);
        }
        // Vertices are identified by the graph's keys (SPEC §3 identity),
        // so that highlights and ghosts given by key find them.
        let key: Vec<String> = m.keys();
        let region = |i: usize| match &m.states[i].body {
            StateBody::Container(r) => Some(r),
            _ => None,
        };
        let cluster_name = |i: usize| format!("cluster_{}", key[i]);

        // Vertex ids first (states, top outcomes), then the extra outcome boxes
        // of the containers, so that every vertex keeps its key as its id.
        let state_id: Vec<String> = key.iter().map(|p| self.vertex(p)).collect();
        let top_outcome_id: Vec<String> = m.top.outcomes.iter().map(|o| self.vertex(o)).collect();
        let mut outcome_box: HashMap<(usize, &str), String> = HashMap::new();
        for (i, p) in key.iter().enumerate() {
            if let Some(r) = region(i) {
                self.container_of_key.insert(p.clone(), i);
                for o in &r.outcomes {
                    let id = self.fresh(&format!("{p}/{o}"));
                    outcome_box.insert((i, o.as_str()), id);
                }
            }
        }

        // Nodes.
        self.state_stmt = vec![None; n];
        self.header = vec![Vec::new(); n];
        self.footer = vec![Vec::new(); n];
        for i in 0..n {
            let s = &m.states[i];
            let condition = match &s.body {
                StateBody::Task(Some(c)) => {
                    crate::model::skill::skill_kind(&c.skill)
                        == Some(crate::model::SkillKind::Condition)
                }
                _ => false,
            };
            let mut a = Attrs::default();
            match &s.body {
                StateBody::Container(r) => {
                    // A region of a parallel state: a dashed box, as UML
                    // separates orthogonal regions with dashed lines.
                    let orthogonal = s.parent.is_some_and(
                        |p| matches!(&m.states[p].body, StateBody::Container(pr) if pr.parallel),
                    );
                    self.container_nodes(i, &s.label, &key[i], r, orthogonal, &outcome_box);
                    continue;
                }
                // SCXML history pseudo-states as in UML: a small circle with H / H*.
                StateBody::Decision if s.pseudo.is_some() => {
                    let h = match s.pseudo {
                        Some(crate::model::Pseudo::DeepHistory) => "H*",
                        _ => "H",
                    };
                    a.set("label", h)
                        .set("shape", "circle")
                        .set("fillcolor", "white")
                        .set("fontsize", "10")
                        .set("width", "0.3")
                        .set("tooltip", &key[i])
                        .style("filled");
                }
                StateBody::Decision => {
                    a.set("label", &s.label)
                        .set("shape", "diamond")
                        .set("fillcolor", DECISION_FILL)
                        .set("fontsize", "10")
                        .set("margin", "0.02,0.02")
                        .set("tooltip", &key[i])
                        .style("filled");
                }
                StateBody::Task(call) => {
                    a.set("label", &s.label).set("shape", "ellipse");
                    if condition {
                        a.set("fillcolor", "white")
                            .set("fontname", "Helvetica-Oblique");
                    } else {
                        a.set("fillcolor", ACTION_FILL);
                    }
                    let tip = match call {
                        Some(c) => format!("{}: {c}", key[i]),
                        None => key[i].clone(),
                    };
                    a.set("tooltip", &tip).style("filled");
                }
            }
            if s.parent.is_none() && m.top.initial == Target::State(i) {
                a.set("penwidth", "2.2");
            }
            a.node_highlight(self.vhl(&key[i]));
            a.changed(self.opts.changed.get(&key[i]));
            self.state_stmt[i] = Some(node_stmt(&state_id[i], a));
        }
        for (o, id) in m.top.outcomes.iter().zip(&top_outcome_id) {
            let mut a = Attrs::default();
            a.set("label", o)
                .set("shape", "doublecircle")
                .set("fontsize", "9")
                .set("margin", "0.02");
            a.node_highlight(self.vhl(o));
            self.top_tail.push(node_stmt(id, a));
        }
        if !top_outcome_id.is_empty() {
            self.top_tail.push(rank_group("sink", &top_outcome_id));
        }
        self.top_states = m.top.states.clone();

        // Clusters, deepest first; below MAX_CLUSTER_NESTING a cluster goes
        // beside its parent's instead of inside it.
        let mut by_level: Vec<usize> = (0..n).filter(|&i| region(i).is_some()).collect();
        by_level.sort_by_key(|&i| (level[i], i));
        let mut slot: Vec<Option<usize>> = vec![None; n];
        for &i in &by_level {
            slot[i] = match m.states[i].parent {
                Some(p) if level[i] >= MAX_CLUSTER_NESTING => slot[p],
                parent => parent,
            };
        }
        for &i in by_level.iter().rev() {
            self.clusters.push(ClusterPlan {
                container: i,
                name: cluster_name(i),
                children: region(i).map(|r| r.states.clone()).unwrap_or_default(),
                in_parent: slot[i] == m.states[i].parent,
                slot: slot[i],
            });
        }

        // Edges.
        for i in 0..n {
            let s = &m.states[i];
            let reg = region(i);
            if let Some(r) = reg {
                for j in r.entered(&m.states) {
                    let mut a = Attrs::default();
                    if region(j).is_some() {
                        a.set("lhead", &cluster_name(j));
                    }
                    a.edge_highlight(self.ahl(&key[i], &key[j], "initial"));
                    self.edges.push(edge_stmt(&state_id[i], &state_id[j], a));
                }
            }
            for t in &s.transitions {
                let mut a = Attrs::default();
                // Tail: a container's outcome transitions leave from its
                // outcome box, anything else from the state's node.
                let tail = match &t.trigger {
                    Trigger::Outcome(o) => outcome_box.get(&(i, o.as_str())),
                    Trigger::Guard(_) => None,
                }
                .unwrap_or(&state_id[i])
                .clone();
                let (head, to_key) = match &t.target {
                    &Target::State(j) => {
                        if region(j).is_some() && j != i {
                            a.set("lhead", &cluster_name(j));
                        }
                        (state_id[j].clone(), key[j].clone())
                    }
                    Target::Outcome(o) | Target::OuterOutcome { outcome: o, .. } => match match &t
                        .target
                    {
                        Target::OuterOutcome { owner, .. } => *owner,
                        _ => s.parent,
                    } {
                        Some(p) => {
                            let head = outcome_box.get(&(p, o.as_str())).unwrap_or(&state_id[p]);
                            (head.clone(), key[p].clone())
                        }
                        None => {
                            let head = m
                                .top
                                .outcomes
                                .iter()
                                .position(|x| x == o)
                                .map_or(o, |k| &top_outcome_id[k]);
                            (head.clone(), o.clone())
                        }
                    },
                };
                if reg.is_some() && tail == state_id[i] && head != state_id[i] {
                    a.set("ltail", &cluster_name(i));
                }
                if head == tail && matches!(s.body, StateBody::Decision) {
                    // A decision state's arcs leave on every side; its
                    // self-loop goes below it, clear of their labels.
                    a.set("tailport", "s").set("headport", "s");
                }
                let color = match &t.trigger {
                    Trigger::Outcome(o) => {
                        Status::from_outcome(o).map_or("black", Status::line_color)
                    }
                    Trigger::Guard(_) => GUARD,
                };
                let label = t.trigger.label();
                a.set("label", &label)
                    .set("color", color)
                    .set("fontcolor", color);
                a.edge_highlight(self.ahl(&key[i], &to_key, &label));
                let was = (key[i].clone(), to_key, label);
                if let Some(old) = self.opts.changed_arcs.get(&was) {
                    a.set("label", &format!("{}\n(was {old})", was.2))
                        .set("color", CHANGED)
                        .set("fontcolor", CHANGED);
                }
                self.edges.push(edge_stmt(&tail, &head, a));
            }
        }
    }

    /// A container's cluster header (attributes, its own vertex as a dot) and
    /// footer (its outcome boxes, side by side).
    fn container_nodes(
        &mut self,
        i: usize,
        label: &str,
        key: &str,
        r: &crate::model::Region,
        orthogonal: bool,
        outcome_box: &HashMap<(usize, &str), String>,
    ) {
        let mut ca = Attrs::default();
        // A parallel state says so in its label (UML's regions).
        let shown_label = if r.parallel {
            format!("{label} ‖")
        } else {
            label.to_string()
        };
        ca.set("label", &shown_label)
            .set("fontname", FONT)
            .set("fontsize", "11")
            .set("labeljust", "l")
            .set("color", "grey40")
            .style(if orthogonal { "dashed" } else { "rounded" });
        match self.vhl(key) {
            Some(Highlight::Added) => {
                ca.set("color", ADDED)
                    .set("fontcolor", ADDED)
                    .set("penwidth", "2.5");
            }
            Some(Highlight::Removed) => {
                ca.style("dashed")
                    .set("color", REMOVED)
                    .set("fontcolor", REMOVED);
            }
            Some(Highlight::Status(st)) => {
                ca.style("filled").set("fillcolor", st.fill_color());
            }
            None => {}
        }
        ca.changed(self.opts.changed.get(key));
        let mut header: Vec<Stmt> = ca.into_vec().into_iter().map(Stmt::Attribute).collect();
        let mut ea = Attrs::default();
        ea.set("shape", "point")
            .set("width", "0.12")
            .set("tooltip", key);
        ea.node_highlight(self.vhl(key));
        let id = self.by_key.get(key).cloned().unwrap_or_else(|| key.into());
        header.push(node_stmt(&id, ea));
        self.header[i] = header;

        let boxes: Vec<String> = r
            .outcomes
            .iter()
            .map(|o| outcome_box[&(i, o.as_str())].clone())
            .collect();
        let footer = &mut self.footer[i];
        for (o, id) in r.outcomes.iter().zip(&boxes) {
            let mut oa = Attrs::default();
            let color = Status::from_outcome(o).map_or("black", Status::line_color);
            oa.set("label", o)
                .set("shape", "box")
                .set("fontsize", "8")
                .set("width", "0.3")
                .set("height", "0.2")
                .set("margin", "0.04,0.02")
                .set("color", color)
                .set("fontcolor", color)
                .set("tooltip", &format!("outcome {o} of {key}"))
                .style("rounded");
            footer.push(node_stmt(id, oa));
        }
        if !boxes.is_empty() {
            footer.push(rank_group("same", &boxes));
        }
    }

    // --- Ghosts (removed elements) --------------------------------------------

    fn ghosts(&mut self) {
        let mut ghost_ids: HashMap<&str, String> = HashMap::new();
        let slotted: HashMap<usize, usize> =
            self.bt_ghost_slots.iter().map(|&(at, g)| (g, at)).collect();
        let mut placed: Vec<(usize, Stmt)> = Vec::with_capacity(slotted.len());
        for (key, label) in &self.opts.ghost_vertices {
            let id = self.fresh(key);
            let mut a = Attrs::default();
            a.set("label", label);
            a.node_highlight(Some(&Highlight::Removed));
            let stmt = node_stmt(&id, a);
            let cluster = self.ghost_cluster(key);
            self.extra.entry(cluster).or_default().push(stmt);
            ghost_ids.entry(key.as_str()).or_insert(id);
        }
        for (g, (from, to, label)) in self.opts.ghost_arcs.iter().enumerate() {
            let mut ends = Vec::with_capacity(2);
            for key in [from, to] {
                let id = match self.by_key.get(key).or(ghost_ids.get(key.as_str())) {
                    Some(id) => id.clone(),
                    None => {
                        let id = self.fresh(key);
                        let mut a = Attrs::default();
                        a.set("label", key);
                        a.node_highlight(Some(&Highlight::Removed));
                        self.extra.entry(None).or_default().push(node_stmt(&id, a));
                        ghost_ids.insert(key.as_str(), id.clone());
                        id
                    }
                };
                ends.push(id);
            }
            let mut a = Attrs::default();
            if !label.is_empty() {
                a.set("label", label);
            }
            a.edge_highlight(Some(&Highlight::Removed));
            match slotted.get(&g) {
                Some(&at) => placed.push((at, edge_stmt(&ends[0], &ends[1], a))),
                None => self.edges.push(edge_stmt(&ends[0], &ends[1], a)),
            }
        }
        // Slotted ghost arcs go before the edge they were placed at (one
        // merge: `placed` is in edge order).
        if !placed.is_empty() {
            placed.sort_by_key(|x| x.0);
            let edges = std::mem::take(&mut self.edges);
            let mut placed = placed.into_iter().peekable();
            for (i, e) in edges.into_iter().enumerate() {
                while let Some((_, p)) = placed.next_if(|x| x.0 <= i) {
                    self.edges.push(p);
                }
                self.edges.push(e);
            }
            self.edges.extend(placed.map(|x| x.1));
        }
    }

    /// The legend of a diff drawing: one sample node per highlight, side by
    /// side in a cluster of their own (ids not used by the policy).
    fn legend(&mut self) -> Stmt {
        let mut ca = Attrs::default();
        ca.set("label", "legend")
            .set("fontname", FONT)
            .set("fontsize", "9")
            .set("color", "grey70")
            .style("rounded");
        let mut stmts: Vec<Stmt> = ca.into_vec().into_iter().map(Stmt::Attribute).collect();
        let samples = [
            ("legend: added", "added", Some(Highlight::Added)),
            ("legend: removed", "removed", Some(Highlight::Removed)),
            ("legend: changed", "changed\n(was: old value)", None),
        ];
        let mut ids = Vec::new();
        for (id, label, h) in samples {
            let id = self.fresh(id);
            let mut a = Attrs::default();
            a.set("label", label)
                .set("shape", "box")
                .set("fontsize", "9")
                .set("height", "0.3")
                .style("rounded");
            a.node_highlight(h.as_ref());
            if h.is_none() {
                a.set("color", CHANGED)
                    .set("fontcolor", CHANGED)
                    .set("penwidth", "2.5");
            }
            stmts.push(node_stmt(&id, a));
            ids.push(id);
        }
        stmts.push(rank_group("same", &ids));
        Stmt::Subgraph(Subgraph {
            id: dot_id("cluster legend"),
            stmts,
        })
    }

    /// The cluster a ghost vertex belongs in: the longest container key that
    /// prefixes its key.
    fn ghost_cluster(&self, key: &str) -> Option<usize> {
        key.rmatch_indices('/')
            .find_map(|(at, _)| self.container_of_key.get(&key[..at]).copied())
    }
}

/// Shape and label of a BT node.
fn bt_node_attrs(n: &BtNode) -> Attrs {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::format::toml::parse_str;
    use graphviz_rust::dot_structures::Graph as DotGraph;
    use std::path::Path;

    fn policy(text: &str) -> Policy {
        match parse_str("inline.toml", text, Path::new("."), &Default::default()) {
            Ok(l) => l.policy,
            Err(d) => panic!("test policy does not parse: {d:?}"),
        }
    }

    const BT: &str = r#"
kind = "bt"
name = "Fetch cube2"
root = "fetch"

[nodes]
fetch        = { sequence = ["reached-cube", "pick", "finish"] }
reached-cube = { fallback = ["at-cube", "move-to-cube"] }
at-cube      = { condition = "Robot-At cube2?", skill = "Robot-At", args = { target = "cube2" } }
move-to-cube = { retry = "move", times = 3 }
move         = { action = "Move-To cube2!", skill = "Move-To", args = { target = "cube2" } }
pick         = { timeout = "pick-it", ms = 5000 }
pick-it      = { action = "Pick cube2!", skill = "Pick", args = { object = "cube2" } }
finish       = { sequence_memory = ["both", "not-tucked"], name = "Finish" }
both         = { parallel = ["dock", "tuck"], success = 1 }
dock         = { action = "Dock!", skill = "Dock" }
tuck         = { action = "Tuck arm!", skill = "Tuck-Arm" }
not-tucked   = { inverter = "tucked" }
tucked       = { condition = "Arm tucked?", skill = "Arm-Tucked" }
"#;

    const FSM: &str = r#"
kind = "fsm"
name = "Fault-tolerant fetch"
initial = "Move-To cube2"
outcomes = ["SUCCESS"]

[states."Move-To cube2"]
skill = "Move-To"
args = { target = "cube2" }
on = { SUCCESS = "Pick cube2", FAILURE = "SELECTOR", RUNNING = "Move-To cube2" }

[states."Pick cube2"]
skill = "Pick"
args = { object = "cube2" }
on = { SUCCESS = "SUCCESS", FAILURE = "SELECTOR", RUNNING = "Pick cube2" }

[states.SELECTOR]
decision = true
guards = [
  { if = "In-Hand", args = { object = "cube2" }, to = "SUCCESS", label = "cube2 in hand" },
  { if = "Robot-At", args = { target = "cube2" }, to = "Pick cube2", label = "cube2 reached" },
  { unless = "Robot-At", args = { target = "cube2" }, to = "Move-To cube2", label = "restart" },
]
on = { RUNNING = "SELECTOR" }
"#;

    const HFSM: &str = r#"
kind = "hfsm"
name = "Fig. 6"
initial = "fetch"
outcomes = ["SUCCESS", "FAILURE", "RUNNING"]

[states.fetch]
label = "Sequence"
initial = "at-cube"
outcomes = ["SUCCESS", "FAILURE", "RUNNING"]
on = { SUCCESS = "SUCCESS", FAILURE = "FAILURE", RUNNING = "RUNNING" }

[states.fetch.states.at-cube]
label = "Fallback"
initial = "is-at"
outcomes = ["SUCCESS", "FAILURE", "RUNNING"]
on = { SUCCESS = "pick", FAILURE = "FAILURE", RUNNING = "RUNNING" }

[states.fetch.states.at-cube.states.is-at]
label = "Robot-At cube2?"
skill = "Robot-At"
args = { target = "cube2" }
on = { SUCCESS = "SUCCESS", FAILURE = "move" }

[states.fetch.states.at-cube.states.move]
label = "Move-To cube2!"
skill = "Move-To"
args = { target = "cube2" }
on = { SUCCESS = "SUCCESS", FAILURE = "FAILURE", RUNNING = "RUNNING" }

[states.fetch.states.pick]
label = "Pick cube2!"
skill = "Pick"
args = { object = "cube2" }
on = { SUCCESS = "SUCCESS", FAILURE = "FAILURE", RUNNING = "RUNNING" }
"#;

    /// Distinct node ids declared anywhere, and the number of edges, of a DOT
    /// text, read back with graphviz-rust's parser (which also checks syntax).
    fn census(dot: &str) -> (Vec<String>, usize) {
        let g = graphviz_rust::parse(dot).unwrap_or_else(|e| panic!("bad DOT: {e}\n{dot}"));
        let DotGraph::DiGraph { stmts, .. } = g else {
            panic!("not a digraph")
        };
        let mut ids = Vec::new();
        let mut edges = 0;
        let mut todo = vec![stmts];
        while let Some(stmts) = todo.pop() {
            for s in stmts {
                match s {
                    Stmt::Node(n) => {
                        let id = match n.id.0 {
                            Id::Plain(s) | Id::Escaped(s) | Id::Html(s) => s,
                            Id::Anonymous(_) => continue,
                        };
                        if !ids.contains(&id) {
                            ids.push(id);
                        }
                    }
                    Stmt::Edge(_) => edges += 1,
                    Stmt::Subgraph(sg) => todo.push(sg.stmts),
                    _ => {}
                }
            }
        }
        (ids, edges)
    }

    /// The drawing has the graph's vertices (plus `extra` outcome boxes) and
    /// exactly its arcs.
    fn assert_matches_graph(p: &Policy, dot: &str, extra: usize) {
        let g = crate::graph::policy_graph(p);
        let (ids, edges) = census(dot);
        assert_eq!(ids.len(), g.vertex_count() + extra, "nodes of\n{dot}");
        assert_eq!(edges, g.arc_count(), "edges of\n{dot}");
        for v in g.g.node_weights() {
            assert!(
                ids.contains(&quote(&v.key)) || ids.contains(&v.key),
                "vertex {} not drawn",
                v.key
            );
        }
    }

    #[test]
    fn bt_golden() {
        let p = policy(BT);
        let dot = policy_dot(&p, &DotOptions::default());
        assert_matches_graph(&p, &dot, 0);
        insta::assert_snapshot!("bt", dot);
    }

    #[test]
    fn fsm_golden() {
        let p = policy(FSM);
        let dot = policy_dot(&p, &DotOptions::default());
        assert_matches_graph(&p, &dot, 0);
        insta::assert_snapshot!("fsm", dot);
    }

    /// A parallel state (TOML `parallel = true`): its regions are dashed
    /// clusters inside its box, one initial arc to each; `/done` is the
    /// machine's outcome, taken from inside a region.
    const PARALLEL: &str = include_str!("../../tests/fixtures/valid/parallel-regions.toml");

    #[test]
    fn parallel_golden() {
        let p = policy(PARALLEL);
        let dot = policy_dot(&p, &DotOptions::default());
        // Two regions with one outcome box each.
        assert_matches_graph(&p, &dot, 2);
        assert!(dot.contains("label=\"both ‖\""), "{dot}");
        assert_eq!(dot.matches("style=dashed").count(), 2, "{dot}");
        assert!(dot.contains("move -> done [label=FAILURE"), "{dot}");
        insta::assert_snapshot!("parallel", dot);
    }

    #[test]
    fn hfsm_golden() {
        let p = policy(HFSM);
        let dot = policy_dot(&p, &DotOptions::default());
        // Two containers with three outcome boxes each.
        assert_matches_graph(&p, &dot, 6);
        assert!(dot.contains("subgraph cluster_fetch {"), "{dot}");
        assert!(dot.contains("subgraph \"cluster_at-cube\" {"), "{dot}");
        insta::assert_snapshot!("hfsm", dot);
    }

    #[test]
    fn output_is_deterministic() {
        for text in [BT, FSM, HFSM] {
            let p = policy(text);
            let a = policy_dot(&p, &DotOptions::default());
            let b = policy_dot(&p.clone(), &DotOptions::default());
            assert_eq!(a, b);
        }
    }

    #[test]
    fn ids_with_quotes_spaces_slashes_and_unicode_are_quoted() {
        let p = policy(
            r#"
kind = "bt"
name = "say \"hi\""
root = 'go "home" now'

[nodes]
'go "home" now' = { sequence = ["a/b", "ü→x", "back\\slash"] }
"a/b"   = { action = "Say \"hi\"!", skill = "Dock" }
"ü→x"   = { condition = "Ünïcode?", skill = "Found" }
"back\\slash" = { action = "C:\\dir\\", skill = "Dock" }
"#,
        );
        let dot = policy_dot(&p, &DotOptions::default());
        assert!(dot.starts_with("digraph \"say \\\"hi\\\"\" {"), "{dot}");
        assert!(dot.contains(r#""go \"home\" now" -> "a/b""#), "{dot}");
        assert!(dot.contains(r#""go \"home\" now" -> "ü→x""#), "{dot}");
        assert!(dot.contains(r#"label="Say \"hi\"!""#), "{dot}");
        assert!(dot.contains(r#"label="C:\\dir\\""#), "{dot}");
        let (ids, edges) = census(&dot);
        assert_eq!(ids.len(), 4);
        assert_eq!(edges, 3);
        // Graphviz itself accepts it, where installed.
        match render(&dot, RenderFormat::Svg, T) {
            Ok(svg) => {
                let svg = String::from_utf8(svg).unwrap();
                assert!(svg.contains("Say &quot;hi&quot;!"), "{svg}");
                assert!(svg.contains("Ünïcode?"), "{svg}");
                assert!(svg.contains(r"C:\dir\"), "{svg}");
            }
            Err(RenderError::NotInstalled { .. }) => {}
            Err(e) => panic!("{e}"),
        }
    }

    #[test]
    fn plain_ids_stay_bare_and_keywords_are_quoted() {
        assert_eq!(dot_id("SELECTOR"), Id::Plain("SELECTOR".into()));
        assert_eq!(dot_id("0.5"), Id::Plain("0.5".into()));
        assert_eq!(dot_id("node"), Id::Escaped("\"node\"".into()));
        assert_eq!(dot_id("Node"), Id::Escaped("\"Node\"".into()));
        assert_eq!(dot_id(""), Id::Escaped("\"\"".into()));
        assert_eq!(dot_id("1.2.3"), Id::Escaped("\"1.2.3\"".into()));
        assert_eq!(quote("a\nb\tc\r"), "\"a\\nb c\"");
    }

    #[test]
    fn missing_dot_is_a_clear_error() {
        let err = render_with(
            "btfsm-test-no-such-graphviz",
            "digraph { a }",
            RenderFormat::Svg,
            T,
        )
        .unwrap_err();
        assert!(matches!(err, RenderError::NotInstalled { .. }), "{err:?}");
        let msg = err.to_string();
        assert!(msg.contains("is not installed"), "{msg}");
        assert!(msg.contains("apt-get install graphviz"), "{msg}");
    }

    #[test]
    fn graphviz_errors_are_reported() {
        match render("digraph { a -> }", RenderFormat::Svg, T) {
            Err(RenderError::Failed { stderr, .. }) => assert!(!stderr.is_empty()),
            Err(RenderError::NotInstalled { .. }) => {}
            other => panic!("expected a syntax error, got {other:?}"),
        }
    }

    /// The budget of the tests that run Graphviz.
    const T: Duration = Duration::from_secs(60);

    /// A fake Graphviz: a shell script in a scratch directory.
    fn fake_graphviz(tag: &str, script: &str) -> std::path::PathBuf {
        use std::os::unix::fs::PermissionsExt;
        let dir = std::env::temp_dir().join(format!("btfsm-gv-{tag}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join("dot");
        std::fs::write(&p, format!("#!/bin/sh\n{script}\n")).unwrap();
        std::fs::set_permissions(&p, std::fs::Permissions::from_mode(0o755)).unwrap();
        p
    }

    /// Runs a fake Graphviz, retrying while the script is "busy" (another
    /// test thread forked while it was open for writing).
    fn run_fake(
        program: &std::path::Path,
        dot: &str,
        budget: Budget,
    ) -> (Result<(Vec<u8>, String), RenderError>, Duration) {
        for _ in 0..100 {
            let t0 = Instant::now();
            match run_graphviz(program.to_str().unwrap(), dot, RenderFormat::Svg, budget) {
                Err(RenderError::Io { source, .. }) if source.raw_os_error() == Some(26) => {
                    std::thread::sleep(Duration::from_millis(20));
                }
                r => return (r, t0.elapsed()),
            }
        }
        panic!("{} stayed busy", program.display());
    }

    #[test]
    fn graphviz_runs_under_a_deadline_and_an_output_cap() {
        let short = Budget::new(Duration::from_millis(300));
        // Answers: the output is what it wrote (here, its input).
        let cat = fake_graphviz("cat", "exec cat");
        let (r, _) = run_fake(&cat, "digraph { a }", short);
        assert_eq!(r.unwrap().0, b"digraph { a }");
        // Never answers; its `sleep` child holds the pipes: killed at the
        // deadline without waiting for them.
        let sleeper = fake_graphviz("sleep", "sleep 30");
        let (r, took) = run_fake(&sleeper, "digraph { a }", short);
        assert!(
            matches!(r, Err(RenderError::Timeout { ms: 300, .. })),
            "{r:?}"
        );
        assert!(took < Duration::from_secs(5), "{took:?}");
        let msg = r.unwrap_err().to_string();
        assert!(msg.contains("did not finish within 300 ms") && msg.contains("--timeout-ms"));
        // Does not read 8 MiB of input: no dead-lock either.
        let big = "x".repeat(8 << 20);
        let (r, took) = run_fake(&sleeper, &big, short);
        assert!(matches!(r, Err(RenderError::Timeout { .. })), "{r:?}");
        assert!(took < Duration::from_secs(5), "{took:?}");
        // Writes without end: stopped past the output cap.
        let flood = fake_graphviz("flood", "exec cat /dev/zero");
        let capped = Budget {
            max_output: 1 << 20,
            ..Budget::new(T)
        };
        let (r, took) = run_fake(&flood, "digraph { a }", capped);
        assert!(
            matches!(r, Err(RenderError::TooLarge { limit: 1048576, .. })),
            "{r:?}"
        );
        assert!(took < Duration::from_secs(10), "{took:?}");
        // Floods its stderr and fails: the message keeps the first bytes.
        let noisy = fake_graphviz("noisy", "yes e | head -c 4000000 >&2; exit 3");
        let (r, _) = run_fake(&noisy, "digraph { a }", Budget::new(T));
        match r {
            Err(RenderError::Failed { stderr, .. }) => {
                // 64 KiB of `e\n`, trimmed.
                assert_eq!(stderr.len() as u64, MAX_RENDER_STDERR_BYTES - 1);
            }
            r => panic!("{r:?}"),
        }
        for p in [cat, sleeper, flood, noisy] {
            let _ = std::fs::remove_dir_all(p.parent().unwrap());
        }
    }

    /// Added and changed elements are drawn in colours that no transition
    /// label, guard, status fill or ghost uses (issue 15, point 5).
    #[test]
    fn diff_colours_are_used_by_no_transition_label() {
        let statuses = [Status::Running, Status::Success, Status::Failure];
        let mut taken: Vec<&str> = statuses.iter().map(|s| s.line_color()).collect();
        taken.extend(statuses.iter().map(|s| s.fill_color()));
        taken.extend([GUARD, REMOVED, "black"]);
        for c in [ADDED, CHANGED] {
            assert!(!taken.contains(&c), "{c}");
        }
        assert_ne!(ADDED, CHANGED);
    }

    #[test]
    fn highlights_and_ghosts() {
        let p = policy(FSM);
        let mut opts = DotOptions::default();
        opts.highlight.insert("Pick cube2".into(), Highlight::Added);
        opts.highlight
            .insert("SELECTOR".into(), Highlight::Status(Status::Running));
        opts.highlight.insert("SUCCESS".into(), Highlight::Removed);
        opts.arc_highlight.insert(
            ("Move-To cube2".into(), "Pick cube2".into()),
            Highlight::Added,
        );
        opts.ghost_vertices
            .push(("Tuck arm".into(), "Tuck arm".into()));
        opts.ghost_arcs
            .push(("Pick cube2".into(), "Tuck arm".into(), "SUCCESS".into()));
        opts.ghost_arcs
            .push(("Tuck arm".into(), "gone".into(), String::new()));
        let dot = policy_dot(&p, &opts);
        let line = |id: &str| {
            dot.lines()
                .find(|l| l.trim_start().starts_with(id))
                .unwrap_or_else(|| panic!("no line for {id} in\n{dot}"))
                .to_string()
        };
        assert!(line("\"Pick cube2\"[").contains("color=magenta"), "{dot}");
        assert!(line("SELECTOR[").contains("fillcolor=gold"), "{dot}");
        assert!(line("SUCCESS[").contains("style=dashed"), "{dot}");
        assert!(line("\"Tuck arm\"[").contains("style=dashed"), "{dot}");
        assert!(line("gone[").contains("color=grey55"), "{dot}");
        assert!(
            line("\"Move-To cube2\" -> \"Pick cube2\"").contains("color=magenta"),
            "{dot}"
        );
        assert!(
            line("\"Pick cube2\" -> \"Tuck arm\"").contains("style=dashed"),
            "{dot}"
        );
        // Ghosts add to the drawing, never to the policy's own elements.
        let (ids, edges) = census(&dot);
        assert_eq!((ids.len(), edges), (4 + 2, 10 + 2));
    }

    #[test]
    fn hfsm_ghost_goes_into_its_cluster_and_arcs_target_outcome_boxes() {
        let p = policy(HFSM);
        let mut opts = DotOptions::default();
        opts.ghost_vertices
            .push(("at-cube/old".into(), "Old!".into()));
        opts.arc_highlight
            .insert(("pick".into(), "fetch".into()), Highlight::Removed);
        opts.arc_label_highlight.insert(
            ("pick".into(), "fetch".into(), "SUCCESS".into()),
            Highlight::Status(Status::Success),
        );
        let dot = policy_dot(&p, &opts);
        let cluster = dot
            .find("subgraph \"cluster_at-cube\"")
            .expect("inner cluster");
        let ghost = dot.find("\"at-cube/old\"[").expect("ghost");
        assert!(ghost > cluster, "{dot}");
        // pick's SUCCESS goes to fetch's SUCCESS box, highlighted.
        let arc = dot
            .lines()
            .find(|l| l.contains("pick -> \"fetch/SUCCESS\""))
            .expect("arc to the outcome box");
        assert!(arc.contains("penwidth=3"), "{arc}");
        // Its parallel arcs get the (from, to) highlight.
        let other = dot
            .lines()
            .find(|l| l.contains("pick -> \"fetch/FAILURE\""))
            .expect("parallel arc");
        assert!(other.contains("style=dashed"), "{other}");
        // fetch's own SUCCESS transition leaves from that box.
        assert!(dot.contains("\"fetch/SUCCESS\" -> SUCCESS"), "{dot}");
    }

    #[test]
    fn deep_hfsm_nesting_is_capped() {
        use crate::model::{Region, State, StateMachine, Transition};
        const DEPTH: usize = 3 * MAX_CLUSTER_NESTING;
        let ok = || vec!["SUCCESS".to_string()];
        let to_success = || Transition {
            trigger: Trigger::Outcome("SUCCESS".into()),
            target: Target::Outcome("SUCCESS".into()),
            span: None,
        };
        // Containers 0..DEPTH, each holding the next; a task at the bottom.
        let mut states: Vec<State> = (0..DEPTH)
            .map(|k| State {
                name: format!("c{k}"),
                label: format!("C{k}"),
                parent: k.checked_sub(1),
                body: StateBody::Container(Region::at(k + 1, ok(), vec![k + 1])),
                transitions: vec![to_success()],
                pseudo: None,
                span: None,
            })
            .collect();
        states.push(State {
            name: "work".into(),
            label: "Work!".into(),
            parent: Some(DEPTH - 1),
            body: StateBody::Task(None),
            transitions: vec![to_success()],
            pseudo: None,
            span: None,
        });
        let p = Policy {
            name: "deep".into(),
            description: None,
            body: PolicyBody::Machine(StateMachine {
                hierarchical: true,
                top: Region::at(0, ok(), vec![0]),
                states,
            }),
        };
        let dot = policy_dot(&p, &DotOptions::default());
        assert_matches_graph(&p, &dot, DEPTH);
        assert_eq!(
            dot.matches("subgraph \"cluster_").count() + dot.matches("subgraph cluster_").count(),
            DEPTH
        );
        let mut depth = 0usize;
        let mut max = 0;
        for c in dot.chars() {
            match c {
                '{' => {
                    depth += 1;
                    max = max.max(depth);
                }
                '}' => depth -= 1,
                _ => {}
            }
        }
        // digraph + clusters + the innermost rank group.
        assert!(max <= MAX_CLUSTER_NESTING + 2, "nesting {max}");
    }

    /// Every bundled policy draws as its graph and, where Graphviz is
    /// installed, renders without warnings. With `BTFSM_RENDER_DIR` set, the
    /// PNGs are written there for a look.
    #[test]
    fn bundled_policies_draw_and_render() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("policies/paper");
        let Ok(entries) = std::fs::read_dir(&dir) else {
            return;
        };
        let mut files: Vec<_> = entries
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|x| x == "toml"))
            .collect();
        files.sort();
        let out = std::env::var_os("BTFSM_RENDER_DIR").map(std::path::PathBuf::from);
        for f in files {
            // Files being edited by others may not load; they are not ours to test.
            let Ok(loaded) = crate::format::load(&f, &Default::default()) else {
                continue;
            };
            let p = loaded.policy;
            let dot = policy_dot(&p, &DotOptions::default());
            let extra = match &p.body {
                PolicyBody::Machine(m) => m
                    .states
                    .iter()
                    .map(|s| match &s.body {
                        StateBody::Container(r) => r.outcomes.len(),
                        _ => 0,
                    })
                    .sum(),
                PolicyBody::Bt(_) => 0,
            };
            assert_matches_graph(&p, &dot, extra);
            let format = if out.is_some() {
                RenderFormat::Png
            } else {
                RenderFormat::Svg
            };
            match run_graphviz("dot", &dot, format, Budget::new(T)) {
                Ok((bytes, warnings)) => {
                    assert!(warnings.is_empty(), "{}: {warnings}", f.display());
                    if let Some(out) = &out {
                        let name = f.file_stem().unwrap().to_string_lossy().to_string();
                        std::fs::write(out.join(format!("{name}.png")), bytes).unwrap();
                        std::fs::write(out.join(format!("{name}.dot")), &dot).unwrap();
                    }
                }
                Err(RenderError::NotInstalled { .. }) => return,
                Err(e) => panic!("{}: {e}", f.display()),
            }
        }
    }
}
