//! The one skill library every executor uses (SPEC §6; the paper's fairness
//! rule, sec. V: BTs and FSMs call the same low-level skills). A binding from a
//! policy ([`crate::model::SkillCall`]) is resolved against the world once into a
//! [`Call`]; actions then run over many steps as [`Running`] instances that return
//! RUNNING, SUCCESS or FAILURE and are cancelled by dropping them (an action
//! leaves nothing half-done in the world: a cancelled Recharge stops charging).
//!
//! Conventions (documented in the README): an action that completes its work
//! in a step returns SUCCESS in that same step, and a navigation succeeds
//! exactly when Robot-At would hold (the same tolerance), so a condition on an
//! action's effect never becomes true while the action still runs;
//! the battery monitor reports "not ready" while the robot charges, so Recharge
//! runs to a full battery under a BT as under an FSM.

use super::world::{P2, Place, World, dist};
use crate::diagnostic::suggest;
use crate::model::{ArgValue, SkillCall};

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
    MoveTo { target: Target, safe: bool },
    Pick { object: usize },
    Place { object: usize, at: usize },
    Recharge,
    Dock,
    TuckArm,
    Search,
    ShutDown,
    RobotAt(Target),
    InHand(usize),
    ObjectAt { object: usize, at: usize },
    BatteryLevel(f64),
    ArmTucked,
    Found,
    NoEmergency,
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
                    ArgValue::Float(x) => crate::sim::scenario::show(*x),
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
        other => {
            return Err(Unresolved {
                message: format!("unknown skill `{other}`"),
                hint: suggest(
                    other,
                    crate::model::skill::SKILLS.iter().map(|(n, _, _)| *n),
                ),
            });
        }
    })
}

/// The pose a target stands for (`None`: an object not found yet).
fn goal_of(t: Target, w: &World) -> Option<P2> {
    match t {
        Target::Station(s) => Some(w.layout.stations[s].1),
        Target::Object(o) => w.objects[o].found.then(|| w.object_pos(o)),
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
        Call::ObjectAt { object, at } => match w.objects[object].place {
            Place::At(p) => near(p, w.layout.stations[at].1, w.params.station_radius),
            Place::Held => false,
        },
        Call::BatteryLevel(min) => !w.charging && w.battery > min,
        Call::ArmTucked => w.arm_tucked,
        Call::Found => w.objects.iter().all(|o| o.found),
        Call::NoEmergency => !w.emergency,
        _ => false,
    }
}

/// A running action: its binding and its progress.
#[derive(Debug, Clone)]
pub struct Running {
    pub call: Call,
    /// Fails when it would succeed (an injected fault).
    pub doomed: bool,
    /// Index of its record in the run's list of executed skills.
    pub record: usize,
    path: Vec<P2>,
    path_i: usize,
    planned_for: Option<(P2, u32)>,
    steps: u32,
    waypoint: usize,
}

impl Running {
    pub fn new(call: Call, doomed: bool, record: usize) -> Self {
        Running {
            call,
            doomed,
            record,
            path: Vec::new(),
            path_i: 0,
            planned_for: None,
            steps: 0,
            waypoint: 0,
        }
    }

    fn finish(&self, ok: bool) -> Status {
        if ok && !self.doomed {
            Status::Success
        } else {
            Status::Failure
        }
    }

    /// Drives toward `goal` along a planned path; `Some(arrived)` or `None`
    /// when no path exists.
    fn navigate(&mut self, w: &mut World, goal: P2, speed: f64, dt: f64) -> Option<bool> {
        let tol = w.params.at_tolerance;
        if dist(w.robot, goal) <= tol {
            return Some(true);
        }
        if self.planned_for != Some((goal, w.map_version)) {
            self.path = w.planner.plan(w.robot, goal)?;
            self.path_i = 0;
            self.planned_for = Some((goal, w.map_version));
        }
        let mut budget = speed * dt;
        while budget > 1e-12 && self.path_i < self.path.len() {
            let wp = self.path[self.path_i];
            let d = dist(w.robot, wp);
            if d <= budget {
                w.drive_toward(wp, d / dt, dt);
                budget -= d;
                self.path_i += 1;
            } else {
                w.drive_toward(wp, budget / dt, dt);
                budget = 0.0;
            }
        }
        Some(self.path_i >= self.path.len() || dist(w.robot, goal) <= tol)
    }

    /// One step of a timed manipulation: `Some(RUNNING)` until `secs` have
    /// passed, then `Some(FAILURE)` for an injected fault, or `None` when the
    /// action may take effect.
    fn work(&mut self, secs: f64, dt: f64) -> Option<Status> {
        self.steps += 1;
        if (self.steps as f64) * dt < secs - 1e-9 {
            Some(Status::Running)
        } else if self.doomed {
            Some(Status::Failure)
        } else {
            None
        }
    }

    /// Performs one step of the action.
    pub fn tick(&mut self, w: &mut World, dt: f64) -> Status {
        let speed = w.params.max_speed;
        let tol = w.params.at_tolerance;
        match self.call {
            Call::MoveTo { target, safe } => {
                let Some(goal) = goal_of(target, w) else {
                    return Status::Failure;
                };
                let v = if safe { speed * 0.5 } else { speed };
                match self.navigate(w, goal, v, dt) {
                    None => Status::Failure,
                    Some(true) => self.finish(true),
                    Some(false) => Status::Running,
                }
            }
            Call::Dock => {
                let goal = w.layout.station("inspection").unwrap_or(w.robot);
                match self.navigate(w, goal, speed * 0.5, dt) {
                    None => Status::Failure,
                    Some(true) => {
                        w.progress += 1;
                        self.finish(true)
                    }
                    Some(false) => Status::Running,
                }
            }
            Call::Recharge => {
                let goal = w.layout.station("charging").unwrap_or(w.robot);
                if !w.charging {
                    match self.navigate(w, goal, speed, dt) {
                        None => return Status::Failure,
                        Some(false) => return Status::Running,
                        Some(true) => w.charging = true,
                    }
                    return Status::Running;
                }
                w.battery = (w.battery + w.params.charge_per_s * dt).min(100.0);
                if w.battery >= 100.0 {
                    w.charging = false;
                    w.progress += 1;
                    self.finish(true)
                } else {
                    Status::Running
                }
            }
            Call::Pick { object } => {
                let o = &w.objects[object];
                let reachable = o.found
                    && o.place != Place::Held
                    && w.held().is_none()
                    && dist(w.object_pos(object), w.robot) <= tol;
                if !reachable {
                    return Status::Failure;
                }
                if let Some(st) = self.work(w.params.manipulation_s, dt) {
                    return st;
                }
                w.objects[object].place = Place::Held;
                w.arm_tucked = false;
                w.progress += 1;
                Status::Success
            }
            Call::Place { object, at } => {
                let spot = w.layout.stations[at].1;
                if w.objects[object].place != Place::Held || dist(spot, w.robot) > tol {
                    return Status::Failure;
                }
                if let Some(st) = self.work(w.params.manipulation_s, dt) {
                    return st;
                }
                w.objects[object].place = Place::At(spot);
                w.progress += 1;
                Status::Success
            }
            Call::TuckArm | Call::ShutDown => {
                if let Some(st) = self.work(w.params.arm_s, dt) {
                    return st;
                }
                if self.call == Call::TuckArm {
                    w.arm_tucked = true;
                } else {
                    w.shut_down = true;
                }
                w.progress += 1;
                Status::Success
            }
            Call::Search => {
                if w.look() > 0 {
                    w.progress += 1;
                }
                if w.objects.iter().all(|o| o.found) {
                    return self.finish(true);
                }
                let Some(&wp) = w.layout.waypoints.get(self.waypoint) else {
                    return Status::Failure;
                };
                match self.navigate(w, wp, speed, dt) {
                    None => {
                        self.waypoint += 1;
                        Status::Running
                    }
                    Some(true) => {
                        self.waypoint += 1;
                        if w.look() > 0 {
                            w.progress += 1;
                        }
                        if w.objects.iter().all(|o| o.found) {
                            self.finish(true)
                        } else if self.waypoint >= w.layout.waypoints.len() {
                            Status::Failure
                        } else {
                            Status::Running
                        }
                    }
                    Some(false) => Status::Running,
                }
            }
            _ => {
                if condition(&self.call, w) {
                    Status::Success
                } else {
                    Status::Failure
                }
            }
        }
    }

    /// Leaves the world clean when the action is cancelled.
    pub fn cancel(&mut self, w: &mut World) {
        if self.call == Call::Recharge {
            w.charging = false;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sim::world::{Layout, Object, Params};
    use std::collections::BTreeMap;

    fn world() -> World {
        let cube = Object {
            name: "cube2".into(),
            place: Place::At((1.7, 0.0)),
            found: true,
        };
        World::new(
            Layout::paper_room(),
            Params::default(),
            (-2.0, -2.2),
            vec![cube],
        )
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

    fn run(w: &mut World, c: Call, doomed: bool) -> (Status, usize) {
        let mut r = Running::new(c, doomed, 0);
        for n in 1..10_000 {
            let s = r.tick(w, 0.1);
            w.advance(0.1);
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
        assert_eq!((s, n), (Status::Success, 15));
        assert!(condition(&Call::InHand(0), &w));
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

    #[test]
    fn recharge_reports_not_ready_until_full() {
        let mut w = world();
        w.battery = 10.0;
        let mut r = Running::new(Call::Recharge, false, 0);
        let mut saw_charging = false;
        loop {
            let s = r.tick(&mut w, 0.1);
            w.advance(0.1);
            if w.charging {
                saw_charging = true;
                assert!(!condition(&Call::BatteryLevel(20.0), &w));
            }
            if s != Status::Running {
                assert_eq!(s, Status::Success);
                break;
            }
        }
        assert!(saw_charging);
        assert!(w.battery > 99.9, "{}", w.battery);
        assert!(condition(&Call::BatteryLevel(20.0), &w));
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
