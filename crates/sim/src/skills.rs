//! The one skill library every executor uses (SPEC §6; the paper's fairness
//! rule, sec. V: BTs and FSMs call the same low-level skills). A binding from a
//! policy ([`btfsm_model::SkillCall`]) is resolved against the world once into a
//! [`Call`]; actions then run over many steps as [`Running`] instances that return
//! RUNNING, SUCCESS or FAILURE and are cancelled ([`Running::cancel`]) when
//! halted, not ticked, or aborted by a new goal for their resource (an action
//! leaves nothing half-done in the world: a cancelled Recharge stops charging).
//!
//! Conventions (docs/simulator-model.md states each with its test): every
//! action's first tick returns RUNNING and its outcome comes at a later tick;
//! the robot has one base and one arm ([`Resource`]), and the base moves once
//! per step, for the one action holding it ([`Running::drive`]); an outcome
//! reached while moving (arrival, an injected fault, a stall) is recorded at
//! that moment and returned at the action's next tick. A navigation goes to
//! the pose its target had (for an object: the believed pose) when it
//! started. `Battery-Level(min)` is `battery >= min`.

use super::world::{P2, Place, World, dist};
use btfsm_core::diagnostic::suggest;
use btfsm_model::{ArgValue, SkillCall};

/// A return status (the paper's sec. II).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "UPPERCASE")]
pub enum Status {
    Running,
    Success,
    Failure,
}

impl Status {
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Running => "RUNNING",
            Status::Success => "SUCCESS",
            Status::Failure => "FAILURE",
        }
    }
}

/// What a navigation skill or Robot-At refers to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Target {
    /// Index into the layout's stations.
    Station(usize),
    /// Index into the world's objects (its grasp pose).
    Object(usize),
}

/// A skill binding resolved against a world.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Call {
    MoveTo {
        target: Target,
        safe: bool,
    },
    Pick {
        object: usize,
    },
    Place {
        object: usize,
        at: usize,
    },
    Recharge,
    Dock,
    TuckArm,
    Search,
    ShutDown,
    RobotAt(Target),
    InHand(usize),
    ObjectAt {
        object: usize,
        at: usize,
    },
    BatteryLevel(f64),
    ArmTucked,
    Found,
    NoEmergency,
    /// A leaf or guard term of the symbolic world (`sim::symbolic`): an
    /// index into its table of bindings, and whether it is an action. The
    /// planar world never makes one and evaluates it as a failing leaf.
    Symbolic {
        id: u32,
        action: bool,
    },
}

impl Call {
    /// The library name of the skill.
    pub fn name(&self) -> &'static str {
        match self {
            Call::MoveTo { safe: false, .. } => "Move-To",
            Call::MoveTo { safe: true, .. } => "Safe-Move-To",
            Call::Pick { .. } => "Pick",
            Call::Place { .. } => "Place",
            Call::Recharge => "Recharge",
            Call::Dock => "Dock",
            Call::TuckArm => "Tuck-Arm",
            Call::Search => "Search",
            Call::ShutDown => "Shut-Down",
            Call::RobotAt(_) => "Robot-At",
            Call::InHand(_) => "In-Hand",
            Call::ObjectAt { .. } => "Object-At",
            Call::BatteryLevel(_) => "Battery-Level",
            Call::ArmTucked => "Arm-Tucked",
            Call::Found => "Found",
            Call::NoEmergency => "No-Emergency",
            Call::Symbolic { .. } => "symbolic",
        }
    }

    pub fn is_action(&self) -> bool {
        matches!(
            self,
            Call::MoveTo { .. }
                | Call::Pick { .. }
                | Call::Place { .. }
                | Call::Recharge
                | Call::Dock
                | Call::TuckArm
                | Call::Search
                | Call::ShutDown
                | Call::Symbolic { action: true, .. }
        )
    }
}

/// A binding that cannot run in a world: the message and the valid names.
#[derive(Debug, Clone, PartialEq)]
pub struct Unresolved {
    pub message: String,
    pub hint: String,
}

fn arg_str<'a>(c: &'a SkillCall, key: &str) -> Result<&'a str, Unresolved> {
    match c.args.get(key) {
        Some(ArgValue::Str(s)) => Ok(s),
        Some(other) => Err(Unresolved {
            message: format!(
                "argument `{key}` of `{}` must be a name, found `{other}`",
                c.skill
            ),
            hint: "write the name of an object or station in quotes".into(),
        }),
        None => Err(Unresolved {
            message: format!("skill `{}` needs the argument `{key}`", c.skill),
            hint: format!("add `{key} = \"...\"` to its args"),
        }),
    }
}

fn object(w: &World, name: &str) -> Result<usize, Unresolved> {
    w.object_index(name).ok_or_else(|| Unresolved {
        message: format!("unknown object `{name}`"),
        hint: suggest(name, w.objects.iter().map(|o| o.name.as_str())),
    })
}

fn station(w: &World, name: &str) -> Result<usize, Unresolved> {
    w.layout.station_index(name).ok_or_else(|| Unresolved {
        message: format!("unknown station `{name}`"),
        hint: suggest(name, w.layout.stations.iter().map(|(n, _)| n.as_str())),
    })
}

fn target(w: &World, name: &str) -> Result<Target, Unresolved> {
    if let Some(i) = w.object_index(name) {
        return Ok(Target::Object(i));
    }
    station(w, name)
        .map(Target::Station)
        .map_err(|_| Unresolved {
            message: format!("unknown station or object `{name}`"),
            hint: suggest(
                name,
                w.layout
                    .stations
                    .iter()
                    .map(|(n, _)| n.as_str())
                    .chain(w.objects.iter().map(|o| o.name.as_str())),
            ),
        })
}

/// Resolves a policy's binding against a world.
pub fn resolve(c: &SkillCall, w: &World) -> Result<Call, Unresolved> {
    Ok(match c.skill.as_str() {
        "Move-To" | "Safe-Move-To" => Call::MoveTo {
            target: target(w, arg_str(c, "target")?)?,
            safe: c.skill == "Safe-Move-To",
        },
        "Pick" => Call::Pick {
            object: object(w, arg_str(c, "object")?)?,
        },
        "Place" => Call::Place {
            object: object(w, arg_str(c, "object")?)?,
            at: station(w, arg_str(c, "at")?)?,
        },
        "Recharge" => Call::Recharge,
        "Dock" => Call::Dock,
        "Tuck-Arm" => Call::TuckArm,
        "Search" => Call::Search,
        "Shut-Down" => Call::ShutDown,
        "Robot-At" => Call::RobotAt(target(w, arg_str(c, "target")?)?),
        "In-Hand" => Call::InHand(object(w, arg_str(c, "object")?)?),
        "Object-At" => Call::ObjectAt {
            object: object(w, arg_str(c, "object")?)?,
            at: station(w, arg_str(c, "at")?)?,
        },
        "Battery-Level" => Call::BatteryLevel(match c.args.get("min") {
            Some(ArgValue::Int(i)) if (0..=100).contains(i) => *i as f64,
            Some(ArgValue::Float(f)) if (0.0..=100.0).contains(f) => *f,
            Some(other @ (ArgValue::Int(_) | ArgValue::Float(_))) => {
                let found = match other {
                    ArgValue::Float(x) => crate::scenario::show(*x),
                    other => other.to_string(),
                };
                return Err(Unresolved {
                    message: format!(
                        "`min` of `Battery-Level` must be a percentage from 0 to 100, found {found}"
                    ),
                    hint: "write e.g. `args = { min = 20 }`".into(),
                });
            }
            _ => {
                return Err(Unresolved {
                    message: "skill `Battery-Level` needs a number `min` (percent)".into(),
                    hint: "write `args = { min = 20 }`".into(),
                });
            }
        }),
        "Arm-Tucked" => Call::ArmTucked,
        "Found" => Call::Found,
        "No-Emergency" => Call::NoEmergency,
        other if other.contains(':') => {
            return Err(Unresolved {
                message: format!(
                    "unknown skill `{other}` (a skill of an action domain: it runs in symbolic scenarios, not in the planar room)"
                ),
                hint: "give the scenario `domain = \"DOMAIN.toml\"` to run it in the domain's world of facts (docs/guide/sim.md, \"Symbolic simulation\")".into(),
            });
        }
        other => {
            return Err(Unresolved {
                message: format!("unknown skill `{other}`"),
                hint: suggest(other, btfsm_model::skill::SKILLS.iter().map(|(n, _, _)| *n)),
            });
        }
    })
}

/// What an action occupies: the robot has one mobile base and one arm, and a
/// new goal for either preempts the action holding it (as an action server
/// aborts its running goal).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Resource {
    Base,
    Arm,
}

impl Call {
    /// The resources the action holds while it runs (Shut-Down stops both).
    pub fn resources(&self) -> &'static [Resource] {
        match self {
            Call::MoveTo { .. } | Call::Dock | Call::Recharge | Call::Search => &[Resource::Base],
            Call::Pick { .. } | Call::Place { .. } | Call::TuckArm => &[Resource::Arm],
            Call::ShutDown => &[Resource::Base, Resource::Arm],
            _ => &[],
        }
    }
}

/// The pose a target stands for: a station's pose, or where the robot
/// believes an object is (`None`: an object never seen).
fn goal_of(t: Target, w: &World) -> Option<P2> {
    match t {
        Target::Station(s) => Some(w.layout.stations[s].1),
        Target::Object(o) => w.believed(o),
    }
}

/// Evaluates a condition (actions evaluate to `false`).
#[inline]
pub fn condition(c: &Call, w: &World) -> bool {
    let tol = w.params.at_tolerance;
    // Squared distances: no square root on the hot path.
    let near = |a: P2, b: P2, r: f64| (a.0 - b.0).powi(2) + (a.1 - b.1).powi(2) <= r * r;
    match *c {
        Call::RobotAt(t) => goal_of(t, w).is_some_and(|g| near(g, w.robot, tol)),
        Call::InHand(o) => w.objects[o].place == Place::Held,
        Call::ObjectAt { object, at } => w.object_at(object, at),
        Call::BatteryLevel(min) => w.battery >= min,
        Call::ArmTucked => w.arm_tucked,
        Call::Found => w.objects.iter().all(|o| o.found),
        Call::NoEmergency => !w.emergency,
        _ => false,
    }
}

/// A running action: its binding and its progress. Its first tick starts it
/// (RUNNING); the base's motion is integrated once per step by
/// [`Running::drive`] for the one action holding the base, and an outcome
/// reached during that motion is delivered at the next tick.
#[derive(Debug, Clone)]
pub struct Running {
    pub call: Call,
    /// An injected fault: the fraction of its execution (of the planned
    /// path of a navigation, of the duration of a timed action) at which
    /// it aborts.
    pub fault_at: Option<f64>,
    /// Index of its record in the run's list of executed skills.
    pub record: usize,
    /// Its outcome, once reached (during the step's motion, or aborted by a
    /// new goal for its resource); returned at its next tick.
    pub result: Option<Status>,
    ticks: u32,
    start: f64,
    /// The navigation goal, fixed when the action starts (an action
    /// server's goal): the believed pose of an object at that moment.
    goal: Option<P2>,
    path: Vec<P2>,
    path_i: usize,
    planned_for: u32,
    /// Length of the path planned at the start, m.
    length: f64,
    travelled: f64,
    stalled: f64,
    waypoint: usize,
    charging: bool,
}

impl Running {
    /// The navigation goal, when it is a navigation that has started.
    pub(crate) fn nav_goal(&self) -> Option<P2> {
        self.goal
    }

    pub fn new(call: Call, fault_at: Option<f64>, record: usize) -> Self {
        Running {
            call,
            fault_at,
            record,
            result: None,
            ticks: 0,
            start: 0.0,
            goal: None,
            path: Vec::new(),
            path_i: 0,
            planned_for: u32::MAX,
            length: 0.0,
            travelled: 0.0,
            stalled: 0.0,
            waypoint: 0,
            charging: false,
        }
    }

    /// The pose the base is driving to now.
    fn target(&self, w: &World) -> Option<P2> {
        match self.call {
            Call::Search => w.layout.waypoints.get(self.waypoint).copied(),
            _ => self.goal,
        }
    }

    fn speed(&self, w: &World) -> f64 {
        match self.call {
            Call::MoveTo { safe: true, .. } | Call::Dock => w.params.max_speed * 0.5,
            _ => w.params.max_speed,
        }
    }

    /// Plans from the robot to the current target; `false`: no path.
    fn plan(&mut self, w: &World) -> bool {
        let Some(g) = self.target(w) else {
            return false;
        };
        self.path_i = 0;
        match w.planner.plan(w.robot, g) {
            Some(p) => {
                self.path = p;
                self.planned_for = w.map_version;
                true
            }
            None => {
                self.path.clear();
                self.planned_for = u32::MAX;
                false
            }
        }
    }

    fn path_length(&self, from: P2) -> f64 {
        let mut prev = from;
        let mut len = 0.0;
        for &p in &self.path[self.path_i..] {
            len += dist(prev, p);
            prev = p;
        }
        len
    }

    /// Starts the action (its first tick).
    fn begin(&mut self, w: &World) {
        self.start = w.time;
        let goal = match self.call {
            Call::MoveTo { target, .. } => goal_of(target, w),
            Call::Dock => w.layout.station("inspection"),
            Call::Recharge => w.layout.station("charging"),
            Call::Search => w.layout.waypoints.first().copied(),
            _ => return,
        };
        self.goal = goal;
        if self.call == Call::Search && goal.is_none() {
            // No waypoint: done if everything is known, else nothing to do.
            return;
        }
        if goal.is_none() || !self.plan(w) {
            if self.call == Call::Search {
                return; // the waypoint is skipped when driving
            }
            self.result = Some(Status::Failure);
            return;
        }
        self.length = self.path_length(w.robot);
    }

    /// One tick of the action: the first starts it and returns RUNNING;
    /// later ones return its outcome once reached.
    pub fn tick(&mut self, w: &mut World, dt: f64) -> Status {
        let _ = dt;
        if !self.call.is_action() {
            return if condition(&self.call, w) {
                Status::Success
            } else {
                Status::Failure
            };
        }
        self.ticks += 1;
        if self.ticks == 1 {
            self.begin(w);
            return Status::Running;
        }
        if w.shut_down && self.call != Call::ShutDown {
            // The drivers are off: nothing that moves succeeds.
            return Status::Failure;
        }
        if let Some(s) = self.result {
            return s;
        }
        let (dur, elapsed) = match self.call {
            Call::Pick { .. } | Call::Place { .. } => {
                (w.params.manipulation_s, w.time - self.start)
            }
            Call::TuckArm | Call::ShutDown => (w.params.arm_s, w.time - self.start),
            // Navigation: outcomes come from `drive`.
            _ => return Status::Running,
        };
        let reach = w.params.reach;
        let ok = match self.call {
            Call::Pick { object } => {
                w.objects[object].place != Place::Held
                    && w.held().is_none()
                    && dist(w.object_pos(object), w.robot) <= reach
            }
            Call::Place { object, at } => {
                w.objects[object].place == Place::Held
                    && dist(w.layout.stations[at].1, w.robot) <= reach
            }
            _ => true,
        };
        if !ok {
            return Status::Failure;
        }
        if let Some(f) = self.fault_at
            && elapsed + 1e-9 >= f * dur
        {
            return Status::Failure;
        }
        if elapsed + 1e-9 < dur {
            return Status::Running;
        }
        match self.call {
            Call::Pick { object } => {
                // The paper's Pick tucks the arm after the grasp.
                w.objects[object].place = Place::Held;
                w.arm_tucked = true;
            }
            Call::Place { object, at } => {
                let place = w.place_spot(object, at);
                let o = &mut w.objects[object];
                o.place = place;
                if let Place::At(p) | Place::Floor(p) = place {
                    o.belief = p;
                    o.found = true;
                }
                w.arm_tucked = false;
            }
            Call::TuckArm => w.arm_tucked = true,
            _ => w.shut_down = w.emergency || w.params.shut_down_latches,
        }
        w.progress += 1;
        Status::Success
    }

    /// Integrates the base's motion over one step for the action holding
    /// the base (called once per step, after the executor's tick); returns
    /// the outcome when it is reached in this step.
    pub fn drive(&mut self, w: &mut World, dt: f64) -> Option<Status> {
        if self.result.is_some() || !self.call.resources().contains(&Resource::Base) {
            return None;
        }
        if self.charging {
            if w.params.charge_per_s.is_finite() {
                w.battery = (w.battery + w.params.charge_per_s * dt).min(100.0);
            } else {
                w.battery = 100.0;
            }
            if w.battery >= 100.0 {
                self.charging = false;
                w.charging = false;
                w.progress += 1;
                return self.set(Status::Success);
            }
            return None;
        }
        let tol = w.params.at_tolerance;
        if w.params.follow_belief
            && let Call::MoveTo {
                target: Target::Object(o),
                ..
            } = self.call
            && let Some(b) = w.believed(o)
            && self.goal != Some(b)
        {
            // Re-targeted: replanned below.
            self.goal = Some(b);
            self.planned_for = u32::MAX;
        }
        let Some(goal) = self.target(w) else {
            // Search past its last waypoint.
            return self.settle(w);
        };
        if self.planned_for != w.map_version && !self.plan(w) {
            if self.call == Call::Search {
                self.waypoint += 1;
                self.planned_for = u32::MAX;
                return self.settle(w);
            }
            return self.set(Status::Failure);
        }
        let mut budget = w.drive_budget(self.speed(w), dt);
        let limit = self.fault_at.map(|f| f * self.length);
        if let Some(l) = limit {
            budget = budget.min((l - self.travelled).max(0.0));
        }
        let (from, odo) = (w.robot, w.odometer);
        while budget > 1e-12 && self.path_i < self.path.len() {
            let wp = self.path[self.path_i];
            let d = dist(w.robot, wp);
            if d <= budget {
                w.translate(wp);
                budget -= d;
                self.path_i += 1;
            } else {
                let f = budget / d;
                let r = w.robot;
                w.translate((r.0 + (wp.0 - r.0) * f, r.1 + (wp.1 - r.1) * f));
                budget = 0.0;
            }
        }
        let moved = w.odometer - odo;
        self.travelled += moved;
        if moved > 1e-9 {
            w.turn_toward((w.robot.1 - from.1).atan2(w.robot.0 - from.0), dt);
            self.stalled = 0.0;
        } else {
            self.stalled += dt;
        }
        // Arrived exactly when Robot-At would hold (the same tolerance).
        if dist(w.robot, goal) <= tol {
            match self.call {
                Call::Search => {
                    self.waypoint += 1;
                    self.planned_for = u32::MAX;
                    return None;
                }
                Call::Recharge => {
                    self.charging = true;
                    w.charging = true;
                    if !w.params.charge_per_s.is_finite() {
                        // The paper's instantaneous recharge.
                        return self.drive(w, dt);
                    }
                    return None;
                }
                Call::Dock => w.progress += 1,
                _ => {}
            }
            return self.set(Status::Success);
        }
        if limit.is_some_and(|l| self.travelled >= l - 1e-9) {
            // The injected fault: stopped short of the goal.
            return self.set(Status::Failure);
        }
        if self.stalled >= w.params.stall_s - 1e-9 {
            return self.set(Status::Failure);
        }
        None
    }

    /// Search's outcome after the camera has looked (end of step): SUCCESS
    /// once every object is found, FAILURE past the last waypoint.
    pub fn settle(&mut self, w: &World) -> Option<Status> {
        if self.call != Call::Search || self.result.is_some() || self.ticks == 0 {
            return None;
        }
        if w.objects.iter().all(|o| o.found) {
            return self.set(Status::Success);
        }
        if self.waypoint >= w.layout.waypoints.len() {
            return self.set(Status::Failure);
        }
        None
    }

    fn set(&mut self, s: Status) -> Option<Status> {
        self.result = Some(s);
        Some(s)
    }

    /// Leaves the world clean when the action is cancelled or aborted.
    pub fn cancel(&mut self, w: &mut World) {
        if self.charging {
            self.charging = false;
            w.charging = false;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::Object;
    use std::collections::BTreeMap;

    fn world() -> World {
        let cube = Object::new("cube2", Place::At((1.7, 0.0)), (1.7, 0.0), true);
        crate::world::paper_room_with(vec![cube])
    }

    fn call(skill: &str, args: &[(&str, &str)]) -> SkillCall {
        SkillCall {
            skill: skill.into(),
            args: args
                .iter()
                .map(|(k, v)| (k.to_string(), ArgValue::Str(v.to_string())))
                .collect::<BTreeMap<_, _>>(),
        }
    }

    /// One step as the robot makes it: the tick, the base's motion, the
    /// camera, then time.
    fn step(w: &mut World, r: &mut Running) -> Status {
        let s = r.tick(w, 0.1);
        if s == Status::Running {
            r.drive(w, 0.1);
            w.sense();
            r.settle(w);
        }
        w.advance(0.1);
        s
    }

    fn run(w: &mut World, c: Call, doomed: bool) -> (Status, usize) {
        let mut r = Running::new(c, doomed.then_some(0.5), 0);
        for n in 1..10_000 {
            let s = step(w, &mut r);
            if s != Status::Running {
                return (s, n);
            }
        }
        panic!("never finished");
    }

    #[test]
    fn resolve_reports_unknown_names_with_hints() {
        let w = world();
        let e = resolve(&call("Pick", &[("object", "cube3")]), &w).unwrap_err();
        assert_eq!(e.message, "unknown object `cube3`");
        assert_eq!(e.hint, "did you mean `cube2`?");
        let e = resolve(&call("Move-To", &[("target", "delivry")]), &w).unwrap_err();
        assert!(e.hint.contains("delivery"), "{e:?}");
    }

    #[test]
    fn fetch_and_deliver() {
        let mut w = world();
        let to_cube = resolve(&call("Move-To", &[("target", "cube2")]), &w).unwrap();
        let at_cube = resolve(&call("Robot-At", &[("target", "cube2")]), &w).unwrap();
        assert!(!condition(&at_cube, &w));
        assert_eq!(run(&mut w, to_cube, false).0, Status::Success);
        assert!(condition(&at_cube, &w));
        let pick = resolve(&call("Pick", &[("object", "cube2")]), &w).unwrap();
        assert_eq!(run(&mut w, pick, true).0, Status::Failure);
        let (s, n) = run(&mut w, pick, false);
        // 1.5 s: the start, then 15 steps of 0.1 s.
        assert_eq!((s, n), (Status::Success, 16));
        assert!(condition(&Call::InHand(0), &w));
        // The paper's Pick tucks the arm after the grasp.
        assert!(condition(&Call::ArmTucked, &w));
        let deliver = resolve(&call("Move-To", &[("target", "delivery")]), &w).unwrap();
        assert_eq!(run(&mut w, deliver, false).0, Status::Success);
        let place = resolve(
            &call("Place", &[("object", "cube2"), ("at", "delivery")]),
            &w,
        )
        .unwrap();
        assert_eq!(run(&mut w, place, false).0, Status::Success);
        assert!(condition(&Call::ObjectAt { object: 0, at: 0 }, &w));
        assert!(w.battery < 100.0);
    }

    /// `Battery-Level(min)` is `battery >= min`, charging or not; Recharge
    /// charges at `charge_per_s` and succeeds at a full battery.
    #[test]
    fn battery_level_is_at_least_min_and_charging_is_gradual() {
        let mut w = world();
        w.battery = 20.0;
        assert!(condition(&Call::BatteryLevel(20.0), &w));
        assert!(!condition(&Call::BatteryLevel(20.5), &w));
        w.params.charge_per_s = 10.0;
        w.battery = 10.0;
        let mut r = Running::new(Call::Recharge, None, 0);
        let mut charging_steps = 0;
        let mut last = 10.0;
        loop {
            let s = step(&mut w, &mut r);
            if w.charging {
                charging_steps += 1;
                assert!(w.battery - last <= 1.0 + 1e-9, "{} -> {}", last, w.battery);
                if w.battery >= 20.0 {
                    // The monitor does not hide the level while charging.
                    assert!(condition(&Call::BatteryLevel(20.0), &w));
                }
            }
            last = w.battery;
            if s != Status::Running {
                assert_eq!(s, Status::Success);
                break;
            }
        }
        assert!(w.battery > 99.9, "{}", w.battery);
        // About 90 % at 1 % a step.
        assert!((85..=95).contains(&charging_steps), "{charging_steps}");
        // The paper's instantaneous recharge: full the step it arrives.
        let mut w = world();
        w.battery = 10.0;
        assert_eq!(run(&mut w, Call::Recharge, false).0, Status::Success);
        // Full, less the 0.05 %/s of the last step.
        assert!(w.battery > 99.99, "{}", w.battery);
    }

    #[test]
    fn search_finds_every_cube() {
        let mut w = world();
        w.objects[0].found = false;
        assert!(!condition(&Call::Found, &w));
        assert_eq!(run(&mut w, Call::Search, false).0, Status::Success);
        assert!(condition(&Call::Found, &w));
    }
}
