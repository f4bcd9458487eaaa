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
use std::time::{Duration, Instant};

/// An immutable shared string of an edit script (a key, a name, a label):
/// an entry of a table of one graph's strings, built once per graph.
/// Cloning it bumps the table's one reference count, so that writing a
/// script of 100k entries allocates nothing and touches no string.
/// Compared, ordered and serialized as the string it names.
#[derive(Clone)]
pub struct Text {
    table: Arc<Vec<String>>,
    index: u32,
}

impl Text {
    /// Entry `index` of `table` (which must have it).
    fn at(table: &Arc<Vec<String>>, index: usize) -> Text {
        debug_assert!(index < table.len());
        Text {
            table: Arc::clone(table),
            index: index as u32,
        }
    }

    pub fn as_str(&self) -> &str {
        self.table
            .get(self.index as usize)
            .map_or("", String::as_str)
    }
}

impl PartialEq for Text {
    fn eq(&self, other: &Text) -> bool {
        (Arc::ptr_eq(&self.table, &other.table) && self.index == other.index)
            || self.as_str() == other.as_str()
    }
}

impl Eq for Text {}

impl PartialOrd for Text {
    fn partial_cmp(&self, other: &Text) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl Ord for Text {
    fn cmp(&self, other: &Text) -> std::cmp::Ordering {
        self.as_str().cmp(other.as_str())
    }
}

impl std::hash::Hash for Text {
    fn hash<H: std::hash::Hasher>(&self, h: &mut H) {
        self.as_str().hash(h);
    }
}

impl std::fmt::Debug for Text {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        std::fmt::Debug::fmt(self.as_str(), f)
    }
}

impl std::ops::Deref for Text {
    type Target = str;
    fn deref(&self) -> &str {
        self.as_str()
    }
}

impl From<&str> for Text {
    fn from(s: &str) -> Text {
        Text::at(&Arc::new(vec![s.to_string()]), 0)
    }
}

impl PartialEq<str> for Text {
    fn eq(&self, other: &str) -> bool {
        self.as_str() == other
    }
}

impl PartialEq<&str> for Text {
    fn eq(&self, other: &&str) -> bool {
        self.as_str() == *other
    }
}

impl std::fmt::Display for Text {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

impl serde::Serialize for Text {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.as_str())
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
    keys: Arc<Vec<String>>,
    names: Arc<Vec<String>>,
    /// Label of each arc (edge index), an entry of one table of the
    /// graph's distinct labels.
    labels: Vec<Text>,
    /// Vertices in key order (keys are unique within a graph).
    by_key: Vec<u32>,
    /// `(tail, head, first, end)`: the arcs from tail to head are
    /// `arcs[first..end]`; sorted by `(tail, head)`.
    groups: Vec<(u32, u32, u32, u32)>,
    /// The groups of tail `u` are `groups[by_tail[u]..by_tail[u + 1]]`.
    by_tail: Vec<u32>,
    /// Group indices in the order of their ends' keys (tail, then head).
    groups_by_key: Vec<u32>,
    /// Edge indices, grouped, by label within a group.
    arcs: Vec<u32>,
}

impl ScriptIndex {
    fn new(g: &PolicyGraph) -> ScriptIndex {
        let nodes = g.g.raw_nodes();
        let n = nodes.len();
        let key = |i: u32| nodes[i as usize].weight.key.as_str();
        let by_key = key_order(n, key);
        let mut rank = vec![0u32; n];
        for (r, &v) in by_key.iter().enumerate() {
            rank[v as usize] = r as u32;
        }
        let edges = g.g.raw_edges();
        let mut distinct: HashMap<&str, usize> = HashMap::new();
        let ids: Vec<usize> = edges
            .iter()
            .map(|e| {
                let next = distinct.len();
                *distinct.entry(e.weight.label()).or_insert(next)
            })
            .collect();
        let mut table = vec![String::new(); distinct.len()];
        for (l, i) in distinct {
            table[i] = l.to_string();
        }
        // Labels ordered as strings once (there are few), arcs then sorted
        // on integers: (tail, head, label rank, edge).
        let mut label_rank: Vec<u32> = vec![0; table.len()];
        let mut by_label: Vec<usize> = (0..table.len()).collect();
        by_label.sort_unstable_by(|&x, &y| table[x].cmp(&table[y]));
        for (r, &l) in by_label.iter().enumerate() {
            label_rank[l] = r as u32;
        }
        let table = Arc::new(table);
        let mut sorted: Vec<(u32, u32, u32, u32)> = edges
            .iter()
            .zip(&ids)
            .enumerate()
            .map(|(e, (x, &l))| {
                let (t, h) = (x.source().index() as u32, x.target().index() as u32);
                (t, h, label_rank[l], e as u32)
            })
            .collect();
        sorted.sort_unstable();
        let labels: Vec<Text> = ids.into_iter().map(|i| Text::at(&table, i)).collect();
        let arcs: Vec<u32> = sorted.iter().map(|x| x.3).collect();
        let mut groups: Vec<(u32, u32, u32, u32)> = Vec::new();
        for (i, &(t, h, _, _)) in sorted.iter().enumerate() {
            match groups.last_mut() {
                Some(last) if (last.0, last.1) == (t, h) => last.3 = i as u32 + 1,
                _ => groups.push((t, h, i as u32, i as u32 + 1)),
            }
        }
        let mut by_tail = vec![0u32; n + 1];
        for &(t, _, _, _) in &groups {
            by_tail[t as usize + 1] += 1;
        }
        for u in 0..n {
            by_tail[u + 1] += by_tail[u];
        }
        let mut groups_by_key: Vec<u32> = (0..groups.len() as u32).collect();
        groups_by_key.sort_unstable_by_key(|&k| {
            let (t, h, _, _) = groups[k as usize];
            (rank[t as usize], rank[h as usize])
        });
        ScriptIndex {
            by_tail,
            groups_by_key,
            keys: Arc::new(nodes.iter().map(|v| v.weight.key.clone()).collect()),
            names: Arc::new(nodes.iter().map(|v| v.weight.label.clone()).collect()),
            labels,
            by_key,
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
        let (&s, &e) = (self.by_tail.get(t)?, self.by_tail.get(t + 1)?);
        let mine = &self.groups[s as usize..e as usize];
        mine.binary_search_by_key(&(h as u32), |&(_, y, _, _)| y)
            .ok()
            .map(|i| s as usize + i)
    }

    fn key(&self, u: usize) -> Text {
        Text::at(&self.keys, u)
    }

    fn name(&self, u: usize) -> Text {
        Text::at(&self.names, u)
    }
}

/// Vertices `0..n` in the order of their keys (then index): sorted on the
/// keys' first 8 bytes as integers (big-endian, zero-padded, which orders
/// as the bytes do), then each run of equal prefixes on the whole keys. On
/// short keys (BT node ids) that is an integer sort, no string compared.
fn key_order<'k>(n: usize, key: impl Fn(u32) -> &'k str) -> Vec<u32> {
    let prefix = |i: u32| {
        let mut b = [0u8; 8];
        let k = key(i).as_bytes();
        let m = k.len().min(8);
        b[..m].copy_from_slice(&k[..m]);
        u64::from_be_bytes(b)
    };
    let mut order: Vec<(u64, u32)> = (0..n as u32).map(|i| (prefix(i), i)).collect();
    order.sort_unstable();
    let mut s = 0;
    while s < order.len() {
        let e = s + order[s..].iter().take_while(|x| x.0 == order[s].0).count();
        if e - s > 1 {
            order[s..e].sort_unstable_by(|x, y| key(x.1).cmp(key(y.1)).then(x.1.cmp(&y.1)));
        }
        s = e;
    }
    order.into_iter().map(|x| x.1).collect()
}

/// Ids for the keys of both graphs: equal keys get equal ids. One merge of
/// the two graphs' vertices in key order.
fn key_ids(ia: &ScriptIndex, ib: &ScriptIndex) -> (Vec<u32>, Vec<u32>) {
    let (na, nb) = (ia.by_key.len(), ib.by_key.len());
    let (mut ids_a, mut ids_b) = (vec![0u32; na], vec![0u32; nb]);
    let key_a = |i: usize| ia.keys[ia.by_key[i] as usize].as_str();
    let key_b = |j: usize| ib.keys[ib.by_key[j] as usize].as_str();
    let (mut i, mut j) = (0, 0);
    let mut last: Option<&str> = None;
    let mut next = 0u32;
    while i < na || j < nb {
        let from_a = j >= nb || (i < na && key_a(i) <= key_b(j));
        let k = if from_a { key_a(i) } else { key_b(j) };
        if last != Some(k) {
            last = Some(k);
            next += 1;
        }
        if from_a {
            ids_a[ia.by_key[i] as usize] = next - 1;
            i += 1;
        } else {
            ids_b[ib.by_key[j] as usize] = next - 1;
            j += 1;
        }
    }
    (ids_a, ids_b)
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
        let (ia, ib) = (ScriptIndex::new(&ga), ScriptIndex::new(&gb));
        let (ids_a, ids_b) = key_ids(&ia, &ib);
        Pair {
            ia,
            ib,
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
    /// next, and the search gets what remains minus twice the time that
    /// script took (the script of the search's mapping, if better, costs
    /// about as much, and the unused one must be freed: 1.3 to 1.6 times
    /// the first on 100k-vertex BTs). `millis` is the time of all of it.
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
            let reserve = before_script.elapsed() * 2;
            // Checked: a budget past the clock's range means no deadline.
            let deadline = start
                .checked_add(opts.timeout)
                .unwrap_or_else(|| start + Duration::from_secs(1 << 32))
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

/// Groups equal labels into one `ArcRef` each, in `ArcRef` order.
fn push_grouped(
    out: &mut Vec<ArcRef>,
    from: Text,
    to: Text,
    labels: &mut [(&Text, Option<&Text>)],
) {
    labels.sort_unstable();
    let first = out.len();
    let mut i = 0;
    while i < labels.len() {
        let l = labels[i];
        let count = labels[i..].iter().take_while(|&&x| x == l).count();
        out.push(ArcRef {
            from: from.clone(),
            to: to.clone(),
            label: l.0.clone(),
            count: count as u32,
            label_in_a: l.1.cloned(),
        });
        i += count;
    }
    if out.len() - first > 1 {
        out[first..].sort_unstable();
    }
}

/// How the arcs of a mapped pair of vertex pairs split: label by label,
/// equal labels kept first, then the rest paired (relabelled), the surplus
/// of either side left over. `la` and `lb` sorted.
#[derive(Default)]
struct Split<'t> {
    /// (label in b, label in a when it differs).
    kept: Vec<(&'t Text, Option<&'t Text>)>,
    only_a: Vec<(&'t Text, Option<&'t Text>)>,
    only_b: Vec<(&'t Text, Option<&'t Text>)>,
}

impl<'t> Split<'t> {
    fn of(&mut self, la: impl Iterator<Item = &'t Text>, lb: impl Iterator<Item = &'t Text>) {
        self.kept.clear();
        self.only_a.clear();
        self.only_b.clear();
        let (mut la, mut lb) = (la.peekable(), lb.peekable());
        loop {
            match (la.peek(), lb.peek()) {
                (Some(p), Some(q)) if p == q => {
                    self.kept.push((*q, None));
                    la.next();
                    lb.next();
                }
                (Some(p), Some(q)) if p < q => {
                    self.only_a.push((*p, None));
                    la.next();
                }
                (Some(p), None) => {
                    self.only_a.push((*p, None));
                    la.next();
                }
                (_, Some(q)) => {
                    self.only_b.push((*q, None));
                    lb.next();
                }
                (None, None) => break,
            }
        }
        let paired = self.only_a.len().min(self.only_b.len());
        for i in 0..paired {
            self.kept.push((self.only_b[i].0, Some(self.only_a[i].0)));
        }
        self.only_a.drain(..paired);
        self.only_b.drain(..paired);
    }
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
            key: x.key(u),
            name: x.name(u),
            vtype: self.vtype(x, u),
        };
        let mut s = Script {
            vertices_kept: Vec::with_capacity(ia.keys.len().min(ib.keys.len())),
            vertices_removed: Vec::with_capacity(ia.keys.len()),
            vertices_added: Vec::with_capacity(ib.keys.len()),
            arcs_kept: Vec::with_capacity(ia.groups.len().min(ib.groups.len())),
            arcs_added: Vec::with_capacity(ib.groups.len()),
            arcs_removed: Vec::with_capacity(ia.groups.len()),
        };
        // In key order: the lists come out sorted.
        for &u in &ia.by_key {
            let u = u as usize;
            match fwd[u] {
                Some(v) => s.vertices_kept.push(KeptVertex {
                    a: ia.key(u),
                    b: ib.key(v),
                }),
                None => s.vertices_removed.push(vref(ia, u)),
            }
        }
        for &v in &ib.by_key {
            if inv[v as usize].is_none() {
                s.vertices_added.push(vref(ib, v as usize));
            }
        }
        // Arcs in key order with no sort: b's groups in key order give the
        // kept and added arcs (named by b's keys), a's the removed ones.
        let mut split = Split::default();
        for &j in &ib.groups_by_key {
            let j = j as usize;
            let (x, y, _, _) = ib.groups[j];
            let (x, y) = (x as usize, y as usize);
            let k = inv[x].zip(inv[y]).and_then(|(t, h)| ia.group(t, h));
            let la = k.into_iter().flat_map(|k| ia.group_labels(k));
            split.of(la, ib.group_labels(j));
            push_grouped(&mut s.arcs_kept, ib.key(x), ib.key(y), &mut split.kept);
            push_grouped(&mut s.arcs_added, ib.key(x), ib.key(y), &mut split.only_b);
        }
        for &k in &ia.groups_by_key {
            let k = k as usize;
            let (t, h, _, _) = ia.groups[k];
            let (t, h) = (t as usize, h as usize);
            let j = fwd[t].zip(fwd[h]).and_then(|(x, y)| ib.group(x, y));
            let lb = j.into_iter().flat_map(|j| ib.group_labels(j));
            split.of(ia.group_labels(k), lb);
            push_grouped(&mut s.arcs_removed, ia.key(t), ia.key(h), &mut split.only_a);
        }
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
    let mut s = crate::sanitize::json(serde_json::to_string_pretty(&out).expect("serializable"));
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

/// The report as GitHub-flavoured markdown, for a pull-request comment: the
/// two policies and the modes as tables, the primary edit script as a
/// `diff` block (added lines green, removed red) in a collapsible section.
pub fn render_markdown(r: &CompareReport) -> String {
    let cell = crate::sanitize::markdown_cell;
    let code = crate::sanitize::markdown_code;
    let mut out = format!(
        "### btfsm compare: {} → {}\n\n| | file | kind | name | vertices | arcs |\n|---|---|---|---|---:|---:|\n",
        code(&r.a.file),
        code(&r.b.file)
    );
    for (tag, s) in [("a", &r.a), ("b", &r.b)] {
        out.push_str(&format!(
            "| {tag} | {} | {} | {} | {} | {} |\n",
            code(&s.file),
            s.kind,
            cell(&s.name),
            s.vertices,
            s.arcs
        ));
    }
    out.push_str("\n| mode | GED | exact | interval | ms |\n|---|---:|---|---|---:|\n");
    for m in &r.modes {
        out.push_str(&format!(
            "| {} | {} | {} | [{}, {}] | {} |\n",
            m.mode.as_str(),
            m.ged,
            if m.exact { "yes" } else { "no" },
            m.lower_bound,
            m.upper_bound,
            m.millis
        ));
    }
    if r.modes.iter().any(|m| !m.exact) {
        out.push_str("\nThe search hit its budget: the distance lies in the certified interval.\n");
    }
    if let Some(p) = r.primary() {
        let script = render_script(p);
        let mut lines = script.lines();
        let title = lines.next().unwrap_or_default().trim_end_matches(':');
        let body: String = lines
            .map(|l| format!("{}\n", l.strip_prefix("  ").unwrap_or(l)))
            .collect();
        // Names are escaped onto one line each and every line starts with
        // its sign; the fence is longer than any run of backticks anyway.
        let fence = crate::sanitize::code_fence(&body);
        out.push_str(&format!(
            "\n<details><summary>{}</summary>\n\n{fence}diff\n{body}{fence}\n\n</details>\n",
            cell(title)
        ));
    }
    out
}

/// One line per edit: `+` added, `-` removed, `~` rematched or relabelled.
fn render_script(m: &ModeReport) -> String {
    use crate::sanitize::shown;
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
            format!(" \"{}\"", shown(&v.name))
        };
        format!("  {sign} {} `{}`{name}\n", v.vtype.as_str(), shown(&v.key))
    };
    let arc = |sign: char, a: &ArcRef| {
        let label = if a.label.is_empty() {
            String::new()
        } else {
            format!(" [{}]", shown(&a.label))
        };
        let times = if a.count > 1 {
            format!(" ×{}", a.count)
        } else {
            String::new()
        };
        format!(
            "  {sign} arc `{}` -> `{}`{label}{times}\n",
            shown(&a.from),
            shown(&a.to)
        )
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
        out.push_str(&format!(
            "  ~ `{}` matched to `{}`\n",
            shown(&k.a),
            shown(&k.b)
        ));
    }
    for a in s.arcs_kept.iter().filter(|a| a.label_in_a.is_some()) {
        out.push_str(&format!(
            "  ~ arc `{}` -> `{}` relabelled [{}] -> [{}]\n",
            shown(&a.from),
            shown(&a.to),
            shown(a.label_in_a.as_deref().unwrap_or_default()),
            shown(&a.label)
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

    /// A random FSM: `n` states, each with three outcome arcs to random
    /// states (parallel arcs and self-loops with different labels).
    fn random_fsm(n: u64, seed: u64) -> String {
        let mut x = seed;
        let mut next = move |m: u64| {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x % m
        };
        let mut s = String::from("kind = \"fsm\"\ninitial = \"s0\"\noutcomes = [\"SUCCESS\"]\n");
        for i in 0..n {
            let to = |t: u64| {
                if t == n {
                    "SUCCESS".to_string()
                } else {
                    format!("s{t}")
                }
            };
            s.push_str(&format!(
                "[states.s{i}]\nskill = \"Dock\"\non = {{ SUCCESS = \"{}\", FAILURE = \"{}\", RUNNING = \"{}\" }}\n",
                to(next(n + 1)),
                to(next(n + 1)),
                to(next(n + 1)),
            ));
        }
        s
    }

    /// The script of any partial mapping costs what `mapping_cost` says,
    /// accounts for every arc of both graphs once, and comes out in the
    /// order the old string sorts gave (vertices by key, arcs by `ArcRef`).
    #[test]
    fn scripts_of_random_mappings_are_complete_and_sorted() {
        use crate::metrics::ged::{Shape, mapping_cost};
        let (pa, pb) = (policy(&random_fsm(12, 3)), policy(&random_fsm(10, 8)));
        let pair = pair(&pa, &pb);
        let (sa, sb) = (Shape::from(&pair.ga), Shape::from(&pair.gb));
        let (na, nb) = (sa.n(), sb.n());
        let mut x = 99u64;
        for round in 0..200 {
            let map: Vec<Option<usize>> = (0..na)
                .map(|_| {
                    x = x
                        .wrapping_mul(6364136223846793005)
                        .wrapping_add(1442695040888963407);
                    let r = (x >> 33) as usize;
                    (!r.is_multiple_of(4)).then_some(r % (nb + 1))
                })
                .collect();
            let s = pair.script(&map);
            assert_eq!(s.cost(), mapping_cost(&sa, &sb, &map), "round {round}");
            let count = |l: &[ArcRef]| l.iter().map(|a| u64::from(a.count)).sum::<u64>();
            assert_eq!(count(&s.arcs_kept) + count(&s.arcs_removed), sa.arc_count());
            assert_eq!(count(&s.arcs_kept) + count(&s.arcs_added), sb.arc_count());
            assert_eq!(s.vertices_kept.len() + s.vertices_removed.len(), na);
            assert_eq!(s.vertices_kept.len() + s.vertices_added.len(), nb);
            for l in [&s.arcs_kept, &s.arcs_removed, &s.arcs_added] {
                assert!(l.windows(2).all(|w| w[0] < w[1]), "round {round}: {l:?}");
            }
            let keys = |l: &[VertexRef]| l.windows(2).all(|w| w[0].key < w[1].key);
            assert!(keys(&s.vertices_added) && keys(&s.vertices_removed));
            assert!(
                s.vertices_kept
                    .windows(2)
                    .all(|w| (&w[0].a, &w[0].b) < (&w[1].a, &w[1].b))
            );
        }
    }

    #[test]
    fn key_order_is_the_string_order() {
        let keys = [
            "n10",
            "n9",
            "",
            "a",
            "ab",
            "ab\0",
            "abcdefgh",
            "abcdefghi",
            "abcdefgh",
            "é",
            "Z",
            "abcdefgha",
            "n1",
        ];
        let got: Vec<&str> = key_order(keys.len(), |i| keys[i as usize])
            .into_iter()
            .map(|i| keys[i as usize])
            .collect();
        let mut want = keys.to_vec();
        want.sort();
        assert_eq!(got, want);
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
