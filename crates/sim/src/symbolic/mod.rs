//! Symbolic simulation (issue 16, point 5): policies whose leaves are bound
//! to an action domain's predicates and actions, run in the abstract world
//! of its facts instead of the planar room, so that users compare their own
//! BT and FSM on their own domain. A scenario with a top-level `domain` is
//! symbolic (`scenario.rs`); `world.rs` is the world, `run.rs` the runs,
//! their verdicts and Monte Carlo. The planar world stays the paper's
//! experiments' world.

pub mod expect;
pub mod report;
pub mod run;
pub mod scenario;
pub mod world;

#[cfg(test)]
mod tests;

pub use scenario::{SymScenario, looks_symbolic};
