//! BehaviorTree.CPP execution logs (issue 18): `btlog.rs` reads
//! `FileLogger2` `.btlog` files as a stream (both record layouts), `tree.rs`
//! the tree a log embeds, `report.rs` per-node figures and node and branch
//! coverage (`btfsm log report`), `replay.rs` the statuses at a moment
//! (`btfsm log dot`), `actions.rs` the actions a log executed and
//! `compare.rs` the first divergence of two runs (`btfsm log compare`),
//! `timeline.rs` the SVG timeline (`btfsm log timeline`).

pub mod actions;
pub mod btlog;
pub mod compare;
pub mod replay;
pub mod report;
pub mod timeline;
pub mod tree;
