//! The fault-tolerant FSM of a plan (the paper's sec. IV-B structure, Fig.
//! 4): one state per step of the plan, a SELECTOR, and the outcome. Every
//! step's state goes on `SUCCESS` to the next step (the last to `SUCCESS`),
//! on `FAILURE` to the SELECTOR, and stays on `RUNNING`. The SELECTOR
//! resumes the task at the latest step whose *kernel* holds: the facts that
//! must hold before step k for steps k..n to reach the goal — the goal
//! regressed through the steps, `K(n+1) = goal`, `K(k) = pre(k) ∪ (K(k+1) −
//! add(k))`, the kernels of the STRIPS triangle table (Fikes, Hart &
//! Nilsson 1972, "Learning and executing generalized robot plans"). Tested
//! latest first, so the machine resumes correctly whatever facts a
//! disturbance undid. The first step's kernel is usually empty (the plan
//! starts from anywhere): its guard is then "not the second kernel", which
//! is what the SELECTOR already knows there, as Fig. 4 writes it.
//!
//! The plan is the BT's nominal execution: at each Fallback its first
//! (cheapest) achiever, each Sequence in order. A step restoring a goal fact
//! of a `volatile` predicate (one the world makes false at any time, the
//! battery level) is not a step of the chain but a *connected* state, as
//! the paper builds Recharge (Figs. 8d, 16b): every other state and the
//! SELECTOR go to it when the fact does not hold (checked first), it
//! returns to the SELECTOR on `SUCCESS` and stays on `RUNNING`.

use super::backchain::{Planned, Step};
use super::domain::Domain;
use super::fact::Fact;
use btfsm_model::skill::Guard;
use btfsm_model::{
    BtNodeKind, Region, State, StateBody, StateMachine, Target, Transition, Trigger,
};

/// Why no FSM can be made.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum FsmError {
    #[error("the plan has no step: the goal holds by itself or no action achieves it")]
    NoStep,
}

/// The plan's steps in nominal execution order.
pub fn steps<'d>(d: &'d Domain, p: &Planned) -> Vec<Step<'d>> {
    let bt = &p.bt;
    let mut out = Vec::new();
    let mut stack = vec![bt.root];
    while let Some(n) = stack.pop() {
        let node = &bt.nodes[n];
        match node.kind {
            BtNodeKind::Action => {
                if let Some((a, bind)) = &p.steps[n] {
                    out.push(Step {
                        action: &d.actions[*a],
                        bind: bind.clone(),
                    });
                }
            }
            BtNodeKind::Fallback | BtNodeKind::FallbackMemory => {
                // The condition is checked, then the first achiever runs.
                if let Some(&first) = node.children.get(1) {
                    stack.push(first);
                }
            }
            _ => stack.extend(node.children.iter().rev()),
        }
    }
    out
}

/// The kernels `K(1)..K(n+1)` of `steps` for `goal` (facts in order: a
/// step's preconditions first, then what later steps still need).
pub fn kernels(steps: &[Step<'_>], goal: &[Fact]) -> Vec<Vec<Fact>> {
    let mut out = vec![goal.to_vec()];
    for s in steps.iter().rev() {
        let adds = s.adds();
        let next = out.last().expect("one");
        let mut k = s.pre();
        for f in next {
            if !adds.contains(f) && !k.contains(f) {
                k.push(f.clone());
            }
        }
        out.push(k);
    }
    out.reverse();
    out
}

fn state_name(d: &Domain, s: &Step<'_>) -> String {
    d.fill(&s.action.label, &s.bind)
        .trim_end_matches('!')
        .to_string()
}

/// The fault-tolerant FSM of the planned tree (see the module docs).
#[expect(clippy::too_many_lines, reason = "to be split: issue 28")]
pub fn plan_fsm(d: &Domain, p: &Planned) -> Result<StateMachine, FsmError> {
    let all = steps(d, p);
    // Steps restoring a volatile goal fact (a battery level) are connected
    // states; the others are the task's chain.
    let volatile: Vec<&Fact> = d
        .goal
        .facts
        .iter()
        .filter(|f| d.predicate(&f.pred).is_some_and(|q| q.volatile))
        .collect();
    let (connected, steps): (Vec<Step<'_>>, Vec<Step<'_>>) = all
        .into_iter()
        .partition(|s| s.adds().iter().any(|f| volatile.contains(&f)));
    if steps.is_empty() {
        return Err(FsmError::NoStep);
    }
    let goal: Vec<Fact> = d
        .goal
        .facts
        .iter()
        .filter(|f| !volatile.contains(f))
        .cloned()
        .collect();
    let ks = kernels(&steps, &goal);
    let n = steps.len();
    let sel = n;
    let mut names: Vec<String> = Vec::new();
    for s in steps.iter().chain(&connected) {
        let mut name = state_name(d, s);
        let mut k = 2;
        while names.contains(&name) || name == "SELECTOR" {
            name = format!("{} ({k})", state_name(d, s));
            k += 1;
        }
        names.push(name);
    }
    // Entering a connected state: the guard "its fact does not hold".
    let mut to_connected: Vec<Transition> = Vec::new();
    for (c, s) in connected.iter().enumerate() {
        let f = s
            .adds()
            .into_iter()
            .find(|f| volatile.contains(&f))
            .expect("partitioned on it");
        let t = d.fact_term(&f, true);
        to_connected.push(Transition {
            trigger: Trigger::Guard(Guard {
                label: t.to_string(),
                all: vec![t],
            }),
            target: Target::State(n + 1 + c),
            span: None,
        });
    }
    let task = |s: &Step<'_>| {
        StateBody::Task(s.action.skill.as_ref().map(|skill| {
            let objs: Vec<String> = s
                .action
                .params
                .iter()
                .map(|p| s.bind[&p.name].clone())
                .collect();
            Domain::skill_call(skill, &s.action.params, &objs)
        }))
    };
    let mut states: Vec<State> = Vec::new();
    for (i, s) in steps.iter().enumerate() {
        let next = if i + 1 < n {
            Target::State(i + 1)
        } else {
            Target::Outcome("SUCCESS".into())
        };
        let mut transitions = to_connected.clone();
        transitions.extend([
            Transition::on_outcome("SUCCESS", next),
            Transition::on_outcome("FAILURE", Target::State(sel)),
            Transition::on_outcome("RUNNING", Target::State(i)),
        ]);
        states.push(State {
            name: names[i].clone(),
            label: names[i].clone(),
            parent: None,
            body: task(s),
            transitions,
            pseudo: None,
            span: None,
        });
    }
    let label = |fs: &[Fact]| {
        fs.iter()
            .map(ToString::to_string)
            .collect::<Vec<_>>()
            .join(" and ")
    };
    let mut guards = to_connected.clone();
    for k in (0..=n).rev() {
        let target = if k == n {
            Target::Outcome("SUCCESS".into())
        } else {
            Target::State(k)
        };
        let (all, text) = if !ks[k].is_empty() {
            let all: Vec<_> = ks[k].iter().map(|f| d.fact_term(f, false)).collect();
            let text = if k == n {
                format!("done: {}", label(&ks[k]))
            } else {
                label(&ks[k])
            };
            (all, text)
        } else {
            // Nothing needed: every later kernel failed. Written as "not the
            // next kernel's first fact", which the SELECTOR knows here.
            match ks.get(k + 1).and_then(|next| next.first()) {
                Some(f) => (vec![d.fact_term(f, true)], "restart the task".to_string()),
                None => (vec![], "restart the task".to_string()),
            }
        };
        if all.is_empty() {
            continue;
        }
        guards.push(Transition {
            trigger: Trigger::Guard(Guard { all, label: text }),
            target,
            span: None,
        });
    }
    guards.push(Transition::on_outcome("RUNNING", Target::State(sel)));
    states.push(State {
        name: "SELECTOR".into(),
        label: "SELECTOR".into(),
        parent: None,
        body: StateBody::Decision,
        transitions: guards,
        pseudo: None,
        span: None,
    });
    for (c, s) in connected.iter().enumerate() {
        let i = n + 1 + c;
        states.push(State {
            name: names[n + c].clone(),
            label: names[n + c].clone(),
            parent: None,
            body: task(s),
            transitions: vec![
                Transition::on_outcome("SUCCESS", Target::State(sel)),
                Transition::on_outcome("RUNNING", Target::State(i)),
            ],
            pseudo: None,
            span: None,
        });
    }
    let count = states.len();
    Ok(StateMachine {
        hierarchical: false,
        top: Region::at(0, vec!["SUCCESS".into()], (0..count).collect()),
        states,
    })
}
