//! Executors: how a BT, an FSM and an HFSM drive the robot, one step at a time
//! (SPEC §6), against the shared skill library behind the [`Leaves`] trait.
//!
//! - BT (the paper's sec. II-A; Colledanchise & Ögren, "Behavior Trees in
//!   Robotics and AI", ch. 1): the root is ticked once per step, every node
//!   as BehaviorTree.CPP 4 ticks its type (docs/bt-semantics.md, checked
//!   against the engine by tests/differential/): `sequence` and `fallback`
//!   are ReactiveSequence and ReactiveFallback, `sequence_memory` and
//!   `fallback_memory` BehaviorTree.CPP's Sequence and Fallback, and the
//!   XML types keep their own semantics (SequenceWithMemory, Parallel with
//!   per-child memory, IfThenElse, ...). A RUNNING leaf is halted
//!   ([`Leaves::halt`]) at the moment BehaviorTree.CPP halts it.
//! - FSM (sec. II-B, Algorithm 3): the current state's guards are checked, in
//!   the order written, before its skill runs; the skill's outcome selects the
//!   transition. A decision state (SELECTOR) only checks guards. Several states
//!   may run in one step (a finished action's successor starts at once), until
//!   an action returns RUNNING or the machine ends.
//! - HFSM (sec. III): containers are entered at their initial state; a
//!   transition to a container's outcome continues with the container's own
//!   transition on that outcome; the guards of the enclosing containers are
//!   checked first, outermost first. Reaching the top-level outcome `RUNNING`
//!   ends the step and the next step re-enters the machine (the construction of
//!   Fig. 6, which makes an HFSM tick like a BT). What a machine does at
//!   SUCCESS and at FAILURE (end, or be re-entered at its initial state) is
//!   set by the run (`after_success`, `after_failure` in the scenario;
//!   [`MachineExec::keep_ticking`], [`MachineExec::reenter_on_failure`]).
//!
//! Both executors walk their structure with explicit stacks, never recursion.
//! A BT's reactive skeleton (its Sequence and Fallback nodes from the root
//! down to the first node with memory or a decorator) is compiled once into
//! a table of successors (`Plan`): a tick then jumps from leaf to leaf as the
//! short-circuit evaluation of an and/or expression does, and takes the stack
//! walk only for the subtrees below the skeleton. When every node's status is
//! noted (`sim --trace`), the composites a status leaves are noted with it (a
//! reactive composite returns the status of the child it stops at). A unit
//! test checks plan and stack walk, noting or not, halts included, against
//! a recursive reference on random trees of every TOML node kind.

mod bt;
mod machine;
mod ops;
mod plan;
#[cfg(test)]
mod tests;

pub use bt::{BtExec, CompiledBt, XNode};
pub use machine::{CompiledMachine, GuardTerms, MachineExec};
pub use ops::{refused, unsupported};

use super::skills::{Call, Status};

/// What an executor needs from the robot.
pub trait Leaves {
    /// Evaluates the condition of leaf `key` (a BT node, an FSM state; for
    /// a guard, its state).
    fn condition(&mut self, key: usize, call: &Call) -> bool;
    /// Ticks the action of leaf `key` (continuing its running instance).
    fn action(&mut self, key: usize, call: &Call) -> Status;
    /// Halts the running action of leaf `key` at once (BehaviorTree.CPP's
    /// `halt()`): called when the executor leaves a RUNNING leaf — a
    /// reactive composite re-ticks from an earlier child, a Parallel is done,
    /// an FSM guard preempts its state. A leaf that is not running ignores it.
    fn halt(&mut self, key: usize) {
        let _ = key;
    }
    /// Simulated time, s (for Timeout).
    fn now(&self) -> f64;
}
