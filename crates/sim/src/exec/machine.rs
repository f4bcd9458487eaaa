//! The FSM and HFSM executor (see the module doc of [`super`]): guards
//! checked before the skill runs, containers entered at their initial state,
//! outcomes passed up to the enclosing container.

use super::Leaves;
use crate::skills::{Call, Status};
use btfsm_model::{StateBody, StateMachine, Target, Trigger};
use std::ops::ControlFlow;
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
    /// Per state, the index of its transition on RUNNING, SUCCESS and
    /// FAILURE (the first written), so a step compares no strings.
    pub on_status: Vec<[Option<u32>; 3]>,
    /// The top-level outcomes include `RUNNING` (the Fig. 6 construction):
    /// the machine is re-entered after FAILURE.
    pub tick_driven: bool,
}

fn status_index(o: &str) -> Option<usize> {
    match o {
        "RUNNING" => Some(0),
        "SUCCESS" => Some(1),
        "FAILURE" => Some(2),
        _ => None,
    }
}

impl CompiledMachine {
    /// Resolves every state's binding and guard with `resolve`.
    pub fn new<E>(
        m: &StateMachine,
        mut resolve: impl FnMut(&btfsm_model::SkillCall) -> Result<Call, E>,
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
            let on_status = (m.states.iter())
                .map(|s| {
                    let mut on = [None; 3];
                    for (i, t) in s.transitions.iter().enumerate() {
                        if let Trigger::Outcome(o) = &t.trigger
                            && let Some(k) = status_index(o)
                        {
                            on[k].get_or_insert(i as u32);
                        }
                    }
                    on
                })
                .collect();
            Ok(CompiledMachine {
                m: m.clone(),
                call,
                guards,
                on_status,
                tick_driven: m.top.outcomes.iter().any(|x| x == "RUNNING"),
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
    /// `after_success = "keep-ticking"`: reaching the top-level outcome
    /// SUCCESS returns SUCCESS and the next step re-enters the machine at
    /// its initial state, instead of ending it.
    pub keep_ticking: bool,
    /// `after_failure = "keep-ticking"`: reaching FAILURE (a top-level
    /// outcome other than SUCCESS, or a state's outcome with no transition)
    /// returns FAILURE and the next tick re-enters the machine at its
    /// initial state (a task reset), instead of ending it. Set by default
    /// for a machine whose top-level outcomes include RUNNING.
    pub reenter_on_failure: bool,
}

/// Where a step goes next.
enum Flow<'a> {
    Enter(usize),
    /// An outcome of the region of the state's parent (`None`: top level).
    Up(Option<usize>, &'a str),
}

/// What entering a state did.
enum Entered<'a> {
    /// It was left at once: by a guard, or a container for its initial
    /// target.
    Left(Flow<'a>),
    /// It ran, with this status.
    Ran(Status),
}

impl MachineExec {
    pub fn new(c: Arc<CompiledMachine>, record: bool) -> Self {
        let current = Self::start(&c);
        MachineExec {
            current,
            finished: None,
            statuses: record.then(Vec::new),
            keep_ticking: false,
            reenter_on_failure: c.tick_driven,
            c,
        }
    }

    /// The state a run starts in (the scenario reader refuses machines that
    /// start in an outcome or hold parallel regions: see
    /// `sim::scenario::policies`).
    fn start(c: &CompiledMachine) -> usize {
        c.m.top.initial_state().unwrap_or(0)
    }

    fn holds(s: usize, terms: &GuardTerms, leaves: &mut impl Leaves) -> bool {
        terms.iter().all(|(c, neg)| leaves.condition(s, c) != *neg)
    }

    fn follow<'a>(c: &'a CompiledMachine, from: usize, t: &'a Target) -> Flow<'a> {
        match t {
            Target::State(s) => Flow::Enter(*s),
            Target::Outcome(o) => Flow::Up(c.m.states[from].parent, o),
            Target::OuterOutcome { owner, outcome } => Flow::Up(*owner, outcome),
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
        let mut flow = self.preempted(&c, leaves);
        loop {
            hops += 1;
            if hops > limit {
                // A cycle of instantaneous transitions: wait for the next step.
                return Status::Running;
            }
            let (from, outcome) = match flow {
                Flow::Up(None, o) => return self.top_outcome(&c, o),
                Flow::Up(Some(container), o) => (container, o),
                Flow::Enter(s) => match self.enter(&c, s, leaves) {
                    Entered::Left(f) => {
                        flow = f;
                        continue;
                    }
                    Entered::Ran(st) => (s, st.as_str()),
                },
            };
            match self.on_outcome(&c, from, outcome) {
                ControlFlow::Continue(f) => flow = f,
                ControlFlow::Break(st) => return st,
            }
        }
    }

    /// Where the step starts: the current state, or where the first guard
    /// that holds of its enclosing containers (outermost first) leads.
    fn preempted<'a>(&self, c: &'a CompiledMachine, leaves: &mut impl Leaves) -> Flow<'a> {
        // Guards of the enclosing containers, outermost first.
        let mut anc = Vec::new();
        let mut p = c.m.states[self.current].parent;
        while let Some(a) = p {
            anc.push(a);
            p = c.m.states[a].parent;
        }
        for &a in anc.iter().rev() {
            for (g, t) in &c.guards[a] {
                if Self::holds(a, g, leaves) {
                    // The running state is left: its action is halted now.
                    leaves.halt(self.current);
                    return Self::follow(c, a, t);
                }
            }
        }
        Flow::Enter(self.current)
    }

    /// Reaching the top-level outcome `o`: the machine is re-entered (at
    /// RUNNING, or as `keep_ticking` and `reenter_on_failure` say) or ends.
    fn top_outcome(&mut self, c: &CompiledMachine, o: &str) -> Status {
        if o == "RUNNING" {
            self.current = Self::start(c);
            return Status::Running;
        }
        if o == "SUCCESS" && self.keep_ticking {
            self.current = Self::start(c);
            return Status::Success;
        }
        // `after_failure = "keep-ticking"` (the default of a tick-driven
        // machine, top-level outcome RUNNING, as the BT -> HFSM
        // construction makes): re-entered after a failure, as a BT's root
        // is ticked again.
        if o != "SUCCESS" && self.reenter_on_failure {
            self.current = Self::start(c);
            return Status::Failure;
        }
        let st = if o == "SUCCESS" {
            Status::Success
        } else {
            Status::Failure
        };
        self.finished = Some((o.to_string(), format!("reached the outcome {o}")));
        st
    }

    /// Enters state `s`: a guard that holds leaves it, a container goes on
    /// at its initial target, a task runs its skill (noted).
    fn enter<'a>(
        &mut self,
        c: &'a CompiledMachine,
        s: usize,
        leaves: &mut impl Leaves,
    ) -> Entered<'a> {
        // A state left by a guard runs nothing (and is not noted).
        if let Some((_, t)) = c.guards[s].iter().find(|(g, _)| Self::holds(s, g, leaves)) {
            // Preempted: a running action of the state is halted at once (a
            // state entered afresh has none).
            leaves.halt(s);
            return Entered::Left(Self::follow(c, s, t));
        }
        let st = match &c.m.states[s].body {
            StateBody::Container(r) => {
                return Entered::Left(match &r.initial {
                    Target::State(i) => Flow::Enter(*i),
                    Target::Outcome(o) | Target::OuterOutcome { outcome: o, .. } => {
                        Flow::Up(Some(s), o)
                    }
                });
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
        Entered::Ran(st)
    }

    /// State `from` ended with `outcome`: its transition for it is followed
    /// (`Continue`), or the step ends with a status (`Break`).
    fn on_outcome<'a>(
        &mut self,
        c: &'a CompiledMachine,
        from: usize,
        outcome: &str,
    ) -> ControlFlow<Status, Flow<'a>> {
        let transitions = &c.m.states[from].transitions;
        let tr = match status_index(outcome) {
            Some(k) => c.on_status[from][k].map(|i| &transitions[i as usize]),
            None => (transitions.iter())
                .find(|t| matches!(&t.trigger, Trigger::Outcome(o) if *o == outcome)),
        };
        match tr {
            Some(t) => match Self::follow(c, from, &t.target) {
                Flow::Enter(next) if outcome == "RUNNING" => {
                    self.current = next;
                    ControlFlow::Break(Status::Running)
                }
                f => ControlFlow::Continue(f),
            },
            None if outcome == "RUNNING" => {
                self.current = from;
                ControlFlow::Break(Status::Running)
            }
            None if self.reenter_on_failure && outcome != "SUCCESS" => {
                self.current = Self::start(c);
                ControlFlow::Break(Status::Failure)
            }
            None => {
                self.finished = Some((
                    "FAILURE".into(),
                    format!(
                        "state `{}` returned {outcome} and has no transition for it",
                        c.m.path(from)
                    ),
                ));
                ControlFlow::Break(Status::Failure)
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use btfsm_format::{Limits, toml::parse_str};
    use btfsm_model::PolicyBody;
    use std::path::Path;

    /// Leaves that log what the executor does: ticks and halts, in order.
    struct Log {
        battery_ok: bool,
        log: Vec<String>,
    }

    impl Leaves for Log {
        fn condition(&mut self, _: usize, _: &Call) -> bool {
            self.battery_ok
        }
        fn action(&mut self, key: usize, call: &Call) -> Status {
            self.log.push(format!("tick {key} {}", call.name()));
            Status::Running
        }
        fn halt(&mut self, key: usize) {
            self.log.push(format!("halt {key}"));
        }
        fn now(&self) -> f64 {
            0.0
        }
    }

    /// A guard that preempts a state whose action is running halts that
    /// action at once, before the next state's action is ticked; with
    /// `keep_ticking`, SUCCESS re-enters the machine instead of ending it.
    #[test]
    fn a_preempting_guard_halts_the_running_action_first() {
        let text = r#"
kind = "fsm"
initial = "A"
outcomes = ["SUCCESS"]
[states.A]
skill = "Tuck-Arm"
guards = [{ unless = "Battery-Level", args = { min = 20 }, to = "R" }]
on = { SUCCESS = "SUCCESS" }
[states.R]
skill = "Recharge"
on = { SUCCESS = "A" }
"#;
        let l = parse_str("f.toml", text, Path::new("."), &Limits::default()).unwrap();
        let PolicyBody::Machine(m) = &l.policy.body else {
            panic!("an FSM")
        };
        let cm = super::super::tests::recharge_machine(m);
        let a = m.states.iter().position(|s| s.name == "A").unwrap();
        let r = m.states.iter().position(|s| s.name == "R").unwrap();
        let mut ex = MachineExec::new(Arc::new(cm), false);
        let mut leaves = Log {
            battery_ok: true,
            log: vec![],
        };
        assert_eq!(ex.step(&mut leaves), Status::Running);
        leaves.battery_ok = false;
        assert_eq!(ex.step(&mut leaves), Status::Running);
        assert_eq!(
            leaves.log,
            vec![
                format!("tick {a} Tuck-Arm"),
                format!("halt {a}"),
                format!("tick {r} Recharge"),
            ]
        );
    }
}
