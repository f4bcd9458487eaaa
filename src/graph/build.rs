//! Builds the graph of a policy as SPEC §2 counts (work in progress).

use super::PolicyGraph;
use crate::model::Policy;

pub fn policy_graph(_p: &Policy) -> PolicyGraph {
    todo!()
}
