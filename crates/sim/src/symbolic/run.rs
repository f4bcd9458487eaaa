//! Runs of policies in the symbolic world, their verdicts, and Monte Carlo.
//!
//! A run ticks the policy once per step (after the step's disturbances)
//! with BehaviorTree.CPP 4 semantics (`sim::exec`, docs/bt-semantics.md).
//! It ends: `success` when the policy reports SUCCESS and the goal's facts
//! hold; `failure` when it reports SUCCESS without them, when a machine
//! reaches another outcome, or after `max_failures` failed ticks in a row
//! without a new goal fact; `chattering` when a state of the world (facts
//! and running actions) recurs `livelock_repeats` times without a new goal
//! fact (a disturbance or a failed action starts the count again: a retry
//! is not a livelock); `timeout` at `max_steps`. A BT that fails is ticked again at the
//! next step (a task retried), as the planar simulator does by default.
//!
//! Two runs *match* when their outcomes and their sequences of actions that
//! succeeded (what the robot did to the world) are the same.

use super::scenario::{Disturbance, SymScenario};
use super::world::World;
use crate::exec::{BtExec, CompiledBt, CompiledMachine, MachineExec};
use crate::monte_carlo::{episode_seed, wilson};
use crate::rng::SimRng;
use crate::skills::Status;
use btfsm_model::PolicyBody;
use std::collections::HashMap;
use std::sync::Arc;

pub use crate::trace::Outcome;

/// One policy's run.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SymRun {
    pub policy: String,
    pub outcome: Outcome,
    pub steps: u64,
    /// Actions finished: `Name(args)` and whether it succeeded, by step.
    pub actions: Vec<(u64, String, bool)>,
}

impl SymRun {
    /// The actions that succeeded, in order.
    pub fn effective(&self) -> Vec<&str> {
        self.actions
            .iter()
            .filter(|a| a.2)
            .map(|a| a.1.as_str())
            .collect()
    }
}

/// Do two runs match (same outcome, same actions that succeeded)? If not,
/// the index of the first differing action (or the shorter length).
pub fn first_difference(a: &SymRun, b: &SymRun) -> Option<usize> {
    let (x, y) = (a.effective(), b.effective());
    match x.iter().zip(&y).position(|(p, q)| p != q) {
        Some(i) => Some(i),
        None if x.len() != y.len() => Some(x.len().min(y.len())),
        None if a.outcome != b.outcome => Some(x.len()),
        None => None,
    }
}

/// The facts that hold and the running actions (leaf, steps left).
type WorldState = (Vec<btfsm_plan::fact::Fact>, Vec<(usize, u32)>);

enum Exec {
    Bt(BtExec),
    Machine(MachineExec),
}

/// Runs policy `i` of the scenario with these disturbances and rates.
pub fn run_policy(
    s: &SymScenario,
    i: usize,
    disturbances: &[Disturbance],
    rates: &std::collections::BTreeMap<String, f64>,
    seed: u64,
) -> SymRun {
    let (_, policy) = &s.policies[i];
    let mut w = World::new(&s.domain, &s.facts, &s.durations, rates.clone(), seed);
    let mut exec = match &policy.body {
        PolicyBody::Bt(bt) => {
            let calls = bt
                .nodes
                .iter()
                .map(|n| n.skill.as_ref().map(|c| w.intern(c)))
                .collect();
            Exec::Bt(BtExec::new(Arc::new(CompiledBt::new(bt, calls)), false))
        }
        PolicyBody::Machine(m) => {
            let cm = CompiledMachine::new(m, |c| Ok::<_, ()>(w.intern(c)))
                .expect("infallible: every binding checked when the scenario was read");
            Exec::Machine(MachineExec::new(Arc::new(cm), false))
        }
    };
    let goal_held = |w: &World| s.goal.iter().filter(|f| w.facts.contains(f)).count();
    let mut best = goal_held(&w);
    let mut seen: HashMap<WorldState, u32> = HashMap::new();
    let mut failures = 0u32;
    let mut finished = 0usize;
    let mut outcome = Outcome::Timeout;
    let mut steps = 0;
    while steps < s.max_steps {
        w.step = steps;
        for d in disturbances.iter().filter(|d| d.at == steps) {
            // The world changed from outside: states seen before are no
            // evidence of a livelock.
            seen.clear();
            for f in &d.unset {
                w.facts.remove(f);
            }
            for f in &d.set {
                w.facts.insert(f.clone());
            }
        }
        let status = match &mut exec {
            Exec::Bt(e) => e.tick(&mut w),
            Exec::Machine(e) => e.step(&mut w),
        };
        steps += 1;
        let held = goal_held(&w);
        if held > best {
            best = held;
            seen.clear();
            failures = 0;
        }
        // A failed action is a retry, not a recurring state.
        if w.done.len() > finished {
            if w.done[finished..].iter().any(|a| !a.2) {
                seen.clear();
            }
            finished = w.done.len();
        }
        match status {
            Status::Success => {
                outcome = if held == s.goal.len() {
                    Outcome::Success
                } else {
                    Outcome::Failure
                };
                break;
            }
            Status::Failure => {
                failures += 1;
                if matches!(exec, Exec::Machine(_)) || failures >= s.max_failures {
                    outcome = Outcome::Failure;
                    break;
                }
            }
            Status::Running => failures = 0,
        }
        let key = (w.facts.iter().cloned().collect(), w.running_keys());
        let n = seen.entry(key).or_insert(0);
        *n += 1;
        if *n >= s.livelock_repeats {
            outcome = Outcome::Chattering;
            break;
        }
    }
    SymRun {
        policy: policy.name.clone(),
        outcome,
        steps,
        actions: w.done,
    }
}

/// Every policy once, with the scenario's disturbances and rates (action
/// failures drawn with `seed`).
pub fn run_all(s: &SymScenario, seed: u64) -> Vec<SymRun> {
    (0..s.policies.len())
        .map(|i| run_policy(s, i, &s.disturbances, &s.rates, seed))
        .collect()
}

/// One policy's Monte Carlo figures.
#[derive(Debug, Clone, serde::Serialize)]
pub struct McPolicy {
    pub policy: String,
    pub runs: u32,
    pub successes: u32,
    pub success_rate: f64,
    pub success_ci95: [f64; 2],
    pub failures: u32,
    pub chattering: u32,
    pub timeouts: u32,
}

/// One pair's Monte Carlo agreement.
#[derive(Debug, Clone, serde::Serialize)]
pub struct McPair {
    pub a: String,
    pub b: String,
    pub match_rate: f64,
    pub match_ci95: [f64; 2],
    /// The first episode whose runs differ, with its seed.
    pub first_diverging: Option<(u32, u64)>,
}

/// Monte Carlo: `runs` episodes; in each, every policy meets the same
/// disturbances (the scenario's, plus the sampled fact made false) and the
/// same failure rates, with the same seed.
pub fn monte_carlo(s: &SymScenario, runs: u32, seed: u64) -> (Vec<McPolicy>, Vec<McPair>) {
    let n = s.policies.len();
    let mut out: Vec<Vec<SymRun>> = vec![Vec::new(); n];
    let mut seeds = Vec::new();
    let mut rates = s.rates.clone();
    rates.extend(s.mc.rates.clone());
    for e in 0..runs {
        let es = episode_seed(seed, e);
        seeds.push(es);
        let mut rng = SimRng::named(es, "symbolic-disturbances");
        let mut dist = s.disturbances.clone();
        if let Some((p, facts, [lo, hi])) = &s.mc.unset
            && !facts.is_empty()
            && rng.chance(*p)
        {
            let at = lo + rng.next_u64() % (hi - lo + 1);
            let f = facts[(rng.next_u64() % facts.len() as u64) as usize].clone();
            dist.push(Disturbance {
                at,
                set: Vec::new(),
                unset: vec![f],
            });
        }
        for (i, runs_i) in out.iter_mut().enumerate() {
            runs_i.push(run_policy(s, i, &dist, &rates, es));
        }
    }
    let policies = out
        .iter()
        .enumerate()
        .map(|(i, rs)| {
            let count = |o: Outcome| rs.iter().filter(|r| r.outcome == o).count() as u32;
            let k = count(Outcome::Success);
            McPolicy {
                policy: s.policies[i].1.name.clone(),
                runs,
                successes: k,
                success_rate: if runs == 0 {
                    0.0
                } else {
                    f64::from(k) / f64::from(runs)
                },
                success_ci95: wilson(k, runs),
                failures: count(Outcome::Failure),
                chattering: count(Outcome::Chattering),
                timeouts: count(Outcome::Timeout),
            }
        })
        .collect();
    let mut pairs = Vec::new();
    for a in 0..n {
        for b in a + 1..n {
            let same: Vec<bool> = (0..runs as usize)
                .map(|e| first_difference(&out[a][e], &out[b][e]).is_none())
                .collect();
            let k = same.iter().filter(|x| **x).count() as u32;
            pairs.push(McPair {
                a: s.policies[a].1.name.clone(),
                b: s.policies[b].1.name.clone(),
                match_rate: if runs == 0 {
                    0.0
                } else {
                    f64::from(k) / f64::from(runs)
                },
                match_ci95: wilson(k, runs),
                first_diverging: same.iter().position(|x| !x).map(|e| (e as u32, seeds[e])),
            });
        }
    }
    (policies, pairs)
}
