//! Ordered labelled tree edit distance (Tai, J. ACM 1979): the fewest unit
//! operations — delete a node (its children take its place), insert one,
//! rename one — that turn tree a into tree b, children order mattering.
//! `btfsm compare --mode tree` computes it between two Behavior Trees, where
//! order is priority: swapping two children of a Sequence costs > 0 here,
//! while the paper's GED (unordered, `metrics::ged`) sees no change.
//!
//! First, bounds from the label sequences (`bounds.rs`, with Myers'
//! bit-parallel Levenshtein distance, `sed.rs`: `n·m/64` word steps, about
//! 13 M for two 10,000-node trees): the preorder, postorder and half the
//! Euler-string distances bound the distance from below, and the pairs of
//! an optimal sequence alignment that keep both orders are a mapping. When
//! the lower bound meets the best mapping (this one or the top-down one of
//! `greedy.rs`), that is the distance (so on the benchmark's copies with 1
//! and 5 edits).
//! Otherwise Zhang & Shasha's algorithm (SIAM J. Comput. 1989; `zs.rs`) runs
//! in a diagonal band of width `u` (Touzet, CPM 2005), starting at the lower
//! bound, with `u` grown by half (or set to the best mapping's cost once
//! close to it) until the band's result is at most `u`, which proves it
//! exact. Similar trees cost about O(n·k·u²) cells (`k` the keyroots on a
//! root-leaf path; measured: docs/performance.md) and O(n·u) memory.
//! Once a band would cost as much as the whole tables — counted before it
//! runs: an upper bound of its cells against the product of the keyroot
//! weights — Zhang & Shasha's algorithm runs unbanded (`dense.rs`: 16-bit
//! cells, contiguous rows), which is exact whatever the distance: two
//! unrelated 10,000-node random trees take seconds (docs/performance.md).
//! Of the trees' two orientations (as drawn and mirrored, same distance:
//! leftmost or rightmost paths, as in Pawlik & Augsten's RTED, PVLDB 2011,
//! but chosen once per pair) the one with fewer cells is used.
//!
//! Work and memory are bounded by counts, not time ([`TedOptions`]): table
//! cells computed, and bytes of tables held, each checked before a table is
//! allocated or a band or the unbanded run starts. Past either, the result
//! is an interval `[lower, upper]` with the script of a mapping costing
//! `upper`, the same on any machine, and [`TedResult::stopped_by`] says
//! which budget ended it.
//!
//! Not built: Pawlik & Augsten's per-subtree-pair optimal path strategies
//! (APTED, TODS 2015, Inf. Syst. 2016), which would need fewer subproblems
//! on deep trees (docs/performance.md counts them) at the price of a
//! strategy table as large as the distance table.

mod band;
mod bounds;
pub mod bt;
mod dense;
mod greedy;
mod mapping;
mod refine;
mod script;
mod sed;
mod sweep;
#[cfg(test)]
mod tests;
mod tree;
pub mod tree_text;

pub use refine::prefer_same_class;
pub use script::{TreeEdit, edit_script};
pub use tree::OrderedTree;

use zs::Banded;
mod zs;

/// A tree to compare: an arena of children lists with a label id per node
/// (ids shared by both trees: equal ids, equal labels).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LabelledTree {
    pub children: Vec<Vec<usize>>,
    pub labels: Vec<u32>,
    pub root: usize,
}

impl LabelledTree {
    /// Nodes reachable from the root, parents before children, children
    /// in order (each node once).
    pub fn preorder(&self) -> Vec<usize> {
        let mut seen = vec![false; self.children.len()];
        let mut out = Vec::new();
        let mut stack = vec![self.root];
        while let Some(n) = stack.pop() {
            if n >= seen.len() || seen[n] {
                continue;
            }
            seen[n] = true;
            out.push(n);
            stack.extend(self.children[n].iter().rev().copied());
        }
        out
    }
}

/// Bounds of one computation, counted so that a result never depends on
/// the machine's load.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct TedOptions {
    /// Most table cells computed, over the bounds, all bands tried and the
    /// unbanded run (checked after each band's forest table, and before
    /// the unbanded run, whose cells are counted in advance). Recovering
    /// the mapping afterwards adds at most as many cells as its tables
    /// took.
    pub max_work: u64,
    /// Most bytes of tables held at once (checked before each is
    /// allocated).
    pub max_bytes: u64,
}

/// Default [`TedOptions::max_work`]: 10¹⁰ cells (about 3 ns each), three
/// times what two unrelated 10,000-node random trees need unbanded
/// (docs/performance.md).
pub const DEFAULT_MAX_WORK: u64 = 10_000_000_000;
/// Default [`TedOptions::max_bytes`]: 1 GiB, enough for the unbanded
/// tables of two unrelated 10,000-node random trees (2 bytes a cell, about
/// 2·n1·n2 cells plus the kept rows: 400–650 MB).
pub const DEFAULT_MAX_BYTES: u64 = 1 << 30;

impl Default for TedOptions {
    fn default() -> Self {
        TedOptions {
            max_work: DEFAULT_MAX_WORK,
            max_bytes: DEFAULT_MAX_BYTES,
        }
    }
}

/// Which budget ended an inexact computation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum TedStop {
    /// [`TedOptions::max_work`]: the next table would pass it.
    Work,
    /// [`TedOptions::max_bytes`]: the next tables would not fit (raising
    /// the work budget alone does not help).
    Memory,
}

impl TedStop {
    pub fn as_str(self) -> &'static str {
        match self {
            TedStop::Work => "work",
            TedStop::Memory => "memory",
        }
    }
}

/// The distance, or the interval it lies in, with a mapping of cost `upper`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct TedResult {
    pub lower: u64,
    pub upper: u64,
    /// Mapped pairs `(node of a, node of b)` in arena indices, sorted.
    pub mapping: Vec<(usize, usize)>,
    /// Table cells computed (the work budget's unit).
    pub work: u64,
    /// Width `u` of the last band that ran to completion (0 when none;
    /// `n1 + n2` after the unbanded run).
    pub band: usize,
    /// Most bytes of tables held at once, never above
    /// [`TedOptions::max_bytes`].
    pub peak_bytes: u64,
    /// When not exact: the budget that ended the computation (`None` when
    /// exact).
    pub stopped_by: Option<TedStop>,
}

impl TedResult {
    pub fn exact(&self) -> bool {
        self.lower >= self.upper
    }
}

/// The ordered tree edit distance of `a` and `b` with unit costs.
pub fn ted(a: &LabelledTree, b: &LabelledTree, opts: &TedOptions) -> TedResult {
    let (f, g) = oriented(a, b);
    let (n1, n2) = (f.len(), g.len());
    if n1 == 0 || n2 == 0 {
        let d = (n1 + n2) as u64;
        return TedResult {
            lower: d,
            upper: d,
            mapping: Vec::new(),
            work: 0,
            band: 0,
            peak_bytes: 0,
            stopped_by: None,
        };
    }
    let mut pr = Progress {
        lower: n1.abs_diff(n2) as u64,
        best: first_mapping(a, b, &f, &g),
        work: 0,
        peak: 0,
        stopped: None,
    };
    // The label sequences' bounds (`bounds.rs`): a lower bound that often
    // meets the upper one on a tree and its edited copy, and a mapping that
    // is often better than the greedy one; skipped when they do not fit
    // the budgets.
    if bounds::work(n1, n2) <= opts.max_work && 4 * bounds::cells(n1, n2) <= opts.max_bytes {
        pr.sequence_bounds(&f, &g);
        if pr.lower >= pr.best.0 {
            return pr.finish(0);
        }
    }
    band_search(&f, &g, opts, pr)
}

/// Both trees in the orientation with fewer cells (as drawn or mirrored):
/// same distance, mirrored mapping.
fn oriented(a: &LabelledTree, b: &LabelledTree) -> (OrderedTree, OrderedTree) {
    let (fa, fb) = (
        OrderedTree::build(&a.children, &a.labels, a.root, false),
        OrderedTree::build(&b.children, &b.labels, b.root, false),
    );
    let (ma, mb) = (
        OrderedTree::build(&a.children, &a.labels, a.root, true),
        OrderedTree::build(&b.children, &b.labels, b.root, true),
    );
    let weight = |x: &OrderedTree, y: &OrderedTree| {
        u128::from(x.keyroot_weight()) * u128::from(y.keyroot_weight())
    };
    let mirrored = weight(&ma, &mb) < weight(&fa, &fb);
    if mirrored { (ma, mb) } else { (fa, fb) }
}

/// Postorder pairs of `f` and `g` as sorted arena pairs.
fn to_arena(f: &OrderedTree, g: &OrderedTree, pairs: Vec<(usize, usize)>) -> Vec<(usize, usize)> {
    let mut m: Vec<(usize, usize)> = pairs
        .into_iter()
        .map(|(x, y)| (f.arena[x], g.arena[y]))
        .collect();
    m.sort_unstable();
    m
}

/// The better of two mappings always available (non-empty trees): the
/// roots to each other, and the top-down alignment of `greedy.rs`.
fn first_mapping(
    a: &LabelledTree,
    b: &LabelledTree,
    f: &OrderedTree,
    g: &OrderedTree,
) -> (u64, Vec<(usize, usize)>) {
    let (n1, n2) = (f.len(), g.len());
    let root_cost = (n1 + n2 - 2) as u64 + u64::from(f.label[n1 - 1] != g.label[n2 - 1]);
    let (gm, gcost) = greedy::greedy_mapping(a, b);
    if gcost < root_cost {
        (gcost, gm)
    } else {
        (root_cost, vec![(f.arena[n1 - 1], g.arena[n2 - 1])])
    }
}

/// What a computation has established so far.
struct Progress {
    /// Lower bound on the distance.
    lower: u64,
    /// The best mapping known (arena pairs) and its cost.
    best: (u64, Vec<(usize, usize)>),
    /// Table cells computed.
    work: u64,
    /// Most bytes of tables held at once.
    peak: u64,
    /// The budget that refused the last step, if one did.
    stopped: Option<TedStop>,
}

impl Progress {
    /// Takes in the label sequences' lower bound and mapping.
    fn sequence_bounds(&mut self, f: &OrderedTree, g: &OrderedTree) {
        let sb = bounds::sequence_bounds(f, g);
        self.work += sb.work;
        self.peak = self.peak.max(4 * sb.peak);
        self.lower = self.lower.max(sb.lower);
        if sb.upper < self.best.0 {
            self.best = (sb.upper, to_arena(f, g, sb.mapping));
        }
    }

    /// The interval `[lower, best]` with the best mapping, `band` the width
    /// of the last band that ran to completion.
    fn finish(self, band: usize) -> TedResult {
        let (upper, mapping) = self.best;
        let lower = self.lower.min(upper);
        TedResult {
            lower,
            upper,
            mapping,
            work: self.work,
            band,
            peak_bytes: self.peak,
            stopped_by: if lower < upper { self.stopped } else { None },
        }
    }

    /// The exact distance `d` with a mapping of that cost (postorder pairs).
    fn exact(
        self,
        f: &OrderedTree,
        g: &OrderedTree,
        d: u64,
        m: Vec<(usize, usize)>,
        band: usize,
    ) -> TedResult {
        TedResult {
            lower: d,
            upper: d,
            mapping: to_arena(f, g, m),
            work: self.work,
            band,
            peak_bytes: self.peak,
            stopped_by: None,
        }
    }
}

/// The width of the next band from the planned `u`: the best mapping's cost
/// once `u` comes close to it, and the full width `full` once the band would
/// cost about as much as Zhang–Shasha's whole tables (`full_cells`), judged
/// from the width and work of the last band run.
fn band_width(
    mut u: usize,
    best: u64,
    last: Option<(usize, u64)>,
    full_cells: u128,
    full: usize,
) -> usize {
    // A band as wide as a known mapping's cost holds that mapping, so
    // its result is exact: jump there once the growth comes close.
    let ub = usize::try_from(best).unwrap_or(usize::MAX);
    if u.saturating_mul(3) >= ub.saturating_mul(2) {
        u = ub;
    }
    // Once a band would cost about as much as Zhang–Shasha's whole
    // tables (the product of the keyroot weights), run those instead.
    if let Some((pu, pw)) = last {
        let grow = (u as f64 / pu as f64).powi(3);
        if pw as f64 * grow >= full_cells as f64 {
            u = full;
        }
    }
    u.min(full)
}

/// Zhang & Shasha's whole tables (`dense.rs`), when their cells (known in
/// advance) fit the work left and their bytes the memory budget: the exact
/// distance; otherwise the interval so far, with the budget that refused.
fn unbanded(
    f: &OrderedTree,
    g: &OrderedTree,
    opts: &TedOptions,
    mut pr: Progress,
    band: usize,
) -> TedResult {
    if dense::memory_bytes(f, g) > opts.max_bytes {
        pr.stopped = Some(TedStop::Memory);
        return pr.finish(band);
    }
    if dense::work(f, g) > u128::from(opts.max_work.saturating_sub(pr.work)) {
        pr.stopped = Some(TedStop::Work);
        return pr.finish(band);
    }
    pr.peak = pr.peak.max(dense::memory_bytes(f, g));
    let (d, m, work) = if dense::cell_bytes(f.len(), g.len()) == 2 {
        run_dense::<u16>(f, g)
    } else {
        run_dense::<u32>(f, g)
    };
    pr.work += work;
    pr.exact(f, g, d, m, f.len() + g.len())
}

/// The distance, an optimal mapping and the cells computed, unbanded.
fn run_dense<T: dense::Cell>(f: &OrderedTree, g: &OrderedTree) -> (u64, Vec<(usize, usize)>, u64) {
    let mut d = dense::Dense::<T>::new(f, g);
    d.run();
    let dist = d.distance() as u64;
    let m = d.mapping();
    (dist, m, d.work)
}

/// Zhang & Shasha in ever wider bands, from the lower bound, until a band's
/// result is at most its width (exact), or unbanded once a band would cost
/// as much, or until a budget is spent (an interval).
fn band_search(f: &OrderedTree, g: &OrderedTree, opts: &TedOptions, mut pr: Progress) -> TedResult {
    let (n1, n2) = (f.len(), g.len());
    // No mapping costs more than n1 + n2: a band this wide prunes nothing.
    let full = n1 + n2;
    let mut done_band = 0;
    // A band narrower than the lower bound cannot prove the distance.
    let mut u = n1
        .abs_diff(n2)
        .max(2)
        .max(usize::try_from(pr.lower).unwrap_or(usize::MAX));
    let full_cells = dense::work(f, g);
    // The width and work of the last band run.
    let mut last: Option<(usize, u64)> = None;
    loop {
        u = band_width(u, pr.best.0, last, full_cells, full);
        let bytes = 4 * Banded::memory_cells(f, g, u);
        let most = Banded::cells_at_most(f, g, u);
        // A band that may not fit the work left is not started (it would
        // spend the budget and end as an interval anyway): the unbanded run
        // knows its cost and stops at once when that does not fit either.
        let left = u128::from(opts.max_work.saturating_sub(pr.work));
        if u == full || most >= full_cells || most > left || bytes > opts.max_bytes {
            return unbanded(f, g, opts, pr, done_band);
        }
        let mut band = Banded::new(f, g, u);
        let ran = band.run(opts.max_work.saturating_sub(pr.work));
        pr.work += band.work;
        pr.peak = pr.peak.max(4 * band.peak);
        last = Some((u.max(1), band.work.max(1)));
        if ran.is_err() {
            pr.stopped = Some(TedStop::Work);
            break;
        }
        done_band = u;
        let r = u64::from(band.distance());
        if r <= u as u64 {
            band.work = 0;
            let m = mapping::mapping(&mut band);
            pr.work += band.work;
            pr.peak = pr.peak.max(4 * band.peak);
            return pr.exact(f, g, r, m, u);
        }
        // The distance is above u; r, if finite, is a mapping's cost.
        pr.lower = pr.lower.max(u as u64 + 1);
        if r < pr.best.0 {
            band.work = 0;
            let m = mapping::mapping(&mut band);
            pr.work += band.work;
            pr.peak = pr.peak.max(4 * band.peak);
            pr.best = (r, to_arena(f, g, m));
        }
        // Grow by half: the work grows as about u³, so overshooting the
        // distance by up to 1.5× costs less than doubling's 2×.
        u = u.saturating_add(u.div_ceil(2));
    }
    pr.finish(done_band)
}
