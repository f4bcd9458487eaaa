//! Graph edit distance (paper sec. IV-A 2, Eq. 2; SPEC §3) between two policy
//! graphs: directed multigraphs with self-loops, unit costs (vertex and arc
//! insertion/deletion 1, substitution 0).
//!
//! Three modes:
//! - `Structural`: the minimum over all vertex mappings — what NetworkX's
//!   `graph_edit_distance` computes by default, which the paper used, but with
//!   self-loops and parallel arcs scored correctly (NetworkX issues #5400,
//!   #8188). Exact by branch and bound (`search.rs`) after an embedding fast
//!   path (`embed.rs`); under a time or expansion budget the result is a
//!   certified interval `[lower_bound, upper_bound]` with `exact = false`.
//! - `Labeled`: the same, but a vertex maps only to a vertex of the same type.
//! - `Named`: vertices map by key; linear time, always exact.
//!
//! Every mode returns the edit script of the mapping it found (`script.rs`).
//! The value does not depend on argument order: the search always starts from
//! the smaller graph (a canonical orientation), and the script is turned back
//! to read a → b.

mod embed;
mod graph;
mod local;
mod lsap;
mod problem;
mod script;
mod search;

#[cfg(test)]
mod brute;
#[cfg(test)]
mod tests;

use std::time::{Duration, Instant};

pub use graph::{GedGraph, GedGraphError};
pub use script::EditScript;

use crate::graph::PolicyGraph;
use problem::{NONE, Problem};

/// Which vertex mappings are allowed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum GedMode {
    /// Any vertex may map to any vertex.
    Structural,
    /// Vertices map only to vertices of the same [`crate::graph::VertexType`].
    Labeled,
    /// Vertices map by key.
    Named,
}

impl GedMode {
    pub fn as_str(self) -> &'static str {
        match self {
            GedMode::Structural => "structural",
            GedMode::Labeled => "labeled",
            GedMode::Named => "named",
        }
    }
}

/// Budgets for the exact search (`Structural` and `Labeled`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GedOptions {
    /// Wall-clock budget; the search stops at the first check past it.
    pub timeout: Duration,
    /// Bound on branch-and-bound nodes expanded (each holds O(n) memory on a
    /// stack of depth at most n, on top of one n × n table).
    pub max_expansions: u64,
}

impl Default for GedOptions {
    fn default() -> Self {
        GedOptions {
            timeout: Duration::from_secs(2),
            max_expansions: 20_000_000,
        }
    }
}

/// A GED value with its certificate.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize)]
pub struct GedResult {
    /// The cost of the best mapping found (= `upper_bound`).
    pub ged: u64,
    /// Whether `ged` is proven minimal (`lower_bound == upper_bound`).
    pub exact: bool,
    /// Certified: no mapping costs less.
    pub lower_bound: u64,
    /// Certified: the mapping of `edit_script` costs this much.
    pub upper_bound: u64,
    /// Wall-clock time spent.
    pub millis: u64,
    /// The edits of the best mapping found, a → b.
    pub edit_script: EditScript,
}

/// GED between two policy graphs (see the module documentation).
pub fn ged(a: &PolicyGraph, b: &PolicyGraph, mode: GedMode, opts: &GedOptions) -> GedResult {
    ged_graphs(&GedGraph::from(a), &GedGraph::from(b), mode, opts)
}

/// GED between two compact graphs; labels are used by `Labeled`, keys by
/// `Named` and by the edit script.
pub fn ged_graphs(a: &GedGraph, b: &GedGraph, mode: GedMode, opts: &GedOptions) -> GedResult {
    let start = Instant::now();
    let finish = |lower: u64, upper: u64, edit_script: EditScript| GedResult {
        ged: upper,
        exact: lower >= upper,
        lower_bound: lower.min(upper),
        upper_bound: upper,
        millis: u64::try_from(start.elapsed().as_millis()).unwrap_or(u64::MAX),
        edit_script,
    };
    if mode == GedMode::Named {
        let map = script::named_mapping(a, b);
        let s = script::build(a, b, &map);
        let c = s.cost();
        return finish(c, c, s);
    }
    let (ua, ub);
    let (ga, gb) = if mode == GedMode::Structural {
        ua = a.unlabeled();
        ub = b.unlabeled();
        (&ua, &ub)
    } else {
        (a, b)
    };
    let swap = orientation_key(gb) < orientation_key(ga);
    let (g1, g2) = if swap { (gb, ga) } else { (ga, gb) };
    let p = Problem::new(g1, g2);
    let limits = search::Limits {
        deadline: start + opts.timeout,
        max_expansions: opts.max_expansions,
    };
    let out = search::solve(&p, &limits);
    // Padded bijection -> partial injection of original vertices g1 -> g2.
    let mut map12: Vec<Option<usize>> = vec![None; g1.n()];
    for (u, &v) in out.sigma.iter().enumerate() {
        let (ou, ov) = (
            p.s1.orig[u],
            p.s2.orig.get(v as usize).copied().unwrap_or(NONE),
        );
        if ou != NONE && ov != NONE {
            map12[ou as usize] = Some(ov as usize);
        }
    }
    let map_ab = if swap {
        let mut m = vec![None; a.n()];
        for (u2, v) in map12.iter().enumerate() {
            if let Some(v) = *v
                && let Some(slot) = m.get_mut(v)
            {
                *slot = Some(u2);
            }
        }
        m
    } else {
        map12
    };
    let s = script::build(a, b, &map_ab);
    // The script scores the same mapping; keep the two in agreement even if
    // the padded and original views ever diverged.
    let upper = s.cost();
    debug_assert_eq!(upper, out.upper, "script and padded cost agree");
    finish(out.lower.min(upper), upper, s)
}

/// Vertex count, arc count, sorted (label, out, in, loops) per vertex.
type OrientationKey = (usize, u64, Vec<(u32, u64, u64, u32)>);

/// Canonical orientation: the graph with fewer vertices (then fewer arcs, then
/// the smaller degree/label signature) is searched from.
fn orientation_key(g: &GedGraph) -> OrientationKey {
    let n = g.n();
    let mut out = vec![0u64; n];
    let mut inn = vec![0u64; n];
    let mut loops = vec![0u32; n];
    for &(t, h, m) in g.arcs() {
        if t == h {
            loops[t as usize] = m;
        } else {
            out[t as usize] += u64::from(m);
            inn[h as usize] += u64::from(m);
        }
    }
    let mut sig: Vec<(u32, u64, u64, u32)> = (0..n)
        .map(|u| (g.labels()[u], out[u], inn[u], loops[u]))
        .collect();
    sig.sort_unstable();
    (n, g.arc_count(), sig)
}
