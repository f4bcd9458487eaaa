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
use super::livelock::{Livelock, NavProgress, abstract_state};
use super::robot::{Faults, MAX_EVENTS, MAX_SKILL_RECORDS, Robot, apply, round3};
use super::scenario::{Afterwards, Disturbance, PolicyEntry, Scenario, When};
use super::skills::{self, Call, Status};
use super::trace::{FinalWorld, Outcome, Run, Step, compact_track, compact_trajectory};
use super::world::{P2, World, dist};
use btfsm_model::PolicyBody;
use std::collections::BTreeMap;
use std::ops::ControlFlow;
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
    let mut e = Episode::new(s, p, world, disturbances, rates, seed, opts);
    let mut ended: Option<(Outcome, String)> = None;
    while e.steps < s.max_steps {
        if let ControlFlow::Break(end) = e.step(every, &mut sink) {
            ended = end;
            break;
        }
    }
    e.into_run(ended)
}

/// The executor of a run: a BT's or a machine's.
enum Ex {
    Bt(BtExec),
    M(MachineExec),
}

impl Ex {
    /// The executor of `p`, noting every node's status when `trace`.
    fn new(p: &Prepared, trace: bool) -> Self {
        match &p.exec {
            Compiled::Bt(b) => Ex::Bt(BtExec::new(b.clone(), trace)),
            Compiled::Machine(m) => {
                let mut m = MachineExec::new(m.clone(), trace);
                m.keep_ticking = p.after_success == Afterwards::KeepTicking;
                m.reenter_on_failure = p.after_failure == Afterwards::KeepTicking;
                Ex::M(m)
            }
        }
    }

    /// The outcome a machine ended with, and why (a BT never ends by itself).
    fn finished(&self) -> Option<(String, String)> {
        match self {
            Ex::Bt(_) => None,
            Ex::M(m) => m.finished.clone(),
        }
    }
}

/// What ends a run early: its outcome and why (`None`: the policy's own).
type Ended = Option<(Outcome, String)>;

/// A run in progress: the robot, the policy's executor, and what the step
/// loop carries from one step to the next.
struct Episode<'a> {
    s: &'a Scenario,
    p: &'a Prepared,
    disturbances: &'a [Disturbance],
    opts: RunOptions,
    robot: Robot,
    ex: Ex,
    /// `after_success = "keep-ticking"`.
    keep_ticking: bool,
    /// `after_success = "stop"`: the policy is no longer ticked once it has
    /// reported SUCCESS (a machine ends at its outcome by itself).
    stopped: bool,
    livelock: Livelock,
    nav: NavProgress,
    goal_terms: &'a [(Call, bool)],
    track: Vec<(u64, P2)>,
    fired: Vec<bool>,
    /// Timed disturbances not yet fired (a run is not over while one is).
    pending_timed: usize,
    first_done: Option<f64>,
    completion: Option<f64>,
    low: bool,
    trajectory: Vec<P2>,
    trace: Vec<Step>,
    steps: u64,
    last: Status,
}

impl<'a> Episode<'a> {
    /// The run at step 0: the robot in `world`, its faults drawn from `seed`.
    fn new(
        s: &'a Scenario,
        p: &'a Prepared,
        world: World,
        disturbances: &'a [Disturbance],
        rates: BTreeMap<String, f64>,
        seed: u64,
        opts: RunOptions,
    ) -> Self {
        let n = p.keys.len();
        let robot = Robot::new(world, s.dt, n, Faults::new(seed, rates), opts.log);
        let mut trajectory: Vec<P2> = Vec::new();
        let mut track: Vec<(u64, P2)> = Vec::new();
        if opts.log {
            trajectory.push(robot.world.robot);
            track.push((0, robot.world.robot));
        }
        Episode {
            s,
            p,
            disturbances,
            opts,
            ex: Ex::new(p, opts.trace),
            keep_ticking: p.after_success == Afterwards::KeepTicking,
            stopped: false,
            livelock: Livelock::new(s.livelock_repeats),
            nav: NavProgress::default(),
            goal_terms: s.goal.as_deref().unwrap_or(&[]),
            track,
            fired: vec![false; disturbances.len()],
            pending_timed: (disturbances.iter())
                .filter(|d| matches!(d.when, When::At(_) | When::AfterDone(_)))
                .count(),
            first_done: None,
            completion: None,
            low: false,
            trajectory,
            trace: Vec::new(),
            steps: 0,
            last: Status::Running,
            robot,
        }
    }

    /// One step: the clock read, disturbances fired, the policy ticked, the
    /// world advanced and recorded; `Break` when the run ends with it.
    fn step(&mut self, every: u64, sink: &mut Option<StepSink<'_>>) -> ControlFlow<Ended> {
        if let Some(d) = self.opts.deadline
            && self.steps.is_multiple_of(every)
            && Instant::now() >= d
        {
            let steps = self.steps;
            return ControlFlow::Break(Some((
                Outcome::Timeout,
                format!("wall-clock budget exhausted at step {steps}"),
            )));
        }
        self.steps += 1;
        let disturbed = self.fire_disturbances();
        self.note_battery();
        if !self.stopped
            && let Some(end) = self.tick_policy()
        {
            return ControlFlow::Break(Some(end));
        }
        self.robot.end_step();
        self.robot.world.advance(self.s.dt);
        if self.opts.log {
            self.record_position();
        }
        if self.opts.trace {
            self.record_trace(sink);
        }
        self.settle(disturbed)
    }

    /// Fires the disturbances due at this step; whether any fired.
    fn fire_disturbances(&mut self) -> bool {
        let now = self.robot.world.time + 1e-9;
        let mut disturbed = false;
        for (i, d) in self.disturbances.iter().enumerate() {
            if self.fired[i] {
                continue;
            }
            let go = match &d.when {
                When::At(t) => now >= *t,
                When::AfterDone(dl) => self.first_done.is_some_and(|f| now >= f + dl),
                When::Holds(terms) => holds(terms, &self.robot.world),
            };
            if go {
                self.fired[i] = true;
                if !matches!(d.when, When::Holds(_)) {
                    self.pending_timed -= 1;
                }
                apply(d, &mut self.robot);
                disturbed = true;
            }
        }
        disturbed
    }

    /// Notes the battery going low (an event, once per time it falls).
    fn note_battery(&mut self) {
        let robot = &mut self.robot;
        let lowb = robot.world.battery <= robot.world.params.low_battery;
        if lowb && !self.low {
            robot.low_at = Some(robot.world.time);
            let b = robot.world.battery;
            robot.event("battery-low", format!("battery at {b:.1}%"));
        }
        self.low = lowb;
    }

    /// Ticks the policy for this step and applies `after_success` and
    /// `after_failure`; `Some` when a BT's FAILURE stops the run.
    fn tick_policy(&mut self) -> Option<(Outcome, String)> {
        self.tick_until_settled();
        let bt = matches!(self.ex, Ex::Bt(_));
        if self.last == Status::Success && !self.keep_ticking && bt {
            self.stopped = true;
        }
        // `after_failure = "stop"` for a BT: its root's FAILURE ends the
        // run (a machine ends at its outcome by itself).
        if self.last == Status::Failure && self.p.after_failure == Afterwards::Stop && bt {
            self.robot.end_step();
            return Some((
                Outcome::Failure,
                "the root returned FAILURE (after_failure = \"stop\")".into(),
            ));
        }
        None
    }

    /// Ticks the policy, and again in the same step while its root fails
    /// because an action failed and it goes on.
    fn tick_until_settled(&mut self) {
        // A policy whose root failed because an action failed, and which
        // goes on (a BT, a machine re-entered after FAILURE), is ticked
        // again in the same step, as an FSM's failure arc starts its next
        // action in the step of the failure: no representation gets a step
        // for free. Bounded: MAX_TICKS_PER_STEP ticks.
        let mut ticks = 0;
        loop {
            ticks += 1;
            let failed = self.robot.failed_ends;
            self.last = match &mut self.ex {
                Ex::Bt(b) => b.tick(&mut self.robot),
                Ex::M(m) => m.step(&mut self.robot),
            };
            let goes_on = match &self.ex {
                Ex::Bt(_) => self.p.after_failure == Afterwards::KeepTicking,
                Ex::M(m) => m.finished.is_none(),
            };
            if self.last != Status::Failure
                || !goes_on
                || self.robot.failed_ends == failed
                || ticks >= MAX_TICKS_PER_STEP
            {
                break;
            }
            // The last tick of the step says which actions go on.
            self.robot.untick();
        }
    }

    /// Records the robot's position: every step in the trajectory, where it
    /// moved in the track.
    fn record_position(&mut self) {
        let at = self.robot.world.robot;
        self.trajectory.push(at);
        if self.track.last().is_none_or(|&(_, q)| dist(q, at) > 1e-6) {
            self.track.push((self.steps, at));
        }
    }

    /// Hands the step's trace record (pose, battery, running skills,
    /// statuses) to `sink`, or keeps it.
    fn record_trace(&mut self, sink: &mut Option<StepSink<'_>>) {
        let robot = &self.robot;
        let st = match &self.ex {
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
        let keys = &self.p.keys;
        let goal = (robot.base)
            .and_then(|k| robot.live[k].as_ref())
            .filter(|r| r.result.is_none())
            .and_then(|r| r.nav_goal())
            .map(|p| [round3(p.0), round3(p.1)]);
        let step = Step {
            t: round3(robot.world.time),
            x: robot.world.robot.0,
            y: robot.world.robot.1,
            yaw: robot.world.yaw,
            battery: (robot.world.battery * 100.0).round() / 100.0,
            running,
            goal,
            statuses: st
                .map(|v| {
                    v.iter()
                        .map(|(k, s)| (keys[*k].clone(), s.as_str().to_string()))
                        .collect()
                })
                .unwrap_or_default(),
        };
        match sink.as_mut() {
            Some(f) => f(&step),
            None => self.trace.push(step),
        }
    }

    /// After the step: notes the policy done, and ends the run on a full
    /// record, a livelock, too many failures, or the policy done with no
    /// timed disturbance pending.
    fn settle(&mut self, disturbed: bool) -> ControlFlow<Ended> {
        let finished = self.ex.finished();
        let done =
            self.last == Status::Success && finished.as_ref().is_none_or(|f| f.0 == "SUCCESS");
        self.note_done(done);
        let pending = self.pending_timed > 0;
        let robot = &mut self.robot;
        if robot.full {
            let steps = self.steps;
            return ControlFlow::Break(Some((
                Outcome::Timeout,
                format!(
                    "record budget exhausted at step {steps}: a run records at most {MAX_SKILL_RECORDS} executed skills and {MAX_EVENTS} events"
                ),
            )));
        }
        let measure = (self.goal_terms.iter())
            .filter(|(c, neg)| skills::condition(c, &robot.world) != *neg)
            .count()
            + usize::from(done);
        let fresh = !robot.started.is_empty();
        let state = abstract_state(robot);
        robot.started.clear();
        let goals = (robot.touched.iter())
            .filter_map(|&k| robot.live[k].as_ref().and_then(|r| r.nav_goal()));
        let advanced = self.nav.advanced(robot.world.robot, goals);
        // No livelock while a scheduled disturbance is still to come (an
        // all-clear may end the waiting), nor while the robot advances.
        let reset = disturbed || pending || advanced;
        if let Some(n) = self.livelock.step(state, fresh, measure, reset) {
            let text = format!(
                "livelock: an abstract state (world facts, running skills) entered {n} times without progress toward the goal"
            );
            robot.event("chattering", text.clone());
            return ControlFlow::Break(Some((Outcome::Chattering, text)));
        }
        if robot.failures > self.s.max_failures {
            let text = format!(
                "gave up after {} failed actions without progress",
                robot.failures
            );
            return ControlFlow::Break(Some((Outcome::Failure, text)));
        }
        if !pending && (done || finished.is_some()) {
            return ControlFlow::Break(None);
        }
        ControlFlow::Continue(())
    }

    /// Notes whether the policy is done at this step: the first time (an
    /// event), and since when it has been without a break (completion).
    fn note_done(&mut self, done: bool) {
        if done {
            if self.completion.is_none() || self.first_done.is_none() {
                self.robot
                    .event("done", "the policy reports SUCCESS".into());
            }
            self.first_done.get_or_insert(self.robot.world.time);
            self.completion.get_or_insert(self.robot.world.time);
        } else {
            self.completion = None;
        }
    }

    /// The outcome and reason of a run the loop did not end early: the
    /// machine's outcome, the BT's SUCCESS, or the step budget.
    fn own_outcome(&self) -> (Outcome, String) {
        match self.ex.finished() {
            Some((o, why)) if o == "SUCCESS" => (Outcome::Success, why),
            Some((_, why)) => (Outcome::Failure, why),
            None if self.last == Status::Success => (
                Outcome::Success,
                match &self.ex {
                    Ex::Bt(_) => "the root returned SUCCESS".into(),
                    Ex::M(_) => "reached the outcome SUCCESS (and ticks on)".into(),
                },
            ),
            None => (
                Outcome::Timeout,
                format!("step budget of {} steps exhausted", self.s.max_steps),
            ),
        }
    }

    /// The record of the run once its loop has ended (`ended`: how, when
    /// the loop decided it).
    fn into_run(self, ended: Ended) -> Run {
        // Whatever still runs at the end stays `running` in the records.
        let (outcome, reason) = ended.unwrap_or_else(|| self.own_outcome());
        let (s, p, robot) = (self.s, self.p, self.robot);
        let goal_met = s.goal.as_ref().map(|g| holds(g, &robot.world));
        Run {
            policy: p.name.clone(),
            file: p.file.clone(),
            kind: p.kind.clone(),
            convert: p.convert.clone(),
            outcome,
            reason,
            goal_met,
            steps: self.steps,
            dt: s.dt,
            pose_tolerance_m: s.pose_tolerance_m,
            start_tolerance_s: s.start_tolerance_s,
            time_shift_s: s.time_shift_s,
            after_success: p.after_success.as_str(),
            after_failure: p.after_failure.as_str(),
            completion_s: self.completion.map(round3),
            duration_s: round3(robot.world.time),
            distance_m: round3(robot.world.odometer),
            skills: robot.records,
            events: robot.events,
            final_world: FinalWorld::of(&robot.world),
            recharge_latency_s: robot.latencies,
            trajectory: self.trajectory,
            track: self.track,
            trace: self.trace,
        }
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
