//! BehaviorTree.CPP execution logs (issue 18): `btlog.rs` reads
//! `FileLogger2` `.btlog` files as a stream (both record layouts), `tree.rs`
//! the tree a log embeds, `report.rs` per-node figures and node and branch
//! coverage (`btfsm log report`).

pub mod btlog;
pub mod replay;
pub mod report;
pub mod tree;
