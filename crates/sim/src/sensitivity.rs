//! Which modelling choices decide a verdict (issue 31, "knowledge that
//! favours no one"; docs/guide/sim.md, "Sensitivity"): the scenario is run
//! again with each policy-independent setting flipped — what the robot
//! knows of a dropped object (`drop_sensed`), whether a Move-To follows its
//! marker (`follow_belief`), whether a Shut-Down outlasts its emergency
//! (`shut_down_latches`), what every policy that does not state its own
//! does after SUCCESS and after FAILURE, the verdict tolerances and the
//! failure and livelock budgets — and every verdict is listed with the
//! flips that reverse it. A verdict no flip reverses was decided by the
//! policies; one a flip reverses was decided by that setting as much as by
//! them, and the report says so.
//!
//! A flip is a whole-scenario change that favours no representation: the
//! same world rule, or the same after-SUCCESS behavior, for every policy.
//! A policy's own `after_success`/`after_failure` is its structure, not a
//! setting, and is never flipped.

use super::monte_carlo::{McResult, wilson};
use super::scenario::expect::{ExpectResult, Status};
use super::scenario::{Afterwards, Scenario};
use super::trace::{FRECHET_POINTS, Run, Verdict};
use serde::Serialize;
use std::time::Instant;

/// One setting changed from the scenario's value.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Flip {
    /// The scenario key (`world.drop_sensed`, `after_failure`, ...).
    pub setting: String,
    /// Its value in the scenario as run.
    pub from: String,
    /// Its value in this flip.
    pub to: String,
}

impl Flip {
    /// `setting = to` (as the scenario would write it).
    pub fn text(&self) -> String {
        format!("{} = {}", self.setting, self.to)
    }
}

/// A verdict and the flips that reverse it.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Sensitive {
    /// What is judged (`BT vs FSM`, `outcome of BT`, `expect NAME`).
    pub verdict: String,
    /// Its value in the scenario as run.
    pub value: String,
    /// The flips under which it reads otherwise, with what it reads.
    pub reversed_by: Vec<Reversal>,
}

#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Reversal {
    pub setting: String,
    pub to: String,
    /// The verdict's value under this flip.
    pub value: String,
}

/// What `--sensitivity` adds to a report.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Sensitivity {
    /// Every flip tried, in order.
    pub flips: Vec<Flip>,
    /// Flips not tried: the wall-clock budget ran out first.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub not_tried: Vec<Flip>,
    pub verdicts: Vec<Sensitive>,
}

/// Every policy-independent setting of `s` flipped, one at a time, each
/// with the scenario it gives.
pub fn flips(s: &Scenario) -> Vec<(Flip, Scenario)> {
    let mut out = Vec::new();
    let p = &s.world.params;
    for (key, v) in [
        ("drop_sensed", p.drop_sensed),
        ("follow_belief", p.follow_belief),
        ("shut_down_latches", p.shut_down_latches),
    ] {
        let mut t = s.clone();
        let f = match key {
            "drop_sensed" => &mut t.world.params.drop_sensed,
            "follow_belief" => &mut t.world.params.follow_belief,
            _ => &mut t.world.params.shut_down_latches,
        };
        *f = !v;
        out.push((flip(&format!("world.{key}"), v, !v), t));
    }
    afterwards_flips(s, 0, &mut out);
    afterwards_flips(s, 1, &mut out);
    scaled_flips(s, &mut out);
    out
}

fn flip(setting: &str, from: impl ToString, to: impl ToString) -> Flip {
    Flip {
        setting: setting.into(),
        from: from.to_string(),
        to: to.to_string(),
    }
}

/// `after_success` (`which` 0) or `after_failure` (1) set to each value for
/// every policy that does not state its own, where that changes one.
fn afterwards_flips(s: &Scenario, which: usize, out: &mut Vec<(Flip, Scenario)>) {
    let key = ["after_success", "after_failure"][which];
    let get = |e: &super::scenario::PolicyEntry| [e.after_success, e.after_failure][which];
    let open: Vec<usize> = (0..s.policies.len())
        .filter(|&i| !s.policies[i].stated[which])
        .collect();
    let now: std::collections::BTreeSet<&str> =
        open.iter().map(|&i| get(&s.policies[i]).as_str()).collect();
    let from = match now.len() {
        1 => now.iter().next().copied().unwrap_or_default().to_string(),
        _ => "per representation (the default)".to_string(),
    };
    for to in [Afterwards::Stop, Afterwards::KeepTicking] {
        if open.iter().all(|&i| get(&s.policies[i]) == to) {
            continue;
        }
        let mut t = s.clone();
        for &i in &open {
            let e = &mut t.policies[i];
            *[&mut e.after_success, &mut e.after_failure][which] = to;
        }
        out.push((flip(key, &from, to.as_str()), t));
    }
}

/// The verdict tolerances halved and doubled, and the failure and
/// livelock budgets doubled.
fn scaled_flips(s: &Scenario, out: &mut Vec<(Flip, Scenario)>) {
    for k in [0.5, 2.0] {
        let mut t = s.clone();
        t.pose_tolerance_m = s.pose_tolerance_m * k;
        out.push((
            flip("pose_tolerance_m", s.pose_tolerance_m, t.pose_tolerance_m),
            t,
        ));
        let mut t = s.clone();
        t.time_shift_s = s.time_shift_s * k;
        out.push((flip("time_shift_s", s.time_shift_s, t.time_shift_s), t));
        let mut t = s.clone();
        t.start_tolerance_s = s.start_tolerance_s * k;
        out.push((
            flip(
                "start_tolerance_s",
                s.start_tolerance_s,
                t.start_tolerance_s,
            ),
            t,
        ));
    }
    let mut t = s.clone();
    t.max_failures = s.max_failures.saturating_mul(2);
    out.push((flip("max_failures", s.max_failures, t.max_failures), t));
    let mut t = s.clone();
    t.livelock_repeats = s.livelock_repeats.saturating_mul(2);
    out.push((
        flip("livelock_repeats", s.livelock_repeats, t.livelock_repeats),
        t,
    ));
}

/// The verdicts of one run of every policy, by name: each policy's
/// outcome (and goal), each pair's match, each expectation's status.
pub fn run_verdicts(
    runs: &[Run],
    verdicts: &[Verdict],
    expect: &[ExpectResult],
) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for r in runs {
        let goal = match r.goal_met {
            Some(true) => ", goal met",
            Some(false) => ", goal not met",
            None => "",
        };
        out.push((
            format!("outcome of {}", r.policy),
            format!("{}{goal}", r.outcome.as_str()),
        ));
    }
    for v in verdicts {
        let m = if v.matches { "match" } else { "differ" };
        out.push((format!("{} vs {}", v.a, v.b), m.to_string()));
    }
    out.extend(expectation_verdicts(expect));
    out
}

fn expectation_verdicts(expect: &[ExpectResult]) -> Vec<(String, String)> {
    (expect.iter())
        .map(|e| (format!("expect {}", e.name), status(e.status).to_string()))
        .collect()
}

fn status(s: Status) -> &'static str {
    match s {
        Status::Pass => "pass",
        Status::Fail => "fail",
        Status::Undecided => "undecided",
    }
}

/// The verdicts of `--runs`: for each pair, which policy succeeds more
/// often (their 95 % intervals apart) or neither; each expectation's
/// status.
pub fn monte_carlo_verdicts(mc: &McResult, expect: &[ExpectResult]) -> Vec<(String, String)> {
    let mut out = Vec::new();
    let ps = &mc.policies;
    for i in 0..ps.len() {
        for j in i + 1..ps.len() {
            let (a, b) = (&ps[i], &ps[j]);
            let (ca, cb) = (wilson(a.successes, a.runs), wilson(b.successes, b.runs));
            let v = if ca[0] > cb[1] {
                format!("{} succeeds more often", a.policy)
            } else if cb[0] > ca[1] {
                format!("{} succeeds more often", b.policy)
            } else {
                "no difference at 95 %".to_string()
            };
            out.push((format!("success of {} vs {}", a.policy, b.policy), v));
        }
    }
    out.extend(expectation_verdicts(expect));
    out
}

/// Builds the sensitivity report: `base` the verdicts as run, `flipped`
/// the verdicts under each flip tried (same order as `tried`).
pub fn compare(
    base: &[(String, String)],
    tried: Vec<Flip>,
    flipped: &[Vec<(String, String)>],
    not_tried: Vec<Flip>,
) -> Sensitivity {
    let verdicts = base
        .iter()
        .map(|(name, value)| Sensitive {
            verdict: name.clone(),
            value: value.clone(),
            reversed_by: tried
                .iter()
                .zip(flipped)
                .filter_map(|(f, vs)| {
                    let now = vs.iter().find(|(n, _)| n == name)?;
                    (now.1 != *value).then(|| Reversal {
                        setting: f.setting.clone(),
                        to: f.to.clone(),
                        value: now.1.clone(),
                    })
                })
                .collect(),
        })
        .collect();
    Sensitivity {
        flips: tried,
        not_tried,
        verdicts,
    }
}

impl Sensitivity {
    /// The flips that reverse verdict `name`, as `setting = value` texts.
    pub fn reversing(&self, name: &str) -> Vec<String> {
        (self.verdicts.iter())
            .filter(|v| v.verdict == name)
            .flat_map(|v| {
                v.reversed_by
                    .iter()
                    .map(|r| format!("{} = {}", r.setting, r.to))
            })
            .collect()
    }

    /// The report as text, or as a markdown list (every name escaped):
    /// every verdict, and what reverses it.
    pub fn text(&self, out: &mut String, md: bool) {
        let cell = |t: &str| {
            if md {
                btfsm_core::sanitize::markdown_cell(t)
            } else {
                t.to_string()
            }
        };
        let item = if md { "- " } else { "  " };
        out.push_str(&format!(
            "\nsensitivity ({} policy-independent settings flipped one at a time):\n{}",
            self.flips.len(),
            if md { "\n" } else { "" }
        ));
        for v in &self.verdicts {
            let (name, value) = (cell(&v.verdict), cell(&v.value));
            if v.reversed_by.is_empty() {
                out.push_str(&format!("{item}{name}: {value} — no flip reverses it\n"));
                continue;
            }
            let by: Vec<String> = (v.reversed_by.iter())
                .map(|r| format!("{} = {} ({})", r.setting, r.to, cell(&r.value)))
                .collect();
            out.push_str(&format!(
                "{item}{name}: {value} — reversed by {}\n",
                by.join("; ")
            ));
        }
        if !self.not_tried.is_empty() {
            let n: Vec<String> = self.not_tried.iter().map(Flip::text).collect();
            out.push_str(&format!(
                "{item}not tried, the wall-clock budget ran out first: {}\n",
                n.join("; ")
            ));
        }
    }
}

/// The verdicts of one run of each policy of `s`, its expectations
/// checked (as `sim` without `--runs` computes them).
fn single_verdicts(s: &Scenario, deadline: Option<Instant>) -> Option<Vec<(String, String)>> {
    let (runs, cut) = super::run::run_scenario_within(s, false, deadline);
    if cut {
        return None;
    }
    let (verdicts, skipped) = super::trace::verdicts_within(&runs, FRECHET_POINTS, deadline);
    if !skipped.is_empty() {
        return None;
    }
    let cut_runs = vec![false; runs.len()];
    let expect = super::scenario::expect::check(&s.expect, &runs, &verdicts, &cut_runs);
    Some(run_verdicts(&runs, &verdicts, &expect))
}

/// `sim --sensitivity` without `--runs`: `base` the verdicts of the run
/// as reported; each flip run until `deadline`.
pub fn of_single_run(
    s: &Scenario,
    base: &[(String, String)],
    deadline: Option<Instant>,
) -> Sensitivity {
    sweep(s, base, |t| single_verdicts(t, deadline))
}

/// `sim --runs N --sensitivity`: every flip's `N` episodes (same seeds)
/// until `deadline`; a flip whose episodes did not all complete is not
/// tried.
pub fn of_monte_carlo(
    s: &Scenario,
    base: &[(String, String)],
    budget: &super::episodes::Budget,
) -> Sensitivity {
    sweep(s, base, |t| {
        let mc = super::monte_carlo::monte_carlo_within(
            t,
            budget.runs,
            budget.seed,
            budget.threads,
            budget.deadline,
        );
        if mc.runs < budget.runs {
            return None;
        }
        let expect = super::scenario::expect::check_monte_carlo(&t.expect, &mc);
        Some(monte_carlo_verdicts(&mc, &expect))
    })
}

/// Runs `verdicts_of` on every flip of `s` in order; once one returns
/// `None` (the budget ran out), the rest are not tried.
fn sweep(
    s: &Scenario,
    base: &[(String, String)],
    mut verdicts_of: impl FnMut(&Scenario) -> Option<Vec<(String, String)>>,
) -> Sensitivity {
    let (mut tried, mut flipped, mut not_tried) = (Vec::new(), Vec::new(), Vec::new());
    for (f, t) in flips(s) {
        match not_tried.is_empty().then(|| verdicts_of(&t)).flatten() {
            Some(v) => {
                tried.push(f);
                flipped.push(v);
            }
            None => not_tried.push(f),
        }
    }
    compare(base, tried, &flipped, not_tried)
}

#[cfg(test)]
mod tests;
