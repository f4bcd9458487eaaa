//! Finite State Machines and Hierarchical FSMs (SPEC §1; the paper's sec. II-B and
//! III). One arena type serves both: an FSM is an HFSM whose states are all leaves.
//! States live in an arena so that machines of any nesting depth are walked
//! without recursion.

use super::{Guard, SkillCall, Span};

/// Index of a state in [`StateMachine::states`].
pub type StateIdx = usize;

#[derive(Debug, Clone, PartialEq)]
pub struct StateMachine {
    /// `true` for `kind = "hfsm"`.
    pub hierarchical: bool,
    /// The top-level region: its states, initial state and terminal outcomes.
    pub top: Region,
    pub states: Vec<State>,
}

/// The content of a machine or of a container state.
#[derive(Debug, Clone, PartialEq)]
pub struct Region {
    pub initial: StateIdx,
    /// Terminal outcomes of this region ("SUCCESS", "FAILURE", ...).
    pub outcomes: Vec<String>,
    /// The states directly inside this region, in file order.
    pub states: Vec<StateIdx>,
}

#[derive(Debug, Clone, PartialEq)]
pub struct State {
    /// Name, unique within its region (the TOML key).
    pub name: String,
    /// Display name; defaults to the name.
    pub label: String,
    /// The container this state is in (`None` at the top level).
    pub parent: Option<StateIdx>,
    pub body: StateBody,
    /// Transitions in file order: guards first (checked before the skill runs),
    /// then outcome transitions.
    pub transitions: Vec<Transition>,
    /// The SCXML pseudo-state this state stands for (`None` for an ordinary
    /// state); such a state has no skill and is drawn and exported as what it is.
    pub pseudo: Option<Pseudo>,
    pub span: Option<Span>,
}

/// SCXML pseudo-states modelled as states of their region (W3C SCXML 3.10).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pseudo {
    /// `<history type="shallow">`: re-enters the region's last active child.
    ShallowHistory,
    /// `<history type="deep">`: re-enters the last active descendants.
    DeepHistory,
}

#[derive(Debug, Clone, PartialEq)]
pub enum StateBody {
    /// A state bound to a skill (an action or a condition); `None` when the file
    /// gives no binding (analysis only).
    Task(Option<SkillCall>),
    /// A decision state such as the paper's SELECTOR: runs no skill, only checks
    /// its guards in the order written.
    Decision,
    /// A container (HFSM only) holding its own states.
    Container(Region),
}

#[derive(Debug, Clone, PartialEq)]
pub struct Transition {
    pub trigger: Trigger,
    pub target: Target,
    pub span: Option<Span>,
}

#[derive(Debug, Clone, PartialEq)]
pub enum Trigger {
    /// Fires when the state's skill (or container) returns this outcome.
    Outcome(String),
    /// Fires when the guard holds, checked before the state's skill runs.
    Guard(Guard),
}

impl Trigger {
    /// Short text for diagrams and edit scripts.
    pub fn label(&self) -> String {
        match self {
            Trigger::Outcome(o) => o.clone(),
            Trigger::Guard(g) => g.label.clone(),
        }
    }
}

#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Target {
    /// A state: a sibling (same region) in TOML files; SCXML transitions may
    /// also target a state of another region.
    State(StateIdx),
    /// One of the enclosing region's outcomes.
    Outcome(String),
}

impl StateMachine {
    /// The region a state is in.
    pub fn region_of(&self, s: StateIdx) -> &Region {
        match self.states[s].parent {
            None => &self.top,
            Some(p) => match &self.states[p].body {
                StateBody::Container(r) => r,
                _ => unreachable!("parent of a state is always a container"),
            },
        }
    }

    /// Path of names from the top level, joined with `/` (unique in the machine).
    pub fn path(&self, s: StateIdx) -> String {
        let mut parts = vec![self.states[s].name.as_str()];
        let mut cur = self.states[s].parent;
        while let Some(p) = cur {
            parts.push(self.states[p].name.as_str());
            cur = self.states[p].parent;
        }
        parts.reverse();
        parts.join("/")
    }

    /// Number of states that run an action skill or have no binding
    /// (not decisions, not containers): the paper's M.
    pub fn task_state_count(&self) -> usize {
        self.states
            .iter()
            .filter(|s| matches!(s.body, StateBody::Task(_)))
            .count()
    }
}
