//! Scenario files (SPEC §6): the world, the policies to run (paths relative to
//! the scenario), the seed, skill failure rates and disturbances at a time or on
//! a trigger. Read from TOML and validated completely before any run; every
//! problem is a positioned [`Diagnostic`] (file, line, column, what would be
//! valid). The format is documented in the README ("Simulator").

use super::skills::{self, Call, Unresolved};
use super::world::{Layout, Object, P2, Params, Place, Rect, World};
use crate::diagnostic::{Diagnostic, SourceFile, suggest};
use crate::format::{self, Limits};
use crate::model::{Policy, PolicyBody, SkillCall, StateBody, skill::SKILLS};
use std::collections::BTreeMap;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use toml::Spanned;
use toml::de::{DeTable, DeValue};

pub mod expect;
pub mod mc;

type Val<'i> = Spanned<DeValue<'i>>;

/// What a policy does once it has reported SUCCESS, or FAILURE (a property
/// of the run, written per policy in the scenario: `after_success`,
/// `after_failure`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Afterwards {
    /// No longer ticked: the robot stands idle (SMACH's final state; the
    /// default for FSMs and HFSMs).
    Stop,
    /// Ticked again every step: a BT from its root, a machine re-entered at
    /// its initial state (the default for BTs, as the paper describes).
    KeepTicking,
}

impl Afterwards {
    pub fn as_str(self) -> &'static str {
        match self {
            Afterwards::Stop => "stop",
            Afterwards::KeepTicking => "keep-ticking",
        }
    }
}

/// A policy of a scenario.
#[derive(Debug, Clone)]
pub struct PolicyEntry {
    /// The file as written in the scenario, resolved against its folder.
    pub file: PathBuf,
    /// `Some("hfsm")` when the scenario asks to convert the BT to an HFSM.
    pub convert: Option<String>,
    /// The policy as run (converted when asked; named by the entry's
    /// `name` when it has one).
    pub policy: Policy,
    /// What the policy does after SUCCESS.
    pub after_success: Afterwards,
    /// What the policy does after FAILURE.
    pub after_failure: Afterwards,
}

/// When a disturbance fires.
#[derive(Debug, Clone, PartialEq)]
pub enum When {
    /// At this simulated time, s.
    At(f64),
    /// This many seconds after the policy first reports that it is done.
    AfterDone(f64),
    /// The first step at which every term holds.
    Holds(Vec<(Call, bool)>),
}

/// What a disturbance does.
#[derive(Debug, Clone, PartialEq)]
pub enum Effect {
    Battery(f64),
    Move { object: usize, to: P2 },
    Drop { object: usize },
    Fail { skill: String, times: u32 },
    Block(Rect),
    Emergency(bool),
}

#[derive(Debug, Clone, PartialEq)]
pub struct Disturbance {
    pub when: When,
    pub effect: Effect,
    /// Human text for events and the report.
    pub text: String,
}

pub use mc::{BatteryDrop, MonteCarlo};

#[derive(Debug, Clone)]
pub struct Scenario {
    pub name: String,
    pub description: Option<String>,
    pub seed: u64,
    /// Step length, s.
    pub dt: f64,
    pub max_steps: u64,
    /// Times an abstract state (world facts, running skills) may be entered
    /// without progress toward the goal before the run is a livelock
    /// (outcome `chattering`): entered this many times, it ends the run.
    pub livelock_repeats: u32,
    /// Action failures without progress after which a run gives up.
    pub max_failures: u32,
    pub world: World,
    pub policies: Vec<PolicyEntry>,
    pub rates: BTreeMap<String, f64>,
    pub disturbances: Vec<Disturbance>,
    /// The task's goal (all terms hold at the end), if given.
    pub goal: Option<Vec<(Call, bool)>>,
    pub monte_carlo: MonteCarlo,
    /// The `[expect]` table, in the order written.
    pub expect: Vec<expect::Expectation>,
    /// Warnings (positioned) about a scenario that is valid.
    pub warnings: Vec<Diagnostic>,
}

/// Reads and validates a scenario and the policies it names.
pub fn load(path: &Path, limits: &Limits) -> Result<Scenario, Vec<Diagnostic>> {
    let shown = path.display().to_string();
    // Bounded by --max-file-bytes, pipes and devices included.
    let file = format::toml::read_source(path, &shown, limits)?;
    let base = path.parent().unwrap_or(Path::new("")).to_path_buf();
    parse(&file, &base, limits)
}

/// Parses a scenario from a source file; policies resolve against `base`.
pub fn parse(
    file: &Arc<SourceFile>,
    base: &Path,
    limits: &Limits,
) -> Result<Scenario, Vec<Diagnostic>> {
    let mut r = Reader {
        file: file.clone(),
        diags: Vec::new(),
        terms: 0,
    };
    // The policies and their includes stay inside the scenario's root.
    let root = format::source::root_for(limits, base);
    let limits = &Limits {
        confinement: root.map_or(format::source::Confinement::Off, |r| {
            format::source::Confinement::Root(r)
        }),
        ..limits.clone()
    };
    // The first TOML error only: the recoverable parser keeps them all.
    let doc = match DeTable::parse(&file.text) {
        Ok(doc) => doc,
        Err(e) => {
            return Err(std::iter::once(e)
                .map(|e| {
                    Diagnostic::error(format!(
                        "invalid TOML: {}",
                        e.message().trim().trim_end_matches('.')
                    ))
                    .at(file, e.span().unwrap_or(0..0))
                    .hint("see the scenario format in the README (Simulator)")
                })
                .collect());
        }
    };
    let s = r.scenario(doc.get_ref(), base, limits);
    match s {
        Some(mut s) if r.diags.iter().all(|d| !d.is_error()) => {
            s.warnings = r.diags;
            Ok(s)
        }
        _ => {
            if r.diags.is_empty() {
                r.diags
                    .push(Diagnostic::error("invalid scenario").in_file(file));
            }
            // The scenario's own problems first, then those of its policies.
            r.diags.sort_by_key(|d| {
                (
                    d.file.as_ref().map(|f| f.path != file.path),
                    d.file.as_ref().map(|f| f.path.clone()),
                    d.span.as_ref().map_or(0, |s| s.start),
                )
            });
            Err(r.diags)
        }
    }
}

/// Policies per scenario: their verdicts are pairwise, so 64 policies give
/// 2016 verdicts (a fixed limit; docs/robustness.md, Limits).
pub const MAX_POLICIES: usize = 64;
/// Stations of `[world.stations]` (the paper room's seven included), objects
/// of `[world.objects]`, obstacles of `[world.obstacles]` and `block`
/// disturbances together, and disturbances: a fixed limit on each, so that
/// checks pairing them (every pose against every obstacle, every object
/// against every station in a final world) stay small.
pub const MAX_STATIONS: usize = 1024;
pub const MAX_OBJECTS: usize = 1024;
pub const MAX_OBSTACLES: usize = 1024;
pub const MAX_DISTURBANCES: usize = 1024;
/// Condition terms in all the lists of a scenario together (`goal`, the
/// disturbances' `when`): those of pending disturbances are evaluated
/// every step.
pub const MAX_TERMS: usize = 1024;

struct Reader {
    file: Arc<SourceFile>,
    diags: Vec<Diagnostic>,
    /// Condition terms read so far (at most [`MAX_TERMS`]).
    terms: usize,
}

/// A number as messages show it: short (`1e300`, not 301 digits).
pub fn show(x: f64) -> String {
    if x.is_finite() && x != 0.0 && !(1e-6..1e15).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

fn num(v: &DeValue<'_>) -> Option<f64> {
    match v {
        DeValue::Integer(i) => i64::from_str_radix(&i.as_str().replace('_', ""), i.radix())
            .ok()
            .map(|x| x as f64),
        DeValue::Float(f) => f.as_str().replace('_', "").parse().ok(),
        _ => None,
    }
}

/// The `[world] params` a scenario may set, with their ranges
/// (docs/simulator-model.md gives their meaning and defaults).
pub const PARAMS: &[(&str, f64, f64)] = &[
    ("max_speed", 0.01, 10.0),
    ("max_turn_rate", 0.01, 100.0),
    ("drain_per_m", 0.0, 100.0),
    ("drain_per_s", 0.0, 100.0),
    ("charge_per_s", 0.01, 1000.0),
    ("low_battery", 0.0, 100.0),
    ("camera_range", 0.0, 100.0),
    ("object_tolerance", 0.0, 1.0),
    ("reach", 0.0, 1.0),
    ("stall_s", 0.0, 1000.0),
    ("manipulation_s", 0.0, 1000.0),
    ("arm_s", 0.0, 1000.0),
];

/// Largest `max_steps`: a run records its trajectory (16 bytes a step).
pub const MAX_STEPS: u64 = 1_000_000;

const TOP_KEYS: &[&str] = &[
    "name",
    "description",
    "seed",
    "dt",
    "max_steps",
    "chatter_switches",
    "livelock_repeats",
    "max_failures",
    "expect",
    "goal",
    "world",
    "policies",
    "rates",
    "disturbances",
    "monte_carlo",
];

impl Reader {
    fn err(&mut self, span: Range<usize>, msg: impl Into<String>, hint: impl Into<String>) {
        self.diags
            .push(Diagnostic::error(msg).at(&self.file, span).hint(hint));
    }

    fn keys(&mut self, t: &DeTable<'_>, allowed: &[&str], what: &str) {
        for (k, _) in t.iter() {
            if !allowed.contains(&k.get_ref().as_ref()) {
                let h = suggest(k.get_ref(), allowed.iter().copied());
                self.err(k.span(), format!("unknown {what} `{}`", k.get_ref()), h);
            }
        }
    }

    /// Refuses a collection of more than `max` entries (at its value, before
    /// any entry is read).
    fn at_most(&mut self, span: Range<usize>, n: usize, max: usize, what: &str) -> bool {
        if n <= max {
            return true;
        }
        self.err(
            span,
            format!("{n} {what}, more than the limit of {max}"),
            format!("a scenario holds at most {max} {what} (a fixed limit)"),
        );
        false
    }

    fn number(&mut self, v: &Val<'_>, what: &str, min: f64, max: f64) -> Option<f64> {
        match num(v.get_ref()) {
            Some(x) if !x.is_finite() => {
                self.err(
                    v.span(),
                    format!("{what} must be a finite number, found {}", show(x)),
                    format!("write a number from {min} to {max}"),
                );
                None
            }
            Some(x) if (min..=max).contains(&x) => Some(x),
            Some(x) => {
                self.err(
                    v.span(),
                    format!("{what} must be between {min} and {max}, found {}", show(x)),
                    format!("write a number from {min} to {max}"),
                );
                None
            }
            None => {
                self.err(
                    v.span(),
                    format!("{what} must be a number"),
                    "write e.g. `1.5`",
                );
                None
            }
        }
    }

    /// A TOML integer from `min` to `max` (`1.5`, `1e3` and `nan` refused).
    fn integer(&mut self, v: &Val<'_>, what: &str, min: u64, max: u64) -> Option<u64> {
        let parsed = match v.get_ref() {
            DeValue::Integer(i) => {
                i64::from_str_radix(&i.as_str().replace('_', ""), i.radix()).ok()
            }
            _ => None,
        };
        match parsed {
            Some(x) if x >= 0 && (min..=max).contains(&(x as u64)) => Some(x as u64),
            Some(x) => {
                self.err(
                    v.span(),
                    format!("{what} must be between {min} and {max}, found {x}"),
                    format!("write a whole number from {min} to {max}"),
                );
                None
            }
            None => {
                let found = match num(v.get_ref()) {
                    Some(x) => format!(", found {}", show(x)),
                    None => String::new(),
                };
                self.err(
                    v.span(),
                    format!("{what} must be an integer{found}"),
                    format!("write a whole number from {min} to {max}, e.g. `{min}`"),
                );
                None
            }
        }
    }

    /// `[lo, hi]` with `min <= lo <= hi <= max` (a range of levels or times).
    fn range(&mut self, v: &Val<'_>, what: &str, min: f64, max: f64) -> Option<(f64, f64)> {
        if let Some(a) = v.get_ref().as_array()
            && a.len() == 2
            && let (Some(lo), Some(hi)) = (num(a[0].get_ref()), num(a[1].get_ref()))
            && min <= lo
            && lo <= hi
            && hi <= max
        {
            return Some((lo, hi));
        }
        self.err(
            v.span(),
            format!("{what} must be a range `[low, high]` of finite numbers with {min} <= low <= high <= {max}"),
            format!("write e.g. `[{min}, {max}]`"),
        );
        None
    }

    fn string(&mut self, v: &Val<'_>, what: &str) -> Option<String> {
        match v.get_ref().as_str() {
            Some(s) => Some(s.to_string()),
            None => {
                self.err(
                    v.span(),
                    format!("{what} must be a string"),
                    "write it in quotes",
                );
                None
            }
        }
    }

    fn table<'a, 'i>(&mut self, v: &'a Val<'i>, what: &str) -> Option<&'a DeTable<'i>> {
        match v.get_ref().as_table() {
            Some(t) => Some(t),
            None => {
                self.err(
                    v.span(),
                    format!("{what} must be a table"),
                    "write `{ ... }`",
                );
                None
            }
        }
    }

    fn array<'a, 'i>(&mut self, v: &'a Val<'i>, what: &str) -> Option<&'a [Val<'i>]> {
        match v.get_ref().as_array() {
            Some(a) => Some(a),
            None => {
                self.err(
                    v.span(),
                    format!("{what} must be an array"),
                    "write `[ ... ]`",
                );
                None
            }
        }
    }

    /// `[x, y]` numbers.
    fn point(&mut self, v: &Val<'_>, what: &str) -> Option<P2> {
        if let Some(a) = v.get_ref().as_array()
            && a.len() == 2
            && let (Some(x), Some(y)) = (num(a[0].get_ref()), num(a[1].get_ref()))
            && x.is_finite()
            && y.is_finite()
        {
            return Some((x, y));
        }
        self.err(
            v.span(),
            format!("{what} must be a position `[x, y]` in metres (finite numbers)"),
            "write e.g. `[0.5, 2.1]`",
        );
        None
    }

    /// A station name or `[x, y]`; checked free of walls and obstacles.
    fn pose(&mut self, v: &Val<'_>, what: &str, layout: &Layout, radius: f64) -> Option<P2> {
        let p = match v.get_ref().as_str() {
            Some(name) => match layout.station(name) {
                Some(p) => p,
                None => {
                    let h = suggest(name, layout.stations.iter().map(|(n, _)| n.as_str()));
                    self.err(v.span(), format!("unknown station `{name}`"), h);
                    return None;
                }
            },
            None => self.point(v, what)?,
        };
        if let Err(what_hit) = layout.check_free(p, radius) {
            self.err(
                v.span(),
                format!(
                    "{what} ({}, {}) is inside {what_hit}",
                    p.0, p.1
                ),
                format!(
                    "the robot (radius {radius} m) must fit inside the room [{}, {}] x [{}, {}] clear of the obstacles",
                    layout.room.x0, layout.room.x1, layout.room.y0, layout.room.y1
                ),
            );
            return None;
        }
        Some(p)
    }

    fn unresolved(&mut self, span: Range<usize>, u: Unresolved) {
        self.err(span, u.message, u.hint);
    }

    /// A condition term `{ if = "Skill", args = {...} }` or `unless`.
    fn term(&mut self, v: &Val<'_>, world: &World) -> Option<(Call, bool)> {
        let t = self.table(v, "a condition")?;
        self.keys(t, &["if", "unless", "args"], "field of a condition");
        let (neg, c) = match (t.get("if"), t.get("unless")) {
            (Some(c), None) => (false, c),
            (None, Some(c)) => (true, c),
            _ => {
                self.err(
                    v.span(),
                    "a condition needs exactly one of `if` or `unless`",
                    "write `{ if = \"In-Hand\", args = { object = \"cube2\" } }`",
                );
                return None;
            }
        };
        let name = self.string(c, "the condition")?;
        let mut args = BTreeMap::new();
        if let Some(a) = t.get("args") {
            for (k, v) in self.table(a, "`args`")?.iter() {
                let val = match v.get_ref() {
                    DeValue::String(s) => crate::model::ArgValue::Str(s.to_string()),
                    other => match num(other) {
                        Some(x) if x.is_finite() => crate::model::ArgValue::Float(x),
                        _ => {
                            self.err(
                                v.span(),
                                "an argument must be a name or a finite number",
                                "",
                            );
                            return None;
                        }
                    },
                };
                args.insert(k.get_ref().to_string(), val);
            }
        }
        if skills::resolve(
            &SkillCall {
                skill: name.clone(),
                args: BTreeMap::new(),
            },
            world,
        )
        .is_err_and(|u| u.message.starts_with("unknown skill"))
        {
            let conds = crate::model::skill::skill_names(crate::model::SkillKind::Condition);
            self.err(
                c.span(),
                format!("unknown condition `{name}`"),
                suggest(&name, conds),
            );
            return None;
        }
        match skills::resolve(&SkillCall { skill: name, args }, world) {
            Ok(call) if !call.is_action() => Some((call, neg)),
            Ok(call) => {
                self.err(
                    c.span(),
                    format!("`{}` is an action, not a condition", call.name()),
                    "conditions: Robot-At, In-Hand, Object-At, Battery-Level, Arm-Tucked, Found, No-Emergency",
                );
                None
            }
            Err(u) => {
                self.unresolved(v.span(), u);
                None
            }
        }
    }

    fn terms(&mut self, v: &Val<'_>, world: &World) -> Option<Vec<(Call, bool)>> {
        let a = self.array(v, "a list of conditions")?;
        self.terms += a.len();
        if !self.at_most(
            v.span(),
            self.terms,
            MAX_TERMS,
            "condition terms (`goal` and every `when` together)",
        ) {
            return None;
        }
        let mut out = Vec::new();
        for t in a {
            out.push(self.term(t, world)?);
        }
        Some(out)
    }

    fn world(&mut self, v: Option<&Val<'_>>) -> Option<World> {
        let mut layout = Layout::paper_room();
        let mut params = Params::default();
        let mut robot = layout.station("start").expect("the paper room has a start");
        let mut objects = Vec::new();
        let mut battery = 100.0;
        let mut placed: Vec<(Range<usize>, usize)> = Vec::new();
        let Some(v) = v else {
            return Some(World::new(layout, params, robot, objects));
        };
        let t = self.table(v, "`world`")?;
        self.keys(
            t,
            &[
                "robot",
                "battery",
                "params",
                "obstacles",
                "stations",
                "objects",
            ],
            "field of `world`",
        );
        if let Some(p) = t.get("params") {
            let pt = self.table(p, "`world.params`")?;
            self.keys(
                pt,
                &(PARAMS.iter().map(|p| p.0))
                    .chain(["follow_belief"])
                    .collect::<Vec<_>>(),
                "world parameter",
            );
            for (k, v) in pt.iter() {
                if k.get_ref().as_ref() == "follow_belief" {
                    match v.get_ref() {
                        DeValue::Boolean(b) => params.follow_belief = *b,
                        _ => self.err(
                            v.span(),
                            "`follow_belief` must be true or false",
                            "write `follow_belief = true`",
                        ),
                    }
                    continue;
                }
                let Some(&(name, lo, hi)) = PARAMS.iter().find(|p| p.0 == k.get_ref().as_ref())
                else {
                    continue;
                };
                let Some(x) = self.number(v, &format!("`{name}`"), lo, hi) else {
                    continue;
                };
                match name {
                    "max_speed" => params.max_speed = x,
                    "max_turn_rate" => params.max_turn_rate = x,
                    "drain_per_m" => params.drain_per_m = x,
                    "drain_per_s" => params.drain_per_s = x,
                    "charge_per_s" => params.charge_per_s = x,
                    "low_battery" => params.low_battery = x,
                    "camera_range" => params.camera_range = x,
                    "object_tolerance" => params.object_tolerance = x,
                    "reach" => params.reach = x,
                    "stall_s" => params.stall_s = x,
                    "manipulation_s" => params.manipulation_s = x,
                    "arm_s" => params.arm_s = x,
                    _ => {}
                }
            }
        }
        if let Some(o) = t.get("obstacles") {
            let a = self.array(o, "`world.obstacles`")?;
            if !self.at_most(o.span(), a.len(), MAX_OBSTACLES, "obstacles") {
                return None;
            }
            for ob in a.iter() {
                if let Some(r) = self.rect(ob) {
                    placed.push((ob.span(), layout.obstacles.len()));
                    layout.obstacles.push(r);
                }
            }
        }
        if let Some(s) = t.get("stations") {
            let st = self.table(s, "`world.stations`")?;
            // The paper room's stations count too (a scenario may move them).
            let new = st
                .iter()
                .filter(|(k, _)| layout.station(k.get_ref()).is_none());
            let n = layout.stations.len() + new.count();
            if !self.at_most(s.span(), n, MAX_STATIONS, "stations") {
                return None;
            }
            for (k, v) in st.iter() {
                if let Some(p) = self.point(v, "a station") {
                    layout.set_station(k.get_ref(), p);
                }
            }
            // Checked after every obstacle is known.
            for (k, v) in self.table(s, "`world.stations`")?.iter() {
                let _ = self.pose(
                    v,
                    &format!("station `{}`", k.get_ref()),
                    &layout,
                    params.robot_radius,
                );
            }
        }
        // The room's stations the scenario keeps where they are must stay
        // free (those it sets were checked above, at their own position).
        let set: Vec<&str> = match t.get("stations").and_then(|s| s.get_ref().as_table()) {
            Some(st) => st.iter().map(|(k, _)| k.get_ref().as_ref()).collect(),
            None => Vec::new(),
        };
        let kept: Vec<(String, P2)> = (layout.stations.iter())
            .filter(|(n, _)| !set.contains(&n.as_str()))
            .cloned()
            .collect();
        for (span, i) in placed {
            let r = layout.obstacles[i].clone();
            self.covers_no_station(span, &r, &kept, params.robot_radius, "obstacle");
        }
        if let Some(b) = t.get("battery")
            && let Some(x) = self.number(b, "`battery`", 0.0, 100.0)
        {
            battery = x;
        }
        if let Some(rv) = t.get("robot")
            && let Some(p) = self.pose(rv, "the robot's start", &layout, params.robot_radius)
        {
            robot = p;
        }
        if let Some(ov) = t.get("objects") {
            let ot = self.table(ov, "`world.objects`")?;
            if !self.at_most(ov.span(), ot.len(), MAX_OBJECTS, "objects") {
                return None;
            }
            for (k, v) in ot.iter() {
                let name = k.get_ref().to_string();
                let Some(ot) = self.table(v, &format!("object `{name}`")) else {
                    continue;
                };
                self.keys(ot, &["at", "found"], "field of an object");
                let Some(at) = ot.get("at") else {
                    self.err(
                        v.span(),
                        format!("object `{name}` needs `at`"),
                        "write `at = \"east-table\"` or `at = [1.7, 0.0]`",
                    );
                    continue;
                };
                let Some(p) = self.pose(
                    at,
                    &format!("object `{name}`"),
                    &layout,
                    params.robot_radius,
                ) else {
                    continue;
                };
                let found = match ot.get("found") {
                    Some(f) => match f.get_ref() {
                        DeValue::Boolean(b) => *b,
                        _ => {
                            self.err(f.span(), "`found` must be true or false", "");
                            true
                        }
                    },
                    None => true,
                };
                // On the table in front of its pose, or on the floor.
                let place = match layout.surface_near(p, params.robot_radius) {
                    Some(_) => Place::At(p),
                    None => Place::Floor(p),
                };
                objects.push(Object::new(&name, place, p, found));
            }
        }
        let mut w = World::new(layout, params, robot, objects);
        w.battery = battery;
        Some(w)
    }

    /// Refuses an obstacle or a `block` over a station (or the robot's
    /// start): the robot must fit at every station. O(stations).
    fn covers_no_station(
        &mut self,
        span: Range<usize>,
        r: &Rect,
        stations: &[(String, P2)],
        radius: f64,
        what: &str,
    ) -> bool {
        let hit = stations.iter().find(|(_, p)| r.distance(*p) < radius);
        if let Some((n, p)) = hit {
            self.err(
                span,
                format!(
                    "{what} `{}` covers station `{n}` ({}, {})",
                    r.name,
                    show(p.0),
                    show(p.1)
                ),
                format!(
                    "keep it at least the robot's radius ({radius} m) away from every station, or move the station"
                ),
            );
            return false;
        }
        true
    }

    fn rect(&mut self, v: &Val<'_>) -> Option<Rect> {
        let t = self.table(v, "an obstacle")?;
        self.keys(t, &["name", "rect"], "field of an obstacle");
        let name = match t.get("name") {
            Some(n) => self.string(n, "`name`")?,
            None => "obstacle".into(),
        };
        let Some(rv) = t.get("rect") else {
            self.err(v.span(), "an obstacle needs `rect = [x0, y0, x1, y1]`", "");
            return None;
        };
        let nums: Vec<f64> = rv
            .get_ref()
            .as_array()
            .map(|a| {
                a.iter()
                    .take(5)
                    .filter_map(|x| num(x.get_ref()))
                    .filter(|x| x.is_finite())
                    .collect()
            })
            .unwrap_or_default();
        let len = rv.get_ref().as_array().map_or(0, |a| a.len());
        if len != 4 || nums.len() != 4 || nums[0] == nums[2] || nums[1] == nums[3] {
            self.err(
                rv.span(),
                "`rect` must be four finite numbers `[x0, y0, x1, y1]` with x0 != x1 and y0 != y1",
                "write e.g. `rect = [-0.5, 1.2, 0.5, 1.4]`",
            );
            return None;
        }
        Some(Rect::new(&name, nums[0], nums[1], nums[2], nums[3]))
    }

    fn skill_name(&mut self, v: &Val<'_>) -> Option<String> {
        let s = self.string(v, "the skill")?;
        if SKILLS.iter().any(|(n, _, _)| *n == s) {
            Some(s)
        } else {
            let h = suggest(&s, SKILLS.iter().map(|(n, _, _)| *n));
            self.err(v.span(), format!("unknown skill `{s}`"), h);
            None
        }
    }

    fn rates(&mut self, v: &Val<'_>) -> Option<BTreeMap<String, f64>> {
        let t = self.table(v, "`rates`")?;
        let mut out = BTreeMap::new();
        for (k, v) in t.iter() {
            let name = k.get_ref().to_string();
            if !SKILLS.iter().any(|(n, _, _)| *n == name) {
                let h = suggest(&name, SKILLS.iter().map(|(n, _, _)| *n));
                self.err(k.span(), format!("unknown skill `{name}`"), h);
                continue;
            }
            if let Some(p) = self.number(v, &format!("the failure rate of `{name}`"), 0.0, 1.0) {
                out.insert(name, p);
            }
        }
        Some(out)
    }

    fn disturbance(&mut self, v: &Val<'_>, world: &World) -> Option<Disturbance> {
        let t = self.table(v, "a disturbance")?;
        self.keys(
            t,
            &[
                "at",
                "after_done",
                "when",
                "battery",
                "move",
                "to",
                "drop",
                "fail",
                "times",
                "block",
                "emergency",
            ],
            "field of a disturbance",
        );
        let whens: Vec<&str> = ["at", "after_done", "when"]
            .into_iter()
            .filter(|k| t.contains_key(*k))
            .collect();
        if whens.len() != 1 {
            self.err(
                v.span(),
                "a disturbance needs exactly one trigger: `at`, `after_done` or `when`",
                "write `at = 12.0` (seconds), `after_done = 2.0` or `when = [{ if = \"In-Hand\", args = { object = \"cube2\" } }]`",
            );
            return None;
        }
        let when = match whens[0] {
            "at" => When::At(self.number(t.get("at").expect("checked above"), "`at`", 0.0, 1e9)?),
            "after_done" => When::AfterDone(self.number(
                t.get("after_done").expect("checked above"),
                "`after_done`",
                0.0,
                1e9,
            )?),
            _ => When::Holds(self.terms(t.get("when").expect("checked above"), world)?),
        };
        let effects: Vec<&str> = ["battery", "move", "drop", "fail", "block", "emergency"]
            .into_iter()
            .filter(|k| t.contains_key(*k))
            .collect();
        if effects.len() != 1 {
            self.err(
                v.span(),
                "a disturbance needs exactly one effect: `battery`, `move`, `drop`, `fail`, `block` or `emergency`",
                "write e.g. `battery = 15` or `move = \"cube2\", to = \"east-table\"`",
            );
            return None;
        }
        let obj = |r: &mut Self, key: &str| -> Option<usize> {
            let v = &t[key];
            let name = r.string(v, &format!("`{key}`"))?;
            match world.object_index(&name) {
                Some(i) => Some(i),
                None => {
                    let h = suggest(&name, world.objects.iter().map(|o| o.name.as_str()));
                    r.err(v.span(), format!("unknown object `{name}`"), h);
                    None
                }
            }
        };
        let (effect, text) = match effects[0] {
            "battery" => {
                let b = self.number(
                    t.get("battery").expect("checked above"),
                    "`battery`",
                    0.0,
                    100.0,
                )?;
                (Effect::Battery(b), format!("battery set to {b}%"))
            }
            "move" => {
                let o = obj(self, "move")?;
                let Some(to) = t.get("to") else {
                    self.err(
                        v.span(),
                        "`move` needs `to`",
                        "write `to = \"east-table\"` or `to = [1.7, 0.0]`",
                    );
                    return None;
                };
                let p = self.pose(
                    to,
                    "the new place",
                    &world.layout,
                    world.params.robot_radius,
                )?;
                (
                    Effect::Move { object: o, to: p },
                    format!("{} moved to ({}, {})", world.objects[o].name, p.0, p.1),
                )
            }
            "drop" => {
                let o = obj(self, "drop")?;
                (
                    Effect::Drop { object: o },
                    format!("{} dropped", world.objects[o].name),
                )
            }
            "fail" => {
                let s = self.skill_name(t.get("fail").expect("checked above"))?;
                let n = match t.get("times") {
                    Some(n) => self.integer(n, "`times`", 1, 1_000_000)? as u32,
                    None => 1,
                };
                (
                    Effect::Fail {
                        skill: s.clone(),
                        times: n,
                    },
                    format!(
                        "{s} fails the next {n} time{}",
                        if n == 1 { "" } else { "s" }
                    ),
                )
            }
            "block" => {
                let bv = t.get("block").expect("checked above");
                let r = self.rect(bv)?;
                if !self.covers_no_station(
                    bv.span(),
                    &r,
                    &world.layout.stations,
                    world.params.robot_radius,
                    "`block`",
                ) {
                    return None;
                }
                if r.distance(world.robot) < world.params.robot_radius {
                    self.err(
                        bv.span(),
                        format!("`block` `{}` covers the robot's start ({}, {})", r.name, show(world.robot.0), show(world.robot.1)),
                        "a box cannot land on the robot; move it (a block that would cover the robot during a run is refused, with an event)",
                    );
                    return None;
                }
                let text = format!("path blocked by {}", r.name);
                (Effect::Block(r), text)
            }
            _ => match t.get("emergency").expect("checked above").get_ref() {
                DeValue::Boolean(b) => (
                    Effect::Emergency(*b),
                    if *b {
                        "emergency".into()
                    } else {
                        "emergency over".into()
                    },
                ),
                _ => {
                    self.err(
                        t.get("emergency").expect("checked above").span(),
                        "`emergency` must be true or false",
                        "",
                    );
                    return None;
                }
            },
        };
        Some(Disturbance { when, effect, text })
    }

    fn scenario(&mut self, t: &DeTable<'_>, base: &Path, limits: &Limits) -> Option<Scenario> {
        self.keys(t, TOP_KEYS, "top-level key");
        let name = match t.get("name") {
            Some(n) => self.string(n, "`name`")?,
            None => Path::new(&self.file.path)
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_default(),
        };
        let description = match t.get("description") {
            Some(d) => self.string(d, "`description`"),
            None => None,
        };
        let seed = t
            .get("seed")
            .and_then(|v| self.integer(v, "`seed`", 0, i64::MAX as u64))
            .unwrap_or(1);
        let dt = t
            .get("dt")
            .and_then(|v| self.number(v, "`dt`", 0.001, 10.0))
            .unwrap_or(0.1);
        let max_steps = t
            .get("max_steps")
            .and_then(|v| self.integer(v, "`max_steps`", 1, MAX_STEPS))
            .unwrap_or(20_000);
        if let Some(v) = t.get("chatter_switches")
            && self
                .integer(v, "`chatter_switches`", 2, 1_000_000)
                .is_some()
        {
            self.diags.push(
                Diagnostic::warning("`chatter_switches` is no longer used: a livelock is a recurring abstract state without progress toward the goal")
                    .at(&self.file, v.span())
                    .hint("remove it; `livelock_repeats` (default 3) sets how often a state may recur"),
            );
        }
        let livelock_repeats = t
            .get("livelock_repeats")
            .and_then(|v| self.integer(v, "`livelock_repeats`", 2, 1_000_000))
            .unwrap_or(3) as u32;
        let max_failures = t
            .get("max_failures")
            .and_then(|v| self.integer(v, "`max_failures`", 1, 1_000_000))
            .unwrap_or(50) as u32;
        let world = self.world(t.get("world"))?;
        let rates = match t.get("rates") {
            Some(r) => self.rates(r)?,
            None => BTreeMap::new(),
        };
        let goal = match t.get("goal") {
            Some(g) => Some(self.terms(g, &world)?),
            None => None,
        };
        let mut disturbances = Vec::new();
        if let Some(d) = t.get("disturbances") {
            let a = self.array(d, "`disturbances`")?;
            if !self.at_most(d.span(), a.len(), MAX_DISTURBANCES, "disturbances") {
                return None;
            }
            // Every `block` adds an obstacle.
            let blocks = (a.iter())
                .filter(|x| {
                    x.get_ref()
                        .as_table()
                        .is_some_and(|t| t.contains_key("block"))
                })
                .count();
            let obstacles = world.layout.obstacles.len() + blocks;
            if !self.at_most(
                d.span(),
                obstacles,
                MAX_OBSTACLES,
                "obstacles (`block` disturbances included)",
            ) {
                return None;
            }
            for x in a {
                if let Some(d) = self.disturbance(x, &world) {
                    disturbances.push(d);
                }
            }
        }
        let monte_carlo = match t.get("monte_carlo") {
            Some(m) => self.monte_carlo(m, &world)?,
            None => MonteCarlo::default(),
        };
        let mut policies = Vec::new();
        match t.get("policies") {
            None => self.err(
                0..0,
                "a scenario needs at least one policy",
                "add `[[policies]]` with `file = \"../paper/fig01-bt.toml\"`",
            ),
            Some(p) => {
                let a = self.array(p, "`policies`")?;
                if !self.at_most(p.span(), a.len(), MAX_POLICIES, "policies") {
                    return None;
                }
                for e in a {
                    if let Some(pe) = self.policy(e, base, limits, &world) {
                        policies.push(pe);
                    }
                }
            }
        }
        let expect = match t.get("expect") {
            Some(e) => {
                let names: Vec<String> = policies.iter().map(|p| p.policy.name.clone()).collect();
                self.expect(e, &names, goal.is_some())
            }
            None => Vec::new(),
        };
        Some(Scenario {
            expect,
            warnings: Vec::new(),
            name,
            description,
            seed,
            dt,
            max_steps,
            livelock_repeats,
            max_failures,
            world,
            policies,
            rates,
            disturbances,
            goal,
            monte_carlo,
        })
    }

    /// `after_success` / `after_failure`: `"stop"` or `"keep-ticking"`.
    fn afterwards(&mut self, v: Option<&Val<'_>>, key: &str, keep: bool) -> Option<Afterwards> {
        let Some(a) = v else {
            return Some(if keep {
                Afterwards::KeepTicking
            } else {
                Afterwards::Stop
            });
        };
        match a.get_ref().as_str() {
            Some("stop") => Some(Afterwards::Stop),
            Some("keep-ticking") => Some(Afterwards::KeepTicking),
            _ => {
                self.err(
                    a.span(),
                    format!("`{key}` must be \"stop\" or \"keep-ticking\""),
                    format!("write `{key} = \"keep-ticking\"` to tick the policy again (a BT's default), `\"stop\"` to end it (an FSM's and an HFSM's)"),
                );
                None
            }
        }
    }

    fn policy(
        &mut self,
        v: &Val<'_>,
        base: &Path,
        limits: &Limits,
        world: &World,
    ) -> Option<PolicyEntry> {
        let t = self.table(v, "a policy entry")?;
        self.keys(
            t,
            &["file", "convert", "name", "after_success", "after_failure"],
            "field of a policy entry",
        );
        let Some(f) = t.get("file") else {
            self.err(
                v.span(),
                "a policy entry needs `file`",
                "write `file = \"../paper/fig01-bt.toml\"` (relative to the scenario)",
            );
            return None;
        };
        let rel = self.string(f, "`file`")?;
        let root = format::source::root_for(limits, base);
        let path = match format::source::resolve(root.as_deref(), base, &rel) {
            Ok(p) => p,
            Err(r) if r.message == "no such file" => {
                self.err(
                    f.span(),
                    format!("policy file `{rel}` not found"),
                    format!(
                        "paths are relative to the scenario's folder (`{}`)",
                        base.display()
                    ),
                );
                return None;
            }
            Err(r) => {
                self.err(
                    f.span(),
                    format!("policy file `{rel}`: {}", r.message),
                    r.hint,
                );
                return None;
            }
        };
        let convert = match t.get("convert") {
            None => None,
            Some(c) => match c.get_ref().as_str() {
                Some("hfsm") => Some("hfsm".to_string()),
                _ => {
                    self.err(c.span(), "`convert` must be \"hfsm\"", "write `convert = \"hfsm\"` to run the BT converted to an HFSM (Fig. 5 -> Fig. 6)");
                    return None;
                }
            },
        };
        let loaded = match format::load(&path, limits) {
            Ok(l) => l,
            Err(d) => {
                self.diags.extend(d);
                return None;
            }
        };
        let mut policy = loaded.policy;
        if convert.is_some() {
            if !matches!(policy.body, PolicyBody::Bt(_)) {
                self.err(
                    f.span(),
                    format!("`{rel}` is not a BT and cannot be converted"),
                    "remove `convert`",
                );
                return None;
            }
            if let PolicyBody::Bt(bt) = &policy.body
                && let Some(&n) = crate::transform::bt_to_hfsm::memory_nodes(bt).first()
            {
                let node = &bt.nodes[n];
                self.err(
                    f.span(),
                    format!(
                        "the HFSM of `{rel}` would not behave as the BT: its `{}` node `{}` keeps memory, and the construction re-enters containers at their first state every tick",
                        node.kind.keyword(),
                        node.id
                    ),
                    "run the BT itself, or make the node reactive (sequence / fallback); `btfsm convert --to hfsm` still gives the HFSM to count",
                );
                return None;
            }
            match crate::transform::bt_to_hfsm::bt_policy_to_hfsm(&policy) {
                Ok(p) => policy = p,
                Err(e) => {
                    self.err(
                        f.span(),
                        e[0].to_string(),
                        "only sequence, fallback and simple decorators convert",
                    );
                    return None;
                }
            }
        }
        check_bindings(&policy, &loaded.path, limits, world, &mut self.diags);
        if convert.is_none()
            && let PolicyBody::Machine(m) = &policy.body
            && m.top.outcomes.iter().any(|o| o == "RUNNING")
            && let Some(st) = (m.states.iter()).find(|st| {
                matches!(st.body, StateBody::Container(_))
                    && (st.label == "Sequence*" || st.label == "Fallback*")
            })
        {
            self.diags.push(
                Diagnostic::warning(format!(
                    "`{rel}` looks converted from a BT with memory: its container `{}` ({}) is re-entered at its first state every tick, so it forgets the running child and does not behave as the BT",
                    st.name, st.label
                ))
                .at(&self.file, f.span())
                .hint("run the BT itself, or convert a BT whose composites are reactive (sequence / fallback)"),
            );
        }
        if let Some(n) = t.get("name") {
            policy.name = self.string(n, "`name`")?;
        }
        // Defaults: a BT keeps ticking after both (its root is ticked every
        // step); a machine stops, unless its top-level outcomes include
        // RUNNING (the Fig. 6 construction says it is ticked), which keeps
        // ticking after FAILURE.
        let (bt, tick_driven) = match &policy.body {
            PolicyBody::Bt(_) => (true, true),
            PolicyBody::Machine(m) => (false, m.top.outcomes.iter().any(|o| o == "RUNNING")),
        };
        let after_success = self.afterwards(t.get("after_success"), "after_success", bt)?;
        let after_failure =
            self.afterwards(t.get("after_failure"), "after_failure", tick_driven)?;
        Some(PolicyEntry {
            file: path,
            convert,
            policy,
            after_success,
            after_failure,
        })
    }
}

/// Span of the line `key = ...` (bare or quoted key) in a TOML text.
#[cfg(test)]
fn key_span(text: &str, key: &str) -> Option<Range<usize>> {
    key_spans(text, &[key].into_iter().collect()).remove(key)
}

/// Spans of the first lines `key = ...` (bare or quoted key) of the `keys`
/// in a TOML text, in one pass over it.
fn key_spans<'k>(
    text: &str,
    keys: &std::collections::HashSet<&'k str>,
) -> std::collections::HashMap<&'k str, Range<usize>> {
    let mut out = std::collections::HashMap::new();
    let mut off = 0;
    for line in text.split_inclusive('\n') {
        let t = line.trim_start();
        let lead = line.len() - t.len();
        if let Some((k, _)) = t.split_once('=') {
            let written = k.trim_end();
            let key = written
                .strip_prefix('"')
                .and_then(|q| q.strip_suffix('"'))
                .unwrap_or(written);
            if let Some(&k) = keys.get(key) {
                out.entry(k)
                    .or_insert(off + lead..off + lead + written.len());
            }
        }
        off += line.len();
    }
    out
}

/// Whether a TOML text is a scenario rather than a policy, from its head:
/// TOML puts top-level keys before the first table, so a policy says `kind`
/// before any header, and a scenario has `[world]` or `[[policies]]`.
pub fn looks_like_scenario(head: &str) -> bool {
    for line in head.lines() {
        let l = line.trim();
        if l.is_empty() || l.starts_with('#') {
            continue;
        }
        if let Some(h) = l.strip_prefix('[') {
            let h = h.trim_start_matches('[').trim_start();
            return ["world", "policies", "disturbances"]
                .iter()
                .any(|k| h.starts_with(k));
        }
        let key = l.split('=').next().unwrap_or("").trim().trim_matches('"');
        match key {
            "kind" => return false,
            "world" | "policies" => return true,
            _ => {}
        }
    }
    false
}

/// Checks that every binding of a policy runs in the world: positioned in the
/// policy file at the node or state.
/// The file is read again only to position the messages, and bounded as
/// when it was loaded (`--max-file-bytes`; a device or pipe stops there).
pub fn check_bindings(
    p: &Policy,
    path: &str,
    limits: &Limits,
    world: &World,
    diags: &mut Vec<Diagnostic>,
) {
    /// Where a problem is: a span of the policy file, or the include of
    /// the subtree it comes from (its key, found in the file's text).
    enum Pos {
        Span(Option<Range<usize>>),
        Include(String),
    }
    let mut problems: Vec<(String, Pos, Unresolved)> = Vec::new();
    let mut push = |what: String, pos: Pos, u: Unresolved| problems.push((what, pos, u));
    match &p.body {
        PolicyBody::Bt(bt) => {
            for n in &bt.nodes {
                // Nodes of an included subtree (`include/...`) have spans in
                // the included file: point at the include in this file.
                let span = || match n.id.split_once('/') {
                    None => Pos::Span(n.span.clone()),
                    Some((inc, _)) => Pos::Include(inc.to_string()),
                };
                if let Some(t) = crate::sim::exec::refused(n) {
                    push(
                        format!("node `{}`", n.id),
                        span(),
                        Unresolved {
                            message: format!("the simulator does not model the node type {t}"),
                            hint: "it executes the node types of docs/bt-semantics.md (sequence, fallback, sequence_memory, fallback_memory, parallel, inverter, force_success, force_failure, repeat, retry, timeout; IfThenElse, WhileDoElse, KeepRunningUntilFailure, ...)".into(),
                        },
                    );
                }
                if n.kind.arity() != crate::model::bt::Arity::Leaf {
                    continue;
                }
                let span = span();
                match &n.skill {
                    Some(c) => {
                        if let Err(u) = skills::resolve(c, world) {
                            push(format!("node `{}`", n.id), span, u);
                        }
                    }
                    None => push(
                        format!("node `{}`", n.id),
                        span,
                        Unresolved {
                            message: "no skill binding".into(),
                            hint: "the simulator needs `skill = \"...\"` on every leaf".into(),
                        },
                    ),
                }
            }
        }
        PolicyBody::Machine(m) => {
            for (i, s) in m.states.iter().enumerate() {
                if s.pseudo.is_some() {
                    push(
                        format!("state `{}`", m.path(i)),
                        Pos::Span(s.span.clone()),
                        Unresolved {
                            message: "the simulator does not execute history pseudo-states".into(),
                            hint: "re-entering a container at its last active state is not modelled; give the container an initial state instead".into(),
                        },
                    );
                    continue;
                }
                let mut calls: Vec<&SkillCall> = Vec::new();
                match &s.body {
                    StateBody::Task(Some(c)) => calls.push(c),
                    StateBody::Task(None) => push(
                        format!("state `{}`", m.path(i)),
                        Pos::Span(s.span.clone()),
                        Unresolved {
                            message: "no skill binding".into(),
                            hint: "the simulator needs `skill = \"...\"` on every state that is not a decision or container".into(),
                        },
                    ),
                    _ => {}
                }
                for t in &s.transitions {
                    if let crate::model::Trigger::Guard(g) = &t.trigger {
                        calls.extend(g.all.iter().map(|x| &x.condition));
                    }
                }
                for c in calls {
                    if let Err(u) = skills::resolve(c, world) {
                        push(
                            format!("state `{}`", m.path(i)),
                            Pos::Span(s.span.clone()),
                            u,
                        );
                    }
                }
            }
        }
    }
    if problems.is_empty() {
        return;
    }
    // At most this many messages per policy (the rest are counted), as the
    // policy readers do.
    const MAX_MESSAGES: usize = 200;
    let more = problems.len().saturating_sub(MAX_MESSAGES);
    problems.truncate(MAX_MESSAGES);
    // Read once more only to position the messages, bounded as when loaded.
    let src = format::toml::read_source(Path::new(path), path, limits).ok();
    let includes: std::collections::HashSet<&str> = (problems.iter())
        .filter_map(|(_, pos, _)| match pos {
            Pos::Include(k) => Some(k.as_str()),
            Pos::Span(_) => None,
        })
        .collect();
    let spans = match &src {
        Some(f) if !includes.is_empty() => key_spans(&f.text, &includes),
        _ => Default::default(),
    };
    for (what, pos, u) in &problems {
        let mut d = Diagnostic::error(format!("{} in {what}", u.message)).hint(u.hint.clone());
        if let Some(f) = &src {
            let span = match pos {
                Pos::Span(s) => s.clone(),
                Pos::Include(k) => spans.get(k.as_str()).cloned(),
            };
            d = match span {
                Some(s) => d.at(f, s),
                None => d.in_file(f),
            };
        }
        diags.push(d);
    }
    if more > 0 {
        let d = Diagnostic::error(format!(
            "{more} more problem{} with the bindings of this policy",
            if more == 1 { "" } else { "s" }
        ));
        diags.push(match &src {
            Some(f) => d.in_file(f),
            None => d,
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn parse_text(text: &str) -> Result<Scenario, Vec<Diagnostic>> {
        let f = SourceFile::new("s.toml", text);
        parse(&f, Path::new("policies/scenarios"), &Limits::default())
    }

    #[test]
    fn reads_a_scenario() {
        let s = parse_text(
            r#"
seed = 3
[world]
robot = "start"
objects = { cube2 = { at = "east-table" } }
[[policies]]
file = "../paper/fig01-bt.toml"
[[disturbances]]
at = 4.0
battery = 15
"#,
        )
        .unwrap();
        assert_eq!(s.seed, 3);
        assert_eq!(s.policies.len(), 1);
        assert_eq!(s.disturbances[0].effect, Effect::Battery(15.0));
    }

    #[test]
    fn reports_unknown_names_and_poses_in_walls() {
        let e = parse_text(
            r#"
[world]
robot = [3.5, 0.0]
objects = { cube2 = { at = "east-tabel" } }
[[policies]]
file = "../paper/fig01-bt.toml"
[[disturbances]]
at = 1.0
fail = "Pik"
"#,
        )
        .unwrap_err();
        let text: Vec<String> = e.iter().map(|d| d.to_string()).collect();
        let all = text.join("");
        assert!(all.contains("inside a wall"), "{all}");
        assert!(all.contains("unknown station `east-tabel`"), "{all}");
        assert!(all.contains("did you mean `east-table`?"), "{all}");
        assert!(all.contains("unknown skill `Pik`"), "{all}");
    }

    #[test]
    fn policy_errors_in_included_subtrees_point_at_the_include() {
        let e = parse_text(
            r#"
[world]
objects = { cube1 = { at = "east-table" } }
[[policies]]
file = "../paper/fig16a-bt.toml"
"#,
        )
        .unwrap_err();
        let first = e[0].to_string();
        assert!(
            first.contains("unknown object `cube2` in node `moma2/"),
            "{first}"
        );
        assert!(first.contains("moma2         = { subtree"), "{first}");
        assert_eq!(key_span("a = 1\n  \"b c\" = 2\n", "b c"), Some(8..13));
    }

    proptest::proptest! {
        #![proptest_config(proptest::test_runner::Config::with_cases(64))]
        /// Random edits of a valid scenario never panic: they parse or give
        /// positioned errors.
        #[test]
        fn mutated_scenarios_never_panic(cut in 0usize..400, junk in "[a-z\\[\\]{}=\",0-9. ]{0,12}") {
            let base = "seed = 1\n[world]\nrobot = [0.5, -1.5]\nobjects = { cube2 = { at = \"east-table\" } }\n[[policies]]\nfile = \"../paper/fig01-bt.toml\"\n[[disturbances]]\nat = 2.0\nmove = \"cube2\"\nto = [1.0, -1.0]\n";
            let cut = cut.min(base.len());
            let cut = (0..=cut).rev().find(|&i| base.is_char_boundary(i)).unwrap_or(0);
            let text = format!("{}{junk}{}", &base[..cut], &base[cut..]);
            match parse_text(&text) {
                Ok(s) => proptest::prop_assert!(!s.policies.is_empty()),
                Err(d) => proptest::prop_assert!(d.iter().any(|x| x.is_error())),
            }
        }
    }

    fn errors_of(text: &str) -> String {
        let e = parse_text(text).expect_err("refused");
        e.iter().map(|d| d.to_string()).collect::<Vec<_>>().join("")
    }

    const ONE_POLICY: &str = "[[policies]]\nfile = \"../paper/fig01-bt.toml\"\n";
    const CUBE: &str = "objects = { cube2 = { at = \"east-table\" } }\n";

    /// 20,000 stations were read in quadratic time (each looked up by a scan
    /// of those before it); now a scenario holds at most MAX_STATIONS, and
    /// the limit is checked before any entry is read.
    #[test]
    fn stations_are_capped_and_read_in_linear_time() {
        let stations = |n: usize| {
            let mut t = format!("[world]\n{CUBE}[world.stations]\n");
            for i in 0..n {
                t.push_str(&format!("s{i} = [-2.0, -2.2]\n"));
            }
            t + ONE_POLICY
        };
        let t = std::time::Instant::now();
        let all = errors_of(&stations(20_000));
        assert!(
            all.contains("20007 stations, more than the limit of 1024")
                && all.contains("s.toml:3:1"),
            "{all}"
        );
        // Up to the limit (the paper room's 7 included): accepted, and a
        // moved paper station keeps its place.
        let mut text = stations(MAX_STATIONS - 7);
        text = text.replace(
            "[world.stations]\n",
            "[world.stations]\ndelivery = [0.5, 2.0]\n",
        );
        let s = parse_text(&text).expect("at the limit");
        let l = &s.world.layout;
        assert_eq!(l.stations.len(), MAX_STATIONS);
        assert_eq!(l.stations[0], ("delivery".to_string(), (0.5, 2.0)));
        assert_eq!(l.station_index("s1016"), Some(MAX_STATIONS - 1));
        assert!(t.elapsed().as_secs() < 5, "{:?}", t.elapsed());
    }

    #[test]
    fn policies_objects_obstacles_and_disturbances_are_capped() {
        let policies = format!("[world]\n{CUBE}{}", ONE_POLICY.repeat(MAX_POLICIES + 1));
        let all = errors_of(&policies);
        assert!(
            all.contains("65 policies, more than the limit of 64") && all.contains("s.toml:3:1"),
            "{all}"
        );
        assert_eq!(
            parse_text(&format!(
                "[world]\n{CUBE}{}",
                ONE_POLICY.repeat(MAX_POLICIES)
            ))
            .expect("64 policies")
            .policies
            .len(),
            MAX_POLICIES
        );
        let objects: String = (0..=MAX_OBJECTS)
            .map(|i| format!("o{i} = {{ at = \"east-table\" }}\n"))
            .collect();
        let all = errors_of(&format!("[world.objects]\n{objects}{ONE_POLICY}"));
        assert!(
            all.contains("1025 objects, more than the limit of 1024"),
            "{all}"
        );
        let obstacles = "{ rect = [2.5, 2.5, 2.6, 2.6] }, ".repeat(MAX_OBSTACLES + 1);
        let all = errors_of(&format!(
            "[world]\n{CUBE}obstacles = [{obstacles}]\n{ONE_POLICY}"
        ));
        assert!(
            all.contains("1025 obstacles, more than the limit of 1024"),
            "{all}"
        );
        let ds = "[[disturbances]]\nat = 1.0\nbattery = 50\n".repeat(MAX_DISTURBANCES + 1);
        let all = errors_of(&format!("[world]\n{CUBE}{ONE_POLICY}{ds}"));
        assert!(
            all.contains("1025 disturbances, more than the limit of 1024"),
            "{all}"
        );
        // `block` disturbances add obstacles: 6 of the room + 1019 blocks.
        let ds = "[[disturbances]]\nat = 1.0\nblock = { rect = [2.5, 2.5, 2.6, 2.6] }\n"
            .repeat(MAX_OBSTACLES - 5);
        let all = errors_of(&format!("[world]\n{CUBE}{ONE_POLICY}{ds}"));
        assert!(
            all.contains("1025 obstacles (`block` disturbances included)"),
            "{all}"
        );
        let terms = "{ if = \"Found\" }, ".repeat(MAX_TERMS / 2);
        let whens = format!("[[disturbances]]\nwhen = [{terms}]\nbattery = 5\n").repeat(2);
        let all = errors_of(&format!(
            "goal = [{{ if = \"Found\" }}]\n[world]\n{CUBE}{ONE_POLICY}{whens}"
        ));
        assert!(
            all.contains("1025 condition terms (`goal` and every `when` together), more than the limit of 1024"),
            "{all}"
        );
    }

    /// NaN and infinities passed the wall and obstacle checks, the battery
    /// drop took any level and window, and `max_steps = 1.5` was read as 1.
    #[test]
    fn numbers_are_finite_integers_where_counted_and_in_range() {
        // (top-level keys, lines of [world], tables after the policy, message)
        let cases: &[(&str, &str, &str, &str)] = &[
            ("", "robot = [nan, 0.0]\n", "", "s.toml:3:9"),
            (
                "",
                "robot = [0.0, inf]\n",
                "",
                "must be a position `[x, y]` in metres (finite numbers)",
            ),
            ("", "stations = { x = [nan, nan] }\n", "", "s.toml:3:18"),
            (
                "",
                "obstacles = [{ rect = [nan, 0, 1, 1] }]\n",
                "",
                "`rect` must be four finite numbers",
            ),
            (
                "",
                "obstacles = [{ rect = [0, 0, inf, 1] }]\n",
                "",
                "s.toml:3:23",
            ),
            (
                "",
                "battery = nan\n",
                "",
                "`battery` must be a finite number, found NaN",
            ),
            (
                "",
                "params = { max_speed = inf }\n",
                "",
                "`max_speed` must be a finite number, found inf",
            ),
            (
                "max_steps = 1.5\n",
                "",
                "",
                "`max_steps` must be an integer, found 1.5",
            ),
            (
                "max_steps = 10000000\n",
                "",
                "",
                "`max_steps` must be between 1 and 1000000, found 10000000",
            ),
            (
                "max_steps = nan\n",
                "",
                "",
                "`max_steps` must be an integer, found NaN",
            ),
            (
                "seed = 1e3\n",
                "",
                "",
                "`seed` must be an integer, found 1000",
            ),
            ("seed = -1\n", "", "", "`seed` must be between 0 and"),
            (
                "chatter_switches = 2.5\n",
                "",
                "",
                "`chatter_switches` must be an integer",
            ),
            (
                "max_failures = inf\n",
                "",
                "",
                "`max_failures` must be an integer, found inf",
            ),
            (
                "dt = nan\n",
                "",
                "",
                "`dt` must be a finite number, found NaN",
            ),
            (
                "",
                "",
                "[[disturbances]]\nat = inf\nbattery = 5\n",
                "`at` must be a finite number, found inf",
            ),
            (
                "",
                "",
                "[[disturbances]]\nat = 1.0\nfail = \"Pick\"\ntimes = 1.5\n",
                "`times` must be an integer, found 1.5",
            ),
            (
                "",
                "",
                "[[disturbances]]\nat = 1.0\nmove = \"cube2\"\nto = [nan, 1.0]\n",
                "s.toml:8:6",
            ),
            (
                "",
                "",
                "[monte_carlo]\nbattery_drop = { level = [nan, 19] }\n",
                "`level` must be a range `[low, high]` of finite numbers with 0 <= low <= high <= 100",
            ),
            (
                "",
                "",
                "[monte_carlo]\nbattery_drop = { level = [5, 190] }\n",
                "`level` must be a range",
            ),
            (
                "",
                "",
                "[monte_carlo]\nbattery_drop = { level = [19, 5] }\n",
                "`level` must be a range",
            ),
            (
                "",
                "",
                "[monte_carlo]\nbattery_drop = { window = [5.0, inf] }\n",
                "`window` must be a range",
            ),
            (
                "",
                "",
                "[monte_carlo]\nbattery_drop = { window = [-5.0, 1.0] }\n",
                "s.toml:6:27",
            ),
            (
                "",
                "",
                "[monte_carlo]\nbattery_drop = { probability = nan }\n",
                "`probability` must be a finite number",
            ),
            (
                "",
                "",
                "[rates]\nPick = nan\n",
                "failure rate of `Pick` must be a finite number",
            ),
            (
                "goal = [{ if = \"Battery-Level\", args = { min = nan } }]\n",
                "",
                "",
                "an argument must be a name or a finite number",
            ),
            (
                "goal = [{ if = \"Battery-Level\", args = { min = 150 } }]\n",
                "",
                "",
                "`min` of `Battery-Level` must be a percentage from 0 to 100, found 150",
            ),
            (
                "goal = [{ if = \"Battery-Level\", args = { min = -inf } }]\n",
                "",
                "",
                "s.toml:1:48",
            ),
        ];
        for (top, world, tail, want) in cases {
            let text = format!("{top}[world]\n{CUBE}{world}{ONE_POLICY}{tail}");
            let all = match parse_text(&text) {
                Ok(_) => panic!("accepted:\n{text}"),
                Err(e) => e.iter().map(|d| d.to_string()).collect::<Vec<_>>().join(""),
            };
            assert!(all.contains(want), "{text}\n=> {all}");
        }
        // Integers written as TOML integers still read, in any radix.
        let s = parse_text(&format!(
            "seed = 0x10\nmax_steps = 1_000\n[world]\n{CUBE}{ONE_POLICY}"
        ))
        .expect("integers");
        assert_eq!((s.seed, s.max_steps), (16, 1000));
    }

    /// The bindings are positioned by reading the policy again, bounded by
    /// --max-file-bytes (it was `read_to_string`, which `/dev/zero` fills).
    #[test]
    fn bindings_are_positioned_by_a_bounded_read() {
        let s = parse_text(&format!("[world]\n{CUBE}{ONE_POLICY}")).expect("valid");
        let policy = crate::format::load(
            Path::new("policies/paper/fig01-bt.toml"),
            &Limits::default(),
        )
        .expect("fig01")
        .policy;
        let mut world = s.world.clone();
        world.objects.clear();
        let world = World::new(
            (*world.layout).clone(),
            world.params.clone(),
            world.robot,
            vec![],
        );
        let limits = Limits {
            max_file_bytes: 4096,
            ..Limits::default()
        };
        let mut diags = Vec::new();
        check_bindings(&policy, "/dev/zero", &limits, &world, &mut diags);
        assert!(!diags.is_empty());
        assert!(diags.iter().all(|d| d.file.is_none()), "{diags:?}");
        let mut diags = Vec::new();
        check_bindings(
            &policy,
            "policies/paper/fig01-bt.toml",
            &limits,
            &world,
            &mut diags,
        );
        assert!(
            diags[0].to_string().contains("fig01-bt.toml:9:1"),
            "{}",
            diags[0]
        );
    }

    #[test]
    fn scenarios_are_told_from_policies_by_their_head() {
        assert!(looks_like_scenario(
            "# c\nname = \"x\"\nseed = 1\n\n[world]\nrobot = \"start\"\n"
        ));
        assert!(looks_like_scenario(
            "name = \"x\"\n[[policies]]\nfile = \"a.toml\"\n"
        ));
        assert!(!looks_like_scenario(
            "kind = \"bt\"\nroot = \"r\"\n[nodes]\n"
        ));
        assert!(!looks_like_scenario("name = \"no kind\"\n[nodes]\n"));
        assert!(!looks_like_scenario(""));
    }
}
