//! A "staircase" band of a two-dimensional table: row `r` stores only the
//! columns `[lo(r), hi(r)]` (inclusive), where `lo` and `hi` never decrease
//! from one row to the next, as for the cells `dlo ≤ column − row ≤ dhi` of
//! a table clipped to its column range. Cells outside are "infinite" when
//! read.
//! It is how the banded tree edit distance (`zs.rs`) keeps both its
//! subtree-distance table and its forest tables in O(n·u) cells.

/// A value larger than any distance (distances are at most the sum of both
/// trees' sizes, far below this), small enough that adding a distance to it
/// does not overflow.
pub(super) const INF: u32 = u32::MAX / 4;

#[derive(Debug, Default)]
pub(super) struct Stair {
    /// First row index.
    pub row0: usize,
    pub lo: Vec<usize>,
    pub hi: Vec<usize>,
    /// Offset of each row's first cell in `data`.
    pub off: Vec<usize>,
    pub data: Vec<u32>,
}

impl Stair {
    /// Cells of the band `dlo ≤ c − r ≤ dhi` over rows `rows` and columns
    /// `cols` (inclusive ranges), without allocating.
    pub(super) fn cells(rows: (usize, usize), cols: (usize, usize), d: (i64, i64)) -> u64 {
        (rows.0..=rows.1)
            .map(|r| {
                let (lo, hi) = window(r, cols, d);
                (hi + 1).saturating_sub(lo) as u64
            })
            .sum()
    }

    /// Re-shapes the band to rows `rows.0..=rows.1`, columns within `cols`
    /// and `dlo ≤ c − r ≤ dhi`, every cell infinite; reuses the allocation.
    pub(super) fn reset(&mut self, rows: (usize, usize), cols: (usize, usize), d: (i64, i64)) {
        self.row0 = rows.0;
        self.lo.clear();
        self.hi.clear();
        self.off.clear();
        let mut total = 0;
        for r in rows.0..=rows.1 {
            let (lo, hi) = window(r, cols, d);
            self.lo.push(lo);
            self.hi.push(hi);
            self.off.push(total);
            total += (hi + 1).saturating_sub(lo);
        }
        self.data.clear();
        self.data.resize(total, INF);
    }

    /// The window of row `r`: `(lo, hi)`, empty when `lo > hi`.
    #[cfg(test)]
    pub(super) fn row_window(&self, r: usize) -> (usize, usize) {
        let i = r - self.row0;
        (self.lo[i], self.hi[i])
    }

    #[inline]
    pub(super) fn get(&self, r: usize, c: usize) -> u32 {
        let Some(i) = r.checked_sub(self.row0) else {
            return INF;
        };
        if i >= self.lo.len() || c < self.lo[i] || c > self.hi[i] {
            return INF;
        }
        self.data[self.off[i] + c - self.lo[i]]
    }

    /// Sets a cell inside the band (a cell outside is ignored).
    #[cfg(test)]
    pub(super) fn set(&mut self, r: usize, c: usize, v: u32) {
        let Some(i) = r.checked_sub(self.row0) else {
            return;
        };
        if i < self.lo.len() && c >= self.lo[i] && c <= self.hi[i] {
            self.data[self.off[i] + c - self.lo[i]] = v;
        }
    }

    /// Cells stored.
    #[cfg(test)]
    pub(super) fn len(&self) -> usize {
        self.data.len()
    }
}

/// Columns of row `r` in the band: `cols` clipped to `[r + dlo, r + dhi]`
/// (empty, `lo > hi`, when they miss).
#[inline]
fn window(r: usize, cols: (usize, usize), d: (i64, i64)) -> (usize, usize) {
    let r = r as i64;
    let lo = (cols.0 as i64).max(r + d.0);
    let hi = (cols.1 as i64).min(r + d.1);
    if hi < lo || hi < 0 {
        (1, 0)
    } else {
        (lo as usize, hi as usize)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_outside_the_band_read_infinite() {
        let mut s = Stair::default();
        s.reset((2, 5), (0, 9), (-1, 1));
        assert_eq!(s.row_window(2), (1, 3));
        assert_eq!(s.row_window(5), (4, 6));
        assert_eq!(s.len(), 12);
        assert_eq!(Stair::cells((2, 5), (0, 9), (-1, 1)), 12);
        assert_eq!(Stair::cells((0, 3), (5, 9), (-1, 1)), 0);
        s.set(3, 4, 7);
        assert_eq!(s.get(3, 4), 7);
        assert_eq!(s.get(3, 5), INF);
        assert_eq!(s.get(1, 1), INF);
        assert_eq!(s.get(6, 6), INF);
        s.set(3, 9, 1);
        assert_eq!(s.get(3, 9), INF);
    }
}
