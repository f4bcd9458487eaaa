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
//!   work budget (or the CPU-time safety cap) runs out, a certified
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

pub use crate::cpu::Deadline;

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
/// exactness, interval) on any machine under any load. `timeout` is a
/// safety cap counted in CPU time of the searching thread ([`crate::cpu`]),
/// so that a loaded machine does not make it fire sooner; by default it is
/// derived from `work` ([`GedOptions::with_work`]) with a wide margin, so
/// that the work budget always ends a search first. When the cap ends a
/// search first anyway, the result says so ([`StopReason::Time`]) and may
/// then depend on the machine.
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
    /// CPU-time safety cap of the whole computation of a mode (graphs,
    /// problems, search, script), checked at every search node and inside
    /// long loops (docs/robustness.md "Budgets" measures the overshoot).
    pub timeout: Duration,
    /// Work budget of the branch and bound, in work units: one unit per
    /// entry of an assignment matrix built to bound a search node (a node
    /// with k unmapped vertices costs about k² units, plus n + 1 for its
    /// set-up), and per (vertex, image) pair scored by the forest bound
    /// (`treebound.rs`): 15 to 40 ns each on the machine of
    /// docs/performance.md. Structural GED on labeled graphs runs a labeled
    /// search with an eighth, then a structural one with the rest (see
    /// `structural`).
    pub work: u64,
}

/// The default work budget ([`GedOptions::work`]): about 4-6 s of CPU on
/// the hardest pairs measured (the random FSM-like pairs of
/// docs/performance.md that no budget settles); pairs settled sooner stop
/// sooner (most policy pairs in milliseconds). It was 10,000,000 until the
/// ascent bound (`ascent.rs`), then 100,000,000 until a labeled pair that
/// HiGHS proves in 6 s (71, docs/performance.md) was found to need 2·10⁸.
pub const DEFAULT_WORK: u64 = 300_000_000;

/// The floor of the derived CPU-time cap ([`GedOptions::with_work`]), in
/// ms: what a small budget's fixed phases (embedding, dives, local search on
/// up to 2048 vertices) may take beside its work.
pub const DEFAULT_TIMEOUT_MS: u64 = 30_000;

/// CPU nanoseconds allowed per work unit by the derived cap: ten times the
/// most measured (docs/performance.md, "Budgets and the CPU-time cap").
pub const CAP_NANOS_PER_WORK: u64 = 400;

impl GedOptions {
    /// The budget `work` with its derived CPU-time cap: `work` ×
    /// [`CAP_NANOS_PER_WORK`] ns, at least [`DEFAULT_TIMEOUT_MS`] (120 s at
    /// the default work), far past what the work takes, so that the work
    /// budget decides.
    pub fn with_work(work: u64) -> GedOptions {
        let nanos = work.saturating_mul(CAP_NANOS_PER_WORK);
        GedOptions {
            timeout: Duration::from_nanos(nanos).max(Duration::from_millis(DEFAULT_TIMEOUT_MS)),
            work,
        }
    }
}

impl Default for GedOptions {
    fn default() -> Self {
        GedOptions::with_work(DEFAULT_WORK)
    }
}

/// Why an inexact search stopped.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum StopReason {
    /// The work budget ran out: reproducible on any machine.
    Work,
    /// The CPU-time safety cap (`--timeout-ms`) ran out before the work
    /// budget: the interval may differ on another machine.
    Time,
    /// The padded graphs are too large for the exact search (above 2048
    /// vertices): the count bound and a local-search mapping.
    Size,
}

impl StopReason {
    pub fn as_str(self) -> &'static str {
        match self {
            StopReason::Work => "work",
            StopReason::Time => "time",
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
    /// Work units the search spent ([`GedOptions::work`]): the same on any
    /// machine.
    pub work: u64,
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
    /// Work units the search spent ([`GedOptions::work`]): the same on any
    /// machine.
    pub work: u64,
}

/// GED between two policy graphs (see the module documentation); the
/// budget's clock starts before the compact graphs are built.
pub fn ged(a: &PolicyGraph, b: &PolicyGraph, mode: GedMode, opts: &GedOptions) -> GedResult {
    let start = Instant::now();
    let deadline = Deadline::after(opts.timeout);
    ged_since(
        start,
        deadline,
        &GedGraph::from(a),
        &GedGraph::from(b),
        mode,
        opts,
    )
}

/// GED between two compact graphs; labels are used by `Labeled`, keys by
/// `Named` and by the edit script.
pub fn ged_graphs(a: &GedGraph, b: &GedGraph, mode: GedMode, opts: &GedOptions) -> GedResult {
    ged_since(
        Instant::now(),
        Deadline::after(opts.timeout),
        a,
        b,
        mode,
        opts,
    )
}

/// [`ged_graphs`] with the time counted from `start` and the safety cap
/// `deadline`.
fn ged_since(
    start: Instant,
    deadline: Deadline,
    a: &GedGraph,
    b: &GedGraph,
    mode: GedMode,
    opts: &GedOptions,
) -> GedResult {
    let finish = |lower: u64, upper: u64, edit_script: EditScript, why, work| GedResult {
        ged: upper,
        exact: lower >= upper,
        lower_bound: lower.min(upper),
        upper_bound: upper,
        millis: u64::try_from(start.elapsed().as_millis()).unwrap_or(u64::MAX),
        stopped_by: if lower >= upper { None } else { why },
        work,
        edit_script,
    };
    let mut by_name = script::named_mapping(a, b);
    if mode == GedMode::Named {
        let s = script::build(a, b, &by_name);
        let c = s.cost();
        return finish(c, c, s, None, 0);
    }
    // The mapping by name, and its script, first: it competes with the
    // search's mapping below, and building it measures what the script of
    // the search's mapping will cost once the search stops, which is kept
    // out of the search's budget.
    if mode == GedMode::Labeled {
        keep_same_labels(a, b, &mut by_name);
    }
    let named = script::build(a, b, &by_name);
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
    finish(
        found.lower_bound.min(upper),
        upper,
        s,
        found.stopped_by,
        found.work,
    )
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
/// result says [`StopReason::Time`]. The search runs in rounds of growing
/// work (`rounds`), so that a pair settled with little work takes little
/// work whatever the budget.
pub fn search_mapping(
    a: &Shape,
    b: &Shape,
    labeled: bool,
    deadline: Deadline,
    work: u64,
) -> GedMapping {
    let mut out = Rounds::default();
    let (lower, map) = if deadline.passed() {
        (count_bound(a, b, labeled), vec![None; a.n()])
    } else {
        let st = if labeled {
            Oriented::within(a, b, deadline)
        } else {
            Oriented::within(&a.unlabeled(), &b.unlabeled(), deadline)
        };
        match st {
            Some(o) => {
                // Structural GED on graphs of several labels, unless a side
                // is a forest (BTs), is seeded by a labeled search (see
                // `rounds`).
                let seed = if !labeled && multi_class(a, b) && !treebound::has_forest(&o.p) {
                    Oriented::within(a, b, deadline)
                } else {
                    None
                };
                out = rounds(&o, seed.as_ref(), deadline, work);
                (out.lower, o.to_ab(&out.sigma))
            }
            None => (count_bound(a, b, labeled), vec![None; a.n()]),
        }
    };
    let upper = mapping_cost(a, b, &map);
    let stopped_by = if lower >= upper {
        None
    } else if deadline.passed() {
        Some(StopReason::Time)
    } else if out.too_large {
        Some(StopReason::Size)
    } else {
        Some(StopReason::Work)
    };
    GedMapping {
        lower_bound: lower.min(upper),
        upper_bound: upper,
        map,
        stopped_by,
        work: out.work,
    }
}

/// Whether the two shapes carry more than one label between them.
fn multi_class(a: &Shape, b: &Shape) -> bool {
    let first_label = a.labels().first().or(b.labels().first());
    a.labels()
        .iter()
        .chain(b.labels())
        .any(|l| Some(l) != first_label)
}

/// What [`rounds`] found: a certified lower bound, the cheapest padded
/// bijection, whether the problem was too large for the exact search, and
/// the work spent.
#[derive(Default)]
struct Rounds {
    lower: u64,
    sigma: Vec<u32>,
    too_large: bool,
    work: u64,
}

/// Work of the first round of [`rounds`].
const FIRST_ROUND_WORK: u64 = 1 << 20;
/// Each round of [`rounds`] gets this many times the work of the one
/// before.
const ROUND_GROWTH: u64 = 8;

/// The search of `o` by rounds of growing work: `FIRST_ROUND_WORK`, then
/// `ROUND_GROWTH` times more each round, each from the cheapest mapping
/// found so far and keeping the best lower bound, until the value is
/// settled; the third round, or one that would leave less than itself of
/// `work`, gets all that is left (at the default budget: 1, 8 and 291
/// million units; at 5 million: 1 and 4, so that a pair settled in the
/// first round takes the same work at both). (A round of 64 million before
/// the rest doubled the work of a structural FSM pair that needs 82
/// million.) (The search's phases share the work they are
/// given — the forest search three quarters on BTs, the root's ascent up
/// to a quarter, a labeled seed an eighth — so one search with the whole
/// budget spent those shares before a later phase settled a pair that a
/// small budget settles: issue 34 measured a pair exact in 0.28 s at
/// `--work 5e6` take 3.42 s at the default.) The rounds take at most the
/// budget in all. Pairs that need more than the first rounds pay for them:
/// on the structural FSM pairs of docs/performance.md settled with 13 to
/// 82 million units, 10 million more.
///
/// With `seed` (structural GED on graphs of several labels), each round
/// first runs a labeled search of `seed` with an eighth of its work, whose
/// mapping is also a structural one, and on policy graphs usually a very
/// good one, while the labeled search is far easier (its classes are
/// small). (Measured on the FSM-like pairs of `bench/ged_vs_highs.py`:
/// this settled structural fsm-1 and fsm-2.) The split is by work, never
/// by time.
fn rounds(o: &Oriented, seed: Option<&Oriented>, deadline: Deadline, work: u64) -> Rounds {
    let mut r = Rounds::default();
    let mut best_cost = u64::MAX;
    if let Some(lab) = seed {
        let s = rounds(lab, None, deadline, work / LABELED_SEED_SHARE);
        r.work = s.work;
        r.sigma = o.padded_from_ab(&lab.to_ab(&s.sigma));
        best_cost = o.p.cost(&r.sigma);
    }
    let mut round = FIRST_ROUND_WORK;
    loop {
        let left = work.saturating_sub(r.work);
        let last = round > FIRST_ROUND_WORK * ROUND_GROWTH || left / 2 < round;
        let budget = if last { left } else { round }.max(1);
        let hint = (!r.sigma.is_empty()).then(|| r.sigma.clone());
        let lim = search::Limits {
            deadline,
            work: budget,
        };
        let out = search::solve(&o.p, &lim, hint);
        r.work += out.work;
        r.lower = r.lower.max(out.lower);
        r.too_large |= out.too_large;
        let c = o.p.cost(&out.sigma);
        if c < best_cost {
            best_cost = c;
            r.sigma = out.sigma;
        }
        if r.lower >= best_cost || last || r.too_large || deadline.passed() {
            return r;
        }
        round = round.saturating_mul(ROUND_GROWTH);
    }
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
    fn within(a: &Shape, b: &Shape, deadline: Deadline) -> Option<Oriented> {
        let swap = Self::swap(a, b);
        if deadline.passed() {
            return None;
        }
        let o = Self::build(a, b, swap);
        (!deadline.passed()).then_some(o)
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
