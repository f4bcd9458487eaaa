//! A quick upper bound for the tree edit distance: a top-down mapping that
//! pairs the roots, then aligns each mapped pair's children in order by a
//! weighted longest common subsequence (identical subtrees first, then equal
//! labels, then any child), and descends into the aligned pairs. It is a
//! valid ordered mapping (parents before children, children in order), so
//! its cost bounds the distance from above; on two versions of one policy
//! it is usually the distance or close to it, which lets `mod.rs` start the
//! exact band at that width instead of growing to it, and gives a script to
//! show when the work budget runs out.

use super::LabelledTree;
use std::collections::HashMap;

/// Children alignments larger than this many cells pair children greedily
/// by position instead.
const MAX_ALIGN_CELLS: usize = 1 << 20;

/// Arena pairs `(node of a, node of b)` of the mapping and its cost.
pub(super) fn greedy_mapping(a: &LabelledTree, b: &LabelledTree) -> (Vec<(usize, usize)>, u64) {
    let mut ids: HashMap<(u32, Vec<u32>), u32> = HashMap::new();
    let sa = signatures(a, &mut ids);
    let sb = signatures(b, &mut ids);
    let mut out = Vec::new();
    let mut stack = vec![(a.root, b.root)];
    while let Some((x, y)) = stack.pop() {
        out.push((x, y));
        let (ca, cb) = (&a.children[x], &b.children[y]);
        let score = |i: usize, j: usize| -> u32 {
            let (u, v) = (ca[i], cb[j]);
            if sa[u] == sb[v] {
                3
            } else if a.labels[u] == b.labels[v] {
                2
            } else {
                1
            }
        };
        let (n, m) = (ca.len(), cb.len());
        if n.saturating_mul(m) > MAX_ALIGN_CELLS {
            for k in 0..n.min(m) {
                stack.push((ca[k], cb[k]));
            }
            continue;
        }
        // best[i][j]: best score aligning ca[i..] with cb[j..].
        let w = m + 1;
        let mut best = vec![0u32; (n + 1) * w];
        for i in (0..n).rev() {
            for j in (0..m).rev() {
                let diag = best[(i + 1) * w + j + 1] + score(i, j);
                best[i * w + j] = diag.max(best[(i + 1) * w + j]).max(best[i * w + j + 1]);
            }
        }
        let (mut i, mut j) = (0, 0);
        while i < n && j < m {
            if best[i * w + j] == best[(i + 1) * w + j + 1] + score(i, j) {
                stack.push((ca[i], cb[j]));
                i += 1;
                j += 1;
            } else if best[i * w + j] == best[(i + 1) * w + j] {
                i += 1;
            } else {
                j += 1;
            }
        }
    }
    let (na, nb) = (a.preorder().len(), b.preorder().len());
    let renames = out
        .iter()
        .filter(|&&(x, y)| a.labels[x] != b.labels[y])
        .count();
    let cost = (na + nb - 2 * out.len() + renames) as u64;
    out.sort_unstable();
    (out, cost)
}

/// Each node's subtree signature (equal ids, identical labelled subtrees).
fn signatures(t: &LabelledTree, ids: &mut HashMap<(u32, Vec<u32>), u32>) -> Vec<u32> {
    let mut sig = vec![0u32; t.children.len()];
    let mut order = t.preorder();
    order.reverse();
    for v in order {
        let kids: Vec<u32> = t.children[v].iter().map(|&c| sig[c]).collect();
        let next = ids.len() as u32;
        sig[v] = *ids.entry((t.labels[v], kids)).or_insert(next);
    }
    sig
}
