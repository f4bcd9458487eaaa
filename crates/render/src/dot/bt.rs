//! Behavior Tree diagrams: each node's look, folded subtrees and the
//! direction of the layout.
//!
//! Looks follow the paper (control nodes are polygons with the symbols of
//! Fig. 1 and Fig. 12: `→`, `?`, `→*`, `?*`) and the convention of Groot and
//! BehaviorTree.CPP's documentation for leaves (actions are boxes,
//! conditions ellipses). A node with a name of its own shows its type
//! (BehaviorTree.CPP registration ID, e.g. `ClearEntireCostmap` under
//! `ClearGlobalCostmap-Context`) on a smaller grey line under the name.
//! Ports are in the tooltip, and under the label with [`DotOptions::ports`].
//!
//! Folding (the paper's Fig. 9a "Moma Task!" and Fig. 16a): a node listed in
//! [`DotOptions::collapse`], at depth [`DotOptions::depth`], or the root of a
//! SubTree with [`DotOptions::fold_subtrees`] is drawn as one node with a
//! double border standing for its whole subtree, labelled with its size.
//!
//! Layout: a tree is drawn top-down unless the estimated drawing is wider
//! than [`SWITCH_ASPECT`] times its height and left-to-right is closer to
//! square (the switch is under the promised [`MAX_ASPECT`], a margin for the
//! estimate's error); the estimate counts label characters (Helvetica's average width)
//! and Graphviz's separations, so no Graphviz is needed to decide.

use super::attrs::Attrs;
use super::*;
use btfsm_model::BtNodeKind;
use btfsm_model::bt::{Bt, BtNode, NodeIdx};

/// The widest aspect (width / height) [`RankDir::Auto`] aims for.
pub const MAX_ASPECT: f64 = 2.5;
/// The estimated aspect above which [`RankDir::Auto`] turns a tree
/// left-to-right: under [`MAX_ASPECT`] by the estimate's error (label
/// widths from average character widths, Graphviz's own packing).
pub(super) const SWITCH_ASPECT: f64 = 2.2;

/// The direction of a BT's layout.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, clap::ValueEnum)]
pub enum RankDir {
    /// Top-down, or left-to-right when top-down is estimated wider than
    /// `SWITCH_ASPECT` and left-to-right is closer to square.
    #[default]
    Auto,
    /// Root at the top, children left to right (the paper's figures).
    #[value(name = "TB")]
    TopDown,
    /// Root at the left, children top to bottom.
    #[value(name = "LR")]
    LeftRight,
}

/// Why a drawing cannot be made as asked.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum FoldError {
    #[error("`--collapse {id}`: no node `{id}` in the tree{hint}")]
    UnknownNode { id: String, hint: String },
    #[error(
        "--collapse, --depth and --subtrees apply to Behavior Trees; this policy is a state machine"
    )]
    NotATree,
}

/// Checks the folding options against the policy: every collapsed id names
/// a node of the tree (else an error with the closest ids).
pub fn check_fold(policy: &btfsm_model::Policy, opts: &DotOptions) -> Result<(), FoldError> {
    let folding = !opts.collapse.is_empty() || opts.depth.is_some() || opts.fold_subtrees;
    let bt = match &policy.body {
        PolicyBody::Bt(bt) => bt,
        PolicyBody::Machine(_) if folding => return Err(FoldError::NotATree),
        PolicyBody::Machine(_) => return Ok(()),
    };
    let ids: std::collections::HashSet<&str> = bt.nodes.iter().map(|n| n.id.as_str()).collect();
    for c in &opts.collapse {
        if !ids.contains(c.as_str()) {
            let s = btfsm_core::diagnostic::suggest(c, bt.nodes.iter().map(|n| n.id.as_str()));
            return Err(FoldError::UnknownNode {
                id: btfsm_core::sanitize::shown(c).into_owned(),
                hint: if s.is_empty() {
                    String::new()
                } else {
                    format!(" ({s})")
                },
            });
        }
    }
    Ok(())
}

/// What of a tree is drawn: per node, whether it is drawn, and the size of
/// the subtree a folded node stands for.
pub(super) struct View {
    pub(super) shown: Vec<bool>,
    pub(super) folded: Vec<Option<usize>>,
    /// Drawn nodes in pre-order.
    pub(super) order: Vec<NodeIdx>,
    depth: Vec<usize>,
}

impl View {
    pub(super) fn new(bt: &Bt, opts: &DotOptions) -> View {
        let n = bt.nodes.len();
        let pre = bt.preorder();
        let mut depth = vec![0usize; n];
        for &i in &pre {
            for &c in &bt.nodes[i].children {
                depth[c] = depth[i] + 1;
            }
        }
        let mut size = vec![1usize; n];
        for &i in pre.iter().rev() {
            for &c in &bt.nodes[i].children {
                size[i] += size[c];
            }
        }
        let mut shown = vec![false; n];
        let mut folded = vec![None; n];
        let mut order = Vec::with_capacity(n);
        let mut stack = vec![bt.root];
        while let Some(i) = stack.pop() {
            shown[i] = true;
            order.push(i);
            let node = &bt.nodes[i];
            let fold = !node.children.is_empty()
                && (opts.collapse.contains(&node.id)
                    || opts.depth == Some(depth[i])
                    || (opts.fold_subtrees && node.subtree.is_some()));
            if fold {
                folded[i] = Some(size[i]);
            } else {
                stack.extend(node.children.iter().rev().copied());
            }
        }
        View {
            shown,
            folded,
            order,
            depth,
        }
    }

    /// The layout direction for [`RankDir::Auto`]: `LR` when top-down is
    /// estimated wider than [`SWITCH_ASPECT`] and left-to-right closer to
    /// square, else `TB`.
    pub(super) fn rankdir(&self, bt: &Bt, opts: &DotOptions) -> &'static str {
        match opts.rankdir {
            RankDir::TopDown => return "TB",
            RankDir::LeftRight => return "LR",
            RankDir::Auto => {}
        }
        // Estimated node sizes in points.
        let n = bt.nodes.len();
        let mut w = vec![0.0f64; n];
        let mut h = vec![0.0f64; n];
        for &i in &self.order {
            (w[i], h[i]) = estimate(&bt.nodes[i], self.folded[i], opts.ports);
        }
        let levels = self.order.iter().map(|&i| self.depth[i]).max().unwrap_or(0) + 1;
        let mut max_w = vec![0.0f64; levels];
        let mut max_h = vec![0.0f64; levels];
        for &i in &self.order {
            let d = self.depth[i];
            max_w[d] = max_w[d].max(w[i]);
            max_h[d] = max_h[d].max(h[i]);
        }
        let ranks = RANKSEP_PT * (levels - 1) as f64;
        let tb_width = self.tidy_extent(bt, &w);
        let tb = tb_width / (max_h.iter().sum::<f64>() + ranks);
        if tb <= SWITCH_ASPECT {
            return "TB";
        }
        let lr = (max_w.iter().sum::<f64>() + ranks) / self.tidy_extent(bt, &h);
        if lr.max(1.0 / lr) < tb { "LR" } else { "TB" }
    }
}

/// The extent across the ranks of a tidy drawing of the drawn tree, where
/// each node takes `size` and siblings' subtrees are packed as close as
/// their contours allow, parents centred over their children (Reingold and
/// Tilford, "Tidier drawings of trees", 1981, as Graphviz's `dot` roughly
/// places a tree). Contours are merged shorter into longer, with a lazy
/// offset: O(n log n) in the drawn nodes, no recursion.
impl View {
    fn tidy_extent(&self, bt: &Bt, size: &[f64]) -> f64 {
        /// Per level from the deepest (index 0) to the subtree's root (last):
        /// left and right edges, plus `offset`.
        struct Contour {
            levels: Vec<(f64, f64)>,
            offset: f64,
        }
        let n = bt.nodes.len();
        let mut contour: Vec<Option<Contour>> = (0..n).map(|_| None).collect();
        for &i in self.order.iter().rev() {
            let kids: Vec<usize> = if self.folded[i].is_some() {
                Vec::new()
            } else {
                bt.nodes[i].children.clone()
            };
            let mut acc: Option<Contour> = None;
            // Centres of the first and last child's root.
            let (mut first, mut last) = (None::<f64>, 0.0f64);
            for c in kids {
                let Some(mut b) = contour[c].take() else {
                    continue;
                };
                let root = |k: &Contour| {
                    let &(l, r) = k.levels.last().expect("a root level");
                    (l + r) / 2.0 + k.offset
                };
                match acc.take() {
                    None => {
                        first = Some(root(&b));
                        last = root(&b);
                        acc = Some(b);
                    }
                    Some(a) => {
                        // Shift b right until it clears a on every common level.
                        let common = a.levels.len().min(b.levels.len());
                        let (la, lb) = (a.levels.len(), b.levels.len());
                        let mut shift = f64::NEG_INFINITY;
                        for k in 0..common {
                            let ra = a.levels[la - 1 - k].1 + a.offset;
                            let lbk = b.levels[lb - 1 - k].0 + b.offset;
                            shift = shift.max(ra - lbk + NODESEP_PT);
                        }
                        b.offset += shift;
                        last = root(&b);
                        let (mut long, short) = if la >= lb { (a, b) } else { (b, a) };
                        let ll = long.levels.len();
                        let sl = short.levels.len();
                        for k in 0..sl {
                            let (l, r) = short.levels[sl - 1 - k];
                            let d = short.offset - long.offset;
                            let e = &mut long.levels[ll - 1 - k];
                            e.0 = e.0.min(l + d);
                            e.1 = e.1.max(r + d);
                        }
                        acc = Some(long);
                    }
                }
            }
            let half = size[i] / 2.0;
            contour[i] = Some(match acc {
                None => Contour {
                    levels: vec![(-half, half)],
                    offset: 0.0,
                },
                Some(mut k) => {
                    let centre = (first.unwrap_or(0.0) + last) / 2.0 - k.offset;
                    k.levels.push((centre - half, centre + half));
                    k
                }
            });
        }
        contour[bt.root].as_ref().map_or(0.0, |k| {
            let l = k.levels.iter().map(|e| e.0).fold(f64::INFINITY, f64::min);
            let r = k
                .levels
                .iter()
                .map(|e| e.1)
                .fold(f64::NEG_INFINITY, f64::max);
            r - l
        })
    }
}

/// Graphviz separations of a BT drawing, in points (72 per inch).
const NODESEP_PT: f64 = 0.25 * 72.0;
const RANKSEP_PT: f64 = 0.45 * 72.0;

/// Estimated size in points of a node's drawing: Helvetica averages about
/// 0.55 em per character; lines are 1.2 em; margins as Graphviz pads.
/// Sizes rather over than under: the switch to left-to-right has a margin.
fn estimate(n: &BtNode, folded: Option<usize>, ports: bool) -> (f64, f64) {
    let (label, sub) = texts(n, folded, ports);
    let width = |s: &str, size: f64| {
        s.lines()
            .map(|l| l.chars().count() as f64 * size * 0.55)
            .fold(0.0, f64::max)
    };
    let lines = |s: &str| s.lines().count().max(1) as f64;
    let sub_w = sub.iter().map(|l| width(l, 8.0)).fold(0.0, f64::max);
    let w = width(&label, 11.0).max(sub_w) + 22.0;
    let head = folded.is_none() && symbol(n).is_some() && !names_a_type(n);
    // Lines are 1.2 x their font size (11, 8 under, 15 for a symbol over a
    // name); about 8 pt of margin; Graphviz's minimum height 0.4 in.
    let h = lines(&label) * 13.2 + sub.len() as f64 * 9.6 + if head { 18.0 } else { 0.0 } + 8.0;
    let shape = if n.kind == BtNodeKind::Condition || is_decorator(n) {
        1.4
    } else {
        1.0
    };
    ((w * shape).max(0.45 * 72.0), h.max(0.4 * 72.0))
}

fn is_decorator(n: &BtNode) -> bool {
    n.kind.is_decorator()
}

/// Is `label` only a type's name (the model's, the file's, or a
/// BehaviorTree.CPP built-in's), not a name of the node's own?
fn names_a_type(n: &BtNode) -> bool {
    n.label == n.kind.default_label()
        || Some(&n.label) == n.type_name.as_ref()
        || n.skill.as_ref().is_some_and(|c| c.skill == n.label)
        || btfsm_format::btcpp_xml::BUILTINS
            .iter()
            .any(|(b, _)| *b == n.label)
}

/// The symbol of a control node the paper draws by symbol.
fn symbol(n: &BtNode) -> Option<String> {
    Some(match n.kind {
        BtNodeKind::Sequence => "→".into(),
        BtNodeKind::Fallback => "?".into(),
        BtNodeKind::SequenceMemory => "→*".into(),
        BtNodeKind::FallbackMemory => "?*".into(),
        BtNodeKind::Parallel { success } => format!("⇉ {success}/{}", n.children.len()),
        _ => return None,
    })
}

/// The label of a node and the grey lines under it (its type, its
/// parameter, its ports with `ports`).
fn texts(n: &BtNode, folded: Option<usize>, ports: bool) -> (String, Vec<String>) {
    let custom = !names_a_type(n);
    let ty = n
        .type_name
        .clone()
        .or_else(|| n.skill.as_ref().map(|c| c.skill.clone()))
        .unwrap_or_else(|| n.kind.default_label().to_string());
    let mut sub = Vec::new();
    if let Some(size) = folded {
        // The SubTree's ID (its root's own name under it), else the root's
        // own name, else an id a person wrote, else its type.
        let name = match (&n.subtree, custom) {
            (Some(t), _) => {
                if custom && n.label != *t {
                    sub.push(n.label.clone());
                }
                t.clone()
            }
            (None, true) => n.label.clone(),
            (None, false) if !n.id.contains(['/', '#', '~']) => n.id.clone(),
            (None, false) => symbol(n).unwrap_or(ty),
        };
        sub.push(format!("({size} nodes)"));
        return (name, sub);
    }
    let label = match symbol(n) {
        // The paper's symbol over the node's name (see `bt_node_attrs`).
        Some(_) if custom => n.label.clone(),
        Some(sym) => sym,
        None => {
            if custom && n.type_name.is_some() {
                sub.push(ty);
            } else if custom && (n.kind.is_decorator() || n.kind.is_control()) {
                sub.push(n.kind.default_label().to_string());
            }
            n.label.clone()
        }
    };
    match n.kind {
        BtNodeKind::Repeat { times: Some(t) } | BtNodeKind::Retry { times: t } => {
            sub.push(format!("×{t}"))
        }
        BtNodeKind::Repeat { times: None } => sub.push("×∞".into()),
        BtNodeKind::Timeout { ms } => sub.push(format!("{ms} ms")),
        _ => {}
    }
    if ports {
        sub.extend(n.ports.iter().map(|(k, v)| format!("{k}={v}")));
    }
    (label, sub)
}

/// Shape and label of a BT node (`folded`: the size of the subtree it
/// stands for).
pub(super) fn bt_node_attrs(n: &BtNode, folded: Option<usize>, ports: bool) -> Attrs {
    let mut a = Attrs::default();
    let (label, sub) = texts(n, folded, ports);
    a.set("label", &label);
    for l in sub {
        a.sub(l);
    }
    if folded.is_some() {
        a.set("shape", "box")
            .set("peripheries", "2")
            .set("fillcolor", ACTION_FILL)
            .style("rounded")
            .style("filled");
    } else if let Some(sym) = symbol(n) {
        let big = label == sym;
        if !big {
            a.head(sym);
        }
        a.set("shape", "box")
            .set("fontsize", if big { "15" } else { "11" })
            .set("width", "0.45")
            .set("height", "0.4")
            .set("margin", "0.06,0.03");
    } else {
        match n.kind {
            BtNodeKind::Control => {
                a.set("shape", "box")
                    .set("height", "0.4")
                    .set("margin", "0.06,0.03");
            }
            BtNodeKind::Action => {
                a.set("shape", "box")
                    .set("fillcolor", ACTION_FILL)
                    .set("margin", "0.1,0.04")
                    .style("rounded")
                    .style("filled");
            }
            BtNodeKind::Condition => {
                a.set("shape", "ellipse")
                    .set("fillcolor", "white")
                    .set("fontname", "Helvetica-Oblique")
                    .set("margin", "0.04,0.02")
                    .style("filled");
            }
            // Decorators: a hexagon, narrower than the diamond for long
            // type names (`RateController`).
            _ => {
                a.set("shape", "hexagon")
                    .set("fillcolor", DECISION_FILL)
                    .set("fontsize", "10")
                    .set("margin", "0.02,0.02")
                    .style("filled");
            }
        }
    }
    // The tooltip says everything the label may leave out.
    let mut tip = n.id.clone();
    if let Some(c) = &n.skill {
        tip.push_str(&format!(": {c}"));
    } else if let Some(t) = &n.type_name {
        tip.push_str(&format!(": {t}"));
    }
    if let Some(t) = &n.subtree {
        tip.push_str(&format!("\nSubTree {t}"));
    }
    for (k, v) in &n.ports {
        tip.push_str(&format!("\n{k}={v}"));
    }
    a.set("tooltip", &tip);
    a
}

#[cfg(test)]
mod tests {
    use super::*;

    fn node(id: &str, kind: BtNodeKind, children: Vec<usize>) -> BtNode {
        BtNode::bare(id.into(), id.into(), kind, children)
    }

    /// A root Sequence over `k` actions.
    fn flat(k: usize) -> Bt {
        let mut nodes = vec![node("root", BtNodeKind::Sequence, (1..=k).collect())];
        nodes.extend((1..=k).map(|i| node(&format!("a{i}"), BtNodeKind::Action, vec![])));
        Bt { nodes, root: 0 }
    }

    #[test]
    fn siblings_are_packed_side_by_side_and_parents_centred() {
        let bt = flat(2);
        let view = View::new(&bt, &DotOptions::default());
        let sizes = [30.0, 40.0, 60.0];
        // The two leaves side by side with one separation; the root above.
        assert_eq!(view.tidy_extent(&bt, &sizes), 40.0 + 60.0 + NODESEP_PT);
        let wide_root = [200.0, 40.0, 60.0];
        assert_eq!(view.tidy_extent(&bt, &wide_root), 200.0);
    }

    #[test]
    fn a_wide_flat_tree_is_drawn_left_to_right_and_a_deep_one_top_down() {
        let opts = DotOptions::default();
        let bt = flat(40);
        assert_eq!(View::new(&bt, &opts).rankdir(&bt, &opts), "LR");
        let bt = flat(2);
        assert_eq!(View::new(&bt, &opts).rankdir(&bt, &opts), "TB");
        let forced = DotOptions {
            rankdir: RankDir::TopDown,
            ..Default::default()
        };
        let bt = flat(40);
        assert_eq!(View::new(&bt, &forced).rankdir(&bt, &forced), "TB");
        // A chain of a thousand decorators: tall, never turned.
        let mut nodes: Vec<BtNode> = (0..1000)
            .map(|i| node(&format!("d{i}"), BtNodeKind::Inverter, vec![i + 1]))
            .collect();
        nodes.push(node("leaf", BtNodeKind::Action, vec![]));
        let bt = Bt { nodes, root: 0 };
        assert_eq!(View::new(&bt, &opts).rankdir(&bt, &opts), "TB");
    }

    #[test]
    fn names_types_and_ports_are_escaped_in_html_labels() {
        let mut n = node("x", BtNodeKind::Action, vec![]);
        n.label = "<b>&\"x\"</b>\u{202e}\n>>".into();
        n.type_name = Some("T<>".into());
        n.ports.insert("p".into(), "{a}>>".into());
        let attrs = bt_node_attrs(&n, None, true).into_vec();
        let label = attrs
            .iter()
            .find(|a| a.0 == graphviz_rust::dot_structures::Id::Plain("label".into()))
            .expect("a label");
        let graphviz_rust::dot_structures::Id::Html(text) = &label.1 else {
            panic!("not HTML: {label:?}")
        };
        assert!(
            text.starts_with("<&lt;b&gt;&amp;&quot;x&quot;&lt;/b&gt; <BR/>&gt;&gt;<BR/>"),
            "{text}"
        );
        assert!(
            text.contains(">T&lt;&gt;<BR/>p={a}&gt;&gt;</FONT>>"),
            "{text}"
        );
        // No raw `>` or `<` from the input: only the label's own tags.
        let inner = &text[1..text.len() - 1];
        let tags = inner.matches('<').count();
        assert_eq!(tags, inner.matches('>').count(), "{text}");
    }

    #[test]
    fn a_legend_only_where_fills_carry_a_status() {
        let policy = btfsm_model::Policy {
            name: "t".into(),
            description: None,
            body: PolicyBody::Bt(flat(2)),
        };
        let plain = policy_dot(&policy, &DotOptions::default());
        assert!(!plain.contains("legend"), "{plain}");
        let traced = DotOptions {
            highlight: [("a1".to_string(), Highlight::Status(Status::Running))].into(),
            ..Default::default()
        };
        let dot = policy_dot(&policy, &traced);
        assert!(dot.contains("subgraph \"cluster legend\""), "{dot}");
        for s in ["RUNNING", "SUCCESS", "FAILURE"] {
            assert!(dot.contains(&format!("\"legend: {s}\"[label={s}")), "{dot}");
        }
        // One node is gold: the legend's sample is written otherwise.
        assert_eq!(dot.matches("fillcolor=gold").count(), 1, "{dot}");
    }

    #[test]
    fn folded_nodes_hide_their_subtree_and_count_it() {
        let bt = flat(3);
        let opts = DotOptions {
            collapse: ["root".to_string()].into(),
            ..Default::default()
        };
        let view = View::new(&bt, &opts);
        assert_eq!(view.order, vec![0]);
        assert_eq!(view.folded[0], Some(4));
        assert!(!view.shown[1]);
    }
}
