//! Rules a policy breaks so badly that it does not load: BehaviorTree.CPP 4
//! refuses such a file when it builds the tree (`createTreeFromFile`) or
//! at its first tick, and btfsm's readers refuse it with a positioned
//! error. `lint` reports those errors as findings of these rules, so a CI
//! gate and code scanning see them with a code like every other finding
//! (ruff reports a syntax error as a diagnostic too). The readers attach
//! the code ([`btfsm_core::diagnostic::Diagnostic::code`]); the other rules do
//! not run on a file that does not load.
//!
//! Sources: BehaviorTree.CPP 4's `ControlNode`/`DecoratorNode` child checks
//! and `ParallelNode::tick` thresholds, its recursive-SubTree check in
//! `XMLParser`, and its include handling.

use super::{Finding, Level, Rule, Sink, Subject, config};
use btfsm_core::diagnostic::Diagnostic;

/// Nothing to check on a loaded policy: these rules are found by the
/// readers.
fn found_by_the_reader(_: &Subject, _: &mut Sink) {}

pub const EMPTY_COMPOSITE: Rule = Rule {
    code: "empty-composite",
    level: Level::Error,
    summary: "a control node (Sequence, Fallback, Parallel...) without children: the file does not load",
    check: found_by_the_reader,
};

pub const WRONG_CHILD_COUNT: Rule = Rule {
    code: "wrong-child-count",
    level: Level::Error,
    summary: "a decorator without one child, a leaf with children, an IfThenElse or SwitchN with a wrong count: does not load",
    check: found_by_the_reader,
};

pub const PARALLEL_THRESHOLD: Rule = Rule {
    code: "parallel-threshold",
    level: Level::Error,
    summary: "a Parallel whose success_count or failure_count exceeds its children: it can never succeed (fail)",
    check: found_by_the_reader,
};

pub const SUBTREE_RECURSION: Rule = Rule {
    code: "subtree-recursion",
    level: Level::Error,
    summary: "a tree that contains itself as a SubTree (or include), directly or through others",
    check: found_by_the_reader,
};

pub const INCLUDE_CYCLE: Rule = Rule {
    code: "include-cycle",
    level: Level::Error,
    summary: "a file that includes itself, directly or through others",
    check: found_by_the_reader,
};

/// The load errors of one input as findings: every error with a code whose
/// rule is not allowed becomes a finding at the rule's configured level;
/// returns them and whether errors without a code remain (the input is
/// then reported as not loading, exit 2). `display` names the input when
/// a diagnostic has no file.
pub fn findings(
    diags: &[Diagnostic],
    display: &str,
    cfg: &config::Config,
) -> (Vec<Finding>, Vec<Diagnostic>) {
    let mut out = Vec::new();
    let mut rest = Vec::new();
    for d in diags {
        let rule = d.code.and_then(super::rule);
        match rule {
            Some(r) if d.is_error() => {
                let level = cfg.level(r);
                if level == Level::Allow {
                    continue;
                }
                let (line, column) = match d.location() {
                    Some((_, l, c)) if l > 0 => (Some(l), Some(c)),
                    _ => (None, None),
                };
                let source = match (&d.file, &d.span) {
                    (Some(f), Some(sp))
                        if sp.end <= f.text.len() && f.text.is_char_boundary(sp.start) =>
                    {
                        Some((f.clone(), sp.clone()))
                    }
                    _ => None,
                };
                out.push(Finding {
                    code: r.code,
                    level,
                    file: d
                        .file
                        .as_ref()
                        .map_or_else(|| display.to_string(), |f| f.path.clone()),
                    line,
                    column,
                    at: String::new(),
                    message: d.message.clone(),
                    help: d.hint.clone().unwrap_or_default(),
                    source,
                });
            }
            _ => rest.push(d.clone()),
        }
    }
    (out, rest)
}
