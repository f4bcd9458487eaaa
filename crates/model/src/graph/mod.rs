//! The graphs the paper measures (SPEC §2): one directed multigraph per policy,
//! self-loops and parallel arcs kept. `build` turns each model into its graph.

pub mod build;

pub use build::policy_graph;

use petgraph::graph::{DiGraph, NodeIndex};

/// The type of a vertex; `labeled` GED only matches vertices of equal type.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum VertexType {
    Sequence,
    Fallback,
    SequenceMemory,
    FallbackMemory,
    Parallel,
    /// A control node of a kind without its own type (BehaviorTree.CPP
    /// `IfThenElse`, Nav2 `RecoveryNode`, ...).
    Control,
    Decorator,
    Action,
    Condition,
    /// An FSM state bound to an action skill (or to no skill).
    State,
    /// An FSM state bound to a condition skill.
    ConditionState,
    /// A decision state such as SELECTOR.
    Decision,
    /// An HFSM container state.
    Container,
    /// An HFSM parallel state (SCXML `<parallel>`): a container whose states
    /// are its orthogonal regions.
    ParallelState,
    /// A terminal outcome (SUCCESS, FAILURE, RUNNING).
    Outcome,
}

impl VertexType {
    pub fn as_str(self) -> &'static str {
        match self {
            VertexType::Sequence => "sequence",
            VertexType::Fallback => "fallback",
            VertexType::SequenceMemory => "sequence_memory",
            VertexType::FallbackMemory => "fallback_memory",
            VertexType::Parallel => "parallel",
            VertexType::Control => "control",
            VertexType::Decorator => "decorator",
            VertexType::Action => "action",
            VertexType::Condition => "condition",
            VertexType::State => "state",
            VertexType::ConditionState => "condition_state",
            VertexType::Decision => "decision",
            VertexType::Container => "container",
            VertexType::ParallelState => "parallel_state",
            VertexType::Outcome => "outcome",
        }
    }
}

/// A vertex: a BT node, a state, or a terminal outcome.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Vertex {
    /// Identity used by `named` GED: the BT node id, the state's path
    /// (`Container/Child`), or the outcome's name. Unique within a graph.
    pub key: String,
    /// Display name.
    pub label: String,
    pub vtype: VertexType,
}

/// What an arc stands for.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum ArcKind {
    /// BT parent -> child.
    Child,
    /// Transition on a returned outcome (SUCCESS, FAILURE, RUNNING, ...).
    Outcome(String),
    /// Guarded transition.
    Guard(String),
    /// HFSM container -> its initial child.
    Initial,
}

impl ArcKind {
    pub fn label(&self) -> &str {
        match self {
            ArcKind::Child => "",
            ArcKind::Outcome(o) => o,
            ArcKind::Guard(g) => g,
            ArcKind::Initial => "initial",
        }
    }
}

/// A policy's graph: directed multigraph with typed, keyed vertices.
#[derive(Debug, Clone)]
pub struct PolicyGraph {
    pub g: DiGraph<Vertex, ArcKind>,
    /// Where execution starts (BT root, initial state).
    pub entry: Option<NodeIndex>,
}

impl PolicyGraph {
    pub fn vertex_count(&self) -> usize {
        self.g.node_count()
    }

    pub fn arc_count(&self) -> usize {
        self.g.edge_count()
    }

    /// Vertices without outgoing arcs.
    pub fn sink_count(&self) -> usize {
        self.g
            .node_indices()
            .filter(|&v| {
                self.g
                    .neighbors_directed(v, petgraph::Direction::Outgoing)
                    .next()
                    .is_none()
            })
            .count()
    }
}
