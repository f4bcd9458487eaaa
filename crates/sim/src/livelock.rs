//! Livelock detection (SPEC §6; docs/simulator-verdicts.md): a run is a
//! livelock when an abstract state of the robot — world facts and the
//! running skills — recurs without progress toward the goal. Bounded
//! memory: at most [`LIVELOCK_STATES`] state hashes.

use super::robot::Robot;
use super::world::Place;

/// Abstract states a run remembers at most between two progresses toward
/// the goal (the set is cleared when full: a cycle through more distinct
/// states is not detected, and runs to its step budget).
pub(crate) const LIVELOCK_STATES: usize = 4096;

/// Livelock detection (SPEC §6): the abstract state — world facts and the
/// running skills — is noted each time it changes; entering one state
/// `repeats` times without progress toward the goal (the number of goal
/// terms that hold, and whether the policy reports SUCCESS) and without a
/// disturbance is a livelock. Memory: at most [`LIVELOCK_STATES`] hashes.
pub(super) struct Livelock {
    repeats: u32,
    pub(super) seen: std::collections::HashMap<u64, u32>,
    last: Option<u64>,
    measure: usize,
}

impl Livelock {
    pub(super) fn new(repeats: u32) -> Self {
        Livelock {
            repeats,
            seen: std::collections::HashMap::new(),
            last: None,
            measure: usize::MAX,
        }
    }

    /// Notes a step's state (`fresh`: an action started in the step, so
    /// the state is entered again even if it is the last one); `Some(times)`
    /// when it is a livelock.
    pub(super) fn step(
        &mut self,
        state: u64,
        fresh: bool,
        measure: usize,
        disturbed: bool,
    ) -> Option<u32> {
        if measure != self.measure || disturbed || self.seen.len() >= LIVELOCK_STATES {
            self.measure = measure;
            self.seen.clear();
            self.last = None;
        }
        if !fresh && self.last == Some(state) {
            return None;
        }
        self.last = Some(state);
        let n = self.seen.entry(state).or_insert(0);
        *n += 1;
        (*n >= self.repeats).then_some(*n)
    }
}

/// Progress of navigation (issue 31): the closest the robot has come to
/// each navigation goal in the run (goals to the centimetre, at most
/// [`LIVELOCK_STATES`] of them). A step that brings the robot more than
/// [`NAV_PROGRESS_M`] closer to a running navigation's goal than ever
/// before is progress: an alternation of skills that advances the robot
/// toward the same goal (a Timeout and a Safe-Move-To) is not a livelock,
/// while going back and forth between two goals already reached is.
#[derive(Default)]
pub(super) struct NavProgress {
    best: std::collections::HashMap<(i64, i64), f64>,
}

/// How much closer than ever to a navigation goal counts as progress, m.
pub(super) const NAV_PROGRESS_M: f64 = 0.05;

impl NavProgress {
    /// Whether the robot at `at` came closer to any of `goals` than ever
    /// by more than [`NAV_PROGRESS_M`] (the best distances updated).
    pub(super) fn advanced(
        &mut self,
        at: (f64, f64),
        goals: impl Iterator<Item = (f64, f64)>,
    ) -> bool {
        let mut advanced = false;
        for g in goals {
            if self.best.len() >= LIVELOCK_STATES {
                self.best.clear();
            }
            let key = ((g.0 * 100.0).round() as i64, (g.1 * 100.0).round() as i64);
            let d = ((at.0 - g.0).powi(2) + (at.1 - g.1).powi(2)).sqrt();
            match self.best.get_mut(&key) {
                Some(b) if d < *b - NAV_PROGRESS_M => {
                    *b = d;
                    advanced = true;
                }
                Some(_) => {}
                None => {
                    self.best.insert(key, d);
                }
            }
        }
        advanced
    }
}

/// The abstract state of the robot, hashed: where each object is (held, or
/// its place on a surface or the floor to the centimetre), whether it was
/// seen and where it is believed to be, the arm, shut-down,
/// emergency, charging, the battery by tenths (and whether it is low),
/// which leaf runs which skill, and which leaves started an action in the
/// step (an action may start and finish within one step). The robot's position is left out: moving is
/// what a running navigation does.
pub(super) fn abstract_state(r: &Robot) -> u64 {
    // A fast multiplicative mix (deterministic, no allocation): this runs
    // every step.
    let mut h: u64 = 0;
    let mut mix = |x: u64| h = (h.rotate_left(5) ^ x).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    let w = &r.world;
    for o in &w.objects {
        match o.place {
            Place::Held => mix(u64::MAX),
            Place::At(p) | Place::Floor(p) => {
                mix(matches!(o.place, Place::Floor(_)) as u64);
                mix((p.0 * 100.0).round() as i64 as u64);
                mix((p.1 * 100.0).round() as i64 as u64);
            }
        }
        mix(o.found as u64);
        // What the robot believes (to the centimetre): a belief that
        // changes is progress of a kind.
        mix((o.belief.0 * 100.0).round() as i64 as u64);
        mix((o.belief.1 * 100.0).round() as i64 as u64);
    }
    mix(w.arm_tucked as u64
        | (w.shut_down as u64) << 1
        | (w.emergency as u64) << 2
        | (w.charging as u64) << 3);
    mix((w.battery / 10.0).floor() as i64 as u64);
    mix((w.battery <= w.params.low_battery) as u64);
    // The live keys, in order (after `end_step`).
    for &k in &r.touched {
        // A key runs one skill: its binding.
        if r.live[k].is_some() {
            mix(k as u64);
        }
    }
    // The actions started in the step (and maybe done in it already).
    mix(u64::MAX - 1);
    for &k in &r.started {
        mix(k as u64);
    }
    h
}
