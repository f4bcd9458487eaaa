//! Effort (paper sec. IV-B, Eq. 4/5; SPEC §3): the edits that make a
//! sequential FSM reactive. Reported twice: from the formula, with M_s and
//! M_fc detected from the FSM, and measured as the named GED between the FSM
//! and the fault-tolerant FSM `transform::fault_tolerant` generates from it
//! (with the structural GED beside it). BTs and HFSMs are reactive by
//! construction: effort 0.

use crate::graph::policy_graph;
use crate::metrics::ged::{GedMode, GedOptions, GedResult, ged};
use crate::model::{Policy, PolicyBody, PolicyKind};
use crate::transform::fault_tolerant::{
    FaultTolerantError, detect, effort_formula, fault_tolerant_policy,
};

/// The effort of one policy.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Effort {
    pub kind: PolicyKind,
    /// Sequential action states (M_s), by name.
    pub sequential: Vec<String>,
    /// Fully connected states (M_fc), by name.
    pub connected: Vec<String>,
    pub m_s: usize,
    pub m_fc: usize,
    /// Eq. 4 at (M_s, M_fc); 0 for BTs and HFSMs.
    pub formula: u64,
    /// Named GED between the policy and its generated fault-tolerant FSM.
    pub named: Option<GedResult>,
    /// Structural GED between the same two graphs.
    pub structural: Option<GedResult>,
    /// Why the measured value is absent or means something else.
    pub note: Option<String>,
}

/// The effort of a policy, with its generated fault-tolerant FSM (FSMs only).
pub fn effort(p: &Policy, opts: &GedOptions) -> (Effort, Option<Policy>) {
    let kind = p.kind();
    let m = match &p.body {
        PolicyBody::Machine(m) if !m.hierarchical => m,
        _ => {
            let why = match kind {
                PolicyKind::Bt => {
                    "a BT is reactive by construction (ticked from the root every step): effort 0"
                }
                _ => "an HFSM built like a BT is reactive by construction: effort 0",
            };
            return (
                Effort {
                    kind,
                    sequential: Vec::new(),
                    connected: Vec::new(),
                    m_s: 0,
                    m_fc: 0,
                    formula: 0,
                    named: None,
                    structural: None,
                    note: Some(why.to_string()),
                },
                None,
            );
        }
    };
    let d = detect(m);
    let names = |v: &[usize]| v.iter().map(|&i| m.states[i].name.clone()).collect();
    let mut e = Effort {
        kind,
        sequential: names(&d.sequential),
        connected: names(&d.connected),
        m_s: d.sequential.len(),
        m_fc: d.connected.len(),
        formula: effort_formula(d.sequential.len() as u64, d.connected.len() as u64),
        named: None,
        structural: None,
        note: None,
    };
    if let Some(s) = d.selector {
        e.note = Some(format!(
            "already has a decision state (`{}`): Eq. 4 counts the edits from a sequential design; the measured value counts only what is missing",
            m.states[s].name
        ));
    }
    match fault_tolerant_policy(p) {
        Ok(ft) => {
            let (ga, gb) = (policy_graph(p), policy_graph(&ft));
            e.named = Some(ged(&ga, &gb, GedMode::Named, opts));
            e.structural = Some(ged(&ga, &gb, GedMode::Structural, opts));
            (e, Some(ft))
        }
        Err(errs) => {
            let msg: Vec<String> = errs.iter().map(FaultTolerantError::to_string).collect();
            e.note = Some(format!(
                "no fault-tolerant FSM generated: {}",
                msg.join("; ")
            ));
            (e, None)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::transform::paper_policy as paper;

    #[test]
    fn formula_and_named_ged_agree_on_the_papers_examples() {
        for (f, m_s, m_fc) in [("fig02-fsm", 4, 0), ("fig10-fsm", 4, 1)] {
            let (e, ft) = effort(&paper(f), &GedOptions::default());
            assert!(ft.is_some());
            assert_eq!((e.m_s, e.m_fc), (m_s, m_fc), "{f}");
            assert_eq!(e.named.as_ref().map(|g| g.ged), Some(e.formula), "{f}");
            assert!(e.structural.as_ref().is_some_and(|g| g.exact));
        }
    }

    #[test]
    fn bts_and_hfsms_need_no_effort() {
        let (e, ft) = effort(&paper("fig01-bt"), &GedOptions::default());
        assert_eq!(e.formula, 0);
        assert!(ft.is_none() && e.note.is_some());
        let (e, _) = effort(&paper("fig06-hfsm"), &GedOptions::default());
        assert_eq!((e.kind, e.formula), (PolicyKind::Hfsm, 0));
    }
}
