//! Navigation and sight in the planar world (SPEC §6): an occupancy grid of
//! the room (obstacles inflated by the robot's radius) planned on with A*
//! (Hart, Nilsson and Raphael 1968), the grid path shortened by line-of-sight
//! checks against the exact rectangles ("string pulling"), and an opacity
//! grid of the obstacles (not inflated) for the camera's line of sight.

use super::world::{Layout, P2, Params, Rect, dist};
use std::collections::BinaryHeap;

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

    pub(super) fn segment_free(&self, a: P2, b: P2) -> bool {
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::world::World;

    fn world() -> World {
        crate::world::empty_paper_room()
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

    /// The grid's line of sight is conservative: a segment that crosses an
    /// obstacle (exactly, by the slab test) is never visible, on random
    /// segments in the paper room with random thin boxes added.
    #[test]
    fn line_of_sight_never_sees_through_an_obstacle() {
        let mut rng = crate::rng::SimRng::named(7, "los");
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
        // The delivery station sees the far side of the central table; its
        // near side does not see through the table.
        let w = world();
        assert!(w.planner.visible((0.5, 2.1), (0.0, 1.3)));
        assert!(!w.planner.visible((0.0, 0.1), (0.0, 1.3)));
    }
}
