//! `compare --mode tree`: the ordered tree edit distance of two Behavior
//! Trees (`metrics::ted`, unit costs on the node labels of
//! `metrics::ted::bt`) and its edit script in the trees' own node ids —
//! renames `~`, moves `>` (a subtree deleted in one place and inserted
//! identically in another, one step costing two per node), deletions `-`,
//! insertions `+`, each with its parent and child position — as a table
//! section, JSON (the `tree` key beside SPEC §7's modes) and markdown.

use btfsm_core::sanitize::shown;
use btfsm_metrics::ted::bt::{BtPair, label_pair};
use btfsm_metrics::ted::{self, TedOptions, TedResult, TedStop, TreeEdit};
use btfsm_model::Bt;
use std::time::Instant;

/// What the label of a node is, told in every report.
pub const LABEL: &str = "node type with parameters, display name, skill binding with arguments, ports (not the node id)";

#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct TreeRename {
    pub a: String,
    pub b: String,
    pub from: String,
    pub to: String,
}

/// A node or subtree root with its place: parent id and child position.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct Place {
    pub id: String,
    pub label: String,
    /// Parent id (`null` for the root).
    pub parent: Option<String>,
    /// Position among the parent's children, from 0.
    pub position: usize,
}

#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct TreeMove {
    /// Nodes in the moved subtree.
    pub nodes: usize,
    pub from: Place,
    pub to: Place,
}

/// The edit script a → b of a tree mapping.
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct TreeScript {
    pub renamed: Vec<TreeRename>,
    pub moved: Vec<TreeMove>,
    /// Nodes of a deleted (their children move up to their parent).
    pub deleted: Vec<Place>,
    /// Nodes of b inserted.
    pub inserted: Vec<Place>,
}

impl TreeScript {
    /// Unit operations: a move costs a deletion and an insertion per node.
    pub fn cost(&self) -> u64 {
        (self.renamed.len() + self.deleted.len() + self.inserted.len()) as u64
            + self.moved.iter().map(|m| 2 * m.nodes as u64).sum::<u64>()
    }
}

/// `tree` in `compare`'s JSON.
#[derive(Debug, Clone, serde::Serialize)]
pub struct TreeReport {
    pub ted: u64,
    pub exact: bool,
    pub lower_bound: u64,
    pub upper_bound: u64,
    /// Table cells computed (the deterministic work budget's unit).
    pub work: u64,
    /// When not exact: the budget that ended the computation, `work`
    /// (`--tree-max-work`) or `memory` (`--tree-max-memory`); `null` when
    /// exact. The same on any machine.
    pub stopped_by: Option<TedStop>,
    pub millis: u64,
    pub label: &'static str,
    pub edit_script: TreeScript,
}

/// Where each node sits: parent and position.
fn places(bt: &Bt) -> Vec<(Option<usize>, usize)> {
    let mut out = vec![(None, 0); bt.nodes.len()];
    for (p, n) in bt.nodes.iter().enumerate() {
        for (i, &c) in n.children.iter().enumerate() {
            if let Some(slot) = out.get_mut(c) {
                *slot = (Some(p), i);
            }
        }
    }
    out
}

/// The ordered tree mapping of two BTs: the distance (or its interval)
/// with a mapping of its upper bound that pairs nodes of one class where an
/// equally cheap mapping does ([`ted::prefer_same_class`]).
pub struct TreeMapping {
    pub pair: BtPair,
    pub result: TedResult,
    pub millis: u64,
}

impl TreeMapping {
    pub fn new(a: &Bt, b: &Bt, opts: &TedOptions) -> TreeMapping {
        let start = Instant::now();
        let pair = label_pair(a, b);
        let mut result = ted::ted(&pair.a, &pair.b, opts);
        let cost = ted::prefer_same_class(
            &pair.a,
            &pair.b,
            &pair.class_a,
            &pair.class_b,
            &mut result.mapping,
        );
        // Never above: on an interval's mapping, possibly below.
        result.upper = result.upper.min(cost);
        result.lower = result.lower.min(result.upper);
        TreeMapping {
            pair,
            result,
            millis: u64::try_from(start.elapsed().as_millis()).unwrap_or(u64::MAX),
        }
    }

    /// The report of this mapping, in the nodes' ids of `a` and `b`.
    pub fn report(&self, a: &Bt, b: &Bt) -> TreeReport {
        let (pair, r) = (&self.pair, &self.result);
        let edits = ted::edit_script(&pair.a, &pair.b, &r.mapping);
        let (pa, pb) = (places(a), places(b));
        let place = |bt: &Bt, pl: &[(Option<usize>, usize)], shown: &[String], n: usize| Place {
            id: bt.nodes[n].id.clone(),
            label: shown[n].clone(),
            parent: pl[n].0.map(|p| bt.nodes[p].id.clone()),
            position: pl[n].1,
        };
        let mut s = TreeScript::default();
        for e in edits {
            match e {
                TreeEdit::Rename { a: x, b: y } => s.renamed.push(TreeRename {
                    a: a.nodes[x].id.clone(),
                    b: b.nodes[y].id.clone(),
                    from: pair.shown_a[x].clone(),
                    to: pair.shown_b[y].clone(),
                }),
                TreeEdit::Move { a: x, b: y, size } => s.moved.push(TreeMove {
                    nodes: size,
                    from: place(a, &pa, &pair.shown_a, x),
                    to: place(b, &pb, &pair.shown_b, y),
                }),
                TreeEdit::Delete { a: x } => s.deleted.push(place(a, &pa, &pair.shown_a, x)),
                TreeEdit::Insert { b: y } => s.inserted.push(place(b, &pb, &pair.shown_b, y)),
            }
        }
        debug_assert_eq!(s.cost(), r.upper);
        TreeReport {
            ted: r.upper,
            exact: r.exact(),
            lower_bound: r.lower,
            upper_bound: r.upper,
            work: r.work,
            stopped_by: if r.exact() { None } else { r.stopped_by },
            millis: self.millis,
            label: LABEL,
            edit_script: s,
        }
    }
}

/// The tree edit distance of `a` and `b` with its script.
pub fn tree_report(a: &Bt, b: &Bt, opts: &TedOptions) -> TreeReport {
    TreeMapping::new(a, b, opts).report(a, b)
}

/// The summary line: distance, exactness, time.
pub fn summary(t: &TreeReport) -> String {
    let how = if t.exact {
        "exact".to_string()
    } else {
        let why = match t.stopped_by {
            Some(TedStop::Memory) => "the memory budget would be passed (raise --tree-max-memory)",
            _ => "the work budget ran out (raise --tree-max-work)",
        };
        format!(
            "not exact: in [{}, {}], {why}",
            t.lower_bound, t.upper_bound
        )
    };
    format!(
        "tree edit distance (ordered, unit costs on node labels): {} ({how}, {} ms)",
        t.ted, t.millis
    )
}

/// One line per edit, signs `~` `>` `-` `+`, in the policies' node ids.
pub fn script_lines(t: &TreeReport) -> Vec<String> {
    let s = &t.edit_script;
    let at = |p: &Place| match &p.parent {
        Some(q) => format!("`{}`[{}]", shown(q), p.position),
        None => "the root".to_string(),
    };
    let mut out = Vec::new();
    for r in &s.renamed {
        let ids = if r.a == r.b {
            format!("`{}`", shown(&r.a))
        } else {
            format!("`{}` → `{}`", shown(&r.a), shown(&r.b))
        };
        out.push(format!("~ {ids}: {} → {}", shown(&r.from), shown(&r.to)));
    }
    for m in &s.moved {
        let ids = if m.from.id == m.to.id {
            format!("`{}`", shown(&m.from.id))
        } else {
            format!("`{}` (as `{}`)", shown(&m.from.id), shown(&m.to.id))
        };
        out.push(format!(
            "> move subtree {ids} ({} node{}, {} edits) from {} to {}",
            m.nodes,
            if m.nodes == 1 { "" } else { "s" },
            2 * m.nodes,
            at(&m.from),
            at(&m.to)
        ));
    }
    for d in &s.deleted {
        out.push(format!(
            "- `{}` {} at {}",
            shown(&d.id),
            shown(&d.label),
            at(d)
        ));
    }
    for i in &s.inserted {
        out.push(format!(
            "+ `{}` {} at {}",
            shown(&i.id),
            shown(&i.label),
            at(i)
        ));
    }
    out
}

/// The table section: summary, then the script (indented).
pub fn render_text(t: &TreeReport) -> String {
    let cost = t.edit_script.cost();
    let mut out = format!(
        "{}\ntree edit script ({} edit{}):\n",
        summary(t),
        cost,
        if cost == 1 { "" } else { "s" }
    );
    let lines = script_lines(t);
    if lines.is_empty() {
        out.push_str("  (none: the trees are identical, children in the same order)\n");
    }
    for l in lines {
        out.push_str(&format!("  {l}\n"));
    }
    out
}
