//! Runs policies in a scenario (SPEC §6): each policy on its own copy of the
//! world with the same seed, stepped until it is done and no timed disturbance
//! is pending, until it chatters or gives up, or until the step budget runs out.
//! Also the `--runs N` Monte Carlo episodes, run in parallel over the cores
//! (deterministic: episode i has its own seed and results are combined in
//! episode order). Under a wall-clock budget (`sim --timeout-ms`), runs read
//! the clock every 1024 steps and stop cleanly when it has passed: a single
//! run ends with outcome `timeout` at the step reached; Monte Carlo keeps
//! the first k whole episodes.

use super::exec::{BtExec, CompiledBt, CompiledMachine, MachineExec};
use super::livelock::{Livelock, abstract_state};
use super::robot::{Faults, MAX_EVENTS, MAX_SKILL_RECORDS, Robot, apply, round3};
use super::scenario::{Afterwards, Disturbance, PolicyEntry, Scenario, When};
use super::skills::{self, Call, Status};
use super::trace::{FinalWorld, Outcome, Run, Step, compact_track, compact_trajectory};
use super::world::{P2, World, dist};
use btfsm_model::PolicyBody;
use std::collections::BTreeMap;
use std::sync::Arc;
use std::time::Instant;

/// A policy ready to run: bindings resolved against the scenario's world.
#[derive(Debug, Clone)]
pub struct Prepared {
    pub name: String,
    pub file: String,
    pub kind: String,
    pub convert: Option<String>,
    /// What the policy does after it reports SUCCESS.
    pub after_success: Afterwards,
    /// What the policy does after it reports FAILURE.
    pub after_failure: Afterwards,
    pub exec: Compiled,
    /// Node id / state path per key (for statuses).
    pub keys: Arc<Vec<String>>,
}

#[derive(Debug, Clone)]
pub enum Compiled {
    Bt(Arc<CompiledBt>),
    Machine(Arc<CompiledMachine>),
}

/// Resolves the bindings of a scenario's policies (validated when the scenario
/// was read, so resolution cannot fail here; an unresolvable binding would run
/// as a failing leaf).
pub fn prepare(s: &Scenario) -> Vec<Prepared> {
    s.policies
        .iter()
        .map(|e| prepare_one(e, &s.world))
        .collect()
}

fn prepare_one(e: &PolicyEntry, w: &World) -> Prepared {
    let (exec, keys) = match &e.policy.body {
        PolicyBody::Bt(bt) => {
            let calls = bt
                .nodes
                .iter()
                .map(|n| n.skill.as_ref().and_then(|c| skills::resolve(c, w).ok()))
                .collect();
            (
                Compiled::Bt(Arc::new(CompiledBt::new(bt, calls))),
                bt.nodes.iter().map(|n| n.id.clone()).collect(),
            )
        }
        PolicyBody::Machine(m) => {
            let cm = CompiledMachine::new(m, |c| skills::resolve(c, w).or(Err(()))).unwrap_or_else(
                |_| {
                    CompiledMachine::new(m, |c| {
                        Ok::<_, ()>(skills::resolve(c, w).unwrap_or(Call::Found))
                    })
                    .expect("infallible")
                },
            );
            (
                Compiled::Machine(Arc::new(cm)),
                (0..m.states.len()).map(|i| m.path(i)).collect(),
            )
        }
    };
    Prepared {
        name: e.policy.name.clone(),
        file: e.file.display().to_string(),
        kind: e.policy.kind().to_string(),
        convert: e.convert.clone(),
        after_success: e.after_success,
        after_failure: e.after_failure,
        exec,
        keys: Arc::new(keys),
    }
}

/// What to record in a run.
#[derive(Debug, Clone, Copy)]
pub struct RunOptions {
    /// Events, trajectory and executed skills (off only for Monte Carlo).
    pub log: bool,
    /// Per-step statuses (for `--trace`).
    pub trace: bool,
    /// Wall-clock budget: the run stops (outcome `timeout`) at the first
    /// clock reading at or past it, read every [`CLOCK_EVERY`] steps.
    pub deadline: Option<Instant>,
}

/// Steps between two readings of the clock under a wall-clock budget: a
/// step costs microseconds, so the run stops within about a millisecond of
/// its deadline, and the clock (tens of nanoseconds) costs nothing.
pub const CLOCK_EVERY: u64 = 1024;

fn holds(terms: &[(Call, bool)], w: &World) -> bool {
    terms.iter().all(|(c, neg)| skills::condition(c, w) != *neg)
}

/// Steps between two clock readings for a policy and disturbances: at most
/// [`CLOCK_EVERY`], fewer as the work of a step grows (a BT of a million
/// nodes, a thousand disturbances with conditions), so that the clock is
/// read about every 64k units of work (node ticks, conditions) whatever
/// the input.
pub fn clock_every(p: &Prepared, disturbances: &[Disturbance], w: &World, goal: usize) -> u64 {
    let terms: usize = (disturbances.iter())
        .map(|d| match &d.when {
            When::Holds(t) => t.len(),
            _ => 1,
        })
        .sum();
    let work = (p.keys.len() + terms + goal + w.objects.len()).max(1) as u64;
    (65_536 / work).clamp(1, CLOCK_EVERY)
}

/// Runs one policy in a scenario.
pub fn run_policy(
    s: &Scenario,
    p: &Prepared,
    world: World,
    disturbances: &[Disturbance],
    rates: BTreeMap<String, f64>,
    seed: u64,
    opts: RunOptions,
) -> Run {
    run_policy_into(s, p, world, disturbances, rates, seed, opts, None)
}

/// Where the steps of a traced run go as they are made (instead of
/// [`Run::trace`]), so that a trace never has to fit in memory.
pub type StepSink<'a> = &'a mut dyn FnMut(&Step);

/// [`run_policy`], handing each step of the trace (`opts.trace`) to `sink`
/// when there is one.
#[allow(clippy::too_many_arguments)]
#[expect(clippy::too_many_lines, reason = "to be split: issue 28")]
pub fn run_policy_into(
    s: &Scenario,
    p: &Prepared,
    world: World,
    disturbances: &[Disturbance],
    rates: BTreeMap<String, f64>,
    seed: u64,
    opts: RunOptions,
    mut sink: Option<StepSink<'_>>,
) -> Run {
    // The goal's terms are evaluated every step too (progress toward it).
    let goal_terms_n = s.goal.as_ref().map_or(0, Vec::len);
    let every = clock_every(p, disturbances, &world, goal_terms_n);
    let n = p.keys.len();
    let mut robot = Robot::new(world, s.dt, n, Faults::new(seed, rates), opts.log);
    enum Ex {
        Bt(BtExec),
        M(MachineExec),
    }
    let keep_ticking = p.after_success == Afterwards::KeepTicking;
    let mut ex = match &p.exec {
        Compiled::Bt(b) => Ex::Bt(BtExec::new(b.clone(), opts.trace)),
        Compiled::Machine(m) => {
            let mut m = MachineExec::new(m.clone(), opts.trace);
            m.keep_ticking = keep_ticking;
            m.reenter_on_failure = p.after_failure == Afterwards::KeepTicking;
            Ex::M(m)
        }
    };
    // `after_success = "stop"`: the policy is no longer ticked once it has
    // reported SUCCESS (a machine ends at its outcome by itself).
    let mut stopped = false;
    let mut livelock = Livelock::new(s.livelock_repeats);
    let goal_terms: &[(Call, bool)] = s.goal.as_deref().unwrap_or(&[]);
    let mut track: Vec<(u64, P2)> = Vec::new();
    let mut fired = vec![false; disturbances.len()];
    // Timed disturbances not yet fired (a run is not over while one is).
    let mut pending_timed = (disturbances.iter())
        .filter(|d| matches!(d.when, When::At(_) | When::AfterDone(_)))
        .count();
    let mut first_done: Option<f64> = None;
    let mut completion: Option<f64> = None;
    let mut low = false;
    let mut trajectory: Vec<P2> = Vec::new();
    let mut trace: Vec<Step> = Vec::new();
    let mut ended: Option<(Outcome, String)> = None;
    let mut steps = 0;
    let mut last = Status::Running;
    if opts.log {
        trajectory.push(robot.world.robot);
        track.push((0, robot.world.robot));
    }
    while steps < s.max_steps {
        if let Some(d) = opts.deadline
            && steps % every == 0
            && Instant::now() >= d
        {
            ended = Some((
                Outcome::Timeout,
                format!("wall-clock budget exhausted at step {steps}"),
            ));
            break;
        }
        steps += 1;
        let now = robot.world.time + 1e-9;
        let mut disturbed = false;
        for (i, d) in disturbances.iter().enumerate() {
            if fired[i] {
                continue;
            }
            let go = match &d.when {
                When::At(t) => now >= *t,
                When::AfterDone(dl) => first_done.is_some_and(|f| now >= f + dl),
                When::Holds(terms) => holds(terms, &robot.world),
            };
            if go {
                fired[i] = true;
                if !matches!(d.when, When::Holds(_)) {
                    pending_timed -= 1;
                }
                apply(d, &mut robot);
                disturbed = true;
            }
        }
        let lowb = robot.world.battery <= robot.world.params.low_battery;
        if lowb && !low {
            robot.low_at = Some(robot.world.time);
            let b = robot.world.battery;
            robot.event("battery-low", format!("battery at {b:.1}%"));
        }
        low = lowb;
        if !stopped {
            // A policy whose root failed because an action failed, and
            // which goes on (a BT, a machine re-entered after FAILURE), is
            // ticked again in the same step, as an FSM's failure arc starts
            // its next action in the step of the failure: no representation
            // gets a step for free. Bounded: MAX_TICKS_PER_STEP ticks.
            let mut ticks = 0;
            loop {
                ticks += 1;
                let failed = robot.failed_ends;
                last = match &mut ex {
                    Ex::Bt(b) => b.tick(&mut robot),
                    Ex::M(m) => m.step(&mut robot),
                };
                let goes_on = match &ex {
                    Ex::Bt(_) => p.after_failure == Afterwards::KeepTicking,
                    Ex::M(m) => m.finished.is_none(),
                };
                if last != Status::Failure
                    || !goes_on
                    || robot.failed_ends == failed
                    || ticks >= MAX_TICKS_PER_STEP
                {
                    break;
                }
                // The last tick of the step says which actions go on.
                robot.untick();
            }
            if last == Status::Success && !keep_ticking && matches!(ex, Ex::Bt(_)) {
                stopped = true;
            }
            // `after_failure = "stop"` for a BT: its root's FAILURE ends the
            // run (a machine ends at its outcome by itself).
            if last == Status::Failure
                && p.after_failure == Afterwards::Stop
                && matches!(ex, Ex::Bt(_))
            {
                robot.end_step();
                ended = Some((
                    Outcome::Failure,
                    "the root returned FAILURE (after_failure = \"stop\")".into(),
                ));
                break;
            }
        }
        robot.end_step();
        robot.world.advance(s.dt);
        if opts.log {
            trajectory.push(robot.world.robot);
            if track
                .last()
                .is_none_or(|&(_, q)| dist(q, robot.world.robot) > 1e-6)
            {
                track.push((steps, robot.world.robot));
            }
        }
        if opts.trace {
            let st = match &ex {
                Ex::Bt(b) => b.statuses.as_ref(),
                Ex::M(m) => m.statuses.as_ref(),
            };
            let running = robot
                .live
                .iter()
                .flatten()
                // An outcome reached while moving is no longer running.
                .filter(|r| r.result.is_none())
                .map(|r| {
                    robot.records[r.record]
                        .text()
                        .trim_end_matches(" -> running")
                        .to_string()
                })
                .collect();
            let step = Step {
                t: round3(robot.world.time),
                x: robot.world.robot.0,
                y: robot.world.robot.1,
                yaw: robot.world.yaw,
                battery: (robot.world.battery * 100.0).round() / 100.0,
                running,
                statuses: st
                    .map(|v| {
                        v.iter()
                            .map(|(k, s)| (p.keys[*k].clone(), s.as_str().to_string()))
                            .collect()
                    })
                    .unwrap_or_default(),
            };
            match sink.as_mut() {
                Some(f) => f(&step),
                None => trace.push(step),
            }
        }
        let finished = match &ex {
            Ex::Bt(_) => None,
            Ex::M(m) => m.finished.clone(),
        };
        let done = last == Status::Success && finished.as_ref().is_none_or(|f| f.0 == "SUCCESS");
        if done {
            if completion.is_none() || first_done.is_none() {
                robot.event("done", "the policy reports SUCCESS".into());
            }
            first_done.get_or_insert(robot.world.time);
            completion.get_or_insert(robot.world.time);
        } else {
            completion = None;
        }
        let pending = pending_timed > 0;
        if robot.full {
            ended = Some((
                Outcome::Timeout,
                format!(
                    "record budget exhausted at step {steps}: a run records at most {MAX_SKILL_RECORDS} executed skills and {MAX_EVENTS} events"
                ),
            ));
            break;
        }
        let measure = (goal_terms.iter())
            .filter(|(c, neg)| skills::condition(c, &robot.world) != *neg)
            .count()
            + usize::from(done);
        let fresh = !robot.started.is_empty();
        let state = abstract_state(&robot);
        robot.started.clear();
        if let Some(n) = livelock.step(state, fresh, measure, disturbed) {
            let text = format!(
                "livelock: an abstract state (world facts, running skills) entered {n} times without progress toward the goal"
            );
            robot.event("chattering", text.clone());
            ended = Some((Outcome::Chattering, text));
            break;
        }
        if robot.failures > s.max_failures {
            let text = format!(
                "gave up after {} failed actions without progress",
                robot.failures
            );
            ended = Some((Outcome::Failure, text));
            break;
        }
        if !pending && (done || finished.is_some()) {
            break;
        }
    }
    // Whatever still runs at the end stays `running` in the records.
    let finished = match &ex {
        Ex::Bt(_) => None,
        Ex::M(m) => m.finished.clone(),
    };
    let (outcome, reason) = ended.unwrap_or_else(|| match finished {
        Some((o, why)) if o == "SUCCESS" => (Outcome::Success, why),
        Some((_, why)) => (Outcome::Failure, why),
        None if last == Status::Success => (
            Outcome::Success,
            match &ex {
                Ex::Bt(_) => "the root returned SUCCESS".into(),
                Ex::M(_) => "reached the outcome SUCCESS (and ticks on)".into(),
            },
        ),
        None => (
            Outcome::Timeout,
            format!("step budget of {} steps exhausted", s.max_steps),
        ),
    });
    let goal_met = s.goal.as_ref().map(|g| holds(g, &robot.world));
    Run {
        policy: p.name.clone(),
        file: p.file.clone(),
        kind: p.kind.clone(),
        convert: p.convert.clone(),
        outcome,
        reason,
        goal_met,
        steps,
        dt: s.dt,
        after_success: p.after_success.as_str(),
        after_failure: p.after_failure.as_str(),
        completion_s: completion.map(round3),
        duration_s: round3(robot.world.time),
        distance_m: round3(robot.world.odometer),
        skills: robot.records,
        events: robot.events,
        final_world: FinalWorld::of(&robot.world),
        recharge_latency_s: robot.latencies,
        trajectory,
        track,
        trace,
    }
}

/// Ticks of a policy in one step at most: the first, and the re-ticks after
/// a FAILURE caused by a failed action.
pub const MAX_TICKS_PER_STEP: u32 = 4;

/// Whether the wall-clock budget cut `r` short: a timeout before the step
/// budget was used up (the clock is read only while steps remain).
pub fn cut_short(s: &Scenario, r: &Run) -> bool {
    r.outcome == Outcome::Timeout
        && r.steps < s.max_steps
        && r.reason.starts_with("wall-clock budget")
}

/// Runs every policy of a scenario once (the scenario's own seed and
/// disturbances).
pub fn run_scenario(s: &Scenario, trace: bool) -> Vec<Run> {
    run_scenario_within(s, trace, None).0
}

/// [`run_scenario`] under a wall-clock deadline for all of its runs: once
/// it passes, the run in progress stops with outcome `timeout` at the step
/// reached, and the later policies stop at step 0. Also says whether the
/// deadline cut any run short.
pub fn run_scenario_within(
    s: &Scenario,
    trace: bool,
    deadline: Option<Instant>,
) -> (Vec<Run>, bool) {
    run_scenario_out(s, trace, deadline, None)
}

/// Receives the runs of a traced scenario as they are made, so that the
/// trace is written out instead of kept (`sim --trace`).
pub trait TraceOut {
    /// A policy's run starts.
    fn begin(&mut self);
    /// One step of it.
    fn step(&mut self, step: &Step);
    /// It ended; `run.trajectory` is whole (it is thinned afterwards).
    fn end(&mut self, run: &Run);
}

/// [`run_scenario_within`] with every step handed to `out` instead of kept
/// in [`Run::trace`] (which stays empty).
pub fn run_scenario_traced(
    s: &Scenario,
    deadline: Option<Instant>,
    out: &mut dyn TraceOut,
) -> (Vec<Run>, bool) {
    run_scenario_out(s, true, deadline, Some(out))
}

fn run_scenario_out(
    s: &Scenario,
    trace: bool,
    deadline: Option<Instant>,
    mut out: Option<&mut dyn TraceOut>,
) -> (Vec<Run>, bool) {
    let mut any_cut = false;
    let runs = prepare(s)
        .iter()
        .map(|p| {
            let opts = RunOptions {
                log: true,
                trace,
                deadline,
            };
            let (world, ds, rates) = (s.world.clone(), &s.disturbances, s.rates.clone());
            let mut run = match out.as_deref_mut() {
                Some(o) => {
                    o.begin();
                    let mut sink = |st: &Step| o.step(st);
                    let run =
                        run_policy_into(s, p, world, ds, rates, s.seed, opts, Some(&mut sink));
                    o.end(&run);
                    run
                }
                None => run_policy(s, p, world, ds, rates, s.seed, opts),
            };
            // Kept for the verdicts and the plot: the points where the
            // robot moved, at most TRAJECTORY_POINTS of them.
            run.trajectory = compact_trajectory(std::mem::take(&mut run.trajectory));
            run.track = compact_track(std::mem::take(&mut run.track));
            any_cut |= cut_short(s, &run);
            run
        })
        .collect();
    (runs, any_cut)
}

#[cfg(test)]
mod tests;
