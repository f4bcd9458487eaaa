//! The compact graph the GED engine works on: `n` vertices with an integer
//! label (the vertex type class) and a key (the vertex's identity for `named`
//! GED), and a multiset of directed arcs in which self-loops `(u, u)` and
//! parallel arcs are kept, as SPEC §2 counts them (one arc per transition).
//!
//! The multiset is stored aggregated: one `(tail, head, multiplicity)` triple
//! per ordered pair, sorted, so that the multiplicity of any ordered pair can be
//! looked up by binary search.

use btfsm_model::graph::PolicyGraph;

/// An input error when building a [`GedGraph`] by hand.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum GedGraphError {
    #[error("{labels} labels but {keys} keys: each vertex needs one of each")]
    LengthMismatch { labels: usize, keys: usize },
    #[error("arc ({tail}, {head}) names a vertex outside 0..{n}")]
    ArcOutOfRange { tail: usize, head: usize, n: usize },
    #[error("more than u32::MAX vertices or parallel arcs")]
    TooLarge,
}

/// The key-less part of a [`GedGraph`]: labels and the aggregated arc
/// multiset, all the search needs. Built from a policy graph in linear time
/// (a counting sort by tail, then each tail's heads sorted; integers only),
/// so that `compare` can build it inside each mode's time budget.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Shape {
    labels: Vec<u32>,
    /// `(tail, head, multiplicity)`, sorted by `(tail, head)`, multiplicity >= 1.
    arcs: Vec<(u32, u32, u32)>,
    /// The arcs of tail `u` are `arcs[first[u]..first[u + 1]]` (n + 1
    /// entries; empty for the default shape).
    first: Vec<u32>,
}

impl Shape {
    /// Builds a shape from per-vertex labels and a list of arcs, one entry
    /// per arc (repeat a pair for parallel arcs; `(u, u)` is a self-loop).
    pub fn new(
        labels: Vec<u32>,
        arcs: impl IntoIterator<Item = (usize, usize)>,
    ) -> Result<Self, GedGraphError> {
        let n = labels.len();
        if u32::try_from(n).is_err() {
            return Err(GedGraphError::TooLarge);
        }
        let mut raw: Vec<(u32, u32)> = Vec::new();
        for (tail, head) in arcs {
            if tail >= n || head >= n {
                return Err(GedGraphError::ArcOutOfRange { tail, head, n });
            }
            // Both fit in u32: n does.
            raw.push((tail as u32, head as u32));
        }
        if u32::try_from(raw.len()).is_err() {
            return Err(GedGraphError::TooLarge);
        }
        // Counting sort by tail, then each tail's heads sorted.
        let mut start = vec![0u32; n + 1];
        for &(t, _) in &raw {
            start[t as usize + 1] += 1;
        }
        for u in 0..n {
            start[u + 1] += start[u];
        }
        let mut heads = vec![0u32; raw.len()];
        let mut fill = start.clone();
        for &(t, h) in &raw {
            heads[fill[t as usize] as usize] = h;
            fill[t as usize] += 1;
        }
        let mut agg: Vec<(u32, u32, u32)> = Vec::with_capacity(raw.len());
        let mut first = Vec::with_capacity(n + 1);
        for u in 0..n {
            first.push(agg.len() as u32);
            let hs = &mut heads[start[u] as usize..start[u + 1] as usize];
            hs.sort_unstable();
            for &h in hs.iter() {
                match agg.last_mut() {
                    Some(last) if last.0 == u as u32 && last.1 == h => {
                        last.2 = last.2.checked_add(1).ok_or(GedGraphError::TooLarge)?;
                    }
                    _ => agg.push((u as u32, h, 1)),
                }
            }
        }
        first.push(agg.len() as u32);
        Ok(Shape {
            labels,
            arcs: agg,
            first,
        })
    }

    /// Number of vertices.
    pub fn n(&self) -> usize {
        self.labels.len()
    }

    /// The label (vertex type class) of each vertex.
    pub fn labels(&self) -> &[u32] {
        &self.labels
    }

    /// The arc multiset, aggregated: `(tail, head, multiplicity)` sorted by
    /// `(tail, head)`.
    pub fn arcs(&self) -> &[(u32, u32, u32)] {
        &self.arcs
    }

    /// Number of arcs, parallel arcs and self-loops included.
    pub fn arc_count(&self) -> u64 {
        self.arcs.iter().map(|&(_, _, m)| u64::from(m)).sum()
    }

    /// Multiplicity of the ordered pair `(u, v)` (0 when there is no arc).
    pub fn mult(&self, u: usize, v: usize) -> u32 {
        let (Ok(u), Ok(v)) = (u32::try_from(u), u32::try_from(v)) else {
            return 0;
        };
        // Within u's arcs only: a short, cache-friendly search.
        let (Some(&s), Some(&e)) = (self.first.get(u as usize), self.first.get(u as usize + 1))
        else {
            return 0;
        };
        let out = &self.arcs[s as usize..e as usize];
        match out.binary_search_by_key(&v, |&(_, h, _)| h) {
            Ok(i) => out[i].2,
            Err(_) => 0,
        }
    }

    /// The same shape with every label replaced by 0 (for `structural` GED).
    pub(crate) fn unlabeled(&self) -> Shape {
        Shape {
            labels: vec![0; self.labels.len()],
            arcs: self.arcs.clone(),
            first: self.first.clone(),
        }
    }
}

impl From<&PolicyGraph> for Shape {
    /// Vertex `i` is petgraph's node index `i`; its label is the vertex
    /// type's discriminant.
    fn from(pg: &PolicyGraph) -> Self {
        let labels: Vec<u32> = pg.g.node_weights().map(|v| v.vtype as u32).collect();
        let arcs =
            pg.g.raw_edges()
                .iter()
                .map(|e| (e.source().index(), e.target().index()));
        // Indices come from the graph itself, so they are in range; a graph
        // with more than u32::MAX elements cannot be built by petgraph's
        // default u32 indices either. Fall back to an empty shape rather
        // than panic if that ever changes.
        Shape::new(labels, arcs).unwrap_or_default()
    }
}

/// A directed multigraph with labelled, keyed vertices `0..n`: a [`Shape`]
/// (which it dereferences to) plus one key per vertex.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GedGraph {
    shape: Shape,
    keys: Vec<String>,
}

impl std::ops::Deref for GedGraph {
    type Target = Shape;
    fn deref(&self) -> &Shape {
        &self.shape
    }
}

impl GedGraph {
    /// Builds a graph from per-vertex labels and keys and a list of arcs, one
    /// entry per arc (repeat a pair for parallel arcs; `(u, u)` is a self-loop).
    pub fn new(
        labels: Vec<u32>,
        keys: Vec<String>,
        arcs: impl IntoIterator<Item = (usize, usize)>,
    ) -> Result<Self, GedGraphError> {
        if labels.len() != keys.len() {
            return Err(GedGraphError::LengthMismatch {
                labels: labels.len(),
                keys: keys.len(),
            });
        }
        Ok(GedGraph {
            shape: Shape::new(labels, arcs)?,
            keys,
        })
    }

    /// The key of each vertex.
    pub fn keys(&self) -> &[String] {
        &self.keys
    }

    /// The labels and arcs.
    pub fn shape(&self) -> &Shape {
        &self.shape
    }

    /// The same graph with every label replaced by 0 (for `structural` GED).
    #[cfg(test)]
    pub(crate) fn unlabeled(&self) -> GedGraph {
        GedGraph {
            shape: self.shape.unlabeled(),
            keys: self.keys.clone(),
        }
    }
}

impl From<&PolicyGraph> for GedGraph {
    /// Vertex `i` of the result is petgraph's node index `i`; its label is the
    /// vertex type's discriminant and its key the vertex's key.
    fn from(pg: &PolicyGraph) -> Self {
        let shape = Shape::from(pg);
        let keys = if shape.n() == pg.g.node_count() {
            pg.g.node_weights().map(|v| v.key.clone()).collect()
        } else {
            Vec::new()
        };
        GedGraph { shape, keys }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn aggregates_parallel_arcs_and_loops() {
        let g = GedGraph::new(
            vec![0, 1],
            vec!["a".into(), "b".into()],
            [(0, 1), (1, 1), (0, 1), (1, 0)],
        )
        .expect("valid graph");
        assert_eq!(g.arcs(), &[(0, 1, 2), (1, 0, 1), (1, 1, 1)]);
        assert_eq!(g.arc_count(), 4);
        assert_eq!(g.mult(0, 1), 2);
        assert_eq!(g.mult(1, 1), 1);
        assert_eq!(g.mult(0, 0), 0);
    }

    #[test]
    fn rejects_bad_input() {
        assert!(matches!(
            GedGraph::new(vec![0], vec![], []),
            Err(GedGraphError::LengthMismatch { .. })
        ));
        assert!(matches!(
            GedGraph::new(vec![0], vec!["a".into()], [(0, 1)]),
            Err(GedGraphError::ArcOutOfRange { .. })
        ));
    }
}
