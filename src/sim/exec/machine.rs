//! The FSM and HFSM executor (see the module doc of [`super`]): guards
//! checked before the skill runs, containers entered at their initial state,
//! outcomes passed up to the enclosing container.

use super::Leaves;
use crate::model::{StateBody, StateMachine, Target, Trigger};
use crate::sim::skills::{Call, Status};
use std::sync::Arc;

/// One guard: all terms (`call`, negated) must hold.
pub type GuardTerms = Vec<(Call, bool)>;

/// A machine with its bindings resolved.
#[derive(Debug)]
pub struct CompiledMachine {
    pub m: StateMachine,
    pub call: Vec<Option<Call>>,
    /// Per state: its guards in order, with their targets.
    pub guards: Vec<Vec<(GuardTerms, Target)>>,
}

impl CompiledMachine {
    /// Resolves every state's binding and guard with `resolve`.
    pub fn new<E>(
        m: &StateMachine,
        mut resolve: impl FnMut(&crate::model::SkillCall) -> Result<Call, E>,
    ) -> Result<Self, Vec<(usize, E)>> {
        let mut errs = Vec::new();
        let mut call = vec![None; m.states.len()];
        let mut guards = vec![Vec::new(); m.states.len()];
        for (i, s) in m.states.iter().enumerate() {
            if let StateBody::Task(Some(c)) = &s.body {
                match resolve(c) {
                    Ok(c) => call[i] = Some(c),
                    Err(e) => errs.push((i, e)),
                }
            }
            for t in &s.transitions {
                if let Trigger::Guard(g) = &t.trigger {
                    let mut terms = Vec::new();
                    for term in &g.all {
                        match resolve(&term.condition) {
                            Ok(c) => terms.push((c, term.negate)),
                            Err(e) => errs.push((i, e)),
                        }
                    }
                    guards[i].push((terms, t.target.clone()));
                }
            }
        }
        if errs.is_empty() {
            Ok(CompiledMachine {
                m: m.clone(),
                call,
                guards,
            })
        } else {
            Err(errs)
        }
    }
}

/// The run-time state of an FSM or HFSM.
#[derive(Debug)]
pub struct MachineExec {
    pub c: Arc<CompiledMachine>,
    pub current: usize,
    /// The outcome the machine ended with, and why.
    pub finished: Option<(String, String)>,
    /// When `Some`, every state run in the last step with its status.
    pub statuses: Option<Vec<(usize, Status)>>,
}

enum Flow {
    Enter(usize),
    /// An outcome of the region of the state's parent (`None`: top level).
    Up(Option<usize>, String),
}

impl MachineExec {
    pub fn new(c: Arc<CompiledMachine>, record: bool) -> Self {
        let current = c.m.top.initial;
        MachineExec {
            c,
            current,
            finished: None,
            statuses: record.then(Vec::new),
        }
    }

    fn holds(s: usize, terms: &GuardTerms, leaves: &mut impl Leaves) -> bool {
        terms.iter().all(|(c, neg)| leaves.condition(s, c) != *neg)
    }

    fn follow(&self, from: usize, t: &Target) -> Flow {
        match t {
            Target::State(s) => Flow::Enter(*s),
            Target::Outcome(o) => Flow::Up(self.c.m.states[from].parent, o.clone()),
        }
    }

    fn note(&mut self, s: usize, st: Status) {
        if let Some(v) = &mut self.statuses {
            v.push((s, st));
        }
    }

    /// Runs one step; `Some` once the machine has ended (SUCCESS for the
    /// outcome `SUCCESS`, FAILURE for any other).
    pub fn step(&mut self, leaves: &mut impl Leaves) -> Status {
        if let Some((o, _)) = &self.finished {
            return if o == "SUCCESS" {
                Status::Success
            } else {
                Status::Failure
            };
        }
        if let Some(v) = &mut self.statuses {
            v.clear();
        }
        let c = self.c.clone();
        let limit = 4 * c.m.states.len() + 16;
        let mut hops = 0;
        // Guards of the enclosing containers, outermost first.
        let mut anc = Vec::new();
        let mut p = c.m.states[self.current].parent;
        while let Some(a) = p {
            anc.push(a);
            p = c.m.states[a].parent;
        }
        let mut flow = Flow::Enter(self.current);
        'anc: for &a in anc.iter().rev() {
            for (g, t) in &c.guards[a] {
                if Self::holds(a, g, leaves) {
                    flow = self.follow(a, t);
                    break 'anc;
                }
            }
        }
        loop {
            hops += 1;
            if hops > limit {
                // A cycle of instantaneous transitions: wait for the next step.
                return Status::Running;
            }
            let (from, outcome) = match flow {
                Flow::Up(None, o) => {
                    if o == "RUNNING" {
                        self.current = c.m.top.initial;
                        return Status::Running;
                    }
                    // A tick-driven machine (top-level outcome RUNNING, as the
                    // BT -> HFSM construction makes) is re-entered after a
                    // failure, as a BT's root is ticked again.
                    if o != "SUCCESS" && c.m.top.outcomes.iter().any(|x| x == "RUNNING") {
                        self.current = c.m.top.initial;
                        return Status::Failure;
                    }
                    let st = if o == "SUCCESS" {
                        Status::Success
                    } else {
                        Status::Failure
                    };
                    self.finished = Some((o.clone(), format!("reached the outcome {o}")));
                    return st;
                }
                Flow::Up(Some(container), o) => (container, o),
                Flow::Enter(s) => {
                    // A state left by a guard runs nothing (and is not noted).
                    if let Some((_, t)) =
                        c.guards[s].iter().find(|(g, _)| Self::holds(s, g, leaves))
                    {
                        flow = self.follow(s, t);
                        continue;
                    }
                    let st = match &c.m.states[s].body {
                        StateBody::Container(r) => {
                            flow = Flow::Enter(r.initial);
                            continue;
                        }
                        StateBody::Decision => Status::Running,
                        StateBody::Task(_) => match &c.call[s] {
                            Some(call) if call.is_action() => leaves.action(s, call),
                            Some(call) => {
                                if leaves.condition(s, call) {
                                    Status::Success
                                } else {
                                    Status::Failure
                                }
                            }
                            None => Status::Failure,
                        },
                    };
                    self.note(s, st);
                    (s, st.as_str().to_string())
                }
            };
            let tr = c.m.states[from]
                .transitions
                .iter()
                .find(|t| matches!(&t.trigger, Trigger::Outcome(o) if *o == outcome));
            match tr {
                Some(t) => match self.follow(from, &t.target) {
                    Flow::Enter(next) if outcome == "RUNNING" => {
                        self.current = next;
                        return Status::Running;
                    }
                    f => flow = f,
                },
                None if outcome == "RUNNING" => {
                    self.current = from;
                    return Status::Running;
                }
                None => {
                    self.finished = Some((
                        "FAILURE".into(),
                        format!(
                            "state `{}` returned {outcome} and has no transition for it",
                            c.m.path(from)
                        ),
                    ));
                    return Status::Failure;
                }
            }
        }
    }
}
