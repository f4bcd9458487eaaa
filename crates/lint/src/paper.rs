//! Rules from the paper (Iovino et al.): the precondition order that makes
//! a BT chatter (Fig. 3), actions a Fallback runs unguarded, FSMs that are
//! not fault tolerant (sec. IV-B), and fully connected states and the
//! effort they cost (Eq. 4). Skills' effects come from the built-in action
//! domain, `policies/domains/moma.toml` (docs/guide/plan.md).

use super::{Level, Rule, Sink, Subject};
use btfsm_model::{Bt, BtNodeKind, PolicyBody, StateBody, Target, Trigger};
use btfsm_plan::Domain;
use btfsm_plan::fact::Fact;
use std::collections::{BTreeMap, HashMap};

pub const CHATTERING_PRECONDITION_ORDER: Rule = Rule {
    code: "chattering-precondition-order",
    level: Level::Error,
    summary: "in a Sequence, a later child's actions undo an earlier child's condition: the robot goes back and forth (Fig. 3)",
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
    d.fact_of(bt.nodes[cond].skill.as_ref()?)
}

/// What the actions of a subtree undo: facts they delete, and per
/// exclusive predicate and its other arguments, the values of the
/// exclusive argument they add (adding `Robot-At(cube2)` undoes every other
/// `Robot-At`). With the action that does it, for the message.
/// An exclusive predicate and its arguments but the exclusive one.
type ExclKey = (String, Vec<String>);

#[derive(Default)]
struct Undoes {
    dels: HashMap<Fact, String>,
    excl: HashMap<ExclKey, BTreeMap<String, String>>,
    /// The values in `excl`, all keys together.
    values: usize,
}

impl Undoes {
    fn size(&self) -> usize {
        self.dels.len() + self.values
    }

    /// Merges `other` into `self` (small into large: linear-logarithmic
    /// over a tree).
    fn absorb(&mut self, mut other: Undoes) {
        if other.size() > self.size() {
            std::mem::swap(self, &mut other);
        }
        for (f, by) in other.dels {
            self.dels.entry(f).or_insert(by);
        }
        for (k, vs) in other.excl {
            let e = self.excl.entry(k).or_default();
            for (v, by) in vs {
                if let std::collections::btree_map::Entry::Vacant(slot) = e.entry(v) {
                    slot.insert(by);
                    self.values += 1;
                }
            }
        }
    }

    /// The action undoing `f`, if one does.
    fn undoing(&self, d: &Domain, f: &Fact) -> Option<&str> {
        if let Some(by) = self.dels.get(f) {
            return Some(by);
        }
        let k = d.predicate(&f.pred)?.exclusive?;
        let mut rest = f.args.clone();
        rest.remove(k);
        let vs = self.excl.get(&(f.pred.clone(), rest))?;
        vs.iter()
            .find(|(v, _)| **v != f.args[k])
            .map(|(_, by)| by.as_str())
    }
}

/// The undoes of one action node.
fn of_action(d: &Domain, node: &btfsm_model::BtNode) -> Undoes {
    let mut u = Undoes::default();
    let Some(step) = node.skill.as_ref().and_then(|c| d.step_of(c)) else {
        return u;
    };
    let adds = step.adds();
    for f in step.deletes() {
        if !adds.contains(&f) {
            u.dels.insert(f, node.id.clone());
        }
    }
    for f in adds {
        if let Some(k) = d.predicate(&f.pred).and_then(|p| p.exclusive) {
            let mut rest = f.args.clone();
            let v = rest.remove(k);
            if u.excl
                .entry((f.pred.clone(), rest))
                .or_default()
                .insert(v, node.id.clone())
                .is_none()
            {
                u.values += 1;
            }
        }
    }
    u
}

fn chattering(p: &Subject, out: &mut Sink) {
    let PolicyBody::Bt(bt) = &p.body else { return };
    let d = btfsm_plan::domain::builtin();
    // Post-order: each subtree's undoes, built from its children's (small
    // into large), checked at each Sequence before they merge.
    let mut undoes: Vec<Option<Undoes>> = (0..bt.nodes.len()).map(|_| None).collect();
    let mut stack = vec![(bt.root, false)];
    while let Some((n, done)) = stack.pop() {
        let node = &bt.nodes[n];
        if !done {
            stack.push((n, true));
            stack.extend(node.children.iter().map(|&c| (c, false)));
            continue;
        }
        if matches!(node.kind, BtNodeKind::Sequence | BtNodeKind::SequenceMemory) {
            check_sequence(d, bt, n, &undoes, out);
        }
        let mut u = if node.kind == BtNodeKind::Action {
            of_action(d, node)
        } else {
            Undoes::default()
        };
        for &c in &node.children {
            if let Some(x) = undoes[c].take() {
                u.absorb(x);
            }
        }
        undoes[n] = Some(u);
    }
}

/// Sequence `n`: a later child undoing the fact an earlier child ensures.
/// Each later child is checked against the earlier facts or its undoes,
/// whichever is fewer.
fn check_sequence(d: &Domain, bt: &Bt, n: usize, undoes: &[Option<Undoes>], out: &mut Sink) {
    let node = &bt.nodes[n];
    let kids = &node.children;
    let mut earlier: Vec<(Fact, usize)> = Vec::new();
    let mut by_fact: HashMap<Fact, usize> = HashMap::new();
    // Per exclusive predicate and other arguments: up to two earlier facts
    // with distinct values of the exclusive argument.
    let mut by_key: HashMap<ExclKey, Vec<(String, usize, Fact)>> = HashMap::new();
    for (j, &c) in kids.iter().enumerate() {
        // The achieving action of a Sequence consumes its preconditions by
        // design (Place lets go of the cube): only subtrees count.
        if bt.nodes[c].kind != BtNodeKind::Action
            && let Some(u) = undoes[c].as_ref()
            && !earlier.is_empty()
        {
            let hit: Option<(usize, Fact, String)> = if earlier.len() <= u.size() {
                earlier
                    .iter()
                    .find_map(|(f, i)| u.undoing(d, f).map(|by| (*i, f.clone(), by.to_string())))
            } else {
                u.dels
                    .iter()
                    .find_map(|(f, by)| by_fact.get(f).map(|&i| (i, f.clone(), by.clone())))
                    .or_else(|| {
                        u.excl.iter().find_map(|(key, vs)| {
                            let list = by_key.get(key)?;
                            // An earlier fact with another value of the
                            // exclusive argument: among the first two of
                            // the list, one differs from any one added value.
                            list.iter().take(2).find_map(|(v, i, f)| {
                                vs.iter()
                                    .find(|(w, _)| *w != v)
                                    .map(|(_, by)| (*i, f.clone(), by.clone()))
                            })
                        })
                    })
            };
            if let Some((i, f, by)) = hit {
                let (earlier_id, later) = (&bt.nodes[kids[i]].id, &bt.nodes[c].id);
                out.push(
                    &node.id,
                    node.span.clone(),
                    format!(
                        "in Sequence `{}`, `{later}` runs `{by}`, which undoes {f}, the condition `{earlier_id}` before it ensures: the Sequence goes back to `{earlier_id}` and the robot chatters between them",
                        node.id
                    ),
                    format!("put `{later}` before `{earlier_id}` (as `btfsm plan` orders preconditions)"),
                );
            }
        }
        if let Some(f) = ensured(d, bt, c) {
            by_fact.entry(f.clone()).or_insert(j);
            if let Some(k) = d.predicate(&f.pred).and_then(|p| p.exclusive) {
                let mut rest = f.args.clone();
                let v = rest.remove(k);
                let list = by_key.entry((f.pred.clone(), rest)).or_default();
                if list.len() < 2 && list.iter().all(|(w, _, _)| *w != v) {
                    list.push((v, j, f.clone()));
                }
            }
            earlier.push((f, j));
        }
    }
}

pub const UNGUARDED_FALLBACK_ACTION: Rule = Rule {
    code: "unguarded-fallback-action",
    level: Level::Warning,
    summary: "an action in a Fallback with no condition before it: it runs even when what it achieves already holds",
    check: unguarded,
};

fn unguarded(p: &Subject, out: &mut Sink) {
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

fn not_fault_tolerant(p: &Subject, out: &mut Sink) {
    let PolicyBody::Machine(m) = &p.body else {
        return;
    };
    // Fully connected states return to the SELECTOR on SUCCESS by the
    // paper's construction (`fully-connected-state`).
    let connected = btfsm_metrics::counts::fully_connected_states(m);
    for (i, s) in m.states.iter().enumerate() {
        if connected.contains(&i) {
            continue;
        }
        let StateBody::Task(Some(call)) = &s.body else {
            continue;
        };
        if btfsm_model::skill::skill_kind(&call.skill) == Some(btfsm_model::SkillKind::Condition) {
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

fn fully_connected(p: &Subject, out: &mut Sink) {
    let PolicyBody::Machine(m) = &p.body else {
        return;
    };
    let fc = btfsm_metrics::counts::fully_connected_states(m);
    if fc.is_empty() {
        return;
    }
    let det = btfsm_metrics::effort::detect(m);
    let (m_s, m_fc) = (det.sequential.len() as u64, det.connected.len() as u64);
    let cost = btfsm_metrics::effort::effort_formula(m_s, m_fc)
        - btfsm_metrics::effort::effort_formula(m_s, 0);
    for &i in &fc {
        out.push(
            &m.path(i),
            m.states[i].span.clone(),
            format!(
                "state `{}` is fully connected: with M_s = {m_s} and M_fc = {m_fc}, the fully connected states cost {cost} of the {} edits of Eq. 4",
                m.path(i),
                btfsm_metrics::effort::effort_formula(m_s, m_fc)
            ),
            "in a BT the same behavior is one subtree at the root (the paper's Fig. 16a)".into(),
        );
    }
}

pub const SELECTOR_WITHOUT_RETURN: Rule = Rule {
    code: "selector-without-return",
    level: Level::Note,
    summary: "an action state that hands over to a decision state (the SELECTOR) which never resumes it",
    check: selector_without_return,
};

/// The paper's fault-tolerant FSM (sec. IV-B, Fig. 4) sends an action
/// state's FAILURE to the SELECTOR, whose guards resume the task at the
/// state its conditions call for, that state included. An action state
/// with a transition into a decision state that has no transition back to
/// it is never retried from there: a failure there restarts the task
/// somewhere else. Fully connected states are exempt (they go to the
/// SELECTOR on SUCCESS by construction). Linear: each transition is read
/// twice, the decision states' targets kept in a set per decision state.
fn selector_without_return(p: &Subject, out: &mut Sink) {
    let PolicyBody::Machine(m) = &p.body else {
        return;
    };
    let decision: Vec<bool> = m
        .states
        .iter()
        .map(|s| matches!(s.body, StateBody::Decision))
        .collect();
    // Targets of each decision state.
    let mut resumes: std::collections::HashMap<usize, std::collections::HashSet<usize>> =
        Default::default();
    for (d, s) in m.states.iter().enumerate().filter(|(d, _)| decision[*d]) {
        let set = resumes.entry(d).or_default();
        for t in &s.transitions {
            if let Target::State(x) = t.target {
                set.insert(x);
            }
        }
    }
    if resumes.is_empty() {
        return;
    }
    let connected = btfsm_metrics::counts::fully_connected_states(m);
    for (i, s) in m.states.iter().enumerate() {
        let StateBody::Task(Some(call)) = &s.body else {
            continue;
        };
        if connected.contains(&i)
            || btfsm_model::skill::skill_kind(&call.skill)
                == Some(btfsm_model::SkillKind::Condition)
        {
            continue;
        }
        let mut seen = std::collections::HashSet::new();
        for t in &s.transitions {
            let Target::State(d) = t.target else { continue };
            if !decision[d] || !seen.insert(d) || resumes[&d].contains(&i) {
                continue;
            }
            out.push(
                &m.path(i),
                s.span.clone(),
                format!(
                    "action state `{}` goes to decision state `{}` on {}, which never comes back to it: the task is not resumed at `{}`",
                    m.path(i),
                    m.path(d),
                    t.trigger.label(),
                    m.path(i)
                ),
                format!(
                    "give `{}` a guarded transition back to `{}` (the condition under which it should run again), as the paper's Fig. 4 does",
                    m.path(d),
                    m.path(i)
                ),
            );
        }
    }
}
