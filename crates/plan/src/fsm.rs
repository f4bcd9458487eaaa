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

/// The plan's steps in nominal execution order: the BT walked from a world
/// where nothing holds (`walked_steps`), so that every step stays in the
/// chain for the SELECTOR to resume at. With initial facts (`init`,
/// `--init`, a PDDL problem's `:init`) that chain must also run from them
/// (each step's preconditions holding when it comes, or its effects
/// holding already, and the goal at the end); when it does not — a domain
/// where a fact has many achievers, such as a robot in one of many rooms —
/// the chain is what the BT does when ticked from them (`ticked_steps`).
pub fn steps<'d>(d: &'d Domain, p: &Planned) -> Vec<Step<'d>> {
    let walked = walked_steps(d, p);
    if d.goal.init.is_empty() || runs_from_init(d, &walked) {
        return walked;
    }
    let ticked = ticked_steps(d, p);
    if ticked.is_empty() { walked } else { ticked }
}

/// The facts after `step` completes: its deletes removed, then its adds.
fn complete(step: &Step<'_>, facts: &mut std::collections::BTreeSet<Fact>) {
    for f in step.deletes() {
        facts.remove(&f);
    }
    facts.extend(step.adds());
}

/// Whether `chain` runs from the initial facts to the goal (see [`steps`]).
fn runs_from_init(d: &Domain, chain: &[Step<'_>]) -> bool {
    let mut facts: std::collections::BTreeSet<Fact> = d.goal.init.iter().cloned().collect();
    for s in chain {
        if s.pre().iter().all(|f| facts.contains(f)) {
            complete(s, &mut facts);
        } else if !s.adds().iter().all(|f| facts.contains(f)) {
            return false;
        }
    }
    d.goal.facts.iter().all(|f| facts.contains(f))
}

/// The BT walked from a world where nothing holds, each step's effects
/// applied as it completes, so a
/// Fallback whose condition an earlier step made true (and no step undid
/// since) runs no achiever — a door unlocked once is not unlocked again
/// for the next part, a robot at the bench does not drive there again.
fn walked_steps<'d>(d: &'d Domain, p: &Planned) -> Vec<Step<'d>> {
    let bt = &p.bt;
    let mut out = Vec::new();
    let mut holds: Vec<Option<Fact>> = Vec::new();
    let mut stack = vec![bt.root];
    while let Some(n) = stack.pop() {
        let node = &bt.nodes[n];
        match node.kind {
            BtNodeKind::Action => {
                if let Some((a, bind)) = &p.steps[n] {
                    let step = Step {
                        action: &d.actions[*a],
                        bind: bind.clone(),
                    };
                    apply(d, &step, &mut holds);
                    out.push(step);
                }
            }
            BtNodeKind::Fallback | BtNodeKind::FallbackMemory => {
                // The condition is checked, then the first achiever runs.
                let checked = node.children.first().and_then(|&c| p.ensured[c].as_ref());
                if checked.is_some_and(|f| holds.iter().flatten().any(|h| h == f)) {
                    continue;
                }
                if let Some(&first) = node.children.get(1) {
                    stack.push(first);
                }
            }
            _ => stack.extend(node.children.iter().rev()),
        }
    }
    out
}

/// Most steps [`ticked_steps`] runs, and ticks of the root.
const MAX_TICKED_STEPS: usize = 10_000;
const MAX_TICKS: usize = 1_000;

/// What the BT does from the initial facts, ticked as BehaviorTree.CPP
/// ticks it with actions that complete at once: a condition succeeds when
/// its fact holds, an action when its preconditions hold (its effects then
/// apply: deletes, then adds), a Sequence runs its children until one does
/// not succeed, a Fallback until one does. The root is ticked again until
/// it succeeds or a tick runs no action (at most [`MAX_TICKS`] ticks and
/// [`MAX_TICKED_STEPS`] steps); the actions run, in order, are the chain.
fn ticked_steps<'d>(d: &'d Domain, p: &Planned) -> Vec<Step<'d>> {
    let mut facts: std::collections::BTreeSet<Fact> = d.goal.init.iter().cloned().collect();
    let mut out = Vec::new();
    for _ in 0..MAX_TICKS {
        let before = out.len();
        let ok = tick(d, p, p.bt.root, &mut facts, &mut out);
        if ok || out.len() == before || out.len() >= MAX_TICKED_STEPS {
            break;
        }
    }
    out
}

/// One tick of node `n` (see [`ticked_steps`]); whether it succeeded.
fn tick<'d>(
    d: &'d Domain,
    p: &Planned,
    n: usize,
    facts: &mut std::collections::BTreeSet<Fact>,
    out: &mut Vec<Step<'d>>,
) -> bool {
    let node = &p.bt.nodes[n];
    match node.kind {
        BtNodeKind::Condition => p.ensured[n].as_ref().is_some_and(|f| facts.contains(f)),
        BtNodeKind::Action => {
            let Some((a, bind)) = &p.steps[n] else {
                return false;
            };
            let step = Step {
                action: &d.actions[*a],
                bind: bind.clone(),
            };
            if out.len() >= MAX_TICKED_STEPS || !step.pre().iter().all(|f| facts.contains(f)) {
                return false;
            }
            complete(&step, facts);
            out.push(step);
            true
        }
        BtNodeKind::Fallback | BtNodeKind::FallbackMemory => {
            (node.children.iter()).any(|&c| tick(d, p, c, facts, out))
        }
        _ => (node.children.iter()).all(|&c| tick(d, p, c, facts, out)),
    }
}

/// The facts that hold after `step` completes where `holds` held.
fn apply(d: &Domain, step: &Step<'_>, holds: &mut Vec<Option<Fact>>) {
    let undone = super::conflicts::undone_by(d, step, holds);
    holds.retain(|f| f.as_ref().is_some_and(|f| !undone.contains(f)));
    for f in step.adds() {
        if !holds.iter().flatten().any(|h| *h == f) {
            holds.push(Some(f));
        }
    }
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
    let names = state_names(d, &steps, &connected);
    let to_connected = connected_guards(d, &connected, &volatile, n);
    let mut states: Vec<State> = Vec::new();
    for (i, s) in steps.iter().enumerate() {
        states.push(step_state(s, i, n, &names[i], &to_connected));
    }
    states.push(selector(d, &ks, to_connected));
    for (c, s) in connected.iter().enumerate() {
        states.push(connected_state(s, n + 1 + c, n, &names[n + c]));
    }
    let count = states.len();
    let start = start_state(&ks, &d.goal.init);
    Ok(StateMachine {
        hierarchical: false,
        top: Region::at(start, vec!["SUCCESS".into()], (0..count).collect()),
        states,
    })
}

/// Where the machine starts, with the `n + 1` kernels `ks`, when the facts
/// `init` hold at the start (and no other): the latest step whose kernel
/// holds, as the SELECTOR would resume; the SELECTOR (state `n`) when the
/// goal itself holds (it goes to `SUCCESS`) or no kernel does. Without
/// `init`: the first step, as Fig. 4 starts.
fn start_state(ks: &[Vec<Fact>], init: &[Fact]) -> usize {
    let n = ks.len() - 1;
    if init.is_empty() {
        return 0;
    }
    let init: std::collections::BTreeSet<&Fact> = init.iter().collect();
    let holds = |k: &Vec<Fact>| k.iter().all(|f| init.contains(f));
    if holds(&ks[n]) {
        return n;
    }
    (0..n).rev().find(|&k| holds(&ks[k])).unwrap_or(n)
}

/// The states' names, the chain's steps then the connected ones: each
/// step's label, numbered " (2)", " (3)"… when taken (or "SELECTOR").
fn state_names(d: &Domain, steps: &[Step<'_>], connected: &[Step<'_>]) -> Vec<String> {
    let mut names: Vec<String> = Vec::new();
    for s in steps.iter().chain(connected) {
        let mut name = state_name(d, s);
        let mut k = 2;
        while names.contains(&name) || name == "SELECTOR" {
            name = format!("{} ({k})", state_name(d, s));
            k += 1;
        }
        names.push(name);
    }
    names
}

/// The transitions into the connected states (numbered from `n + 1`), each
/// guarded by "its volatile fact does not hold".
fn connected_guards(
    d: &Domain,
    connected: &[Step<'_>],
    volatile: &[&Fact],
    n: usize,
) -> Vec<Transition> {
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
    to_connected
}

/// A step's body: the task calling its action's skill, if it has one.
fn task(s: &Step<'_>) -> StateBody {
    StateBody::Task(s.action.skill.as_ref().map(|skill| {
        let objs: Vec<String> = s
            .action
            .params
            .iter()
            .map(|p| s.bind[&p.name].clone())
            .collect();
        Domain::skill_call(skill, &s.action.params, &objs)
    }))
}

/// The state of step `i` of `n` in the chain: the connected states' guards
/// first, then on `SUCCESS` the next step (or `SUCCESS`), on `FAILURE` the
/// SELECTOR (state `n`), and itself on `RUNNING`.
fn step_state(s: &Step<'_>, i: usize, n: usize, name: &str, to_connected: &[Transition]) -> State {
    let next = if i + 1 < n {
        Target::State(i + 1)
    } else {
        Target::Outcome("SUCCESS".into())
    };
    let mut transitions = to_connected.to_vec();
    transitions.extend([
        Transition::on_outcome("SUCCESS", next),
        Transition::on_outcome("FAILURE", Target::State(n)),
        Transition::on_outcome("RUNNING", Target::State(i)),
    ]);
    State {
        name: name.to_string(),
        label: name.to_string(),
        parent: None,
        body: task(s),
        transitions,
        pseudo: None,
        span: None,
    }
}

/// Facts joined with " and ", as a guard's label.
fn facts_label(fs: &[Fact]) -> String {
    fs.iter()
        .map(ToString::to_string)
        .collect::<Vec<_>>()
        .join(" and ")
}

/// The SELECTOR (state `n`, with `ks` the `n + 1` kernels): after the
/// connected states' guards `guards`, one guard per kernel, latest first,
/// resuming at its step (the last one at `SUCCESS`); itself on `RUNNING`.
fn selector(d: &Domain, ks: &[Vec<Fact>], mut guards: Vec<Transition>) -> State {
    let n = ks.len() - 1;
    for k in (0..=n).rev() {
        if let Some(t) = kernel_guard(d, ks, k) {
            guards.push(t);
        }
    }
    guards.push(Transition::on_outcome("RUNNING", Target::State(n)));
    State {
        name: "SELECTOR".into(),
        label: "SELECTOR".into(),
        parent: None,
        body: StateBody::Decision,
        transitions: guards,
        pseudo: None,
        span: None,
    }
}

/// The SELECTOR's guard resuming at step `k` when kernel `ks[k]` holds (at
/// `SUCCESS` for the goal's kernel); `None` when there is nothing to test.
fn kernel_guard(d: &Domain, ks: &[Vec<Fact>], k: usize) -> Option<Transition> {
    let n = ks.len() - 1;
    let target = if k == n {
        Target::Outcome("SUCCESS".into())
    } else {
        Target::State(k)
    };
    let (all, text) = if !ks[k].is_empty() {
        let all: Vec<_> = ks[k].iter().map(|f| d.fact_term(f, false)).collect();
        let text = if k == n {
            format!("done: {}", facts_label(&ks[k]))
        } else {
            facts_label(&ks[k])
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
        return None;
    }
    Some(Transition {
        trigger: Trigger::Guard(Guard { all, label: text }),
        target,
        span: None,
    })
}

/// Connected state `i`: back to the SELECTOR (state `sel`) on `SUCCESS`,
/// itself on `RUNNING`.
fn connected_state(s: &Step<'_>, i: usize, sel: usize, name: &str) -> State {
    State {
        name: name.to_string(),
        label: name.to_string(),
        parent: None,
        body: task(s),
        transitions: vec![
            Transition::on_outcome("SUCCESS", Target::State(sel)),
            Transition::on_outcome("RUNNING", Target::State(i)),
        ],
        pseudo: None,
        span: None,
    }
}
