//! Bounds of the tree edit distance from the trees' label sequences, cheap
//! enough (`n·m/64` word steps, `sed.rs`) for two unrelated 10,000-node trees.
//!
//! Lower: a mapping of the trees keeps both the preorder and the postorder
//! of the nodes it pairs (Zhang & Shasha, SIAM J. Comput. 1989: `x₁` is an
//! ancestor of `x₂` iff it comes first in preorder and last in postorder,
//! left of it iff first in both), so it is an alignment of the preorder
//! label sequences, and one of the postorder ones, of the same cost: each
//! sequence's Levenshtein distance bounds the tree distance from below
//! (Guha, Jagadish, Koudas, Srivastava, Yu, SIGMOD 2002). The Euler
//! strings (each node's label opening before its subtree and closing after
//! it) change by at most two symbols per tree edit, so half their distance
//! is a lower bound too (Akutsu, Fukagawa, Takasu, ISAAC 2006); it is often
//! the strongest of the three on unrelated trees.
//!
//! Upper: conversely, pairs that keep both orders are a mapping. Of an
//! optimal postorder alignment, the pairs whose preorder ranks also
//! increase together — a heaviest increasing subsequence, a kept pair
//! weighing 2 (1 when renamed) since a mapping costs `n₁ + n₂ − Σ weights`
//! — form a mapping; likewise of a preorder alignment, in postorder. The
//! cheaper one is returned. On a tree and an edited copy both alignments
//! mostly follow the edits, and the two bounds often meet.

use super::sed;
use super::tree::OrderedTree;

/// Both bounds, the mapping of cost `upper` (postorder pairs, sorted) and
/// what computing them took.
#[derive(Debug, Clone)]
pub(super) struct SeqBounds {
    pub lower: u64,
    pub upper: u64,
    pub mapping: Vec<(usize, usize)>,
    /// Word steps of the alignments (each 64 cells) plus the pairs sorted.
    pub work: u64,
    /// Most 4-byte cells held at once.
    pub peak: u64,
}

/// Work [`sequence_bounds`] does at most on trees of `n1` and `n2` nodes.
pub(super) fn work(n1: usize, n2: usize) -> u64 {
    2 * (sed::alignment_work(n1, n2) + n1.min(n2) as u64) + sed::distance_work(2 * n1, 2 * n2)
}

/// Cells [`sequence_bounds`] holds at most: one alignment's or the Euler
/// strings' distance, plus the orders, Euler strings, pairs and the
/// increasing-subsequence arrays.
pub(super) fn cells(n1: usize, n2: usize) -> u64 {
    sed::alignment_cells(n1, n2).max(sed::distance_cells(2 * n1))
        + 8 * (n1 + n2) as u64
        + 8 * n1.min(n2) as u64
}

/// Preorder of a postorder tree: the postorder indices in preorder, each
/// node's preorder rank, and the Euler string (label `l` opens as `2l`,
/// closes as `2l + 1`).
fn preorder(t: &OrderedTree) -> (Vec<usize>, Vec<usize>, Vec<u32>) {
    let n = t.len();
    // Children lists (increasing postorder = left to right), as offsets.
    let mut count = vec![0usize; n + 1];
    for x in 0..n {
        if t.parent[x] != usize::MAX {
            count[t.parent[x] + 1] += 1;
        }
    }
    for x in 0..n {
        count[x + 1] += count[x];
    }
    let mut fill = count.clone();
    let mut kids = vec![0usize; n.saturating_sub(1)];
    for x in 0..n {
        let p = t.parent[x];
        if p != usize::MAX {
            kids[fill[p]] = x;
            fill[p] += 1;
        }
    }
    let mut order = Vec::with_capacity(n);
    let mut euler = Vec::with_capacity(2 * n);
    // (node, closing): a node is pushed again to close after its children.
    let mut stack: Vec<(usize, bool)> = (0..n)
        .filter(|&x| t.parent[x] == usize::MAX)
        .rev()
        .map(|x| (x, false))
        .collect();
    while let Some((x, closing)) = stack.pop() {
        // Ids from 2³¹ on share symbols: coarser labels only lower the
        // distance, which stays a lower bound.
        let l = t.label[x].wrapping_mul(2);
        if closing {
            euler.push(l | 1);
            continue;
        }
        order.push(x);
        euler.push(l);
        stack.push((x, true));
        stack.extend(
            kids[count[x]..count[x + 1]]
                .iter()
                .rev()
                .map(|&c| (c, false)),
        );
    }
    let mut rank = vec![0usize; n];
    for (i, &x) in order.iter().enumerate() {
        rank[x] = i;
    }
    (order, rank, euler)
}

/// The heaviest subset of `pairs` (one-to-one, `(x, y)`) whose `kf` and `kg`
/// keys increase together; each pair weighs `weight(x, y)` (> 0). Returns
/// the subset and its weight.
fn heaviest_chain(
    mut pairs: Vec<(usize, usize)>,
    kf: &[usize],
    kg: &[usize],
    weight: impl Fn(usize, usize) -> u64,
) -> (Vec<(usize, usize)>, u64) {
    pairs.sort_unstable_by_key(|&(x, _)| kf[x]);
    let size = kg.len();
    // Fenwick tree of prefix maxima over kg: (best weight, pair index + 1).
    let mut fen = vec![(0u64, 0usize); size + 1];
    let mut best = vec![0u64; pairs.len()];
    let mut prev = vec![usize::MAX; pairs.len()];
    let mut top = (0u64, 0usize);
    for (i, &(x, y)) in pairs.iter().enumerate() {
        // Best chain ending below kg[y].
        let mut q = kg[y];
        let mut here = (0u64, 0usize);
        while q > 0 {
            here = here.max(fen[q]);
            q &= q - 1;
        }
        best[i] = here.0 + weight(x, y);
        prev[i] = here.1.wrapping_sub(1);
        let entry = (best[i], i + 1);
        top = top.max(entry);
        let mut q = kg[y] + 1;
        while q <= size {
            fen[q] = fen[q].max(entry);
            q += q & q.wrapping_neg();
        }
    }
    let mut out = Vec::new();
    let mut i = top.1.wrapping_sub(1);
    while i != usize::MAX {
        out.push(pairs[i]);
        i = prev[i];
    }
    out.sort_unstable();
    (out, top.0)
}

/// Lower and upper bounds of the distance of `f` and `g` (both non-empty)
/// from their preorder and postorder label sequences.
pub(super) fn sequence_bounds(f: &OrderedTree, g: &OrderedTree) -> SeqBounds {
    let (n1, n2) = (f.len(), g.len());
    let (pre_f, rank_f, euler_f) = preorder(f);
    let (pre_g, rank_g, euler_g) = preorder(g);
    let d_euler = sed::distance(&euler_f, &euler_g).div_ceil(2);
    let post_f: Vec<usize> = (0..n1).collect();
    let post_g: Vec<usize> = (0..n2).collect();
    let weight = |x: usize, y: usize| 2 - u64::from(f.label[x] != g.label[y]);
    let mut work = sed::distance_work(euler_f.len(), euler_g.len());
    // Postorder alignment, kept where preorder agrees.
    let (d_post, pairs) = sed::alignment(&f.label, &g.label);
    work += sed::alignment_work(n1, n2) + pairs.len() as u64;
    let (m_post, w_post) = heaviest_chain(pairs, &rank_f, &rank_g, weight);
    // Preorder alignment (as postorder nodes), kept where postorder agrees.
    let la: Vec<u32> = pre_f.iter().map(|&x| f.label[x]).collect();
    let lb: Vec<u32> = pre_g.iter().map(|&y| g.label[y]).collect();
    let (d_pre, pairs) = sed::alignment(&la, &lb);
    work += sed::alignment_work(n1, n2) + pairs.len() as u64;
    let pairs = pairs
        .into_iter()
        .map(|(i, j)| (pre_f[i], pre_g[j]))
        .collect();
    let (m_pre, w_pre) = heaviest_chain(pairs, &post_f, &post_g, weight);
    let (mapping, w) = if w_pre > w_post {
        (m_pre, w_pre)
    } else {
        (m_post, w_post)
    };
    SeqBounds {
        lower: u64::from(d_post.max(d_pre).max(d_euler)),
        upper: (n1 + n2) as u64 - w,
        mapping,
        work,
        peak: cells(n1, n2),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn preorder_of_a_postorder_tree() {
        // r(a(b c) d): postorder b c a d r; preorder r a b c d.
        let children = vec![vec![1, 4], vec![2, 3], vec![], vec![], vec![]];
        let t = OrderedTree::build(&children, &[0, 1, 2, 3, 4], 0, false);
        let (order, rank, euler) = preorder(&t);
        assert_eq!(order, vec![4, 2, 0, 1, 3]);
        assert_eq!(rank, vec![2, 3, 1, 4, 0]);
        assert_eq!(euler, vec![0, 2, 4, 5, 6, 7, 3, 8, 9, 1]);
    }

    #[test]
    fn heaviest_chain_keeps_pairs_increasing_in_both_keys() {
        // Keys: pair (0,0) and (1,2) agree; (2,1) crosses (1,2).
        let kf = [0, 1, 2];
        let kg = [0, 2, 1];
        let (chain, w) = heaviest_chain(vec![(0, 0), (1, 1), (2, 2)], &kf, &kg, |x, _| {
            if x == 1 { 1 } else { 2 }
        });
        assert_eq!((chain, w), (vec![(0, 0), (2, 2)], 4));
    }
}
