//! Scenario files (SPEC §6): the world, the policies to run (paths relative to
//! the scenario), the seed, skill failure rates and disturbances at a time or on
//! a trigger. Read from TOML and validated completely before any run; every
//! problem is a positioned [`Diagnostic`] (file, line, column, what would be
//! valid). The format is documented in docs/guide/sim.md.

use super::skills::{self, Call, Unresolved};
use super::world::{Layout, Object, P2, Params, Place, Rect, World};
use btfsm_core::diagnostic::{Diagnostic, SourceFile, suggest};
use btfsm_format::{self as format, Limits};
use btfsm_model::{Policy, PolicyBody, SkillCall, StateBody, skill::SKILLS};
use std::collections::BTreeMap;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use toml::Spanned;
use toml::de::{DeTable, DeValue};

mod disturbance;
pub mod expect;
pub mod mc;
mod policies;
pub(crate) use policies::numbered;
mod world;

type Val<'i> = Spanned<DeValue<'i>>;

/// What a policy does once it has reported SUCCESS, or FAILURE (a property
/// of the run, written per policy in the scenario: `after_success`,
/// `after_failure`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Afterwards {
    /// No longer ticked: the robot stands idle (SMACH's final state; after
    /// SUCCESS, the default for FSMs and HFSMs).
    Stop,
    /// Ticked again every step: a BT from its root, a machine re-entered at
    /// its initial state (after SUCCESS, the default for BTs, as the paper
    /// describes; after FAILURE, the default for every policy).
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
    /// Whether the policy's own entry states `after_success` and
    /// `after_failure` (a choice of the policy), rather than taking the
    /// scenario's setting or the default (a modelling choice that
    /// `sim --sensitivity` flips).
    pub stated: [bool; 2],
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
    /// The verdicts' tolerances: the largest distance between two robots
    /// at the same step, m, and between two starts of the same skill, s,
    /// for their behavior to match (defaults 0.2 m and one step).
    pub pose_tolerance_m: f64,
    pub start_tolerance_s: f64,
    /// The largest time shift between two runs under which their poses
    /// are compared, s (default `start_tolerance_s`): a run that does the
    /// same a step later moves alike.
    pub time_shift_s: f64,
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
        after: (None, None),
    };
    // The policies and their includes stay inside the scenario's root.
    let root = format::source::root_for(limits, base);
    let limits = &Limits {
        confinement: root.map_or(format::source::Confinement::Off, |r| {
            format::source::Confinement::Root(r)
        }),
        ..limits.clone()
    };
    // Counted before the parser allocates 70-112 bytes per token.
    btfsm_core::toml_budget::check(
        file,
        limits.max_toml_tokens(),
        "a scenario's counts are capped (docs/guide/sim.md); raise --max-nodes",
    )
    .map_err(|d| vec![d])?;
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
                    .hint("see the scenario format in docs/guide/sim.md")
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
    /// The scenario's own `after_success` / `after_failure`, for every
    /// policy entry that does not state its own.
    after: (Option<Afterwards>, Option<Afterwards>),
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
    "after_success",
    "after_failure",
    "pose_tolerance_m",
    "start_tolerance_s",
    "time_shift_s",
    "expect",
    "goal",
    "world",
    "policies",
    "rates",
    "disturbances",
    "monte_carlo",
];

impl Reader {
    pub(super) fn err(
        &mut self,
        span: Range<usize>,
        msg: impl Into<String>,
        hint: impl Into<String>,
    ) {
        self.diags
            .push(Diagnostic::error(msg).at(&self.file, span).hint(hint));
    }

    pub(super) fn keys(&mut self, t: &DeTable<'_>, allowed: &[&str], what: &str) {
        for (k, _) in t.iter() {
            if !allowed.contains(&k.get_ref().as_ref()) {
                let h = suggest(k.get_ref(), allowed.iter().copied());
                self.err(k.span(), format!("unknown {what} `{}`", k.get_ref()), h);
            }
        }
    }

    /// Refuses a collection of more than `max` entries (at its value, before
    /// any entry is read).
    pub(super) fn at_most(&mut self, span: Range<usize>, n: usize, max: usize, what: &str) -> bool {
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

    pub(super) fn number(&mut self, v: &Val<'_>, what: &str, min: f64, max: f64) -> Option<f64> {
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
    pub(super) fn integer(&mut self, v: &Val<'_>, what: &str, min: u64, max: u64) -> Option<u64> {
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
    pub(super) fn range(
        &mut self,
        v: &Val<'_>,
        what: &str,
        min: f64,
        max: f64,
    ) -> Option<(f64, f64)> {
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

    pub(super) fn string(&mut self, v: &Val<'_>, what: &str) -> Option<String> {
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

    pub(super) fn table<'a, 'i>(&mut self, v: &'a Val<'i>, what: &str) -> Option<&'a DeTable<'i>> {
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

    pub(super) fn array<'a, 'i>(&mut self, v: &'a Val<'i>, what: &str) -> Option<&'a [Val<'i>]> {
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
    pub(super) fn point(&mut self, v: &Val<'_>, what: &str) -> Option<P2> {
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
    pub(super) fn pose(
        &mut self,
        v: &Val<'_>,
        what: &str,
        layout: &Layout,
        radius: f64,
    ) -> Option<P2> {
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

    pub(super) fn unresolved(&mut self, span: Range<usize>, u: Unresolved) {
        self.err(span, u.message, u.hint);
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
    let mut problems: Vec<Problem> = Vec::new();
    match &p.body {
        PolicyBody::Bt(bt) => bt_binding_problems(bt, world, &mut problems),
        PolicyBody::Machine(m) => machine_binding_problems(m, world, &mut problems),
    }
    if problems.is_empty() {
        return;
    }
    report_binding_problems(problems, path, limits, diags);
}

/// Where a problem is: a span of the policy file, or the include of
/// the subtree it comes from (its key, found in the file's text).
enum Pos {
    Span(Option<Range<usize>>),
    Include(String),
}

/// A binding problem: what has it (``node `x` ``), where, and why.
type Problem = (String, Pos, Unresolved);

/// The binding problems of a BT: node types the simulator does not model,
/// leaves without a skill or with one that does not resolve.
fn bt_binding_problems(bt: &btfsm_model::bt::Bt, world: &World, problems: &mut Vec<Problem>) {
    for n in &bt.nodes {
        // Nodes of an included subtree (`include/...`) have spans in
        // the included file: point at the include in this file.
        let span = || match n.id.split_once('/') {
            None => Pos::Span(n.span.clone()),
            Some((inc, _)) => Pos::Include(inc.to_string()),
        };
        if let Some(t) = crate::exec::refused(n) {
            problems.push((
                format!("node `{}`", n.id),
                span(),
                Unresolved {
                    message: format!("the simulator does not model the node type {t}"),
                    hint: "it executes the node types of docs/bt-semantics.md (sequence, fallback, sequence_memory, fallback_memory, parallel, inverter, force_success, force_failure, repeat, retry, timeout; IfThenElse, WhileDoElse, KeepRunningUntilFailure, ...)".into(),
                },
            ));
        }
        if n.kind.arity() != btfsm_model::bt::Arity::Leaf {
            continue;
        }
        let span = span();
        match &n.skill {
            Some(c) => {
                if let Err(u) = skills::resolve(c, world) {
                    problems.push((format!("node `{}`", n.id), span, u));
                }
            }
            None => problems.push((
                format!("node `{}`", n.id),
                span,
                Unresolved {
                    message: "no skill binding".into(),
                    hint: "the simulator needs `skill = \"...\"` on every leaf".into(),
                },
            )),
        }
    }
}

/// The binding problems of a machine: history pseudo-states, tasks
/// without a skill, skills and guards that do not resolve.
fn machine_binding_problems(
    m: &btfsm_model::StateMachine,
    world: &World,
    problems: &mut Vec<Problem>,
) {
    for (i, s) in m.states.iter().enumerate() {
        if s.pseudo.is_some() {
            problems.push((
                format!("state `{}`", m.path(i)),
                Pos::Span(s.span.clone()),
                Unresolved {
                    message: "the simulator does not execute history pseudo-states".into(),
                    hint: "re-entering a container at its last active state is not modelled; give the container an initial state instead".into(),
                },
            ));
            continue;
        }
        let mut calls: Vec<&SkillCall> = Vec::new();
        match &s.body {
            StateBody::Task(Some(c)) => calls.push(c),
            StateBody::Task(None) => problems.push((
                format!("state `{}`", m.path(i)),
                Pos::Span(s.span.clone()),
                Unresolved {
                    message: "no skill binding".into(),
                    hint: "the simulator needs `skill = \"...\"` on every state that is not a decision or container".into(),
                },
            )),
            _ => {}
        }
        for t in &s.transitions {
            if let btfsm_model::Trigger::Guard(g) = &t.trigger {
                calls.extend(g.all.iter().map(|x| &x.condition));
            }
        }
        for c in calls {
            if let Err(u) = skills::resolve(c, world) {
                problems.push((
                    format!("state `{}`", m.path(i)),
                    Pos::Span(s.span.clone()),
                    u,
                ));
            }
        }
    }
}

/// The binding problems as diagnostics, at most 200 (the rest counted),
/// positioned by reading the policy file at `path` once more.
fn report_binding_problems(
    mut problems: Vec<Problem>,
    path: &str,
    limits: &Limits,
    diags: &mut Vec<Diagnostic>,
) {
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
mod tests;
