//! The edit script of a vertex mapping told in the policies' own terms:
//! an index of each graph's keys, names and arcs grouped by end points
//! (built once per graph), and the label-by-label split of parallel arcs
//! (equal labels kept first, then relabelled, the surplus added or removed).

use super::{ArcRef, KeptVertex, Pair, Script, Text, VertexRef};
use btfsm_metrics::ged::injective;
use btfsm_model::graph::{PolicyGraph, VertexType};
use std::collections::HashMap;
use std::sync::Arc;

/// What writing edit scripts needs of one graph, computed once with the
/// graph (it depends on that graph only): its keys, names and arc labels as
/// shared strings, its vertices in key order, and its arcs grouped by
/// ordered pair of vertices with their labels sorted. With it, an edit
/// script costs O((n + m) log m) integer work and allocates no strings.
pub(super) struct ScriptIndex {
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
    pub(super) fn new(g: &PolicyGraph) -> ScriptIndex {
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

    /// The vertex with key `k`, if any.
    pub(super) fn find(&self, k: &str) -> Option<usize> {
        self.by_key
            .binary_search_by(|&u| self.keys[u as usize].as_str().cmp(k))
            .ok()
            .map(|i| self.by_key[i] as usize)
    }

    pub(super) fn key(&self, u: usize) -> Text {
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
pub(super) fn key_order<'k>(n: usize, key: impl Fn(u32) -> &'k str) -> Vec<u32> {
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
pub(super) fn key_ids(ia: &ScriptIndex, ib: &ScriptIndex) -> (Vec<u32>, Vec<u32>) {
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
    pub(super) fn script(&self, map: &[Option<usize>]) -> Script {
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
            relabelled: Vec::new(),
            reordered: Vec::new(),
        };
        // In key order: the lists come out sorted.
        for &u in &ia.by_key {
            let u = u as usize;
            match fwd[u] {
                Some(v) => s.vertices_kept.push(KeptVertex {
                    a: ia.key(u),
                    b: ib.key(v),
                    derived: self.derived_a.get(u).copied().unwrap_or(false)
                        && self.derived_b.get(v).copied().unwrap_or(false),
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
        self.changes(&fwd, &inv, &mut s);
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
