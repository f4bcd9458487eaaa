//! The ordered labelled tree that the tree edit distance works on: nodes in
//! postorder (children left to right, then the parent), each with an interned
//! label, its leftmost leaf descendant `lml` and its parent — the
//! representation of Zhang & Shasha, "Simple fast algorithms for the editing
//! distance between trees and related problems", SIAM J. Comput. 18(6), 1989,
//! sec. 2 — plus the "keyroots" (the root and every node with a left
//! sibling) whose subtrees start the forest tables.
//!
//! Built without recursion from any arena of children lists, optionally
//! mirrored (children right to left): the ordered edit distance of two trees
//! equals that of their mirror images, and one orientation may need far
//! fewer table cells than the other (see `mod.rs`).

/// An ordered labelled tree in postorder.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct OrderedTree {
    /// Label id of each node (ids shared by the trees being compared).
    pub label: Vec<u32>,
    /// Postorder index of the leftmost leaf descendant of each node.
    pub lml: Vec<usize>,
    /// Postorder index of each node's parent (`usize::MAX` for the root).
    pub parent: Vec<usize>,
    /// For each postorder index, the index of the node in the arena it was
    /// built from.
    pub arena: Vec<usize>,
    /// Keyroots in increasing postorder: the root and every node that is not
    /// its parent's first child.
    pub keyroots: Vec<usize>,
    /// For each node, the keyroot whose leftmost path holds it (the highest
    /// ancestor-or-self with the same leftmost leaf).
    pub keyroot_of: Vec<usize>,
    /// Depth of each node (the root at 0).
    pub depth: Vec<usize>,
}

impl OrderedTree {
    /// The tree below `root` of an arena: `children[i]` are node `i`'s
    /// children in order, `label[i]` its label id. Mirrored: children read
    /// right to left. A node reached twice (an arena that is not a tree) is
    /// taken once, at its first visit in preorder.
    pub fn build(children: &[Vec<usize>], label: &[u32], root: usize, mirrored: bool) -> Self {
        let n_arena = children.len();
        let mut seen = vec![false; n_arena];
        // Explicit-stack postorder: (node, next child cursor).
        let mut order: Vec<usize> = Vec::with_capacity(n_arena);
        let mut post_parent_arena: Vec<usize> = Vec::with_capacity(n_arena);
        let mut stack: Vec<(usize, usize)> = Vec::new();
        if root < n_arena {
            seen[root] = true;
            stack.push((root, 0));
        }
        while let Some(&mut (node, ref mut cursor)) = stack.last_mut() {
            let kids = &children[node];
            let next = if *cursor < kids.len() {
                let k = if mirrored {
                    kids[kids.len() - 1 - *cursor]
                } else {
                    kids[*cursor]
                };
                *cursor += 1;
                Some(k)
            } else {
                None
            };
            match next {
                Some(k) if k < n_arena && !seen[k] => {
                    seen[k] = true;
                    stack.push((k, 0));
                }
                Some(_) => {}
                None => {
                    stack.pop();
                    order.push(node);
                    post_parent_arena.push(stack.last().map_or(usize::MAX, |&(p, _)| p));
                }
            }
        }
        let n = order.len();
        let mut post_of = vec![usize::MAX; n_arena];
        for (i, &a) in order.iter().enumerate() {
            post_of[a] = i;
        }
        let parent: Vec<usize> = post_parent_arena
            .iter()
            .map(|&p| if p == usize::MAX { p } else { post_of[p] })
            .collect();
        // lml: a node's first child comes before it in postorder and is the
        // first of its children to be visited, so one left-to-right pass
        // suffices: a node whose lml is unset is a leaf.
        let mut lml = vec![usize::MAX; n];
        let mut first_child = vec![true; n];
        let mut is_first = vec![false; n];
        for i in 0..n {
            if lml[i] == usize::MAX {
                lml[i] = i;
            }
            let p = parent[i];
            if p != usize::MAX && first_child[p] {
                first_child[p] = false;
                lml[p] = lml[i];
                is_first[i] = true;
            }
        }
        let keyroots: Vec<usize> = (0..n).filter(|&i| !is_first[i]).collect();
        // keyroot_of: walk from the top down (reverse postorder): a first
        // child shares its parent's keyroot.
        let mut keyroot_of = vec![0; n];
        let mut depth = vec![0; n];
        for i in (0..n).rev() {
            keyroot_of[i] = if is_first[i] {
                keyroot_of[parent[i]]
            } else {
                i
            };
            if parent[i] != usize::MAX {
                depth[i] = depth[parent[i]] + 1;
            }
        }
        OrderedTree {
            label: order.iter().map(|&a| label[a]).collect(),
            lml,
            parent,
            arena: order,
            keyroots,
            keyroot_of,
            depth,
        }
    }

    /// Nodes left of `x`, above it (ancestors), in its subtree, right of
    /// it: a mapping that pairs `x` with `y` maps each of these regions of
    /// one tree into the same region of the other (Zhang & Shasha's
    /// mapping conditions), so it costs at least the sum of the four size
    /// differences.
    pub fn regions(&self, x: usize) -> [usize; 4] {
        let left = self.lml[x];
        let above = self.depth[x];
        let inside = x + 1 - left;
        [left, above, inside, self.len() - left - above - inside]
    }

    pub fn len(&self) -> usize {
        self.label.len()
    }

    pub fn is_empty(&self) -> bool {
        self.label.is_empty()
    }

    /// Sum of the sizes of the keyroots' subtrees: Zhang–Shasha's table
    /// cells for this tree are this number times the other tree's.
    pub fn keyroot_weight(&self) -> u64 {
        self.keyroots
            .iter()
            .map(|&k| (k + 1 - self.lml[k]) as u64)
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// r(a(b c) d): postorder b c a d r.
    fn sample(mirrored: bool) -> OrderedTree {
        let children = vec![vec![1, 4], vec![2, 3], vec![], vec![], vec![]];
        OrderedTree::build(&children, &[0, 1, 2, 3, 4], 0, mirrored)
    }

    #[test]
    fn postorder_leftmost_leaves_and_keyroots() {
        let t = sample(false);
        assert_eq!(t.label, vec![2, 3, 1, 4, 0]);
        assert_eq!(t.lml, vec![0, 1, 0, 3, 0]);
        assert_eq!(t.parent, vec![2, 2, 4, 4, usize::MAX]);
        assert_eq!(t.keyroots, vec![1, 3, 4]);
        assert_eq!(t.keyroot_of, vec![4, 1, 4, 3, 4]);
        assert_eq!(t.keyroot_weight(), 1 + 1 + 5);
    }

    #[test]
    fn mirrored_reads_children_right_to_left() {
        // r(d a(c b)): postorder d c b a r.
        let t = sample(true);
        assert_eq!(t.label, vec![4, 3, 2, 1, 0]);
        assert_eq!(t.arena, vec![4, 3, 2, 1, 0]);
        assert_eq!(t.lml, vec![0, 1, 2, 1, 0]);
    }

    #[test]
    fn a_node_reached_twice_is_taken_once() {
        let children = vec![vec![1, 1], vec![0]];
        let t = OrderedTree::build(&children, &[7, 8], 0, false);
        assert_eq!(t.label, vec![8, 7]);
    }
}
