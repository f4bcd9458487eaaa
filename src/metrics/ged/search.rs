//! Exact GED by depth-first branch and bound over the padded instance of
//! `problem.rs`, with an assignment lower bound at every node.
//!
//! The bound follows the branch-match bound of Chang, Feng, Lin, Qin, Zhang
//! and Zhou ("Speeding Up GED Verification for Graph Similarity Search",
//! ICDE 2020; "Accelerating Graph Similarity Search via Efficient GED
//! Computation", TKDE 2022), adapted to directed multigraphs with self-loops.
//! At a node with partial mapping f (cost g on the pairs it fixes), a
//! completion σ costs g plus, for each unmapped u,
//!   (a) Σ_{w mapped} |A(u,w) − B(σu, f w)| + |A(w,u) − B(f w, σu)|  — exact,
//!   (b) |A(u,u) − B(σu,σu)|                                         — exact,
//!   (c) half of Σ_{w unmapped} |A(u,w) − B(σu,σw)| + |A(w,u) − B(σw,σu)|,
//! since each unmapped–unmapped pair is seen from both ends. For (c) the sum
//! over w of |a_w − b_{σw}| is at least the sorted-matching distance of the
//! two multisets of multiplicities, which for non-negative integers is
//! Σ_t |#{a ≥ t} − #{b ≥ t}|; we keep the layers t = 1, 2, 3 and the mass
//! above 3 (a valid relaxation) for out- and in-arcs separately. A linear
//! assignment (`lsap.rs`) of these local costs, class by class, is the lower
//! bound; its optimal assignment is also a complete mapping, hence an upper
//! bound, polished by 2-swaps (`local.rs`). The assignment's duals bound each
//! child (`total + reduced cost`) so that children are ordered and discarded
//! without being solved. All bounds are rounded up to the parity every
//! mapping's cost has (vertex cost + m1 + m2, mod 2).
//!
//! (a) is maintained incrementally: with |x − y| = x + y − 2 min(x, y),
//! (a) = row[u] + col[v] − 2 pair[u][v], where row/col count arcs to the
//! mapped/used part and pair accumulates the minima, updated only along the
//! arcs of the newly mapped pair.
//!
//! The branching vertex is the unmapped real G1 vertex with the fewest
//! children surviving the bound (fail first), ties to the most arcs towards
//! the mapped part. G2 dummies of a class are interchangeable, so only one is
//! ever a child. When the time budget or the expansion budget runs out, the
//! certified lower bound is the smallest bound among the subtrees still open
//! on the stack.

use std::time::Instant;

use super::embed::{self, Embedding};
use super::local;
use super::lsap::{Assignment, Lsap};
use super::problem::{NONE, Problem};

/// Above this padded size the exact search is not attempted (the pair table
/// is n² words); the result is then the count bound and a local-search upper
/// bound.
const MAX_SEARCH_N: usize = 2048;
/// Candidate tries allowed to the embedding fast path.
const EMBED_BUDGET: u64 = 200_000;

/// Budgets for one GED computation.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Limits {
    pub deadline: Instant,
    pub max_expansions: u64,
}

/// A certified interval and the best mapping found.
#[derive(Debug, Clone)]
pub(crate) struct Outcome {
    pub lower: u64,
    pub upper: u64,
    /// Padded G1 → padded G2 bijection of cost `upper`.
    pub sigma: Vec<u32>,
}

type Layers = [u32; 4];

#[inline]
fn layer_add(l: &mut Layers, m: u32) {
    l[0] += u32::from(m >= 1);
    l[1] += u32::from(m >= 2);
    l[2] += u32::from(m >= 3);
    l[3] += m.saturating_sub(3);
}

#[inline]
fn layer_sub(l: &mut Layers, m: u32) {
    l[0] -= u32::from(m >= 1);
    l[1] -= u32::from(m >= 2);
    l[2] -= u32::from(m >= 3);
    l[3] -= m.saturating_sub(3);
}

#[inline]
fn layer_dist(a: &Layers, b: &Layers) -> i64 {
    (0..4).map(|t| i64::from(a[t].abs_diff(b[t]))).sum()
}

/// One open node of the depth-first search.
struct Frame {
    /// Branching vertex of G1.
    u: u32,
    /// `(bound, image)` for each surviving child, sorted.
    children: Vec<(u64, u32)>,
    /// Child being explored (or next to explore).
    cur: usize,
    /// The mapping step that led here, to undo on leaving: (w, x, Δg).
    via: Option<(u32, u32, u64)>,
}

enum Eval {
    Prune,
    Branch(Frame),
    Timeout,
}

/// Per-class data of the assignment solved at a node.
struct ClassLsap {
    rows: Vec<u32>,
    cols: Vec<u32>,
    cost: Vec<i64>,
    sol: Assignment,
}

struct Bnb<'a> {
    p: &'a Problem,
    n: usize,
    f: Vec<u32>,
    used: Vec<bool>,
    g: u64,
    row: Vec<u64>,
    col: Vec<u64>,
    pair: Vec<u32>,
    out1: Vec<Layers>,
    in1: Vec<Layers>,
    out2: Vec<Layers>,
    in2: Vec<Layers>,
    ub: u64,
    best: Vec<u32>,
    parity: u64,
    lsap: Lsap,
    lim: Limits,
    expansions: u64,
}

impl<'a> Bnb<'a> {
    fn new(p: &'a Problem, ub: u64, best: Vec<u32>, lim: Limits) -> Bnb<'a> {
        let n = p.n();
        let layers = |lists: &Vec<Vec<(u32, u32)>>| -> Vec<Layers> {
            lists
                .iter()
                .map(|l| {
                    let mut x = [0u32; 4];
                    for &(_, m) in l {
                        layer_add(&mut x, m);
                    }
                    x
                })
                .collect()
        };
        Bnb {
            p,
            n,
            f: vec![NONE; n],
            used: vec![false; n],
            g: 0,
            row: vec![0; n],
            col: vec![0; n],
            pair: vec![0; n * n],
            out1: layers(&p.s1.out),
            in1: layers(&p.s1.inn),
            out2: layers(&p.s2.out),
            in2: layers(&p.s2.inn),
            ub,
            best,
            parity: (p.vertex_cost + p.s1.arcs + p.s2.arcs) % 2,
            lsap: Lsap::default(),
            lim,
            expansions: 0,
        }
    }

    /// Rounds a lower bound up to the parity every mapping cost has.
    fn round(&self, lb: u64) -> u64 {
        if lb % 2 == self.parity { lb } else { lb + 1 }
    }

    /// Maps `w` to `x`; returns the cost added to `g`.
    fn map(&mut self, w: u32, x: u32) -> u64 {
        let (p, n) = (self.p, self.n);
        let (wu, xu) = (w as usize, x as usize);
        let dg = self.row[wu] + self.col[xu] - 2 * u64::from(self.pair[wu * n + xu])
            + u64::from(p.s1.loops[wu].abs_diff(p.s2.loops[xu]));
        self.g += dg;
        for &(u, a) in &p.s1.out[wu] {
            self.row[u as usize] += u64::from(a);
            layer_sub(&mut self.in1[u as usize], a);
        }
        for &(u, a) in &p.s1.inn[wu] {
            self.row[u as usize] += u64::from(a);
            layer_sub(&mut self.out1[u as usize], a);
        }
        for &(v, b) in &p.s2.out[xu] {
            self.col[v as usize] += u64::from(b);
            layer_sub(&mut self.in2[v as usize], b);
        }
        for &(v, b) in &p.s2.inn[xu] {
            self.col[v as usize] += u64::from(b);
            layer_sub(&mut self.out2[v as usize], b);
        }
        for &(u, a) in &p.s1.inn[wu] {
            for &(v, b) in &p.s2.inn[xu] {
                self.pair[u as usize * n + v as usize] += a.min(b);
            }
        }
        for &(u, a) in &p.s1.out[wu] {
            for &(v, b) in &p.s2.out[xu] {
                self.pair[u as usize * n + v as usize] += a.min(b);
            }
        }
        self.f[wu] = x;
        self.used[xu] = true;
        dg
    }

    /// Exactly undoes `map(w, x)` that returned `dg`.
    fn unmap(&mut self, w: u32, x: u32, dg: u64) {
        let (p, n) = (self.p, self.n);
        let (wu, xu) = (w as usize, x as usize);
        self.f[wu] = NONE;
        self.used[xu] = false;
        for &(u, a) in &p.s1.out[wu] {
            for &(v, b) in &p.s2.out[xu] {
                self.pair[u as usize * n + v as usize] -= a.min(b);
            }
        }
        for &(u, a) in &p.s1.inn[wu] {
            for &(v, b) in &p.s2.inn[xu] {
                self.pair[u as usize * n + v as usize] -= a.min(b);
            }
        }
        for &(v, b) in &p.s2.inn[xu] {
            self.col[v as usize] -= u64::from(b);
            layer_add(&mut self.out2[v as usize], b);
        }
        for &(v, b) in &p.s2.out[xu] {
            self.col[v as usize] -= u64::from(b);
            layer_add(&mut self.in2[v as usize], b);
        }
        for &(u, a) in &p.s1.inn[wu] {
            self.row[u as usize] -= u64::from(a);
            layer_add(&mut self.out1[u as usize], a);
        }
        for &(u, a) in &p.s1.out[wu] {
            self.row[u as usize] -= u64::from(a);
            layer_add(&mut self.in1[u as usize], a);
        }
        self.g -= dg;
    }

    /// Doubled local cost of mapping unmapped `u` onto unused `v`.
    #[inline]
    fn local_cost(&self, u: usize, v: usize) -> i64 {
        let p = self.p;
        let a = self.row[u] as i64 + self.col[v] as i64 - 2 * i64::from(self.pair[u * self.n + v]);
        let lp = i64::from(p.s1.loops[u].abs_diff(p.s2.loops[v]));
        2 * (a + lp)
            + layer_dist(&self.out1[u], &self.out2[v])
            + layer_dist(&self.in1[u], &self.in2[v])
    }

    /// Offers a complete mapping as an upper bound, polishing it when it wins.
    fn offer(&mut self, mut sigma: Vec<u32>) {
        let c = self.p.cost(&sigma);
        if c < self.ub {
            local::two_swap(self.p, &mut sigma, self.lim.deadline);
            self.ub = self.p.cost(&sigma);
            self.best = sigma;
        }
    }

    /// Bounds the current node and, unless it can be discarded, lists its children.
    fn eval(&mut self, parent_lb: u64) -> Eval {
        let p = self.p;
        let mut classes: Vec<ClassLsap> = Vec::new();
        let mut total = 0i64;
        for &(s, e) in &p.classes {
            let rows: Vec<u32> = (s..e)
                .filter(|&u| self.f[u] == NONE)
                .map(|u| u as u32)
                .collect();
            if rows.is_empty() {
                continue;
            }
            let cols: Vec<u32> = (s..e)
                .filter(|&v| !self.used[v])
                .map(|v| v as u32)
                .collect();
            let k = rows.len();
            if cols.len() != k {
                return Eval::Timeout; // cannot happen: classes are balanced
            }
            let mut cost = Vec::with_capacity(k * k);
            for &u in &rows {
                for &v in &cols {
                    cost.push(self.local_cost(u as usize, v as usize));
                }
            }
            let Some(sol) = self.lsap.solve(k, &cost, self.lim.deadline) else {
                return Eval::Timeout;
            };
            total += sol.total;
            classes.push(ClassLsap {
                rows,
                cols,
                cost,
                sol,
            });
        }
        let half = |t: i64| (t.max(0) as u64).div_ceil(2);
        let lb = self.round(parent_lb.max(self.g + half(total)));
        if lb >= self.ub {
            return Eval::Prune;
        }
        // The assignment completes the partial mapping: an upper bound.
        let mut sigma = self.f.clone();
        for c in &classes {
            for (i, &u) in c.rows.iter().enumerate() {
                sigma[u as usize] = c.cols[c.sol.col_of_row[i]];
            }
        }
        self.offer(sigma);
        if lb >= self.ub {
            return Eval::Prune;
        }
        // Fail-first choice of the branching vertex among real rows.
        let mut choice: Option<(usize, usize)> = None; // (class idx, row idx)
        let mut key = (usize::MAX, 0u64, 0u64);
        for (ci, c) in classes.iter().enumerate() {
            let k = c.rows.len();
            for (i, &u) in c.rows.iter().enumerate() {
                if p.s1.is_dummy(u) {
                    continue;
                }
                let mut viable = 0usize;
                let mut dummy_seen = false;
                for (j, &v) in c.cols.iter().enumerate() {
                    if p.s2.is_dummy(v) {
                        if dummy_seen {
                            continue;
                        }
                        dummy_seen = true;
                    }
                    let est = self.g + half(total + c.sol.reduced(&c.cost, k, i, j));
                    if self.round(est) < self.ub {
                        viable += 1;
                    }
                }
                let uu = u as usize;
                let cand = (viable, self.row[uu], p.s1.degree(uu));
                let better = choice.is_none()
                    || cand.0 < key.0
                    || (cand.0 == key.0 && (cand.1, cand.2) > (key.1, key.2));
                if better {
                    choice = Some((ci, i));
                    key = cand;
                }
            }
        }
        let Some((ci, i)) = choice else {
            // Only dummies left: the assignment was exact and has been offered.
            return Eval::Prune;
        };
        if key.0 == 0 {
            return Eval::Prune;
        }
        let c = &classes[ci];
        let k = c.rows.len();
        let mut children = Vec::with_capacity(key.0);
        let mut dummy_seen = false;
        for (j, &v) in c.cols.iter().enumerate() {
            if p.s2.is_dummy(v) {
                if dummy_seen {
                    continue;
                }
                dummy_seen = true;
            }
            let est = self.round(lb.max(self.g + half(total + c.sol.reduced(&c.cost, k, i, j))));
            if est < self.ub {
                children.push((est, v));
            }
        }
        children.sort_unstable();
        Eval::Branch(Frame {
            u: c.rows[i],
            children,
            cur: 0,
            via: None,
        })
    }

    /// Runs the search from the root; returns the certified lower bound.
    fn run(&mut self, root_lb: u64) -> u64 {
        let mut stack: Vec<Frame> = Vec::new();
        match self.eval(root_lb) {
            Eval::Prune => return self.ub,
            Eval::Timeout => return root_lb.min(self.ub),
            Eval::Branch(fr) => stack.push(fr),
        }
        let mut timed_out = false;
        while let Some(top) = stack.last() {
            let exhausted = top.cur >= top.children.len() || top.children[top.cur].0 >= self.ub;
            if exhausted {
                if let Some(fr) = stack.pop()
                    && let Some((w, x, dg)) = fr.via
                {
                    self.unmap(w, x, dg);
                }
                if let Some(parent) = stack.last_mut() {
                    parent.cur += 1;
                }
                continue;
            }
            let (est, v) = top.children[top.cur];
            let u = top.u;
            self.expansions += 1;
            if self.expansions > self.lim.max_expansions || Instant::now() > self.lim.deadline {
                timed_out = true;
                break;
            }
            let dg = self.map(u, v);
            match self.eval(est) {
                Eval::Branch(mut fr) => {
                    fr.via = Some((u, v, dg));
                    stack.push(fr);
                }
                Eval::Prune => {
                    self.unmap(u, v, dg);
                    if let Some(top) = stack.last_mut() {
                        top.cur += 1;
                    }
                }
                Eval::Timeout => {
                    self.unmap(u, v, dg);
                    timed_out = true;
                    break;
                }
            }
        }
        if !timed_out {
            return self.ub;
        }
        let open = stack
            .iter()
            .filter_map(|fr| fr.children.get(fr.cur).map(|&(est, _)| est))
            .min()
            .unwrap_or(self.ub);
        self.round(open.max(root_lb)).min(self.ub)
    }
}

/// Computes GED on a padded instance within the limits.
pub(crate) fn solve(p: &Problem, lim: &Limits) -> Outcome {
    let count = p.count_bound();
    let mut best = p.greedy();
    let mut ub = p.cost(&best);
    let done = |lower: u64, upper: u64, sigma: Vec<u32>| Outcome {
        lower,
        upper,
        sigma,
    };
    if ub == count {
        return done(ub, ub, best);
    }
    let now = Instant::now();
    let embed_deadline = now + lim.deadline.saturating_duration_since(now) / 4;
    let mut lb = count;
    match embed::find(p, embed_deadline, EMBED_BUDGET) {
        Embedding::Found(sigma) => return done(count, count, sigma),
        Embedding::Absent => lb = count + 2,
        Embedding::Unknown => {}
    }
    local::two_swap(p, &mut best, lim.deadline);
    ub = p.cost(&best);
    if lb >= ub {
        return done(ub, ub, best);
    }
    if p.n() > MAX_SEARCH_N {
        return done(lb, ub, best);
    }
    let mut bnb = Bnb::new(p, ub, best, *lim);
    let lower = bnb.run(lb);
    done(lower, bnb.ub, bnb.best)
}
