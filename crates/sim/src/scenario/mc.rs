//! The `[monte_carlo]` table of a scenario (SPEC §6): the distribution the
//! random disturbances of `sim --runs N` (and of `sim --seed S`, one
//! episode) are drawn from — failure rates per skill, a battery drop,
//! objects moved during the task and after it is done, dropped objects,
//! blocked paths, emergencies — and [`draw`], which makes one episode's
//! disturbances from its seed alone, so that the seed replays the episode.
//!
//! ```toml
//! [monte_carlo]
//! rates = { Pick = 0.1 }                      # failure probability per start
//! battery_drop = { probability = 0.5, level = [5, 19], window = [5.0, 120.0] }
//! move = { probability = 0.2, objects = ["cube2"], to = ["west-table"], window = [0.0, 60.0] }
//! move_after_done = { probability = 0.2, objects = ["cube2"], to = ["west-table"], delay = [1.0, 5.0] }
//! drop = { probability = 0.1, window = [5.0, 60.0] }            # objects = all by default
//! block = { probability = 0.1, rects = [{ name = "box", rect = [1.0, 1.3, 2.9, 1.6] }], window = [0.0, 30.0] }
//! emergency = { probability = 0.05, window = [5.0, 60.0], duration = [1.0, 5.0] }
//! ```

use super::{Disturbance, Effect, MAX_OBSTACLES, MAX_STATIONS, Reader, Val, When};
use crate::rng::SimRng;
use crate::world::{P2, Rect, World};
use btfsm_core::diagnostic::suggest;
use std::collections::BTreeMap;
use toml::de::DeTable;

/// `(probability, level range in percent, time window in s)` of a random
/// battery drop.
pub type BatteryDrop = (f64, (f64, f64), (f64, f64));

/// When a random disturbance fires.
#[derive(Debug, Clone, PartialEq)]
pub enum RandomWhen {
    /// At a time drawn uniformly from `[t0, t1]` s.
    Window(f64, f64),
    /// A delay drawn from `[d0, d1]` s after the policy first reports SUCCESS.
    AfterDone(f64, f64),
}

/// What a random disturbance does.
#[derive(Debug, Clone, PartialEq)]
pub enum RandomEffect {
    /// One of `objects` moved to one of `to`.
    Move { objects: Vec<usize>, to: Vec<P2> },
    /// One of `objects` dropped (if held when it fires).
    Drop { objects: Vec<usize> },
    /// One of `rects` blocks the way.
    Block(Vec<Rect>),
    /// An emergency lasting a duration drawn from the range, s.
    Emergency(f64, f64),
}

/// One random disturbance: with `probability`, per episode.
#[derive(Debug, Clone, PartialEq)]
pub struct Random {
    pub probability: f64,
    pub when: RandomWhen,
    pub effect: RandomEffect,
}

/// Randomisation of Monte Carlo episodes.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MonteCarlo {
    /// Extra failure probability per start of a skill.
    pub rates: BTreeMap<String, f64>,
    /// `(probability, level range, time window)` of a battery drop.
    pub battery_drop: Option<BatteryDrop>,
    /// The other random disturbances, in the order of `KEYS`.
    pub random: Vec<Random>,
}

const KEYS: &[&str] = &[
    "rates",
    "battery_drop",
    "move",
    "move_after_done",
    "drop",
    "block",
    "emergency",
];

impl Reader {
    fn names_of(&mut self, v: Option<&Val<'_>>, world: &World, what: &str) -> Option<Vec<usize>> {
        let Some(v) = v else {
            if world.objects.is_empty() {
                return None;
            }
            return Some((0..world.objects.len()).collect());
        };
        let a = self.array(v, what)?;
        let mut out = Vec::new();
        for x in a {
            let name = self.string(x, "an object")?;
            match world.object_index(&name) {
                Some(i) => out.push(i),
                None => {
                    let h = suggest(&name, world.objects.iter().map(|o| o.name.as_str()));
                    self.err(x.span(), format!("unknown object `{name}`"), h);
                    return None;
                }
            }
        }
        if out.is_empty() {
            self.err(
                v.span(),
                format!("{what} must name at least one object"),
                "",
            );
            return None;
        }
        Some(out)
    }

    /// Reads `[monte_carlo]`.
    pub(super) fn monte_carlo(&mut self, m: &Val<'_>, world: &World) -> Option<MonteCarlo> {
        let mut out = MonteCarlo::default();
        let mt = self.table(m, "`monte_carlo`")?;
        self.keys(mt, KEYS, "field of `monte_carlo`");
        if let Some(r) = mt.get("rates") {
            out.rates = self.rates(r)?;
        }
        for key in &KEYS[1..] {
            let Some(b) = mt.get(*key) else {
                continue;
            };
            self.random(key, b, world, &mut out)?;
        }
        Some(out)
    }

    /// The random disturbance `key` of `[monte_carlo]` (its table `b`):
    /// the battery drop, or one of [`MonteCarlo::random`].
    fn random(
        &mut self,
        key: &str,
        b: &Val<'_>,
        world: &World,
        out: &mut MonteCarlo,
    ) -> Option<()> {
        let bt = self.table(b, &format!("`{key}`"))?;
        let fields: &[&str] = match key {
            "battery_drop" => &["probability", "level", "window"],
            "move" => &["probability", "objects", "to", "window"],
            "move_after_done" => &["probability", "objects", "to", "delay"],
            "drop" => &["probability", "objects", "window"],
            "block" => &["probability", "rects", "window"],
            _ => &["probability", "window", "duration"],
        };
        self.keys(bt, fields, &format!("field of `{key}`"));
        let p = bt
            .get("probability")
            .and_then(|v| self.number(v, "`probability`", 0.0, 1.0))
            .unwrap_or(0.5);
        let window = self.range_or(bt, "window", 1e9, (5.0, 60.0));
        let effect = match key {
            "battery_drop" => {
                let level = self.range_or(bt, "level", 100.0, (5.0, 19.0));
                out.battery_drop = Some((p, level, window));
                return Some(());
            }
            "move" | "move_after_done" => self.random_move(key, b, bt, world)?,
            "drop" => RandomEffect::Drop {
                objects: self.names_of(bt.get("objects"), world, "`objects`")?,
            },
            "block" => self.random_block(b, bt)?,
            _ => {
                let (d0, d1) = self.range_or(bt, "duration", 1e9, (1.0, 5.0));
                RandomEffect::Emergency(d0, d1)
            }
        };
        let when = if key == "move_after_done" {
            let (d0, d1) = self.range_or(bt, "delay", 1e9, (1.0, 5.0));
            RandomWhen::AfterDone(d0, d1)
        } else {
            RandomWhen::Window(window.0, window.1)
        };
        out.random.push(Random {
            probability: p,
            when,
            effect,
        });
        Some(())
    }

    /// The range `k` of a random disturbance's table, `default` when it
    /// is missing or refused.
    fn range_or(&mut self, bt: &DeTable<'_>, k: &str, max: f64, default: (f64, f64)) -> (f64, f64) {
        bt.get(k)
            .and_then(|v| self.range(v, &format!("`{k}`"), 0.0, max))
            .unwrap_or(default)
    }

    /// `move` and `move_after_done`: the objects and the places (`to`, at
    /// least one) they may be moved to.
    fn random_move(
        &mut self,
        key: &str,
        b: &Val<'_>,
        bt: &DeTable<'_>,
        world: &World,
    ) -> Option<RandomEffect> {
        let objects = self.names_of(bt.get("objects"), world, "`objects`")?;
        let Some(to) = bt.get("to") else {
            self.err(
                b.span(),
                format!("`{key}` needs `to`"),
                "write `to = [\"west-table\"]`",
            );
            return None;
        };
        let ta = self.array(to, "`to`")?;
        if !self.at_most(to.span(), ta.len(), MAX_STATIONS, "places") || ta.is_empty() {
            self.err(to.span(), "`to` must list at least one place", "");
            return None;
        }
        let mut places = Vec::new();
        for x in ta {
            places.push(self.pose(x, "a place", &world.layout, world.params.robot_radius)?);
        }
        Some(RandomEffect::Move {
            objects,
            to: places,
        })
    }

    /// `block`: the obstacles (`rects`, at least one) that may block the way.
    fn random_block(&mut self, b: &Val<'_>, bt: &DeTable<'_>) -> Option<RandomEffect> {
        let Some(rs) = bt.get("rects") else {
            self.err(
                b.span(),
                "`block` needs `rects`",
                "write `rects = [{ name = \"box\", rect = [1.0, 1.3, 2.9, 1.6] }]`",
            );
            return None;
        };
        let ra = self.array(rs, "`rects`")?;
        if !self.at_most(rs.span(), ra.len(), MAX_OBSTACLES, "obstacles") {
            return None;
        }
        let mut rects = Vec::new();
        for x in ra {
            rects.push(self.rect(x)?);
        }
        if rects.is_empty() {
            self.err(rs.span(), "`rects` must list at least one obstacle", "");
            return None;
        }
        Some(RandomEffect::Block(rects))
    }
}

fn tenth(x: f64) -> f64 {
    (x * 10.0).round() / 10.0
}

fn pick<T: Clone>(rng: &mut SimRng, v: &[T]) -> T {
    let i = ((rng.range(0.0, 1.0) * v.len() as f64) as usize).min(v.len() - 1);
    v[i].clone()
}

/// The disturbances of the episode with seed `ep_seed`: the scenario's own,
/// those at a time moved to a random time between half and one and a half
/// times it, then each random disturbance of the distribution with its
/// probability. A function of the scenario and `ep_seed` alone.
/// Moves each disturbance given at a time to a random time between half
/// and one and a half times it, keeping their order: the times drawn are
/// sorted and given back in the order the scenario's times are in. (Drawn
/// independently, an all-clear at 9 s could come before the emergency of
/// 5 s it clears, leaving the emergency in force for the rest of the run:
/// 17 of 1000 Fig. 9 episodes, issue 31.)
fn jitter_in_order(ds: &mut [Disturbance], rng: &mut SimRng) {
    let mut timed: Vec<(usize, f64)> = (ds.iter().enumerate())
        .filter_map(|(i, d)| match d.when {
            When::At(t) => Some((i, t)),
            _ => None,
        })
        .collect();
    let mut drawn: Vec<f64> = (timed.iter())
        .map(|&(_, t)| tenth(t * rng.range(0.5, 1.5)))
        .collect();
    drawn.sort_by(f64::total_cmp);
    // Stable: disturbances at the same time keep the scenario's order.
    timed.sort_by(|a, b| a.1.total_cmp(&b.1));
    for (&(i, _), t) in timed.iter().zip(drawn) {
        ds[i].when = When::At(t);
    }
}

pub fn draw(s: &super::Scenario, ep_seed: u64) -> Vec<Disturbance> {
    let mut rng = SimRng::named(ep_seed, "disturbances");
    let mut ds = s.disturbances.clone();
    jitter_in_order(&mut ds, &mut rng);
    let w = &s.world;
    if let Some((p, (lo, hi), (t0, t1))) = s.monte_carlo.battery_drop
        && rng.chance(p)
    {
        let level = rng.range(lo, hi).round();
        let at = tenth(rng.range(t0, t1));
        ds.push(Disturbance {
            when: When::At(at),
            effect: Effect::Battery(level),
            text: format!("battery set to {level}%"),
        });
    }
    for r in &s.monte_carlo.random {
        if !rng.chance(r.probability) {
            continue;
        }
        let (at, after_done) = match r.when {
            RandomWhen::Window(t0, t1) => (tenth(rng.range(t0, t1)), false),
            RandomWhen::AfterDone(d0, d1) => (tenth(rng.range(d0, d1)), true),
        };
        let timed = |t: f64| {
            if after_done {
                When::AfterDone(t)
            } else {
                When::At(t)
            }
        };
        let when = timed(at);
        match &r.effect {
            RandomEffect::Move { objects, to } => {
                let (o, p) = (pick(&mut rng, objects), pick(&mut rng, to));
                ds.push(Disturbance {
                    when,
                    effect: Effect::Move { object: o, to: p },
                    text: format!("{} moved to ({}, {})", w.objects[o].name, p.0, p.1),
                });
            }
            RandomEffect::Drop { objects } => {
                let o = pick(&mut rng, objects);
                ds.push(Disturbance {
                    when,
                    effect: Effect::Drop { object: o },
                    text: format!("{} dropped", w.objects[o].name),
                });
            }
            RandomEffect::Block(rects) => {
                let r = pick(&mut rng, rects);
                ds.push(Disturbance {
                    when,
                    text: format!("path blocked by {}", r.name),
                    effect: Effect::Block(r),
                });
            }
            RandomEffect::Emergency(d0, d1) => {
                let dur = tenth(rng.range(*d0, *d1)).max(0.1);
                let end = timed(tenth(at + dur));
                ds.push(Disturbance {
                    when,
                    effect: Effect::Emergency(true),
                    text: "emergency".into(),
                });
                ds.push(Disturbance {
                    when: end,
                    effect: Effect::Emergency(false),
                    text: "emergency over".into(),
                });
            }
        }
    }
    ds
}

/// The failure rates of an episode: the scenario's `[rates]` combined with
/// the distribution's (independent failures).
pub fn rates(s: &super::Scenario) -> BTreeMap<String, f64> {
    let mut rates = s.rates.clone();
    for (k, v) in &s.monte_carlo.rates {
        let e = rates.entry(k.clone()).or_insert(0.0);
        *e = 1.0 - (1.0 - *e) * (1.0 - v);
    }
    rates
}
