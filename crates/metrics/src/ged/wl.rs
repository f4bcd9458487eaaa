//! Weisfeiler–Lehman colour refinement on both padded sides at once, used
//! only as a tie-breaker by the upper-bound heuristics (never by a lower
//! bound).
//!
//! Colour 0 of a vertex is its class; colour k+1 is a shared identifier of
//! (colour k, its loops, the sorted multisets of (colour k, multiplicity) of
//! its out- and in-neighbours) — the 1-dimensional Weisfeiler–Lehman
//! refinement (Weisfeiler & Leman, 1968; in the form of Shervashidze et al.,
//! "Weisfeiler-Lehman Graph Kernels", JMLR 12, 2011), with one dictionary for
//! both graphs so colours are comparable across them. `similarity(u, v)` is
//! the last round at which u and v still have the same colour: vertices whose
//! surroundings agree to a larger radius are likelier images of each other.
//! Degree-based local costs cannot tell apart siblings of equal degree whose
//! subtrees differ; this can.

use std::collections::BTreeMap;

use super::problem::{Problem, Side};

/// Rounds of refinement (radius of the neighbourhood compared).
const ROUNDS: usize = 6;

/// Per-round colours of both sides.
#[derive(Debug, Clone)]
pub(crate) struct Colours {
    c1: Vec<Vec<u32>>,
    c2: Vec<Vec<u32>>,
}

type Signature = (u32, u32, Vec<(u32, u32)>, Vec<(u32, u32)>);

fn signature(s: &Side, prev: &[u32], u: usize) -> Signature {
    let mut out: Vec<(u32, u32)> = s.out[u]
        .iter()
        .map(|&(w, m)| (prev[w as usize], m))
        .collect();
    let mut inn: Vec<(u32, u32)> = s.inn[u]
        .iter()
        .map(|&(w, m)| (prev[w as usize], m))
        .collect();
    out.sort_unstable();
    inn.sort_unstable();
    (prev[u], s.loops[u], out, inn)
}

impl Colours {
    pub(super) fn new(p: &Problem) -> Colours {
        let mut c1 = vec![p.class_of.clone()];
        let mut c2 = vec![p.class_of.clone()];
        for _ in 0..ROUNDS {
            let (Some(prev1), Some(prev2)) = (c1.last(), c2.last()) else {
                break;
            };
            let mut dict: BTreeMap<Signature, u32> = BTreeMap::new();
            let mut next = |s: &Side, prev: &[u32]| -> Vec<u32> {
                (0..s.n)
                    .map(|u| {
                        let sig = signature(s, prev, u);
                        let id = dict.len() as u32;
                        *dict.entry(sig).or_insert(id)
                    })
                    .collect()
            };
            let n1 = next(&p.s1, prev1);
            let n2 = next(&p.s2, prev2);
            let stable = dict.len() == distinct(prev1, prev2);
            c1.push(n1);
            c2.push(n2);
            if stable {
                break;
            }
        }
        Colours { c1, c2 }
    }

    /// The number of rounds after which `u` (side 1) and `v` (side 2) still
    /// share a colour (0 when their classes differ).
    pub(super) fn similarity(&self, u: usize, v: usize) -> u32 {
        let mut k = 0;
        for (a, b) in self.c1.iter().zip(&self.c2) {
            if a[u] != b[v] {
                break;
            }
            k += 1;
        }
        k
    }

    /// Upper bound of `similarity`.
    pub(super) fn max_similarity(&self) -> u32 {
        self.c1.len() as u32
    }
}

fn distinct(a: &[u32], b: &[u32]) -> usize {
    let mut all: Vec<u32> = a.iter().chain(b).copied().collect();
    all.sort_unstable();
    all.dedup();
    all.len()
}

#[cfg(test)]
mod tests {
    use super::super::graph::GedGraph;
    use super::*;

    #[test]
    fn separates_siblings_with_different_subtrees() {
        // 0 -> 1, 0 -> 2, 1 -> 3: vertices 1 and 2 have equal degree from
        // the root's side but different subtrees.
        let keys = |n: usize| (0..n).map(|i| format!("v{i}")).collect::<Vec<_>>();
        let a = GedGraph::new(vec![0; 4], keys(4), [(0, 1), (0, 2), (1, 3)]).expect("valid");
        let p = Problem::new(&a, &a);
        let c = Colours::new(&p);
        assert!(c.similarity(1, 1) > c.similarity(1, 2));
        assert_eq!(c.similarity(1, 1), c.max_similarity());
    }
}
