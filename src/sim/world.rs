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

use std::collections::{BinaryHeap, HashMap};
use std::sync::Arc;

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

    fn inflated(&self, r: f64) -> Rect {
        Rect {
            name: self.name.clone(),
            x0: self.x0 - r,
            y0: self.y0 - r,
            x1: self.x1 + r,
            y1: self.y1 + r,
        }
    }

    fn contains(&self, p: P2) -> bool {
        p.0 > self.x0 && p.0 < self.x1 && p.1 > self.y0 && p.1 < self.y1
    }

    /// Distance from `p` to the closed rectangle (0 inside).
    pub fn distance(&self, p: P2) -> f64 {
        let dx = (self.x0 - p.0).max(p.0 - self.x1).max(0.0);
        let dy = (self.y0 - p.1).max(p.1 - self.y1).max(0.0);
        (dx * dx + dy * dy).sqrt()
    }

    /// Does the rectangle overlap the open box `[x0, x1] x [y0, y1]`?
    fn overlaps(&self, x0: f64, y0: f64, x1: f64, y1: f64) -> bool {
        self.x0 < x1 && x0 < self.x1 && self.y0 < y1 && y0 < self.y1
    }

    /// Does the segment a-b pass through the open rectangle (slab method)?
    fn hits_segment(&self, a: P2, b: P2) -> bool {
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

/// An occupancy grid with A* planning, shared (read-only) by the copies of a
/// world until an obstacle is added.
#[derive(Debug, Clone)]
pub struct Planner {
    origin: P2,
    res: f64,
    w: usize,
    h: usize,
    free: Vec<bool>,
    /// Cells any obstacle (not inflated) overlaps: what the camera cannot
    /// see through ([`Planner::visible`]).
    opaque: Vec<bool>,
    /// Obstacles inflated by the robot radius (for line-of-sight checks).
    inflated: Vec<Rect>,
    walls: Rect,
}

impl Planner {
    pub fn new(layout: &Layout, p: &Params) -> Self {
        let r = &layout.room;
        let res = p.grid;
        let w = ((r.x1 - r.x0) / res).ceil() as usize;
        let h = ((r.y1 - r.y0) / res).ceil() as usize;
        let inflated: Vec<Rect> = layout
            .obstacles
            .iter()
            .map(|o| o.inflated(p.robot_radius))
            .collect();
        let walls = Rect::new(
            "walls",
            r.x0 + p.robot_radius,
            r.y0 + p.robot_radius,
            r.x1 - p.robot_radius,
            r.y1 - p.robot_radius,
        );
        let mut pl = Planner {
            origin: (r.x0, r.y0),
            res,
            w,
            h,
            free: vec![false; w * h],
            opaque: vec![false; w * h],
            inflated,
            walls,
        };
        for j in 0..h {
            for i in 0..w {
                let c = pl.center(i, j);
                pl.free[j * w + i] = pl.point_free(c);
            }
        }
        for o in &layout.obstacles {
            pl.mark_opaque(o);
        }
        pl
    }

    /// Marks the cells `o` overlaps as opaque (only the cells of its
    /// bounding box are visited).
    fn mark_opaque(&mut self, o: &Rect) {
        let (i0, j0) = self.cell((o.x0, o.y0));
        let (i1, j1) = self.cell((o.x1, o.y1));
        for j in j0..=j1 {
            for i in i0..=i1 {
                let (x0, y0) = (
                    self.origin.0 + i as f64 * self.res,
                    self.origin.1 + j as f64 * self.res,
                );
                if o.overlaps(x0, y0, x0 + self.res, y0 + self.res) {
                    self.opaque[j * self.w + i] = true;
                }
            }
        }
    }

    /// Line of sight from `a` to `b`: the segment crosses no opaque cell
    /// (a grid traversal, Amanatides and Woo 1987: at most one cell per
    /// grid line crossed, so a check costs O(length / resolution)). The
    /// grid is conservative: a segment crossing an obstacle is never
    /// visible (test `line_of_sight_never_sees_through_an_obstacle`).
    pub fn visible(&self, a: P2, b: P2) -> bool {
        let (mut i, mut j) = self.cell(a);
        let (gi, gj) = self.cell(b);
        let (dx, dy) = (b.0 - a.0, b.1 - a.1);
        let (si, sj): (i64, i64) = (if dx > 0.0 { 1 } else { -1 }, if dy > 0.0 { 1 } else { -1 });
        let next = |p: f64, d: f64, c: usize, o: f64| -> (f64, f64) {
            if d.abs() < 1e-12 {
                return (f64::INFINITY, f64::INFINITY);
            }
            let lo = o + c as f64 * self.res;
            let edge = if d > 0.0 { lo + self.res } else { lo };
            ((edge - p) / d, self.res / d.abs())
        };
        let (mut tx, ddx) = next(a.0, dx, i, self.origin.0);
        let (mut ty, ddy) = next(a.1, dy, j, self.origin.1);
        let n = gi.abs_diff(i) + gj.abs_diff(j) + 1;
        for _ in 0..n {
            if self.opaque[j * self.w + i] {
                return false;
            }
            if (i, j) == (gi, gj) {
                break;
            }
            if tx < ty {
                let ni = i as i64 + si;
                if ni < 0 || ni >= self.w as i64 {
                    break;
                }
                i = ni as usize;
                tx += ddx;
            } else {
                let nj = j as i64 + sj;
                if nj < 0 || nj >= self.h as i64 {
                    break;
                }
                j = nj as usize;
                ty += ddy;
            }
        }
        true
    }

    /// This planner with one more obstacle: the grid cells it covers are
    /// marked (the cells of the others are kept), so adding k obstacles one
    /// by one costs k grid passes, not k rebuilds of every obstacle.
    pub fn with_obstacle(&self, o: &Rect, robot_radius: f64) -> Planner {
        let mut pl = self.clone();
        let r = o.inflated(robot_radius);
        for j in 0..pl.h {
            for i in 0..pl.w {
                if r.contains(pl.center(i, j)) {
                    pl.free[j * pl.w + i] = false;
                }
            }
        }
        pl.inflated.push(r);
        pl.mark_opaque(o);
        pl
    }

    fn center(&self, i: usize, j: usize) -> P2 {
        (
            self.origin.0 + (i as f64 + 0.5) * self.res,
            self.origin.1 + (j as f64 + 0.5) * self.res,
        )
    }

    fn cell(&self, p: P2) -> (usize, usize) {
        let i = ((p.0 - self.origin.0) / self.res).floor().max(0.0) as usize;
        let j = ((p.1 - self.origin.1) / self.res).floor().max(0.0) as usize;
        (i.min(self.w - 1), j.min(self.h - 1))
    }

    fn point_free(&self, p: P2) -> bool {
        let wl = &self.walls;
        p.0 >= wl.x0
            && p.0 <= wl.x1
            && p.1 >= wl.y0
            && p.1 <= wl.y1
            && !self.inflated.iter().any(|o| o.contains(p))
    }

    fn segment_free(&self, a: P2, b: P2) -> bool {
        self.point_free(a)
            && self.point_free(b)
            && !self.inflated.iter().any(|o| o.hits_segment(a, b))
    }

    /// A collision-free polyline from `a` to `b` (without `a`), or `None`.
    pub fn plan(&self, a: P2, b: P2) -> Option<Vec<P2>> {
        if self.segment_free(a, b) {
            return Some(vec![b]);
        }
        if !self.point_free(b) {
            return None;
        }
        let start = self.nearest_free_cell(a)?;
        let goal = self.nearest_free_cell(b)?;
        let cells = self.astar(start, goal)?;
        // Points: a, cell centres, b; then string pulling.
        let mut pts = Vec::with_capacity(cells.len() + 2);
        pts.push(a);
        pts.extend(cells.iter().map(|&(i, j)| self.center(i, j)));
        pts.push(b);
        let mut out = Vec::new();
        let mut k = 0;
        while k + 1 < pts.len() {
            let mut next = k + 1;
            for m in (k + 2..pts.len()).rev() {
                if self.segment_free(pts[k], pts[m]) {
                    next = m;
                    break;
                }
            }
            out.push(pts[next]);
            k = next;
        }
        Some(out)
    }

    fn nearest_free_cell(&self, p: P2) -> Option<(usize, usize)> {
        let (ci, cj) = self.cell(p);
        let mut best: Option<((usize, usize), f64)> = None;
        for r in 0..4i64 {
            for dj in -r..=r {
                for di in -r..=r {
                    let (i, j) = (ci as i64 + di, cj as i64 + dj);
                    if i < 0 || j < 0 || i >= self.w as i64 || j >= self.h as i64 {
                        continue;
                    }
                    let (i, j) = (i as usize, j as usize);
                    if self.free[j * self.w + i] && self.segment_free(p, self.center(i, j)) {
                        let d = dist(p, self.center(i, j));
                        if best.is_none_or(|(_, bd)| d < bd) {
                            best = Some(((i, j), d));
                        }
                    }
                }
            }
            if best.is_some() {
                return best.map(|(c, _)| c);
            }
        }
        None
    }

    fn astar(&self, s: (usize, usize), g: (usize, usize)) -> Option<Vec<(usize, usize)>> {
        #[derive(PartialEq)]
        struct Item(f64, usize);
        impl Eq for Item {}
        impl PartialOrd for Item {
            fn partial_cmp(&self, o: &Self) -> Option<std::cmp::Ordering> {
                Some(self.cmp(o))
            }
        }
        impl Ord for Item {
            fn cmp(&self, o: &Self) -> std::cmp::Ordering {
                o.0.total_cmp(&self.0).then(o.1.cmp(&self.1))
            }
        }
        let n = self.w * self.h;
        let idx = |(i, j): (usize, usize)| j * self.w + i;
        let (si, gi) = (idx(s), idx(g));
        let h = |k: usize| {
            let (dx, dy) = (
                (k % self.w).abs_diff(g.0) as f64,
                (k / self.w).abs_diff(g.1) as f64,
            );
            dx.max(dy) + (std::f64::consts::SQRT_2 - 1.0) * dx.min(dy)
        };
        let mut cost = vec![f64::INFINITY; n];
        let mut prev = vec![usize::MAX; n];
        let mut open = BinaryHeap::new();
        cost[si] = 0.0;
        open.push(Item(h(si), si));
        while let Some(Item(_, k)) = open.pop() {
            if k == gi {
                let mut path = vec![g];
                let mut c = k;
                while c != si {
                    c = prev[c];
                    path.push((c % self.w, c / self.w));
                }
                path.reverse();
                return Some(path);
            }
            let (i, j) = ((k % self.w) as i64, (k / self.w) as i64);
            for (di, dj) in [
                (1, 0),
                (-1, 0),
                (0, 1),
                (0, -1),
                (1, 1),
                (1, -1),
                (-1, 1),
                (-1, -1),
            ] {
                let (ni, nj) = (i + di, j + dj);
                if ni < 0 || nj < 0 || ni >= self.w as i64 || nj >= self.h as i64 {
                    continue;
                }
                let nk = nj as usize * self.w + ni as usize;
                if !self.free[nk] {
                    continue;
                }
                // No corner cutting.
                if di != 0
                    && dj != 0
                    && (!self.free[j as usize * self.w + ni as usize]
                        || !self.free[nj as usize * self.w + i as usize])
                {
                    continue;
                }
                let step = if di != 0 && dj != 0 {
                    std::f64::consts::SQRT_2
                } else {
                    1.0
                };
                let c = cost[k] + step;
                if c < cost[nk] {
                    cost[nk] = c;
                    prev[nk] = k;
                    open.push(Item(c + h(nk), nk));
                }
            }
        }
        None
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
            }
        }
        changed
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn world() -> World {
        World::new(
            Layout::paper_room(),
            Params::default(),
            (-2.0, -2.2),
            vec![],
        )
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

    #[test]
    fn planner_goes_around_the_central_table() {
        let w = world();
        let (a, b) = ((0.0, -0.3), (0.0, 1.5));
        let path = w.planner.plan(a, b).expect("a path");
        assert!(path.len() >= 2, "{path:?}");
        let mut prev = a;
        let mut len = 0.0;
        for &p in &path {
            assert!(w.planner.segment_free(prev, p), "{prev:?} -> {p:?}");
            len += dist(prev, p);
            prev = p;
        }
        assert_eq!(prev, b);
        assert!(len > 1.8 && len < 3.5, "{len}");
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

    /// A `block` disturbance adds its obstacle to the grid (it rebuilt the
    /// grid from every obstacle, so k blocks cost k^2 obstacle passes): the
    /// same planner as one built with the obstacle.
    #[test]
    fn adding_an_obstacle_gives_the_planner_built_with_it() {
        let p = Params::default();
        let mut l = Layout::paper_room();
        let mut pl = Planner::new(&l, &p);
        for (k, r) in [
            Rect::new("a", -0.5, 1.4, 1.5, 1.5),
            Rect::new("b", -2.9, -2.9, -2.5, 2.9),
            Rect::new("c", 1.0, -1.0, 1.05, -0.2),
        ]
        .into_iter()
        .enumerate()
        {
            pl = pl.with_obstacle(&r, p.robot_radius);
            l.obstacles.push(r);
            let fresh = Planner::new(&l, &p);
            assert_eq!(pl.free, fresh.free, "{k}");
            assert_eq!(pl.inflated, fresh.inflated, "{k}");
        }
        let mut w = world();
        let t = std::time::Instant::now();
        for i in 0..1000 {
            let x = -2.5 + (i % 50) as f64 * 0.1;
            w.block(Rect::new("b", x, 2.5, x + 0.01, 2.51));
        }
        assert_eq!(w.layout.obstacles.len(), 1006);
        assert!(t.elapsed().as_secs() < 5, "{:?}", t.elapsed());
    }

    #[test]
    fn blocked_goal_has_no_path() {
        let mut w = world();
        w.block(Rect::new("wall", -3.0, 1.2, 3.0, 1.3));
        assert!(w.planner.plan((0.0, -0.3), (0.5, 2.1)).is_none());
        assert_eq!(w.map_version, 1);
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

    /// The grid's line of sight is conservative: a segment that crosses an
    /// obstacle (exactly, by the slab test) is never visible, on random
    /// segments in the paper room with random thin boxes added.
    #[test]
    fn line_of_sight_never_sees_through_an_obstacle() {
        let mut rng = crate::sim::rng::SimRng::named(7, "los");
        let mut w = world();
        for k in 0..8 {
            let (x, y) = (rng.range(-2.8, 2.5), rng.range(-2.8, 2.5));
            w.block(Rect::new(
                &format!("b{k}"),
                x,
                y,
                x + 0.02,
                y + rng.range(0.05, 0.5),
            ));
        }
        let (mut seen, mut hidden) = (0, 0);
        for _ in 0..20_000 {
            let a = (rng.range(-2.95, 2.95), rng.range(-2.95, 2.95));
            let b = (rng.range(-2.95, 2.95), rng.range(-2.95, 2.95));
            let blocked = w.layout.obstacles.iter().any(|o| o.hits_segment(a, b));
            let vis = w.planner.visible(a, b);
            assert!(!(blocked && vis), "{a:?} -> {b:?} seen through an obstacle");
            if vis {
                seen += 1;
            } else {
                hidden += 1;
            }
        }
        // Both answers occur (the check is not trivially false).
        assert!(seen > 1000 && hidden > 1000, "{seen} {hidden}");
        // The delivery station sees the far side of the central table, not
        // the west table behind it, nor the east table from the start.
        let w = world();
        assert!(w.planner.visible((0.5, 2.1), (0.0, 1.3)));
        assert!(!w.planner.visible((0.0, 0.1), (0.0, 1.3)));
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
