//! Zhang & Shasha's dynamic program for the ordered tree edit distance
//! (SIAM J. Comput. 18(6), 1989: keyroots, forest distances, Theorem 2),
//! restricted to a diagonal band `|i − j| ≤ u` of postorder positions, after
//! Touzet ("A linear tree edit distance algorithm for similar ordered
//! trees", CPM 2005), who showed that a mapping of cost `k` pairs only nodes
//! whose postorder indices differ by at most `k`.
//!
//! Why the band is exact when the distance is at most `u`: take an optimal
//! mapping `M` of cost `d ≤ u`. Every table cell on its derivation stands
//! for two postorder prefixes `F[..x]`, `G[..y]` that `M` maps into each
//! other (a mapping keeps postorder order and, for a pair `i ↔ j`, maps the
//! nodes before `lml(i)` to nodes before `lml(j)`), so `M` deletes or inserts
//! at least `|x − y|` nodes: `|x − y| ≤ d ≤ u`. Cells outside the band are
//! read as infinite, which only removes mappings, so every computed cell is
//! the cost of some mapping (never below the true value) and the cells of
//! `M`'s derivation are computed exactly. Hence the result `r` is the cost
//! of a mapping, `r ≥ TED`, and `r ≤ u` implies `r = TED`.
//! A keyroot pair whose tables start more than `u` apart is skipped whole:
//! its origin cell is outside the band, so all its cells would be infinite.

use super::band::{INF, Stair};
use super::tree::OrderedTree;

/// The band's tables and the work spent on them.
pub(super) struct Banded<'a> {
    pub f: &'a OrderedTree,
    pub g: &'a OrderedTree,
    pub u: usize,
    /// Distance between the subtrees rooted at `i` (of `f`) and `j` (of `g`).
    pub td: Stair,
    /// The forest table of the pair being computed.
    pub fd: Stair,
    /// Cells computed so far.
    pub work: u64,
    /// Most cells held at once (`td` and the largest forest table).
    pub peak: u64,
    path1: Vec<usize>,
    path2: Vec<usize>,
}

/// Why a banded computation stopped before its end.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct Exhausted;

/// The diagonals `d = q − p` of a table starting at `(l1, l2)` whose cells
/// can lie on a mapping of cost ≤ `u`: with `λ = l2 − l1` and `c = n2 − n1`,
/// such a mapping deletes or inserts at least `|λ|` nodes before the table,
/// `|d − λ|` in the forests of the cell and `|d − c|` after it, so
/// `|λ| + |d − λ| + |d − c| ≤ u`. `None` when no diagonal qualifies.
fn diagonals(l1: usize, l2: usize, n1: usize, n2: usize, u: usize) -> Option<(i64, i64)> {
    let lambda = l2 as i64 - l1 as i64;
    let c = n2 as i64 - n1 as i64;
    let s = u as i64 - lambda.abs();
    let (lo, hi) = (lambda.min(c), lambda.max(c));
    if hi - lo > s {
        return None;
    }
    // |d − lo| + |d − hi| ≤ s  ⇔  (lo + hi − s)/2 ≤ d ≤ (lo + hi + s)/2.
    Some(((lo + hi - s + 1).div_euclid(2), (lo + hi + s).div_euclid(2)))
}

impl<'a> Banded<'a> {
    /// Cells this band needs at most at once: the subtree table plus the
    /// largest forest table.
    pub(super) fn memory_cells(f: &OrderedTree, g: &OrderedTree, u: usize) -> u64 {
        let (n1, n2) = (f.len(), g.len());
        if n1 == 0 || n2 == 0 {
            return 0;
        }
        let band = (-(u as i64), u as i64);
        Stair::cells((0, n1 - 1), (0, n2 - 1), band) + Stair::cells((0, n1), (0, n2), band)
    }

    /// An upper bound of the cells [`Banded::run`] computes at width `u`,
    /// counted in O(n1 + n2) without running it: the table of keyroots
    /// `k1`, `k2` (run only when their leftmost leaves are at most `u`
    /// apart) has at most `|T(k1)| + 1` rows of at most
    /// `min(|T(k2)| + 1, u + 1)` cells (its diagonals, [`diagonals`]).
    pub(super) fn cells_at_most(f: &OrderedTree, g: &OrderedTree, u: usize) -> u128 {
        let n2 = g.len();
        // Row width of the keyroot of g starting at each leaf, summed.
        let mut prefix = vec![0u128; n2 + 1];
        for q in 0..n2 {
            let w = if g.lml[q] == q {
                let k = g.keyroot_of[q];
                (k + 2 - q).min(u + 1) as u128
            } else {
                0
            };
            prefix[q + 1] = prefix[q] + w;
        }
        f.keyroots
            .iter()
            .map(|&k1| {
                let l1 = f.lml[k1];
                let (from, to) = (
                    l1.saturating_sub(u).min(n2),
                    l1.saturating_add(u + 1).min(n2),
                );
                (k1 + 2 - l1) as u128 * (prefix[to] - prefix[from])
            })
            .sum()
    }

    pub(super) fn new(f: &'a OrderedTree, g: &'a OrderedTree, u: usize) -> Self {
        let mut td = Stair::default();
        if !f.is_empty() && !g.is_empty() {
            td.reset((0, f.len() - 1), (0, g.len() - 1), (-(u as i64), u as i64));
        }
        Banded {
            f,
            g,
            u,
            td,
            fd: Stair::default(),
            work: 0,
            peak: 0,
            path1: Vec::new(),
            path2: Vec::new(),
        }
    }

    /// Fills `td` for every pair of subtrees that a mapping of cost ≤ `u`
    /// can pair, keyroot pair by keyroot pair in increasing postorder,
    /// unless the work passes `budget` cells.
    pub(super) fn run(&mut self, budget: u64) -> Result<(), Exhausted> {
        let (f, g, u) = (self.f, self.g, self.u);
        // A keyroot is the top of the leftmost path of exactly one leaf, so
        // the keyroots of g whose tables start near l1 are found through the
        // leaves l1 − u ..= l1 + u.
        let mut partners: Vec<usize> = Vec::new();
        for &k1 in &f.keyroots {
            let l1 = f.lml[k1];
            partners.clear();
            let from = l1.saturating_sub(u);
            let to = l1.saturating_add(u).min(g.len().saturating_sub(1));
            for leaf in from..=to {
                if g.lml[leaf] == leaf && diagonals(l1, leaf, f.len(), g.len(), u).is_some() {
                    partners.push(g.keyroot_of[leaf]);
                }
            }
            partners.sort_unstable();
            for &k2 in &partners {
                self.table(k1, k2);
                if self.work > budget {
                    return Err(Exhausted);
                }
            }
        }
        Ok(())
    }

    /// Nodes of the leftmost path from leaf `lml(k)` up to `k`, bottom up.
    fn path(t: &OrderedTree, k: usize, out: &mut Vec<usize>) {
        out.clear();
        let mut x = t.lml[k];
        loop {
            out.push(x);
            if x >= k {
                break;
            }
            x = t.parent[x];
        }
    }

    /// The forest table of keyroots (or leftmost-path nodes) `k1`, `k2`:
    /// positions `p` of f's prefixes from `lml(k1)` (empty) to `k1 + 1`, `q`
    /// likewise in g, on the diagonals of [`diagonals`] and only as far as
    /// the last pair of subtrees on the two leftmost paths those diagonals
    /// allow; records the distance of every pair of subtrees that both start
    /// the table in `td`.
    pub(super) fn table(&mut self, k1: usize, k2: usize) {
        let (f, g, u) = (self.f, self.g, self.u);
        let (l1, l2) = (f.lml[k1], g.lml[k2]);
        let Some((dlo, dhi)) = diagonals(l1, l2, f.len(), g.len(), u) else {
            self.fd.reset((l1, l1), (l2, l2), (1, 0));
            return;
        };
        let Some((rmax, cmax)) = self.last_pair(k1, k2, dlo, dhi) else {
            self.fd.reset((l1, l1), (l2, l2), (1, 0));
            return;
        };
        self.fd.reset((l1, rmax + 1), (l2, cmax + 1), (dlo, dhi));
        self.peak = self
            .peak
            .max((self.td.data.len() + self.fd.data.len()) as u64);
        self.work += fill(&mut self.fd, &mut self.td, f, g, (l1, l2), rmax);
    }

    /// The last row and column the table of `k1`, `k2` needs: the highest
    /// path pairs (x, y) with y − x in `dlo..=dhi` (both paths ascend) whose
    /// four regions (`OrderedTree::regions`) differ by at most u in all;
    /// `None` when no pair qualifies.
    fn last_pair(&mut self, k1: usize, k2: usize, dlo: i64, dhi: i64) -> Option<(usize, usize)> {
        let (f, g, u) = (self.f, self.g, self.u);
        Self::path(f, k1, &mut self.path1);
        Self::path(g, k2, &mut self.path2);
        let (mut rmax, mut cmax) = (None::<usize>, None::<usize>);
        let mut j0 = 0;
        for &x in &self.path1 {
            while j0 < self.path2.len() && (self.path2[j0] as i64) < x as i64 + dlo {
                j0 += 1;
            }
            let mut j = j0;
            let rx = f.regions(x);
            while j < self.path2.len() && (self.path2[j] as i64) <= x as i64 + dhi {
                let y = self.path2[j];
                let ry = g.regions(y);
                let bound: usize = (0..4).map(|k| rx[k].abs_diff(ry[k])).sum();
                if bound <= u {
                    rmax = Some(x);
                    cmax = Some(cmax.map_or(y, |c| c.max(y)));
                }
                j += 1;
            }
        }
        Some((rmax?, cmax?))
    }

    /// The distance of the two whole trees under this band (infinite when
    /// the band holds no mapping).
    pub(super) fn distance(&self) -> u32 {
        match (self.f.len(), self.g.len()) {
            (0, n) | (n, 0) => n as u32,
            (n1, n2) => self.td.get(n1 - 1, n2 - 1),
        }
    }
}

/// Fills the forest table `fd` (already reset to rows `l1..=rmax + 1`) row
/// by row, writing the distance of every pair of subtrees that both start
/// the table into `td`; returns the number of cells computed.
#[inline]
fn fill(
    fd: &mut Stair,
    td: &mut Stair,
    f: &OrderedTree,
    g: &OrderedTree,
    (l1, l2): (usize, usize),
    rmax: usize,
) -> u64 {
    let mut work = 0u64;
    for p in l1..=rmax + 1 {
        let i = p - fd.row0;
        let (lo, hi) = (fd.lo[i], fd.hi[i]);
        if lo > hi {
            continue;
        }
        work += (hi + 1 - lo) as u64;
        let (before, rest) = fd.data.split_at_mut(fd.off[i]);
        let cur = &mut rest[..hi + 1 - lo];
        // The table above this row, read-only.
        let above = At {
            row0: fd.row0,
            lo: &fd.lo[..i],
            hi: &fd.hi[..i],
            off: &fd.off[..i],
            data: before,
        };
        if p == l1 {
            for q in lo..=hi {
                cur[q - lo] = (q - l2) as u32;
            }
            continue;
        }
        let x = p - 1;
        let x_starts = f.lml[x] == l1;
        let (lx, labx) = (f.lml[x], f.label[x]);
        // Row p − 1 (the deletion of x) and td's row x, as slices.
        let (plo, phi) = (above.lo[i - 1], above.hi[i - 1]);
        let prev: &[u32] = if plo <= phi {
            &above.data[above.off[i - 1]..above.off[i - 1] + phi + 1 - plo]
        } else {
            &[]
        };
        let at_prev = |q: usize| -> u32 {
            if q >= plo && q <= phi {
                prev[q - plo]
            } else {
                INF
            }
        };
        // td's row x: read and written in place.
        let ti = x - td.row0;
        let (tlo, thi, toff) = (td.lo[ti], td.hi[ti], td.off[ti]);
        let mut left = INF;
        for q in lo..=hi {
            let del = at_prev(q) + 1;
            let v = if q == l2 {
                del
            } else {
                let y = q - 1;
                let ins = left + 1;
                let gy = g.lml[y];
                if x_starts && gy == l2 {
                    let rename = u32::from(labx != g.label[y]);
                    let v = del.min(ins).min(at_prev(q - 1) + rename).min(INF);
                    if y >= tlo && y <= thi {
                        td.data[toff + y - tlo] = v;
                    }
                    v
                } else {
                    let t = if y >= tlo && y <= thi {
                        td.data[toff + y - tlo]
                    } else {
                        INF
                    };
                    del.min(ins).min(above.get(lx, gy) + t)
                }
            };
            left = v.min(INF);
            cur[q - lo] = left;
        }
    }
    work
}

/// Read access to the rows of a [`Stair`] above the row being written.
struct At<'s> {
    row0: usize,
    lo: &'s [usize],
    hi: &'s [usize],
    off: &'s [usize],
    data: &'s [u32],
}

impl At<'_> {
    #[inline]
    fn get(&self, r: usize, c: usize) -> u32 {
        let Some(i) = r.checked_sub(self.row0) else {
            return INF;
        };
        if i >= self.lo.len() || c < self.lo[i] || c > self.hi[i] {
            return INF;
        }
        self.data[self.off[i] + c - self.lo[i]]
    }
}

#[cfg(test)]
mod tests {
    use super::diagonals;

    #[test]
    fn diagonals_of_a_table() {
        // Same start, same sizes: |d| + |d| ≤ 4.
        assert_eq!(diagonals(0, 0, 10, 10, 4), Some((-2, 2)));
        // Tables 3 apart in trees of equal size: 3 + |d − 3| + |d| ≤ 4.
        assert_eq!(diagonals(0, 3, 10, 10, 4), None);
        assert_eq!(diagonals(0, 1, 10, 10, 4), Some((-1, 2)));
        // Sizes differ by 2: |d| + |d − 2| ≤ 3.
        assert_eq!(diagonals(5, 5, 10, 12, 3), Some((0, 2)));
    }
}
