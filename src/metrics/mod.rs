//! The paper's metrics (sec. IV), one per file, all computed from the graphs of
//! `crate::graph`.

pub mod ged;
