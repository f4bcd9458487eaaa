//! The forward pass of the unbanded Zhang–Shasha computation (`dense.rs`;
//! Zhang & Shasha, SIAM J. Comput. 18(6), 1989, algorithm EDIT) with the
//! forest tables of one keyroot `k1` of `f` against *every* keyroot of `g`
//! computed together, row by row: row `p` of all of them (one "super-row",
//! the tables side by side in increasing postorder of `g`'s keyroots) is
//! one pass over contiguous memory, reading one row of the subtree
//! distances. Most keyroots have small subtrees, so table by table the
//! rows would hold a few cells each and their set-up would cost more than
//! the cells.
//!
//! Only the rows a later row reads are kept: the one above, and the row
//! before each leaf `L` whose leftmost path (up to `k1`) is still open —
//! those rows are read by the nodes whose leftmost leaf is `L`. The paths'
//! spans nest (subtrees are postorder intervals), so the kept rows form a
//! stack no deeper than the number of keyroots on a root path (plus one).

use super::dense::{Cell, Dense};
use super::tree::OrderedTree;

/// The side-by-side layout of `g`'s keyroot tables in a super-row.
struct Layout {
    /// Width of a super-row: the sum of `|T(k2)| + 1` over `g`'s keyroots.
    width: usize,
    /// Per column: where its "forest before `lml(y)`" cell sits in the
    /// super-row (itself at a table's first column), and the node `y` of
    /// `g` it ends at (0 at a first column), packed for the inner loop.
    at: Vec<(u32, u32)>,
    /// Per column: all ones at a table's first column (whose cell is the
    /// deletion of the row's prefix, `p`), else 0.
    first: Vec<bool>,
    /// Per column: `lml(y) − l2`, 0 when `y` is on its table's leftmost
    /// path (or at a first column).
    cl: Vec<usize>,
    /// Row 0 of every table: the insertion of the prefix, `q`.
    row0: Vec<usize>,
}

impl Layout {
    fn new(g: &OrderedTree) -> Layout {
        let width = g.keyroots.iter().map(|&k| k + 2 - g.lml[k]).sum();
        let mut l = Layout {
            width,
            at: Vec::with_capacity(width),
            first: Vec::with_capacity(width),
            cl: Vec::with_capacity(width),
            row0: Vec::with_capacity(width),
        };
        for &k2 in &g.keyroots {
            let (l2, off) = (g.lml[k2], l.at.len());
            l.at.push((off as u32, 0));
            l.first.push(true);
            l.cl.push(0);
            l.row0.push(0);
            for y in l2..=k2 {
                let c = g.lml[y] - l2;
                l.at.push(((off + c) as u32, y as u32));
                l.first.push(false);
                l.cl.push(c);
                l.row0.push(y + 1 - l2);
            }
        }
        l
    }
}

/// Most super-rows kept at once for `f`: the row above, the row being
/// written, and one per open leftmost path (at most the keyroots on a
/// root path).
pub(super) fn rows_kept(f: &OrderedTree) -> usize {
    let mut depth = vec![0usize; f.len()];
    let mut most = 0;
    for x in (0..f.len()).rev() {
        let above = if f.parent[x] == usize::MAX {
            0
        } else {
            depth[f.parent[x]]
        };
        depth[x] = above + usize::from(f.keyroot_of[x] == x);
        most = most.max(depth[x]);
    }
    most + 3
}

/// Cells of the super-rows (all keyroot tables of `g` side by side).
pub(super) fn row_cells(g: &OrderedTree) -> usize {
    g.keyroots.iter().map(|&k| k + 2 - g.lml[k]).sum()
}

impl<T: Cell> Dense<'_, T> {
    /// Every keyroot pair, `f`'s keyroots in increasing postorder, each
    /// against all of `g`'s at once: afterwards `td` holds the distance of
    /// every pair of subtrees.
    pub(super) fn run(&mut self) {
        let (f, g) = (self.f, self.g);
        let lay = Layout::new(g);
        let row0: Vec<T> = lay.row0.iter().map(|&v| T::of(v)).collect();
        let kw_g = g.keyroot_weight();
        let mut pool: Vec<Vec<T>> = Vec::new();
        for &k1 in &f.keyroots {
            let l1 = f.lml[k1];
            self.work += (k1 + 1 - l1) as u64 * kw_g;
            // Kept rows: (row, last node reading it); `prev` is the row above.
            let mut stack: Vec<(Vec<T>, usize)> = Vec::new();
            let mut prev = row0.clone();
            for x in l1..=k1 {
                while stack.last().is_some_and(|&(_, top)| top < x) {
                    pool.extend(stack.pop().map(|(r, _)| r));
                }
                let mut cur = pool.pop().unwrap_or_else(|| vec![T::default(); lay.width]);
                // A leaf: the row above is the row before it, kept for
                // every node whose leftmost leaf it is.
                let leaf = f.lml[x] == x;
                if leaf {
                    stack.push((std::mem::take(&mut prev), f.keyroot_of[x].min(k1)));
                }
                let src: &[T] = stack.last().map_or(&row0, |(r, _)| r);
                let up: &[T] = if leaf { src } else { &prev };
                let p = T::of(x + 1 - l1);
                self.sweep_row(&lay, (x, p, l1), (&mut cur, up, src));
                if !leaf {
                    pool.push(std::mem::take(&mut prev));
                }
                prev = cur;
            }
            pool.push(prev);
            pool.extend(stack.into_iter().map(|(r, _)| r));
        }
    }

    /// Row `p` (node `x`) of every table of `k1` (starting at `l1`): from
    /// the row above and the kept row before `lml(x)` (`src`, the top of
    /// the stack).
    fn sweep_row(
        &mut self,
        lay: &Layout,
        (x, p, l1): (usize, T, usize),
        rows: (&mut [T], &[T], &[T]),
    ) {
        let n2 = self.g.len();
        let td_row = &mut self.td[x * n2..(x + 1) * n2];
        if self.f.lml[x] == l1 {
            let lx = self.f.label[x];
            path_sweep(lay, (rows.0, rows.1), td_row, p, (lx, &self.g.label));
        } else {
            inner_sweep(lay, rows, td_row, p);
        }
    }
}

/// A row of a node `x` on `k1`'s leftmost path, all tables of `g`: against
/// nodes also on their table's leftmost path a cell is the distance of two
/// subtrees (a rename or keep after the cell diagonally above), stored in
/// `td_row`; against other nodes `y`, the insertion of the forest before
/// `y` plus the subtrees' distance.
fn path_sweep<T: Cell>(
    lay: &Layout,
    (cur, up): (&mut [T], &[T]),
    td_row: &mut [T],
    p: T,
    (lx, lg): (u32, &[u32]),
) {
    let mut left = p;
    for j in 0..lay.width {
        let (c, y) = (lay.cl[j], lay.at[j].1 as usize);
        let v = if lay.first[j] {
            p
        } else if c == 0 {
            let del = up[j].inc().min(left.inc());
            let v = del.min(up[j - 1].add(T::of(usize::from(lx != lg[y]))));
            td_row[y] = v;
            v
        } else {
            up[j].inc().min(left.inc()).min(T::of(c).add(td_row[y]))
        };
        cur[j] = v;
        left = v;
    }
}

/// A row of a node `x` off `k1`'s leftmost path, all tables of `g`:
/// deletion of `x`, insertion of `y`, or the forests before `lml(x)` and
/// `lml(y)` (row `src`) plus the distance of the subtrees of `x` and `y`.
fn inner_sweep<T: Cell>(lay: &Layout, (cur, up, src): (&mut [T], &[T], &[T]), td_row: &[T], p: T) {
    let mut left = p;
    let cols = cur.iter_mut().zip(up).zip(lay.at.iter().zip(&lay.first));
    for ((c, &u), (&(s, y), &first)) in cols {
        // At a table's first column `u + 1 = p` and the other terms are
        // at least `p` or ignored: the select keeps the loop free of
        // unpredictable branches.
        let v = u
            .inc()
            .min(left.inc())
            .min(src[s as usize].add(td_row[y as usize]));
        let v = if first { p } else { v };
        *c = v;
        left = v;
    }
}
