//! btfsm: metrics for robot policy structures (Behavior Trees, FSMs, HFSMs) after
//! Iovino et al., "Comparison between Behavior Trees and Finite State Machines".

pub mod diagnostic;
pub mod format;
pub mod graph;
pub mod metrics;
pub mod model;
