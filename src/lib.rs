//! btfsm: metrics for robot policy structures (Behavior Trees, FSMs, HFSMs) after
//! Iovino et al., "Comparison between Behavior Trees and Finite State Machines".
//!
//! The path of a policy: `format` reads a file into the `model`, `graph` turns
//! the model into the graph the paper counts, `metrics` measure it, `report`
//! formats the results and `cli` prints them. The library never prints; only
//! `cli` does.

pub mod cli;
pub mod diagnostic;
pub mod format;
#[doc(hidden)]
pub mod fuzzing;
pub mod graph;
pub mod lint;
pub mod log;
pub mod metrics;
pub mod model;
pub mod plan;
pub mod render;
pub mod report;
pub mod sanitize;
pub mod sim;
pub mod tick;
pub mod transform;
pub mod view;

pub use cli::run;
