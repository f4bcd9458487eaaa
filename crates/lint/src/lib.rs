//! `btfsm lint`: coded rules over loaded policies, as ruff and cargo-deny
//! have them — each rule a stable kebab-case code, a default level, a
//! one-line summary, and a page in docs/lint.md with a bad and a good
//! example (and a fixture under tests/fixtures/lint/ with a snapshot test).
//! Levels are changed per code by `--deny`/`--warn`/`--allow` or a
//! `[lint]` table in `btfsm.toml` ([`config`]). Findings print as
//! positioned text, JSON, SARIF 2.1.0 ([`sarif`]) for code scanning, or a
//! JUnit XML test report ([`junit`]) for CI.
//!
//! Rules: [`structure`] (BT and FSM shape), [`paper`] (the paper's notions:
//! chattering-prone precondition order, unguarded actions, fault tolerance,
//! fully connected states), [`dataflow`] (BehaviorTree.CPP ports and
//! blackboard keys), [`load`] (what makes a file not load: the readers
//! find it, lint reports it with a code).

pub mod config;
pub mod dataflow;
pub mod junit;
pub mod load;
pub mod models;
pub mod paper;
pub mod sarif;
pub mod search;
pub mod structure;

use btfsm_core::diagnostic::SourceFile;
use btfsm_model::Policy;
use std::ops::Range;
use std::sync::Arc;

/// How serious a finding is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Level {
    /// Not reported (`--allow`).
    Allow,
    Note,
    Warning,
    Error,
}

impl Level {
    pub fn as_str(self) -> &'static str {
        match self {
            Level::Allow => "allow",
            Level::Note => "note",
            Level::Warning => "warning",
            Level::Error => "error",
        }
    }
}

/// A rule: its code, default level, summary, and check.
pub struct Rule {
    pub code: &'static str,
    pub level: Level,
    pub summary: &'static str,
    pub check: fn(&Subject, &mut Sink),
}

/// What a rule checks: the policy and, for a BehaviorTree.CPP tree, its
/// blackboard dataflow. Dereferences to the policy.
pub struct Subject<'a> {
    pub policy: &'a Policy,
    pub dataflow: Option<&'a btfsm_format::btcpp_xml::Dataflow>,
}

impl std::ops::Deref for Subject<'_> {
    type Target = Policy;
    fn deref(&self) -> &Policy {
        self.policy
    }
}

/// Every rule, in docs/lint.md order.
pub const RULES: &[Rule] = &[
    structure::UNREACHABLE_CHILD,
    structure::REACTIVE_ASYNC_SIBLINGS,
    structure::STATE_WITHOUT_EXIT,
    structure::OUTCOME_NEVER_REACHED,
    paper::CHATTERING_PRECONDITION_ORDER,
    paper::UNGUARDED_FALLBACK_ACTION,
    paper::NOT_FAULT_TOLERANT,
    paper::FULLY_CONNECTED_STATE,
    paper::SELECTOR_WITHOUT_RETURN,
    dataflow::OUTPUT_PORT_LITERAL,
    dataflow::UNDECLARED_PORT,
    dataflow::MISSING_REQUIRED_PORT,
    dataflow::MISSING_MODEL_PORT,
    dataflow::READ_BEFORE_WRITE,
    dataflow::KEY_NEVER_READ,
    dataflow::PORT_TYPE_MISMATCH,
    dataflow::SUBTREE_REMAP_UNPROVIDED,
    load::EMPTY_COMPOSITE,
    load::WRONG_CHILD_COUNT,
    load::PARALLEL_THRESHOLD,
    load::SUBTREE_RECURSION,
    load::INCLUDE_CYCLE,
    models::UNKNOWN_NODE_TYPE,
    models::UNKNOWN_SUBTREE,
    models::MODEL_CONFLICT,
    load::LOAD_ERROR,
];

/// The rule of `code`.
pub fn rule(code: &str) -> Option<&'static Rule> {
    RULES.iter().find(|r| r.code == code)
}

/// What a rule reports about one node or state.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Raw {
    pub message: String,
    pub help: String,
    /// The node or state (its id or path) the finding is about.
    pub at: String,
    pub span: Option<Range<usize>>,
    /// The highest level it is reported at, whatever the rule's (a finding
    /// the rule is less sure of: `unknown-node-type` without a model).
    pub cap: Option<Level>,
}

/// Where rules put what they find.
#[derive(Default)]
pub struct Sink {
    pub found: Vec<Raw>,
}

impl Sink {
    pub fn push(&mut self, at: &str, span: Option<Range<usize>>, message: String, help: String) {
        self.push_capped(at, span, message, help, None);
    }

    /// [`Sink::push`] of a finding reported at `cap` at most.
    pub fn push_capped(
        &mut self,
        at: &str,
        span: Option<Range<usize>>,
        message: String,
        help: String,
        cap: Option<Level>,
    ) {
        self.found.push(Raw {
            message,
            help,
            at: at.to_string(),
            span,
            cap,
        });
    }
}

/// One finding, at its level, in its file.
#[derive(Debug, Clone, serde::Serialize)]
pub struct Finding {
    pub code: &'static str,
    pub level: Level,
    pub file: String,
    /// 1-based line and column, when the finding has a position.
    pub line: Option<usize>,
    pub column: Option<usize>,
    pub at: String,
    pub message: String,
    pub help: String,
    #[serde(skip)]
    pub source: Option<(Arc<SourceFile>, Range<usize>)>,
}

/// Runs every rule not allowed on a policy read from `file` (`display`:
/// its path as shown), in rule order, findings of a rule in the order
/// found. A span is kept only when it lies in `file` (a node read from an
/// included file carries a span of that file: it is reported by name).
pub fn lint(
    policy: &Policy,
    file: Option<&Arc<SourceFile>>,
    display: &str,
    cfg: &config::Config,
) -> Vec<Finding> {
    let subject = Subject {
        policy,
        dataflow: None,
    };
    lint_subject(&subject, file, display, cfg)
}

/// [`lint`] of a policy with its dataflow (a loaded BehaviorTree.CPP tree:
/// [`btfsm_format::Loaded::dataflow`]).
pub fn lint_subject(
    subject: &Subject,
    file: Option<&Arc<SourceFile>>,
    display: &str,
    cfg: &config::Config,
) -> Vec<Finding> {
    let mut out = Vec::new();
    for r in RULES {
        let level = cfg.level(r);
        if level == Level::Allow {
            continue;
        }
        let mut sink = Sink::default();
        (r.check)(subject, &mut sink);
        // A finding in a SubTree expanded several times is said once.
        let mut said = std::collections::HashSet::new();
        for raw in sink.found {
            if !said.insert((raw.message.clone(), raw.span.clone())) {
                continue;
            }
            let source = match (file, raw.span) {
                (Some(f), Some(sp))
                    if sp.end <= f.text.len() && f.text.is_char_boundary(sp.start) =>
                {
                    Some((f.clone(), sp))
                }
                _ => None,
            };
            let (line, column) = match &source {
                Some((f, sp)) => {
                    let (l, c) = f.line_col(sp.start);
                    (Some(l), Some(c))
                }
                None => (None, None),
            };
            out.push(Finding {
                code: r.code,
                level: raw.cap.map_or(level, |c| c.min(level)),
                file: display.to_string(),
                line,
                column,
                at: raw.at,
                message: raw.message,
                help: raw.help,
                source,
            });
        }
    }
    out
}

/// A finding as positioned text (file:line:col, snippet, caret, hint), its
/// code after the level as clippy prints it: `warning[unreachable-child]: ...`.
pub fn render_text(f: &Finding) -> String {
    use btfsm_core::diagnostic::Diagnostic;
    let mut d = match f.level {
        Level::Error => Diagnostic::error(f.message.clone()),
        _ => Diagnostic::warning(f.message.clone()),
    }
    .hint(f.help.clone());
    d = match &f.source {
        Some((file, sp)) => d.at(file, sp.clone()),
        None => {
            d.message = format!(
                "{} (in {})",
                d.message,
                btfsm_core::sanitize::shown(&f.file)
            );
            d
        }
    };
    let text = d.to_string();
    let head = match f.level {
        Level::Error => "error",
        _ => "warning",
    };
    match text.strip_prefix(&format!("{head}: ")) {
        Some(rest) => format!("{}[{}]: {rest}", f.level.as_str(), f.code),
        None => text,
    }
}

#[cfg(test)]
mod dataflow_tests;
#[cfg(test)]
mod tests;
