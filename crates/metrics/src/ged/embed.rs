//! Fast path: does the graph with fewer arcs embed in the other one?
//!
//! With the padded formulation of `problem.rs`, GED = vertex cost +
//! Σ_{u,w} |A(u,w) − B(σ u, σ w)| ≥ vertex cost + |m1 − m2| (the count bound),
//! with equality exactly when, say for m1 ≤ m2, A(u,w) ≤ B(σ u, σ w) for every
//! ordered pair: every arc of G1, with its multiplicity, lands on arcs of G2
//! (a class-preserving subgraph monomorphism). Inserting vertices and arcs
//! into a policy — a BT gaining a subtree, an FSM gaining a connected state —
//! gives exactly such pairs, so they are settled here, exactly and with a
//! certificate, before any branch and bound.
//!
//! The search is a backtracking matcher in the style of VF2 (Cordella et al.,
//! IEEE TPAMI 26(10), 2004) for monomorphism: vertices of the smaller side in a
//! connected, depth-first order; candidates drawn from the neighbourhood of an
//! already matched neighbour; degree, loop and distinct-neighbour filters; and
//! full consistency with every matched neighbour. It also yields a parity
//! fact used elsewhere: since Σ|x| ≡ Σx (mod 2), every mapping's cost has the
//! parity of vertex cost + m1 + m2, so when no embedding exists the GED is at
//! least the count bound + 2.

use crate::cpu::Deadline;

use super::problem::{NONE, Problem, Side, invert};

/// What the embedding search established.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum Embedding {
    /// A bijection σ of padded G1 onto padded G2 reaching the count bound.
    Found(Vec<u32>),
    /// The search was exhaustive: no mapping reaches the count bound.
    Absent,
    /// Budget or deadline hit.
    Unknown,
}

struct Degrees {
    out: Vec<u64>,
    inn: Vec<u64>,
    out_distinct: Vec<usize>,
    inn_distinct: Vec<usize>,
}

impl Degrees {
    fn of(s: &Side) -> Degrees {
        Degrees {
            out: s
                .out
                .iter()
                .map(|l| l.iter().map(|&(_, m)| u64::from(m)).sum())
                .collect(),
            inn: s
                .inn
                .iter()
                .map(|l| l.iter().map(|&(_, m)| u64::from(m)).sum())
                .collect(),
            out_distinct: s.out.iter().map(<[_]>::len).collect(),
            inn_distinct: s.inn.iter().map(<[_]>::len).collect(),
        }
    }
}

/// The connected, depth-first-leaning matching order of the vertices of `sub`
/// that have arcs: next is the vertex with most arcs to the ordered set, ties
/// to the neighbour of the most recently ordered vertex, then higher degree.
///
/// The next vertex comes from a max-heap keyed `(arcs to the ordered set,
/// stamp, degree, lowest index)` with stale entries skipped, so the order
/// costs O(m log m), not O(n²) (a 100k-vertex BT is ordered in milliseconds).
fn order(sub: &Side) -> Vec<u32> {
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;
    let n = sub.n;
    let deg: Vec<u64> = (0..n).map(|u| sub.degree(u)).collect();
    let mut placed = vec![false; n];
    let mut conn = vec![0u64; n];
    let mut stamp = vec![0usize; n];
    let mut out = Vec::new();
    let mut heap: BinaryHeap<(u64, usize, u64, Reverse<u32>)> = (0..n)
        .filter(|&u| deg[u] > 0)
        .map(|u| (0, 0, deg[u], Reverse(u as u32)))
        .collect();
    while let Some((c, st, _, Reverse(pick))) = heap.pop() {
        let pu = pick as usize;
        if placed[pu] || c != conn[pu] || st != stamp[pu] {
            continue;
        }
        placed[pu] = true;
        out.push(pick);
        let t = out.len();
        for &(w, m) in sub.out[pu].iter().chain(&sub.inn[pu]) {
            let w = w as usize;
            if !placed[w] {
                conn[w] += u64::from(m);
                stamp[w] = t;
                heap.push((conn[w], t, deg[w], Reverse(w as u32)));
            }
        }
    }
    out
}

/// Searches for a count-bound mapping within `budget` candidate tries.
pub(crate) fn find(p: &Problem, deadline: Deadline, budget: u64) -> Embedding {
    let flipped = p.s1.arcs > p.s2.arcs;
    let (sub, sup) = if flipped {
        (&p.s2, &p.s1)
    } else {
        (&p.s1, &p.s2)
    };
    match search(p, sub, sup, deadline, budget) {
        Embedding::Found(s) if flipped => Embedding::Found(invert(&s)),
        other => other,
    }
}

/// Searches `sub` into `sup`: set-up, backtracking, then completion with the
/// arc-less vertices.
fn search(p: &Problem, sub: &Side, sup: &Side, deadline: Deadline, budget: u64) -> Embedding {
    let m = match Matcher::new(p, sub, sup, deadline) {
        Ok(m) => m,
        Err(settled) => return settled,
    };
    let n = p.n();
    let mut sigma = vec![NONE; n];
    let mut used = vec![false; n];
    if let Err(settled) = m.backtrack(&mut sigma, &mut used, deadline, budget) {
        return settled;
    }
    complete(p, sigma, &used)
}

/// Per class, whether `sup` has at least as many vertices with arcs as `sub`
/// (a quick necessary condition for an embedding).
fn classes_can_host(p: &Problem, sub: &Side, sup: &Side) -> bool {
    p.classes.iter().all(|&(s, e)| {
        let need = (s..e).filter(|&u| sub.degree(u) > 0).count();
        let have = (s..e).filter(|&v| sup.degree(v) > 0).count();
        need <= have
    })
}

/// The two sides of an embedding search with their degrees and the matching
/// order of `sub`.
struct Matcher<'a> {
    p: &'a Problem,
    sub: &'a Side,
    sup: &'a Side,
    ds: Degrees,
    dp: Degrees,
    ord: Vec<u32>,
}

impl<'a> Matcher<'a> {
    /// Builds the degrees and the order, reading the clock between the steps;
    /// `Err` holds the outcome when the set-up already settles the search.
    fn new(
        p: &'a Problem,
        sub: &'a Side,
        sup: &'a Side,
        deadline: Deadline,
    ) -> Result<Self, Embedding> {
        // The set-up below is O((n + m) log m), milliseconds on 100k vertices:
        // the clock is read between its steps, so that a spent budget stops it.
        let late = || deadline.passed();
        let ds = Degrees::of(sub);
        let dp = Degrees::of(sup);
        if late() {
            return Err(Embedding::Unknown);
        }
        let ord = order(sub);
        if late() {
            return Err(Embedding::Unknown);
        }
        if !classes_can_host(p, sub, sup) {
            return Err(Embedding::Absent);
        }
        if late() {
            return Err(Embedding::Unknown);
        }
        Ok(Matcher {
            p,
            sub,
            sup,
            ds,
            dp,
            ord,
        })
    }

    /// Whether `v` of `sup` can host `u` of `sub` on its own: same class, and
    /// at least as many loops, arcs and distinct neighbours each way.
    #[inline]
    fn fits(&self, u: usize, v: usize) -> bool {
        let (ds, dp) = (&self.ds, &self.dp);
        self.p.class_of[u] == self.p.class_of[v]
            && self.sup.loops[v] >= self.sub.loops[u]
            && dp.out[v] >= ds.out[u]
            && dp.inn[v] >= ds.inn[u]
            && dp.out_distinct[v] >= ds.out_distinct[u]
            && dp.inn_distinct[v] >= ds.inn_distinct[u]
    }

    /// The unused vertices of `sup` consistent with the matched neighbours of
    /// the vertex at depth `d`, tightest (closest degrees) first.
    fn candidates(&self, d: usize, sigma: &[u32], used: &[bool]) -> Vec<u32> {
        let (p, sub, sup) = (self.p, self.sub, self.sup);
        let u = self.ord[d] as usize;
        // Anchor: a matched neighbour, preferring the one with fewest options.
        let mut pool: Option<Vec<u32>> = None;
        for &(w, _) in &sub.inn[u] {
            let sw = sigma[w as usize];
            if sw != NONE {
                let l: Vec<u32> = sup.out[sw as usize].iter().map(|&(x, _)| x).collect();
                if pool.as_ref().is_none_or(|p| l.len() < p.len()) {
                    pool = Some(l);
                }
            }
        }
        for &(w, _) in &sub.out[u] {
            let sw = sigma[w as usize];
            if sw != NONE {
                let l: Vec<u32> = sup.inn[sw as usize].iter().map(|&(x, _)| x).collect();
                if pool.as_ref().is_none_or(|p| l.len() < p.len()) {
                    pool = Some(l);
                }
            }
        }
        let pool = pool.unwrap_or_else(|| {
            let c = p.class_of[u] as usize;
            let (s, e) = p.classes.get(c).copied().unwrap_or((0, 0));
            (s as u32..e as u32).collect()
        });
        let mut out: Vec<u32> = pool
            .into_iter()
            .filter(|&v| {
                let vu = v as usize;
                if used[vu] || !self.fits(u, vu) {
                    return false;
                }
                sub.out[u].iter().all(|&(w, a)| {
                    let sw = sigma[w as usize];
                    sw == NONE || sup.mult(v, sw) >= a
                }) && sub.inn[u].iter().all(|&(w, a)| {
                    let sw = sigma[w as usize];
                    sw == NONE || sup.mult(sw, v) >= a
                })
            })
            .collect();
        // Tightest first: candidates whose degrees are closest to u's.
        let (ds, dp) = (&self.ds, &self.dp);
        out.sort_by_key(|&v| {
            let v = v as usize;
            (dp.out[v] - ds.out[u] + dp.inn[v] - ds.inn[u], v)
        });
        out
    }

    /// Depth-first matching of the ordered vertices into `sigma` (and
    /// `used`); `Ok` once all are matched, `Err` with the outcome otherwise.
    fn backtrack(
        &self,
        sigma: &mut [u32],
        used: &mut [bool],
        deadline: Deadline,
        budget: u64,
    ) -> Result<(), Embedding> {
        let ord = &self.ord;
        // Per depth: candidate list and next index.
        let mut cands: Vec<Vec<u32>> = Vec::with_capacity(ord.len());
        let mut next: Vec<usize> = Vec::with_capacity(ord.len());
        let mut tries = 0u64;
        if !ord.is_empty() {
            cands.push(self.candidates(0, sigma, used));
            next.push(0);
        }
        loop {
            let d = cands.len();
            if d == 0 {
                return Err(Embedding::Absent);
            }
            if d > ord.len() {
                return Ok(());
            }
            let top = d - 1;
            let u = ord[top] as usize;
            // Undo the previous choice at this depth.
            if sigma[u] != NONE {
                used[sigma[u] as usize] = false;
                sigma[u] = NONE;
            }
            let i = next[top];
            if i >= cands[top].len() {
                cands.pop();
                next.pop();
                continue;
            }
            next[top] = i + 1;
            tries += 1;
            // The clock is read at every try: one try builds a candidate list,
            // which on a large class costs far more than reading it.
            if tries > budget || deadline.passed() {
                return Err(Embedding::Unknown);
            }
            let v = cands[top][i];
            sigma[u] = v;
            used[v as usize] = true;
            if d == ord.len() {
                return Ok(());
            }
            let c = self.candidates(d, sigma, used);
            cands.push(c);
            next.push(0);
        }
    }
}

/// Completes `sigma` with the arc-less vertices, class by class.
fn complete(p: &Problem, mut sigma: Vec<u32>, used: &[bool]) -> Embedding {
    for &(s, e) in &p.classes {
        let mut free = (s..e).filter(|&v| !used[v]);
        for slot in sigma[s..e].iter_mut() {
            if *slot == NONE {
                match free.next() {
                    Some(v) => *slot = v as u32,
                    None => return Embedding::Unknown,
                }
            }
        }
    }
    Embedding::Found(sigma)
}

#[cfg(test)]
mod tests {
    use super::super::graph::GedGraph;
    use super::*;
    use std::time::Duration;

    fn g(n: usize, arcs: &[(usize, usize)]) -> GedGraph {
        let keys = (0..n).map(|i| format!("v{i}")).collect();
        GedGraph::new(vec![0; n], keys, arcs.iter().copied()).expect("valid")
    }

    #[test]
    fn finds_path_in_cycle_and_refuses_loop() {
        let far = Deadline::after(Duration::from_secs(10));
        let path = g(3, &[(0, 1), (1, 2)]);
        let cycle = g(4, &[(0, 1), (1, 2), (2, 3), (3, 0)]);
        let p = Problem::new(&path, &cycle);
        match find(&p, far, 1_000) {
            Embedding::Found(s) => {
                assert!(p.is_valid(&s));
                assert_eq!(p.cost(&s), p.count_bound());
            }
            other => panic!("expected an embedding, got {other:?}"),
        }
        // A self-loop cannot land on a plain arc (NetworkX's mistake).
        let looped = g(2, &[(0, 0)]);
        let plain = g(2, &[(0, 1)]);
        let q = Problem::new(&looped, &plain);
        assert_eq!(find(&q, far, 1_000), Embedding::Absent);
        // Reverse orientation (more arcs first).
        let r = Problem::new(&cycle, &path);
        assert!(matches!(find(&r, far, 1_000), Embedding::Found(_)));
    }
}
