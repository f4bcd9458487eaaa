//! Which BehaviorTree.CPP 4 node type each BT node is ticked as
//! (docs/bt-semantics.md, "Node types"): from its model kind and the type
//! name kept from XML, with the numbers the type reads from its ports; and
//! the types the executor refuses rather than approximates.

use btfsm_model::BtNodeKind;
use btfsm_model::bt::{Bt, BtNode};

/// How a node is ticked: one BehaviorTree.CPP node type each (the TOML kind
/// names in parentheses).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Op {
    /// ReactiveSequence (`sequence`).
    Sequence,
    /// ReactiveFallback (`fallback`).
    Fallback,
    /// Sequence (`sequence_memory`): resumes at its running child, starts
    /// over after a failure.
    SequenceMemory,
    /// Fallback (`fallback_memory`).
    FallbackMemory,
    /// SequenceWithMemory: resumes at its running child and at a failed one.
    SequenceWithMemory,
    AsyncSequence,
    AsyncFallback,
    /// Parallel (`parallel`): a child that finished is not ticked again until
    /// the node finishes.
    Parallel,
    ParallelAll,
    IfThenElse,
    WhileDoElse,
    Inverter,
    ForceSuccess,
    ForceFailure,
    /// Repeat (`repeat`).
    Repeat,
    /// RetryUntilSuccessful (`retry`).
    Retry,
    KeepRunningUntilFailure,
    /// Timeout (`timeout`), on simulated time.
    Timeout,
    /// A kind the executor does not model (scenarios and `tick` refuse it):
    /// passes its first child's status through.
    PassThrough,
    /// An action bound to a skill.
    Action,
    /// A condition bound to a skill.
    Condition,
    /// A leaf without a binding: fails.
    Unbound,
}

impl Op {
    pub(super) fn is_decorator(self) -> bool {
        matches!(
            self,
            Op::Inverter
                | Op::ForceSuccess
                | Op::ForceFailure
                | Op::Repeat
                | Op::Retry
                | Op::KeepRunningUntilFailure
                | Op::Timeout
                | Op::PassThrough
        )
    }
}

/// A threshold as BehaviorTree.CPP reads it: negative counts from the
/// number of children (-1 = all).
fn threshold(v: i64, n: usize) -> i64 {
    if v < 0 { (n as i64 + v + 1).max(0) } else { v }
}

/// An integer port of a node.
fn port(n: &BtNode, name: &str) -> Option<i64> {
    n.ports.get(name).and_then(|v| v.trim().parse::<i64>().ok())
}

/// The op of a node (and its numbers), or why the executor cannot tick it
/// as BehaviorTree.CPP 4 does.
pub(super) fn op_of(n: &BtNode) -> Result<(Op, i64, i64), String> {
    let ty = n.type_name.as_deref();
    let k = n.children.len();
    Ok(match n.kind {
        BtNodeKind::Sequence => (Op::Sequence, 0, 0),
        BtNodeKind::Fallback => (Op::Fallback, 0, 0),
        BtNodeKind::SequenceMemory => match ty {
            None | Some("Sequence") => (Op::SequenceMemory, 0, 0),
            Some("SequenceWithMemory" | "SequenceStar") => (Op::SequenceWithMemory, 0, 0),
            Some("AsyncSequence") => (Op::AsyncSequence, 0, 0),
            Some(t) => return Err(format!("`{t}`")),
        },
        BtNodeKind::FallbackMemory => match ty {
            None | Some("Fallback") => (Op::FallbackMemory, 0, 0),
            Some("AsyncFallback") => (Op::AsyncFallback, 0, 0),
            Some(t) => return Err(format!("`{t}`")),
        },
        BtNodeKind::Parallel { success } => match ty {
            None | Some("Parallel") => {
                // The paper's Parallel fails when it can no longer succeed;
                // an imported one has BehaviorTree.CPP's `failure_count`.
                let fail = port(n, "failure_count")
                    .map_or((k - success.min(k)) as i64 + 1, |f| threshold(f, k));
                (Op::Parallel, success as i64, fail)
            }
            Some("ParallelAll") => {
                let f = threshold(port(n, "max_failures").unwrap_or(1), k);
                (Op::ParallelAll, 0, f)
            }
            Some(t) => return Err(format!("`{t}`")),
        },
        BtNodeKind::Inverter => (Op::Inverter, 0, 0),
        BtNodeKind::ForceSuccess => (Op::ForceSuccess, 0, 0),
        BtNodeKind::ForceFailure => (Op::ForceFailure, 0, 0),
        BtNodeKind::Repeat { times } => (Op::Repeat, times.map_or(-1, i64::from), 0),
        BtNodeKind::Retry { times } => (Op::Retry, i64::from(times), 0),
        BtNodeKind::Timeout { ms } => (Op::Timeout, ms.min(i64::MAX as u64) as i64, 0),
        BtNodeKind::Control => match ty {
            Some(t @ ("IfThenElse" | "WhileDoElse")) => {
                if k != 2 && k != 3 {
                    return Err(format!(
                        "`{t}` with {k} children (BehaviorTree.CPP 4 takes 2 or 3)"
                    ));
                }
                let op = if t == "IfThenElse" {
                    Op::IfThenElse
                } else {
                    Op::WhileDoElse
                };
                (op, 0, 0)
            }
            t => return Err(format!("`{}`", t.unwrap_or("control"))),
        },
        BtNodeKind::Decorator => match ty {
            Some("KeepRunningUntilFailure") => (Op::KeepRunningUntilFailure, 0, 0),
            t => return Err(format!("`{}`", t.unwrap_or("decorator"))),
        },
        BtNodeKind::Action => (Op::Action, 0, 0),
        BtNodeKind::Condition => (Op::Condition, 0, 0),
    })
}

/// BehaviorTree.CPP 4's pre- and post-condition ports (scripts run around
/// a node's tick), which the executor does not model.
use btfsm_format::btcpp_xml::ports::SCRIPT_ATTRS as PRE_POST;

/// Why the executor cannot tick node `n` as BehaviorTree.CPP 4 does (its
/// type, as written, or a pre/post condition), if it cannot.
pub fn refused(n: &BtNode) -> Option<String> {
    if let Some(p) = n.ports.keys().find(|p| PRE_POST.contains(&p.as_str())) {
        return Some(format!("`{p}` (a pre/post-condition script)"));
    }
    op_of(n).err()
}

/// The first node (in pre-order) whose type the executor cannot tick as
/// BehaviorTree.CPP 4 does, with what it is (`tick` refuses such a tree).
pub fn unsupported(bt: &Bt) -> Option<(usize, String)> {
    let k = |i: usize| bt.nodes[i].children.len() as i64;
    bt.preorder().into_iter().find_map(|i| {
        let n = &bt.nodes[i];
        if let Some(what) = refused(n) {
            return Some((i, what));
        }
        match op_of(n) {
            Err(what) => Some((i, what)),
            Ok((Op::Parallel, s, f)) if s < 1 || f < 1 || s > k(i) || f > k(i) => Some((
                i,
                "a `Parallel` whose thresholds are not between 1 and its number of children".into(),
            )),
            Ok((Op::ParallelAll, _, f)) if f > k(i) => Some((
                i,
                "a `ParallelAll` whose `max_failures` is more than its children".into(),
            )),
            Ok((Op::Timeout, ..)) => Some((i, "`Timeout` (wall-clock time)".into())),
            Ok((Op::Sequence, ..))
                if (n.children.iter())
                    .filter(|&&c| matches!(op_of(&bt.nodes[c]), Ok((Op::AsyncSequence, ..))))
                    .count()
                    > 1 =>
            {
                Some((
                    i,
                    "a `ReactiveSequence` with more than one `AsyncSequence` child (BehaviorTree.CPP 4 refuses it)"
                        .into(),
                ))
            }
            _ => None,
        }
    })
}
