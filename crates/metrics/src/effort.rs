//! The paper's effort formulas. Eq. 3 (sec. IV-A): what BT edits cost the
//! HFSM built from the BT, from their named edit script ([`eq3`]).
//! Effort (sec. IV-B, Eq. 4/5; SPEC §3): the edits that make a
//! sequential FSM reactive, from the formula at the M_s sequential action
//! states and M_fc fully connected states detected in the FSM. The measured
//! effort (the named GED to the fault-tolerant FSM that
//! `btfsm_transform::fault_tolerant` generates) is composed above this crate,
//! in `btfsm_report::effort`.

use crate::ged::EditScript;
use btfsm_model::graph::{PolicyGraph, VertexType};
use btfsm_model::{StateBody, StateMachine};

/// The states Eq. 4 counts, by index, in file order.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Detected {
    /// Action states that are not fully connected (M_s).
    pub sequential: Vec<usize>,
    /// Fully connected action states (M_fc), see
    /// [`crate::counts::fully_connected_states`].
    pub connected: Vec<usize>,
    /// The first top-level decision state (the paper's SELECTOR), if any.
    pub selector: Option<usize>,
}

/// Detects M_s, M_fc and the SELECTOR of a flat FSM.
pub fn detect(m: &StateMachine) -> Detected {
    let connected = crate::counts::fully_connected_states(m);
    let sequential = m
        .top
        .states
        .iter()
        .copied()
        .filter(|&i| is_action_state(m, i) && !connected.contains(&i))
        .collect();
    let selector = m
        .top
        .states
        .iter()
        .copied()
        .find(|&i| matches!(m.states[i].body, StateBody::Decision));
    Detected {
        sequential,
        connected,
        selector,
    }
}

fn is_action_state(m: &StateMachine, i: usize) -> bool {
    matches!(
        btfsm_model::graph::build::state_vertex_type(&m.states[i].body),
        btfsm_model::graph::VertexType::State
    )
}

/// Eq. 4: E(M_s, M_fc) = 3(M_s + 1) + M_fc[(M_s + M_fc - 1) + 3], the number
/// of edits that make a sequential FSM with M_s sequential and M_fc fully
/// connected states fault tolerant. Eq. 5 is the same number written with
/// M = M_s + M_fc: 3(M + 1) + M_fc(M - 1).
pub fn effort_formula(m_s: u64, m_fc: u64) -> u64 {
    if m_fc == 0 {
        return 3 * (m_s + 1);
    }
    3 * (m_s + 1) + m_fc * ((m_s + m_fc - 1) + 3)
}

/// Eq. 3 (paper sec. IV-A): what adding and removing BT nodes costs the
/// HFSM built from the BT, 3Δc + 4Δa + 5Δi over the nodes the named edit
/// script of the two BTs' graphs adds or removes (c conditions, a actions,
/// i control and decorator nodes: each added node's own vertex and arcs).
pub fn eq3(a: &PolicyGraph, b: &PolicyGraph, script: &EditScript) -> i64 {
    let ty =
        |g: &PolicyGraph, key: &str| g.g.node_weights().find(|v| v.key == key).map(|v| v.vtype);
    let weight = |t: Option<VertexType>| match t {
        Some(VertexType::Condition) => 3,
        Some(VertexType::Action) => 4,
        Some(_) => 5,
        None => 0,
    };
    let added: i64 = script.vertices_added.iter().map(|k| weight(ty(b, k))).sum();
    let removed: i64 = script
        .vertices_removed
        .iter()
        .map(|k| weight(ty(a, k)))
        .sum();
    added + removed
}

#[cfg(test)]
mod tests {
    use super::*;
    use btfsm_format::{Limits, load};

    fn machine(name: &str) -> StateMachine {
        let p = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../policies/paper"))
            .join(format!("{name}.toml"));
        match load(&p, &Limits::default()).unwrap().policy.body {
            btfsm_model::PolicyBody::Machine(m) => m,
            btfsm_model::PolicyBody::Bt(_) => panic!("not a machine"),
        }
    }

    #[test]
    fn eq4_and_eq5_agree() {
        for m_s in 0..20u64 {
            for m_fc in 0..5u64 {
                let m = m_s + m_fc;
                let eq5 = 3 * (m + 1) + m_fc * m.saturating_sub(1);
                assert_eq!(effort_formula(m_s, m_fc), eq5, "M_s {m_s} M_fc {m_fc}");
            }
        }
    }

    #[test]
    fn detects_sequential_and_connected_states() {
        let fig10 = machine("fig10-fsm");
        let d = detect(&fig10);
        assert_eq!((d.sequential.len(), d.connected.len()), (4, 1));
        assert_eq!(fig10.states[d.connected[0]].name, "Recharge");
        assert_eq!(d.selector, None);
        let fig02 = machine("fig02-fsm");
        let d = detect(&fig02);
        assert_eq!((d.sequential.len(), d.connected.len()), (4, 0));
    }

    /// Table II's "HFSM Eq. 3" column: Tuck arm 12, Safe-Move-To 4, Dock
    /// 17, Recharge 17 (Fig. 1 to Fig. 7a-d).
    #[test]
    fn eq3_gives_table_ii_hfsm_column() {
        let graph = |name: &str| {
            let p =
                std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../policies/paper"))
                    .join(format!("{name}.toml"));
            btfsm_model::graph::policy_graph(&load(&p, &Limits::default()).unwrap().policy)
        };
        let fig01 = graph("fig01-bt");
        for (to, want) in [
            ("fig07a-bt", 12),
            ("fig07b-bt", 4),
            ("fig07c-bt", 17),
            ("fig07d-bt", 17),
        ] {
            let b = graph(to);
            let named =
                crate::ged::ged(&fig01, &b, crate::ged::GedMode::Named, &Default::default());
            assert_eq!(eq3(&fig01, &b, &named.edit_script), want, "{to}");
        }
    }
}
