//! `btfsm compare`: graph edit distance between two policies (paper sec. IV-A 2,
//! Eq. 2; SPEC §3) in the `structural`, `labeled` and `named` modes, each with
//! the edit script of its mapping told in the policies' own terms (vertex
//! names and types, transition labels) with the relabels and reorders the
//! distance does not count (`changes.rs`), and the diff drawing of the
//! paper's Figs. 7 and 8 (the new policy with added elements magenta, the
//! old one's removed elements dashed grey, changed ones orange; DOT in
//! `diff_dot.rs`, Mermaid in `diff_mermaid.rs`).
//!
//! The GED engine (`metrics::ged`) works on unlabeled arcs, so a mapping says
//! only how many arcs between two vertices are kept. Which of several
//! parallel transitions those are is decided here, label by label: arcs whose
//! labels agree are kept first, so a re-routed `FAILURE` arc shows up as one
//! `FAILURE` arc removed and one added, not as an arbitrary pair.

mod changes;
#[cfg(test)]
mod changes_tests;
mod changes_text;
mod diff_dot;
mod diff_mermaid;
mod render;
mod script;
#[cfg(test)]
mod tests;
mod text;
pub mod tree;

pub use changes::{Relabel, Reorder};
pub use render::{render_json, render_markdown, render_table};
use script::{ScriptIndex, key_ids};
pub use text::Text;

use btfsm_metrics::cpu::thread_cpu_time;
use btfsm_metrics::ged::{
    Deadline, GedMode, GedOptions, Shape, StopReason, keep_same_labels, mapping_cost,
    named_mapping_of_ids, search_mapping,
};
use btfsm_metrics::ted::TedOptions;
use btfsm_model::graph::{PolicyGraph, VertexType, policy_graph};
use btfsm_model::{IdSource, Policy, PolicyBody, PolicyKind};
use std::collections::BTreeMap;
use std::time::Instant;

/// One policy being compared.
#[derive(Debug, Clone, Copy)]
pub struct Side<'a> {
    /// The file it came from, as given.
    pub file: &'a str,
    pub policy: &'a Policy,
}

/// The modes `compare` computes, in report order.
pub fn modes_of(selection: Option<GedMode>) -> Vec<GedMode> {
    match selection {
        Some(m) => vec![m],
        None => vec![GedMode::Structural, GedMode::Labeled, GedMode::Named],
    }
}

/// A vertex named in an edit script.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct VertexRef {
    /// Identity (BT node id, state path, outcome name).
    pub key: Text,
    /// Display name.
    pub name: Text,
    #[serde(rename = "type")]
    pub vtype: VertexType,
}

/// A vertex of a kept (substituted at cost 0) as the vertex of b it maps to.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct KeptVertex {
    pub a: Text,
    pub b: Text,
    /// Both keys were derived by a reader (BehaviorTree.CPP nodes without
    /// `btfsm:id`): a new key says nothing of the node, so it is not told
    /// as a rematch.
    #[serde(skip)]
    pub derived: bool,
}

/// Arcs between two vertices with one label.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, serde::Serialize)]
pub struct ArcRef {
    /// Tail key (of b for added and kept arcs, of a for removed ones).
    pub from: Text,
    /// Head key, likewise.
    pub to: Text,
    /// Outcome or guard label; `initial` for an HFSM container's arc to its
    /// initial state; empty for a BT edge.
    pub label: Text,
    /// How many such parallel arcs.
    pub count: u32,
    /// For a kept arc whose label differs in a: a's label (unit-cost GED does
    /// not charge for it, a reviewer wants to see it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub label_in_a: Option<Text>,
}

/// The edit script of one mode's mapping, a → b.
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct Script {
    pub vertices_added: Vec<VertexRef>,
    pub vertices_removed: Vec<VertexRef>,
    pub vertices_kept: Vec<KeptVertex>,
    pub arcs_added: Vec<ArcRef>,
    pub arcs_removed: Vec<ArcRef>,
    pub arcs_kept: Vec<ArcRef>,
    /// Kept elements whose type, skill, arguments, name, initial state or
    /// guard terms changed (not charged by the GED; `changes.rs`).
    pub relabelled: Vec<Relabel>,
    /// Kept composites whose kept children (states whose kept guards) come
    /// in another order (not charged by the GED; `changes.rs`).
    pub reordered: Vec<Reorder>,
}

impl Script {
    /// Unit edit operations: vertices and arcs added and removed.
    pub fn cost(&self) -> u64 {
        let arcs = |l: &[ArcRef]| l.iter().map(|a| u64::from(a.count)).sum::<u64>();
        (self.vertices_added.len() + self.vertices_removed.len()) as u64
            + arcs(&self.arcs_added)
            + arcs(&self.arcs_removed)
    }

    /// Kept vertices whose key changes, keys derived by a reader aside
    /// (`structural` and `labeled` mappings have them; `named` only when a
    /// node's given id changed into a derived one or back).
    pub fn rematched(&self) -> impl Iterator<Item = &KeptVertex> {
        self.vertices_kept
            .iter()
            .filter(|k| k.a != k.b && !k.derived)
    }

    /// Relabels: the entries of `relabelled` and the kept arcs whose label
    /// changed (each parallel arc once).
    pub fn relabels(&self) -> u64 {
        let arcs: u64 = self
            .arcs_kept
            .iter()
            .filter(|a| a.label_in_a.is_some())
            .map(|a| u64::from(a.count))
            .sum();
        self.relabelled.len() as u64 + arcs
    }

    /// Reorders: the entries of `reordered`.
    pub fn reorders(&self) -> u64 {
        self.reordered.len() as u64
    }

    /// Whether the mapping keeps everything as it was: no edit, no
    /// rematch, no relabel, no reorder.
    pub fn is_unchanged(&self) -> bool {
        self.cost() == 0
            && self.rematched().next().is_none()
            && self.relabels() == 0
            && self.reorders() == 0
    }
}

/// One mode's result (SPEC §7: `ged`, `exact`, `lower_bound`, `upper_bound`,
/// `millis`, `edit_script`), with the counts of the script's relabels and
/// reorders beside the distance, which does not count them.
#[derive(Debug, Clone, serde::Serialize)]
pub struct ModeReport {
    #[serde(skip)]
    pub mode: GedMode,
    pub ged: u64,
    pub relabels: u64,
    pub reorders: u64,
    pub exact: bool,
    pub lower_bound: u64,
    pub upper_bound: u64,
    pub millis: u64,
    /// The same time in microseconds (for timing pairs that take under a
    /// millisecond; `millis` = `micros` / 1000, rounded down).
    pub micros: u64,
    /// When `exact` is false: what ended the search, `work` (the work
    /// budget, reproducible on any machine), `time` (the CPU-time safety
    /// cap `--timeout-ms`, before the work budget: the interval may differ
    /// on another machine) or `size` (too large for the exact search).
    /// Absent when exact.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stopped_by: Option<StopReason>,
    /// Work units the search spent (`--work`; 0 for `named`): the same on
    /// any machine.
    pub work: u64,
    pub edit_script: Script,
}

/// Size and kind of one side, for the table header.
#[derive(Debug, Clone)]
pub struct SideSummary {
    pub file: String,
    pub name: String,
    pub kind: PolicyKind,
    pub vertices: usize,
    pub arcs: usize,
}

/// `btfsm compare A B`.
#[derive(Debug, Clone)]
pub struct CompareReport {
    pub a: SideSummary,
    pub b: SideSummary,
    pub modes: Vec<ModeReport>,
    /// The primary mode's diff as a Mermaid flowchart (`diff_mermaid.rs`),
    /// `Err` with the numbers of nodes and links when it is too large.
    pub diagram: Option<Result<String, (usize, usize)>>,
    /// The ordered tree edit distance (`--mode tree`; BT pairs only).
    pub tree: Option<tree::TreeReport>,
}

impl CompareReport {
    /// The result of one mode, if computed.
    pub fn mode(&self, mode: GedMode) -> Option<&ModeReport> {
        self.modes.iter().find(|m| m.mode == mode)
    }

    /// The mode whose edit script the table prints and `--dot` draws: the
    /// only one computed, or `named` (the engineer's own edits) when all are.
    pub fn primary(&self) -> Option<&ModeReport> {
        self.mode(GedMode::Named).or(self.modes.first())
    }
}

/// The two graphs of a comparison, built once and reused by every mode.
pub struct Pair<'a> {
    a: Side<'a>,
    b: Side<'a>,
    ga: PolicyGraph,
    gb: PolicyGraph,
    ia: ScriptIndex,
    ib: ScriptIndex,
    /// HFSM containment in a: state key -> its container's key.
    parent_a: BTreeMap<String, String>,
    /// What relabels and reorders read of two BTs (`changes.rs`).
    bt_facts: Option<(changes::BtFacts, changes::BtFacts)>,
    /// Per vertex, whether its key was derived by a reader (BT nodes
    /// without a given id); empty for machines.
    derived_a: Vec<bool>,
    derived_b: Vec<bool>,
    /// The ordered tree mapping of two BTs (`tree.rs`).
    tree: Option<tree::TreeMapping>,
    /// The `named` mapping (a → b): equal keys; for two BTs, derived keys
    /// by the ordered tree mapping instead (`named_mapping`).
    by_name: Vec<Option<usize>>,
}

/// State key -> container key, for every nested state of an HFSM.
fn containers(p: &Policy) -> BTreeMap<String, String> {
    let PolicyBody::Machine(m) = &p.body else {
        return BTreeMap::new();
    };
    let keys = m.keys();
    m.states
        .iter()
        .enumerate()
        .filter_map(|(i, s)| s.parent.map(|q| (keys[i].clone(), keys[q].clone())))
        .collect()
}

/// Per BT node, whether its id was derived by a reader.
fn derived_ids(p: &Policy) -> Vec<bool> {
    match &p.body {
        PolicyBody::Bt(bt) => bt.nodes.iter().map(|n| n.id_source.is_derived()).collect(),
        PolicyBody::Machine(_) => Vec::new(),
    }
}

/// The `named` mapping of two graphs whose keys have ids `ids_a`, `ids_b`:
/// equal keys, except that a key derived from a node's position names no
/// node across versions (five Nav2 nodes inserted before a RateController
/// give it the position of the first of them); then the nodes whose keys
/// were derived (from a position or a display name) and are still
/// unpaired, by the ordered tree mapping `tree` of two BTs. Keys the
/// author gave (TOML keys, `btfsm:id`) pair by equality only, as the
/// paper's named GED does.
fn named_mapping(
    (a, ids_a): (&Policy, &[u32]),
    (b, ids_b): (&Policy, &[u32]),
    tree: Option<&tree::TreeMapping>,
) -> Vec<Option<usize>> {
    let mut map = named_mapping_of_ids(ids_a, ids_b);
    let (PolicyBody::Bt(ta), PolicyBody::Bt(tb)) = (&a.body, &b.body) else {
        return map;
    };
    let positional =
        |n: Option<&btfsm_model::BtNode>| n.is_some_and(|n| n.id_source == IdSource::Position);
    for (u, m) in map.iter_mut().enumerate() {
        if let Some(v) = *m
            && (positional(ta.nodes.get(u)) || positional(tb.nodes.get(v)))
        {
            *m = None;
        }
    }
    let Some(t) = tree else { return map };
    let mut taken = vec![false; ids_b.len()];
    for v in map.iter().flatten() {
        taken[*v] = true;
    }
    let derived = |n: Option<&btfsm_model::BtNode>| n.is_some_and(|n| n.id_source.is_derived());
    for &(x, y) in &t.result.mapping {
        if map.get(x) == Some(&None)
            && taken.get(y) == Some(&false)
            && derived(ta.nodes.get(x))
            && derived(tb.nodes.get(y))
        {
            map[x] = Some(y);
            taken[y] = true;
        }
    }
    map
}

impl<'a> Pair<'a> {
    pub fn new(a: Side<'a>, b: Side<'a>) -> Self {
        Self::with_tree_options(a, b, &TedOptions::default(), true)
    }

    /// [`Pair::new`], with the ordered tree mapping of two BTs computed
    /// under `topts` (`compare --tree-max-work`) when `tree` asks for it or
    /// the `named` mapping needs it (a node whose id a reader derived).
    pub fn with_tree_options(a: Side<'a>, b: Side<'a>, topts: &TedOptions, tree: bool) -> Self {
        let (ga, gb) = (policy_graph(a.policy), policy_graph(b.policy));
        let (ia, ib) = (ScriptIndex::new(&ga), ScriptIndex::new(&gb));
        // Each vertex's key as an id shared by both graphs (equal keys,
        // equal ids): the mapping by name costs no string work.
        let (ids_a, ids_b) = key_ids(&ia, &ib);
        let (derived_a, derived_b) = (derived_ids(a.policy), derived_ids(b.policy));
        let needed = tree || derived_a.iter().chain(&derived_b).any(|&d| d);
        let tree = match (&a.policy.body, &b.policy.body) {
            (PolicyBody::Bt(x), PolicyBody::Bt(y)) if needed => {
                Some(tree::TreeMapping::new(x, y, topts))
            }
            _ => None,
        };
        let by_name = named_mapping((a.policy, &ids_a), (b.policy, &ids_b), tree.as_ref());
        Pair {
            ia,
            ib,
            ga,
            gb,
            parent_a: containers(a.policy),
            bt_facts: changes::bt_facts(a.policy, b.policy),
            derived_a,
            derived_b,
            tree,
            by_name,
            a,
            b,
        }
    }

    /// The ordered tree edit distance of two BTs and its script.
    pub fn tree_report(&self) -> Option<tree::TreeReport> {
        match (&self.a.policy.body, &self.b.policy.body, &self.tree) {
            (PolicyBody::Bt(a), PolicyBody::Bt(b), Some(t)) => Some(t.report(a, b)),
            _ => None,
        }
    }

    /// GED in one mode, with its labelled edit script, within
    /// `opts.timeout` of CPU time for the whole of it: the clock starts
    /// before the compact graphs are built, the mapping by name and its
    /// script come next, and the search gets what remains minus twice the
    /// CPU time that script took (the script of the search's mapping, if
    /// better, costs about as much, and the unused one must be freed: 1.3
    /// to 1.6 times the first on 100k-vertex BTs). `millis` is the
    /// wall-clock time of all of it.
    pub fn run(&self, mode: GedMode, opts: &GedOptions) -> ModeReport {
        let start = Instant::now();
        let cpu = || thread_cpu_time().unwrap_or_else(|| start.elapsed());
        let cpu_start = cpu();
        let (sa, sb) = (Shape::from(&self.ga), Shape::from(&self.gb));
        let mut by_name = self.by_name.clone();
        if mode == GedMode::Labeled {
            keep_same_labels(&sa, &sb, &mut by_name);
        }
        let named_cost = mapping_cost(&sa, &sb, &by_name);
        let before_script = cpu();
        let named = self.script(&by_name);
        let (lower, upper, edit_script, stopped_by, work) = if mode == GedMode::Named {
            (named_cost, named_cost, named, None, 0)
        } else {
            let now = cpu();
            let reserve = now.saturating_sub(before_script) * 2;
            let used = now.saturating_sub(cpu_start);
            let deadline = Deadline::after(opts.timeout.saturating_sub(used + reserve));
            let found = search_mapping(&sa, &sb, mode == GedMode::Labeled, deadline, opts.work);
            // Among mappings of equal cost, prefer the one by name: its
            // script reads as the engineer's own edits.
            if named_cost <= found.upper_bound {
                (
                    found.lower_bound,
                    named_cost,
                    named,
                    found.stopped_by,
                    found.work,
                )
            } else {
                let s = self.script(&found.map);
                let (lo, hi) = (found.lower_bound, found.upper_bound);
                (lo, hi, s, found.stopped_by, found.work)
            }
        };
        debug_assert_eq!(edit_script.cost(), upper);
        let micros = u64::try_from(start.elapsed().as_micros()).unwrap_or(u64::MAX);
        ModeReport {
            mode,
            ged: upper,
            relabels: edit_script.relabels(),
            reorders: edit_script.reorders(),
            exact: lower >= upper,
            lower_bound: lower.min(upper),
            upper_bound: upper,
            millis: micros / 1000,
            micros,
            stopped_by: if lower >= upper { None } else { stopped_by },
            work,
            edit_script,
        }
    }

    pub fn report(&self, modes: Vec<ModeReport>) -> CompareReport {
        let summary = |s: &Side, g: &PolicyGraph| SideSummary {
            file: s.file.to_string(),
            name: s.policy.name.clone(),
            kind: s.policy.kind(),
            vertices: g.vertex_count(),
            arcs: g.arc_count(),
        };
        let diagram = modes
            .iter()
            .find(|m| m.mode == GedMode::Named)
            .or(modes.first())
            .map(|p| self.diagram(&p.edit_script));
        CompareReport {
            a: summary(&self.a, &self.ga),
            b: summary(&self.b, &self.gb),
            modes,
            diagram,
            tree: None,
        }
    }
}
