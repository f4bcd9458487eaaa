//! The Levenshtein (string edit) distance of two label sequences, and one
//! optimal alignment, by Myers' bit-vector algorithm (G. Myers, "A fast
//! bit-vector algorithm for approximate string matching based on dynamic
//! programming", J. ACM 46(3), 1999: the block-based form, one 64-row word
//! at a time) made global — the first row of the table counts `0, 1, 2, …`
//! — by feeding a +1 horizontal delta into the first block of every column
//! (as in H. Hyyrö, "A bit-vector algorithm for computing Levenshtein and
//! Damerau edit distances", Nordic J. Computing 10, 2003).
//!
//! Column `j` of the table (`j` symbols of `b` read) is kept as two bit
//! vectors over the rows: `pv` has bit `i` set when `D[i+1][j] − D[i][j] =
//! +1`, `mv` when it is −1. The whole table is `n·m` cells; one word step
//! computes 64 of them. For an alignment, every column's vectors are kept
//! (`2·m·⌈n/64⌉` words) and walked back from `(n, m)`.
//!
//! `bounds.rs` uses it on the preorder and postorder label sequences
//! of two trees: both distances bound the tree edit distance from below.

use std::collections::HashMap;

/// Words per column for `n` rows.
pub(super) fn blocks(n: usize) -> usize {
    n.div_ceil(64)
}

/// The pattern `a` as one bit mask per distinct symbol: bit `i` of
/// `masks[k]` is set when `a[i]` is the `k`-th symbol.
struct Peq {
    index: HashMap<u32, usize>,
    masks: Vec<u64>,
    blocks: usize,
}

impl Peq {
    fn new(a: &[u32]) -> Self {
        let blocks = blocks(a.len());
        let mut index = HashMap::new();
        let mut masks = Vec::new();
        for (i, &s) in a.iter().enumerate() {
            let next = index.len();
            let k = *index.entry(s).or_insert(next);
            if k == next {
                masks.resize(masks.len() + blocks, 0);
            }
            masks[k * blocks + i / 64] |= 1 << (i % 64);
        }
        Peq {
            index,
            masks,
            blocks,
        }
    }

    /// The masks of symbol `s` (`None`: it does not occur in `a`).
    fn of(&self, s: u32) -> Option<&[u64]> {
        self.index
            .get(&s)
            .map(|&k| &self.masks[k * self.blocks..(k + 1) * self.blocks])
    }
}

/// One word step of Myers' algorithm: updates the vertical deltas
/// `(pv, mv)` of one 64-row block for a column with match mask `eq`, given
/// the horizontal delta `hin` entering the block's top, and returns the
/// horizontal delta leaving its row `top` (63, or the last row of `a`).
#[inline]
fn advance(pv: &mut u64, mv: &mut u64, eq: u64, hin: i32, top: u32) -> i32 {
    let (p, m) = (*pv, *mv);
    let xv = eq | m;
    let eq = if hin < 0 { eq | 1 } else { eq };
    let xh = ((eq & p).wrapping_add(p) ^ p) | eq;
    let mut ph = m | !(xh | p);
    let mut mh = p & xh;
    let hout = ((ph >> top) & 1) as i32 - ((mh >> top) & 1) as i32;
    ph <<= 1;
    mh <<= 1;
    if hin < 0 {
        mh |= 1;
    } else if hin > 0 {
        ph |= 1;
    }
    *pv = mh | !(xv | ph);
    *mv = ph & xv;
    hout
}

/// Runs the columns of `b` over the pattern `a` (`⌈n/64⌉·m` word steps),
/// calling `column(j, pv, mv)` after each column `j ≥ 1`; returns `D[n][m]`.
fn sweep(a: &[u32], b: &[u32], mut column: impl FnMut(usize, &[u64], &[u64])) -> u32 {
    let n = a.len();
    if n == 0 {
        return b.len() as u32;
    }
    let peq = Peq::new(a);
    let nb = peq.blocks;
    let mut pv = vec![u64::MAX; nb];
    let mut mv = vec![0u64; nb];
    let last_top = ((n - 1) % 64) as u32;
    let zeros = vec![0u64; nb];
    let mut score = n as i64;
    for (j, &s) in b.iter().enumerate() {
        let eqs = peq.of(s).unwrap_or(&zeros);
        let mut h = 1;
        for k in 0..nb {
            let top = if k + 1 == nb { last_top } else { 63 };
            h = advance(&mut pv[k], &mut mv[k], eqs[k], h, top);
        }
        score += i64::from(h);
        column(j + 1, &pv, &mv);
    }
    score as u32
}

/// Word steps [`distance`] takes.
pub(super) fn distance_work(n: usize, m: usize) -> u64 {
    (blocks(n) * m) as u64
}

/// 4-byte cells [`distance`] holds at most: the pattern's masks (at most
/// one per row) and three working columns.
pub(super) fn distance_cells(n: usize) -> u64 {
    (blocks(n) * (2 * n + 6)) as u64
}

/// The Levenshtein distance alone, in `O(⌈n/64⌉)` words besides the masks.
pub(super) fn distance(a: &[u32], b: &[u32]) -> u32 {
    sweep(a, b, |_, _, _| {})
}

/// Word steps [`alignment`] takes at most: the sweep, one prefix count
/// per column on the walk back, and one step per row and column.
pub(super) fn alignment_work(n: usize, m: usize) -> u64 {
    (2 * blocks(n) * m + n + m + 1) as u64
}

/// 4-byte cells [`alignment`] holds at most: both vectors of every column,
/// the pattern's masks (at most one per row) and three working columns.
pub(super) fn alignment_cells(n: usize, m: usize) -> u64 {
    (blocks(n) * (4 * m + 2 * n + 6)) as u64
}

/// The distance and the pairs `(i, j)` of one optimal alignment that
/// matches or substitutes `a[i]` with `b[j]`, increasing in both.
pub(super) fn alignment(a: &[u32], b: &[u32]) -> (u32, Vec<(usize, usize)>) {
    let (n, m) = (a.len(), b.len());
    let nb = blocks(n);
    let mut cols: Vec<u64> = Vec::with_capacity(2 * nb * m);
    let d = sweep(a, b, |_, pv, mv| {
        cols.extend_from_slice(pv);
        cols.extend_from_slice(mv);
    });
    // The vertical delta D[i+1][j] − D[i][j] (column 0: all +1).
    let delta = |i: usize, j: usize| -> i64 {
        if j == 0 {
            return 1;
        }
        let base = 2 * nb * (j - 1) + i / 64;
        let bit = 1u64 << (i % 64);
        i64::from(cols[base] & bit != 0) - i64::from(cols[base + nb] & bit != 0)
    };
    // D[i][j] by a prefix count of column j's deltas.
    let value = |i: usize, j: usize| -> i64 {
        if j == 0 {
            return i as i64;
        }
        let base = 2 * nb * (j - 1);
        let (pv, mv) = (&cols[base..base + nb], &cols[base + nb..base + 2 * nb]);
        let mut v = j as i64;
        let full = i / 64;
        for k in 0..full {
            v += i64::from(pv[k].count_ones()) - i64::from(mv[k].count_ones());
        }
        if !i.is_multiple_of(64) {
            let mask = (1u64 << (i % 64)) - 1;
            v += i64::from((pv[full] & mask).count_ones())
                - i64::from((mv[full] & mask).count_ones());
        }
        v
    };
    // Walk back from (n, m) with D[i][j] and D[i][j − 1] at hand: a step up
    // updates both by one delta each, a step left or diagonal counts the
    // new left column once.
    let mut pairs = Vec::new();
    let (mut i, mut j) = (n, m);
    let mut cur = i64::from(d);
    let mut left = if j > 0 { value(i, j - 1) } else { 0 };
    while i > 0 && j > 0 {
        let diag = left - delta(i - 1, j - 1);
        if cur == diag + i64::from(a[i - 1] != b[j - 1]) {
            pairs.push((i - 1, j - 1));
            i -= 1;
            j -= 1;
            cur = diag;
            left = if j > 0 { value(i, j - 1) } else { 0 };
            continue;
        }
        let up = cur - delta(i - 1, j);
        if cur == up + 1 {
            i -= 1;
            cur = up;
            left = diag;
        } else {
            // Left: the only step left (the table is a valid one).
            j -= 1;
            cur = left;
            left = if j > 0 { value(i, j - 1) } else { 0 };
        }
    }
    pairs.reverse();
    (d, pairs)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The textbook table, row by row.
    fn plain(a: &[u32], b: &[u32]) -> u32 {
        let mut prev: Vec<u32> = (0..=b.len() as u32).collect();
        for (i, &x) in a.iter().enumerate() {
            let mut cur = vec![i as u32 + 1; b.len() + 1];
            for (j, &y) in b.iter().enumerate() {
                cur[j + 1] = (prev[j] + u32::from(x != y))
                    .min(prev[j + 1] + 1)
                    .min(cur[j] + 1);
            }
            prev = cur;
        }
        prev[b.len()]
    }

    fn rng(state: &mut u64) -> u64 {
        *state = state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = *state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }

    #[test]
    fn bit_vectors_agree_with_the_table_and_the_alignment_costs_the_distance() {
        let mut s = 17u64;
        for round in 0..3000 {
            // Lengths across block borders (63, 64, 65, 128, …).
            let max = if round % 10 == 0 { 200 } else { 70 };
            let n = (rng(&mut s) % max) as usize;
            let m = (rng(&mut s) % max) as usize;
            let sigma = 1 + rng(&mut s) % 5;
            let a: Vec<u32> = (0..n).map(|_| (rng(&mut s) % sigma) as u32).collect();
            let b: Vec<u32> = (0..m).map(|_| (rng(&mut s) % sigma + 1) as u32).collect();
            let d = plain(&a, &b);
            assert_eq!(distance(&a, &b), d, "{a:?} {b:?}");
            let (d2, pairs) = alignment(&a, &b);
            assert_eq!(d2, d);
            let subs = pairs.iter().filter(|&&(i, j)| a[i] != b[j]).count();
            assert_eq!((n + m - 2 * pairs.len() + subs) as u32, d);
            for w in pairs.windows(2) {
                assert!(w[0].0 < w[1].0 && w[0].1 < w[1].1);
            }
        }
    }

    #[test]
    fn empty_and_equal_sequences() {
        assert_eq!(alignment(&[], &[1, 2]), (2, vec![]));
        assert_eq!(alignment(&[1, 2, 3], &[]), (3, vec![]));
        let long: Vec<u32> = (0..300).map(|i| i % 7).collect();
        assert_eq!(
            alignment(&long, &long),
            (0, (0..300).map(|i| (i, i)).collect())
        );
    }
}
