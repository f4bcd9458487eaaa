//! A FlexBE behavior's containers (read by `collect`) made into the
//! FSM/HFSM model, checked as flexbe_core checks them when the behavior is
//! built and run (`StateMachine.add` refuses a label added twice or named
//! like an outcome; `_execute_current_state` resolves a transition target
//! to a label first, then to an outcome of the container). Containers are
//! walked from the one `create` returns with a queue (no recursion).

use super::collect::{Add, Behavior, Container, Kind, StateRef};
use crate::Limits;
use btfsm_core::diagnostic::{Diagnostic, SourceFile};
use btfsm_core::sanitize::shown;
use btfsm_model::{
    Policy, PolicyBody, Region, State, StateBody, StateMachine, Target, Transition, Trigger,
};
use std::collections::{HashMap, VecDeque};
use std::ops::Range;
use std::sync::Arc;

struct Cx<'a> {
    file: &'a Arc<SourceFile>,
    diags: &'a mut Vec<Diagnostic>,
    limits: &'a Limits,
}

impl Cx<'_> {
    fn err(&mut self, at: Range<usize>, msg: String, hint: impl Into<String>) {
        self.diags
            .push(Diagnostic::error(msg).at(self.file, at).hint(hint));
    }
}

/// The behavior as a machine; `None` (with errors) when it does not hold
/// together.
pub(super) fn build(
    b: Behavior,
    file: &Arc<SourceFile>,
    limits: &Limits,
    diags: &mut Vec<Diagnostic>,
) -> Option<Policy> {
    let mut cx = Cx {
        file,
        diags,
        limits,
    };
    let by_var: HashMap<&str, usize> = b
        .containers
        .iter()
        .enumerate()
        .map(|(i, c)| (c.var.as_str(), i))
        .collect();
    let (top_var, top_span) = &b.top;
    let Some(&top) = by_var.get(top_var.as_str()) else {
        cx.err(
            top_span.clone(),
            format!(
                "`create` returns `{}`, which is no container",
                shown(top_var)
            ),
            "return the variable bound to `OperatableStateMachine(outcomes=[...])`",
        );
        return None;
    };
    let mut m = StateMachine::unset();
    let mut used = vec![false; b.containers.len()];
    used[top] = true;
    // (container, the state it fills or `None` for the top, depth)
    let mut queue = VecDeque::from([(top, None::<usize>, 0usize)]);
    while let Some((ci, owner, depth)) = queue.pop_front() {
        let c = &b.containers[ci];
        if depth > cx.limits.max_depth {
            cx.err(
                c.span.clone(),
                format!(
                    "containers nested deeper than the limit of {} levels",
                    cx.limits.max_depth
                ),
                "raise the limit with --max-depth",
            );
            return None;
        }
        let region = region(&mut cx, &mut m, c, owner)?;
        for (add, &s) in c.adds.iter().zip(&region.states) {
            if let StateRef::Container(var, at) = &add.state {
                let child = by_var[var.as_str()];
                if std::mem::replace(&mut used[child], true) {
                    cx.err(
                        at.clone(),
                        format!("container `{}` is added a second time", shown(var)),
                        "a container is one state: define another one for the second use",
                    );
                    return None;
                }
                queue.push_back((child, Some(s), depth + 1));
            }
        }
        match owner {
            None => m.top = region,
            Some(s) => m.states[s].body = StateBody::Container(region),
        }
    }
    check_container_outcomes(&mut cx, &m);
    if cx.diags.iter().any(Diagnostic::is_error) {
        return None;
    }
    m.hierarchical = m
        .states
        .iter()
        .any(|s| matches!(s.body, StateBody::Container(_)));
    Some(Policy {
        name: b.name,
        description: b.description,
        body: PolicyBody::Machine(m),
    })
}

/// The states of container `c`, added to `m` inside `owner`, with their
/// transitions, as a region.
fn region(
    cx: &mut Cx<'_>,
    m: &mut StateMachine,
    c: &Container,
    owner: Option<usize>,
) -> Option<Region> {
    if c.adds.is_empty() {
        cx.err(
            c.span.clone(),
            format!("container `{}` has no states", shown(&c.var)),
            "add its states in a `with` block: `with VAR: OperatableStateMachine.add('Name', ...)`",
        );
        return None;
    }
    let mut names: HashMap<&str, usize> = HashMap::new();
    let mut states = Vec::with_capacity(c.adds.len());
    for add in &c.adds {
        if m.states.len() >= cx.limits.max_nodes {
            cx.err(
                add.name_span.clone(),
                format!("more than {} states", cx.limits.max_nodes),
                "raise the limit with --max-nodes",
            );
            return None;
        }
        if names.contains_key(add.name.as_str()) {
            cx.err(
                add.name_span.clone(),
                format!("state `{}` is added twice to this container", shown(&add.name)),
                "labels are unique within their container (flexbe_core's `StateMachine.add` refuses a second one)",
            );
            continue;
        }
        if c.outcomes.contains(&add.name) {
            cx.err(
                add.name_span.clone(),
                format!(
                    "state `{}` has the name of an outcome of this container",
                    shown(&add.name)
                ),
                "rename the state or the outcome (flexbe_core's `StateMachine.add` refuses it)",
            );
            continue;
        }
        let idx = m.states.len();
        m.states.push(State {
            name: add.name.clone(),
            label: label(add),
            parent: owner,
            body: match add.state {
                StateRef::Container(..) => StateBody::Container(Region::unset(vec![])),
                StateRef::Task => StateBody::Task(None),
            },
            transitions: Vec::new(),
            pseudo: None,
            span: Some(add.name_span.clone()),
        });
        names.insert(&add.name, idx);
        states.push(idx);
    }
    if states.len() != c.adds.len() {
        return None;
    }
    for (add, &s) in c.adds.iter().zip(&states) {
        m.states[s].transitions = transitions(cx, c, add, &names);
    }
    check_conditions(cx, c, &names);
    Some(Region {
        parallel: c.kind == Kind::Concurrent,
        ..Region::at(states[0], c.outcomes.clone(), states)
    })
}

/// A state's transitions: each target a state of its container, else one
/// of the container's outcomes.
fn transitions(
    cx: &mut Cx<'_>,
    c: &Container,
    add: &Add,
    names: &HashMap<&str, usize>,
) -> Vec<Transition> {
    let mut out = Vec::with_capacity(add.transitions.len());
    for (outcome, target, at) in &add.transitions {
        let target = if let Some(&s) = names.get(target.as_str()) {
            Target::State(s)
        } else if c.outcomes.contains(target) {
            Target::Outcome(target.clone())
        } else {
            let mut valid: Vec<&str> = c.adds.iter().map(|a| a.name.as_str()).collect();
            valid.extend(c.outcomes.iter().map(String::as_str));
            let valid: Vec<String> = valid
                .iter()
                .take(12)
                .map(|v| format!("`{}`", shown(v)))
                .collect();
            cx.err(
                at.clone(),
                format!(
                    "transition target `{}` is neither a state of container `{}` nor one of its outcomes",
                    shown(target),
                    shown(&c.var)
                ),
                format!("valid: {}", valid.join(", ")),
            );
            continue;
        };
        out.push(Transition {
            trigger: Trigger::Outcome(outcome.clone()),
            target,
            span: Some(at.clone()),
        });
    }
    out
}

/// A ConcurrencyContainer's conditions name its outcomes and its states.
fn check_conditions(cx: &mut Cx<'_>, c: &Container, names: &HashMap<&str, usize>) {
    for (outcome, reqs, at) in &c.conditions {
        if !c.outcomes.contains(outcome) {
            cx.err(
                at.clone(),
                format!(
                    "condition for `{}`, which is not an outcome of container `{}`",
                    shown(outcome),
                    shown(&c.var)
                ),
                format!("valid: {}", quoted(&c.outcomes)),
            );
        }
        if let Some((s, _)) = reqs.iter().find(|(s, _)| !names.contains_key(s.as_str())) {
            cx.err(
                at.clone(),
                format!("condition names `{}`, which is not a state of container `{}`", shown(s), shown(&c.var)),
                "a condition is `('outcome', [('State', 'state outcome'), ...])` over the states added to the container",
            );
        }
    }
}

/// A nested container's transitions map only outcomes it has (its own
/// content is read after its parent's).
fn check_container_outcomes(cx: &mut Cx<'_>, m: &StateMachine) {
    for s in &m.states {
        let StateBody::Container(r) = &s.body else {
            continue;
        };
        for t in &s.transitions {
            let Trigger::Outcome(o) = &t.trigger else {
                continue;
            };
            if !r.outcomes.contains(o) {
                let at = t.span.clone().unwrap_or(0..0);
                cx.err(
                    at,
                    format!(
                        "container state `{}` has no outcome `{}`",
                        shown(&s.name),
                        shown(o)
                    ),
                    format!("valid: {}", quoted(&r.outcomes)),
                );
            }
        }
    }
}

fn quoted(v: &[String]) -> String {
    v.iter()
        .take(12)
        .map(|o| format!("`{}`", shown(o)))
        .collect::<Vec<_>>()
        .join(", ")
}

/// A state's label: its name, and its autonomy levels when it has any
/// (`Decide [back:High done:Low]`).
fn label(add: &Add) -> String {
    if add.autonomy.is_empty() {
        return add.name.clone();
    }
    let levels: Vec<String> = add
        .autonomy
        .iter()
        .map(|(o, l)| format!("{o}:{l}"))
        .collect();
    format!("{} [{}]", add.name, levels.join(" "))
}
