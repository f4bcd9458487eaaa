//! The planar world of the simulator (SPEC §6), modelled on the room of the
//! paper's Experiments 1-5 (sec. V, Fig. 17): walls, tables as rectangular
//! obstacles, named station poses (delivery (0.5, 2.1), charging (0.5, -2.0),
//! inspection (-1.0, -1.0), the fetch tables), five search waypoints and cubes
//! on the tables. The robot is a holonomic disc with a speed limit, a gripper
//! holding at most one object, an arm that is tucked or not, a camera with a
//! range, and a battery that drains with distance and time.
//!
//! Navigation plans on an occupancy grid (obstacles inflated by the robot's
//! radius) with A* (Hart, Nilsson and Raphael 1968) and shortens the grid path
//! by line-of-sight checks against the exact rectangles ("string pulling").
//!
//! An object's position is the pose from which the robot grasps it (the near
//! edge of its table). An object lies on a surface (a table or box within
//! [`SURFACE_REACH`] of that pose), on the floor (dropped) or in the gripper;
//! the robot acts on its *believed* pose, which the camera updates when the
//! object is within range and in line of sight (tables, boxes and walls
//! occlude: [`Planner::visible`]). docs/simulator-model.md states the model.

use std::collections::HashMap;
use std::sync::Arc;

pub use super::planner::Planner;

/// A point or pose position in metres.
pub type P2 = (f64, f64);

pub fn dist(a: P2, b: P2) -> f64 {
    ((a.0 - b.0).powi(2) + (a.1 - b.1).powi(2)).sqrt()
}

/// An axis-aligned rectangle `[x0, y0, x1, y1]` (x0 < x1, y0 < y1).
#[derive(Debug, Clone, PartialEq)]
pub struct Rect {
    pub name: String,
    pub x0: f64,
    pub y0: f64,
    pub x1: f64,
    pub y1: f64,
}

impl Rect {
    pub fn new(name: &str, x0: f64, y0: f64, x1: f64, y1: f64) -> Self {
        Rect {
            name: name.into(),
            x0: x0.min(x1),
            y0: y0.min(y1),
            x1: x0.max(x1),
            y1: y0.max(y1),
        }
    }

    pub(super) fn inflated(&self, r: f64) -> Rect {
        Rect {
            name: self.name.clone(),
            x0: self.x0 - r,
            y0: self.y0 - r,
            x1: self.x1 + r,
            y1: self.y1 + r,
        }
    }

    pub(super) fn contains(&self, p: P2) -> bool {
        p.0 > self.x0 && p.0 < self.x1 && p.1 > self.y0 && p.1 < self.y1
    }

    /// Distance from `p` to the closed rectangle (0 inside).
    pub fn distance(&self, p: P2) -> f64 {
        let dx = (self.x0 - p.0).max(p.0 - self.x1).max(0.0);
        let dy = (self.y0 - p.1).max(p.1 - self.y1).max(0.0);
        (dx * dx + dy * dy).sqrt()
    }

    /// Does the rectangle overlap the open box `[x0, x1] x [y0, y1]`?
    pub(super) fn overlaps(&self, x0: f64, y0: f64, x1: f64, y1: f64) -> bool {
        self.x0 < x1 && x0 < self.x1 && self.y0 < y1 && y0 < self.y1
    }

    /// Does the segment a-b pass through the open rectangle (slab method)?
    pub(super) fn hits_segment(&self, a: P2, b: P2) -> bool {
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        for (p, d, lo, hi) in [(a.0, dx, self.x0, self.x1), (a.1, dy, self.y0, self.y1)] {
            if d.abs() < 1e-12 {
                if p <= lo || p >= hi {
                    return false;
                }
            } else {
                let (mut ta, mut tb) = ((lo - p) / d, (hi - p) / d);
                if ta > tb {
                    std::mem::swap(&mut ta, &mut tb);
                }
                t0 = t0.max(ta);
                t1 = t1.min(tb);
                if t0 >= t1 {
                    return false;
                }
            }
        }
        t1 - t0 > 1e-9
    }
}

/// Where an object is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Place {
    /// On a surface (a table or box), grasped from this pose.
    At(P2),
    /// On the floor where it fell: never "at" a station.
    Floor(P2),
    /// In the robot's gripper.
    Held,
}

#[derive(Debug, Clone, PartialEq)]
pub struct Object {
    pub name: String,
    pub place: Place,
    /// Seen by the camera (or known from the start).
    pub found: bool,
    /// Where the robot believes it is (meaningful when `found`): updated only
    /// when the camera sees it ([`World::sense`]).
    pub belief: P2,
}

impl Object {
    /// An object at `p`, known there (`found`) or not yet seen.
    pub fn new(name: &str, place: Place, p: P2, found: bool) -> Self {
        Object {
            name: name.into(),
            place,
            found,
            belief: p,
        }
    }
}

/// How far from a pose a table or box still counts as the surface in front
/// of it (beyond the robot's radius), m: the paper room's stations stand
/// 0.3 m from their tables.
pub const SURFACE_REACH: f64 = 0.15;
/// Spacing of the places an object is put on a surface, m (5 cm cubes with
/// 2 cm between them); Place uses the first free one, centre first.
pub const SLOT_SPACING: f64 = 0.07;
/// Places per surface (centre, then alternately right and left).
pub const SLOTS: usize = 9;

/// Physical constants of a world (defaults: the paper's room and a TIAGo-like
/// base).
#[derive(Debug, Clone, PartialEq)]
pub struct Params {
    /// Robot radius (obstacles are inflated by it), m.
    pub robot_radius: f64,
    /// Top speed of Move-To, m/s (Safe-Move-To and Dock go at half of it).
    pub max_speed: f64,
    /// Top turn rate of the base, rad/s (the holonomic base translates in
    /// any direction; its heading turns toward the motion at most this fast).
    pub max_turn_rate: f64,
    /// Battery drain per metre driven, percent.
    pub drain_per_m: f64,
    /// Battery drain per second, percent.
    pub drain_per_s: f64,
    /// Charging rate at the charging station, percent per second;
    /// `f64::INFINITY` (the default, the paper's assumption) fills the
    /// battery the step the robot arrives.
    pub charge_per_s: f64,
    /// Battery level at or below which the "battery low" event is logged.
    pub low_battery: f64,
    /// Camera range, m (the camera sees every step, not only in Search).
    pub camera_range: f64,
    /// Distance within which an object on a surface counts as at a station
    /// (Object-At), m.
    pub object_tolerance: f64,
    /// Distance within which the robot counts as at a target, m.
    pub at_tolerance: f64,
    /// Distance from the robot within which Pick grasps an object and Place
    /// reaches its station, m.
    pub reach: f64,
    /// A navigation that has not moved for this long aborts, s (Nav2's
    /// progress checker).
    pub stall_s: f64,
    /// A Move-To toward an object re-targets when the robot's belief about
    /// the object changes (a skill that tracks its marker); default `false`:
    /// the goal is the believed pose when the action started, as a
    /// navigation action server's goal.
    pub follow_belief: bool,
    /// The robot knows where an object it held fell: its believed pose is
    /// set there at once (default `true`). With `false` it stays where the
    /// object was last seen until the camera sees it, and a policy that
    /// reacts to the drop in the same step (a BT's In-Hand condition)
    /// drives back to that stale pose: a modelling choice that favoured
    /// the policy reacting later (issue 31).
    pub drop_sensed: bool,
    /// A Shut-Down that completes when no emergency is in force (it was
    /// cleared while the arm folded) leaves the robot down for the rest of
    /// the run (`true`), or has no lasting effect, the shut-down lasting as
    /// long as the emergency it answered (`false`, the default): then how
    /// the robot resumes follows each policy's structure (a BT re-checks
    /// its condition, the FSM of Fig. 9b leaves its Shut Down state), where
    /// a latched shut-down failed every policy whose Shut-Down outlasted
    /// the emergency (issue 31).
    pub shut_down_latches: bool,
    /// Duration of Pick (grasp and tuck) and Place, s.
    pub manipulation_s: f64,
    /// Duration of Tuck-Arm and Shut-Down, s.
    pub arm_s: f64,
    /// Planner grid resolution, m.
    pub grid: f64,
}

impl Default for Params {
    fn default() -> Self {
        Params {
            robot_radius: 0.2,
            max_speed: 0.5,
            max_turn_rate: 1.0,
            drain_per_m: 1.0,
            drain_per_s: 0.05,
            charge_per_s: f64::INFINITY,
            low_battery: 20.0,
            camera_range: 1.6,
            object_tolerance: 0.15,
            at_tolerance: 0.02,
            reach: 0.1,
            stall_s: 10.0,
            follow_belief: false,
            drop_sensed: true,
            shut_down_latches: false,
            manipulation_s: 1.5,
            arm_s: 0.5,
            grid: 0.1,
        }
    }
}

/// The static layout: room, obstacles, stations, waypoints.
#[derive(Debug, Clone, PartialEq)]
pub struct Layout {
    /// The room's inner walls `[x0, y0, x1, y1]`.
    pub room: Rect,
    pub obstacles: Vec<Rect>,
    /// Named poses, in order (delivery, charging, inspection, tables...).
    /// Add or move one with [`Layout::set_station`], which keeps the index
    /// by name.
    pub stations: Vec<(String, P2)>,
    /// Search waypoints, visited in order.
    pub waypoints: Vec<P2>,
    /// Index of each station by name (lookups in constant time: a scenario
    /// may define many stations and a policy many bindings).
    station_ix: HashMap<String, usize>,
}

impl Layout {
    /// The paper's room (SPEC §6): a 6 m x 6 m room with a central table, two
    /// fetch tables, the delivery table, the charger and the inspection table.
    pub fn paper_room() -> Self {
        let mut l = Layout {
            room: Rect::new("room", -3.0, -3.0, 3.0, 3.0),
            obstacles: vec![
                Rect::new("central table", -0.8, 0.4, 0.8, 1.0),
                Rect::new("east table", 2.0, -1.2, 2.6, 1.0),
                Rect::new("west table", -2.6, 0.2, -2.0, 2.0),
                Rect::new("delivery table", 0.1, 2.4, 0.9, 2.9),
                Rect::new("charger", 0.3, -2.9, 0.7, -2.4),
                Rect::new("inspection table", -1.7, -1.4, -1.3, -0.6),
            ],
            stations: vec![
                ("delivery".into(), (0.5, 2.1)),
                ("charging".into(), (0.5, -2.0)),
                ("inspection".into(), (-1.0, -1.0)),
                ("east-table".into(), (1.7, 0.0)),
                ("west-table".into(), (-1.7, 1.1)),
                ("central-table".into(), (0.0, 0.1)),
                ("start".into(), (-2.0, -2.2)),
            ],
            waypoints: vec![
                (-1.0, -2.0),
                (1.4, -1.6),
                (1.2, 1.4),
                (-0.9, 1.6),
                (-1.2, 0.0),
            ],
            station_ix: HashMap::new(),
        };
        l.station_ix = (l.stations.iter().enumerate())
            .map(|(i, (n, _))| (n.clone(), i))
            .collect();
        l
    }

    /// The index of the station `name` in [`Layout::stations`].
    pub fn station_index(&self, name: &str) -> Option<usize> {
        self.station_ix.get(name).copied()
    }

    pub fn station(&self, name: &str) -> Option<P2> {
        self.station_index(name).map(|i| self.stations[i].1)
    }

    /// Moves the station `name` to `p`, or adds it (after the others).
    pub fn set_station(&mut self, name: &str, p: P2) {
        match self.station_ix.get(name) {
            Some(&i) => self.stations[i].1 = p,
            None => {
                self.station_ix
                    .insert(name.to_string(), self.stations.len());
                self.stations.push((name.to_string(), p));
            }
        }
    }

    /// The table or box in front of the pose `p` (the nearest obstacle within
    /// `radius + SURFACE_REACH`), on which an object at `p` lies.
    pub fn surface_near(&self, p: P2, radius: f64) -> Option<&Rect> {
        let mut best: Option<(&Rect, f64)> = None;
        for o in &self.obstacles {
            let d = o.distance(p);
            if d <= radius + SURFACE_REACH + 1e-9 && best.is_none_or(|(_, b)| d < b) {
                best = Some((o, d));
            }
        }
        best.map(|(o, _)| o)
    }

    /// Is a robot centred at `p` clear of walls and obstacles? `Err` names what
    /// it collides with.
    pub fn check_free(&self, p: P2, radius: f64) -> Result<(), String> {
        let r = &self.room;
        // NaN compares false with everything: refuse it before the walls.
        if !(p.0.is_finite() && p.1.is_finite()) {
            return Err("no position (not a finite number)".into());
        }
        if p.0 - radius < r.x0 || p.0 + radius > r.x1 || p.1 - radius < r.y0 || p.1 + radius > r.y1
        {
            return Err("a wall".into());
        }
        match self
            .obstacles
            .iter()
            .find(|o| o.inflated(radius).contains(p))
        {
            Some(o) => Err(format!("the {}", o.name)),
            None => Ok(()),
        }
    }
}

/// The dynamic state of a world plus its layout.
#[derive(Debug, Clone)]
pub struct World {
    pub params: Params,
    pub layout: Arc<Layout>,
    pub planner: Arc<Planner>,
    /// Bumped when an obstacle is added (running navigations replan).
    pub map_version: u32,
    /// Simulated time, s.
    pub time: f64,
    pub robot: P2,
    pub yaw: f64,
    /// Percent, 0..=100.
    pub battery: f64,
    /// `true` while the robot is on the charger and charging is not complete:
    /// the battery monitor reports "not ready" until the charge completes.
    pub charging: bool,
    pub arm_tucked: bool,
    pub emergency: bool,
    pub shut_down: bool,
    pub objects: Vec<Object>,
    /// Distance driven, m.
    pub odometer: f64,
    /// Incremented on every change of the discrete world state that a task
    /// step makes (pick, place, object found, charge complete, dock, a
    /// disturbance); chattering is switching actions without it changing.
    pub progress: u64,
    /// Index of each object by name (objects are never added or renamed).
    object_ix: Arc<HashMap<String, usize>>,
}

impl World {
    pub fn new(layout: Layout, params: Params, robot: P2, objects: Vec<Object>) -> Self {
        let planner = Arc::new(Planner::new(&layout, &params));
        let mut ix = HashMap::new();
        for (i, o) in objects.iter().enumerate() {
            ix.entry(o.name.clone()).or_insert(i);
        }
        let object_ix = Arc::new(ix);
        World {
            params,
            layout: Arc::new(layout),
            planner,
            map_version: 0,
            time: 0.0,
            robot,
            yaw: 0.0,
            battery: 100.0,
            charging: false,
            arm_tucked: true,
            emergency: false,
            shut_down: false,
            objects,
            odometer: 0.0,
            progress: 0,
            object_ix,
        }
    }

    pub fn object_index(&self, name: &str) -> Option<usize> {
        self.object_ix.get(name).copied()
    }

    pub fn held(&self) -> Option<usize> {
        self.objects.iter().position(|o| o.place == Place::Held)
    }

    /// Where an object is (the robot's position when held).
    pub fn object_pos(&self, i: usize) -> P2 {
        match self.objects[i].place {
            Place::At(p) | Place::Floor(p) => p,
            Place::Held => self.robot,
        }
    }

    /// Where the robot believes an object is: in its gripper, where the
    /// camera last saw it, or unknown (`None`: never seen).
    pub fn believed(&self, i: usize) -> Option<P2> {
        let o = &self.objects[i];
        match o.place {
            Place::Held => Some(self.robot),
            _ => o.found.then_some(o.belief),
        }
    }

    /// Where an object put down at `p` comes to rest: on the surface in
    /// front of `p`, or on the floor when there is none.
    pub fn rest_at(&self, p: P2) -> Place {
        match self.layout.surface_near(p, self.params.robot_radius) {
            Some(_) => Place::At(p),
            None => Place::Floor(p),
        }
    }

    /// Where Place puts `object` at station `at`: the first free place on
    /// the station's surface, along the table's edge (centre first, then
    /// alternately either side, [`SLOT_SPACING`] apart), or the floor at the
    /// robot's feet when the station has no surface. O(objects) per slot.
    pub fn place_spot(&self, object: usize, at: usize) -> Place {
        let s = self.layout.stations[at].1;
        let Some(r) = self.layout.surface_near(s, self.params.robot_radius) else {
            return Place::Floor(self.robot);
        };
        // The edge faces the station: along x when the table is above or
        // below it, along y otherwise.
        let (dx, dy) = (
            (r.x0 - s.0).max(s.0 - r.x1).max(0.0),
            (r.y0 - s.1).max(s.1 - r.y1).max(0.0),
        );
        let dir = if dy >= dx { (1.0, 0.0) } else { (0.0, 1.0) };
        let mut spot = s;
        for k in 0..SLOTS {
            let m = k.div_ceil(2) as f64 * if k % 2 == 1 { 1.0 } else { -1.0 };
            spot = (
                s.0 + dir.0 * m * SLOT_SPACING,
                s.1 + dir.1 * m * SLOT_SPACING,
            );
            let taken = self.objects.iter().enumerate().any(|(i, o)| {
                i != object && matches!(o.place, Place::At(q) if dist(q, spot) < SLOT_SPACING / 2.0)
            });
            if !taken {
                break;
            }
        }
        Place::At(spot)
    }

    /// Adds an obstacle (a blocked path) and rebuilds the planner.
    pub fn block(&mut self, r: Rect) {
        let mut layout = (*self.layout).clone();
        self.planner = Arc::new(self.planner.with_obstacle(&r, self.params.robot_radius));
        layout.obstacles.push(r);
        self.layout = Arc::new(layout);
        self.map_version += 1;
    }

    /// How far the base may drive this step at `speed`: nothing while shut
    /// down, and no further than the battery lasts.
    pub fn drive_budget(&self, speed: f64, dt: f64) -> f64 {
        if self.shut_down || self.battery <= 0.0 {
            return 0.0;
        }
        let mut b = speed.min(self.params.max_speed) * dt;
        if self.params.drain_per_m > 0.0 {
            b = b.min(self.battery / self.params.drain_per_m);
        }
        b.max(0.0)
    }

    /// Moves the robot straight to `p` (the caller keeps within the
    /// step's budget), draining the battery.
    pub fn translate(&mut self, p: P2) {
        let d = dist(self.robot, p);
        self.robot = p;
        self.odometer += d;
        self.battery = (self.battery - d * self.params.drain_per_m).max(0.0);
    }

    /// Turns the heading toward `heading` by at most `max_turn_rate * dt`.
    pub fn turn_toward(&mut self, heading: f64, dt: f64) {
        use std::f64::consts::{PI, TAU};
        let mut d = (heading - self.yaw) % TAU;
        if d > PI {
            d -= TAU;
        } else if d < -PI {
            d += TAU;
        }
        let m = self.params.max_turn_rate * dt;
        self.yaw += d.clamp(-m, m);
        if self.yaw > PI {
            self.yaw -= TAU;
        } else if self.yaw < -PI {
            self.yaw += TAU;
        }
    }

    /// Time passes: the clock advances and the battery drains (not while
    /// charging).
    pub fn advance(&mut self, dt: f64) {
        self.time += dt;
        if !self.charging {
            self.battery = (self.battery - self.params.drain_per_s * dt).max(0.0);
        }
    }

    /// The station whose pose the robot is at, if any.
    pub fn robot_station(&self) -> Option<&str> {
        self.layout
            .stations
            .iter()
            .find(|(_, p)| dist(*p, self.robot) <= self.params.at_tolerance)
            .map(|(n, _)| n.as_str())
    }

    /// Object-At: the object lies on a surface within
    /// [`Params::object_tolerance`] of the station (on the floor or in the
    /// gripper it is at no station).
    pub fn object_at(&self, i: usize, at: usize) -> bool {
        let s = self.layout.stations[at].1;
        let r = self.params.object_tolerance;
        match self.objects[i].place {
            Place::At(p) => (p.0 - s.0).powi(2) + (p.1 - s.1).powi(2) <= r * r,
            _ => false,
        }
    }

    /// The station an object is at (Object-At holds), if any.
    pub fn object_station(&self, i: usize) -> Option<&str> {
        (0..self.layout.stations.len())
            .find(|&s| self.object_at(i, s))
            .map(|s| self.layout.stations[s].0.as_str())
    }

    /// The camera: every object within [`Params::camera_range`] and in line
    /// of sight is seen, its believed pose set to where it is. Returns how
    /// many beliefs changed (newly found or seen elsewhere). O(objects x
    /// range / grid) per call.
    pub fn sense(&mut self) -> usize {
        self.sense_noting(None)
    }

    /// [`World::sense`], pushing the index of each object whose belief
    /// changed onto `changed` when given (the trace's `belief` events).
    pub fn sense_noting(&mut self, mut noted: Option<&mut Vec<usize>>) -> usize {
        let (r, range) = (self.robot, self.params.camera_range);
        let mut changed = 0;
        for i in 0..self.objects.len() {
            let p = match self.objects[i].place {
                Place::At(p) | Place::Floor(p) => p,
                Place::Held => continue,
            };
            let o = &self.objects[i];
            if o.found && o.belief == p {
                continue;
            }
            if dist(p, r) <= range && self.planner.visible(r, p) {
                let o = &mut self.objects[i];
                o.found = true;
                o.belief = p;
                changed += 1;
                if let Some(n) = noted.as_mut() {
                    n.push(i);
                }
            }
        }
        changed
    }
}

/// The paper's room with the robot at the start and `objects` (tests).
#[cfg(test)]
pub fn paper_room_with(objects: Vec<Object>) -> World {
    World::new(
        Layout::paper_room(),
        Params::default(),
        (-2.0, -2.2),
        objects,
    )
}

/// The paper's room with the robot at the start and no objects (tests).
#[cfg(test)]
pub fn empty_paper_room() -> World {
    paper_room_with(vec![])
}

#[cfg(test)]
mod tests {
    use super::*;

    fn world() -> World {
        empty_paper_room()
    }

    #[test]
    fn stations_of_the_paper_room_are_free() {
        let l = Layout::paper_room();
        for (n, p) in &l.stations {
            assert!(l.check_free(*p, 0.2).is_ok(), "{n}");
        }
        for p in &l.waypoints {
            assert!(l.check_free(*p, 0.2).is_ok(), "{p:?}");
        }
        assert_eq!(l.station("delivery"), Some((0.5, 2.1)));
        assert!(l.check_free((3.5, 0.0), 0.2).unwrap_err().contains("wall"));
        assert!(
            l.check_free((0.0, 0.7), 0.2)
                .unwrap_err()
                .contains("central")
        );
    }

    /// NaN compared false with the walls and obstacles, so it passed.
    #[test]
    fn a_position_that_is_not_a_number_is_not_free() {
        let l = Layout::paper_room();
        for p in [
            (f64::NAN, 0.0),
            (0.0, f64::NAN),
            (f64::INFINITY, 0.0),
            (0.0, f64::NEG_INFINITY),
        ] {
            assert!(l.check_free(p, 0.2).is_err(), "{p:?}");
        }
    }

    #[test]
    fn driving_drains_the_battery_and_an_empty_one_stops_the_base() {
        let mut w = world();
        let budget = w.drive_budget(0.5, 0.1);
        assert!((budget - 0.05).abs() < 1e-12);
        w.translate((-1.0, -2.2));
        assert!((w.odometer - 1.0).abs() < 1e-9);
        assert!((w.battery - 99.0).abs() < 1e-9);
        // The speed limit holds whatever a skill asks.
        assert!((w.drive_budget(5.0, 0.1) - 0.05).abs() < 1e-12);
        w.battery = 0.01;
        assert!((w.drive_budget(0.5, 0.1) - 0.01).abs() < 1e-12);
        w.battery = 0.0;
        assert_eq!(w.drive_budget(0.5, 0.1), 0.0);
        w.battery = 50.0;
        w.shut_down = true;
        assert_eq!(w.drive_budget(0.5, 0.1), 0.0);
    }

    #[test]
    fn the_heading_turns_at_most_max_turn_rate() {
        let mut w = world();
        w.yaw = 0.0;
        w.turn_toward(3.0, 0.1);
        assert!((w.yaw - 0.1).abs() < 1e-12);
        // The short way round, wrapped to (-pi, pi].
        w.yaw = 3.1;
        w.turn_toward(-3.1, 0.1);
        assert!(w.yaw > 3.1 || w.yaw < -3.0, "{}", w.yaw);
        assert!(w.yaw.abs() <= std::f64::consts::PI);
    }

    /// The camera updates beliefs within range and in sight only.
    #[test]
    fn the_camera_sees_within_range_and_line_of_sight() {
        let far = Object::new("far", Place::At((1.7, 0.0)), (1.7, 0.0), false);
        let behind = Object::new("behind", Place::At((0.0, 1.3)), (0.0, 1.3), false);
        let near = Object::new("near", Place::At((0.0, -0.5)), (0.0, -0.5), false);
        let mut w = World::new(
            Layout::paper_room(),
            Params::default(),
            (0.0, 0.1),
            vec![far, behind, near],
        );
        assert_eq!(w.sense(), 1);
        assert!(!w.objects[0].found, "1.7 m away: beyond the camera's 1.6 m");
        assert!(!w.objects[1].found, "behind the central table");
        assert!(w.objects[2].found);
        // Moved while seen: the belief follows; moved out of sight: it stays.
        w.objects[2].place = Place::At((0.3, -0.5));
        assert_eq!(w.sense(), 1);
        assert_eq!(w.objects[2].belief, (0.3, -0.5));
        w.objects[2].place = Place::At((0.0, 1.3));
        assert_eq!(w.sense(), 0);
        assert_eq!(w.believed(2), Some((0.3, -0.5)));
    }

    /// Place puts objects side by side on the station's surface, never two
    /// on one spot, all within Object-At's tolerance for five of them; a
    /// station with no table in front of it gets them on the floor.
    #[test]
    fn placed_objects_lie_side_by_side_on_the_surface() {
        let objs = (0..6)
            .map(|i| Object::new(&format!("c{i}"), Place::Held, (0.0, 0.0), true))
            .collect();
        let mut w = World::new(Layout::paper_room(), Params::default(), (0.5, 2.1), objs);
        let delivery = w.layout.station_index("delivery").unwrap();
        let mut spots: Vec<P2> = Vec::new();
        for i in 0..6 {
            let Place::At(p) = w.place_spot(i, delivery) else {
                panic!("the delivery table is a surface")
            };
            assert!(
                spots.iter().all(|q| dist(*q, p) >= SLOT_SPACING - 1e-9),
                "{p:?}"
            );
            assert!((p.1 - 2.1).abs() < 1e-9, "along the table's edge: {p:?}");
            w.objects[i].place = Place::At(p);
            spots.push(p);
            assert_eq!(w.object_at(i, delivery), i < 5, "{i}");
        }
        let start = w.layout.station_index("start").unwrap();
        assert!(matches!(w.place_spot(0, start), Place::Floor(_)));
        // A cube on the floor is at no station, even on the station's spot.
        w.objects[0].place = Place::Floor((0.5, 2.1));
        assert!(!w.object_at(0, delivery));
    }
}
