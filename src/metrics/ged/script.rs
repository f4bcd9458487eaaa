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
    let mut fwd: Vec<Option<usize>> = vec![None; a.n()];
    let mut inv: Vec<Option<usize>> = vec![None; b.n()];
    for (u, m) in map.iter().enumerate().take(a.n()) {
        if let Some(v) = *m
            && v < b.n()
            && inv[v].is_none()
        {
            fwd[u] = Some(v);
            inv[v] = Some(u);
        }
    }
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
    s.vertices_added.sort();
    s.vertices_removed.sort();
    s.vertices_kept.sort();
    s.arcs_added.sort();
    s.arcs_removed.sort();
    s.arcs_kept.sort();
    s
}

/// The `named` mapping: each vertex of a maps to the vertex of b with the
/// same key. Keys are unique within a graph; should one repeat, its
/// occurrences are paired in index order and the rest left unmapped.
pub(crate) fn named_mapping(a: &GedGraph, b: &GedGraph) -> Vec<Option<usize>> {
    let mut by_key: HashMap<&str, Vec<usize>> = HashMap::with_capacity(b.n());
    for (v, k) in b.keys().iter().enumerate().rev() {
        by_key.entry(k.as_str()).or_default().push(v);
    }
    a.keys()
        .iter()
        .map(|k| by_key.get_mut(k.as_str()).and_then(|vs| vs.pop()))
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
