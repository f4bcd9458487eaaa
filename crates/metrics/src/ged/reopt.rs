//! When a node below the root re-optimises the ascent's shares
//! (`search.rs`), as a MIP solver re-solves its relaxation at every node.
//! Only a node that would branch under the shares it inherits is a
//! candidate; re-optimising costs about as much as a few hundred plain
//! nodes and pays only where it prunes a large subtree, so the search keeps,
//! per depth, the average work of the subtrees it finished there (nodes that
//! branched) and the average work of a re-optimisation, and re-optimises at
//! a depth whose subtrees cost at least `ratio` re-optimisations. Work is
//! counted, so the choice is the same on any machine.
//!
//! Measured on the 20 FSM-like pair-modes of `bench/ged_vs_highs.py` (seed
//! 2017, default budget; docs/performance.md): 13 exact before, 17 with
//! this and the single seeded structural search of `mod.rs` (labeled fsm-7,
//! structural fsm-1, fsm-2, fsm-4). Fixed depths instead of the measured
//! rule (re-optimise down to depth 1, 2, 3, 4, 6 or 10) settled 13 or 14
//! and swung with the depth; ratios 2, 4 or 8 re-optimised too rarely
//! (fsm-7 labeled stayed open); 5 ascent steps settled one more pair than
//! 0 or 20; 30 subgradient steps settled as many as 50 or 100, for less.

/// Depths re-optimised before anything is known about their subtrees.
const BLIND_DEPTH: usize = 2;
/// Most bytes of saved shares and local values held at once by the nodes
/// on the search's stack that re-optimised (each holds one copy, up to
/// 8 bytes per arc pair and per vertex pair: 4.5 MB at `ascent`'s limits);
/// past it a node does not re-optimise.
pub(super) const MAX_HELD_BYTES: usize = 64 << 20;
/// Re-optimise where a subtree costs at least this many re-optimisations.
pub(super) const RATIO: u64 = 1;
/// A re-optimisation: at most this many ascent steps, then at most this
/// many subgradient steps, ending once the Polyak factor has been halved
/// more than `MAX_HALVINGS` times (`root.rs`).
pub(super) const STEPS: usize = 5;
pub(super) const SHAKES: usize = 30;
pub(super) const MAX_HALVINGS: usize = 1;

#[derive(Debug)]
pub(super) struct Reopt {
    ratio: u64,
    /// (sum, count) of the work of finished subtrees, by depth.
    sub: Vec<(u64, u64)>,
    /// (sum, count) of the work of re-optimisations.
    cost: (u64, u64),
    branched: u64,
    always: bool,
    /// Bytes of snapshots held by nodes on the stack.
    held: usize,
    /// The schedule of one re-optimisation (`STEPS`, `SHAKES`).
    pub(super) steps: usize,
    pub(super) shakes: usize,
}

impl Reopt {
    pub(super) fn new(ratio: u64) -> Reopt {
        Reopt {
            ratio,
            sub: Vec::new(),
            cost: (0, 0),
            branched: 0,
            always: false,
            held: 0,
            steps: STEPS,
            shakes: SHAKES,
        }
    }

    /// Re-optimising at every candidate node, with a short schedule that
    /// seldom prunes, so that most of those nodes still branch (tests).
    #[cfg(test)]
    pub(super) fn everywhere() -> Reopt {
        Reopt {
            always: true,
            steps: 2,
            shakes: 1,
            ..Reopt::new(1)
        }
    }

    /// Re-optimisations done so far, and how many of their nodes still
    /// branched.
    #[cfg(test)]
    pub(super) fn count(&self) -> (u64, u64) {
        (self.cost.1, self.branched)
    }

    /// The average work of a finished subtree at `depth`, or an estimate
    /// from the nearest shallower depth known (halved per level).
    fn subtree(&self, depth: usize) -> Option<u64> {
        (1..=depth).rev().find_map(|d| {
            let &(sum, count) = self.sub.get(d)?;
            (count > 0).then(|| (sum / count) >> (depth - d).min(63))
        })
    }

    /// Whether a node at `depth` (≥ 1) should re-optimise.
    pub(super) fn wants(&self, depth: usize) -> bool {
        if depth == 0 || self.ratio == 0 {
            return false;
        }
        if self.always {
            return true;
        }
        match (self.subtree(depth), self.cost) {
            (_, (_, 0)) | (None, _) => depth <= BLIND_DEPTH,
            (Some(s), (sum, count)) => s >= self.ratio.saturating_mul(sum / count),
        }
    }

    /// Whether a node may keep a snapshot of `bytes` more.
    pub(super) fn may_hold(&self, bytes: usize) -> bool {
        self.held.saturating_add(bytes) <= MAX_HELD_BYTES
    }

    /// A node on the stack keeps (`hold`) or gives back (`release`) a
    /// snapshot of `bytes`.
    pub(super) fn hold(&mut self, bytes: usize) {
        self.held += bytes;
    }

    pub(super) fn release(&mut self, bytes: usize) {
        self.held = self.held.saturating_sub(bytes);
    }

    /// A subtree at `depth` (the node and everything below it) took `work`.
    pub(super) fn subtree_done(&mut self, depth: usize, work: u64) {
        if self.sub.len() <= depth {
            self.sub.resize(depth + 1, (0, 0));
        }
        let e = &mut self.sub[depth];
        *e = (e.0.saturating_add(work), e.1 + 1);
    }

    /// A re-optimisation took `work`; the node still branched after it.
    pub(super) fn reopt_done(&mut self, work: u64, branched: bool) {
        self.cost = (self.cost.0.saturating_add(work), self.cost.1 + 1);
        self.branched += u64::from(branched);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn re_optimises_where_subtrees_cost_more_than_it() {
        let mut r = Reopt::new(4);
        assert!(!r.wants(0));
        // Nothing known: the shallow depths only.
        assert!(r.wants(1) && r.wants(2) && !r.wants(3));
        r.reopt_done(100, true);
        r.subtree_done(3, 1000);
        r.subtree_done(5, 100);
        assert!(
            r.wants(3),
            "subtrees of 1000 against re-optimisations of 100"
        );
        assert!(r.wants(4), "estimated from depth 3: 500");
        assert!(!r.wants(5), "subtrees of 100 cost one re-optimisation");
        assert!(!r.wants(6), "estimated from depth 5: 50");
        assert!(!Reopt::new(0).wants(1), "ratio 0 turns it off");
    }

    #[test]
    fn snapshots_held_stay_within_their_cap() {
        let mut r = Reopt::new(1);
        assert!(r.may_hold(MAX_HELD_BYTES));
        r.hold(MAX_HELD_BYTES - 10);
        assert!(r.may_hold(10) && !r.may_hold(11));
        r.release(MAX_HELD_BYTES - 10);
        assert!(r.may_hold(MAX_HELD_BYTES));
        assert!(!r.may_hold(usize::MAX), "no overflow");
    }
}
