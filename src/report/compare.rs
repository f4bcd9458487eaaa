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
use crate::metrics::ged::{GedMode, GedOptions, GedResult, ged};
use crate::model::{Policy, PolicyBody, PolicyKind};
use crate::render::dot::{DotOptions, Highlight};
use std::collections::{BTreeMap, BTreeSet};

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
    pub key: String,
    /// Display name.
    pub name: String,
    #[serde(rename = "type")]
    pub vtype: VertexType,
}

/// A vertex of a kept (substituted at cost 0) as the vertex of b it maps to.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct KeptVertex {
    pub a: String,
    pub b: String,
}

/// Arcs between two vertices with one label.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, serde::Serialize)]
pub struct ArcRef {
    /// Tail key (of b for added and kept arcs, of a for removed ones).
    pub from: String,
    /// Head key, likewise.
    pub to: String,
    /// Outcome or guard label; `initial` for an HFSM container's arc to its
    /// initial state; empty for a BT edge.
    pub label: String,
    /// How many such parallel arcs.
    pub count: u32,
    /// For a kept arc whose label differs in a: a's label (unit-cost GED does
    /// not charge for it, a reviewer wants to see it).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub label_in_a: Option<String>,
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
    /// HFSM containment in a: state key -> its container's key.
    parent_a: BTreeMap<String, String>,
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
        Pair {
            ga: policy_graph(a.policy),
            gb: policy_graph(b.policy),
            parent_a: containers(a.policy),
            a,
            b,
        }
    }

    /// GED in one mode, with its labelled edit script.
    pub fn run(&self, mode: GedMode, opts: &GedOptions) -> ModeReport {
        let r: GedResult = ged(&self.ga, &self.gb, mode, opts);
        let mapping: BTreeMap<&str, &str> = r
            .edit_script
            .vertices_kept
            .iter()
            .map(|(x, y)| (x.as_str(), y.as_str()))
            .collect();
        let edit_script = labelled_script(&self.ga, &self.gb, &mapping);
        debug_assert_eq!(edit_script.cost(), r.edit_script.cost());
        ModeReport {
            mode,
            ged: r.ged,
            exact: r.exact,
            lower_bound: r.lower_bound,
            upper_bound: r.upper_bound,
            millis: r.millis,
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
            opts.highlight.insert(v.key.clone(), Highlight::Added);
        }
        for arc in &script.arcs_added {
            opts.arc_label_highlight.insert(
                (arc.from.clone(), arc.to.clone(), arc.label.clone()),
                Highlight::Added,
            );
        }
        // a's keys as drawn in b: kept vertices under their image, removed
        // ones under a ghost key that cannot collide with a key of b.
        let mut taken: BTreeSet<String> = self.gb.g.node_weights().map(|v| v.key.clone()).collect();
        let mut drawn: BTreeMap<&str, String> = script
            .vertices_kept
            .iter()
            .map(|k| (k.a.as_str(), k.b.clone()))
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
                .get(&v.key)
                .and_then(|p| drawn.get(p.as_str()))
            {
                Some(parent) => format!("{parent}/{leaf}"),
                None => v.key.clone(),
            };
            while taken.contains(&ghost) {
                ghost.push_str(" (removed)");
            }
            taken.insert(ghost.clone());
            opts.ghost_vertices.push((ghost.clone(), v.name.clone()));
            drawn.insert(v.key.as_str(), ghost);
        }
        for arc in &script.arcs_removed {
            let end = |k: &str| drawn.get(k).cloned().unwrap_or_else(|| k.to_string());
            for _ in 0..arc.count {
                opts.ghost_arcs
                    .push((end(&arc.from), end(&arc.to), arc.label.clone()));
            }
        }
        opts
    }
}

/// Arcs of a graph grouped by ordered pair of vertex keys, each with its
/// labels (sorted, one entry per parallel arc).
fn arcs_by_pair(g: &PolicyGraph) -> BTreeMap<(&str, &str), Vec<&str>> {
    let mut m: BTreeMap<(&str, &str), Vec<&str>> = BTreeMap::new();
    for e in g.g.raw_edges() {
        let t = g.g[e.source()].key.as_str();
        let h = g.g[e.target()].key.as_str();
        m.entry((t, h)).or_default().push(e.weight.label());
    }
    for labels in m.values_mut() {
        labels.sort_unstable();
    }
    m
}

/// Groups equal labels into one `ArcRef` each.
fn push_grouped(out: &mut Vec<ArcRef>, from: &str, to: &str, labels: &[(&str, Option<&str>)]) {
    let mut counts: BTreeMap<(&str, Option<&str>), u32> = BTreeMap::new();
    for &l in labels {
        *counts.entry(l).or_default() += 1;
    }
    for ((label, was), count) in counts {
        out.push(ArcRef {
            from: from.to_string(),
            to: to.to_string(),
            label: label.to_string(),
            count,
            label_in_a: was.map(str::to_string),
        });
    }
}

/// The edit script of the vertex mapping `map` (a key → b key), with arcs
/// told apart by label. Per ordered pair of mapped vertices, arcs with equal
/// labels are kept first, then the remaining ones pairwise (relabelled);
/// the surplus on either side is removed or added.
fn labelled_script(a: &PolicyGraph, b: &PolicyGraph, map: &BTreeMap<&str, &str>) -> Script {
    let vref = |g: &PolicyGraph, i: petgraph::graph::NodeIndex| {
        let v = &g.g[i];
        VertexRef {
            key: v.key.clone(),
            name: v.label.clone(),
            vtype: v.vtype,
        }
    };
    let image: BTreeSet<&str> = map.values().copied().collect();
    let mut s = Script::default();
    for i in a.g.node_indices() {
        match map.get(a.g[i].key.as_str()) {
            Some(&k) => s.vertices_kept.push(KeptVertex {
                a: a.g[i].key.clone(),
                b: k.to_string(),
            }),
            None => s.vertices_removed.push(vref(a, i)),
        }
    }
    for i in b.g.node_indices() {
        if !image.contains(b.g[i].key.as_str()) {
            s.vertices_added.push(vref(b, i));
        }
    }
    let arcs_a = arcs_by_pair(a);
    let mut arcs_b = arcs_by_pair(b);
    for ((t, h), la) in &arcs_a {
        let (Some(&x), Some(&y)) = (map.get(t), map.get(h)) else {
            let removed: Vec<_> = la.iter().map(|&l| (l, None)).collect();
            push_grouped(&mut s.arcs_removed, t, h, &removed);
            continue;
        };
        let lb = arcs_b.remove(&(x, y)).unwrap_or_default();
        // Multiset intersection of two sorted lists, and the leftovers.
        let (mut i, mut j) = (0, 0);
        let (mut kept, mut only_a, mut only_b) = (Vec::new(), Vec::new(), Vec::new());
        while i < la.len() || j < lb.len() {
            match (la.get(i), lb.get(j)) {
                (Some(p), Some(q)) if p == q => {
                    kept.push((*q, None));
                    i += 1;
                    j += 1;
                }
                (Some(p), Some(q)) if p < q => {
                    only_a.push(*p);
                    i += 1;
                }
                (Some(p), None) => {
                    only_a.push(*p);
                    i += 1;
                }
                (_, Some(q)) => {
                    only_b.push(*q);
                    j += 1;
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
        push_grouped(&mut s.arcs_kept, x, y, &kept);
        let removed: Vec<_> = only_a[paired..].iter().map(|&l| (l, None)).collect();
        push_grouped(&mut s.arcs_removed, t, h, &removed);
        let added: Vec<_> = only_b[paired..].iter().map(|&l| (l, None)).collect();
        push_grouped(&mut s.arcs_added, x, y, &added);
    }
    for ((x, y), lb) in &arcs_b {
        let added: Vec<_> = lb.iter().map(|&l| (l, None)).collect();
        push_grouped(&mut s.arcs_added, x, y, &added);
    }
    let by_key = |v: &VertexRef| v.key.clone();
    s.vertices_added.sort_by_key(by_key);
    s.vertices_removed.sort_by_key(by_key);
    s.vertices_kept
        .sort_by(|p, q| (&p.a, &p.b).cmp(&(&q.a, &q.b)));
    s.arcs_added.sort();
    s.arcs_removed.sort();
    s.arcs_kept.sort();
    s
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
