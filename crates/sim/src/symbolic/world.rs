//! The symbolic world: the facts of an action domain that hold, and the
//! actions running in it. A condition holds when its fact is true. An
//! action, on its first tick, fails at once when a precondition does not
//! hold; otherwise it runs for its duration (`durations`, default one step:
//! RUNNING until then) and then fails with its failure rate or succeeds and
//! applies its effects — the facts it deletes, the facts excluded by the
//! ones it adds (`exclusive` predicates), then the facts it adds. A halted
//! action has no effect. Nothing else changes the facts but disturbances.

use crate::exec::Leaves;
use crate::rng::SimRng;
use crate::skills::{Call, Status};
use btfsm_model::SkillCall;
use btfsm_plan::Domain;
use btfsm_plan::backchain::Step;
use btfsm_plan::fact::Fact;
use std::collections::{BTreeMap, BTreeSet, HashMap};

/// What a leaf or guard term of a policy stands for in the domain.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Binding {
    /// A condition: this fact holds.
    Fact(Fact),
    /// An action of the domain (index) with its parameters' objects.
    Action(usize, BTreeMap<String, String>),
}

/// The binding of a skill call: the predicate or else the action of the
/// domain that names the skill (a library skill, or the domain's own
/// `domain:Name`), its parameters taken from the call's arguments by name
/// ([`Domain::fact_of`], [`Domain::action_of`]).
pub fn binding(d: &Domain, c: &SkillCall) -> Option<Binding> {
    if d.predicates
        .iter()
        .any(|p| p.skill.as_deref() == Some(&c.skill))
    {
        return d.fact_of(c).map(Binding::Fact);
    }
    d.action_of(c).map(|(i, bind)| Binding::Action(i, bind))
}

/// An action instance of a leaf.
#[derive(Debug, Clone)]
struct Instance {
    left: u32,
    fails: bool,
}

/// The facts that hold, the running actions, and the log of finished ones.
pub struct World<'d> {
    pub domain: &'d Domain,
    pub facts: BTreeSet<Fact>,
    /// The bindings a policy's `Call::Symbolic(i)` stand for.
    pub table: Vec<Binding>,
    running: HashMap<usize, Instance>,
    durations: &'d BTreeMap<String, u32>,
    rates: BTreeMap<String, f64>,
    /// The episode's seed: each start's failure is drawn from a stream of
    /// its own, keyed by the call and its ordinal (common random numbers:
    /// policies that start the same actions meet the same failures).
    seed: u64,
    /// Starts so far per action instance (`Name(args)`).
    starts: HashMap<String, u32>,
    pub step: u64,
    /// Actions finished: (step, `Name(args)`, succeeded).
    pub done: Vec<(u64, String, bool)>,
}

impl<'d> World<'d> {
    pub fn new(
        domain: &'d Domain,
        facts: &[Fact],
        durations: &'d BTreeMap<String, u32>,
        rates: BTreeMap<String, f64>,
        seed: u64,
    ) -> Self {
        World {
            domain,
            facts: facts.iter().cloned().collect(),
            table: Vec::new(),
            running: HashMap::new(),
            durations,
            rates,
            seed,
            starts: HashMap::new(),
            step: 0,
            done: Vec::new(),
        }
    }

    /// The call a policy's leaf runs with: an index into the table.
    pub fn intern(&mut self, c: &SkillCall) -> Call {
        let b = binding(self.domain, c).expect("checked when the scenario was read");
        let action = matches!(b, Binding::Action(..));
        let i = match self.table.iter().position(|x| *x == b) {
            Some(i) => i,
            None => {
                self.table.push(b);
                self.table.len() - 1
            }
        };
        Call::Symbolic {
            id: i as u32,
            action,
        }
    }

    fn binding(&self, c: &Call) -> Option<&Binding> {
        match c {
            Call::Symbolic { id, .. } => self.table.get(*id as usize),
            _ => None,
        }
    }

    /// The actions running, by leaf, with the steps they have left (for
    /// the livelock state: a long action is not a recurring state).
    pub fn running_keys(&self) -> Vec<(usize, u32)> {
        let mut k: Vec<(usize, u32)> = self.running.iter().map(|(k, i)| (*k, i.left)).collect();
        k.sort_unstable();
        k
    }

    /// The random stream of this start of `step`'s action instance.
    fn fault_draw(&mut self, step: &Step<'_>) -> SimRng {
        let call = instance(step);
        let n = self.starts.entry(call.clone()).or_insert(0);
        let ordinal = *n;
        *n += 1;
        SimRng::named(
            self.seed,
            &format!("symbolic-fault\u{1f}{call}\u{1f}{ordinal}"),
        )
    }

    fn finish(&mut self, step: &Step<'_>, ok: bool) {
        let name = instance(step);
        self.done.push((self.step, name, ok));
        if !ok {
            return;
        }
        for f in step.deletes() {
            self.facts.remove(&f);
        }
        for f in step.adds() {
            if let Some(k) = self.domain.predicate(&f.pred).and_then(|p| p.exclusive) {
                self.facts.retain(|g| {
                    g.pred != f.pred
                        || g.args[k] == f.args[k]
                        || g.args
                            .iter()
                            .zip(&f.args)
                            .enumerate()
                            .any(|(i, (x, y))| i != k && x != y)
                });
            }
        }
        for f in step.adds() {
            self.facts.insert(f);
        }
    }
}

/// An action instance as the runs report it: `Name(arg, ...)`.
fn instance(step: &Step<'_>) -> String {
    format!(
        "{}({})",
        step.action.name,
        step.action
            .params
            .iter()
            .map(|p| step.bind[&p.name].as_str())
            .collect::<Vec<_>>()
            .join(", ")
    )
}

impl Leaves for World<'_> {
    fn condition(&mut self, _: usize, call: &Call) -> bool {
        match self.binding(call) {
            Some(Binding::Fact(f)) => self.facts.contains(f),
            _ => false,
        }
    }

    fn action(&mut self, key: usize, call: &Call) -> Status {
        let Some(Binding::Action(a, bind)) = self.binding(call).cloned() else {
            return Status::Failure;
        };
        let action = &self.domain.actions[a];
        let step = Step { action, bind };
        if let Some(inst) = self.running.get_mut(&key) {
            if inst.left > 1 {
                inst.left -= 1;
                return Status::Running;
            }
            let fails = inst.fails;
            self.running.remove(&key);
            self.finish(&step, !fails);
            return if fails {
                Status::Failure
            } else {
                Status::Success
            };
        }
        // Started: preconditions first.
        if !step.pre().iter().all(|f| self.facts.contains(f)) {
            self.finish(&step, false);
            return Status::Failure;
        }
        let rate = self.rates.get(&action.name).copied().unwrap_or(0.0);
        let fails = rate > 0.0 && self.fault_draw(&step).chance(rate);
        let d = self.durations.get(&action.name).copied().unwrap_or(1);
        if d <= 1 {
            self.finish(&step, !fails);
            return if fails {
                Status::Failure
            } else {
                Status::Success
            };
        }
        self.running.insert(key, Instance { left: d - 1, fails });
        Status::Running
    }

    fn halt(&mut self, key: usize) {
        self.running.remove(&key);
    }

    fn now(&self) -> f64 {
        self.step as f64
    }
}
