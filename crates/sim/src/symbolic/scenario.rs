//! Symbolic scenarios: a scenario file with a top-level `domain` runs its
//! policies in the abstract world of that action domain's facts instead of
//! the planar room (docs/guide/sim.md, "Symbolic simulation"). Read with serde from TOML;
//! every problem is reported at once with its position.

use btfsm_core::diagnostic::{Diagnostic, SourceFile, suggest};
use btfsm_format::{self as format, Limits};
use btfsm_model::{Policy, PolicyBody};
use btfsm_plan::Domain;
use btfsm_plan::fact::Fact;
use serde::Deserialize;
use std::collections::BTreeMap;
use std::ops::Range;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use toml::Spanned;

/// Most policies and disturbances of a symbolic scenario (each).
pub const MAX_ENTRIES: usize = 64;
/// Most steps a run may take.
pub const MAX_STEPS: u64 = 1_000_000;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Raw {
    name: String,
    #[serde(default)]
    description: Option<String>,
    domain: Spanned<String>,
    #[serde(default)]
    task: Option<Spanned<String>>,
    #[serde(default)]
    seed: u64,
    #[serde(default = "default_steps")]
    max_steps: Spanned<u64>,
    #[serde(default = "default_repeats")]
    livelock_repeats: Spanned<u32>,
    #[serde(default = "default_failures")]
    max_failures: u32,
    #[serde(default)]
    facts: Vec<Spanned<String>>,
    #[serde(default)]
    durations: BTreeMap<String, Spanned<u32>>,
    #[serde(default)]
    rates: BTreeMap<String, Spanned<f64>>,
    policies: Vec<RawPolicy>,
    #[serde(default)]
    disturbances: Vec<RawDisturbance>,
    #[serde(default)]
    monte_carlo: Option<RawMc>,
    #[serde(default)]
    expect: Option<super::expect::RawExpect>,
}

fn default_steps() -> Spanned<u64> {
    Spanned::new(0..0, 1000)
}
fn default_repeats() -> Spanned<u32> {
    Spanned::new(0..0, 3)
}
fn default_failures() -> u32 {
    10
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawPolicy {
    file: Spanned<String>,
    /// The name reports and `[expect]` give it (default: the policy's own).
    #[serde(default)]
    name: Option<String>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDisturbance {
    at: u64,
    #[serde(default)]
    set: Vec<Spanned<String>>,
    #[serde(default)]
    unset: Vec<Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMc {
    #[serde(default)]
    rates: BTreeMap<String, Spanned<f64>>,
    #[serde(default)]
    unset: Option<RawFlip>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFlip {
    probability: Spanned<f64>,
    facts: Vec<Spanned<String>>,
    window: [u64; 2],
}

/// A disturbance: facts made true and false at a step.
#[derive(Debug, Clone, PartialEq)]
pub struct Disturbance {
    pub at: u64,
    pub set: Vec<Fact>,
    pub unset: Vec<Fact>,
}

/// Monte Carlo sampling: action failure rates, and one fact made false at a
/// random step of `window` with `probability` per episode.
#[derive(Debug, Clone, Default)]
pub struct Mc {
    pub rates: BTreeMap<String, f64>,
    pub unset: Option<(f64, Vec<Fact>, [u64; 2])>,
}

/// A validated symbolic scenario.
#[derive(Debug, Clone)]
pub struct SymScenario {
    pub name: String,
    pub description: Option<String>,
    pub domain: Arc<Domain>,
    pub goal: Vec<Fact>,
    pub seed: u64,
    pub max_steps: u64,
    pub livelock_repeats: u32,
    pub max_failures: u32,
    pub facts: Vec<Fact>,
    /// Steps per action, by action name (default 1).
    pub durations: BTreeMap<String, u32>,
    /// Failure probability per action name (single runs too).
    pub rates: BTreeMap<String, f64>,
    pub policies: Vec<(PathBuf, Policy)>,
    pub disturbances: Vec<Disturbance>,
    pub mc: Mc,
    /// The scenario's `[expect]`, checked against one run per policy.
    pub expect: Vec<crate::scenario::expect::Expectation>,
}

/// Does a TOML text set `domain` before its first table (a symbolic
/// scenario)?
pub fn looks_symbolic(text: &str) -> bool {
    for line in text.lines() {
        let l = line.trim();
        if l.starts_with('[') {
            return false;
        }
        let key = l.split('=').next().unwrap_or("").trim().trim_matches('"');
        if key == "domain" && l.contains('=') {
            return true;
        }
    }
    false
}

/// Parses a symbolic scenario from its text (its domain and policies too:
/// paths relative to `base`, confined as every file a file names).
pub fn parse(
    file: &Arc<SourceFile>,
    base: &Path,
    limits: &Limits,
) -> Result<SymScenario, Vec<Diagnostic>> {
    let raw = read_raw(file)?;
    let mut pb = Problems {
        file,
        diags: Vec::new(),
    };
    let files = Files {
        root: format::source::root_for(limits, base),
        base,
        limits,
    };
    let Some(mut domain) = load_domain(&raw.domain, &files, &mut pb)? else {
        return Err(pb.diags);
    };
    if let Some(t) = &raw.task
        && let Err(e) = domain.select_task(t.get_ref())
    {
        pb.err(t.span(), e, "name a `[tasks.NAME]` of the domain".into());
    }
    let initial = ground(&domain, &raw.facts, &mut pb);
    let disturbances = read_disturbances(&domain, &raw, &mut pb);
    let mut rates = BTreeMap::new();
    check_rates(&domain, &raw.rates, &mut rates, &mut pb);
    let mc = read_mc(&domain, raw.monte_carlo.as_ref(), &mut pb);
    let durations = read_durations(&domain, &raw.durations, &mut pb);
    check_bounds(&raw, &mut pb);
    let policies = load_policies(&domain, &raw.policies, &files, &mut pb);
    let expect = match &raw.expect {
        Some(e) if pb.diags.is_empty() => {
            let names: Vec<String> = policies.iter().map(|(_, p)| p.name.clone()).collect();
            super::expect::read(e, &names, file, &mut pb.diags)
        }
        _ => Vec::new(),
    };
    if !pb.diags.is_empty() {
        return Err(pb.diags);
    }
    Ok(SymScenario {
        name: raw.name,
        description: raw.description,
        goal: domain.goal.facts.clone(),
        domain: Arc::new(domain),
        seed: raw.seed,
        max_steps: *raw.max_steps.get_ref(),
        livelock_repeats: *raw.livelock_repeats.get_ref(),
        max_failures: raw.max_failures,
        facts: initial,
        durations,
        rates,
        policies,
        disturbances,
        mc,
        expect,
    })
}

/// The problems found in a symbolic scenario, positioned in its file.
struct Problems<'f> {
    file: &'f Arc<SourceFile>,
    diags: Vec<Diagnostic>,
}

impl Problems<'_> {
    /// An error at `span` of the scenario, with a hint.
    fn err(&mut self, span: Range<usize>, msg: String, hint: String) {
        self.diags
            .push(Diagnostic::error(msg).at(self.file, span).hint(hint));
    }
}

/// Where the files a scenario names are read: relative to `base`, inside
/// `root` when there is one, within `limits`.
struct Files<'a> {
    root: Option<PathBuf>,
    base: &'a Path,
    limits: &'a Limits,
}

impl Files<'_> {
    /// The path of a file the scenario names.
    fn resolve(&self, rel: &str) -> Result<PathBuf, format::source::Refusal> {
        format::source::resolve(self.root.as_deref(), self.base, rel)
    }
}

/// The scenario's TOML as written (a syntax or type error is the one
/// diagnostic).
fn read_raw(file: &Arc<SourceFile>) -> Result<Raw, Vec<Diagnostic>> {
    btfsm_core::toml_budget::check(
        file,
        btfsm_core::toml_budget::DEFAULT_MAX_TOKENS,
        "a scenario's counts are capped (docs/guide/sim.md)",
    )
    .map_err(|d| vec![d])?;
    toml::from_str(&file.text).map_err(|e| {
        let d = Diagnostic::error(format!("invalid symbolic scenario: {}", e.message().trim()))
            .hint("see docs/guide/sim.md (\"Symbolic simulation\") for the format");
        vec![match e.span() {
            Some(s) => d.at(file, s),
            None => d,
        }]
    })
}

/// Loads the scenario's domain: `Ok(None)` (with an error) when its path
/// is refused, `Err` with the domain file's own problems.
fn load_domain(
    domain: &Spanned<String>,
    files: &Files<'_>,
    pb: &mut Problems<'_>,
) -> Result<Option<Domain>, Vec<Diagnostic>> {
    match files.resolve(domain.get_ref()) {
        Ok(p) => {
            let shown = p.display().to_string();
            let f = format::source::read(&p, &shown, files.limits, true)?;
            // Checked before it is parsed: a file that is not a domain is
            // refused quoting none of it (issue 33).
            let is_toml = p
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("toml"));
            if !is_toml || !format::discover::looks_like_domain(&f.text) {
                return Err(vec![
                    Diagnostic::error(format!(
                        "domain `{}`: not an action domain: it is not read, and nothing of it is shown",
                        btfsm_core::sanitize::shown(&shown)
                    ))
                    .hint("a domain is a `.toml` file with `[actions.NAME]` or `[predicates]` tables (docs/guide/plan.md)"),
                ]);
            }
            btfsm_plan::load(&f).map(Some)
        }
        Err(r) => {
            pb.err(
                domain.span(),
                format!(
                    "domain `{}`: {}",
                    btfsm_core::sanitize::shown(domain.get_ref()),
                    r.message
                ),
                r.hint,
            );
            Ok(None)
        }
    }
}

/// Grounds facts written as text in the domain (an error for each that
/// does not ground).
fn ground(domain: &Domain, list: &[Spanned<String>], pb: &mut Problems<'_>) -> Vec<Fact> {
    let mut out = Vec::new();
    for f in list {
        match domain.ground_fact(f.get_ref()) {
            Ok(g) => out.push(g),
            Err((m, h)) => pb.err(f.span(), m, h),
        }
    }
    out
}

/// The disturbances, their facts grounded (at most [`MAX_ENTRIES`]; more
/// policies or disturbances are an error).
fn read_disturbances(domain: &Domain, raw: &Raw, pb: &mut Problems<'_>) -> Vec<Disturbance> {
    let mut disturbances = Vec::new();
    if raw.disturbances.len() > MAX_ENTRIES || raw.policies.len() > MAX_ENTRIES {
        pb.err(
            0..0,
            format!("more than {MAX_ENTRIES} policies or disturbances"),
            "split the scenario".into(),
        );
    }
    for d in raw.disturbances.iter().take(MAX_ENTRIES) {
        let set = ground(domain, &d.set, pb);
        let unset = ground(domain, &d.unset, pb);
        disturbances.push(Disturbance {
            at: d.at,
            set,
            unset,
        });
    }
    disturbances
}

/// Whether the domain has an action `name` (if not, an error at `span`
/// with the nearest name).
fn known_action(domain: &Domain, name: &str, span: Range<usize>, pb: &mut Problems<'_>) -> bool {
    if domain.actions.iter().any(|a| a.name == name) {
        return true;
    }
    let h = suggest(name, domain.actions.iter().map(|a| a.name.as_str()));
    pb.err(
        span,
        format!(
            "no action `{}` in the domain",
            btfsm_core::sanitize::shown(name)
        ),
        h,
    );
    false
}

/// Checks a table of failure rates (actions of the domain, probabilities)
/// into `out`.
fn check_rates(
    domain: &Domain,
    table: &BTreeMap<String, Spanned<f64>>,
    out: &mut BTreeMap<String, f64>,
    pb: &mut Problems<'_>,
) {
    for (name, p) in table {
        if !known_action(domain, name, p.span(), pb) {
            continue;
        }
        if !(0.0..=1.0).contains(p.get_ref()) {
            pb.err(
                p.span(),
                format!("a failure rate is a probability, found {}", p.get_ref()),
                "write a number from 0 to 1".into(),
            );
        } else {
            out.insert(name.clone(), *p.get_ref());
        }
    }
}

/// The `[monte_carlo]` table: its rates and the fact it may unset.
fn read_mc(domain: &Domain, m: Option<&RawMc>, pb: &mut Problems<'_>) -> Mc {
    let mut mc = Mc::default();
    let Some(m) = m else {
        return mc;
    };
    check_rates(domain, &m.rates, &mut mc.rates, pb);
    if let Some(u) = &m.unset {
        let p = *u.probability.get_ref();
        if !(0.0..=1.0).contains(&p) {
            pb.err(
                u.probability.span(),
                format!("`probability` must be from 0 to 1, found {p}"),
                "write e.g. `probability = 0.3`".into(),
            );
        }
        let fs = ground(domain, &u.facts, pb);
        if u.window[0] > u.window[1] {
            pb.err(
                u.probability.span(),
                "`window` must be [first, last] with first <= last".into(),
                "write e.g. `window = [2, 20]`".into(),
            );
        }
        mc.unset = Some((p, fs, u.window));
    }
    mc
}

/// The steps per action (actions of the domain, 1 to 10000 steps).
fn read_durations(
    domain: &Domain,
    table: &BTreeMap<String, Spanned<u32>>,
    pb: &mut Problems<'_>,
) -> BTreeMap<String, u32> {
    let mut durations = BTreeMap::new();
    for (name, v) in table {
        if !known_action(domain, name, v.span(), pb) {
            continue;
        }
        if *v.get_ref() == 0 || *v.get_ref() > 10_000 {
            pb.err(
                v.span(),
                format!("a duration is 1 to 10000 steps, found {}", v.get_ref()),
                "write e.g. `Move-To = 3`".into(),
            );
        } else {
            durations.insert(name.clone(), *v.get_ref());
        }
    }
    durations
}

/// Checks `max_steps` and `livelock_repeats`.
fn check_bounds(raw: &Raw, pb: &mut Problems<'_>) {
    let steps = *raw.max_steps.get_ref();
    if steps == 0 || steps > MAX_STEPS {
        pb.err(
            raw.max_steps.span(),
            format!("`max_steps` must be 1 to {MAX_STEPS}, found {steps}"),
            "write e.g. `max_steps = 1000`".into(),
        );
    }
    if *raw.livelock_repeats.get_ref() < 2 {
        pb.err(
            raw.livelock_repeats.span(),
            "`livelock_repeats` must be at least 2".into(),
            "the default is 3".into(),
        );
    }
}

/// Loads the policies (at most [`MAX_ENTRIES`]), each checked to run in the
/// domain's world; the policy files' own problems come after the others.
fn load_policies(
    domain: &Domain,
    list: &[RawPolicy],
    files: &Files<'_>,
    pb: &mut Problems<'_>,
) -> Vec<(PathBuf, Policy)> {
    let mut policies = Vec::new();
    let mut loaded_errors = Vec::new();
    for p in list.iter().take(MAX_ENTRIES) {
        let rel = p.file.get_ref();
        let path = match files.resolve(rel) {
            Ok(x) => x,
            Err(r) => {
                pb.err(
                    p.file.span(),
                    format!(
                        "policy file `{}`: {}",
                        btfsm_core::sanitize::shown(rel),
                        r.message
                    ),
                    r.hint,
                );
                continue;
            }
        };
        match format::load_named(&path, files.limits) {
            Ok(mut l) => match unbound(domain, &l.policy) {
                None => {
                    if let Some(n) = &p.name {
                        l.policy.name = n.clone();
                    }
                    if let Some(name) = distinct_name(&policies, &l.policy.name, p, pb) {
                        l.policy.name = name;
                        policies.push((path, l.policy));
                    }
                }
                Some(why) => pb.err(
                    p.file.span(),
                    format!("policy `{}`: {why}", btfsm_core::sanitize::shown(rel)),
                    format!(
                        "bind every leaf to a skill that domain `{}` has a predicate or action for",
                        btfsm_core::sanitize::shown(&domain.name)
                    ),
                ),
            },
            Err(ds) => loaded_errors.extend(ds),
        }
    }
    pb.diags.extend(loaded_errors);
    policies
}

/// The name a policy is reported by: its own, or `NAME#2` (`#3`, ...)
/// when an earlier policy has it (two entries of one file); a `name` the
/// scenario states twice is an error (`None`).
fn distinct_name(
    policies: &[(PathBuf, Policy)],
    name: &str,
    p: &RawPolicy,
    pb: &mut Problems<'_>,
) -> Option<String> {
    let taken = |n: &str| policies.iter().any(|(_, q)| q.name == n);
    if !taken(name) {
        return Some(name.to_string());
    }
    if p.name.is_some() {
        pb.err(
            p.file.span(),
            format!(
                "two policies are named `{}`",
                btfsm_core::sanitize::shown(name)
            ),
            "names tell policies apart in reports and `[expect]`: give this entry another `name`"
                .into(),
        );
        return None;
    }
    Some(crate::scenario::numbered(name, taken))
}

/// Why a policy cannot run in the domain's world (a leaf or guard bound to
/// a skill the domain has no predicate or action for), if it cannot.
fn unbound(d: &Domain, p: &Policy) -> Option<String> {
    let ok = |c: &btfsm_model::SkillCall| super::world::binding(d, c).is_some();
    match &p.body {
        PolicyBody::Bt(bt) => bt
            .nodes
            .iter()
            .find_map(|n| match (&n.skill, n.kind.arity()) {
                (Some(c), _) if !ok(c) => Some(format!("node `{}` runs `{c}`", n.id)),
                (None, btfsm_model::bt::Arity::Leaf) => {
                    Some(format!("leaf `{}` has no skill", n.id))
                }
                _ => None,
            }),
        PolicyBody::Machine(m) => m.states.iter().find_map(|s| {
            if let btfsm_model::StateBody::Task(Some(c)) = &s.body
                && !ok(c)
            {
                return Some(format!("state `{}` runs `{c}`", s.name));
            }
            s.transitions.iter().find_map(|t| match &t.trigger {
                btfsm_model::Trigger::Guard(g) => g
                    .all
                    .iter()
                    .find(|term| !ok(&term.condition))
                    .map(|term| format!("a guard of `{}` checks `{}`", s.name, term.condition)),
                _ => None,
            })
        }),
    }
}
