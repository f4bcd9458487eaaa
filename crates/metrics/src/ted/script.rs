//! The edit script of a tree mapping: every pair of mapped nodes whose labels
//! differ is a rename, every node of a left unmapped a deletion, every node
//! of b left unmapped an insertion (Tai, "The tree-to-tree correction
//! problem", J. ACM 26(3), 1979: the cost of a mapping is that of these
//! operations). A whole subtree deleted from a whose identical copy (same
//! labels, same shape) is inserted whole into b is told as one move; it
//! still costs its deletions plus its insertions, so the script's cost is the
//! mapping's cost.

use super::LabelledTree;
use std::collections::{BTreeMap, HashMap};

/// One step of the script, in arena indices of a and b.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum TreeEdit {
    /// Node `a` becomes node `b` with another label.
    Rename {
        a: usize,
        b: usize,
    },
    Delete {
        a: usize,
    },
    Insert {
        b: usize,
    },
    /// The subtree at `a` (of `size` nodes) is deleted and inserted
    /// identically at `b`.
    Move {
        a: usize,
        b: usize,
        size: usize,
    },
}

impl TreeEdit {
    /// Unit operations this step stands for.
    pub fn cost(&self) -> u64 {
        match self {
            TreeEdit::Move { size, .. } => 2 * *size as u64,
            _ => 1,
        }
    }
}

/// The script of `mapping` (arena pairs `(a, b)`), in the order renames,
/// moves, deletions, insertions, each by arena index.
pub fn edit_script(
    a: &LabelledTree,
    b: &LabelledTree,
    mapping: &[(usize, usize)],
) -> Vec<TreeEdit> {
    let mut mapped_a = vec![false; a.children.len()];
    let mut mapped_b = vec![false; b.children.len()];
    let mut out = Vec::new();
    for &(x, y) in mapping {
        mapped_a[x] = true;
        mapped_b[y] = true;
        if a.labels[x] != b.labels[y] {
            out.push(TreeEdit::Rename { a: x, b: y });
        }
    }
    // Identical subtrees share a signature id: (label, children's ids).
    let mut ids: HashMap<(u32, Vec<u32>), u32> = HashMap::new();
    let (sa, size_a, whole_a) = signatures(a, &mapped_a, &mut ids);
    let (sb, size_b, whole_b) = signatures(b, &mapped_b, &mut ids);
    // Maximal wholly-unmapped subtrees, in preorder.
    let maximal = |t: &LabelledTree, whole: &[bool]| -> Vec<usize> {
        let mut out = Vec::new();
        let mut stack = vec![t.root];
        while let Some(n) = stack.pop() {
            if whole[n] {
                out.push(n);
            } else {
                stack.extend(t.children[n].iter().rev().copied());
            }
        }
        out
    };
    let mut inserted: BTreeMap<u32, Vec<usize>> = BTreeMap::new();
    for r in maximal(b, &whole_b).into_iter().rev() {
        inserted.entry(sb[r]).or_default().push(r);
    }
    let mut moved_a = vec![false; a.children.len()];
    let mut moved_b = vec![false; b.children.len()];
    for r in maximal(a, &whole_a) {
        if let Some(to) = inserted.get_mut(&sa[r]).and_then(|v| v.pop()) {
            out.push(TreeEdit::Move {
                a: r,
                b: to,
                size: size_a[r],
            });
            debug_assert_eq!(size_a[r], size_b[to]);
            mark(a, r, &mut moved_a);
            mark(b, to, &mut moved_b);
        }
    }
    for n in a.preorder() {
        if !mapped_a[n] && !moved_a[n] {
            out.push(TreeEdit::Delete { a: n });
        }
    }
    for n in b.preorder() {
        if !mapped_b[n] && !moved_b[n] {
            out.push(TreeEdit::Insert { b: n });
        }
    }
    out
}

/// Each node's subtree signature and size, and whether its whole subtree is
/// unmapped; bottom-up over a postorder (no recursion).
fn signatures(
    t: &LabelledTree,
    mapped: &[bool],
    ids: &mut HashMap<(u32, Vec<u32>), u32>,
) -> (Vec<u32>, Vec<usize>, Vec<bool>) {
    let n = t.children.len();
    let mut sig = vec![0u32; n];
    let mut size = vec![1usize; n];
    let mut whole = vec![false; n];
    let mut order = t.preorder();
    order.reverse();
    for v in order {
        let kids: Vec<u32> = t.children[v].iter().map(|&c| sig[c]).collect();
        size[v] = 1 + t.children[v].iter().map(|&c| size[c]).sum::<usize>();
        whole[v] = !mapped[v] && t.children[v].iter().all(|&c| whole[c]);
        let next = ids.len() as u32;
        sig[v] = *ids.entry((t.labels[v], kids)).or_insert(next);
    }
    (sig, size, whole)
}

fn mark(t: &LabelledTree, root: usize, flag: &mut [bool]) {
    let mut stack = vec![root];
    while let Some(n) = stack.pop() {
        flag[n] = true;
        stack.extend(t.children[n].iter().copied());
    }
}
