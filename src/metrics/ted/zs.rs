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
pub struct Banded<'a> {
    pub f: &'a OrderedTree,
    pub g: &'a OrderedTree,
    pub u: usize,
    /// Distance between the subtrees rooted at `i` (of `f`) and `j` (of `g`).
    pub td: Stair,
    /// The forest table of the pair being computed.
    pub fd: Stair,
    /// Cells computed so far.
    pub work: u64,
}

/// Why a banded computation stopped before its end.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Exhausted;

impl<'a> Banded<'a> {
    /// Cells this band needs at most at once: the subtree table plus the
    /// largest forest table.
    pub fn memory_cells(f: &OrderedTree, g: &OrderedTree, u: usize) -> u64 {
        let (n1, n2) = (f.len(), g.len());
        if n1 == 0 || n2 == 0 {
            return 0;
        }
        Stair::cells((0, n1 - 1), (0, n2 - 1), u) + Stair::cells((0, n1), (0, n2), u)
    }

    pub fn new(f: &'a OrderedTree, g: &'a OrderedTree, u: usize) -> Self {
        let mut td = Stair::default();
        if !f.is_empty() && !g.is_empty() {
            td.reset((0, f.len() - 1), (0, g.len() - 1), u);
        }
        Banded {
            f,
            g,
            u,
            td,
            fd: Stair::default(),
            work: 0,
        }
    }

    /// Fills `td` for every pair of subtrees, keyroot pair by keyroot pair
    /// in increasing postorder, unless the work passes `budget` cells.
    pub fn run(&mut self, budget: u64) -> Result<(), Exhausted> {
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
                if g.lml[leaf] == leaf {
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

    /// The forest table of keyroots (or leftmost-path nodes) `k1`, `k2`:
    /// positions `p` of f's prefixes from `lml(k1)` (empty) to `k1 + 1`, `q`
    /// likewise in g; records the distance of every pair of subtrees that
    /// both start the table in `td`.
    pub fn table(&mut self, k1: usize, k2: usize) {
        let (f, g, u) = (self.f, self.g, self.u);
        let (l1, l2) = (f.lml[k1], g.lml[k2]);
        self.fd.reset((l1, k1 + 1), (l2, k2 + 1), u);
        let fd = &mut self.fd;
        let td = &mut self.td;
        let mut work = 0u64;
        for p in l1..=k1 + 1 {
            let (lo, hi) = fd.row_window(p);
            for q in lo..=hi {
                let v = if p == l1 {
                    (q - l2) as u32
                } else if q == l2 {
                    fd.get(p - 1, q).saturating_add(1)
                } else {
                    let (x, y) = (p - 1, q - 1);
                    let del = fd.get(p - 1, q) + 1;
                    let ins = fd.get(p, q - 1) + 1;
                    let both_start = f.lml[x] == l1 && g.lml[y] == l2;
                    let v = if both_start {
                        let rename = u32::from(f.label[x] != g.label[y]);
                        let v = del.min(ins).min(fd.get(p - 1, q - 1) + rename).min(INF);
                        td.set(x, y, v);
                        v
                    } else {
                        let sub = fd.get(f.lml[x], g.lml[y]) + td.get(x, y);
                        del.min(ins).min(sub)
                    };
                    v.min(INF)
                };
                fd.set(p, q, v);
            }
            work += (hi + 1).saturating_sub(lo) as u64;
        }
        self.work += work;
    }

    /// The distance of the two whole trees under this band (infinite when
    /// the band holds no mapping).
    pub fn distance(&self) -> u32 {
        match (self.f.len(), self.g.len()) {
            (0, n) | (n, 0) => n as u32,
            (n1, n2) => self.td.get(n1 - 1, n2 - 1),
        }
    }
}
