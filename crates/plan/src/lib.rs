//! Planning from action domains (issue 16): a domain file (TOML, STRIPS
//! actions with typed parameters) read into a [`domain::Domain`], and the
//! Behavior Tree a static backchaining planner derives from its goal
//! ([`backchain::plan_bt`]), with the precondition conflicts it resolved or
//! left ([`conflicts`]).

pub mod backchain;
pub mod conflicts;
pub mod domain;
pub mod fact;
pub mod fsm;
pub mod pddl;
mod validate;

pub use backchain::{Options, PlanError, Planned, plan_bt};
pub use domain::{Domain, load};

#[cfg(test)]
mod tests;
