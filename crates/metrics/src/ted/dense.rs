//! Zhang & Shasha's dynamic program for the ordered tree edit distance
//! over the whole tables (SIAM J. Comput. 18(6), 1989, sec. 3: keyroots,
//! forest distances, Theorem 2 and its algorithm EDIT), for trees whose
//! distance is far from zero, where a diagonal band (`zs.rs`) prunes
//! nothing.
//!
//! Its cost is known before it runs: the forest table of keyroots `k1`,
//! `k2` has `|T(k1)|·|T(k2)|` cells, so the whole computation has the
//! product of the two trees' keyroot weights (`OrderedTree::
//! keyroot_weight`), and `mod.rs` runs it only when that fits the work
//! budget. Of the two decompositions Zhang & Shasha allow (leftmost paths,
//! or rightmost ones: the mirrored trees), `mod.rs` picks the one with
//! fewer cells — the choice Pawlik & Augsten's RTED (PVLDB 5(4), 2011) makes
//! per subtree pair, made here once for the whole pair.
//!
//! Memory: the subtree-distance table (`n1·n2` cells) and one forest table
//! (`(n1 + 1)·(n2 + 1)` cells, reused by every keyroot pair), both of
//! 16-bit cells when `n1 + n2` fits in 16 bits (no distance exceeds it) and
//! 32-bit ones otherwise. The rows of both are contiguous, so the inner
//! loop reads the row above, one earlier row at the subtrees' leftmost
//! leaves and a row of the subtree distances, all as slices.

use super::tree::OrderedTree;

/// A table cell: an unsigned distance of 16 or 32 bits.
pub(super) trait Cell: Copy + Ord + Default {
    fn of(v: usize) -> Self;
    fn get(self) -> usize;
    /// `self + 1` (never overflows: values stay ≤ n1 + n2 < the maximum).
    fn inc(self) -> Self;
    fn add(self, o: Self) -> Self;
}

macro_rules! cell {
    ($t:ty) => {
        impl Cell for $t {
            #[inline]
            fn of(v: usize) -> Self {
                v as $t
            }
            #[inline]
            fn get(self) -> usize {
                self as usize
            }
            #[inline]
            fn inc(self) -> Self {
                self + 1
            }
            #[inline]
            fn add(self, o: Self) -> Self {
                self + o
            }
        }
    };
}
cell!(u16);
cell!(u32);

/// Bytes of one cell for trees of these sizes.
pub(super) fn cell_bytes(n1: usize, n2: usize) -> u64 {
    if n1 + n2 < usize::from(u16::MAX) {
        2
    } else {
        4
    }
}

/// Bytes the dense computation holds at most: the subtree distances, the
/// forward pass's kept rows with their layout (`sweep.rs`) and the whole
/// trees' forest table (the mapping's walk). The rows are freed before the
/// walk, but counted with it: an allocator may keep their memory.
pub(super) fn memory_bytes(f: &OrderedTree, g: &OrderedTree) -> u64 {
    let (n1, n2) = (f.len() as u64, g.len() as u64);
    let cell = cell_bytes(f.len(), g.len());
    let w = super::sweep::row_cells(g) as u64;
    if w > u64::from(u32::MAX) {
        // The layout's 32-bit column indices would not reach.
        return u64::MAX;
    }
    let rows = (super::sweep::rows_kept(f) as u64 + 1) * w * cell + 32 * w;
    cell * n1 * n2 + rows + cell * (n1 + 1) * (n2 + 1)
}

/// Cells the forward computation fills: the product of the keyroot weights.
pub(super) fn work(f: &OrderedTree, g: &OrderedTree) -> u128 {
    u128::from(f.keyroot_weight()) * u128::from(g.keyroot_weight())
}

/// The two tables and the work spent on them.
pub(super) struct Dense<'a, T: Cell> {
    pub f: &'a OrderedTree,
    pub g: &'a OrderedTree,
    /// Distance of the subtrees rooted at `x` and `y`: `td[x·n2 + y]`.
    pub td: Vec<T>,
    /// The forest table of the last keyroot pair, rows of `stride` cells:
    /// `fd[p·stride + q]` for `f`'s nodes `l1..l1 + p` and `g`'s
    /// `l2..l2 + q`.
    pub fd: Vec<T>,
    pub stride: usize,
    /// For the last keyroot pair's column `q ≥ 1` (node `y = l2 + q − 1`):
    /// the column before `y`'s leftmost leaf, `lml(y) − l2`.
    cl: Vec<usize>,
    /// Cells computed.
    pub work: u64,
}

impl<'a, T: Cell> Dense<'a, T> {
    pub(super) fn new(f: &'a OrderedTree, g: &'a OrderedTree) -> Self {
        let (n1, n2) = (f.len(), g.len());
        Dense {
            f,
            g,
            td: vec![T::default(); n1 * n2],
            fd: Vec::new(),
            stride: 0,
            cl: Vec::with_capacity(n2 + 1),
            work: 0,
        }
    }

    /// The distance of the two whole trees (after [`Dense::run`]).
    pub(super) fn distance(&self) -> usize {
        self.td[self.td.len() - 1].get()
    }

    /// The forest table of keyroots `k1`, `k2` (or any nodes: a table
    /// starting at their leftmost leaves), recording in `td` the distance
    /// of every pair of subtrees that both start it.
    pub(super) fn table(&mut self, k1: usize, k2: usize) {
        let (f, g) = (self.f, self.g);
        let (l1, l2) = (f.lml[k1], g.lml[k2]);
        let (m, n) = (k1 + 1 - l1, k2 + 1 - l2);
        let w = n + 1;
        self.stride = w;
        if self.fd.len() < (m + 1) * w {
            self.fd.resize((m + 1) * w, T::default());
        }
        self.work += (m * n) as u64;
        self.cl.clear();
        self.cl.push(0);
        self.cl.extend(g.lml[l2..=k2].iter().map(|&ly| ly - l2));
        for (q, c) in self.fd[..w].iter_mut().enumerate() {
            *c = T::of(q);
        }
        let n2 = g.len();
        for p in 1..=m {
            let x = l1 + p - 1;
            let rx = f.lml[x] - l1;
            let (before, after) = self.fd.split_at_mut(p * w);
            let up = &before[(p - 1) * w..];
            let cur = &mut after[..w];
            let td_row = &mut self.td[x * n2 + l2..x * n2 + l2 + n];
            cur[0] = T::of(p);
            if rx == 0 {
                let labels = (f.label[x], &g.label[l2..=k2]);
                path_row(cur, up, &self.cl, td_row, labels);
            } else {
                inner_row(cur, up, &before[rx * w..rx * w + w], &self.cl, td_row);
            }
        }
    }
}

/// A row of a node `x` on the table's leftmost path (its forest starts the
/// table): against nodes also on the other leftmost path the cell is the
/// distance of two subtrees, a rename or a keep after the cell diagonally
/// above, and is stored in `td_row`; against other nodes `y` it is the
/// insertion of the forest before `y` plus the subtrees' distance.
#[inline]
fn path_row<T: Cell>(
    cur: &mut [T],
    up: &[T],
    cl: &[usize],
    td_row: &mut [T],
    (lx, lg): (u32, &[u32]),
) {
    let mut left = cur[0];
    for q in 1..cur.len() {
        let c = cl[q];
        let del = up[q].inc().min(left.inc());
        let v = if c == 0 {
            let v = del.min(up[q - 1].add(T::of(usize::from(lx != lg[q - 1]))));
            td_row[q - 1] = v;
            v
        } else {
            del.min(T::of(c).add(td_row[q - 1]))
        };
        cur[q] = v;
        left = v;
    }
}

/// A row of a node `x` off the table's leftmost path: deletion of `x`,
/// insertion of `y`, or the forests before `lml(x)` and `lml(y)` (row `src`,
/// column `cl[q]`) plus the distance of the subtrees of `x` and `y`.
#[inline]
fn inner_row<T: Cell>(cur: &mut [T], up: &[T], src: &[T], cl: &[usize], td_row: &[T]) {
    let mut left = cur[0];
    let cells = cur[1..].iter_mut().zip(&up[1..]).zip(&cl[1..]).zip(td_row);
    for (((c, &u), &from), &t) in cells {
        let v = u.inc().min(left.inc()).min(src[from].add(t));
        *c = v;
        left = v;
    }
}

impl<T: Cell> Dense<'_, T> {
    /// The forest table's cell for `f`'s nodes `l1..p` and `g`'s `l2..q`.
    fn at(&self, (l1, l2): (usize, usize), p: usize, q: usize) -> usize {
        self.fd[(p - l1) * self.stride + q - l2].get()
    }

    /// Postorder pairs `(x of f, y of g)` of an optimal mapping (after
    /// [`Dense::run`]), walked back from the whole trees as `mapping.rs`
    /// does for the band: each keyroot pair's table is recomputed at most
    /// once, in decreasing order, so the walk costs at most the run's cells.
    pub(super) fn mapping(&mut self) -> Vec<(usize, usize)> {
        let (f, g) = (self.f, self.g);
        let mut out = Vec::new();
        let (r1, r2) = (f.len() - 1, g.len() - 1);
        let mut groups = std::collections::BTreeMap::new();
        groups.insert((r1, r2), vec![(r1, r2)]);
        while let Some(((k1, k2), mut pending)) = groups.pop_last() {
            self.table(k1, k2);
            let l = (f.lml[k1], g.lml[k2]);
            while let Some((i, j)) = pending.pop() {
                let (mut p, mut q) = (i + 1, j + 1);
                while p > l.0 || q > l.1 {
                    let cur = self.at(l, p, q);
                    if p > l.0 && q > l.1 {
                        let (x, y) = (p - 1, q - 1);
                        if f.lml[x] == l.0 && g.lml[y] == l.1 {
                            let rename = usize::from(f.label[x] != g.label[y]);
                            if cur == self.at(l, p - 1, q - 1) + rename {
                                out.push((x, y));
                                (p, q) = (p - 1, q - 1);
                                continue;
                            }
                        } else if cur
                            == self.at(l, f.lml[x], g.lml[y]) + self.td[x * g.len() + y].get()
                        {
                            let key = (f.keyroot_of[x], g.keyroot_of[y]);
                            if key == (k1, k2) {
                                pending.push((x, y));
                            } else {
                                groups.entry(key).or_insert_with(Vec::new).push((x, y));
                            }
                            (p, q) = (f.lml[x], g.lml[y]);
                            continue;
                        }
                    }
                    if p > l.0 && cur == self.at(l, p - 1, q) + 1 {
                        p -= 1;
                    } else {
                        // The table's recurrence leaves only the insertion.
                        debug_assert!(q > l.1 && cur == self.at(l, p, q - 1) + 1);
                        q -= 1;
                    }
                }
            }
        }
        out.sort_unstable();
        out
    }
}
