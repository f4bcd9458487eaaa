//! BehaviorTree.CPP XML (formats 3 and 4, as documented at behaviortree.dev and
//! used by Nav2 and Groot2) read into the BT model.
//!
//! - `<root>` holds `<BehaviorTree ID>` definitions, `<include path>` (relative to
//!   the including file; cycles rejected) and `<TreeNodesModel>`; the tree run is
//!   `--tree ID`, else `main_tree_to_execute`, else the only tree of the main file.
//! - Nodes in compact (`<Sequence>`) or explicit (`<Action ID="...">`) syntax.
//!   `<SubTree ID>` (and format 3's `<SubTreePlus>`) is expanded in place: the
//!   subtree's root takes the SubTree element's place, as TOML subtree includes
//!   do, so counts are those of the expanded tree; recursion is rejected. Its
//!   ports remap the subtree's blackboard entries, so inside the expansion a
//!   port `{key}` becomes the value or outer entry the SubTree maps `key` to
//!   (BehaviorTree.CPP 4 "Remapping ports between Trees and SubTrees"); in a
//!   `BTCPP_format="3"` file a `<SubTree>` port names the outer entry by its
//!   bare name, as BehaviorTree.CPP 3 reads it.
//! - A `<SubTree ID>` that neither the file nor its includes define is read
//!   from the other BehaviorTree.CPP files given together ([`Companions`]),
//!   as BehaviorTree.CPP's factory registers every file of a project.
//! - Built-in types map onto the model (see [`BUILTINS`] and the table in docs/guide/btcpp-xml.md);
//!   other types are resolved through a `<TreeNodesModel>` (in the files read or
//!   given with `--nodes-model`), or `--assume-leaf` decides for leaves.
//! - Node identity (for `named` GED): a `btfsm:id` attribute when present (written
//!   by `btfsm convert`), else the `name` attribute when no other node of the
//!   expanded tree has that name, else the parent's identity and the child's
//!   position (`Parent/2`); the root without a name takes the tree's ID.
//!
//! The expansion walks an explicit stack (no recursion on input depth).

mod companions;
mod expand;
mod flow;
mod ids;
mod loader;
mod node;
pub mod ports;
#[cfg(test)]
mod tests;

pub use companions::{Companions, root_trees};
pub use ids::derive_ids;
use loader::load;
pub use ports::{Dataflow, builtin_ports};

use super::xml::XElem;
use super::{AssumeLeaf, Limits, Loaded};
use btfsm_core::diagnostic::{Diagnostic, SourceFile, suggest};
use btfsm_model::skill::{self, ArgValue, SkillCall, SkillKind};
use btfsm_model::{BtNode, BtNodeKind};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// What a node type is, as a `<TreeNodesModel>` says.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Category {
    Action,
    Condition,
    Control,
    Decorator,
}

impl Category {
    pub fn tag(self) -> &'static str {
        match self {
            Category::Action => "Action",
            Category::Condition => "Condition",
            Category::Control => "Control",
            Category::Decorator => "Decorator",
        }
    }
}

/// BehaviorTree.CPP's built-in node types (formats 3 and 4) and their category.
/// How each maps onto the model is [`builtin_kind`].
pub const BUILTINS: &[(&str, Category)] = &[
    ("Sequence", Category::Control),
    ("ReactiveSequence", Category::Control),
    ("SequenceWithMemory", Category::Control),
    ("SequenceStar", Category::Control),
    ("AsyncSequence", Category::Control),
    ("Fallback", Category::Control),
    ("ReactiveFallback", Category::Control),
    ("AsyncFallback", Category::Control),
    ("Parallel", Category::Control),
    ("ParallelAll", Category::Control),
    ("IfThenElse", Category::Control),
    ("WhileDoElse", Category::Control),
    ("Switch2", Category::Control),
    ("Switch3", Category::Control),
    ("Switch4", Category::Control),
    ("Switch5", Category::Control),
    ("Switch6", Category::Control),
    ("ManualSelector", Category::Control),
    ("TryCatch", Category::Control),
    ("Inverter", Category::Decorator),
    ("ForceSuccess", Category::Decorator),
    ("ForceFailure", Category::Decorator),
    ("RetryUntilSuccessful", Category::Decorator),
    ("RetryUntilSuccesful", Category::Decorator),
    ("Repeat", Category::Decorator),
    ("Timeout", Category::Decorator),
    ("Delay", Category::Decorator),
    ("KeepRunningUntilFailure", Category::Decorator),
    ("RunOnce", Category::Decorator),
    ("Precondition", Category::Decorator),
    ("LoopInt", Category::Decorator),
    ("LoopDouble", Category::Decorator),
    ("LoopString", Category::Decorator),
    ("LoopBool", Category::Decorator),
    ("EntryUpdated", Category::Decorator),
    ("SkipUnlessUpdated", Category::Decorator),
    ("WaitValueUpdate", Category::Decorator),
    ("BlackboardCheckInt", Category::Decorator),
    ("BlackboardCheckDouble", Category::Decorator),
    ("BlackboardCheckString", Category::Decorator),
    ("BlackboardCheckBool", Category::Decorator),
    ("AlwaysSuccess", Category::Action),
    ("AlwaysFailure", Category::Action),
    ("Script", Category::Action),
    ("SetBlackboard", Category::Action),
    ("UnsetBlackboard", Category::Action),
    ("Sleep", Category::Action),
    ("ScriptCondition", Category::Condition),
    ("WasEntryUpdated", Category::Action),
];

/// The BehaviorTree.CPP 4 name of a format-3 built-in renamed in 4.
pub fn v4_name(t: &str) -> &str {
    match t {
        "SequenceStar" => "SequenceWithMemory",
        "RetryUntilSuccesful" => "RetryUntilSuccessful",
        t => t,
    }
}

/// BehaviorTree.CPP 4's rules on a `Parallel` with `n` children: its
/// thresholds are 32-bit `int`s, and one above `n` can never be met.
fn parallel_rule(el: &XElem, n: usize) -> Option<(String, &'static str, Option<&'static str>)> {
    let int = |a: &str| el.attr(a).and_then(|v| v.trim().parse::<i64>().ok());
    // Its ports are `int`: BehaviorTree.CPP 4 refuses a literal out
    // of its range when it creates the tree ("can not be
    // converted"), where i64::MIN was read as a threshold of 1.
    let out_of_range = ["success_count", "failure_count"]
        .into_iter()
        .find_map(|a| {
            let v = el.attr(a)?.trim();
            let digits = v.strip_prefix(['-', '+']).unwrap_or(v);
            let literal = !digits.is_empty() && digits.bytes().all(|b| b.is_ascii_digit());
            (literal && v.parse::<i32>().is_err()).then_some((a, v))
        });
    if let Some((a, v)) = out_of_range {
        return Some((
            format!(
                "`Parallel` {a}={} is out of the range of a 32-bit `int`, which BehaviorTree.CPP 4 refuses",
                btfsm_core::sanitize::shown_max(v, 40)
            ),
            "a number of children, or a negative count from the end (-1: all)",
            None,
        ));
    }
    let over = |k: i64| k > 0 && k as usize > n;
    match (int("success_count"), int("failure_count")) {
        (Some(k), _) if over(k) => Some((
            format!("`Parallel` success_count={k} with {n} children can never succeed"),
            "at most the number of children (-1: all)",
            Some("parallel-threshold"),
        )),
        (_, Some(k)) if over(k) => Some((
            format!("`Parallel` failure_count={k} with {n} children can never fail"),
            "at most the number of children (-1: all)",
            Some("parallel-threshold"),
        )),
        _ => None,
    }
}

/// A rule BehaviorTree.CPP 4 enforces on a built-in node with `n`
/// children (at load or at its first tick): the message, a hint, and the
/// lint code when the problem is one (docs/lint.md).
fn builtin_rule(
    ty: &str,
    el: &XElem,
    n: usize,
) -> Option<(String, &'static str, Option<&'static str>)> {
    match ty {
        "IfThenElse" | "WhileDoElse" if !(2..=3).contains(&n) => Some((
            format!("`{ty}` takes 2 or 3 children, found {n}"),
            "a condition, a branch and an optional else branch",
            Some("wrong-child-count"),
        )),
        "Switch2" | "Switch3" | "Switch4" | "Switch5" | "Switch6" => {
            let cases: usize = ty[6..].parse().unwrap_or(0);
            (n != cases + 1).then(|| {
                (
                    format!(
                        "`{ty}` takes {} children ({cases} cases and a default), found {n}",
                        cases + 1
                    ),
                    "one child per case, then the default",
                    Some("wrong-child-count"),
                )
            })
        }
        "Parallel" => parallel_rule(el, n),
        "RetryUntilSuccessful" if el.attr("num_attempts").is_none() => Some((
            "`RetryUntilSuccessful` needs `num_attempts`".into(),
            "write num_attempts=\"3\" (-1: forever)",
            None,
        )),
        // Ports these built-ins read when they are ticked: BehaviorTree.CPP
        // 4 fails the node ("Missing parameter [msec] in SleepNode").
        "Sleep" | "Timeout" if el.attr("msec").is_none() => Some((
            format!("`{ty}` needs `msec`"),
            "write msec=\"1000\" (milliseconds)",
            None,
        )),
        "Delay" if el.attr("delay_msec").is_none() => Some((
            "`Delay` needs `delay_msec`".into(),
            "write delay_msec=\"1000\" (milliseconds)",
            None,
        )),
        "Repeat" if el.attr("num_cycles").is_none() => Some((
            "`Repeat` needs `num_cycles`".into(),
            "write num_cycles=\"3\" (-1: forever)",
            None,
        )),
        // Ports these built-ins read when they are created: BehaviorTree.CPP
        // 4 refuses the tree without them ("Missing port [code] in Script").
        "Script" | "ScriptCondition" if el.attr("code").is_none() => Some((
            format!("`{ty}` needs `code`"),
            "write code=\"key := 1\" (the script to run)",
            None,
        )),
        "Precondition" if el.attr("if").is_none() => Some((
            "`Precondition` needs `if`".into(),
            "write if=\"battery > 20\" (the condition script)",
            None,
        )),
        "WasEntryUpdated" | "SkipUnlessUpdated" | "WaitValueUpdate"
            if el.attr("entry").is_none() =>
        {
            Some((
                format!("`{ty}` needs `entry`"),
                "write entry=\"{key}\" (the blackboard entry to watch)",
                None,
            ))
        }
        "LoopInt" | "LoopDouble" | "LoopString" | "LoopBool" if el.attr("queue").is_none() => {
            Some((
                format!("`{ty}` needs `queue`"),
                "write queue=\"{key}\" or queue=\"1;2;3\"",
                None,
            ))
        }
        _ => None,
    }
}

/// The category of a built-in type.
pub fn builtin(name: &str) -> Option<Category> {
    BUILTINS.iter().find(|(n, _)| *n == name).map(|(_, c)| *c)
}

/// The model kind of a built-in type with `n` children, the attributes that the
/// kind carries (not kept as ports), and whether the type name must be kept
/// (it is not the one [`canonical_type`] gives the kind).
pub fn builtin_kind(
    name: &str,
    e: &XElem,
    n: usize,
) -> (BtNodeKind, &'static [&'static str], bool) {
    let int = |a: &str| e.attr(a).and_then(|v| v.trim().parse::<i64>().ok());
    match name {
        "Sequence" => (BtNodeKind::SequenceMemory, &[], false),
        "ReactiveSequence" => (BtNodeKind::Sequence, &[], false),
        "SequenceWithMemory" | "SequenceStar" | "AsyncSequence" => {
            (BtNodeKind::SequenceMemory, &[], true)
        }
        "Fallback" => (BtNodeKind::FallbackMemory, &[], false),
        "ReactiveFallback" => (BtNodeKind::Fallback, &[], false),
        "AsyncFallback" => (BtNodeKind::FallbackMemory, &[], true),
        "Parallel" => {
            // Format 4: success_count (negative: counted from the number of
            // children, -1 = all); format 3: success_threshold / threshold.
            let (attr, v) = ["success_count", "success_threshold", "threshold"]
                .iter()
                .find_map(|a| e.attr(a).map(|_| (*a, int(a))))
                .unwrap_or(("", Some(-1)));
            match v {
                Some(c) => {
                    let nn = n as i64;
                    let s = if c < 0 { nn + c + 1 } else { c };
                    let success = s.clamp(1, nn.max(1)) as usize;
                    let keep = attr != "success_count";
                    let consumed: &'static [&'static str] = match attr {
                        "success_count" => &["success_count"],
                        "success_threshold" => &["success_threshold"],
                        "threshold" => &["threshold"],
                        _ => &[],
                    };
                    (BtNodeKind::Parallel { success }, consumed, keep)
                }
                None => (BtNodeKind::Control, &[], true),
            }
        }
        "ParallelAll" => (BtNodeKind::Parallel { success: n.max(1) }, &[], true),
        "Inverter" => (BtNodeKind::Inverter, &[], false),
        "ForceSuccess" => (BtNodeKind::ForceSuccess, &[], false),
        "ForceFailure" => (BtNodeKind::ForceFailure, &[], false),
        "RetryUntilSuccessful" | "RetryUntilSuccesful" => match int("num_attempts") {
            Some(t) if t >= 0 => (
                BtNodeKind::Retry {
                    times: t.min(u32::MAX as i64) as u32,
                },
                &["num_attempts"],
                false,
            ),
            _ => (BtNodeKind::Decorator, &[], true),
        },
        "Repeat" => match int("num_cycles") {
            Some(t) if t >= 0 => (
                BtNodeKind::Repeat {
                    times: Some(t.min(u32::MAX as i64) as u32),
                },
                &["num_cycles"],
                false,
            ),
            Some(-1) => (BtNodeKind::Repeat { times: None }, &["num_cycles"], false),
            _ => (BtNodeKind::Decorator, &[], true),
        },
        "Timeout" => match int("msec") {
            Some(ms) if ms >= 0 => (BtNodeKind::Timeout { ms: ms as u64 }, &["msec"], false),
            _ => (BtNodeKind::Decorator, &[], true),
        },
        _ => match builtin(name) {
            Some(Category::Control) => (BtNodeKind::Control, &[], true),
            Some(Category::Decorator) => (BtNodeKind::Decorator, &[], true),
            Some(Category::Condition) => (BtNodeKind::Condition, &[], true),
            _ => (BtNodeKind::Action, &[], true),
        },
    }
}

/// The BehaviorTree.CPP type written for a model kind that carries no type name.
pub fn canonical_type(kind: BtNodeKind) -> Option<&'static str> {
    Some(match kind {
        BtNodeKind::Sequence => "ReactiveSequence",
        BtNodeKind::Fallback => "ReactiveFallback",
        BtNodeKind::SequenceMemory => "Sequence",
        BtNodeKind::FallbackMemory => "Fallback",
        BtNodeKind::Parallel { .. } => "Parallel",
        BtNodeKind::Inverter => "Inverter",
        BtNodeKind::ForceSuccess => "ForceSuccess",
        BtNodeKind::ForceFailure => "ForceFailure",
        BtNodeKind::Repeat { .. } => "Repeat",
        BtNodeKind::Retry { .. } => "RetryUntilSuccessful",
        BtNodeKind::Timeout { .. } => "Timeout",
        _ => return None,
    })
}

/// Reads a BehaviorTree.CPP XML file (with its includes).
pub fn load_file(path: &Path, limits: &Limits) -> Result<Loaded, Vec<Diagnostic>> {
    let shown = path.display().to_string();
    let file = super::toml::read_source(path, &shown, limits)?;
    load_read(file, path, limits)
}

/// Reads BehaviorTree.CPP XML already read from `path` (includes resolve
/// beside it).
pub fn load_read(
    file: Arc<SourceFile>,
    path: &Path,
    limits: &Limits,
) -> Result<Loaded, Vec<Diagnostic>> {
    let base = path.parent().unwrap_or(Path::new("")).to_path_buf();
    load(file, super::toml::canonical(path), base, limits)
}

/// Reads BehaviorTree.CPP XML from text; includes resolve against `base`.
pub fn parse_str(
    name: &str,
    text: &str,
    base: &Path,
    limits: &Limits,
) -> Result<Loaded, Vec<Diagnostic>> {
    let file = SourceFile::new(name, text);
    load(file, PathBuf::from(name), base.to_path_buf(), limits)
}

/// A skill argument from attribute text: integer, float, boolean or string.
pub fn arg_value(v: &str) -> ArgValue {
    if let Ok(i) = v.parse::<i64>() {
        ArgValue::Int(i)
    } else if let Ok(x) = v.parse::<f64>()
        && x.is_finite()
        && v.chars().any(|c| c.is_ascii_digit())
    {
        ArgValue::Float(x)
    } else if v == "true" || v == "false" {
        ArgValue::Bool(v == "true")
    } else {
        ArgValue::Str(v.to_string())
    }
}
