//! Transformations between representations (the paper's constructions).

pub mod bt_to_hfsm;
pub mod edit;
pub mod fault_tolerant;
