//! The robot as the executors see it (SPEC §6): the world, the actions
//! running on it (one [`Running`] per leaf), injected faults, and the
//! records of executed skills and events that a run reports.

use super::exec::Leaves;
use super::rng::SimRng;
use super::scenario::{Disturbance, Effect};
use super::skills::{self, Call, Running, Status, Target};
use super::trace::{Event, SkillRecord};
use super::world::{Place, World};
use std::collections::BTreeMap;

/// Injected faults: "fail the next N times" and failure rates.
#[derive(Debug, Clone)]
pub(super) struct Faults {
    pub(super) next: BTreeMap<String, u32>,
    pub(super) rates: BTreeMap<String, f64>,
    pub(super) rng: SimRng,
}

impl Faults {
    fn doomed(&mut self, skill: &str) -> bool {
        if let Some(n) = self.next.get_mut(skill)
            && *n > 0
        {
            *n -= 1;
            return true;
        }
        match self.rates.get(skill) {
            Some(&p) => self.rng.chance(p),
            None => false,
        }
    }
}

/// The robot as the executors see it: the world, the running actions and the
/// records.
pub(super) struct Robot {
    pub(super) world: World,
    pub(super) dt: f64,
    pub(super) live: Vec<Option<Running>>,
    pub(super) ticked: Vec<bool>,
    pub(super) records: Vec<SkillRecord>,
    pub(super) events: Vec<Event>,
    pub(super) faults: Faults,
    pub(super) log: bool,
    pub(super) last_failed: Option<Call>,
    pub(super) switches: u32,
    pub(super) failures: u32,
    pub(super) mark: u64,
    pub(super) low_at: Option<f64>,
    pub(super) latencies: Vec<f64>,
    /// An action start or an event was refused: the run's records are full
    /// ([`MAX_SKILL_RECORDS`], [`MAX_EVENTS`]); the run ends after the step.
    pub(super) full: bool,
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
            self.switches = 0;
            self.failures = 0;
        }
    }

    fn close(&mut self, rec: usize, outcome: &str) {
        let t = round3(self.world.time);
        let r = &mut self.records[rec];
        r.outcome = outcome.into();
        r.end = Some(t);
        if self.log {
            let text = r.text();
            self.event("end", text);
        }
    }

    /// Cancels the actions that were not ticked in this step.
    pub(super) fn end_step(&mut self) {
        for k in 0..self.live.len() {
            if !self.ticked[k]
                && let Some(mut r) = self.live[k].take()
            {
                r.cancel(&mut self.world);
                self.close(r.record, "cancelled");
            }
            self.ticked[k] = false;
        }
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
        self.ticked[key] = true;
        if self.live[key].as_ref().is_none_or(|r| r.call != *call) {
            if self.records.len() >= MAX_SKILL_RECORDS {
                // Not started: the run ends after this step.
                self.full = true;
                return Status::Failure;
            }
            if let Some(mut old) = self.live[key].take() {
                old.cancel(&mut self.world);
                self.close(old.record, "cancelled");
            }
            self.sync_progress();
            // Every start counts, except a retry of the action that just failed.
            if self.last_failed != Some(*call) {
                self.switches += 1;
            }
            self.last_failed = None;
            let doomed = self.faults.doomed(call.name());
            if *call == Call::Recharge
                && let Some(t) = self.low_at.take()
            {
                self.latencies.push(round3(self.world.time - t));
            }
            self.records.push(SkillRecord {
                skill: call.name().into(),
                args: call_args(call, &self.world),
                outcome: "running".into(),
                start: round3(self.world.time),
                end: None,
            });
            if self.log {
                let text = self.records.last().expect("pushed").text();
                self.event("start", text.trim_end_matches(" -> running").to_string());
            }
            self.live[key] = Some(Running::new(*call, doomed, self.records.len() - 1));
        }
        let r = self.live[key].as_mut().expect("started above");
        let s = r.tick(&mut self.world, self.dt);
        if s != Status::Running {
            let rec = r.record;
            self.live[key] = None;
            self.close(
                rec,
                if s == Status::Success {
                    "success"
                } else {
                    "failure"
                },
            );
            if s == Status::Failure {
                self.sync_progress();
                self.failures += 1;
                self.last_failed = Some(*call);
            }
        }
        s
    }

    fn halt(&mut self, key: usize) {
        if let Some(mut r) = self.live[key].take() {
            r.cancel(&mut self.world);
            self.close(r.record, "cancelled");
        }
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
        Effect::Move { object, to } => w.objects[*object].place = Place::At(*to),
        Effect::Drop { object } => {
            if w.objects[*object].place == Place::Held {
                w.objects[*object].place = Place::At(w.robot);
            }
        }
        Effect::Fail { skill, times } => *r.faults.next.entry(skill.clone()).or_insert(0) += times,
        Effect::Block(rect) => w.block(rect.clone()),
        Effect::Emergency(b) => w.emergency = *b,
    }
    r.world.progress += 1;
    r.event("disturbance", d.text.clone());
}
