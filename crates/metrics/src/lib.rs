//! The paper's metrics (sec. IV), one per file, all computed from the graphs of
//! `btfsm_model::graph`.

pub mod complexity;
pub mod counts;
pub mod cpu;
pub mod effort;
pub mod ged;
pub mod ted;
