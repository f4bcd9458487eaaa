//! Builds the graph of a policy exactly as the paper counts (SPEC §2):
//! - BT: one vertex per node, one edge from each parent to each child (Fig. 1:
//!   14 vertices, 13 edges);
//! - FSM: one vertex per state and per terminal outcome, one arc per transition,
//!   self-loops and parallel arcs kept (Fig. 4: 6 vertices, 18 arcs);
//! - HFSM (paper sec. IV-A c): one vertex per state of any level plus one per
//!   top-level outcome; a transition to a container's own outcome becomes an arc
//!   to the container's vertex, and each container has one more arc to its
//!   initial child (Fig. 1 as an HFSM: 17 vertices, 44 arcs).
//! - Beyond the paper (SCXML): a parallel state has one arc to each of its
//!   orthogonal regions (the states directly inside it, all entered
//!   together); a region whose initial is one of its outcomes (a state
//!   holding only a `<final>`) has no initial arc, and a machine that is only
//!   outcomes enters at its initial outcome's vertex; a transition to an
//!   outcome of an enclosing region is an arc to that region's container (or
//!   to the top-level outcome's vertex), as one to the source's own region's.

use super::{ArcKind, PolicyGraph, Vertex, VertexType};
use crate::skill::{SkillKind, skill_kind};
use crate::{Bt, BtNodeKind, Policy, PolicyBody, StateBody, StateMachine, Target, Trigger};
use petgraph::graph::{DiGraph, NodeIndex};

/// The graph of any policy.
pub fn policy_graph(p: &Policy) -> PolicyGraph {
    match &p.body {
        PolicyBody::Bt(bt) => bt_graph(bt),
        PolicyBody::Machine(m) => machine_graph(m),
    }
}

/// The vertex type of a BT node.
pub fn bt_vertex_type(kind: BtNodeKind) -> VertexType {
    match kind {
        BtNodeKind::Sequence => VertexType::Sequence,
        BtNodeKind::Fallback => VertexType::Fallback,
        BtNodeKind::SequenceMemory => VertexType::SequenceMemory,
        BtNodeKind::FallbackMemory => VertexType::FallbackMemory,
        BtNodeKind::Parallel { .. } => VertexType::Parallel,
        BtNodeKind::Control => VertexType::Control,
        BtNodeKind::Action => VertexType::Action,
        BtNodeKind::Condition => VertexType::Condition,
        _ => VertexType::Decorator,
    }
}

/// BT: parent -> child edges.
pub fn bt_graph(bt: &Bt) -> PolicyGraph {
    let mut g = DiGraph::with_capacity(bt.nodes.len(), bt.nodes.len().saturating_sub(1));
    for n in &bt.nodes {
        g.add_node(Vertex {
            key: n.id.clone(),
            label: n.label.clone(),
            vtype: bt_vertex_type(n.kind),
        });
    }
    for &i in &bt.preorder() {
        for &c in &bt.nodes[i].children {
            g.add_edge(NodeIndex::new(i), NodeIndex::new(c), ArcKind::Child);
        }
    }
    PolicyGraph {
        g,
        entry: Some(NodeIndex::new(bt.root)),
    }
}

/// The vertex type of a state.
pub fn state_vertex_type(body: &StateBody) -> VertexType {
    match body {
        StateBody::Container(r) if r.parallel => VertexType::ParallelState,
        StateBody::Container(_) => VertexType::Container,
        StateBody::Decision => VertexType::Decision,
        StateBody::Task(Some(call)) if skill_kind(&call.skill) == Some(SkillKind::Condition) => {
            VertexType::ConditionState
        }
        StateBody::Task(_) => VertexType::State,
    }
}

/// FSM / HFSM: states, top-level outcomes, transitions, container -> initial.
pub fn machine_graph(m: &StateMachine) -> PolicyGraph {
    let mut g = DiGraph::with_capacity(
        m.states.len() + m.top.outcomes.len(),
        m.states.iter().map(|s| s.transitions.len() + 1).sum(),
    );
    for (s, key) in m.states.iter().zip(m.keys()) {
        g.add_node(Vertex {
            key,
            label: s.label.clone(),
            vtype: state_vertex_type(&s.body),
        });
    }
    let outcome_base = m.states.len();
    for o in &m.top.outcomes {
        g.add_node(Vertex {
            key: o.clone(),
            label: o.clone(),
            vtype: VertexType::Outcome,
        });
    }
    let top_outcome = |o: &str| {
        let k = m
            .top
            .outcomes
            .iter()
            .position(|x| x == o)
            .expect("validated: outcome of the top region");
        outcome_base + k
    };
    for (i, s) in m.states.iter().enumerate() {
        if let StateBody::Container(r) = &s.body {
            for c in r.entered(&m.states) {
                g.add_edge(NodeIndex::new(i), NodeIndex::new(c), ArcKind::Initial);
            }
        }
        for t in &s.transitions {
            let to = match &t.target {
                Target::State(j) => *j,
                Target::Outcome(o) => match s.parent {
                    Some(p) => p,
                    None => top_outcome(o),
                },
                Target::OuterOutcome { owner, outcome } => match owner {
                    Some(c) => *c,
                    None => top_outcome(outcome),
                },
            };
            let kind = match &t.trigger {
                Trigger::Outcome(o) => ArcKind::Outcome(o.clone()),
                Trigger::Guard(gd) => ArcKind::Guard(gd.label.clone()),
            };
            g.add_edge(NodeIndex::new(i), NodeIndex::new(to), kind);
        }
    }
    PolicyGraph {
        g,
        entry: Some(NodeIndex::new(match &m.top.initial {
            Target::State(s) => *s,
            Target::Outcome(o) | Target::OuterOutcome { outcome: o, .. } => top_outcome(o),
        })),
    }
}
