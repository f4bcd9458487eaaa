//! The schedule of the search's root bound with the ascent of `ascent.rs`:
//! dual ascent until it stalls, then Polyak subgradient steps (Polyak,
//! "Minimization of unsmooth functionals", USSR Comput. Math. 9, 1969),
//! then back to the best shares seen. Used by `search.rs` at the root, and
//! shortened at the nodes below it that re-optimise the shares.
//!
//! Measured on the FSM-like pairs of `bench/ged_vs_highs.py` (root bound,
//! default budget): the ascent alone stalls well below the relaxation's
//! optimum (fsm-1 labeled: 43 against 53); ascent steps between the
//! subgradient steps did not help (50 steps with 3 ascent steps after
//! each: 49; 200 subgradient steps alone: 49 as well, with less work);
//! 1000 subgradient steps, the factor halved after 20 without progress,
//! reach 53 and made 12 of the 20 pair-modes exact, against 10 with the
//! 50-and-3 schedule.

/// Ascent steps at the root (at most; it stops once `STALL` steps in a
/// row have not raised the bound). Below the root the shares stay fixed,
/// so that the local values can be updated pair by pair (`Ascent::apply`),
/// except at the nodes that re-optimise them (`reopt.rs`, with a shorter
/// schedule: `RootPhase::with`).
const ROOT_STEPS: usize = 300;
const STALL: usize = 12;
/// Subgradient steps at the root, once the ascent stalls; the Polyak
/// factor halves after `SHAKE_STALL` of them in a row without a better
/// bound. (The root also stops when it has used a quarter of the search's
/// work, `search.rs`.)
pub(super) const SUB_STEPS: usize = 1000;
const SHAKE_STALL: usize = 20;

/// What the root does next with the shares of `ascent.rs`.
pub(super) enum Next {
    Done,
    Ascend,
    /// A subgradient step with this Polyak factor.
    Shake(f64),
    /// Back to the best shares seen (their assignment is then recomputed).
    Restore,
}

/// The schedule of the root's bound: ascent until it stalls, then
/// subgradient steps, then the best shares seen. Elsewhere (or without the
/// ascent) one evaluation.
pub(super) struct RootPhase {
    active: bool,
    steps: usize,
    best_total: i64,
    stalled: usize,
    shakes: usize,
    pub(super) best_total_sub: i64,
    shake_stall: usize,
    lambda: f64,
    pub(super) best_alpha: Vec<i64>,
    restored: bool,
    halvings: usize,
    /// The subgradient steps end once the factor has been halved more often.
    pub(super) max_halvings: usize,
}

impl RootPhase {
    /// With at most `shakes` subgradient steps (`SUB_STEPS` but in tests).
    pub(super) fn new(active: bool, shakes: usize) -> RootPhase {
        RootPhase::with(active, ROOT_STEPS, shakes)
    }

    /// At most `steps` ascent steps, then at most `shakes` subgradient steps.
    pub(super) fn with(active: bool, steps: usize, shakes: usize) -> RootPhase {
        RootPhase {
            active,
            steps,
            best_total: i64::MIN,
            stalled: 0,
            shakes,
            best_total_sub: i64::MIN,
            shake_stall: 0,
            lambda: 1.0,
            best_alpha: Vec::new(),
            restored: false,
            halvings: 0,
            max_halvings: usize::MAX,
        }
    }

    /// Given the bound `total` just computed, and whether the root's budget
    /// is `spent`.
    pub(super) fn next(&mut self, total: i64, spent: bool) -> Next {
        if !self.active || self.restored {
            return Next::Done;
        }
        if total > self.best_total {
            self.best_total = total;
            self.stalled = 0;
        } else {
            self.stalled += 1;
        }
        if !spent && self.steps > 0 && self.stalled < STALL {
            self.steps -= 1;
            return Next::Ascend;
        }
        if !spent && self.shakes > 0 {
            self.shakes -= 1;
            if total > self.best_total_sub {
                self.best_total_sub = total;
                self.shake_stall = 0;
            } else {
                self.shake_stall += 1;
                if self.shake_stall >= SHAKE_STALL {
                    self.lambda /= 2.0;
                    self.shake_stall = 0;
                    self.halvings += 1;
                    if self.halvings > self.max_halvings {
                        self.shakes = 0;
                    }
                }
            }
            self.stalled = 0;
            self.steps = 0;
            return Next::Shake(self.lambda);
        }
        if !self.best_alpha.is_empty() && total < self.best_total_sub {
            self.restored = true;
            return Next::Restore;
        }
        Next::Done
    }
}
