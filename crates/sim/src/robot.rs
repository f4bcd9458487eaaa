//! The robot as the executors see it (SPEC §6): the world, the actions
//! running on it (one [`Running`] per leaf), injected faults, and the
//! records of executed skills and events that a run reports.
//!
//! One base, one arm: an action that needs a resource held by another
//! running action aborts it (its record ends as `aborted` at once, and its
//! leaf gets FAILURE at its next tick), as a navigation action server aborts
//! its goal for a new one. A halted action ([`Leaves::halt`]) stops at once;
//! at the end of a step the actions not ticked are cancelled, then the base
//! moves for the one action holding it, then the camera looks.

use super::exec::Leaves;
use super::rng::SimRng;
use super::scenario::{Disturbance, Effect};
use super::skills::{self, Call, Resource, Running, Status, Target};
use super::trace::{Event, SkillRecord};
use super::world::{Place, World};
use std::collections::BTreeMap;

/// Injected faults: "fail the next N times" and failure rates.
///
/// Common random numbers (issue 31): whether a start of a skill is doomed,
/// and where it aborts, is drawn from a stream of its own, keyed by the
/// episode's seed, the call (skill and arguments) and how many times that
/// call started before in the run: two policies that make the same calls
/// meet the same faults, whatever else they do in between.
#[derive(Debug, Clone)]
pub(super) struct Faults {
    pub(super) next: BTreeMap<String, u32>,
    pub(super) rates: BTreeMap<String, f64>,
    seed: u64,
    /// Starts so far per call (at most `MAX_SKILL_RECORDS` entries).
    starts: std::collections::HashMap<String, u32>,
}

impl Faults {
    pub(super) fn new(seed: u64, rates: BTreeMap<String, f64>) -> Self {
        Faults {
            next: BTreeMap::new(),
            rates,
            seed,
            starts: std::collections::HashMap::new(),
        }
    }

    /// `Some(f)`: this start of `skill` with these arguments aborts at the
    /// fraction `f` (drawn uniformly from [0.05, 0.95]) of its execution.
    fn doomed(&mut self, skill: &str, args: &BTreeMap<String, String>) -> Option<f64> {
        let mut call = String::from(skill);
        for (k, v) in args {
            call.push_str(&format!("\u{1f}{k}={v}"));
        }
        let n = self.starts.entry(call.clone()).or_insert(0);
        let ordinal = *n;
        *n += 1;
        let mut rng = SimRng::named(
            self.seed,
            &format!("skill-fault\u{1f}{call}\u{1f}{ordinal}"),
        );
        let doomed = if let Some(n) = self.next.get_mut(skill)
            && *n > 0
        {
            *n -= 1;
            true
        } else {
            match self.rates.get(skill) {
                Some(&p) => rng.chance(p),
                None => false,
            }
        };
        doomed.then(|| rng.range(0.05, 0.95))
    }
}

/// The robot as the executors see it: the world, the running actions and the
/// records.
pub(super) struct Robot {
    pub(super) world: World,
    pub(super) dt: f64,
    pub(super) live: Vec<Option<Running>>,
    pub(super) ticked: Vec<bool>,
    /// The keys ticked in this step or live, so that a step's bookkeeping
    /// costs what it touched, not the size of the policy; after
    /// [`Robot::end_step`], the live keys in ascending order.
    pub(super) touched: Vec<usize>,
    pub(super) records: Vec<SkillRecord>,
    pub(super) events: Vec<Event>,
    pub(super) faults: Faults,
    pub(super) log: bool,
    /// Actions that ended in FAILURE so far (the run loop re-ticks a policy
    /// whose root failed because one did, within the same step).
    pub(super) failed_ends: u64,
    /// Leaves whose action started in this step, a retry of the action that
    /// just failed excepted (livelock detection; cleared by the run loop).
    pub(super) started: Vec<usize>,
    /// The leaf whose action failed last, until the next start.
    pub(super) failed_key: Option<usize>,
    pub(super) failures: u32,
    pub(super) mark: u64,
    pub(super) low_at: Option<f64>,
    pub(super) latencies: Vec<f64>,
    /// An action start or an event was refused: the run's records are full
    /// ([`MAX_SKILL_RECORDS`], [`MAX_EVENTS`]); the run ends after the step.
    pub(super) full: bool,
    /// The leaf whose action holds the base, and the arm.
    pub(super) base: Option<usize>,
    pub(super) arm: Option<usize>,
}

/// Executed skills a run records at most: a policy that picks and places
/// every step for 10^6 steps held 2 million records (3.3 GB, and 1 GB of
/// JSON); past this the run ends with outcome `timeout` (the bundled
/// scenarios record at most 24).
pub const MAX_SKILL_RECORDS: usize = 1024;
/// Events a run records at most (likewise; the bundled scenarios: 50).
pub const MAX_EVENTS: usize = 4096;

/// The arguments of a resolved call, by name.
pub fn call_args(c: &Call, w: &World) -> BTreeMap<String, String> {
    let tgt = |t: &Target| match *t {
        Target::Station(s) => w.layout.stations[s].0.clone(),
        Target::Object(o) => w.objects[o].name.clone(),
    };
    let obj = |o: usize| w.objects[o].name.clone();
    let st = |s: usize| w.layout.stations[s].0.clone();
    let mut m = BTreeMap::new();
    match c {
        Call::MoveTo { target, .. } | Call::RobotAt(target) => {
            m.insert("target".into(), tgt(target));
        }
        Call::Pick { object } | Call::InHand(object) => {
            m.insert("object".into(), obj(*object));
        }
        Call::Place { object, at } | Call::ObjectAt { object, at } => {
            m.insert("object".into(), obj(*object));
            m.insert("at".into(), st(*at));
        }
        Call::BatteryLevel(x) => {
            m.insert("min".into(), x.to_string());
        }
        _ => {}
    }
    m
}

impl Robot {
    /// A robot in `world` for a policy of `leaves` leaf keys.
    pub(super) fn new(world: World, dt: f64, leaves: usize, faults: Faults, log: bool) -> Self {
        Robot {
            world,
            dt,
            live: vec![None; leaves],
            ticked: vec![false; leaves],
            records: Vec::new(),
            events: Vec::new(),
            faults,
            log,
            touched: Vec::new(),
            failed_ends: 0,
            started: Vec::new(),
            failed_key: None,
            failures: 0,
            mark: 0,
            low_at: None,
            latencies: Vec::new(),
            full: false,
            base: None,
            arm: None,
        }
    }

    pub(super) fn event(&mut self, kind: &str, text: String) {
        if self.events.len() >= MAX_EVENTS {
            self.full = true;
            return;
        }
        if self.log {
            self.events.push(Event {
                t: round3(self.world.time),
                kind: kind.into(),
                text,
                x: self.world.robot.0,
                y: self.world.robot.1,
            });
        }
    }

    fn sync_progress(&mut self) {
        if self.world.progress != self.mark {
            self.mark = self.world.progress;
            self.failures = 0;
        }
    }

    fn close(&mut self, rec: usize, outcome: &str) {
        self.close_at(rec, outcome, self.world.time);
    }

    fn close_at(&mut self, rec: usize, outcome: &str, t: f64) {
        let t = round3(t);
        let r = &mut self.records[rec];
        r.outcome = outcome.into();
        r.end = Some(t);
        if self.log {
            let text = r.text();
            self.event("end", text);
        }
    }

    /// Frees the resources leaf `key` holds.
    fn release(&mut self, key: usize) {
        if self.base == Some(key) {
            self.base = None;
        }
        if self.arm == Some(key) {
            self.arm = None;
        }
    }

    /// Stops the action of leaf `key` now: `cancelled` unless its outcome
    /// was already reached (then its record stands).
    fn stop(&mut self, key: usize) {
        if let Some(mut r) = self.live[key].take() {
            r.cancel(&mut self.world);
            if r.result.is_none() {
                self.close(r.record, "cancelled");
            }
        }
        self.release(key);
    }

    /// Gives `res` to leaf `key`, aborting the action that held it.
    fn claim(&mut self, key: usize, res: Resource) {
        let holder = match res {
            Resource::Base => self.base.replace(key),
            Resource::Arm => self.arm.replace(key),
        };
        let Some(j) = holder.filter(|&j| j != key) else {
            return;
        };
        if let Some(r) = self.live[j].as_mut()
            && r.result.is_none()
        {
            r.cancel(&mut self.world);
            r.result = Some(Status::Failure);
            let rec = r.record;
            self.close(rec, "aborted");
            let text = format!("{} aborted by a new goal", self.records[rec].skill);
            self.event("aborted", text);
        }
        // It holds nothing any more.
        if self.base == Some(j) {
            self.base = None;
        }
        if self.arm == Some(j) {
            self.arm = None;
        }
    }

    /// Ends a step: cancels the actions that were not ticked, moves the base
    /// for the action holding it (once), lets the camera look, and records
    /// the outcomes reached.
    pub(super) fn end_step(&mut self) {
        // Only the keys touched since the last step can hold a live action;
        // in key order, as a walk over every key would stop them.
        let mut keys = std::mem::take(&mut self.touched);
        keys.sort_unstable();
        keys.dedup();
        for &k in &keys {
            if !self.ticked[k] && self.live[k].is_some() {
                self.stop(k);
            }
            self.ticked[k] = false;
        }
        keys.retain(|&k| self.live[k].is_some());
        self.touched = keys;
        let dt = self.dt;
        let end = self.world.time + dt;
        if let Some(k) = self.base
            && let Some(r) = self.live[k].as_mut()
            && let Some(s) = r.drive(&mut self.world, dt)
        {
            let rec = r.record;
            self.close_at(rec, outcome(s), end);
        }
        let mut seen = Vec::new();
        if self.world.sense_noting(self.log.then_some(&mut seen)) > 0 {
            self.world.progress += 1;
        }
        for i in seen {
            let o = &self.world.objects[i];
            let text = format!(
                "camera: {} believed at ({:.2}, {:.2})",
                o.name, o.belief.0, o.belief.1
            );
            self.event("belief", text);
        }
        if let Some(k) = self.base
            && let Some(r) = self.live[k].as_mut()
            && let Some(s) = r.settle(&self.world)
        {
            let rec = r.record;
            self.close_at(rec, outcome(s), end);
        }
    }

    /// Forgets which keys were ticked in this step (the run loop ticks the
    /// policy again: its last tick says which actions go on).
    pub(super) fn untick(&mut self) {
        for &k in &self.touched {
            self.ticked[k] = false;
        }
    }
}

fn outcome(s: Status) -> &'static str {
    match s {
        Status::Success => "success",
        Status::Failure => "failure",
        Status::Running => "running",
    }
}

pub(super) fn round3(x: f64) -> f64 {
    (x * 1000.0).round() / 1000.0
}

impl Leaves for Robot {
    #[inline]
    fn condition(&mut self, _key: usize, call: &Call) -> bool {
        skills::condition(call, &self.world)
    }

    fn action(&mut self, key: usize, call: &Call) -> Status {
        if !self.ticked[key] {
            self.ticked[key] = true;
            self.touched.push(key);
        }
        if self.live[key].as_ref().is_none_or(|r| r.call != *call) {
            if self.records.len() >= MAX_SKILL_RECORDS {
                // Not started: the run ends after this step.
                self.full = true;
                return Status::Failure;
            }
            if self.live[key].is_some() {
                self.stop(key);
            }
            self.sync_progress();
            if self.failed_key != Some(key) && self.started.len() < 64 {
                self.started.push(key);
            }
            self.failed_key = None;
            let args = call_args(call, &self.world);
            let fault_at = self.faults.doomed(call.name(), &args);
            if *call == Call::Recharge
                && let Some(t) = self.low_at.take()
            {
                self.latencies.push(round3(self.world.time - t));
            }
            self.records.push(SkillRecord {
                skill: call.name().into(),
                args,
                outcome: "running".into(),
                start: round3(self.world.time),
                end: None,
            });
            if self.log {
                let text = self.records.last().expect("pushed").text();
                self.event("start", text.trim_end_matches(" -> running").to_string());
            }
            for &res in call.resources() {
                self.claim(key, res);
            }
            self.live[key] = Some(Running::new(*call, fault_at, self.records.len() - 1));
        }
        let r = self.live[key].as_mut().expect("started above");
        let known = r.result.is_some();
        let s = r.tick(&mut self.world, self.dt);
        if s != Status::Running {
            let rec = r.record;
            self.live[key] = None;
            self.release(key);
            if !known {
                self.close(rec, outcome(s));
            }
            if s == Status::Failure {
                self.sync_progress();
                self.failures += 1;
                self.failed_ends += 1;
                self.failed_key = Some(key);
            }
        }
        s
    }

    fn halt(&mut self, key: usize) {
        self.stop(key);
    }

    fn now(&self) -> f64 {
        self.world.time
    }
}

/// Applies a disturbance's effect.
pub(super) fn apply(d: &Disturbance, r: &mut Robot) {
    let w = &mut r.world;
    match &d.effect {
        Effect::Battery(b) => w.battery = *b,
        Effect::Move { object, to } => w.objects[*object].place = w.rest_at(*to),
        Effect::Drop { object } => {
            if w.objects[*object].place == Place::Held {
                // It lies on the floor where it fell, and (`drop_sensed`)
                // the robot that held it knows where.
                w.objects[*object].place = Place::Floor(w.robot);
                if w.params.drop_sensed {
                    w.objects[*object].belief = w.robot;
                    w.objects[*object].found = true;
                    let o = &w.objects[*object];
                    let text = format!(
                        "drop sensed: {} believed at ({:.2}, {:.2})",
                        o.name, o.belief.0, o.belief.1
                    );
                    r.event("belief", text);
                }
            }
        }
        Effect::Fail { skill, times } => *r.faults.next.entry(skill.clone()).or_insert(0) += times,
        Effect::Block(rect) => {
            if rect.distance(w.robot) < w.params.robot_radius {
                // A box cannot land on the robot: refused, and said so.
                let text = format!("{} refused: it would cover the robot", d.text);
                r.event("disturbance", text);
                return;
            }
            w.block(rect.clone())
        }
        Effect::Emergency(b) => {
            w.emergency = *b;
            if !*b {
                // Shut-Down holds until the emergency clears.
                w.shut_down = false;
            }
        }
    }
    r.world.progress += 1;
    r.event("disturbance", d.text.clone());
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn args(object: &str) -> BTreeMap<String, String> {
        BTreeMap::from([("object".to_string(), object.to_string())])
    }

    proptest! {
        /// Common random numbers: a policy that makes extra calls between
        /// the same calls meets the same faults on those calls, at the same
        /// points.
        #[test]
        fn the_same_calls_meet_the_same_faults_whatever_comes_between(
            seed in any::<u64>(),
            rate in 0.05f64..0.95,
            calls in proptest::collection::vec(0usize..3, 1..40),
            extra in proptest::collection::vec((0usize..40, 0usize..4), 0..20),
        ) {
            let objects = ["cube1", "cube2", "cube3", "cube4"];
            let rates = BTreeMap::from([
                ("Pick".to_string(), rate),
                ("Place".to_string(), rate),
            ]);
            let mut a = Faults::new(seed, rates.clone());
            let mut b = Faults::new(seed, rates);
            let mut inserted: Vec<Vec<usize>> = vec![Vec::new(); calls.len()];
            for (at, o) in extra {
                inserted[at % calls.len()].push(o);
            }
            for (k, &c) in calls.iter().enumerate() {
                for &o in &inserted[k] {
                    // Another skill, or the same one on another object.
                    let _ = b.doomed(if o % 2 == 0 { "Place" } else { "Move-To" }, &args(objects[o]));
                }
                let da = a.doomed("Pick", &args(objects[c]));
                let db = b.doomed("Pick", &args(objects[c]));
                prop_assert_eq!(da, db);
            }
        }
    }
}
