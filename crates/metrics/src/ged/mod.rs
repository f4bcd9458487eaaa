//! Graph edit distance (paper sec. IV-A 2, Eq. 2; SPEC §3) between two policy
//! graphs: directed multigraphs with self-loops and parallel arcs, unit costs
//! (vertex and arc insertion/deletion 1, substitution 0). For a vertex
//! mapping f, the cost is the vertices deleted and inserted, plus
//! Σ |mult_a(u, w) − mult_b(f u, f w)| over ordered pairs of mapped vertices
//! (self-loops are the pairs (u, u)), plus every arc at a deleted or inserted
//! vertex.
//!
//! Three modes:
//! - `Structural`: the minimum over all vertex mappings — what NetworkX's
//!   `graph_edit_distance` computes by default, which the paper used, but with
//!   self-loops scored correctly (NetworkX issues #5400, #8188). NP-hard:
//!   exact by an embedding fast path (`embed.rs`), a Lagrangian forest
//!   bound and search when one side is a forest (`treebound.rs`), and a
//!   branch and bound with assignment lower bounds (`search.rs`); when the
//!   work budget (or the wall-clock safety cap) runs out, a certified
//!   interval `[lower_bound, upper_bound]` with `exact = false`, never a
//!   guess, and the reason ([`StopReason`]).
//! - `Labeled`: the same, but a vertex maps only to a vertex of the same
//!   type.
//! - `Named`: vertices map by key; linear time (plus sorting the script),
//!   always exact.
//!
//! Every mode returns the edit script of the mapping it found (`script.rs`),
//! whose cost is `upper_bound`. [`search_mapping`] is the search alone, on
//! key-less [`Shape`]s, with everything it builds (padded problems, fast
//! path, local search) inside its deadline; `compare` calls it with the
//! mapping by name and the edit scripts built around it, so that a mode's
//! whole computation fits its budget. The search always starts from a canonical
//! orientation of the pair (fewer vertices first, then a total order on the
//! graphs), so `ged(a, b)` and `ged(b, a)` run the same search; the script
//! is turned back to read a → b.
//!
//! Files: `graph.rs` the compact graph; `problem.rs` the padded instance and
//! its cost; `embed.rs` the count-bound fast path; `lsap.rs` linear
//! assignment; `ascent.rs` the Lagrangian bound with dual ascent (graphs
//! that are not forests) and `root.rs` its schedule at the search's root; `local.rs` 2-swap local search; `wl.rs` Weisfeiler–Lehman
//! tie-breaking; `treebound.rs` the Lagrangian forest bound and its search
//! (when one side is a forest: BTs); `search.rs` the branch and bound;
//! `script.rs` edit scripts
//! and the named mapping; `brute.rs` and `tests.rs` the test oracle and
//! tests.

mod ascent;
mod embed;
mod graph;
mod local;
mod lsap;
mod problem;
mod reopt;
mod root;
mod script;
mod search;
mod treebound;
mod wl;

#[cfg(test)]
mod brute;
#[cfg(test)]
mod tests;

use std::time::{Duration, Instant};

pub use graph::{GedGraph, GedGraphError, Shape};

pub use script::{EditScript, injective, named_mapping_of_ids, named_mapping_of_keys};

use btfsm_model::graph::PolicyGraph;
use problem::{NONE, Problem};

/// Which vertex mappings are allowed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum GedMode {
    /// Any vertex may map to any vertex.
    Structural,
    /// Vertices map only to vertices of the same [`btfsm_model::graph::VertexType`].
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

/// Budgets for the exact search (`Structural` and `Labeled`; `Named` needs
/// none).
///
/// The search is decided by `work` alone: every step that may end it early
/// counts work units, never the clock, so one pair gives one result (value,
/// exactness, interval) on any machine under any load, as long as `timeout`
/// is not reached. `timeout` is a wall-clock safety cap: when it ends a
/// search first, the result says so ([`StopReason::Timeout`]) and may then
/// depend on the machine.
///
/// Memory does not grow with either budget: with n the larger vertex count,
/// the search holds two n × n tables (4 + 1 bytes per entry) and a stack of
/// at most n frames of O(n) words, those that re-optimised the ascent's
/// shares each with a copy of them (64 MiB in all at most,
/// `reopt::MAX_HELD_BYTES`); when one side is a forest, the forest
/// bound adds one n × n table of 8 bytes per entry. Above 2048 vertices no search is made
/// (the count bound and a local-search mapping are returned).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct GedOptions {
    /// Wall-clock safety cap of the whole computation of a mode (graphs,
    /// problems, search, script), checked at every search node and inside
    /// long loops (docs/robustness.md "Budgets" measures the overshoot).
    pub timeout: Duration,
    /// Work budget of the branch and bound, in work units: one unit per
    /// entry of an assignment matrix built to bound a search node (a node
    /// with k unmapped vertices costs about k² units, plus n + 1 for its
    /// set-up), and per (vertex, image) pair scored by the forest bound
    /// (`treebound.rs`): 20 to 50 ns each on the machine of
    /// docs/performance.md. Structural GED on labeled graphs runs a labeled
    /// search with an eighth, then a structural one with the rest (see
    /// `structural`).
    pub work: u64,
}

/// The default work budget ([`GedOptions::work`]): about 4-5 s on the
/// hardest pairs measured (the random FSM-like pairs of
/// docs/performance.md that no budget settles, otherwise idle machine),
/// inside the default 30 s cap with room for a loaded machine; pairs
/// settled sooner stop sooner (most policy pairs in milliseconds). It was
/// 10,000,000 until the ascent bound (`ascent.rs`), then 100,000,000 until
/// a labeled pair that HiGHS proves in 6 s (71, docs/performance.md) was
/// found to need 2·10⁸.
pub const DEFAULT_WORK: u64 = 300_000_000;

/// The default wall-clock safety cap ([`GedOptions::timeout`]), in ms: six
/// times what the default work takes at most on an idle machine.
pub const DEFAULT_TIMEOUT_MS: u64 = 30_000;

impl Default for GedOptions {
    fn default() -> Self {
        GedOptions {
            timeout: Duration::from_millis(DEFAULT_TIMEOUT_MS),
            work: DEFAULT_WORK,
        }
    }
}

/// Why an inexact search stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum StopReason {
    /// The work budget ran out: reproducible on any machine.
    Work,
    /// The wall-clock cap (`--timeout-ms`) ran out first: the interval may
    /// differ on another machine or under another load.
    Timeout,
    /// The padded graphs are too large for the exact search (above 2048
    /// vertices): the count bound and a local-search mapping.
    Size,
}

impl StopReason {
    pub fn as_str(self) -> &'static str {
        match self {
            StopReason::Work => "work",
            StopReason::Timeout => "timeout",
            StopReason::Size => "size",
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
    /// Why the search stopped when `exact` is false.
    pub stopped_by: Option<StopReason>,
    /// The edits of the best mapping found, a → b.
    pub edit_script: EditScript,
}

/// A mapping found by [`search_mapping`], with its certificate, before any
/// edit script is written.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct GedMapping {
    /// Certified: no mapping (of the mode searched) costs less.
    pub lower_bound: u64,
    /// The cost of `map` ([`mapping_cost`]), `>= lower_bound`.
    pub upper_bound: u64,
    /// Vertex of a -> vertex of b (a partial injection).
    pub map: Vec<Option<usize>>,
    /// Why the search stopped, when `lower_bound < upper_bound`.
    pub stopped_by: Option<StopReason>,
}

/// GED between two policy graphs (see the module documentation); the
/// budget's clock starts before the compact graphs are built.
pub fn ged(a: &PolicyGraph, b: &PolicyGraph, mode: GedMode, opts: &GedOptions) -> GedResult {
    let start = Instant::now();
    ged_since(start, &GedGraph::from(a), &GedGraph::from(b), mode, opts)
}

/// GED between two compact graphs; labels are used by `Labeled`, keys by
/// `Named` and by the edit script.
pub fn ged_graphs(a: &GedGraph, b: &GedGraph, mode: GedMode, opts: &GedOptions) -> GedResult {
    ged_since(Instant::now(), a, b, mode, opts)
}

/// [`ged_graphs`] with the budget counted from `start`.
fn ged_since(
    start: Instant,
    a: &GedGraph,
    b: &GedGraph,
    mode: GedMode,
    opts: &GedOptions,
) -> GedResult {
    let finish = |lower: u64, upper: u64, edit_script: EditScript, why| GedResult {
        ged: upper,
        exact: lower >= upper,
        lower_bound: lower.min(upper),
        upper_bound: upper,
        millis: u64::try_from(start.elapsed().as_millis()).unwrap_or(u64::MAX),
        stopped_by: if lower >= upper { None } else { why },
        edit_script,
    };
    let mut by_name = script::named_mapping(a, b);
    if mode == GedMode::Named {
        let s = script::build(a, b, &by_name);
        let c = s.cost();
        return finish(c, c, s, None);
    }
    // The mapping by name, and its script, first: it competes with the
    // search's mapping below, and building it measures what the script of
    // the search's mapping will cost once the search stops, which is kept
    // out of the search's budget.
    if mode == GedMode::Labeled {
        keep_same_labels(a, b, &mut by_name);
    }
    let named = script::build(a, b, &by_name);
    let deadline = start + opts.timeout.saturating_sub(start.elapsed());
    let found = search_mapping(a, b, mode == GedMode::Labeled, deadline, opts.work);
    // Among mappings of equal cost, prefer the one by name: its script reads
    // as the engineer's own edits rather than as an arbitrary rematching.
    // It also tightens the upper bound when the search ran out of budget.
    let s = if named.cost() <= found.upper_bound {
        named
    } else {
        script::build(a, b, &found.map)
    };
    // The script scores the mapping kept, in the original graphs.
    let upper = s.cost();
    finish(found.lower_bound.min(upper), upper, s, found.stopped_by)
}

/// Unmaps the pairs of `map` whose labels differ (a mapping by name made
/// fit for `labeled` GED).
pub fn keep_same_labels(a: &Shape, b: &Shape, map: &mut [Option<usize>]) {
    for (u, m) in map.iter_mut().enumerate() {
        if m.is_some_and(|v| a.labels().get(u) != b.labels().get(v)) {
            *m = None;
        }
    }
}

/// The cost of the partial injection `map` under the unit cost model (the
/// cost of its edit script), in O((n + m) log m) integer work. Entries out
/// of range or not injective count as unmapped, as in the edit script.
pub fn mapping_cost(a: &Shape, b: &Shape, map: &[Option<usize>]) -> u64 {
    let (fwd, _) = script::injective(a.n(), b.n(), map);
    let mapped = fwd.iter().filter(|m| m.is_some()).count() as u64;
    let mut kept = 0u64;
    for &(t, h, m) in a.arcs() {
        if let (Some(x), Some(y)) = (fwd[t as usize], fwd[h as usize]) {
            kept += u64::from(m.min(b.mult(x, y)));
        }
    }
    (a.n() as u64 - mapped) + (b.n() as u64 - mapped) + a.arc_count() + b.arc_count() - 2 * kept
}

/// The count bound: vertex insertions and deletions forced by the class
/// sizes (one class when `labeled` is false), plus |m1 − m2|.
fn count_bound(a: &Shape, b: &Shape, labeled: bool) -> u64 {
    let arcs = a.arc_count().abs_diff(b.arc_count());
    if !labeled {
        return a.n().abs_diff(b.n()) as u64 + arcs;
    }
    let mut diff: std::collections::BTreeMap<u32, i64> = std::collections::BTreeMap::new();
    for &l in a.labels() {
        *diff.entry(l).or_default() += 1;
    }
    for &l in b.labels() {
        *diff.entry(l).or_default() -= 1;
    }
    diff.values().map(|d| d.unsigned_abs()).sum::<u64>() + arcs
}

/// The search of `structural` (`labeled` false) or `labeled` GED on two
/// shapes, everything included (padded problems, fast path, branch and
/// bound, local search) within `deadline`: a certified lower bound and the
/// best mapping found. Work after the search is O(n + m log m) (mapping the
/// padded bijection back and scoring it). If the deadline has passed on
/// entry, no problem is built: the count bound and the empty mapping.
///
/// Nothing but `work` decides how far the search goes; `deadline` only
/// aborts it, and when it did (the clock is past it at the end) an inexact
/// result says [`StopReason::Timeout`].
pub fn search_mapping(
    a: &Shape,
    b: &Shape,
    labeled: bool,
    deadline: Instant,
    work: u64,
) -> GedMapping {
    let mut too_large = false;
    let (lower, map) = if Instant::now() >= deadline {
        (count_bound(a, b, labeled), vec![None; a.n()])
    } else if labeled {
        match Oriented::within(a, b, deadline) {
            Some(o) => {
                let lim = search::Limits { deadline, work };
                let out = search::solve(&o.p, &lim, None);
                too_large = out.too_large;
                (out.lower, o.to_ab(&out.sigma))
            }
            None => (count_bound(a, b, true), vec![None; a.n()]),
        }
    } else {
        let (lower, map, large) = structural(a, b, deadline, work);
        too_large = large;
        (lower, map)
    };
    let upper = mapping_cost(a, b, &map);
    let stopped_by = if lower >= upper {
        None
    } else if Instant::now() >= deadline {
        Some(StopReason::Timeout)
    } else if too_large {
        Some(StopReason::Size)
    } else {
        Some(StopReason::Work)
    };
    GedMapping {
        lower_bound: lower.min(upper),
        upper_bound: upper,
        map,
        stopped_by,
    }
}

/// Structural GED. When the graphs carry more than one label, a labeled
/// mapping is also a structural one, and on policy graphs usually a very
/// good one, while the labeled search is far easier (its classes are
/// small); so, unless a side is a forest, a labeled search with an eighth
/// of the work budget first finds a mapping, and one structural search
/// with the rest starts from it. (Measured on the FSM-like pairs of
/// `bench/ged_vs_highs.py`: this settled structural fsm-1 and fsm-2, which
/// the earlier split — a structural search, then a labeled one seeding a
/// second structural search, a third each — did not; each structural
/// search repeated the root's bound.) The split is by work, never by time.
/// Returns the bound, the mapping, and whether the graphs were too large
/// for the exact search.
fn structural(
    a: &Shape,
    b: &Shape,
    deadline: Instant,
    work: u64,
) -> (u64, Vec<Option<usize>>, bool) {
    let (ua, ub) = (a.unlabeled(), b.unlabeled());
    let Some(st) = Oriented::within(&ua, &ub, deadline) else {
        return (count_bound(a, b, false), vec![None; a.n()], false);
    };
    let first_label = a.labels().first().or(b.labels().first());
    let multi_class = a
        .labels()
        .iter()
        .chain(b.labels())
        .any(|l| Some(l) != first_label);
    // One search with the whole budget when there is one class, or when a
    // side is a forest (BTs): the forest search settles those far better
    // than a labeled seed would help it.
    let seeded = multi_class && !treebound::has_forest(&st.p);
    let hint = if seeded {
        let lim = search::Limits {
            deadline,
            work: work / LABELED_SEED_SHARE,
        };
        Oriented::within(a, b, deadline).map(|labeled| {
            let lab = search::solve(&labeled.p, &lim, None);
            st.padded_from_ab(&labeled.to_ab(&lab.sigma))
        })
    } else {
        None
    };
    let lim = search::Limits {
        deadline,
        work: if seeded {
            (work - work / LABELED_SEED_SHARE).max(1)
        } else {
            work
        },
    };
    let out = search::solve(&st.p, &lim, hint);
    (out.lower, st.to_ab(&out.sigma), out.too_large)
}

/// The labeled search that seeds a structural one gets 1/this of the work.
const LABELED_SEED_SHARE: u64 = 8;

/// A padded instance in canonical orientation, with conversions between its
/// padded bijections and partial injections of the original a → b.
struct Oriented {
    p: Problem,
    swap: bool,
    n_a: usize,
    n_b: usize,
}

impl Oriented {
    /// [`Oriented::new`], unless `deadline` passes before the padded
    /// problem is built (its set-up, O((n + m) log n), reads the clock
    /// between its steps: milliseconds each on 100k vertices).
    fn within(a: &Shape, b: &Shape, deadline: Instant) -> Option<Oriented> {
        let swap = Self::swap(a, b);
        if Instant::now() >= deadline {
            return None;
        }
        let o = Self::build(a, b, swap);
        (Instant::now() < deadline).then_some(o)
    }

    #[cfg(test)]
    fn new(a: &Shape, b: &Shape) -> Oriented {
        Self::build(a, b, Self::swap(a, b))
    }

    /// Whether b is searched from (see `orientation_key`).
    fn swap(a: &Shape, b: &Shape) -> bool {
        match (b.n(), b.arc_count()).cmp(&(a.n(), a.arc_count())) {
            std::cmp::Ordering::Less => true,
            std::cmp::Ordering::Greater => false,
            std::cmp::Ordering::Equal => {
                // Equal sizes: the degree signatures, then the raw data, so
                // that (a, b) and (b, a) always run the same search.
                let (ka, kb) = (orientation_key(a), orientation_key(b));
                kb < ka || (kb == ka && (b.labels(), b.arcs()) < (a.labels(), a.arcs()))
            }
        }
    }

    fn build(a: &Shape, b: &Shape, swap: bool) -> Oriented {
        let p = if swap {
            Problem::new(b, a)
        } else {
            Problem::new(a, b)
        };
        Oriented {
            p,
            swap,
            n_a: a.n(),
            n_b: b.n(),
        }
    }

    /// Padded bijection -> partial injection of the original a -> b.
    fn to_ab(&self, sigma: &[u32]) -> Vec<Option<usize>> {
        let mut m = vec![None; self.n_a];
        for (u, &v) in sigma.iter().enumerate() {
            let ou = self.p.s1.orig.get(u).copied().unwrap_or(NONE);
            let ov = self.p.s2.orig.get(v as usize).copied().unwrap_or(NONE);
            if ou == NONE || ov == NONE {
                continue;
            }
            let (x, y) = if self.swap { (ov, ou) } else { (ou, ov) };
            if let Some(slot) = m.get_mut(x as usize) {
                *slot = Some(y as usize);
            }
        }
        m
    }

    /// Partial injection a -> b -> padded bijection: pairs that respect the
    /// classes are kept, the rest filled in index order within each class.
    fn padded_from_ab(&self, map_ab: &[Option<usize>]) -> Vec<u32> {
        let p = &self.p;
        let n = p.n();
        let (n1, n2) = if self.swap {
            (self.n_b, self.n_a)
        } else {
            (self.n_a, self.n_b)
        };
        let mut pos1 = vec![NONE; n1];
        let mut pos2 = vec![NONE; n2];
        for u in 0..n {
            if let Some(slot) = pos1.get_mut(p.s1.orig[u] as usize) {
                *slot = u as u32;
            }
            if let Some(slot) = pos2.get_mut(p.s2.orig[u] as usize) {
                *slot = u as u32;
            }
        }
        let mut sigma = vec![NONE; n];
        let mut used = vec![false; n];
        for (x, y) in map_ab.iter().enumerate() {
            let Some(y) = *y else { continue };
            let (o1, o2) = if self.swap { (y, x) } else { (x, y) };
            let (Some(&u), Some(&v)) = (pos1.get(o1), pos2.get(o2)) else {
                continue;
            };
            if u == NONE || v == NONE || used[v as usize] {
                continue;
            }
            if p.class_of[u as usize] == p.class_of[v as usize] {
                sigma[u as usize] = v;
                used[v as usize] = true;
            }
        }
        for &(s, e) in &p.classes {
            let mut free = (s..e).filter(|&v| !used[v]);
            for slot in sigma[s..e].iter_mut() {
                if *slot == NONE {
                    *slot = free.next().map_or(NONE, |v| v as u32);
                }
            }
        }
        sigma
    }
}

/// Sorted (label, out, in, loops) per vertex.
type OrientationKey = Vec<(u32, u64, u64, u32)>;

/// Canonical orientation: the graph with fewer vertices (then fewer arcs, then
/// the smaller degree/label signature (this key), then the smaller raw data)
/// is searched from.
fn orientation_key(g: &Shape) -> OrientationKey {
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
    sig
}
