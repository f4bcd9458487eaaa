//! The compiled reactive skeleton of a BT ([`Plan`]): the short-circuit
//! evaluation of its ReactiveSequence/ReactiveFallback nodes as a table of
//! successors (see the module doc of [`super`]), and where a RUNNING slot is
//! halted when a tick leaves it (BehaviorTree.CPP's `haltChild` and
//! `resetChildren` of the reactive nodes, src/controls/reactive_*.cpp).

use super::bt::XNode;
use super::ops::Op;

/// The tree's reactive skeleton — the root and the reactive Sequence and
/// Fallback nodes below it through reactive nodes only — compiled to a table
/// of slots: every other node under the skeleton (a leaf, or a subtree whose
/// root keeps memory or is not a reactive composite) is a slot, with the slot
/// to tick next when it succeeds and when it fails. A reactive composite
/// returns RUNNING as soon as a child does, so a RUNNING slot ends the tick.
/// This is the short-circuit evaluation of an and/or tree; it visits the
/// same leaves in the same order as the stack walk, without the frames. At
/// most one slot is RUNNING between ticks (a reactive composite halts its
/// other children when one runs); it is halted when a tick leaves the
/// skeleton node that holds it without ticking it again.
#[derive(Debug, Default)]
pub(super) struct Plan {
    pub(super) slots: Vec<Slot>,
    /// The slot ticked first (or the tick's status, for an empty composite).
    pub(super) first: usize,
    /// Whether a recording tick can go through the plan: every skeleton
    /// composite has children (an empty one is never visited, so it would
    /// not be noted; valid files have none).
    pub(super) records: bool,
}

/// A slot's successors: a slot index, [`DONE_SUCCESS`] or [`DONE_FAILURE`];
/// the skeleton composite where each successor continues (its ancestors
/// below it are left with the slot's status; [`NO_NODE`]: every ancestor is
/// left), and the highest node left (a RUNNING slot inside it is halted).
#[derive(Debug, Clone, Copy)]
pub(super) struct Slot {
    pub(super) node: usize,
    pub(super) on_success: usize,
    pub(super) on_failure: usize,
    pub(super) stop_success: usize,
    pub(super) stop_failure: usize,
}

/// No node (above the root), no slot.
pub(super) const NO_NODE: usize = usize::MAX;

/// The root succeeds.
pub(super) const DONE_SUCCESS: usize = usize::MAX;
/// The root fails.
pub(super) const DONE_FAILURE: usize = usize::MAX - 1;

impl Plan {
    /// Builds the table without recursion: children are visited last to
    /// first, so that a child's successor (its next sibling's first slot) is
    /// known when the child is visited.
    pub(super) fn new(nodes: &[XNode], kids: &[u32], root: usize) -> Plan {
        /// Where a node's status sends the tick: (slot or DONE_*, the
        /// composite where it continues or NO_NODE, the highest node left).
        type Cont = (usize, usize, usize);
        enum Work {
            /// Visit a node with its successors on success and on failure;
            /// leaves its first slot on `firsts`.
            Visit(usize, Cont, Cont),
            /// Visit child `i` of the composite `p` (whose successors are
            /// given); for all but the last child, the next child's first
            /// slot is on top of `firsts`.
            Child(usize, usize, Cont, Cont),
        }
        let reactive = |n: usize| matches!(nodes[n].op, Op::Sequence | Op::Fallback);
        let kids_of = |n: usize| &kids[nodes[n].start as usize..nodes[n].end as usize];
        let mut slots = Vec::new();
        let mut firsts: Vec<usize> = Vec::new();
        let mut records = true;
        let mut work = vec![Work::Visit(
            root,
            (DONE_SUCCESS, NO_NODE, root),
            (DONE_FAILURE, NO_NODE, root),
        )];
        while let Some(w) = work.pop() {
            match w {
                Work::Visit(n, on_success, on_failure) => {
                    if !reactive(n) {
                        slots.push(Slot {
                            node: n,
                            on_success: on_success.0,
                            on_failure: on_failure.0,
                            stop_success: on_success.1,
                            stop_failure: on_failure.1,
                        });
                        firsts.push(slots.len() - 1);
                    } else if kids_of(n).is_empty() {
                        // Sequence() succeeds and Fallback() fails at once.
                        let seq = nodes[n].op == Op::Sequence;
                        firsts.push(if seq { on_success.0 } else { on_failure.0 });
                        records = false;
                    } else {
                        let last = kids_of(n).len() - 1;
                        work.push(Work::Child(n, last, on_success, on_failure));
                    }
                }
                Work::Child(p, i, on_success, on_failure) => {
                    let k = kids_of(p);
                    let (s, f) = if i + 1 == k.len() {
                        (on_success, on_failure)
                    } else {
                        let next = (firsts.pop().unwrap_or(DONE_FAILURE), p, k[i] as usize);
                        if nodes[p].op == Op::Sequence {
                            (next, on_failure)
                        } else {
                            (on_success, next)
                        }
                    };
                    if i > 0 {
                        work.push(Work::Child(p, i - 1, on_success, on_failure));
                    }
                    work.push(Work::Visit(k[i] as usize, s, f));
                }
            }
        }
        Plan {
            slots,
            first: firsts.pop().unwrap_or(DONE_FAILURE),
            records,
        }
    }
}
