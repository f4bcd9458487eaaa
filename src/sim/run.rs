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
use super::robot::{Faults, MAX_EVENTS, MAX_SKILL_RECORDS, Robot, apply, round3};
use super::scenario::{Disturbance, PolicyEntry, Scenario, When};
use super::skills::{self, Call, Status};
use super::trace::{FinalWorld, Outcome, Run, Step, compact_trajectory};
use super::world::{P2, World};
use crate::model::PolicyBody;
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
pub fn clock_every(p: &Prepared, disturbances: &[Disturbance], w: &World) -> u64 {
    let terms: usize = (disturbances.iter())
        .map(|d| match &d.when {
            When::Holds(t) => t.len(),
            _ => 1,
        })
        .sum();
    let work = (p.keys.len() + terms + w.objects.len()).max(1) as u64;
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
    let every = clock_every(p, disturbances, &world);
    let n = p.keys.len();
    let mut robot = Robot::new(world, s.dt, n, Faults::new(seed, rates), opts.log);
    enum Ex {
        Bt(BtExec),
        M(MachineExec),
    }
    let mut ex = match &p.exec {
        Compiled::Bt(b) => Ex::Bt(BtExec::new(b.clone(), opts.trace)),
        Compiled::Machine(m) => Ex::M(MachineExec::new(m.clone(), opts.trace)),
    };
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
            }
        }
        let lowb = robot.world.battery <= robot.world.params.low_battery;
        if lowb && !low {
            robot.low_at = Some(robot.world.time);
            let b = robot.world.battery;
            robot.event("battery-low", format!("battery at {b:.1}%"));
        }
        low = lowb;
        last = match &mut ex {
            Ex::Bt(b) => b.tick(&mut robot),
            Ex::M(m) => m.step(&mut robot),
        };
        robot.end_step();
        robot.world.advance(s.dt);
        if opts.log {
            trajectory.push(robot.world.robot);
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
        if robot.switches > s.chatter_switches {
            let text = format!("{} actions started without progress", robot.switches);
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
        None if last == Status::Success => (Outcome::Success, "the root returned SUCCESS".into()),
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
        completion_s: completion.map(round3),
        duration_s: round3(robot.world.time),
        distance_m: round3(robot.world.odometer),
        skills: robot.records,
        events: robot.events,
        final_world: FinalWorld::of(&robot.world),
        recharge_latency_s: robot.latencies,
        trajectory,
        trace,
    }
}

/// Whether the wall-clock budget cut `r` short: a timeout before the step
/// budget was used up (the clock is read only while steps remain).
pub(super) fn cut_short(s: &Scenario, r: &Run) -> bool {
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
            any_cut |= cut_short(s, &run);
            run
        })
        .collect();
    (runs, any_cut)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::diagnostic::SourceFile;
    use crate::format::Limits;
    use crate::sim::monte_carlo::{monte_carlo, monte_carlo_within};
    use std::path::Path;

    fn scenario(text: &str) -> Scenario {
        let f = SourceFile::new("t.toml", text);
        super::super::scenario::parse(&f, Path::new("policies/scenarios"), &Limits::default())
            .expect("valid scenario")
    }

    const FLAKY: &str = r#"
seed = 11
goal = [{ if = "Object-At", args = { object = "cube2", at = "delivery" } }]
[world]
objects = { cube2 = { at = "east-table" } }
[rates]
Pick = 0.5
[[policies]]
file = "../paper/fig01-bt.toml"
[[policies]]
file = "../paper/fig04-fsm.toml"
[monte_carlo]
battery_drop = { probability = 1.0, level = [10, 15], window = [1.0, 5.0] }
"#;

    #[test]
    fn runs_are_deterministic_given_the_seed() {
        let s = scenario(FLAKY);
        let a = run_scenario(&s, false);
        let b = run_scenario(&s, false);
        assert_eq!(a[0].skills, b[0].skills);
        assert_eq!(a[0].trajectory, b[0].trajectory);
        // With a 50% grasp failure rate some seed makes a Pick fail.
        let failed = (0..10u64).any(|seed| {
            let mut s = s.clone();
            s.seed = seed;
            run_scenario(&s, false)[0]
                .skills
                .iter()
                .any(|r| r.skill == "Pick" && r.outcome == "failure")
        });
        assert!(failed);
    }

    #[test]
    fn monte_carlo_does_not_depend_on_the_number_of_threads() {
        let s = scenario(FLAKY);
        let one = monte_carlo(&s, 6, 3, 1);
        let two = monte_carlo(&s, 6, 3, 2);
        assert_eq!(one, two);
        assert_eq!(one.len(), 2);
        assert_eq!(one[0].runs, 6);
        // Every episode drops the battery, so every policy recharges.
        assert!(
            one.iter()
                .all(|p| p.recharges == 0 || p.mean_recharge_latency_s.is_some())
        );
        assert!(one.iter().all(|p| p.success_rate > 0.0));
    }

    #[test]
    fn a_spent_wall_clock_budget_stops_every_run_at_once() {
        let s = scenario(FLAKY);
        // No deadline: the same figures as without the budget.
        let (stats, done) = monte_carlo_within(&s, 6, 3, 2, None);
        assert_eq!((stats, done), (monte_carlo(&s, 6, 3, 2), 6));
        // A deadline already past: no episode completes, no figure is made up.
        let (stats, done) = monte_carlo_within(&s, 6, 3, 2, Some(Instant::now()));
        assert_eq!(done, 0);
        assert!(stats.iter().all(|p| p.runs == 0 && p.successes == 0));
        let (runs, cut) = run_scenario_within(&s, false, Some(Instant::now()));
        assert!(cut);
        for r in &runs {
            assert_eq!(r.outcome, Outcome::Timeout);
            assert_eq!(
                (r.steps, r.reason.as_str()),
                (0, "wall-clock budget exhausted at step 0")
            );
        }
        let (free, cut) = run_scenario_within(&s, false, None);
        assert!(!cut);
        let plain = run_scenario(&s, false);
        let key = |r: &Run| (r.outcome, r.steps, r.reason.clone());
        assert_eq!(
            free.iter().map(key).collect::<Vec<_>>(),
            plain.iter().map(key).collect::<Vec<_>>()
        );
    }

    /// A BT that picks and places the cube every other step (both instantaneous)
    /// recorded two skills and four events a step, 3.3 GB over 10^6 steps:
    /// a run now ends once its records are full, and that is not taken for
    /// the wall-clock budget.
    #[test]
    fn a_run_ends_when_its_records_are_full() {
        let dir = std::env::temp_dir().join(format!("btfsm-records-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(
            dir.join("pp.toml"),
            "kind = \"bt\"\nroot = \"root\"\n[nodes]\nroot = { sequence_memory = [\"pick\", \"place\"] }\npick = { action = \"Pick\", skill = \"Pick\", args = { object = \"cube2\" } }\nplace = { action = \"Place\", skill = \"Place\", args = { object = \"cube2\", at = \"east-table\" } }\n",
        )
        .unwrap();
        let text = "max_steps = 1000000\n[world]\nrobot = \"east-table\"\nparams = { manipulation_s = 0 }\nobjects = { cube2 = { at = \"east-table\" } }\n[[policies]]\nfile = \"pp.toml\"\n[[disturbances]]\nat = 1000000000.0\nbattery = 100.0\n";
        let f = SourceFile::new("pp-scenario.toml", text);
        let s = super::super::scenario::parse(&f, &dir, &Limits::default()).expect("valid");
        let (runs, cut) = run_scenario_within(&s, false, None);
        assert!(!cut);
        let r = &runs[0];
        assert_eq!(r.outcome, Outcome::Timeout);
        assert!(
            r.reason.starts_with("record budget exhausted at step"),
            "{}",
            r.reason
        );
        assert_eq!(r.skills.len(), MAX_SKILL_RECORDS);
        assert!(r.events.len() <= MAX_EVENTS);
        // Every action takes at least one step: two steps a record.
        assert!(r.steps < 2100, "{}", r.steps);
        // Monte Carlo: a timeout of the episode, not a budget cut.
        let (stats, done) = monte_carlo_within(&s, 2, 1, 1, None);
        assert_eq!((done, stats[0].timeouts), (2, 2));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn a_sequential_policy_without_a_failure_arc_fails() {
        let s = scenario(
            r#"
[world]
objects = { cube2 = { at = "east-table" } }
[[policies]]
file = "../paper/fig02-fsm.toml"
[[disturbances]]
at = 0.0
fail = "Move-To"
"#,
        );
        let r = &run_scenario(&s, true)[0];
        assert_eq!(r.outcome, Outcome::Failure);
        assert_eq!(r.skills.len(), 1);
        assert!(!r.trace.is_empty());
        assert!(
            r.trace[0]
                .statuses
                .iter()
                .any(|(k, st)| k == "Move-To cube2" && st == "RUNNING")
        );
    }

    #[test]
    fn a_dropped_cube_is_picked_again_and_a_blocked_goal_gives_up() {
        let s = scenario(
            r#"
goal = [{ if = "Object-At", args = { object = "cube2", at = "delivery" } }]
[world]
objects = { cube2 = { at = "east-table" } }
[[policies]]
file = "../paper/fig01-bt.toml"
[[policies]]
file = "../paper/fig04-fsm.toml"
[[disturbances]]
when = [{ if = "In-Hand", args = { object = "cube2" } }]
drop = "cube2"
"#,
        );
        let runs = run_scenario(&s, false);
        for r in &runs {
            assert_eq!(r.goal_met, Some(true), "{}", r.policy);
            let picks = r
                .skills
                .iter()
                .filter(|x| x.skill == "Pick" && x.outcome == "success");
            assert_eq!(picks.count(), 2, "{}", r.policy);
        }
        // The BT notices the drop at once; the FSM only when Place fails.
        assert!(
            !runs[0]
                .skills
                .iter()
                .any(|x| x.skill == "Place" && x.outcome == "failure")
        );
        assert!(
            runs[1]
                .skills
                .iter()
                .any(|x| x.skill == "Place" && x.outcome == "failure")
        );

        let s = scenario(
            r#"
[world]
objects = { cube2 = { at = "east-table" } }
[[policies]]
file = "../paper/fig01-bt.toml"
[[policies]]
file = "../paper/fig04-fsm.toml"
[[disturbances]]
at = 0.0
block = { name = "fence", rect = [-0.5, 1.4, 1.5, 1.5] }
[[disturbances]]
at = 0.0
block = { name = "fence2", rect = [-0.5, 1.4, -0.4, 2.99] }
[[disturbances]]
at = 0.0
block = { name = "fence3", rect = [1.4, 1.4, 1.5, 2.99] }
"#,
        );
        for r in run_scenario(&s, false) {
            assert_eq!(r.outcome, Outcome::Failure, "{}", r.policy);
            assert!(r.reason.starts_with("gave up"), "{}", r.reason);
        }
    }
}
