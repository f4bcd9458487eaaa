//! What a run records (SPEC §6): per step the time, pose, battery, running skills
//! and node/state statuses; the executed skills with arguments and outcomes;
//! events; the final world; the outcome. Also the behavior-match verdict between
//! two runs: the same executed skills in the same order (arguments, outcomes,
//! start times within a tolerance, one step by default), the same goal
//! outcome and the same final world, with the first divergence and its time,
//! the distance between the robot's positions at the same times (time-aligned)
//! and, beside it, the time-free discrete Fréchet distance between the paths
//! (Eiter and Mannila 1994).

use super::world::{P2, Place, World, dist};

mod divergence;
pub use divergence::{SkillSeq, SkillSlice, first_divergence};
use serde::Serialize;
use std::collections::BTreeMap;

/// One execution of an action skill.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SkillRecord {
    pub skill: String,
    pub args: BTreeMap<String, String>,
    /// `success`, `failure`, `cancelled` (halted by the policy, or not
    /// ticked), `aborted` (its base or arm taken by a new goal of the same
    /// policy, as an action server aborts a goal), or `running` at the end.
    pub outcome: String,
    pub start: f64,
    pub end: Option<f64>,
}

impl SkillRecord {
    /// `Pick(object=cube2) -> success`.
    pub fn text(&self) -> String {
        let args: Vec<String> = self.args.iter().map(|(k, v)| format!("{k}={v}")).collect();
        format!("{}({}) -> {}", self.skill, args.join(", "), self.outcome)
    }

    /// The same skill, arguments and what the world did: it completed
    /// (`success`), it did not (`failure`, `cancelled`, `aborted`: the
    /// same here), or it was still running. How a skill that did not
    /// complete ended is the executor's bookkeeping, not behavior: a BT
    /// halts a Pick whose object moved away (`cancelled`) where an FSM's
    /// Pick runs into it (`failure`), and BehaviorTree.CPP starts the new
    /// action before it halts the old one (`aborted`) where an FSM leaves
    /// its state first. When the two ended at different times, the next
    /// start (or the trajectories) tells.
    fn same(&self, o: &SkillRecord) -> bool {
        fn class(x: &str) -> &str {
            match x {
                "aborted" | "cancelled" | "failure" => "not completed",
                x => x,
            }
        }
        self.skill == o.skill && self.args == o.args && class(&self.outcome) == class(&o.outcome)
    }
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Event {
    pub t: f64,
    /// `start`, `end`, `battery-low`, `disturbance`, `done`, `chattering`, ...
    pub kind: String,
    pub text: String,
    pub x: f64,
    pub y: f64,
}

/// One step of a trace.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Step {
    pub t: f64,
    pub x: f64,
    pub y: f64,
    pub yaw: f64,
    pub battery: f64,
    /// Action skills running after the step.
    pub running: Vec<String>,
    /// Where the navigation running after the step is going, m: the goal
    /// fixed when it started (for an object, its believed pose then), so a
    /// detour to a stale belief shows. `None` when nothing drives the base.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub goal: Option<[f64; 2]>,
    /// Node id (BT) or state path (FSM/HFSM) of everything ticked in the step,
    /// with its status.
    pub statuses: Vec<(String, String)>,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ObjectState {
    pub x: f64,
    pub y: f64,
    /// The station the object is at, if any.
    pub at: Option<String>,
    pub held: bool,
    pub found: bool,
}

/// The world at the end of a run.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FinalWorld {
    pub robot: [f64; 2],
    /// The station the robot is at, if any.
    pub robot_at: Option<String>,
    pub battery: f64,
    pub holding: Option<String>,
    pub arm_tucked: bool,
    pub shut_down: bool,
    pub objects: BTreeMap<String, ObjectState>,
}

fn cm(x: f64) -> f64 {
    (x * 100.0).round() / 100.0
}

impl FinalWorld {
    pub fn of(w: &World) -> Self {
        FinalWorld {
            robot: [cm(w.robot.0), cm(w.robot.1)],
            robot_at: w.robot_station().map(str::to_string),
            battery: (w.battery * 10.0).round() / 10.0,
            holding: w.held().map(|i| w.objects[i].name.clone()),
            arm_tucked: w.arm_tucked,
            shut_down: w.shut_down,
            objects: w
                .objects
                .iter()
                .enumerate()
                .map(|(i, o)| {
                    let p = w.object_pos(i);
                    (
                        o.name.clone(),
                        ObjectState {
                            x: cm(p.0),
                            y: cm(p.1),
                            at: w.object_station(i).map(str::to_string),
                            held: o.place == Place::Held,
                            found: o.found,
                        },
                    )
                })
                .collect(),
        }
    }

    /// The discrete state compared by the verdict: where each object is (its
    /// station, or its position to the centimetre), what is held, the arm, the
    /// robot's station (or position to the centimetre). The battery level is
    /// reported but not compared (it depends on timing to the step).
    pub fn same_state(&self, o: &FinalWorld) -> bool {
        type Key = (String, Option<String>, bool, bool, Option<[f64; 2]>);
        let objs = |f: &FinalWorld| -> Vec<Key> {
            f.objects
                .iter()
                .map(|(n, s)| {
                    (
                        n.clone(),
                        s.at.clone(),
                        s.held,
                        s.found,
                        s.at.is_none().then_some([s.x, s.y]),
                    )
                })
                .collect()
        };
        let robot = |f: &FinalWorld| match &f.robot_at {
            Some(s) => (Some(s.clone()), None),
            None => (None, Some(f.robot)),
        };
        objs(self) == objs(o)
            && self.holding == o.holding
            && self.arm_tucked == o.arm_tucked
            && self.shut_down == o.shut_down
            && robot(self) == robot(o)
    }
}

/// How a run ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Outcome {
    /// The policy reported SUCCESS (BT root, machine outcome `SUCCESS`).
    Success,
    /// The machine ended with another outcome, or the run gave up after too
    /// many failed actions without progress.
    Failure,
    /// Switched between actions without progress (the paper's Fig. 3).
    Chattering,
    /// The step budget ran out.
    Timeout,
}

impl Outcome {
    pub fn as_str(self) -> &'static str {
        match self {
            Outcome::Success => "success",
            Outcome::Failure => "failure",
            Outcome::Chattering => "chattering",
            Outcome::Timeout => "timeout",
        }
    }
}

/// Everything a run records.
#[derive(Debug, Clone, Serialize)]
pub struct Run {
    pub policy: String,
    pub file: String,
    pub kind: String,
    pub convert: Option<String>,
    pub outcome: Outcome,
    pub reason: String,
    /// Whether the scenario's goal holds at the end (`None`: no goal given).
    pub goal_met: Option<bool>,
    pub steps: u64,
    /// Step length, s.
    #[serde(skip)]
    pub dt: f64,
    /// The scenario's verdict tolerances (`pose_tolerance_m`,
    /// `start_tolerance_s`).
    #[serde(skip)]
    pub pose_tolerance_m: f64,
    #[serde(skip)]
    pub start_tolerance_s: f64,
    /// The largest time shift under which poses are compared, s.
    #[serde(skip)]
    pub time_shift_s: f64,
    /// What the policy did after SUCCESS (`stop` or `keep-ticking`).
    pub after_success: &'static str,
    /// What the policy did after FAILURE (`stop` or `keep-ticking`).
    pub after_failure: &'static str,
    /// Time at which the policy last reported it was done, s.
    pub completion_s: Option<f64>,
    pub duration_s: f64,
    pub distance_m: f64,
    pub skills: Vec<SkillRecord>,
    pub events: Vec<Event>,
    pub final_world: FinalWorld,
    /// Latencies from a battery-low event to the start of Recharge, s.
    pub recharge_latency_s: Vec<f64>,
    #[serde(skip)]
    pub trajectory: Vec<P2>,
    /// The positions with the step at which the robot reached each: the
    /// steps where it moved (and the start), at most [`TRAJECTORY_POINTS`];
    /// between two, it stood still. For the time-aligned distance.
    #[serde(skip)]
    pub track: Vec<(u64, P2)>,
    #[serde(skip)]
    pub trace: Vec<Step>,
}

/// Where two runs first differ.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Divergence {
    /// Index in the executed-skill lists.
    pub index: usize,
    pub a: Option<String>,
    pub b: Option<String>,
    /// When, s: the earlier start of the two skills (`skill`, `start`),
    /// the earlier end of the two calls (`outcome`: when the worlds
    /// stopped doing the same), or the end of the shorter run when one has
    /// no skill there (`missing`).
    pub t: f64,
    /// `skill` (skill or arguments differ), `outcome` (the same call
    /// completed in one run and not in the other), `start` (the same skill
    /// started more than the tolerance apart) or `missing` (one run has no
    /// skill there).
    pub kind: &'static str,
    /// The two start times, s, for `start`.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub starts: Option<[f64; 2]>,
    /// When the differing calls made the worlds differ, s: `t` for
    /// `outcome`, else the earliest end of one of the two that completed
    /// (its effect is in one world only from then); `None` when neither
    /// completed.
    #[serde(skip)]
    pub parted: Option<f64>,
}

impl Divergence {
    /// `at 10.0 s, skill 3: Pick(object=cube2) -> success | (none)`.
    pub fn summary(&self) -> String {
        let what = match (self.kind, self.starts) {
            ("start", Some([a, b])) => format!(" (started at {a} s | {b} s)"),
            _ => String::new(),
        };
        format!(
            "at {} s, skill {}: {} | {}{what}",
            self.t,
            self.index + 1,
            self.a.as_deref().unwrap_or("(none)"),
            self.b.as_deref().unwrap_or("(none)")
        )
    }
}

/// The behavior-match verdict between two runs.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Verdict {
    pub a: String,
    pub b: String,
    /// Same skills, same outcome and goal, same final world.
    #[serde(rename = "match")]
    pub matches: bool,
    /// The same executed skills in order: skill, arguments, outcome, and
    /// start times at most `tolerance_s` apart.
    pub same_skills: bool,
    /// The same run outcome and the same goal result.
    pub same_outcome: bool,
    pub same_final_world: bool,
    /// The two robots were never more than `pose_tolerance_m` apart at the
    /// same step (`trajectory_distance_m`).
    pub same_motion: bool,
    pub tolerance_s: f64,
    pub pose_tolerance_m: f64,
    /// The scenario's `time_shift_s`: the largest shift tried, s.
    pub max_time_shift_s: f64,
    pub first_divergence: Option<Divergence>,
    /// The largest distance between the two robots at the same time, m,
    /// once the second run's clock is shifted by `time_shift_s` (after its
    /// run ended, a robot stands where it stopped).
    pub trajectory_distance_m: f64,
    /// The shift of the second run's clock, s, within the scenario's
    /// `time_shift_s`, that brings the two robots closest (the smallest
    /// such shift; positive: the second run is later).
    pub time_shift_s: f64,
    /// When the two worlds stopped being the same, s: the first time the
    /// robots are more than `pose_tolerance_m` apart (at that shift), or
    /// one of the first differing calls completed (its effect is then in
    /// one world only: [`Divergence::parted`]); `None` when neither
    /// happened.
    pub worlds_diverge_s: Option<f64>,
    /// Discrete Fréchet distance between the two paths, m: how far apart
    /// the paths are, whatever the time each took.
    pub path_distance_m: f64,
}
/// The verdict of every pair of runs, in pair order, their trajectories
/// thinned once to at most `points` points each for the Fréchet distance.
pub fn verdicts(runs: &[Run], points: usize) -> Vec<Verdict> {
    verdicts_within(runs, points, None).0
}

/// [`verdicts`] under a wall-clock deadline, read before each pair: the
/// pairs not compared once it has passed are returned (names `a`, `b`).
pub fn verdicts_within(
    runs: &[Run],
    points: usize,
    deadline: Option<std::time::Instant>,
) -> (Vec<Verdict>, Vec<[String; 2]>) {
    let thinned: Vec<Vec<P2>> = runs.iter().map(|r| thin(&r.trajectory, points)).collect();
    let mut out = Vec::new();
    let mut skipped = Vec::new();
    for i in 0..runs.len() {
        for j in i + 1..runs.len() {
            if deadline.is_some_and(|d| std::time::Instant::now() >= d) {
                skipped.push([runs[i].policy.clone(), runs[j].policy.clone()]);
                continue;
            }
            out.push(verdict_on(&runs[i], &runs[j], &thinned[i], &thinned[j]));
        }
    }
    (out, skipped)
}

/// Trajectory points kept for the Fréchet distance when time allows.
pub const FRECHET_POINTS: usize = 3000;
/// The fewest kept under a wall-clock budget.
pub const FRECHET_POINTS_MIN: usize = 300;

/// Points per trajectory for `pairs` Fréchet distances to fit in
/// `remaining` (about 5 ns per point pair on the machines measured), between
/// [`FRECHET_POINTS_MIN`] and [`FRECHET_POINTS`].
pub fn frechet_points(pairs: usize, remaining: std::time::Duration) -> usize {
    let per_pair_ns = remaining.as_nanos() as f64 / pairs.max(1) as f64;
    let p = (per_pair_ns / 5.0).sqrt() as usize;
    p.clamp(FRECHET_POINTS_MIN, FRECHET_POINTS)
}

pub fn verdict(a: &Run, b: &Run) -> Verdict {
    verdict_on(
        a,
        b,
        &thin(&a.trajectory, FRECHET_POINTS),
        &thin(&b.trajectory, FRECHET_POINTS),
    )
}

/// The verdict of two runs without the Fréchet distance of their paths
/// (`path_distance_m` 0), which Monte Carlo episodes do not report.
pub fn verdict_without_path(a: &Run, b: &Run) -> Verdict {
    verdict_on(a, b, &[], &[])
}

fn verdict_on(a: &Run, b: &Run, ta: &[P2], tb: &[P2]) -> Verdict {
    let tol = a.start_tolerance_s.max(b.start_tolerance_s) + 1e-6;
    let pose_tol = a.pose_tolerance_m.max(b.pose_tolerance_m);
    // The common prefix compared in place (no record cloned: 2,016 pairs
    // of 1,024 records each in a 64-policy scenario), the rest by the one
    // divergence function shared with `log compare`.
    let same = (a.skills.iter().zip(&b.skills))
        .take_while(|(x, y)| x.same(y) && (x.start - y.start).abs() <= tol)
        .count();
    let mut sa = SkillSlice::new(&a.skills[same..], a.duration_s);
    let mut sb = SkillSlice::new(&b.skills[same..], b.duration_s);
    let first = match first_divergence(&mut sa, &mut sb, tol) {
        Ok(d) => d.map(|d| Divergence {
            index: d.index + same,
            ..d
        }),
        Err(e) => match e {},
    };
    let same_world = a.final_world.same_state(&b.final_world);
    let same_outcome = a.outcome == b.outcome && a.goal_met == b.goal_met;
    let max_shift = (a.time_shift_s.max(b.time_shift_s) / a.dt.max(1e-9)).round() as i64;
    let aligned = best_alignment(&a.track, &b.track, max_shift, pose_tol);
    let apart = (aligned.distance * 1000.0).round() / 1000.0;
    let same_motion = apart <= pose_tol + 1e-9;
    let moved_apart = aligned.first_apart.map(|k| k as f64 * a.dt);
    let ended_apart = first.as_ref().and_then(|d| d.parted);
    let worlds_diverge_s = match (moved_apart, ended_apart) {
        (Some(x), Some(y)) => Some(x.min(y)),
        (x, y) => x.or(y),
    }
    .map(|t| (t * 1000.0).round() / 1000.0);
    Verdict {
        a: a.policy.clone(),
        b: b.policy.clone(),
        matches: first.is_none() && same_world && same_outcome && same_motion,
        same_skills: first.is_none(),
        same_outcome,
        same_final_world: same_world,
        same_motion,
        tolerance_s: (tol * 1000.0).round() / 1000.0,
        pose_tolerance_m: pose_tol,
        max_time_shift_s: (max_shift as f64 * a.dt * 1000.0).round() / 1000.0,
        first_divergence: first,
        trajectory_distance_m: apart,
        time_shift_s: (aligned.shift as f64 * a.dt * 1000.0).round() / 1000.0,
        worlds_diverge_s,
        path_distance_m: (frechet_thinned(ta, tb) * 1000.0).round() / 1000.0,
    }
}

/// Two tracks compared at one time shift.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Alignment {
    /// Steps the second track's clock is shifted by (positive: it is later).
    pub shift: i64,
    /// The largest distance between the two at the same (shifted) step.
    pub distance: f64,
    /// The first step at which they were more than the tolerance apart.
    pub first_apart: Option<u64>,
}

/// Shifts tried on each side of zero at most: past this many steps, a grid
/// of this many (every k-th step) up to the largest shift.
pub const MAX_SHIFTS: i64 = 64;

/// Of the shifts of the second track's clock within `±max_shift` steps, the
/// one that brings the two tracks closest ([`aligned_distance`]); among
/// equals, the smallest in magnitude (zero first, then the later second).
/// At most `2·MAX_SHIFTS + 1` shifts, each linear in the points.
pub fn best_alignment(a: &[(u64, P2)], b: &[(u64, P2)], max_shift: i64, tol: f64) -> Alignment {
    let stride = (max_shift.max(0) + MAX_SHIFTS - 1) / MAX_SHIFTS;
    let mut best = shifted_alignment(a, b, 0, tol);
    let mut k = stride;
    while stride > 0 && k <= max_shift {
        for shift in [k, -k] {
            let c = shifted_alignment(a, b, shift, tol);
            if c.distance < best.distance - 1e-9 {
                best = c;
            }
        }
        k += stride;
    }
    best
}

/// The largest distance between two tracks at the same step: each holds its
/// position between two points and after its last. Linear in the points.
pub fn aligned_distance(a: &[(u64, P2)], b: &[(u64, P2)]) -> f64 {
    shifted_alignment(a, b, 0, f64::INFINITY).distance
}

/// [`aligned_distance`] with the second track's steps read `shift` steps earlier
/// (`shift` steps earlier on the first's clock: a point moved before step
/// 0 stands at step 0).
fn shifted_alignment(a: &[(u64, P2)], b: &[(u64, P2)], shift: i64, tol: f64) -> Alignment {
    let at = |k: u64| (k as i64 - shift).max(0) as u64;
    let (Some(&(_, mut pa)), Some(&(_, mut pb))) = (a.first(), b.first()) else {
        return Alignment {
            shift,
            distance: 0.0,
            first_apart: None,
        };
    };
    let (mut i, mut j) = (0, 0);
    let mut best = dist(pa, pb);
    let mut first_apart = (best > tol + 1e-9).then_some(0);
    while i < a.len() || j < b.len() {
        let next = match (a.get(i), b.get(j)) {
            (Some(x), Some(y)) => x.0.min(at(y.0)),
            (Some(x), None) => x.0,
            (None, Some(y)) => at(y.0),
            (None, None) => break,
        };
        while let Some(&(k, p)) = a.get(i)
            && k == next
        {
            pa = p;
            i += 1;
        }
        while let Some(&(k, p)) = b.get(j)
            && at(k) == next
        {
            pb = p;
            j += 1;
        }
        let d = dist(pa, pb);
        if d > tol + 1e-9 && first_apart.is_none() {
            first_apart = Some(next);
        }
        best = best.max(d);
    }
    Alignment {
        shift,
        distance: best,
        first_apart,
    }
}

/// A run's track as kept: every k-th point when there are more than
/// [`TRAJECTORY_POINTS`], and the last.
pub fn compact_track(t: Vec<(u64, P2)>) -> Vec<(u64, P2)> {
    if t.len() <= TRAJECTORY_POINTS {
        return t;
    }
    let last = *t.last().expect("non-empty");
    let stride = t.len().div_ceil(TRAJECTORY_POINTS);
    let mut out: Vec<(u64, P2)> = t.into_iter().step_by(stride).collect();
    if out.last() != Some(&last) {
        out.push(last);
    }
    out
}

/// Trajectory points a run keeps once it has ended (for the verdicts and
/// the plot): 1 MiB a run, whatever `max_steps`.
pub const TRAJECTORY_POINTS: usize = 65_536;

/// A run's trajectory as kept: the points where the robot moved (as
/// `thin` keeps them), every k-th when there are more than
/// [`TRAJECTORY_POINTS`], and the last point. The Fréchet distance of the
/// verdicts is the same as on the whole trajectory up to that many points,
/// and so is the plot.
pub fn compact_trajectory(p: Vec<P2>) -> Vec<P2> {
    let Some(&last) = p.last() else {
        return p;
    };
    let n = p.len();
    let mut out: Vec<P2> = Vec::new();
    let mut kept_last = false;
    for (i, &q) in p.iter().enumerate() {
        if out.last().is_none_or(|&l| dist(l, q) > 1e-6) {
            out.push(q);
            kept_last = i + 1 == n;
        }
    }
    drop(p);
    if out.len() > TRAJECTORY_POINTS {
        let stride = out.len().div_ceil(TRAJECTORY_POINTS);
        out = out.into_iter().step_by(stride).collect();
        kept_last = false;
    }
    if !kept_last && n > 1 {
        out.push(last);
    }
    out.shrink_to_fit();
    out
}

/// Keeps the points where the robot moved, at most `max` of them.
fn thin(p: &[P2], max: usize) -> Vec<P2> {
    let mut out: Vec<P2> = Vec::new();
    for &q in p {
        if out.last().is_none_or(|&l| dist(l, q) > 1e-6) {
            out.push(q);
        }
    }
    if out.len() > max {
        let stride = out.len().div_ceil(max);
        let last = *out.last().expect("non-empty");
        out = out.into_iter().step_by(stride).collect();
        out.push(last);
    }
    out
}

/// Discrete Fréchet distance (rolling rows, O(n m) time, O(m) memory), on
/// trajectories thinned to [`FRECHET_POINTS`].
pub fn frechet(a: &[P2], b: &[P2]) -> f64 {
    frechet_thinned(&thin(a, FRECHET_POINTS), &thin(b, FRECHET_POINTS))
}

/// Discrete Fréchet distance of two point sequences as given.
fn frechet_thinned(a: &[P2], b: &[P2]) -> f64 {
    if a.is_empty() || b.is_empty() {
        return 0.0;
    }
    let mut prev = vec![0.0f64; b.len()];
    let mut cur = vec![0.0f64; b.len()];
    for (i, &p) in a.iter().enumerate() {
        for (j, &q) in b.iter().enumerate() {
            let d = dist(p, q);
            cur[j] = match (i, j) {
                (0, 0) => d,
                (0, _) => cur[j - 1].max(d),
                (_, 0) => prev[0].max(d),
                _ => prev[j].min(prev[j - 1]).min(cur[j - 1]).max(d),
            };
        }
        std::mem::swap(&mut prev, &mut cur);
    }
    prev[b.len() - 1]
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A run keeps at most TRAJECTORY_POINTS points of its trajectory once
    /// it has ended (it kept one per step: 16 MB a run at 10^6 steps), and
    /// the verdict's distance is the same below that.
    #[test]
    fn a_kept_trajectory_is_bounded_and_measures_the_same() {
        // Standing still, then moving 1 cm a step, then standing still.
        let mut p: Vec<P2> = vec![(0.0, 0.0); 50];
        p.extend((0..5000).map(|i| (i as f64 * 0.01, 0.0)));
        p.extend(std::iter::repeat_n((49.99, 0.0), 50));
        let q: Vec<P2> = p.iter().map(|&(x, y)| (x, y + 0.5)).collect();
        let (cp, cq) = (compact_trajectory(p.clone()), compact_trajectory(q.clone()));
        assert_eq!(cp.len(), 5001, "the points where it moved, and the last");
        for pts in [FRECHET_POINTS, FRECHET_POINTS_MIN] {
            assert_eq!(thin(&cp, pts), thin(&p, pts));
            assert_eq!(frechet_thinned(&thin(&cp, pts), &thin(&cq, pts)), 0.5);
        }
        let long: Vec<P2> = (0..1_000_000).map(|i| (i as f64 * 1e-5, 0.0)).collect();
        let c = compact_trajectory(long);
        assert!(c.len() <= TRAJECTORY_POINTS + 1, "{}", c.len());
        assert_eq!(c.last(), Some(&(999_999.0 * 1e-5, 0.0)));
        assert_eq!(compact_trajectory(vec![(1.0, 1.0)]), vec![(1.0, 1.0)]);
        assert_eq!(compact_trajectory(vec![]), vec![]);
    }

    #[test]
    fn frechet_points_fit_the_time_left() {
        use std::time::Duration;
        // 6 pairs in 1 s: plenty, the full 3000; in 1 ms: sqrt(1e6 / 6 / 5)
        // = 182, so the floor of 300; none left: the floor.
        assert_eq!(frechet_points(6, Duration::from_secs(1)), FRECHET_POINTS);
        assert_eq!(
            frechet_points(6, Duration::from_millis(1)),
            FRECHET_POINTS_MIN
        );
        assert_eq!(frechet_points(6, Duration::ZERO), FRECHET_POINTS_MIN);
        assert_eq!(frechet_points(1, Duration::from_millis(2)), 632);
    }

    /// A straight run at 0.1 m a step from `start`, 100 steps long.
    fn drive(start: u64) -> Vec<(u64, P2)> {
        let mut t = vec![(0, (0.0, 0.0))];
        t.extend((1..=100).map(|i| (start + i, (i as f64 * 0.1, 0.0))));
        t
    }

    #[test]
    fn the_best_alignment_finds_the_shift_within_the_bound() {
        let (a, b) = (drive(0), drive(5));
        let none = best_alignment(&a, &b, 0, 0.2);
        assert_eq!((none.shift, none.first_apart), (0, Some(3)));
        assert!((none.distance - 0.5).abs() < 1e-9, "{none:?}");
        let within = best_alignment(&a, &b, 10, 0.2);
        assert_eq!((within.shift, within.distance), (5, 0.0));
        assert_eq!(within.first_apart, None);
        // Either order: the first run later is a negative shift.
        assert_eq!(best_alignment(&b, &a, 10, 0.2).shift, -5);
        // Past 64 steps a grid: 32 is on the grid of every 16th up to 1000.
        let far = best_alignment(&a, &drive(32), 1000, 0.2);
        assert_eq!((far.shift, far.distance), (32, 0.0));
        assert_eq!(aligned_distance(&a, &a), 0.0);
    }

    #[test]
    fn the_worlds_diverge_when_the_robots_part() {
        let a = drive(0);
        let mut b = drive(0);
        for p in b.iter_mut().skip(40) {
            p.1.1 = 1.0;
        }
        let al = best_alignment(&a, &b, 2, 0.2);
        assert_eq!(al.first_apart, Some(40), "{al:?}");
        assert_eq!(al.shift, 0);
    }

    #[test]
    fn an_outcome_divergence_is_timed_when_the_calls_part() {
        let call = |skill: &str, outcome: &str, start: f64, end: f64| SkillRecord {
            skill: skill.into(),
            args: BTreeMap::from([("object".to_string(), "cube".to_string())]),
            outcome: outcome.into(),
            start,
            end: Some(end),
        };
        let a = [call("Pick", "success", 2.0, 5.0)];
        let b = [call("Pick", "failure", 2.0, 3.5)];
        let d = first_divergence(
            &mut SkillSlice::new(&a, 9.0),
            &mut SkillSlice::new(&b, 9.0),
            0.1,
        )
        .unwrap()
        .unwrap();
        assert_eq!((d.kind, d.t, d.index), ("outcome", 3.5, 0));
        // `failure` and `cancelled` are the same for the world.
        let c = [call("Pick", "cancelled", 2.0, 3.0)];
        let same = first_divergence(
            &mut SkillSlice::new(&b, 9.0),
            &mut SkillSlice::new(&c, 9.0),
            0.1,
        );
        assert_eq!(same.unwrap(), None);
        // Another skill: at the earlier start.
        let e = [call("Place", "success", 1.5, 3.0)];
        let d = first_divergence(
            &mut SkillSlice::new(&a, 9.0),
            &mut SkillSlice::new(&e, 9.0),
            0.1,
        )
        .unwrap()
        .unwrap();
        assert_eq!((d.kind, d.t), ("skill", 1.5));
    }

    #[test]
    fn frechet_of_shifted_paths() {
        let a: Vec<P2> = (0..10).map(|i| (i as f64, 0.0)).collect();
        let b: Vec<P2> = (0..10).map(|i| (i as f64, 1.0)).collect();
        assert!((frechet(&a, &b) - 1.0).abs() < 1e-12);
        assert_eq!(frechet(&a, &a), 0.0);
        // Waiting in place does not change the distance.
        let mut c = a.clone();
        c.insert(3, (3.0, 0.0));
        assert_eq!(frechet(&a, &c), 0.0);
    }
}
