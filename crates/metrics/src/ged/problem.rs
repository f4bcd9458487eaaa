//! The padded form of a GED instance, on which the exact search, the embedding
//! fast path and the local search all work.
//!
//! Cost model (SPEC §3, unit costs, directed, substitution free): for a partial
//! injection f from G1 to G2, cost = vertices deleted + vertices inserted +
//! Σ over ordered pairs (u, w) of mapped G1 vertices of |A(u,w) − B(f u, f w)|
//! (self-loops are the pairs (u, u)) + every arc incident to a deleted or an
//! inserted vertex. Mapping a deleted vertex onto an inserted one of the same
//! label never raises the cost (it saves 2 and turns a + b arc edits into at
//! most |a − b|), so some optimal f is maximal: per label class it maps every
//! vertex of the side with fewer vertices of that class.
//!
//! We pad each class of the smaller side with arc-less dummy vertices until
//! both sides have the same number of vertices of that class; a maximal f then
//! becomes a class-preserving bijection σ of the padded vertex sets, a real
//! vertex mapped to a dummy is deleted (or inserted), and
//!
//! GED = Σ_classes |c1 − c2| + min_σ Σ_{u,w} |A(u,w) − B(σ u, σ w)|,
//!
//! a quadratic assignment problem (the formulation of Riesen & Bunke's
//! bipartite GED and of Chang et al., TKDE 2022, specialised to unit costs).
//! Since Σ|a − b| = a + b − 2·min(a, b), this equals
//! vertex cost + m1 + m2 − 2·Σ_{arcs (u,w) of G1} min(A(u,w), B(σ u, σ w)).

use super::graph::Shape;

/// Index value meaning "not mapped" / "no vertex".
pub(crate) const NONE: u32 = u32::MAX;

/// Adjacency lists of `n` vertices in one flat array (compressed rows):
/// `adj[u]` is the slice of `(neighbour, multiplicity)` of `u`. One
/// allocation instead of one per vertex, which on 100k-vertex graphs is
/// most of the cost of building a [`Problem`].
#[derive(Debug, Clone, Default)]
pub(crate) struct Adj {
    start: Vec<usize>,
    items: Vec<(u32, u32)>,
}

impl Adj {
    /// From `(vertex, (neighbour, multiplicity))` entries; each list sorted.
    fn build(n: usize, entries: &[(u32, (u32, u32))]) -> Adj {
        let mut start = vec![0usize; n + 1];
        for &(u, _) in entries {
            start[u as usize + 1] += 1;
        }
        for i in 0..n {
            start[i + 1] += start[i];
        }
        let mut fill = start.clone();
        let mut items = vec![(0u32, 0u32); entries.len()];
        for &(u, x) in entries {
            items[fill[u as usize]] = x;
            fill[u as usize] += 1;
        }
        for u in 0..n {
            items[start[u]..start[u + 1]].sort_unstable();
        }
        Adj { start, items }
    }

    /// Flat index of `u`'s first entry: entry `i` of `self[u]` has flat
    /// index `first(u) + i` (used as an arc id).
    #[inline]
    pub(super) fn first(&self, u: usize) -> usize {
        self.start[u]
    }

    /// Number of entries in all lists.
    pub(super) fn total(&self) -> usize {
        self.items.len()
    }

    /// The lists, vertex by vertex.
    pub(super) fn iter(&self) -> impl Iterator<Item = &[(u32, u32)]> {
        self.start.windows(2).map(|w| &self.items[w[0]..w[1]])
    }
}

impl std::ops::Index<usize> for Adj {
    type Output = [(u32, u32)];
    #[inline]
    fn index(&self, u: usize) -> &[(u32, u32)] {
        &self.items[self.start[u]..self.start[u + 1]]
    }
}

/// One side of the padded instance.
#[derive(Debug, Clone)]
pub(crate) struct Side {
    /// Padded vertex count (the same on both sides).
    pub n: usize,
    /// Original vertex of each padded vertex, `NONE` for a dummy.
    pub orig: Vec<u32>,
    /// Out-arcs `(head, multiplicity)` sorted by head, self-loops excluded.
    pub out: Adj,
    /// In-arcs `(tail, multiplicity)` sorted by tail, self-loops excluded.
    pub inn: Adj,
    /// Self-loop multiplicity.
    pub loops: Vec<u32>,
    /// Total number of arcs (with multiplicity).
    pub arcs: u64,
}

impl Side {
    /// Multiplicity of the ordered pair `(u, v)` of padded vertices.
    #[inline]
    pub(super) fn mult(&self, u: u32, v: u32) -> u32 {
        if u == v {
            return self.loops[u as usize];
        }
        let list = &self.out[u as usize];
        match list.binary_search_by_key(&v, |&(h, _)| h) {
            Ok(i) => list[i].1,
            Err(_) => 0,
        }
    }

    /// Whether exchanging `u1` and `u2` is an automorphism (same class
    /// assumed): equal loops, equal arcs to and from every third vertex,
    /// and as many arcs u1 -> u2 as u2 -> u1.
    pub(super) fn twins(&self, u1: u32, u2: u32) -> bool {
        let (a, b) = (u1 as usize, u2 as usize);
        if self.loops[a] != self.loops[b]
            || self.out[a].len() != self.out[b].len()
            || self.inn[a].len() != self.inn[b].len()
            || self.mult(u1, u2) != self.mult(u2, u1)
        {
            return false;
        }
        let others = |l: &[(u32, u32)]| -> Vec<(u32, u32)> {
            l.iter()
                .copied()
                .filter(|&(w, _)| w != u1 && w != u2)
                .collect()
        };
        others(&self.out[a]) == others(&self.out[b]) && others(&self.inn[a]) == others(&self.inn[b])
    }

    /// For each vertex, the nearest lower-index twin in its class (`NONE` if
    /// none). Twin classes are equivalence classes (transpositions that are
    /// automorphisms compose into automorphisms), so this chains each class
    /// in index order.
    pub(super) fn twin_prev(&self, classes: &[(usize, usize)]) -> Vec<u32> {
        let mut prev = vec![NONE; self.n];
        let sigs: Vec<(u32, usize, usize, u64)> = (0..self.n)
            .map(|u| {
                (
                    self.loops[u],
                    self.out[u].len(),
                    self.inn[u].len(),
                    self.degree(u),
                )
            })
            .collect();
        let sig = |u: usize| sigs[u];
        for &(s, e) in classes {
            for (u2, slot) in prev.iter_mut().enumerate().take(e).skip(s) {
                let s2 = sig(u2);
                if let Some(u1) = (s..u2)
                    .rev()
                    .find(|&u1| sig(u1) == s2 && self.twins(u1 as u32, u2 as u32))
                {
                    *slot = u1 as u32;
                }
            }
        }
        prev
    }

    /// Out-degree + in-degree + loops (with multiplicity).
    pub(super) fn degree(&self, u: usize) -> u64 {
        let o: u64 = self.out[u].iter().map(|&(_, m)| u64::from(m)).sum();
        let i: u64 = self.inn[u].iter().map(|&(_, m)| u64::from(m)).sum();
        o + i + u64::from(self.loops[u])
    }

    pub(super) fn is_dummy(&self, u: u32) -> bool {
        self.orig[u as usize] == NONE
    }
}

/// A padded instance: `s1` is searched (rows), `s2` is matched (columns).
#[derive(Debug, Clone)]
pub(crate) struct Problem {
    pub s1: Side,
    pub s2: Side,
    /// Padded index range `[start, end)` of each label class, equal on both sides.
    pub classes: Vec<(usize, usize)>,
    /// Class index of each padded vertex.
    pub class_of: Vec<u32>,
    /// Σ over classes of |c1 − c2|: vertex insertions and deletions.
    pub vertex_cost: u64,
}

impl Problem {
    /// Pads `g1` and `g2` class by class (classes are the distinct labels).
    /// O((n + m) log n), integers only.
    pub(super) fn new(g1: &Shape, g2: &Shape) -> Problem {
        let mut labels: Vec<u32> = g1.labels().iter().chain(g2.labels()).copied().collect();
        labels.sort_unstable();
        labels.dedup();
        let class = |lab: u32| labels.binary_search(&lab).unwrap_or(0);
        // Members of each class, in index order, on each side.
        let members = |g: &Shape| -> Vec<Vec<u32>> {
            let mut m = vec![Vec::new(); labels.len()];
            for (i, &lab) in g.labels().iter().enumerate() {
                m[class(lab)].push(i as u32);
            }
            m
        };
        let (m1, m2) = (members(g1), members(g2));
        let mut classes = Vec::with_capacity(labels.len());
        let mut class_of = Vec::new();
        let mut pos1 = vec![NONE; g1.n()];
        let mut pos2 = vec![NONE; g2.n()];
        let mut orig1 = Vec::new();
        let mut orig2 = Vec::new();
        let mut vertex_cost = 0u64;
        for (k, (members1, members2)) in m1.iter().zip(&m2).enumerate() {
            let start = orig1.len();
            let size = members1.len().max(members2.len());
            vertex_cost += members1.len().abs_diff(members2.len()) as u64;
            for (orig, pos, members) in [
                (&mut orig1, &mut pos1, members1),
                (&mut orig2, &mut pos2, members2),
            ] {
                for &i in members.iter() {
                    pos[i as usize] = orig.len() as u32;
                    orig.push(i);
                }
                orig.resize(start + size, NONE);
            }
            class_of.resize(start + size, k as u32);
            classes.push((start, start + size));
        }
        let n = orig1.len();
        let s1 = Self::side(g1, &pos1, orig1, n);
        let s2 = Self::side(g2, &pos2, orig2, n);
        Problem {
            s1,
            s2,
            classes,
            class_of,
            vertex_cost,
        }
    }

    fn side(g: &Shape, pos: &[u32], orig: Vec<u32>, n: usize) -> Side {
        let mut out = Vec::with_capacity(g.arcs().len());
        let mut inn = Vec::with_capacity(g.arcs().len());
        let mut loops = vec![0u32; n];
        for &(t, h, m) in g.arcs() {
            let (pt, ph) = (pos[t as usize], pos[h as usize]);
            if pt == ph {
                loops[pt as usize] = m;
            } else {
                out.push((pt, (ph, m)));
                inn.push((ph, (pt, m)));
            }
        }
        Side {
            n,
            orig,
            out: Adj::build(n, &out),
            inn: Adj::build(n, &inn),
            loops,
            arcs: g.arc_count(),
        }
    }

    /// Padded vertex count.
    pub(super) fn n(&self) -> usize {
        self.s1.n
    }

    /// The count bound |vertex classes| + |m1 − m2|, a lower bound on GED.
    pub(super) fn count_bound(&self) -> u64 {
        self.vertex_cost + self.s1.arcs.abs_diff(self.s2.arcs)
    }

    /// Arcs of G1 preserved by σ: Σ_{arcs (u,w)} min(A(u,w), B(σ u, σ w)).
    pub(super) fn overlap(&self, sigma: &[u32]) -> u64 {
        let mut total = 0u64;
        for u in 0..self.n() {
            let su = sigma[u];
            total += u64::from(self.s1.loops[u].min(self.s2.mult(su, su)));
            for &(w, a) in &self.s1.out[u] {
                total += u64::from(a.min(self.s2.mult(su, sigma[w as usize])));
            }
        }
        total
    }

    /// The cost of a class-preserving bijection σ of the padded vertices.
    pub(super) fn cost(&self, sigma: &[u32]) -> u64 {
        self.vertex_cost + self.s1.arcs + self.s2.arcs - 2 * self.overlap(sigma)
    }

    /// Whether σ is a class-preserving bijection (a debugging aid for tests).
    #[cfg(test)]
    pub(super) fn is_valid(&self, sigma: &[u32]) -> bool {
        if sigma.len() != self.n() {
            return false;
        }
        let mut seen = vec![false; self.n()];
        for (u, &v) in sigma.iter().enumerate() {
            let v = v as usize;
            if v >= self.n() || seen[v] || self.class_of[u] != self.class_of[v] {
                return false;
            }
            seen[v] = true;
        }
        true
    }

    /// A quick starting bijection: within each class, vertices of both sides
    /// sorted by decreasing degree and paired in that order.
    pub(super) fn greedy(&self) -> Vec<u32> {
        let mut sigma = vec![NONE; self.n()];
        for &(s, e) in &self.classes {
            let mut a: Vec<usize> = (s..e).collect();
            let mut b: Vec<usize> = (s..e).collect();
            a.sort_by_cached_key(|&u| (std::cmp::Reverse(self.s1.degree(u)), u));
            b.sort_by_cached_key(|&v| (std::cmp::Reverse(self.s2.degree(v)), v));
            for (u, v) in a.into_iter().zip(b) {
                sigma[u] = v as u32;
            }
        }
        sigma
    }
}

/// Inverse of a bijection given as a vector.
pub(crate) fn invert(sigma: &[u32]) -> Vec<u32> {
    let mut inv = vec![NONE; sigma.len()];
    for (u, &v) in sigma.iter().enumerate() {
        if let Some(slot) = inv.get_mut(v as usize) {
            *slot = u as u32;
        }
    }
    inv
}

#[cfg(test)]
mod tests {
    use super::*;

    use super::super::graph::GedGraph;

    fn g(labels: Vec<u32>, arcs: &[(usize, usize)]) -> GedGraph {
        let keys = (0..labels.len()).map(|i| format!("v{i}")).collect();
        GedGraph::new(labels, keys, arcs.iter().copied()).expect("valid")
    }

    #[test]
    fn pads_each_class() {
        let a = g(vec![0, 1, 1], &[(0, 1), (1, 2), (2, 2)]);
        let b = g(vec![0, 0, 1], &[(0, 1)]);
        let p = Problem::new(&a, &b);
        assert_eq!(p.classes, vec![(0, 2), (2, 4)]);
        assert_eq!(p.vertex_cost, 2);
        assert_eq!(p.s1.orig, vec![0, NONE, 1, 2]);
        assert_eq!(p.s2.orig, vec![0, 1, 2, NONE]);
        assert_eq!(p.count_bound(), 2 + 2);
        let id: Vec<u32> = (0..4).collect();
        assert!(p.is_valid(&id));
        // a: 0->1(pos 2), 1->2 (2->3), loop at 3. b: 0->1 (pos 0 -> pos 1).
        // identity keeps nothing: cost = 2 + 3 + 1.
        assert_eq!(p.cost(&id), 6);
    }

    #[test]
    fn finds_twins() {
        // 0 -> {1, 2, 3}; 1 and 2 are leaves (twins), 3 has a loop; 4 and 5
        // form a 2-cycle (twins of each other), 6 is isolated.
        let a = g(
            vec![0; 7],
            &[(0, 1), (0, 2), (0, 3), (3, 3), (4, 5), (5, 4)],
        );
        let p = Problem::new(&a, &a);
        let prev = p.s1.twin_prev(&p.classes);
        assert_eq!(prev, vec![NONE, NONE, 1, NONE, NONE, 4, NONE]);
    }
}
