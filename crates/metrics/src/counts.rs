//! Element counts (paper sec. IV-C, Tables I and III): vertices, edges, per-type
//! counts, graphical and active elements, and Table I's estimates for the
//! policy's M (action nodes / states) and M_fc (fully connected states).

use btfsm_model::graph::{PolicyGraph, VertexType};
use btfsm_model::{PolicyKind, StateBody, StateMachine, Target, Trigger};
use petgraph::visit::EdgeRef;
use std::collections::BTreeMap;

/// Measured counts of one policy graph.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Counts {
    pub vertices: usize,
    pub edges: usize,
    /// Vertices per type (`action`, `fallback`, `state`, `outcome`, ...).
    pub by_type: BTreeMap<&'static str, usize>,
    /// Vertices + edges.
    pub graphical_elements: usize,
    /// BT: vertices; FSM and HFSM: vertices + edges (Table III).
    pub active_elements: usize,
}

pub fn counts(kind: PolicyKind, g: &PolicyGraph) -> Counts {
    let mut by_type = BTreeMap::new();
    for v in g.g.node_weights() {
        *by_type.entry(v.vtype.as_str()).or_insert(0) += 1;
    }
    let vertices = g.vertex_count();
    let edges = g.arc_count();
    Counts {
        vertices,
        edges,
        by_type,
        graphical_elements: vertices + edges,
        active_elements: match kind {
            PolicyKind::Bt => vertices,
            PolicyKind::Fsm | PolicyKind::Hfsm => vertices + edges,
        },
    }
}

/// Table I's estimates (paper sec. IV-C), evaluated at the policy's M and M_fc.
/// These are approximations the paper derives for backchained designs; they are
/// printed beside the measured counts, never in their place.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct TableOne {
    /// Action nodes (BT) or action states (FSM, HFSM).
    pub m: usize,
    /// Fully connected states (FSM only; 0 otherwise).
    pub m_fc: usize,
    /// `T_fc = M_fc (M - 1)`.
    pub t_fc: usize,
    /// BT `7M - 1`; FSM `5M + 4 + T_fc`; HFSM `36M - 3`.
    pub graphical_estimate: f64,
    /// BT `3.5M`; FSM `5M + 4 + T_fc`; HFSM `29M - 3`.
    pub active_estimate: f64,
}

pub fn table_one(kind: PolicyKind, g: &PolicyGraph, m_fc: usize) -> TableOne {
    let m =
        g.g.node_weights()
            .filter(|v| matches!(v.vtype, VertexType::Action | VertexType::State))
            .count();
    let mf = m as f64;
    let t_fc = m_fc * m.saturating_sub(1);
    let (graphical_estimate, active_estimate) = match kind {
        PolicyKind::Bt => (7.0 * mf - 1.0, 3.5 * mf),
        PolicyKind::Fsm => {
            let e = 5.0 * mf + 4.0 + t_fc as f64;
            (e, e)
        }
        PolicyKind::Hfsm => (36.0 * mf - 3.0, 29.0 * mf - 3.0),
    };
    TableOne {
        m,
        m_fc,
        t_fc,
        graphical_estimate,
        active_estimate,
    }
}

/// Action states that every other action state has a transition to: the
/// paper's fully connected states (M_fc, Fig. 10/11's Recharge). Only for flat
/// machines with at least three action states (in smaller ones every state
/// would trivially qualify).
pub fn fully_connected_states(m: &StateMachine) -> Vec<usize> {
    if m.hierarchical {
        return Vec::new();
    }
    let actions: Vec<usize> = (0..m.states.len())
        .filter(|&i| is_action_state(m, i))
        .collect();
    if actions.len() < 3 {
        return Vec::new();
    }
    // Distinct action-state predecessors of every state.
    let is_action: Vec<bool> = (0..m.states.len()).map(|i| is_action_state(m, i)).collect();
    let mut preds: Vec<Vec<usize>> = vec![Vec::new(); m.states.len()];
    for &i in &actions {
        for t in &m.states[i].transitions {
            if let Target::State(j) = t.target
                && j != i
            {
                preds[j].push(i);
            }
        }
    }
    let mut out = Vec::new();
    for &c in &actions {
        {
            let p = &mut preds[c];
            p.sort_unstable();
            p.dedup();
        }
        if is_action[c] && preds[c].len() == actions.len() - 1 {
            out.push(c);
        }
    }
    out
}

fn is_action_state(m: &StateMachine, i: usize) -> bool {
    matches!(
        btfsm_model::graph::build::state_vertex_type(&m.states[i].body),
        VertexType::State
    ) && matches!(m.states[i].body, StateBody::Task(_))
}

/// Number of guarded transitions (for reports).
pub fn guard_count(m: &StateMachine) -> usize {
    m.states
        .iter()
        .flat_map(|s| &s.transitions)
        .filter(|t| matches!(t.trigger, Trigger::Guard(_)))
        .count()
}

/// Self-loops of a graph (RUNNING transitions of an FSM).
pub fn self_loops(g: &PolicyGraph) -> usize {
    g.g.edge_references()
        .filter(|e| e.source() == e.target())
        .count()
}
