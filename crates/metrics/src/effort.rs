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
use btfsm_model::{StateBody, StateMachine, Target, Trigger};

/// The states Eq. 4 counts, by index, in file order, and the task they
/// make up.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Detected {
    /// Action states that are not fully connected (M_s), side states
    /// aside.
    pub sequential: Vec<usize>,
    /// Fully connected action states (M_fc), see
    /// [`crate::counts::fully_connected_states`].
    pub connected: Vec<usize>,
    /// Side states: action states off the task's chain that other action
    /// states enter on a guard only (a Recharge entered when the battery is
    /// low, from some of the states: not every one, else it is connected).
    /// Like a connected state, a recovery, not a step of the task.
    pub side: Vec<usize>,
    /// The first top-level decision state (the paper's SELECTOR), if any.
    pub selector: Option<usize>,
    /// The task's chain: the sequential states from the initial one along
    /// their `SUCCESS` transitions, in order.
    pub chain: Vec<usize>,
    /// The outcome the task ends in (the goal, [`goal_outcome`]) and
    /// whether the chain reaches it.
    pub goal: Option<String>,
    pub chain_reaches_goal: bool,
}

/// Detects M_s, M_fc, the side states, the SELECTOR and the task of a flat
/// FSM.
pub fn detect(m: &StateMachine) -> Detected {
    let all: Vec<usize> = m
        .top
        .states
        .iter()
        .copied()
        .filter(|&i| is_action_state(m, i))
        .collect();
    // The task first: a step of it that every other action state happens
    // to reach (Pick, after Move-To and a Recharge that resumes there) is
    // a step, not a fully connected recovery.
    let (chain, reached) = success_chain(m, &all);
    let mut on_chain = vec![false; m.states.len()];
    for &c in &chain {
        on_chain[c] = true;
    }
    let connected: Vec<usize> = crate::counts::fully_connected_states(m)
        .into_iter()
        .filter(|&c| !on_chain[c])
        .collect();
    let actions: Vec<usize> = all.into_iter().filter(|i| !connected.contains(i)).collect();
    let side = side_states(m, &actions, &chain);
    let sequential = actions.into_iter().filter(|i| !side.contains(i)).collect();
    let selector = m
        .top
        .states
        .iter()
        .copied()
        .find(|&i| matches!(m.states[i].body, StateBody::Decision));
    let chain_reaches_goal = reached.is_some();
    Detected {
        sequential,
        connected,
        side,
        selector,
        chain,
        goal: reached.or_else(|| goal_outcome(m)),
        chain_reaches_goal,
    }
}

/// The states from the initial one along `SUCCESS` transitions while they
/// are among `actions`, and the top-level outcome the walk ends in, if it
/// ends in one.
fn success_chain(m: &StateMachine, actions: &[usize]) -> (Vec<usize>, Option<String>) {
    let mut is_action = vec![false; m.states.len()];
    for &a in actions {
        is_action[a] = true;
    }
    let mut chain: Vec<usize> = Vec::new();
    let mut cur = m.top.initial_state();
    while let Some(s) = cur.take() {
        // Each state once: `is_action` is cleared as the walk passes.
        if !is_action.get(s).copied().unwrap_or(false) {
            break;
        }
        is_action[s] = false;
        chain.push(s);
        let next = m.states[s]
            .transitions
            .iter()
            .find(|t| matches!(&t.trigger, Trigger::Outcome(o) if o == "SUCCESS"));
        match next.map(|t| &t.target) {
            Some(Target::State(j)) => cur = Some(*j),
            Some(Target::Outcome(o) | Target::OuterOutcome { outcome: o, .. }) => {
                return (chain, Some(o.clone()));
            }
            None => {}
        }
    }
    (chain, None)
}

/// The outcome a task ends in when no `SUCCESS` chain from the initial
/// state says it: the one named like success (`SUCCESS`, `succeeded`,
/// any case), else the first top-level outcome.
pub fn goal_outcome(m: &StateMachine) -> Option<String> {
    let outs = &m.top.outcomes;
    outs.iter()
        .find(|o| o.eq_ignore_ascii_case("success") || o.eq_ignore_ascii_case("succeeded"))
        .or(outs.first())
        .cloned()
}

/// Action states off `chain`, other than the initial one, that other
/// action states enter on a guard and none on an outcome.
fn side_states(m: &StateMachine, actions: &[usize], chain: &[usize]) -> Vec<usize> {
    let n = m.states.len();
    let (mut by_guard, mut by_outcome) = (vec![false; n], vec![false; n]);
    let (mut is_action, mut on_chain) = (vec![false; n], vec![false; n]);
    for &a in actions {
        is_action[a] = true;
    }
    for &c in chain {
        on_chain[c] = true;
    }
    for (i, st) in m.states.iter().enumerate() {
        for t in &st.transitions {
            let Target::State(j) = t.target else { continue };
            if j == i || j >= n {
                continue;
            }
            match t.trigger {
                Trigger::Guard(_) if is_action[i] => by_guard[j] = true,
                Trigger::Guard(_) => {}
                _ => by_outcome[j] = true,
            }
        }
    }
    let initial = m.top.initial_state();
    actions
        .iter()
        .copied()
        .filter(|&s| !on_chain[s] && Some(s) != initial && by_guard[s] && !by_outcome[s])
        .collect()
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

    /// The machine of issue 29: a Recharge only two states enter, on a
    /// guard, written last: a side state, not a step; the chain ends in
    /// SUCCESS.
    #[test]
    fn a_recharge_entered_on_a_guard_is_a_side_state() {
        let text = r#"kind = "fsm"
name = "side"
initial = "Move-To cube2"
outcomes = ["SUCCESS", "FAILURE"]
[states."Move-To cube2"]
skill = "Move-To"
args = { target = "cube2" }
guards = [{ unless = "Battery-Level", args = { min = 20 }, to = "Recharge" }]
on = { SUCCESS = "Pick cube2" }
[states."Pick cube2"]
skill = "Pick"
args = { object = "cube2" }
on = { SUCCESS = "Move-To delivery" }
[states."Move-To delivery"]
skill = "Move-To"
args = { target = "delivery" }
guards = [{ unless = "Battery-Level", args = { min = 20 }, to = "Recharge" }]
on = { SUCCESS = "Place cube2" }
[states."Place cube2"]
skill = "Place"
args = { object = "cube2", at = "delivery" }
on = { SUCCESS = "SUCCESS" }
[states.Recharge]
skill = "Recharge"
on = { SUCCESS = "Move-To cube2" }
"#;
        let m = match btfsm_format::toml::parse_str(
            "side.toml",
            text,
            std::path::Path::new("."),
            &Limits::default(),
        )
        .unwrap()
        .policy
        .body
        {
            btfsm_model::PolicyBody::Machine(m) => m,
            btfsm_model::PolicyBody::Bt(_) => panic!("a machine"),
        };
        let d = detect(&m);
        let name = |v: &[usize]| {
            v.iter()
                .map(|&i| m.states[i].name.as_str())
                .collect::<Vec<_>>()
        };
        assert_eq!(name(&d.side), ["Recharge"]);
        assert_eq!(
            name(&d.sequential),
            [
                "Move-To cube2",
                "Pick cube2",
                "Move-To delivery",
                "Place cube2"
            ]
        );
        assert_eq!(name(&d.chain), name(&d.sequential));
        assert_eq!(
            (d.goal.as_deref(), d.chain_reaches_goal),
            (Some("SUCCESS"), true)
        );
        // Fig. 8b's Safe-Move-To is entered on Move-To's FAILURE: an
        // alternative step, not a side state.
        let fig08b = machine("fig08b-fsm");
        assert!(detect(&fig08b).side.is_empty());
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
