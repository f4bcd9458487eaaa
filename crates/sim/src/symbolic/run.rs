//! Runs of policies in the symbolic world, their verdicts, and Monte Carlo.
//!
//! A run ticks the policy once per step (after the step's disturbances)
//! with BehaviorTree.CPP 4 semantics (`sim::exec`, docs/bt-semantics.md).
//! It ends: `success` when the policy reports SUCCESS and the goal's facts
//! hold; `failure` when it reports SUCCESS without them, when a machine
//! stops at another outcome, or after `max_failures` failed ticks in a row
//! without a new goal fact (BTs and tick-driven machines alike: both are
//! ticked again after a failure); `chattering` when a state of the world (facts
//! and running actions) recurs `livelock_repeats` times without a new goal
//! fact (a disturbance or a failed action starts the count again: a retry
//! is not a livelock; the one detector of `crate::livelock`, as in the
//! planar simulator, which remembers at most 4096 states between two
//! progresses); `timeout` at `max_steps` or when `--timeout-ms` runs out
//! (the run is then `cut_short`). A BT that fails is ticked again at the
//! next step (a task retried), as the planar simulator does by default.
//! Monte Carlo runs its episodes through `crate::episodes`, the contract
//! both simulators share (threads, deadline, order, bounded memory).
//!
//! Two runs *match* when their outcomes and their sequences of actions that
//! succeeded (what the robot did to the world) are the same.

use super::scenario::{Disturbance, SymScenario};
use super::world::World;
use crate::episodes::{self, Budget, PairTally};
use crate::exec::{BtExec, CompiledBt, CompiledMachine, MachineExec};
use crate::livelock::Livelock;
use crate::monte_carlo::wilson;
use crate::rng::SimRng;
use crate::skills::Status;
use btfsm_model::PolicyBody;
use std::sync::Arc;
use std::time::Instant;

pub use crate::trace::Outcome;

/// One policy's run.
#[derive(Debug, Clone, serde::Serialize)]
pub struct SymRun {
    pub policy: String,
    pub outcome: Outcome,
    pub steps: u64,
    /// Actions finished: `Name(args)` and whether it succeeded, by step.
    pub actions: Vec<(u64, String, bool)>,
    /// Whether the wall-clock deadline cut the run short (its outcome is
    /// then `timeout` at the step reached).
    #[serde(skip)]
    pub cut_short: bool,
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

enum Exec {
    Bt(BtExec),
    Machine(MachineExec),
}

/// The state of the world livelock detection compares, hashed: the facts
/// that hold and the running actions (leaf, steps left).
fn world_state(w: &World) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::hash::DefaultHasher::new();
    for f in &w.facts {
        f.hash(&mut h);
    }
    w.running_keys().hash(&mut h);
    h.finish()
}

/// Steps between two clock readings under a deadline: about every 64k
/// node ticks, at most [`crate::run::CLOCK_EVERY`].
fn clock_every(policy: &btfsm_model::Policy) -> u64 {
    let work = match &policy.body {
        PolicyBody::Bt(bt) => bt.nodes.len(),
        PolicyBody::Machine(m) => m.states.len(),
    };
    (65_536 / work.max(1) as u64).clamp(1, crate::run::CLOCK_EVERY)
}

/// The executor of policy `i` of the scenario, its leaves bound in `w`.
fn executor(s: &SymScenario, i: usize, w: &mut World) -> Exec {
    match &s.policies[i].1.body {
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
    }
}

/// Runs policy `i` of the scenario with these disturbances and rates,
/// until its verdict, `max_steps`, or the deadline (read every
/// `clock_every` steps; the run is then `timeout` and `cut_short`).
pub fn run_policy(
    s: &SymScenario,
    i: usize,
    disturbances: &[Disturbance],
    rates: &std::collections::BTreeMap<String, f64>,
    seed: u64,
    deadline: Option<Instant>,
) -> SymRun {
    let (_, policy) = &s.policies[i];
    let mut w = World::new(&s.domain, &s.facts, &s.durations, rates.clone(), seed);
    let mut exec = executor(s, i, &mut w);
    let every = clock_every(policy);
    let goal_held = |w: &World| s.goal.iter().filter(|f| w.facts.contains(f)).count();
    let mut best = goal_held(&w);
    // The one livelock detector of both simulators: every step's state is
    // counted (`fresh`), and progress is a new most goal facts held.
    let mut livelock = Livelock::new(s.livelock_repeats);
    let (mut failures, mut finished) = (0u32, 0usize);
    let (mut outcome, mut steps, mut cut_short) = (Outcome::Timeout, 0, false);
    while steps < s.max_steps {
        if deadline.is_some_and(|d| steps % every == 0 && Instant::now() >= d) {
            cut_short = true;
            break;
        }
        w.step = steps;
        // The world changed from outside: states seen before are no
        // evidence of a livelock.
        let mut disturbed = false;
        for d in disturbances.iter().filter(|d| d.at == steps) {
            disturbed = true;
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
            failures = 0;
        }
        // A failed action is a retry, not a recurring state.
        if w.done.len() > finished {
            disturbed |= w.done[finished..].iter().any(|a| !a.2);
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
                // One failure budget for every representation: a policy
                // ticked again after a failure (a BT, a tick-driven machine
                // such as the HFSM of a BT) has `max_failures`; a machine
                // that stopped at its outcome has ended.
                let stopped = matches!(&exec, Exec::Machine(e) if e.finished.is_some());
                if stopped || failures >= s.max_failures {
                    outcome = Outcome::Failure;
                    break;
                }
            }
            Status::Running => failures = 0,
        }
        if livelock
            .step(world_state(&w), true, best, disturbed)
            .is_some()
        {
            outcome = Outcome::Chattering;
            break;
        }
    }
    SymRun {
        policy: policy.name.clone(),
        outcome,
        steps,
        actions: w.done,
        cut_short,
    }
}

/// Every policy once, with the scenario's disturbances and rates (action
/// failures drawn with the scenario's seed); with `seed`, the episode of
/// that seed as `--runs` draws it ([`episode`]), so that the seed a Monte
/// Carlo report names replays its episode.
pub fn run_all(s: &SymScenario, seed: Option<u64>, deadline: Option<Instant>) -> Vec<SymRun> {
    let (ds, rates, seed) = match seed {
        Some(seed) => {
            let (ds, rates) = episode(s, seed);
            (ds, rates, seed)
        }
        None => (s.disturbances.clone(), s.rates.clone(), s.seed),
    };
    (0..s.policies.len())
        .map(|i| run_policy(s, i, &ds, &rates, seed, deadline))
        .collect()
}

/// The disturbances and failure rates of the episode with seed `ep_seed`:
/// the scenario's disturbances, plus (with the `[monte_carlo]` table's
/// probability) one of its facts made false at a step drawn in its range;
/// the scenario's rates with the table's on top.
pub fn episode(
    s: &SymScenario,
    ep_seed: u64,
) -> (Vec<Disturbance>, std::collections::BTreeMap<String, f64>) {
    let mut rates = s.rates.clone();
    rates.extend(s.mc.rates.clone());
    let mut rng = SimRng::named(ep_seed, "symbolic-disturbances");
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
    (dist, rates)
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

/// What `--runs N` of a symbolic scenario computes.
#[derive(Debug, Clone)]
pub struct McResult {
    pub policies: Vec<McPolicy>,
    pub pairs: Vec<McPair>,
    /// Episodes the figures cover (all asked for, unless the deadline
    /// passed: then the first that completed).
    pub runs: u32,
}

/// Monte Carlo: the episodes of `budget`; in each, every policy meets the
/// same disturbances (the scenario's, plus the sampled fact made false) and
/// the same failure rates, with the same seed. Episodes go through the one
/// contract of [`crate::episodes`] (threads, deadline, in-order folding in
/// memory bounded by the threads), as the planar simulator's do.
pub fn monte_carlo(s: &SymScenario, budget: &Budget) -> McResult {
    let n = s.policies.len();
    let pairs = episodes::pairs(n);
    let mut counts = vec![[0u32; 4]; n];
    let mut agree = vec![PairTally::default(); pairs.len()];
    let done = episodes::stream(
        budget,
        |_, es| {
            let (dist, rates) = episode(s, es);
            let mut runs = Vec::with_capacity(n);
            for i in 0..n {
                let r = run_policy(s, i, &dist, &rates, es, budget.deadline);
                if r.cut_short {
                    return None;
                }
                runs.push(r);
            }
            let same: Vec<bool> = (pairs.iter())
                .map(|&(a, b)| first_difference(&runs[a], &runs[b]).is_none())
                .collect();
            Some((runs.iter().map(|r| r.outcome).collect::<Vec<_>>(), same))
        },
        |e, es, (outcomes, same)| {
            for (c, o) in counts.iter_mut().zip(outcomes) {
                c[o as usize] += 1;
            }
            for (t, m) in agree.iter_mut().zip(same) {
                t.fold(e, es, m);
            }
        },
    );
    let rate = |k: u32| {
        if done == 0 {
            0.0
        } else {
            f64::from(k) / f64::from(done)
        }
    };
    let policies = (s.policies.iter().zip(&counts))
        .map(|((_, p), c)| {
            let k = c[Outcome::Success as usize];
            McPolicy {
                policy: p.name.clone(),
                runs: done,
                successes: k,
                success_rate: rate(k),
                success_ci95: wilson(k, done),
                failures: c[Outcome::Failure as usize],
                chattering: c[Outcome::Chattering as usize],
                timeouts: c[Outcome::Timeout as usize],
            }
        })
        .collect();
    let pairs = (pairs.iter().zip(&agree))
        .map(|(&(a, b), t)| McPair {
            a: s.policies[a].1.name.clone(),
            b: s.policies[b].1.name.clone(),
            match_rate: rate(t.matches),
            match_ci95: wilson(t.matches, done),
            first_diverging: t.first_divergence,
        })
        .collect();
    McResult {
        policies,
        pairs,
        runs: done,
    }
}
