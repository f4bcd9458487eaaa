//! A Lagrangian lower bound for the branch and bound of `search.rs` on
//! graphs that are not forests, tightened by dual ascent at every node.
//!
//! **Relaxation.** GED = vertex cost + m1 + m2 − 2·P, P the preserved arc
//! multiplicity (`problem.rs`). Write y\[k, l\] = 1 when G1's arc k = (u, w)
//! is mapped onto G2's arc l = (v, z), worth p = min(A(u,w), B(v,z)). Under
//! a bijection with σu = v, u's out-arcs meet v's out-arcs in a matching
//! (each arc has one image), and likewise u's in-arcs meet v's in-arcs.
//! So y\[k, l\] is counted twice: once in the *tail view* of the pair
//! (u, v), a matching of out-arcs, and once in the *head view* of (w, z), a
//! matching of in-arcs. Give the tail view a share α\[k, l\] of p and the head
//! view p − α\[k, l\]: for **any** α, P ≤ max over bijections σ of
//! Σ_u MT(u, σu) + MH(u, σu), where MT (MH) is the best matching of the
//! tail (head) view under its share. That is a linear assignment of local
//! values, as in the branch-match bound of `search.rs` (which is α = p/2
//! with sorted multiplicities), and its minimum over α is the bound of the
//! linear relaxation with both views' matching constraints — the
//! first-level reformulation–linearisation (RLT1) of Adams & Johnson ("Improved
//! linear programming-based lower bounds for the quadratic assignment
//! problem", DIMACS 16, 1994) restricted to arcs. On the FSM-like pairs of
//! `bench/ged_vs_highs.py` that relaxation was measured (with HiGHS) at 5–15
//! units above the plain LP of the F2 formulation.
//!
//! **Ascent.** α is improved in the manner of Hahn & Grant's dual procedure
//! for the QAP ("Lower bounds for the quadratic assignment problem based
//! upon a dual formulation", Operations Research 46, 1998): every local
//! matching's dual gives each entry a slack (how far its share may grow
//! without raising the matching's value), the outer assignment's reduced
//! cost at (u, v) is spread over the rows of (u, v)'s two views, and each
//! entry's share moves to the view with more room, by half the difference.
//! Each move stays within the receiving view's room and only lowers the
//! other, so the old outer duals stay feasible: the bound never decreases.
//!
//! Any α gives a valid bound, so α is global, carried from node to node
//! (a node that re-optimises it for its subproblem puts it back on leaving:
//! [`Ascent::snapshot`], [`Ascent::restore`]);
//! integer arithmetic (shares in units of 1/`S`) keeps it exact.

use super::problem::{NONE, Problem};

/// Above this many (G1 arc, G2 arc) entries, or this many padded
/// vertices, the ascent is not used: its tables hold 8 bytes per vertex
/// pair and 28 per entry (at most 0.5 MB and 14.7 MB).
pub(crate) const MAX_ENTRIES: usize = 1 << 19;
pub(crate) const MAX_N: usize = 256;

/// Whether the ascent is used on `p` (see [`MAX_ENTRIES`]).
pub(crate) fn fits(p: &Problem) -> bool {
    let (m1, m2) = (p.s1.out.total(), p.s2.out.total());
    p.n() <= MAX_N && m1 > 0 && m2 > 0 && m1.saturating_mul(m2) <= MAX_ENTRIES
}
/// Share units per unit of preserved multiplicity.
pub(crate) const S: i64 = 64;

/// Arcs of one side (self-loops excluded), numbered in out-list order.
struct Arcs {
    tail: Vec<u32>,
    head: Vec<u32>,
    mult: Vec<u32>,
    /// Arc ids of each vertex's out-arcs: `out_ids[out_start[u]..out_start[u + 1]]`.
    out_start: Vec<usize>,
    /// Arc ids of each vertex's in-arcs, in the same layout.
    in_start: Vec<usize>,
    in_ids: Vec<u32>,
}

impl Arcs {
    fn new(s: &super::problem::Side) -> Arcs {
        let n = s.n;
        let (mut tail, mut head, mut mult) = (Vec::new(), Vec::new(), Vec::new());
        let mut out_start = Vec::with_capacity(n + 1);
        for u in 0..n {
            out_start.push(tail.len());
            debug_assert_eq!(s.out.first(u), tail.len());
            for &(w, m) in &s.out[u] {
                tail.push(u as u32);
                head.push(w);
                mult.push(m);
            }
        }
        out_start.push(tail.len());
        let mut in_start = Vec::with_capacity(n + 1);
        let mut in_ids = Vec::with_capacity(tail.len());
        for w in 0..n {
            in_start.push(in_ids.len());
            for &(u, _) in &s.inn[w] {
                let list = &s.out[u as usize];
                let i = list.partition_point(|&(h, _)| h < w as u32);
                in_ids.push((out_start[u as usize] + i) as u32);
            }
        }
        in_start.push(in_ids.len());
        Arcs {
            tail,
            head,
            mult,
            out_start,
            in_start,
            in_ids,
        }
    }

    fn len(&self) -> usize {
        self.tail.len()
    }

    fn outs(&self, u: usize) -> std::ops::Range<u32> {
        self.out_start[u] as u32..self.out_start[u + 1] as u32
    }

    fn ins(&self, u: usize) -> &[u32] {
        &self.in_ids[self.in_start[u]..self.in_start[u + 1]]
    }
}

/// Dense min-cost assignment with potentials, for the small local matchings
/// (Kuhn–Munkres in the shortest-augmenting-path form, O(k³)).
#[derive(Default)]
struct Hungarian {
    u: Vec<i64>,
    v: Vec<i64>,
    p: Vec<usize>,
    way: Vec<usize>,
    minv: Vec<i64>,
    done: Vec<bool>,
}

impl Hungarian {
    /// Solves the `k × k` problem `a`; afterwards `a[i][j] − u[i+1] − v[j+1]
    /// ≥ 0` and the optimum is Σu + Σv. Returns the optimum.
    fn solve(&mut self, k: usize, a: &[i64]) -> i64 {
        const INF: i64 = i64::MAX / 4;
        for b in [&mut self.u, &mut self.v, &mut self.minv] {
            b.clear();
            b.resize(k + 1, 0);
        }
        for b in [&mut self.p, &mut self.way] {
            b.clear();
            b.resize(k + 1, 0);
        }
        for i in 1..=k {
            self.p[0] = i;
            let mut j0 = 0usize;
            self.minv.iter_mut().for_each(|x| *x = INF);
            self.done.clear();
            self.done.resize(k + 1, false);
            loop {
                self.done[j0] = true;
                let i0 = self.p[j0];
                let mut delta = INF;
                let mut j1 = 0usize;
                let row = &a[(i0 - 1) * k..i0 * k];
                for j in 1..=k {
                    if !self.done[j] {
                        let cur = row[j - 1] - self.u[i0] - self.v[j];
                        if cur < self.minv[j] {
                            self.minv[j] = cur;
                            self.way[j] = j0;
                        }
                        if self.minv[j] < delta {
                            delta = self.minv[j];
                            j1 = j;
                        }
                    }
                }
                for j in 0..=k {
                    if self.done[j] {
                        self.u[self.p[j]] += delta;
                        self.v[j] -= delta;
                    } else {
                        self.minv[j] -= delta;
                    }
                }
                j0 = j1;
                if self.p[j0] == 0 {
                    break;
                }
            }
            loop {
                let j1 = self.way[j0];
                self.p[j0] = self.p[j1];
                j0 = j1;
                if j0 == 0 {
                    break;
                }
            }
        }
        -self.v[0]
    }
}

/// The shares α and the local matchings of the current node.
pub(crate) struct Ascent {
    n: usize,
    a1: Arcs,
    a2: Arcs,
    class_of: Vec<u32>,
    /// Tail share of each entry `k · m2 + l`, in units of 1/`S`.
    alpha: Vec<i64>,
    slack_t: Vec<i64>,
    slack_h: Vec<i64>,
    /// Epoch at which each entry's tail (head) slack was last computed.
    stamp_t: Vec<u32>,
    stamp_h: Vec<u32>,
    epoch: u32,
    /// MT + MH of each pair (u, v) at the current node (row-major).
    pub msum: Vec<i64>,
    /// Rows of (u, v)'s two views: arcs of u to unmapped vertices.
    rows: Vec<u32>,
    /// The current node's arcs among unmapped (G1) and unused (G2) vertices.
    t_rows: Vec<Vec<u32>>,
    h_rows: Vec<Vec<u32>>,
    t_cols: Vec<Vec<u32>>,
    h_cols: Vec<Vec<u32>>,
    hung: Hungarian,
    buf: Vec<i64>,
    /// Subgradient of the current outer solution: (entry, ±1) pairs.
    grad: Vec<(usize, i64)>,
    /// Once frozen (after the root), α no longer changes and `msum` is
    /// kept up to date pair by pair along the search ([`Ascent::apply`]).
    pub frozen: bool,
    /// Old values of the `msum` entries changed since each mark.
    trail: Vec<(usize, i64)>,
    marks: Vec<usize>,
    /// Scratch: vertices whose lists changed at the current step.
    touched: Vec<bool>,
    /// Work units spent since the last [`Ascent::take_work`].
    work: u64,
}

impl Ascent {
    /// The ascent for `p`, with α = `num`/2 of each entry's worth (`num` in
    /// 0..=2: the branch-match split), or `None` when `p` has too many entries.
    pub(super) fn new(p: &Problem, num: i64) -> Option<Ascent> {
        let (a1, a2) = (Arcs::new(&p.s1), Arcs::new(&p.s2));
        if !fits(p) {
            return None;
        }
        let entries = a1.len() * a2.len();
        let n = p.n();
        let mut alpha = vec![0i64; entries];
        for k in 0..a1.len() {
            for l in 0..a2.len() {
                let w = S * i64::from(a1.mult[k].min(a2.mult[l]));
                alpha[k * a2.len() + l] = w * num / 2;
            }
        }
        Some(Ascent {
            n,
            class_of: p.class_of.clone(),
            alpha,
            slack_t: vec![0; entries],
            slack_h: vec![0; entries],
            stamp_t: vec![0; entries],
            stamp_h: vec![0; entries],
            epoch: 0,
            msum: vec![0; n * n],
            rows: vec![0; n],
            t_rows: vec![Vec::new(); n],
            h_rows: vec![Vec::new(); n],
            t_cols: vec![Vec::new(); n],
            h_cols: vec![Vec::new(); n],
            a1,
            a2,
            hung: Hungarian::default(),
            buf: Vec::new(),
            grad: Vec::new(),
            frozen: false,
            trail: Vec::new(),
            marks: Vec::new(),
            touched: vec![false; n],
            work: 0,
        })
    }

    /// The shares (to keep the best seen and restore them).
    /// The shares and the local values, to put back with [`Ascent::restore`].
    pub(super) fn snapshot(&self) -> (Vec<i64>, Vec<i64>) {
        (self.alpha.clone(), self.msum.clone())
    }

    /// Bytes a [`Ascent::snapshot`] holds.
    pub(super) fn snapshot_bytes(&self) -> usize {
        (self.alpha.len() + self.msum.len()) * std::mem::size_of::<i64>()
    }

    pub(super) fn restore(&mut self, saved: &(Vec<i64>, Vec<i64>)) {
        self.alpha.copy_from_slice(&saved.0);
        self.msum.copy_from_slice(&saved.1);
    }

    pub(super) fn shares(&self) -> &[i64] {
        &self.alpha
    }

    /// Restores shares saved by [`Ascent::shares`].
    pub(super) fn set_shares(&mut self, alpha: &[i64]) {
        self.alpha.copy_from_slice(alpha);
    }

    /// Work units spent since the last call.
    pub(super) fn take_work(&mut self) -> u64 {
        std::mem::take(&mut self.work)
    }

    #[inline]
    fn worth(&self, k: u32, l: u32) -> i64 {
        S * i64::from(self.a1.mult[k as usize].min(self.a2.mult[l as usize]))
    }

    /// Computes `msum` for every unmapped u and unused v of one class, with
    /// the partial mapping `f` (G1 → G2, `NONE` if unmapped) and `used`.
    pub(super) fn evaluate(&mut self, p: &Problem, f: &[u32], used: &[bool]) {
        self.epoch = self.epoch.wrapping_add(1);
        if self.epoch == 0 {
            self.stamp_t.fill(0);
            self.stamp_h.fill(0);
            self.epoch = 1;
        }
        let n = self.n;
        for u in 0..n {
            self.rows_of(f, u);
            self.cols_of(used, u);
        }
        for &(s, e) in &p.classes {
            for u in (s..e).filter(|&u| f[u] == NONE) {
                for v in (s..e).filter(|&v| !used[v]) {
                    let mt = self.view(u, v, true, 0);
                    let mh = self.view(u, v, false, 0);
                    self.msum[u * n + v] = mt + mh;
                }
            }
        }
    }

    /// The entry of G1 arc `k` and G2 arc `l` in a tail view (`tail`) or a
    /// head view, if the arcs' other ends may map onto each other (same class).
    #[inline]
    fn entry(&self, tail: bool, k: u32, l: u32) -> Option<usize> {
        let (k, l) = (k as usize, l as usize);
        let (o1, o2) = if tail {
            (self.a1.head[k], self.a2.head[l])
        } else {
            (self.a1.tail[k], self.a2.tail[l])
        };
        (self.class_of[o1 as usize] == self.class_of[o2 as usize]).then_some(k * self.a2.len() + l)
    }

    /// The share of entry `e` (arcs `k`, `l`) in a tail view or a head view.
    #[inline]
    fn share(&self, tail: bool, k: u32, l: u32, e: usize) -> i64 {
        if tail {
            self.alpha[e]
        } else {
            self.worth(k, l) - self.alpha[e]
        }
    }

    /// Rebuilds the view rows of G1 vertex `u` (its arcs to unmapped vertices).
    fn rows_of(&mut self, f: &[u32], u: usize) {
        let (tr, hr) = (&mut self.t_rows[u], &mut self.h_rows[u]);
        tr.clear();
        hr.clear();
        if f[u] == NONE {
            let a = &self.a1;
            tr.extend(
                a.outs(u)
                    .filter(|&k| f[a.head[k as usize] as usize] == NONE),
            );
            hr.extend(
                a.ins(u)
                    .iter()
                    .copied()
                    .filter(|&k| f[a.tail[k as usize] as usize] == NONE),
            );
        }
        self.rows[u] = (tr.len() + hr.len()) as u32;
    }

    /// Rebuilds the view columns of G2 vertex `v` (its arcs to unused vertices).
    fn cols_of(&mut self, used: &[bool], v: usize) {
        let (tc, hc) = (&mut self.t_cols[v], &mut self.h_cols[v]);
        tc.clear();
        hc.clear();
        if !used[v] {
            let a = &self.a2;
            tc.extend(a.outs(v).filter(|&l| !used[a.head[l as usize] as usize]));
            hc.extend(
                a.ins(v)
                    .iter()
                    .copied()
                    .filter(|&l| !used[a.tail[l as usize] as usize]),
            );
        }
    }

    /// Neighbours of `u` on side 1 (`first`) or 2, `u` included.
    fn around(&self, first: bool, u: usize) -> Vec<usize> {
        let a = if first { &self.a1 } else { &self.a2 };
        let mut out: Vec<usize> = std::iter::once(u)
            .chain(a.outs(u).map(|k| a.head[k as usize] as usize))
            .chain(a.ins(u).iter().map(|&k| a.tail[k as usize] as usize))
            .collect();
        out.sort_unstable();
        out.dedup();
        out
    }

    /// After the search maps `w` onto `x` (`f`, `used` already updated):
    /// brings `msum` up to date, recomputing only the pairs whose views
    /// changed — those of `w`'s neighbours and of `x`'s — and remembers the
    /// old values for [`Ascent::undo`]. O((deg w + deg x) · n) views
    /// instead of n².
    pub(super) fn apply(&mut self, p: &Problem, f: &[u32], used: &[bool], w: usize, x: usize) {
        self.marks.push(self.trail.len());
        let n = self.n;
        let near1 = self.around(true, w);
        let near2 = self.around(false, x);
        for &u in &near1 {
            self.rows_of(f, u);
        }
        for &v in &near2 {
            self.cols_of(used, v);
        }
        for &u in &near1 {
            if f[u] != NONE {
                continue;
            }
            self.touched[u] = true;
            let (s, e) = p.classes[p.class_of[u] as usize];
            for v in (s..e).filter(|&v| !used[v]) {
                self.refresh(u, v);
            }
        }
        for &v in &near2 {
            if used[v] {
                continue;
            }
            let (s, e) = p.classes[p.class_of[v] as usize];
            for u in (s..e).filter(|&u| f[u] == NONE) {
                if !self.touched[u] {
                    self.refresh(u, v);
                }
            }
        }
        for &u in &near1 {
            self.touched[u] = false;
        }
        debug_assert!(n == f.len());
    }

    /// Undoes the last [`Ascent::apply`] of `w` onto `x`, after the search
    /// has restored `f` and `used`.
    pub(super) fn undo(&mut self, f: &[u32], used: &[bool], w: usize, x: usize) {
        for u in self.around(true, w) {
            self.rows_of(f, u);
        }
        for v in self.around(false, x) {
            self.cols_of(used, v);
        }
        let mark = self.marks.pop().unwrap_or(0);
        while self.trail.len() > mark {
            if let Some((i, old)) = self.trail.pop() {
                self.msum[i] = old;
            }
        }
    }

    /// Whether the incrementally kept `msum` equals a full evaluation at
    /// this node (a check for debug builds; leaves the state as it found it).
    #[cfg(debug_assertions)]
    pub(super) fn consistent(&mut self, p: &Problem, f: &[u32], used: &[bool]) -> bool {
        let kept = self.msum.clone();
        self.evaluate(p, f, used);
        self.work = 0;
        let n = self.n;
        let ok = (0..n * n).all(|i| f[i / n] != NONE || used[i % n] || self.msum[i] == kept[i]);
        self.msum = kept;
        ok
    }

    fn refresh(&mut self, u: usize, v: usize) {
        let i = u * self.n + v;
        self.trail.push((i, self.msum[i]));
        self.msum[i] = self.view(u, v, true, 0) + self.view(u, v, false, 0);
    }

    /// The best matching of (u, v)'s tail view (`tail`) or head view under
    /// the current shares; records each entry's slack.
    /// With `sign` ≠ 0, also records `(entry, sign)` for each entry of the
    /// optimal matching in `grad`.
    fn view(&mut self, u: usize, v: usize, tail: bool, sign: i64) -> i64 {
        let m2 = self.a2.len();
        let (rows, cols) = if tail {
            (&self.t_rows[u], &self.t_cols[v])
        } else {
            (&self.h_rows[u], &self.h_cols[v])
        };
        if rows.is_empty() || cols.is_empty() {
            return 0;
        }
        let (r, c) = (rows.len(), cols.len());
        let k = r.max(c);
        self.buf.clear();
        self.buf.resize(k * k, 0);
        let mut any = false;
        for (i, &ka) in rows.iter().enumerate() {
            for (j, &lb) in cols.iter().enumerate() {
                let Some(e) = self.entry(tail, ka, lb) else {
                    continue;
                };
                let share = self.share(tail, ka, lb, e);
                if share > 0 {
                    self.buf[i * k + j] = -share;
                    any = true;
                }
            }
        }
        self.work += (k * k) as u64;
        if !any {
            // All zero: the zero dual is optimal, and every slack is −share.
        } else if self.frozen && sign == 0 && k <= 2 {
            // Below the root no slack is needed: small views in closed form.
            let b = &self.buf;
            return if k == 1 {
                -b[0]
            } else {
                -(b[0] + b[3]).min(b[1] + b[2])
            };
        }
        let value = if any {
            -self.hung.solve(k, &self.buf)
        } else {
            0
        };
        if self.frozen && sign == 0 {
            return value;
        }
        if sign != 0 && any {
            for j in 1..=k {
                let i = self.hung.p[j];
                if i == 0 || i > r || j > c || self.buf[(i - 1) * k + j - 1] >= 0 {
                    continue;
                }
                let e = rows[i - 1] as usize * m2 + cols[j - 1] as usize;
                self.grad.push((e, sign));
            }
        }
        // Slacks s_i + t_j − share with s = −u, t = −v (all zero if no entry
        // has a positive share: the zero dual is optimal).
        let epoch = self.epoch;
        for (i, &ka) in rows.iter().enumerate() {
            for (j, &lb) in cols.iter().enumerate() {
                let Some(e) = self.entry(tail, ka, lb) else {
                    continue;
                };
                let dual = if any {
                    -self.hung.u[i + 1] - self.hung.v[j + 1]
                } else {
                    0
                };
                let slack = dual - self.share(tail, ka, lb, e);
                if tail {
                    self.slack_t[e] = slack;
                    self.stamp_t[e] = epoch;
                } else {
                    self.slack_h[e] = slack;
                    self.stamp_h[e] = epoch;
                }
            }
        }
        value
    }

    /// One ascent step after [`Ascent::evaluate`], given the outer
    /// assignment's reduced cost `rc[u · n + v]` (in the units of the outer
    /// matrix, where a pair's value enters with factor −4) at every
    /// unmapped u and unused v.
    pub(super) fn step(&mut self, p: &Problem, f: &[u32], used: &[bool], rc: &[i64]) {
        let (n, m2) = (self.n, self.a2.len());
        let epoch = self.epoch;
        let eps = |rows: u32, rc: i64| {
            if rows == 0 {
                0
            } else {
                rc.max(0) / (4 * i64::from(rows))
            }
        };
        for &(s, e) in &p.classes {
            for u in s..e {
                if f[u] != NONE {
                    continue;
                }
                for v in s..e {
                    if used[v] {
                        continue;
                    }
                    let e_uv = eps(self.rows[u], rc[u * n + v]);
                    for &k in &self.t_rows[u] {
                        let w = self.a1.head[k as usize] as usize;
                        for &l in &self.t_cols[v] {
                            let ent = k as usize * m2 + l as usize;
                            if self.stamp_t[ent] != epoch || self.stamp_h[ent] != epoch {
                                continue;
                            }
                            let z = self.a2.head[l as usize] as usize;
                            let gt = self.slack_t[ent] + e_uv;
                            let gh = self.slack_h[ent] + eps(self.rows[w], rc[w * n + z]);
                            self.alpha[ent] += (gt - gh).div_euclid(2);
                        }
                    }
                    self.work += (self.t_rows[u].len() * self.t_cols[v].len()) as u64;
                }
            }
        }
    }
}

impl Ascent {
    /// A subgradient step on the shares, after [`Ascent::evaluate`] at the
    /// same node: `chosen` are the pairs of the outer assignment; an entry
    /// matched in the tail view of a chosen pair but not in the head view of
    /// its other chosen pair loses tail share, and conversely. `gap` is the
    /// distance from the bound to the target (in arc edits), `lambda` the
    /// Polyak factor; the move is λ·gap·S/(2·‖g‖²) per entry (‖g‖² = number
    /// of entries moved). Returns whether anything moved.
    pub(super) fn subgradient(&mut self, chosen: &[(usize, usize)], gap: f64, lambda: f64) -> bool {
        self.grad.clear();
        for &(u, v) in chosen {
            self.view(u, v, true, 1);
            self.view(u, v, false, -1);
        }
        self.grad.sort_unstable();
        let mut g: Vec<(usize, i64)> = Vec::with_capacity(self.grad.len());
        for &(e, s) in &self.grad {
            match g.last_mut() {
                Some(last) if last.0 == e => last.1 += s,
                _ => g.push((e, s)),
            }
        }
        g.retain(|&(_, s)| s != 0);
        if g.is_empty() {
            return false;
        }
        let step = (lambda * gap * S as f64 / (2.0 * g.len() as f64)).round() as i64;
        let step = step.max(1);
        for (e, s) in g {
            self.alpha[e] -= step * s;
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::super::brute::random_pairs;
    use super::{Ascent, Hungarian, S};
    use crate::ged::problem::{NONE, Problem};

    /// The bound of the current shares at the root, by the definition in
    /// the module doc: vertex cost + ⌈min over bijections of Σ local / 2S⌉,
    /// with the outer reduced costs (for a step).
    fn root_bound(p: &Problem, a: &mut Ascent) -> (u64, Vec<i64>) {
        let n = p.n();
        let f = vec![NONE; n];
        let used = vec![false; n];
        a.evaluate(p, &f, &used);
        let arcs = |s: &super::super::problem::Side, u: usize| -> i64 {
            s.out[u]
                .iter()
                .chain(&s.inn[u])
                .map(|&(_, m)| i64::from(m))
                .sum()
        };
        let mut total = 0i64;
        let mut rc = vec![0i64; n * n];
        let mut h = Hungarian::default();
        for &(s, e) in &p.classes {
            let k = e - s;
            let mut c = vec![0i64; k * k];
            for u in s..e {
                for v in s..e {
                    let loops = i64::from(p.s1.loops[u].abs_diff(p.s2.loops[v]));
                    c[(u - s) * k + v - s] =
                        S * (2 * loops + arcs(&p.s1, u) + arcs(&p.s2, v)) - 4 * a.msum[u * n + v];
                }
            }
            total += h.solve(k, &c);
            for u in s..e {
                for v in s..e {
                    rc[u * n + v] = c[(u - s) * k + v - s] - h.u[u - s + 1] - h.v[v - s + 1];
                }
            }
        }
        let lb = p.vertex_cost + (total.max(0) as u64).div_ceil(2 * S as u64);
        (lb, rc)
    }

    /// Any split of the arc pairs' worth, even an absurd one, bounds GED
    /// from below: the relaxation's claim.
    #[test]
    fn every_split_gives_a_valid_bound() {
        let mut x = 0x5EED_u64;
        for (i, (a, b, labeled)) in random_pairs(200, 0x00A5_CE17, 6).into_iter().enumerate() {
            let p = Problem::new(&a, &b);
            let Some(mut asc) = Ascent::new(&p, 1) else {
                continue;
            };
            for share in asc.alpha.iter_mut() {
                x ^= x << 13;
                x ^= x >> 7;
                x ^= x << 17;
                *share = (x % (4 * S as u64)) as i64 - S;
            }
            let truth = super::super::brute::brute_ged(&a, &b, labeled);
            let (lb, _) = root_bound(&p, &mut asc);
            assert!(lb <= truth, "pair {i}: bound {lb} above GED {truth}");
        }
    }

    /// An ascent step never lowers the bound (module doc), and over the
    /// pairs it raises it somewhere.
    #[test]
    fn ascent_steps_never_lower_the_bound() {
        let mut raised = 0;
        for (i, (a, b, labeled)) in random_pairs(200, 0xB0B, 6).into_iter().enumerate() {
            let p = Problem::new(&a, &b);
            let Some(mut asc) = Ascent::new(&p, 1) else {
                continue;
            };
            let truth = super::super::brute::brute_ged(&a, &b, labeled);
            let n = p.n();
            let (first, mut rc) = root_bound(&p, &mut asc);
            let mut last = first;
            for _ in 0..20 {
                asc.step(&p, &vec![NONE; n], &vec![false; n], &rc);
                let (lb, r) = root_bound(&p, &mut asc);
                assert!(lb >= last, "pair {i}: {last} -> {lb}");
                assert!(lb <= truth, "pair {i}: bound {lb} above GED {truth}");
                last = lb;
                rc = r;
            }
            raised += usize::from(last > first);
        }
        assert!(raised > 0, "no pair's bound was raised");
    }

    #[test]
    fn hungarian_finds_the_optimum_and_a_tight_dual() {
        let a = [4, 1, 3, 2, 0, 5, 3, 2, 2];
        let mut h = Hungarian::default();
        let v = h.solve(3, &a);
        assert_eq!(v, 5); // 1 + 2 + 2
        let dual: i64 = h.u[1..].iter().sum::<i64>() + h.v[1..].iter().sum::<i64>();
        assert_eq!(dual, v);
        for i in 0..3 {
            for j in 0..3 {
                assert!(a[i * 3 + j] - h.u[i + 1] - h.v[j + 1] >= 0);
            }
        }
    }
}
