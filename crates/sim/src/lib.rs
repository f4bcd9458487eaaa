//! The planar robot simulator (SPEC §6): a deterministic, seeded 2D world after
//! the paper's Experiments 1-5, one skill library shared by every policy kind,
//! BT/FSM/HFSM executors, scenario files with disturbances, traces and the
//! behavior-match verdict, SVG plots in the style of the paper's Fig. 17, and
//! Monte Carlo episodes.

mod csv;
pub mod episodes;
pub mod exec;
#[cfg(test)]
mod fault_tolerant_tests;
mod livelock;
pub mod monte_carlo;
#[cfg(test)]
mod physics_tests;
pub mod planner;
pub mod plot;
pub mod report;
pub mod rng;
pub mod robot;
pub mod run;
pub mod scenario;
pub mod sensitivity;
pub mod skills;
pub mod symbolic;
#[cfg(test)]
mod test_support;
pub mod trace;
pub mod world;
