//! Linear sum assignment on a square integer matrix, with dual variables.
//!
//! Shortest augmenting path method of Jonker & Volgenant ("A shortest
//! augmenting path algorithm for dense and sparse linear assignment problems",
//! Computing 38, 1987), in the row-by-row form described by Crouse ("On
//! implementing 2D rectangular assignment algorithms", IEEE TAES 52(4), 2016):
//! each row is inserted by a Dijkstra search over reduced costs, then the
//! potentials are updated so that every reduced cost stays non-negative.
//! O(n³). The duals give, for a forced pair (i, j), the bound
//! `total + reduced_cost(i, j)` on every assignment that uses (i, j), which the
//! branch and bound uses to discard children without solving them.

use crate::cpu::Deadline;

const NIL: usize = usize::MAX;
const INF: i64 = i64::MAX / 4;

/// An optimal assignment with a feasible dual certifying it.
#[derive(Debug, Clone, Default)]
pub(crate) struct Assignment {
    /// Column assigned to each row.
    pub col_of_row: Vec<usize>,
    /// Σ cost(i, col_of_row[i]).
    pub total: i64,
    /// Row potentials.
    pub u: Vec<i64>,
    /// Column potentials; `cost(i, j) − u[i] − v[j] >= 0`, with equality on
    /// assigned pairs.
    pub v: Vec<i64>,
}

impl Assignment {
    /// Reduced cost of the pair (i, j).
    #[inline]
    pub(super) fn reduced(&self, cost: &[i64], n: usize, i: usize, j: usize) -> i64 {
        cost[i * n + j] - self.u[i] - self.v[j]
    }
}

/// Reusable buffers for [`solve`].
#[derive(Debug, Default)]
pub(crate) struct Lsap {
    spc: Vec<i64>,
    path: Vec<usize>,
    row_of_col: Vec<usize>,
    in_sr: Vec<bool>,
    in_sc: Vec<bool>,
    sr: Vec<usize>,
}

impl Lsap {
    /// Solves the `n × n` problem `cost` (row-major). Returns `None` if the
    /// deadline passes first (checked once per row when `n` is large).
    pub(super) fn solve(
        &mut self,
        n: usize,
        cost: &[i64],
        deadline: Deadline,
    ) -> Option<Assignment> {
        self.solve_warm(n, cost, deadline, None)
    }

    /// As [`Lsap::solve`], warm-started from column potentials and a
    /// tentative assignment (for instance those of a similar matrix solved
    /// before): row potentials are set to the row minima of the reduced
    /// costs, which makes the duals feasible; tentative pairs that are tight
    /// under them are kept; only the remaining rows are augmented. The
    /// result is optimal whatever the start.
    pub(super) fn solve_warm(
        &mut self,
        n: usize,
        cost: &[i64],
        deadline: Deadline,
        init: Option<(&[i64], &[usize])>,
    ) -> Option<Assignment> {
        if cost.len() != n * n {
            return None;
        }
        let mut a = Assignment {
            col_of_row: vec![NIL; n],
            total: 0,
            u: vec![0; n],
            v: vec![0; n],
        };
        self.row_of_col.clear();
        self.row_of_col.resize(n, NIL);
        if let Some((v0, cols0)) = init
            && v0.len() == n
            && cols0.len() == n
        {
            self.warm_start(n, cost, &mut a, v0, cols0);
        }
        let every = if n >= 256 { 1 } else { 8 };
        for cur in 0..n {
            if a.col_of_row[cur] != NIL {
                continue;
            }
            if n >= 48 && cur % every == 0 && deadline.passed() {
                return None;
            }
            self.reset_row_buffers(n);
            let (sink, min_val) = self.shortest_path(n, cost, &a, cur)?;
            self.update_potentials(n, &mut a, cur, min_val);
            self.augment(&mut a, cur, sink)?;
        }
        a.total = (0..n).map(|i| cost[i * n + a.col_of_row[i]]).sum();
        Some(a)
    }

    /// Takes the column potentials `v0`, sets each row potential to its row
    /// minimum of reduced costs, and keeps the pairs of `cols0` that are tight.
    fn warm_start(
        &mut self,
        n: usize,
        cost: &[i64],
        a: &mut Assignment,
        v0: &[i64],
        cols0: &[usize],
    ) {
        a.v.copy_from_slice(v0);
        for i in 0..n {
            let row = &cost[i * n..(i + 1) * n];
            a.u[i] = row
                .iter()
                .zip(&a.v)
                .map(|(&c, &vj)| c - vj)
                .min()
                .unwrap_or(0);
            let j = cols0[i];
            if j < n && self.row_of_col[j] == NIL && row[j] - a.u[i] - a.v[j] == 0 {
                self.row_of_col[j] = i;
                a.col_of_row[i] = j;
            }
        }
    }

    /// Clears the per-row search buffers for an `n × n` problem.
    #[inline]
    fn reset_row_buffers(&mut self, n: usize) {
        self.spc.clear();
        self.spc.resize(n, INF);
        self.path.clear();
        self.path.resize(n, NIL);
        self.in_sr.clear();
        self.in_sr.resize(n, false);
        self.in_sc.clear();
        self.in_sc.resize(n, false);
        self.sr.clear();
    }

    /// Dijkstra search over reduced costs from the free row `cur` to a free
    /// column: returns that column (the sink) and the path length.
    #[inline]
    fn shortest_path(
        &mut self,
        n: usize,
        cost: &[i64],
        a: &Assignment,
        cur: usize,
    ) -> Option<(usize, i64)> {
        let mut min_val = 0i64;
        let mut i = cur;
        loop {
            self.in_sr[i] = true;
            self.sr.push(i);
            let row = &cost[i * n..(i + 1) * n];
            let mut lowest = INF;
            let mut best = NIL;
            for (j, &cij) in row.iter().enumerate() {
                if self.in_sc[j] {
                    continue;
                }
                let r = min_val + cij - a.u[i] - a.v[j];
                if r < self.spc[j] {
                    self.spc[j] = r;
                    self.path[j] = i;
                }
                let s = self.spc[j];
                if s < lowest || (s == lowest && best != NIL && self.row_of_col[j] == NIL) {
                    lowest = s;
                    best = j;
                }
            }
            if best == NIL {
                return None;
            }
            min_val = lowest;
            self.in_sc[best] = true;
            let r = self.row_of_col[best];
            if r == NIL {
                return Some((best, min_val));
            }
            i = r;
        }
    }

    /// Updates the potentials after the search from row `cur` so that every
    /// reduced cost stays non-negative and the new path is tight.
    #[inline]
    fn update_potentials(&self, n: usize, a: &mut Assignment, cur: usize, min_val: i64) {
        a.u[cur] += min_val;
        for &r in &self.sr {
            if r != cur {
                a.u[r] += min_val - self.spc[a.col_of_row[r]];
            }
        }
        for j in 0..n {
            if self.in_sc[j] {
                a.v[j] -= min_val - self.spc[j];
            }
        }
    }

    /// Flips the augmenting path ending at column `sink` back to row `cur`.
    #[inline]
    fn augment(&mut self, a: &mut Assignment, cur: usize, sink: usize) -> Option<()> {
        let mut j = sink;
        loop {
            let r = self.path[j];
            if r == NIL {
                return None;
            }
            self.row_of_col[j] = r;
            let prev = a.col_of_row[r];
            a.col_of_row[r] = j;
            if r == cur {
                return Some(());
            }
            j = prev;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    fn brute(n: usize, cost: &[i64]) -> i64 {
        fn rec(n: usize, cost: &[i64], i: usize, used: &mut Vec<bool>, acc: i64, best: &mut i64) {
            if i == n {
                *best = (*best).min(acc);
                return;
            }
            for j in 0..n {
                if !used[j] {
                    used[j] = true;
                    rec(n, cost, i + 1, used, acc + cost[i * n + j], best);
                    used[j] = false;
                }
            }
        }
        let mut best = i64::MAX;
        rec(n, cost, 0, &mut vec![false; n], 0, &mut best);
        best
    }

    #[test]
    fn matches_brute_force_and_duals_are_feasible() {
        let mut seed = 0x9E37_79B9_7F4A_7C15u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let mut lsap = Lsap::default();
        let deadline = Deadline::after(Duration::from_secs(60));
        for _ in 0..300 {
            let n = (next() % 7) as usize;
            let range = 1 + next() % 12;
            let cost: Vec<i64> = (0..n * n).map(|_| (next() % range) as i64).collect();
            let a = lsap.solve(n, &cost, deadline).expect("no deadline");
            assert_eq!(a.total, if n == 0 { 0 } else { brute(n, &cost) });
            let mut seen = vec![false; n];
            for i in 0..n {
                assert!(!seen[a.col_of_row[i]]);
                seen[a.col_of_row[i]] = true;
                assert_eq!(a.reduced(&cost, n, i, a.col_of_row[i]), 0);
                for j in 0..n {
                    assert!(a.reduced(&cost, n, i, j) >= 0);
                }
            }
            assert_eq!(a.u.iter().sum::<i64>() + a.v.iter().sum::<i64>(), a.total);
            // Warm starts from arbitrary potentials and assignments, and from
            // the optimum of a perturbed matrix, reach the same optimum.
            let v0: Vec<i64> = (0..n).map(|_| (next() % 9) as i64 - 4).collect();
            let c0: Vec<usize> = (0..n).map(|_| (next() % (n as u64 + 1)) as usize).collect();
            let mut perturbed = cost.clone();
            for x in perturbed.iter_mut() {
                if next() % 4 == 0 {
                    *x += (next() % 3) as i64;
                }
            }
            for (v, c) in [(v0, c0), (a.v.clone(), a.col_of_row.clone())] {
                let w = lsap
                    .solve_warm(n, &perturbed, deadline, Some((&v, &c)))
                    .expect("no deadline");
                assert_eq!(w.total, if n == 0 { 0 } else { brute(n, &perturbed) });
                for i in 0..n {
                    for j in 0..n {
                        assert!(w.reduced(&perturbed, n, i, j) >= 0);
                    }
                }
            }
        }
    }
}
