//! Rules the readers find: what BehaviorTree.CPP 4 refuses when it builds
//! the tree (`createTreeFromFile`: an empty composite, a decorator without
//! one child, a recursive SubTree, a cyclic include) makes the file not
//! load, and what it refuses only when it ticks the node (a Parallel
//! threshold, an IfThenElse or SwitchN child count) is read for `lint` as
//! a coded warning on a file that loads, so the other rules still run
//! ([`btfsm_format::Limits::for_lint`]). `lint` reports both as findings
//! of these rules, so a CI gate and code scanning see them with a code like
//! every other finding (ruff reports a syntax error as a diagnostic too);
//! any other reason a file does not load is a `load-error` finding, and
//! a file that was not linted is always reported. The readers attach the
//! code ([`btfsm_core::diagnostic::Diagnostic::code`]).
//!
//! Sources: BehaviorTree.CPP 4's `ControlNode`/`DecoratorNode` child checks
//! and `ParallelNode::tick` thresholds, its recursive-SubTree check in
//! `XMLParser`, and its include handling; which of them fail at creation
//! and which at the first tick is checked against behaviortreepy by
//! tests/differential/btcpp_when.py.

use super::{Finding, Level, Rule, Sink, Subject, config};
use btfsm_core::diagnostic::Diagnostic;

/// Nothing to check on a loaded policy: these rules are found by the
/// readers.
pub(crate) fn found_by_the_reader(_: &Subject, _: &mut Sink) {}

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

pub const LOAD_ERROR: Rule = Rule {
    code: "load-error",
    level: Level::Error,
    summary: "a file that does not load (malformed, unknown tree, a limit passed...): it was not linted",
    check: found_by_the_reader,
};

/// The diagnostics of one input as findings. Every diagnostic with a code
/// (an error of a file that does not load, or a warning of one that does:
/// a Parallel threshold BehaviorTree.CPP meets only when it ticks) is a
/// finding of that rule at its configured level; every error without one
/// is a `load-error`. A file that does not load (`loaded` false) and would
/// show no error-level finding — its coded errors allowed or lowered — gets
/// a `load-error` saying it was not linted: a file is never dropped
/// silently, whatever `--allow` says. `display` names the input when a
/// diagnostic has no file.
pub fn findings(
    diags: &[Diagnostic],
    display: &str,
    cfg: &config::Config,
    loaded: bool,
) -> Vec<Finding> {
    let mut out = Vec::new();
    for d in diags {
        let rule = match d.code.and_then(super::rule) {
            Some(r) => r,
            None if d.is_error() => &LOAD_ERROR,
            None => continue,
        };
        let level = cfg.level(rule);
        if level == Level::Allow {
            continue;
        }
        out.push(finding(d, rule, level, display));
    }
    if !loaded && !out.iter().any(|f| f.level == Level::Error) {
        let first = diags.iter().find(|d| d.is_error());
        let why = first.map_or_else(String::new, |d| format!(": {}", d.message));
        let mut f = Finding {
            message: format!("this file was not linted: it does not load{why}"),
            help: "fix the load error (`btfsm validate` shows every one); lint reports it whatever --allow says".into(),
            ..first.map_or_else(
                || finding(&Diagnostic::error(""), &LOAD_ERROR, Level::Error, display),
                |d| finding(d, &LOAD_ERROR, Level::Error, display),
            )
        };
        f.code = LOAD_ERROR.code;
        f.level = Level::Error;
        out.push(f);
    }
    out
}

/// One diagnostic as a finding of `rule` at `level`.
fn finding(d: &Diagnostic, rule: &Rule, level: Level, display: &str) -> Finding {
    let (line, column) = match d.location() {
        Some((_, l, c)) if l > 0 => (Some(l), Some(c)),
        _ => (None, None),
    };
    let source = match (&d.file, &d.span) {
        (Some(f), Some(sp)) if sp.end <= f.text.len() && f.text.is_char_boundary(sp.start) => {
            Some((f.clone(), sp.clone()))
        }
        _ => None,
    };
    Finding {
        code: rule.code,
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
    }
}
