//! A symbolic scenario's `[expect]` (issue 31 item 6): the planar
//! scenario's table (`crate::scenario::expect`) on the runs of the domain's
//! world — which policies reach the goal, which end how, which pairs match
//! or differ — read with positions and checked against the runs, so that a
//! failed expectation makes `sim` exit 1 as it does in the planar room.
//!
//! ```toml
//! [expect]
//! reach_goal = ["Fig. 1 BT baseline"]
//! miss_goal = ["Fig. 2 FSM sequential"]
//! outcome = { "Fig. 3 BT chattering" = "chattering" }
//! match = [["Fig. 1 BT baseline", "Fig. 4 FSM fault tolerant"]]
//! differ = [["Fig. 1 BT baseline", "Fig. 2 FSM sequential"]]
//! ```

use super::run::{SymRun, first_difference};
use crate::scenario::expect::{Check, ExpectResult, Expectation, Status};
use crate::trace::Outcome;
use btfsm_core::diagnostic::{Diagnostic, SourceFile, suggest};
use serde::Deserialize;
use std::collections::BTreeMap;
use std::sync::Arc;
use toml::Spanned;

/// `[expect]` as written.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct RawExpect {
    #[serde(default)]
    reach_goal: Vec<Spanned<String>>,
    #[serde(default)]
    miss_goal: Vec<Spanned<String>>,
    #[serde(default)]
    outcome: BTreeMap<Spanned<String>, Spanned<String>>,
    #[serde(default, rename = "match")]
    matches: Vec<Spanned<[Spanned<String>; 2]>>,
    #[serde(default)]
    differ: Vec<Spanned<[Spanned<String>; 2]>>,
}

/// Expectations a symbolic scenario holds at most.
const MAX_EXPECTATIONS: usize = 10_000;

/// The expectations of `raw`, every name checked against the policies'
/// `names` (errors, positioned, into `diags`).
pub(super) fn read(
    raw: &RawExpect,
    names: &[String],
    file: &Arc<SourceFile>,
    diags: &mut Vec<Diagnostic>,
) -> Vec<Expectation> {
    let mut find = |n: &Spanned<String>| {
        let i = names.iter().position(|x| x == n.get_ref());
        if i.is_none() {
            diags.push(
                Diagnostic::error(format!(
                    "`[expect]` names no policy of the scenario: `{}`",
                    btfsm_core::sanitize::shown(n.get_ref())
                ))
                .at(file, n.span())
                .hint(suggest(n.get_ref(), names.iter().map(String::as_str))),
            );
        }
        i
    };
    let mut out = Vec::new();
    let mut bad = Vec::new();
    for n in &raw.reach_goal {
        if let Some(i) = find(n) {
            out.push(named(
                Check::ReachGoal(i),
                format!("{} reaches the goal", n.get_ref()),
            ));
        }
    }
    for n in &raw.miss_goal {
        if let Some(i) = find(n) {
            out.push(named(
                Check::MissGoal(i),
                format!("{} misses the goal", n.get_ref()),
            ));
        }
    }
    for (n, o) in &raw.outcome {
        let outcome = match o.get_ref().as_str() {
            "success" => Some(Outcome::Success),
            "failure" => Some(Outcome::Failure),
            "chattering" => Some(Outcome::Chattering),
            "timeout" => Some(Outcome::Timeout),
            _ => None,
        };
        let Some(outcome) = outcome else {
            bad.push(
                Diagnostic::error(format!(
                    "unknown outcome `{}`",
                    btfsm_core::sanitize::shown(o.get_ref())
                ))
                .at(file, o.span())
                .hint("an outcome is success, failure, chattering or timeout"),
            );
            continue;
        };
        if let Some(i) = find(n) {
            let name = format!("{} ends {}", n.get_ref(), outcome.as_str());
            out.push(named(Check::Outcome(i, outcome), name));
        }
    }
    for (pairs, want_match) in [(&raw.matches, true), (&raw.differ, false)] {
        for p in pairs {
            let [a, b] = p.get_ref();
            let (Some(x), Some(y)) = (find(a), find(b)) else {
                continue;
            };
            let (check, verb) = if want_match {
                (Check::Match(x, y), "matches")
            } else {
                (Check::Differ(x, y), "differs from")
            };
            out.push(named(
                check,
                format!("{} {verb} {}", a.get_ref(), b.get_ref()),
            ));
        }
    }
    diags.extend(bad);
    if out.len() > MAX_EXPECTATIONS {
        out.truncate(MAX_EXPECTATIONS);
        diags.push(
            Diagnostic::error(format!("more than {MAX_EXPECTATIONS} expectations"))
                .in_file(file)
                .hint("a scenario holds at most 10000 expectations (a fixed limit)"),
        );
    }
    out
}

fn named(check: Check, name: String) -> Expectation {
    Expectation { check, name }
}

/// Checks the expectations against one run per policy (in the scenario's
/// order); a run the deadline cut short makes what names it `undecided`.
pub fn check(expect: &[Expectation], runs: &[SymRun]) -> Vec<ExpectResult> {
    let found = |r: &SymRun| format!("outcome {}", r.outcome.as_str());
    let decided = |ok: bool, cut: bool| match (ok, cut) {
        (_, true) => Status::Undecided,
        (true, _) => Status::Pass,
        (false, _) => Status::Fail,
    };
    (expect.iter())
        .map(|e| {
            let (status, text) = match e.check {
                Check::ReachGoal(i) => {
                    let r = &runs[i];
                    (
                        decided(r.outcome == Outcome::Success, r.cut_short),
                        found(r),
                    )
                }
                // A symbolic run keeps no final facts: the goal is missed
                // when the run does not end `success` (which needs them).
                Check::MissGoal(i) => {
                    let r = &runs[i];
                    (
                        decided(r.outcome != Outcome::Success, r.cut_short),
                        found(r),
                    )
                }
                Check::Outcome(i, o) => {
                    let r = &runs[i];
                    (decided(r.outcome == o, r.cut_short), found(r))
                }
                Check::Match(a, b) | Check::Differ(a, b) => {
                    let d = first_difference(&runs[a], &runs[b]);
                    let text = match d {
                        None => "they match".to_string(),
                        Some(k) => format!("they differ from action {}", k + 1),
                    };
                    let want = matches!(e.check, Check::Match(..));
                    let cut = runs[a].cut_short || runs[b].cut_short;
                    (decided(d.is_none() == want, cut), text)
                }
                Check::Completion(..) | Check::SuccessRate(..) | Check::MatchRate(..) => {
                    (Status::Undecided, "not in a symbolic run".into())
                }
            };
            ExpectResult {
                name: e.name.clone(),
                status,
                found: text,
                reversed_by: Vec::new(),
            }
        })
        .collect()
}
