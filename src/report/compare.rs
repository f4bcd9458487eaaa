//! `btfsm compare`: graph edit distance between two policies (paper sec. IV-A 2,
//! Eq. 2; SPEC §3) in the `structural`, `labeled` and `named` modes, each with
//! the edit script of its mapping told in the policies' own terms (vertex
//! names and types, transition labels), and the diff drawing of the paper's
//! Figs. 7 and 8 (the new policy with added elements red and the old one's
//! removed elements dashed grey).
//!
//! The GED engine (`metrics::ged`) works on unlabeled arcs, so a mapping says
//! only how many arcs between two vertices are kept. Which of several
//! parallel transitions those are is decided here, label by label: arcs whose
//! labels agree are kept first, so a re-routed `FAILURE` arc shows up as one
//! `FAILURE` arc removed and one added, not as an arbitrary pair.

use crate::graph::{PolicyGraph, VertexType, policy_graph};
use crate::metrics::ged::{
    GedMode, GedOptions, Shape, injective, keep_same_labels, mapping_cost, named_mapping_of_ids,
    search_mapping,
};
use crate::model::{Policy, PolicyBody, PolicyKind};
use crate::render::dot::{DotOptions, Highlight};
use std::collections::{BTreeMap, BTreeSet, HashMap};
use std::sync::Arc;
use std::time::Instant;

/// An immutable shared string of an edit script (a key, a name, a label):
/// cloning it copies a pointer, so that writing a script of 100k entries
/// allocates no strings. Serialized as a plain string.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Text(Arc<str>);

impl Text {
    pub fn as_str(&self) -> &str {
        &self.0
    }
}

impl std::ops::Deref for Text {
    type Target = str;
    fn deref(&self) -> &str {
        &self.0
    }
}

impl From<&str> for Text {
    fn from(s: &str) -> Text {
        Text(Arc::from(s))
    }
}

impl PartialEq<str> for Text {
    fn eq(&self, other: &str) -> bool {
        &*self.0 == other
    }
}

impl PartialEq<&str> for Text {
    fn eq(&self, other: &&str) -> bool {
        &*self.0 == *other
    }
}

impl std::fmt::Display for Text {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl serde::Serialize for Text {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.0)
    }
}

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
}

impl Script {
    /// Unit edit operations: vertices and arcs added and removed.
    pub fn cost(&self) -> u64 {
        let arcs = |l: &[ArcRef]| l.iter().map(|a| u64::from(a.count)).sum::<u64>();
        (self.vertices_added.len() + self.vertices_removed.len()) as u64
            + arcs(&self.arcs_added)
            + arcs(&self.arcs_removed)
    }

    /// Kept vertices whose key changes (only `structural` and `labeled`
    /// mappings have them).
    pub fn rematched(&self) -> impl Iterator<Item = &KeptVertex> {
        self.vertices_kept.iter().filter(|k| k.a != k.b)
    }
}

/// One mode's result (SPEC §7: `ged`, `exact`, `lower_bound`, `upper_bound`,
/// `millis`, `edit_script`).
#[derive(Debug, Clone, serde::Serialize)]
pub struct ModeReport {
    #[serde(skip)]
    pub mode: GedMode,
    pub ged: u64,
    pub exact: bool,
    pub lower_bound: u64,
    pub upper_bound: u64,
    pub millis: u64,
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
    /// Each vertex's key as an id shared by both graphs (equal keys, equal
    /// ids), so that the mapping by name costs no string work per mode.
    ids_a: Vec<u32>,
    ids_b: Vec<u32>,
    /// HFSM containment in a: state key -> its container's key.
    parent_a: BTreeMap<String, String>,
}

/// What writing edit scripts needs of one graph, computed once with the
/// graph (it depends on that graph only): its keys, names and arc labels as
/// shared strings, its vertices in key order, and its arcs grouped by
/// ordered pair of vertices with their labels sorted. With it, an edit
/// script costs O((n + m) log m) integer work and allocates no strings.
struct ScriptIndex {
    keys: Vec<Text>,
    names: Vec<Text>,
    /// Label of each arc (edge index), interned.
    labels: Vec<Text>,
    /// Vertices in key order (keys are unique within a graph).
    by_key: Vec<u32>,
    /// Position of each vertex in `by_key`.
    rank: Vec<u32>,
    /// `(tail, head, first, end)`: the arcs from tail to head are
    /// `arcs[first..end]`; sorted by `(tail, head)`.
    groups: Vec<(u32, u32, u32, u32)>,
    /// Edge indices, grouped, by label within a group.
    arcs: Vec<u32>,
}

impl ScriptIndex {
    fn new(g: &PolicyGraph) -> ScriptIndex {
        let nodes = g.g.raw_nodes();
        let n = nodes.len();
        let key = |i: u32| nodes[i as usize].weight.key.as_str();
        let mut by_key: Vec<u32> = (0..n as u32).collect();
        by_key.sort_unstable_by(|&x, &y| key(x).cmp(key(y)).then(x.cmp(&y)));
        let mut rank = vec![0u32; n];
        for (r, &v) in by_key.iter().enumerate() {
            rank[v as usize] = r as u32;
        }
        let edges = g.g.raw_edges();
        let mut interned: HashMap<&str, Text> = HashMap::new();
        let labels: Vec<Text> = edges
            .iter()
            .map(|e| {
                let l = e.weight.label();
                interned.entry(l).or_insert_with(|| Text::from(l)).clone()
            })
            .collect();
        let ends = |e: u32| {
            let x = &edges[e as usize];
            (x.source().index() as u32, x.target().index() as u32)
        };
        let mut arcs: Vec<u32> = (0..edges.len() as u32).collect();
        arcs.sort_unstable_by(|&x, &y| {
            ends(x)
                .cmp(&ends(y))
                .then_with(|| labels[x as usize].cmp(&labels[y as usize]))
                .then(x.cmp(&y))
        });
        let mut groups: Vec<(u32, u32, u32, u32)> = Vec::new();
        for (i, &e) in arcs.iter().enumerate() {
            let (t, h) = ends(e);
            match groups.last_mut() {
                Some(last) if (last.0, last.1) == (t, h) => last.3 = i as u32 + 1,
                _ => groups.push((t, h, i as u32, i as u32 + 1)),
            }
        }
        ScriptIndex {
            keys: nodes
                .iter()
                .map(|v| Text::from(v.weight.key.as_str()))
                .collect(),
            names: nodes
                .iter()
                .map(|v| Text::from(v.weight.label.as_str()))
                .collect(),
            labels,
            by_key,
            rank,
            groups,
            arcs,
        }
    }

    /// The labels of group `k`, sorted.
    fn group_labels(&self, k: usize) -> impl Iterator<Item = &Text> {
        let (_, _, s, e) = self.groups[k];
        self.arcs[s as usize..e as usize]
            .iter()
            .map(|&e| &self.labels[e as usize])
    }

    /// The group of arcs from `t` to `h`, if any.
    fn group(&self, t: usize, h: usize) -> Option<usize> {
        let key = (t as u32, h as u32);
        self.groups
            .binary_search_by(|&(x, y, _, _)| (x, y).cmp(&key))
            .ok()
    }

    /// An end of an arc: its key and the key's rank.
    fn end(&self, u: usize) -> (&Text, u32) {
        (&self.keys[u], self.rank[u])
    }
}

/// Ids for the keys of both graphs: equal keys get equal ids.
fn key_ids<'g>(a: &'g PolicyGraph, b: &'g PolicyGraph) -> (Vec<u32>, Vec<u32>) {
    let mut ids: HashMap<&'g str, u32> = HashMap::with_capacity(a.g.node_count());
    let mut of = |g: &'g PolicyGraph| -> Vec<u32> {
        keys(g)
            .map(|k| {
                let next = ids.len() as u32;
                *ids.entry(k).or_insert(next)
            })
            .collect()
    };
    let ia = of(a);
    let ib = of(b);
    (ia, ib)
}

/// The vertex keys of a graph, in vertex order.
fn keys(g: &PolicyGraph) -> impl Iterator<Item = &str> {
    g.g.raw_nodes().iter().map(|v| v.weight.key.as_str())
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

impl<'a> Pair<'a> {
    pub fn new(a: Side<'a>, b: Side<'a>) -> Self {
        let (ga, gb) = (policy_graph(a.policy), policy_graph(b.policy));
        let (ids_a, ids_b) = key_ids(&ga, &gb);
        Pair {
            ia: ScriptIndex::new(&ga),
            ib: ScriptIndex::new(&gb),
            ids_a,
            ids_b,
            ga,
            gb,
            parent_a: containers(a.policy),
            a,
            b,
        }
    }

    /// GED in one mode, with its labelled edit script, within
    /// `opts.timeout` for the whole of it: the clock starts before the
    /// compact graphs are built, the mapping by name and its script come
    /// next, and the search gets what remains minus the time that script
    /// took (the script of the search's mapping, if better, costs as much).
    /// `millis` is the time of all of it.
    pub fn run(&self, mode: GedMode, opts: &GedOptions) -> ModeReport {
        let start = Instant::now();
        let (sa, sb) = (Shape::from(&self.ga), Shape::from(&self.gb));
        let mut by_name = named_mapping_of_ids(&self.ids_a, &self.ids_b);
        if mode == GedMode::Labeled {
            keep_same_labels(&sa, &sb, &mut by_name);
        }
        let named_cost = mapping_cost(&sa, &sb, &by_name);
        let before_script = Instant::now();
        let named = self.script(&by_name);
        let (lower, upper, edit_script) = if mode == GedMode::Named {
            (named_cost, named_cost, named)
        } else {
            let reserve = before_script.elapsed();
            let deadline = (start + opts.timeout)
                .checked_sub(reserve)
                .map_or(start, |d| d.max(start));
            let found = search_mapping(
                &sa,
                &sb,
                mode == GedMode::Labeled,
                deadline,
                opts.max_expansions,
            );
            // Among mappings of equal cost, prefer the one by name: its
            // script reads as the engineer's own edits.
            if named_cost <= found.upper_bound {
                (found.lower_bound, named_cost, named)
            } else {
                let s = self.script(&found.map);
                (found.lower_bound, found.upper_bound, s)
            }
        };
        debug_assert_eq!(edit_script.cost(), upper);
        ModeReport {
            mode,
            ged: upper,
            exact: lower >= upper,
            lower_bound: lower.min(upper),
            upper_bound: upper,
            millis: u64::try_from(start.elapsed().as_millis()).unwrap_or(u64::MAX),
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
        CompareReport {
            a: summary(&self.a, &self.ga),
            b: summary(&self.b, &self.gb),
            modes,
        }
    }

    /// Drawing options for b: what `script` added in red, what it removed
    /// from a as dashed grey ghosts beside the vertices they were attached to.
    pub fn dot_options(&self, script: &Script) -> DotOptions {
        let mut opts = DotOptions::default();
        for v in &script.vertices_added {
            opts.highlight.insert(v.key.to_string(), Highlight::Added);
        }
        for arc in &script.arcs_added {
            opts.arc_label_highlight.insert(
                (
                    arc.from.to_string(),
                    arc.to.to_string(),
                    arc.label.to_string(),
                ),
                Highlight::Added,
            );
        }
        // a's keys as drawn in b: kept vertices under their image, removed
        // ones under a ghost key that cannot collide with a key of b.
        let mut taken: BTreeSet<String> = self.gb.g.node_weights().map(|v| v.key.clone()).collect();
        let mut drawn: BTreeMap<&str, String> = script
            .vertices_kept
            .iter()
            .map(|k| (k.a.as_str(), k.b.to_string()))
            .collect();
        // Containers before what they contain, so that a removed state is
        // drawn inside its container's cluster in b, or beside its ghost.
        let depth = |k: &str| {
            let mut d = 0usize;
            let mut cur = k;
            while let Some(p) = self.parent_a.get(cur) {
                d += 1;
                cur = p;
            }
            d
        };
        let mut removed: Vec<&VertexRef> = script.vertices_removed.iter().collect();
        removed.sort_by_cached_key(|v| depth(&v.key));
        for v in removed {
            let leaf = v.key.rsplit('/').next().unwrap_or(&v.key);
            let mut ghost = match self
                .parent_a
                .get(v.key.as_str())
                .and_then(|p| drawn.get(p.as_str()))
            {
                Some(parent) => format!("{parent}/{leaf}"),
                None => v.key.to_string(),
            };
            while taken.contains(&ghost) {
                ghost.push_str(" (removed)");
            }
            taken.insert(ghost.clone());
            opts.ghost_vertices
                .push((ghost.clone(), v.name.to_string()));
            drawn.insert(v.key.as_str(), ghost);
        }
        for arc in &script.arcs_removed {
            let end = |k: &str| drawn.get(k).cloned().unwrap_or_else(|| k.to_string());
            for _ in 0..arc.count {
                opts.ghost_arcs
                    .push((end(&arc.from), end(&arc.to), arc.label.to_string()));
            }
        }
        opts
    }
}

/// Arcs between two vertices with one label each, being sorted into an
/// edit script: `(tail rank, head rank, arc)`.
type RankedArcs = Vec<(u32, u32, ArcRef)>;

/// Groups equal labels into one `ArcRef` each, in `ArcRef` order.
fn push_grouped(
    out: &mut RankedArcs,
    (from, rf): (&Text, u32),
    (to, rt): (&Text, u32),
    labels: &mut [(&Text, Option<&Text>)],
) {
    labels.sort_unstable();
    let first = out.len();
    let mut i = 0;
    while i < labels.len() {
        let l = labels[i];
        let count = labels[i..].iter().take_while(|&&x| x == l).count();
        out.push((
            rf,
            rt,
            ArcRef {
                from: from.clone(),
                to: to.clone(),
                label: l.0.clone(),
                count: count as u32,
                label_in_a: l.1.cloned(),
            },
        ));
        i += count;
    }
    if out.len() - first > 1 {
        out[first..].sort_unstable_by(|x, y| x.2.cmp(&y.2));
    }
}

/// The arcs in `ArcRef` order: by tail and head key (keys are unique in a
/// graph, so their ranks order them as the keys do; one integer sort, then
/// the arcs permuted in place), each pair's arcs already in order.
fn sorted_arcs(l: RankedArcs) -> Vec<ArcRef> {
    let mut order: Vec<(u64, u32)> = l
        .iter()
        .enumerate()
        .map(|(i, x)| ((u64::from(x.0) << 32) | u64::from(x.1), i as u32))
        .collect();
    order.sort_unstable();
    let mut arcs: Vec<ArcRef> = l.into_iter().map(|x| x.2).collect();
    // Position i takes the arc at perm[i]: follow each cycle once.
    let mut perm: Vec<u32> = order.into_iter().map(|(_, i)| i).collect();
    for i in 0..perm.len() {
        let mut j = i;
        loop {
            let k = perm[j] as usize;
            perm[j] = j as u32;
            if k == i {
                break;
            }
            arcs.swap(j, k);
            j = k;
        }
    }
    arcs
}

impl Pair<'_> {
    /// The edit script of the vertex mapping `map` (vertex of a → vertex of
    /// b), with arcs told apart by label. Per ordered pair of mapped
    /// vertices, arcs with equal labels are kept first, then the remaining
    /// ones pairwise (relabelled); the surplus on either side is removed or
    /// added. Entries that are out of range or not injective are unmapped.
    fn script(&self, map: &[Option<usize>]) -> Script {
        let (ia, ib) = (&self.ia, &self.ib);
        let (fwd, inv) = injective(ia.keys.len(), ib.keys.len(), map);
        let vref = |x: &ScriptIndex, u: usize| VertexRef {
            key: x.keys[u].clone(),
            name: x.names[u].clone(),
            vtype: self.vtype(x, u),
        };
        let mut s = Script {
            vertices_kept: Vec::with_capacity(ia.keys.len().min(ib.keys.len())),
            vertices_removed: Vec::with_capacity(ia.keys.len()),
            vertices_added: Vec::with_capacity(ib.keys.len()),
            ..Script::default()
        };
        // In key order: the lists come out sorted.
        for &u in &ia.by_key {
            let u = u as usize;
            match fwd[u] {
                Some(v) => s.vertices_kept.push(KeptVertex {
                    a: ia.keys[u].clone(),
                    b: ib.keys[v].clone(),
                }),
                None => s.vertices_removed.push(vref(ia, u)),
            }
        }
        for &v in &ib.by_key {
            if inv[v as usize].is_none() {
                s.vertices_added.push(vref(ib, v as usize));
            }
        }
        let (na, nb) = (ia.groups.len(), ib.groups.len());
        let mut kept_l = Vec::with_capacity(na.min(nb));
        let mut removed_l = Vec::with_capacity(na);
        let mut added_l = Vec::with_capacity(nb);
        let mut used_b = vec![false; ib.groups.len()];
        // Buffers reused across groups.
        let (mut kept, mut only_a, mut only_b) = (Vec::new(), Vec::new(), Vec::new());
        let mut rest: Vec<(&Text, Option<&Text>)> = Vec::new();
        for (k, &(t, h, _, _)) in ia.groups.iter().enumerate() {
            let (t, h) = (t as usize, h as usize);
            let (Some(x), Some(y)) = (fwd[t], fwd[h]) else {
                rest.clear();
                rest.extend(ia.group_labels(k).map(|l| (l, None)));
                push_grouped(&mut removed_l, ia.end(t), ia.end(h), &mut rest);
                continue;
            };
            let j = ib.group(x, y);
            if let Some(j) = j {
                used_b[j] = true;
            }
            // Multiset intersection of two sorted lists, and the leftovers.
            let mut la = ia.group_labels(k).peekable();
            let mut lb = j.into_iter().flat_map(|j| ib.group_labels(j)).peekable();
            kept.clear();
            only_a.clear();
            only_b.clear();
            loop {
                match (la.peek(), lb.peek()) {
                    (Some(p), Some(q)) if p == q => {
                        kept.push((*q, None));
                        la.next();
                        lb.next();
                    }
                    (Some(p), Some(q)) if p < q => {
                        only_a.push(*p);
                        la.next();
                    }
                    (Some(p), None) => {
                        only_a.push(*p);
                        la.next();
                    }
                    (_, Some(q)) => {
                        only_b.push(*q);
                        lb.next();
                    }
                    (None, None) => break,
                }
            }
            let paired = only_a.len().min(only_b.len());
            kept.extend(
                only_b[..paired]
                    .iter()
                    .zip(&only_a[..paired])
                    .map(|(q, p)| (*q, Some(*p))),
            );
            push_grouped(&mut kept_l, ib.end(x), ib.end(y), &mut kept);
            rest.clear();
            rest.extend(only_a[paired..].iter().map(|&l| (l, None)));
            push_grouped(&mut removed_l, ia.end(t), ia.end(h), &mut rest);
            rest.clear();
            rest.extend(only_b[paired..].iter().map(|&l| (l, None)));
            push_grouped(&mut added_l, ib.end(x), ib.end(y), &mut rest);
        }
        for (j, &(x, y, _, _)) in ib.groups.iter().enumerate() {
            if !used_b[j] {
                rest.clear();
                rest.extend(ib.group_labels(j).map(|l| (l, None)));
                push_grouped(
                    &mut added_l,
                    ib.end(x as usize),
                    ib.end(y as usize),
                    &mut rest,
                );
            }
        }
        s.arcs_added = sorted_arcs(added_l);
        s.arcs_removed = sorted_arcs(removed_l);
        s.arcs_kept = sorted_arcs(kept_l);
        s
    }

    /// The type of vertex `u` of the graph indexed by `x`.
    fn vtype(&self, x: &ScriptIndex, u: usize) -> VertexType {
        let g = if std::ptr::eq(x, &self.ia) {
            &self.ga
        } else {
            &self.gb
        };
        g.g.raw_nodes()[u].weight.vtype
    }
}

// ------------------------------------------------------------------ output

/// SPEC §7: `{"a", "b", "structural": {...}, "labeled": {...}, "named": {...}}`
/// (only the modes computed), in that field order.
pub fn render_json(r: &CompareReport) -> String {
    #[derive(serde::Serialize)]
    struct Out<'a> {
        a: &'a str,
        b: &'a str,
        #[serde(skip_serializing_if = "Option::is_none")]
        structural: Option<&'a ModeReport>,
        #[serde(skip_serializing_if = "Option::is_none")]
        labeled: Option<&'a ModeReport>,
        #[serde(skip_serializing_if = "Option::is_none")]
        named: Option<&'a ModeReport>,
    }
    let out = Out {
        a: &r.a.file,
        b: &r.b.file,
        structural: r.mode(GedMode::Structural),
        labeled: r.mode(GedMode::Labeled),
        named: r.mode(GedMode::Named),
    };
    let mut s = serde_json::to_string_pretty(&out).expect("serializable");
    s.push('\n');
    s
}

/// The human-readable report: both policies, one row per mode, and the edit
/// script of the primary mode.
pub fn render_table(r: &CompareReport) -> String {
    let mut out = String::new();
    for (tag, s) in [("a", &r.a), ("b", &r.b)] {
        out.push_str(&format!(
            "{tag}: {} ({} `{}`, {} vertices, {} arcs)\n",
            s.file, s.kind, s.name, s.vertices, s.arcs
        ));
    }
    if r.a.kind != r.b.kind {
        out.push_str(&format!(
            "note: comparing a {} with a {}: labeled and named GED count every vertex of a differing type or name as replaced\n",
            r.a.kind, r.b.kind
        ));
    }
    out.push('\n');
    let mut t = super::table::Table::new(&["mode", "GED", "exact", "interval", "ms"]);
    for m in &r.modes {
        t.row(vec![
            m.mode.as_str().to_string(),
            m.ged.to_string(),
            if m.exact { "yes" } else { "no" }.to_string(),
            format!("[{}, {}]", m.lower_bound, m.upper_bound),
            m.millis.to_string(),
        ]);
    }
    out.push_str(&t.render());
    if r.modes.iter().any(|m| !m.exact) {
        out.push_str(
            "note: the search hit its budget; the distance lies in the certified interval (raise --timeout-ms to narrow it)\n",
        );
    }
    if let Some(p) = r.primary() {
        out.push('\n');
        out.push_str(&render_script(p));
    }
    out
}

/// One line per edit: `+` added, `-` removed, `~` rematched or relabelled.
fn render_script(m: &ModeReport) -> String {
    let s = &m.edit_script;
    let cost = s.cost();
    let mut out = format!(
        "{} edit script ({} edit{}):\n",
        m.mode.as_str(),
        cost,
        if cost == 1 { "" } else { "s" }
    );
    let vertex = |sign: char, v: &VertexRef| {
        let name = if v.name == v.key {
            String::new()
        } else {
            format!(" \"{}\"", v.name)
        };
        format!("  {sign} {} `{}`{name}\n", v.vtype.as_str(), v.key)
    };
    let arc = |sign: char, a: &ArcRef| {
        let label = if a.label.is_empty() {
            String::new()
        } else {
            format!(" [{}]", a.label)
        };
        let times = if a.count > 1 {
            format!(" ×{}", a.count)
        } else {
            String::new()
        };
        format!("  {sign} arc `{}` -> `{}`{label}{times}\n", a.from, a.to)
    };
    for v in &s.vertices_removed {
        out.push_str(&vertex('-', v));
    }
    for v in &s.vertices_added {
        out.push_str(&vertex('+', v));
    }
    for a in &s.arcs_removed {
        out.push_str(&arc('-', a));
    }
    for a in &s.arcs_added {
        out.push_str(&arc('+', a));
    }
    for k in s.rematched() {
        out.push_str(&format!("  ~ `{}` matched to `{}`\n", k.a, k.b));
    }
    for a in s.arcs_kept.iter().filter(|a| a.label_in_a.is_some()) {
        out.push_str(&format!(
            "  ~ arc `{}` -> `{}` relabelled [{}] -> [{}]\n",
            a.from,
            a.to,
            a.label_in_a.as_deref().unwrap_or_default(),
            a.label
        ));
    }
    if cost == 0 && s.rematched().next().is_none() {
        out.push_str("  (none: the graphs are identical under this mapping)\n");
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::format::toml::parse_str;
    use std::path::Path;

    fn pair<'a>(a: &'a Policy, b: &'a Policy) -> Pair<'a> {
        let side = |policy| Side {
            file: "test.toml",
            policy,
        };
        Pair::new(side(a), side(b))
    }

    fn policy(src: &str) -> Policy {
        parse_str("test.toml", src, Path::new(""), &Default::default())
            .expect("valid")
            .policy
    }

    const A: &str = r#"
kind = "fsm"
initial = "Go"
outcomes = ["SUCCESS"]
[states.Go]
skill = "Move-To"
args = { target = "cube2" }
on = { SUCCESS = "Pick", FAILURE = "Go", RUNNING = "Go" }
[states.Pick]
skill = "Pick"
args = { object = "cube2" }
on = { SUCCESS = "SUCCESS", FAILURE = "Go", RUNNING = "Pick" }
"#;

    /// A with `Safe-Move-To` as the alternative to `Go` (Fig. 8b's edit).
    fn b() -> String {
        A.replace(
            "on = { SUCCESS = \"Pick\", FAILURE = \"Go\", RUNNING = \"Go\" }",
            "on = { SUCCESS = \"Pick\", FAILURE = \"Safe\", RUNNING = \"Go\" }\n\
             [states.Safe]\n\
             skill = \"Safe-Move-To\"\n\
             args = { target = \"cube2\" }\n\
             on = { SUCCESS = \"Pick\", FAILURE = \"Go\", RUNNING = \"Safe\" }",
        )
    }

    #[test]
    fn named_script_tells_arcs_apart_by_label() {
        let (pa, pb) = (policy(A), policy(&b()));
        let pair = pair(&pa, &pb);
        let m = pair.run(GedMode::Named, &GedOptions::default());
        let s = &m.edit_script;
        assert_eq!(m.ged, s.cost());
        // Go's FAILURE self-loop goes, Safe and its three arcs and Go -> Safe come.
        let arc = |f: &str, t: &str, l: &str| ArcRef {
            from: f.into(),
            to: t.into(),
            label: l.into(),
            count: 1,
            label_in_a: None,
        };
        assert_eq!(s.arcs_removed, vec![arc("Go", "Go", "FAILURE")]);
        assert_eq!(
            s.arcs_added,
            vec![
                arc("Go", "Safe", "FAILURE"),
                arc("Safe", "Go", "FAILURE"),
                arc("Safe", "Pick", "SUCCESS"),
                arc("Safe", "Safe", "RUNNING"),
            ]
        );
        assert_eq!(s.vertices_added.len(), 1);
        assert_eq!(s.vertices_added[0].key, "Safe");
        assert_eq!(m.ged, 6);
        // The structural optimum is no larger and its script costs what it says.
        let st = pair.run(GedMode::Structural, &GedOptions::default());
        assert!(st.exact && st.ged <= m.ged);
        assert_eq!(st.edit_script.cost(), st.ged);
    }

    #[test]
    fn relabelled_parallel_arc_is_kept_and_shown() {
        let b = A.replace(
            "FAILURE = \"Go\", RUNNING = \"Go\"",
            "FAILURE = \"Go\", RUNNING = \"Pick\"",
        );
        let (pa, pb) = (policy(A), policy(&b));
        let pair = pair(&pa, &pb);
        let m = pair.run(GedMode::Named, &GedOptions::default());
        // Go -> Go loses its RUNNING arc; Go -> Pick gains one (now 2 arcs).
        assert_eq!(m.ged, 2);
        assert_eq!(m.edit_script.arcs_removed.len(), 1);
        assert_eq!(m.edit_script.arcs_removed[0].label, "RUNNING");
        assert_eq!(m.edit_script.arcs_added[0].label, "RUNNING");
        assert!(
            m.edit_script
                .arcs_kept
                .iter()
                .all(|a| a.label_in_a.is_none())
        );
    }

    #[test]
    fn dot_options_never_reuse_a_key_of_b_for_a_ghost() {
        // Structurally, b's `Safe` may take a's place under another key; a
        // removed vertex whose key b also uses must be drawn apart.
        let (pa, pb) = (policy(&b()), policy(A));
        let pair = pair(&pa, &pb);
        for mode in [GedMode::Structural, GedMode::Named] {
            let m = pair.run(mode, &GedOptions::default());
            let o = pair.dot_options(&m.edit_script);
            assert_eq!(o.ghost_vertices.len(), 1);
            let b_keys: Vec<_> = pair.gb.g.node_weights().map(|v| v.key.clone()).collect();
            assert!(!b_keys.contains(&o.ghost_vertices[0].0));
            let ghost_arcs: u64 = o.ghost_arcs.len() as u64;
            let removed: u64 = m
                .edit_script
                .arcs_removed
                .iter()
                .map(|a| u64::from(a.count))
                .sum();
            assert_eq!(ghost_arcs, removed);
        }
    }
}
