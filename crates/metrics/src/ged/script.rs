//! The edit script of a vertex mapping, and the `named` mapping.
//!
//! Given a partial injection f from the vertices of graph a to those of graph
//! b, the script lists what an engineer does to turn a into b under the unit
//! cost model of SPEC §3: vertices of a outside f's domain are removed,
//! vertices of b outside its image are added, mapped pairs are kept; for every
//! ordered pair of mapped vertices (u, w) (u = w for self-loops), min(A, B)
//! arcs are kept and the surplus on either side removed or added; arcs at a
//! removed or added vertex are removed or added with it. Its cost (vertex and
//! arc counts) is the GED of that mapping. Lists are sorted, so output is
//! deterministic.
//!
//! `named` GED (SPEC §3) fixes f by key equality: the edit script of a policy
//! whose elements have stable identities, in time linear in the graph sizes
//! plus the final sort.

use std::collections::HashMap;

use super::graph::GedGraph;

/// Which vertices and arcs are added, removed and kept, a → b.
///
/// Vertices are named by key: `vertices_removed` and `arcs_removed` by keys of
/// a, `vertices_added`, `arcs_added` and `arcs_kept` by keys of b;
/// `vertices_kept` pairs an a key with the b key it maps to. Arcs are
/// `(tail, head, count)` with count ≥ 1 (parallel arcs aggregated).
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct EditScript {
    pub vertices_added: Vec<String>,
    pub vertices_removed: Vec<String>,
    pub vertices_kept: Vec<(String, String)>,
    pub arcs_added: Vec<(String, String, u32)>,
    pub arcs_removed: Vec<(String, String, u32)>,
    pub arcs_kept: Vec<(String, String, u32)>,
}

impl EditScript {
    /// Number of unit edit operations (vertex and arc insertions and deletions).
    pub fn cost(&self) -> u64 {
        let arcs = |l: &[(String, String, u32)]| l.iter().map(|t| u64::from(t.2)).sum::<u64>();
        self.vertices_added.len() as u64
            + self.vertices_removed.len() as u64
            + arcs(&self.arcs_added)
            + arcs(&self.arcs_removed)
    }
}

/// The script of the partial injection `map` (vertex of a → vertex of b).
/// Entries of `map` that are out of range or not injective are treated as
/// unmapped.
pub(crate) fn build(a: &GedGraph, b: &GedGraph, map: &[Option<usize>]) -> EditScript {
    let (fwd, inv) = injective(a.n(), b.n(), map);
    let ka = a.keys();
    let kb = b.keys();
    let mut s = EditScript::default();
    for u in 0..a.n() {
        match fwd[u] {
            Some(v) => s.vertices_kept.push((ka[u].clone(), kb[v].clone())),
            None => s.vertices_removed.push(ka[u].clone()),
        }
    }
    for v in 0..b.n() {
        if inv[v].is_none() {
            s.vertices_added.push(kb[v].clone());
        }
    }
    for &(t, h, m) in a.arcs() {
        let (t, h) = (t as usize, h as usize);
        let kept = match (fwd[t], fwd[h]) {
            (Some(x), Some(y)) => {
                let k = m.min(b.mult(x, y));
                if k > 0 {
                    s.arcs_kept.push((kb[x].clone(), kb[y].clone(), k));
                }
                k
            }
            _ => 0,
        };
        if m > kept {
            s.arcs_removed
                .push((ka[t].clone(), ka[h].clone(), m - kept));
        }
    }
    for &(x, y, m) in b.arcs() {
        let (x, y) = (x as usize, y as usize);
        let kept = match (inv[x], inv[y]) {
            (Some(t), Some(h)) => m.min(a.mult(t, h)),
            _ => 0,
        };
        if m > kept {
            s.arcs_added.push((kb[x].clone(), kb[y].clone(), m - kept));
        }
    }
    s.vertices_added.sort_unstable();
    s.vertices_removed.sort_unstable();
    s.vertices_kept.sort_unstable();
    s.arcs_added.sort_unstable();
    s.arcs_removed.sort_unstable();
    s.arcs_kept.sort_unstable();
    s
}

/// `map` restricted to an injection of `0..na` into `0..nb` (entries out of
/// range, or repeating an earlier image, dropped), and its inverse.
pub fn injective(
    na: usize,
    nb: usize,
    map: &[Option<usize>],
) -> (Vec<Option<usize>>, Vec<Option<usize>>) {
    let mut fwd: Vec<Option<usize>> = vec![None; na];
    let mut inv: Vec<Option<usize>> = vec![None; nb];
    for (u, m) in map.iter().enumerate().take(na) {
        if let Some(v) = *m
            && v < nb
            && inv[v].is_none()
        {
            fwd[u] = Some(v);
            inv[v] = Some(u);
        }
    }
    (fwd, inv)
}

/// The `named` mapping: each vertex of a maps to the vertex of b with the
/// same key. Keys are unique within a graph; should one repeat, its
/// occurrences are paired in index order and the rest left unmapped.
pub(crate) fn named_mapping(a: &GedGraph, b: &GedGraph) -> Vec<Option<usize>> {
    named_mapping_of_keys(
        a.keys().iter().map(String::as_str),
        b.keys().iter().map(String::as_str),
    )
}

/// `named_mapping` on key ids (equal keys, equal ids; ids are small
/// integers, below about the number of keys): linear time, no hashing.
pub fn named_mapping_of_ids(a: &[u32], b: &[u32]) -> Vec<Option<usize>> {
    const END: usize = usize::MAX;
    let top = a.iter().chain(b).max().map_or(0, |&m| m as usize + 1);
    let mut first = vec![END; top];
    let mut next = vec![END; b.len()];
    for (v, &k) in b.iter().enumerate().rev() {
        next[v] = first[k as usize];
        first[k as usize] = v;
    }
    a.iter()
        .map(|&k| {
            let v = first[k as usize];
            if v == END {
                return None;
            }
            first[k as usize] = next[v];
            Some(v)
        })
        .collect()
}

/// `named_mapping` on the keys of a and of b, in vertex order: one hash
/// map of b's keys, linear time.
pub fn named_mapping_of_keys<'k>(
    a: impl Iterator<Item = &'k str>,
    b: impl Iterator<Item = &'k str>,
) -> Vec<Option<usize>> {
    const END: usize = usize::MAX;
    let kb: Vec<&str> = b.collect();
    // First unpaired vertex of b with each key, and the next one with the
    // same key after each vertex (keys repeat only in hand-built graphs).
    let mut first: HashMap<&str, usize> = HashMap::with_capacity(kb.len());
    let mut next = vec![END; kb.len()];
    for (v, k) in kb.iter().enumerate().rev() {
        if let Some(w) = first.insert(k, v) {
            next[v] = w;
        }
    }
    a.map(|k| {
        let slot = first.get_mut(k)?;
        let v = *slot;
        if v == END {
            return None;
        }
        *slot = next[v];
        Some(v)
    })
    .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn g(keys: &[&str], arcs: &[(usize, usize)]) -> GedGraph {
        GedGraph::new(
            vec![0; keys.len()],
            keys.iter().map(|k| k.to_string()).collect(),
            arcs.iter().copied(),
        )
        .expect("valid")
    }

    #[test]
    fn named_script_counts_every_edit() {
        let a = g(&["x", "y", "z"], &[(0, 1), (0, 1), (1, 1), (1, 2)]);
        let b = g(&["y", "x", "w"], &[(1, 0), (0, 0), (0, 0), (0, 2)]);
        let m = named_mapping(&a, &b);
        assert_eq!(m, vec![Some(1), Some(0), None]);
        let s = build(&a, &b, &m);
        assert_eq!(s.vertices_removed, vec!["z".to_string()]);
        assert_eq!(s.vertices_added, vec!["w".to_string()]);
        assert_eq!(
            s.arcs_kept,
            vec![("x".into(), "y".into(), 1), ("y".into(), "y".into(), 1)]
        );
        assert_eq!(
            s.arcs_removed,
            vec![("x".into(), "y".into(), 1), ("y".into(), "z".into(), 1)]
        );
        assert_eq!(
            s.arcs_added,
            vec![("y".into(), "w".into(), 1), ("y".into(), "y".into(), 1)]
        );
        assert_eq!(s.cost(), 2 + 2 + 2);
    }
}
