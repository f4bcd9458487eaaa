//! Rules from the paper (Iovino et al.): the precondition order that makes
//! a BT chatter (Fig. 3), actions a Fallback runs unguarded, FSMs that are
//! not fault tolerant (sec. IV-B), and fully connected states and the
//! effort they cost (Eq. 4). Skills' effects come from the built-in action
//! domain, `policies/domains/moma.toml` (README "Action domains").

use super::{Level, Rule, Sink};
use crate::model::{Bt, BtNodeKind, Policy, PolicyBody, StateBody, Trigger};
use crate::plan::Domain;
use crate::plan::fact::Fact;
use crate::sim::symbolic::world::{Binding, binding};
use crate::transform::fault_tolerant::{builtin_domain, step_of};
use std::collections::BTreeSet;

pub const CHATTERING_PRECONDITION_ORDER: Rule = Rule {
    code: "chattering-precondition-order",
    level: Level::Error,
    summary: "in a Sequence, a later child's actions undo the condition an earlier child ensures: the robot goes back and forth (the paper's Fig. 3)",
    check: chattering,
};

/// The fact node `n` ensures: its own (a condition), or the first child's
/// of a Fallback.
fn ensured(d: &Domain, bt: &Bt, n: usize) -> Option<Fact> {
    let node = &bt.nodes[n];
    let cond = match node.kind {
        BtNodeKind::Condition => n,
        BtNodeKind::Fallback | BtNodeKind::FallbackMemory => {
            let &c = node.children.first()?;
            (bt.nodes[c].kind == BtNodeKind::Condition).then_some(c)?
        }
        _ => return None,
    };
    match binding(d, bt.nodes[cond].skill.as_ref()?)? {
        Binding::Fact(f) => Some(f),
        Binding::Action(..) => None,
    }
}

/// The facts the actions below `n` delete (explicitly or by excluding
/// them), among `wanted`; with the action that does.
fn undone(d: &Domain, bt: &Bt, n: usize, wanted: &[Option<Fact>]) -> Vec<(Fact, String)> {
    let mut out = Vec::new();
    let mut stack = vec![n];
    while let Some(x) = stack.pop() {
        let node = &bt.nodes[x];
        stack.extend(node.children.iter().copied());
        if node.kind != BtNodeKind::Action {
            continue;
        }
        let Some(step) = node.skill.as_ref().and_then(|c| step_of(d, c)) else {
            continue;
        };
        for f in crate::plan::conflicts::undone_by(d, &step, wanted) {
            out.push((f, node.id.clone()));
        }
    }
    out
}

fn chattering(p: &Policy, out: &mut Sink) {
    let PolicyBody::Bt(bt) = &p.body else { return };
    let d = builtin_domain();
    for node in &bt.nodes {
        if !matches!(node.kind, BtNodeKind::Sequence | BtNodeKind::SequenceMemory) {
            continue;
        }
        let kids = &node.children;
        let facts: Vec<Option<Fact>> = kids.iter().map(|&c| ensured(d, bt, c)).collect();
        let mut reported = BTreeSet::new();
        for (j, &c) in kids.iter().enumerate() {
            // The achieving action of a Sequence consumes its preconditions
            // by design (Place lets go of the cube): only subtrees count.
            if bt.nodes[c].kind == BtNodeKind::Action {
                continue;
            }
            for (f, by) in undone(d, bt, c, &facts[..j]) {
                let Some(i) = facts[..j].iter().position(|x| x.as_ref() == Some(&f)) else {
                    continue;
                };
                if !reported.insert((i, j)) {
                    continue;
                }
                let (earlier, later) = (&bt.nodes[kids[i]].id, &bt.nodes[c].id);
                out.push(
                    &node.id,
                    node.span.clone(),
                    format!(
                        "in Sequence `{}`, `{later}` runs `{by}`, which undoes {f}, the condition `{earlier}` before it ensures: the Sequence goes back to `{earlier}` and the robot chatters between them",
                        node.id
                    ),
                    format!("put `{later}` before `{earlier}` (as `btfsm plan` orders preconditions)"),
                );
            }
        }
    }
}

pub const UNGUARDED_FALLBACK_ACTION: Rule = Rule {
    code: "unguarded-fallback-action",
    level: Level::Warning,
    summary: "an action in a Fallback with no condition before it: it runs even when what it achieves already holds",
    check: unguarded,
};

fn unguarded(p: &Policy, out: &mut Sink) {
    let PolicyBody::Bt(bt) = &p.body else { return };
    for node in &bt.nodes {
        if !matches!(node.kind, BtNodeKind::Fallback | BtNodeKind::FallbackMemory) {
            continue;
        }
        let Some(&first) = node.children.first() else {
            continue;
        };
        let n = &bt.nodes[first];
        if n.kind == BtNodeKind::Action && n.skill.is_some() {
            out.push(
                &n.id,
                n.span.clone(),
                format!(
                    "Fallback `{}` starts with action `{}`: it runs every tick, even when its goal already holds",
                    node.id, n.id
                ),
                "put the condition it achieves first: Fallback(condition, action), the paper's pattern".into(),
            );
        }
    }
}

pub const NOT_FAULT_TOLERANT: Rule = Rule {
    code: "not-fault-tolerant",
    level: Level::Warning,
    summary: "an FSM action state with no FAILURE transition: a failure ends the task (sec. IV-B)",
    check: not_fault_tolerant,
};

fn not_fault_tolerant(p: &Policy, out: &mut Sink) {
    let PolicyBody::Machine(m) = &p.body else {
        return;
    };
    // Fully connected states return to the SELECTOR on SUCCESS by the
    // paper's construction (`fully-connected-state`).
    let connected = crate::metrics::counts::fully_connected_states(m);
    for (i, s) in m.states.iter().enumerate() {
        if connected.contains(&i) {
            continue;
        }
        let StateBody::Task(Some(call)) = &s.body else {
            continue;
        };
        if crate::model::skill::skill_kind(&call.skill) == Some(crate::model::SkillKind::Condition)
        {
            continue;
        }
        let on_failure = s
            .transitions
            .iter()
            .any(|t| matches!(&t.trigger, Trigger::Outcome(o) if o == "FAILURE"));
        if !on_failure {
            out.push(
                &m.path(i),
                s.span.clone(),
                format!("action state `{}` has no FAILURE transition: a failed {} ends the task", m.path(i), call.skill),
                "send FAILURE to a decision state that resumes the task (`btfsm convert --to fault-tolerant`)".into(),
            );
        }
    }
}

pub const FULLY_CONNECTED_STATE: Rule = Rule {
    code: "fully-connected-state",
    level: Level::Note,
    summary: "a state every action state can enter (T_fc): each costs M_s + M_fc + 2 more edits to make the FSM reactive (Eq. 4)",
    check: fully_connected,
};

fn fully_connected(p: &Policy, out: &mut Sink) {
    let PolicyBody::Machine(m) = &p.body else {
        return;
    };
    let fc = crate::metrics::counts::fully_connected_states(m);
    if fc.is_empty() {
        return;
    }
    let det = crate::transform::fault_tolerant::detect(m);
    let (m_s, m_fc) = (det.sequential.len() as u64, det.connected.len() as u64);
    let cost = crate::transform::fault_tolerant::effort_formula(m_s, m_fc)
        - crate::transform::fault_tolerant::effort_formula(m_s, 0);
    for &i in &fc {
        out.push(
            &m.path(i),
            m.states[i].span.clone(),
            format!(
                "state `{}` is fully connected: with M_s = {m_s} and M_fc = {m_fc}, the fully connected states cost {cost} of the {} edits of Eq. 4",
                m.path(i),
                crate::transform::fault_tolerant::effort_formula(m_s, m_fc)
            ),
            "in a BT the same behavior is one subtree at the root (the paper's Fig. 16a)".into(),
        );
    }
}
