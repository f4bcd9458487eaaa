//! Test oracle: GED by enumerating every partial injection from the vertices
//! of a to those of b (each vertex of a is either deleted or mapped to an
//! unused vertex of b, of the same label when `labeled`), scored straight from
//! the cost model's definition in SPEC §3 — vertices deleted + inserted, |A −
//! B| over mapped ordered pairs (self-loops included), every arc at a deleted
//! or inserted vertex. It shares no code with the search (not even the
//! padding), so it checks the padding argument too. Partial costs only grow,
//! so branches already at the best cost are cut; nothing else is.

use super::graph::GedGraph;

struct Oracle<'a> {
    a: &'a GedGraph,
    b: &'a GedGraph,
    labeled: bool,
    f: Vec<Option<usize>>,
    used: Vec<bool>,
    best: u64,
}

impl Oracle<'_> {
    fn step(&mut self, u: usize, acc: u64) {
        if acc >= self.best {
            return;
        }
        let (a, b) = (self.a, self.b);
        if u == a.n() {
            let mut c = acc;
            for v in 0..b.n() {
                if !self.used[v] {
                    c += 1;
                }
            }
            for &(x, y, m) in b.arcs() {
                if !self.used[x as usize] || !self.used[y as usize] {
                    c += u64::from(m);
                }
            }
            self.best = self.best.min(c);
            return;
        }
        // Delete u: 1 + its arcs to already decided vertices and its loop.
        let mut del = 1 + u64::from(a.mult(u, u));
        for w in 0..u {
            del += u64::from(a.mult(u, w)) + u64::from(a.mult(w, u));
        }
        self.f[u] = None;
        self.step(u + 1, acc + del);
        for v in 0..b.n() {
            if self.used[v] || (self.labeled && a.labels()[u] != b.labels()[v]) {
                continue;
            }
            let mut c = u64::from(a.mult(u, u).abs_diff(b.mult(v, v)));
            for w in 0..u {
                match self.f[w] {
                    Some(x) => {
                        c += u64::from(a.mult(u, w).abs_diff(b.mult(v, x)));
                        c += u64::from(a.mult(w, u).abs_diff(b.mult(x, v)));
                    }
                    None => c += u64::from(a.mult(u, w)) + u64::from(a.mult(w, u)),
                }
            }
            self.f[u] = Some(v);
            self.used[v] = true;
            self.step(u + 1, acc + c);
            self.used[v] = false;
            self.f[u] = None;
        }
    }
}

/// Exact GED by exhaustive enumeration (small graphs only).
pub(super) fn brute_ged(a: &GedGraph, b: &GedGraph, labeled: bool) -> u64 {
    // Deleting all of a and inserting all of b is always possible.
    let trivial = a.n() as u64 + a.arc_count() + b.n() as u64 + b.arc_count();
    let mut o = Oracle {
        a,
        b,
        labeled,
        f: vec![None; a.n()],
        used: vec![false; b.n()],
        best: trivial + 1,
    };
    o.step(0, 0);
    o.best
}

/// `count` seeded random multigraph pairs of 1 to `max_n` vertices each
/// (self-loops and parallel arcs; even pairs unlabelled, odd ones with three
/// labels), each with whether its labels are to be used.
pub(super) fn random_pairs(count: usize, seed: u64, max_n: u64) -> Vec<(GedGraph, GedGraph, bool)> {
    let mut x = seed;
    let mut next = move |m: u64| {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x % m.max(1)
    };
    (0..count)
        .map(|i| {
            let n1 = next(max_n) as usize + 1;
            let n2 = next(max_n) as usize + 1;
            let labels = if i % 2 == 0 { 1 } else { 3 };
            let mut graph = |n: usize| {
                let m = next(3 * n as u64 + 2) as usize;
                let l: Vec<u32> = (0..n).map(|_| next(labels) as u32).collect();
                let k: Vec<String> = (0..n).map(|i| format!("v{i}")).collect();
                let arcs: Vec<(usize, usize)> = (0..m)
                    .map(|_| (next(n as u64) as usize, next(n as u64) as usize))
                    .collect();
                GedGraph::new(l, k, arcs).expect("valid")
            };
            (graph(n1), graph(n2), labels > 1)
        })
        .collect()
}
