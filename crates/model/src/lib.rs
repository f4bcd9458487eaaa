//! The policy model: what a Behavior Tree, an FSM or an HFSM *is*, independent of
//! the file format it was read from (SPEC §1). Formats in `btfsm_format` build
//! these types; `crate::graph` turns them into the graphs the paper measures.

pub mod bt;
pub mod fsm;
pub mod graph;
pub mod skill;

pub use bt::{Bt, BtNode, BtNodeKind, IdSource};
pub use fsm::{Pseudo, Region, State, StateBody, StateMachine, Target, Transition, Trigger, UNSET};
pub use skill::{ArgValue, Guard, GuardTerm, SkillCall, SkillKind};

use std::ops::Range;

/// Byte range in the source file a model element was read from.
pub type Span = Range<usize>;

/// The three representations the paper compares.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum PolicyKind {
    Bt,
    Fsm,
    Hfsm,
}

impl PolicyKind {
    pub fn as_str(self) -> &'static str {
        match self {
            PolicyKind::Bt => "bt",
            PolicyKind::Fsm => "fsm",
            PolicyKind::Hfsm => "hfsm",
        }
    }
}

impl std::fmt::Display for PolicyKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// One policy, as read from one file.
#[derive(Debug, Clone, PartialEq)]
pub struct Policy {
    pub name: String,
    pub description: Option<String>,
    pub body: PolicyBody,
}

#[derive(Debug, Clone, PartialEq)]
pub enum PolicyBody {
    Bt(Bt),
    /// An FSM or an HFSM (an FSM whose states may be containers).
    Machine(StateMachine),
}

impl Policy {
    pub fn kind(&self) -> PolicyKind {
        match &self.body {
            PolicyBody::Bt(_) => PolicyKind::Bt,
            PolicyBody::Machine(m) if m.hierarchical => PolicyKind::Hfsm,
            PolicyBody::Machine(_) => PolicyKind::Fsm,
        }
    }
}
