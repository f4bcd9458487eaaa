//! Structure rules: what the shape of a BT or an FSM says before it runs
//! (docs/lint.md). BT semantics are BehaviorTree.CPP 4's
//! (docs/bt-semantics.md). What BehaviorTree.CPP itself refuses — empty
//! composites, decorators without one child, recursive SubTrees, Parallel
//! thresholds above the number of children — is found by the readers and
//! reported by the rules of [`super::load`].

use super::{Level, Rule, Sink, Subject};
use btfsm_model::{Bt, BtNodeKind, PolicyBody, StateBody, Target};

/// How a subtree always ends, when its shape decides it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Always {
    Succeeds,
    Fails,
}

/// Does node `n` always end the same way, whatever the world?
/// `AlwaysSuccess`/`AlwaysFailure` leaves, `ForceSuccess`/`ForceFailure`
/// (once their child finishes), an `Inverter` of one that always ends.
fn always(bt: &Bt, n: usize) -> Option<Always> {
    let node = &bt.nodes[n];
    let ty = node.type_name.as_deref().unwrap_or("");
    match node.kind {
        BtNodeKind::ForceSuccess => Some(Always::Succeeds),
        BtNodeKind::ForceFailure => Some(Always::Fails),
        BtNodeKind::Inverter => {
            node.children
                .first()
                .and_then(|&c| always(bt, c))
                .map(|a| match a {
                    Always::Succeeds => Always::Fails,
                    Always::Fails => Always::Succeeds,
                })
        }
        BtNodeKind::Action | BtNodeKind::Condition if node.skill.is_none() => match ty {
            "AlwaysSuccess" => Some(Always::Succeeds),
            "AlwaysFailure" => Some(Always::Fails),
            _ => None,
        },
        _ => None,
    }
}

fn is_sequence(k: BtNodeKind) -> bool {
    matches!(k, BtNodeKind::Sequence | BtNodeKind::SequenceMemory)
}

fn is_fallback(k: BtNodeKind) -> bool {
    matches!(k, BtNodeKind::Fallback | BtNodeKind::FallbackMemory)
}

pub const UNREACHABLE_CHILD: Rule = Rule {
    code: "unreachable-child",
    level: Level::Warning,
    summary: "a child after one that always succeeds (in a Fallback) or always fails (in a Sequence) never runs",
    check: unreachable_child,
};

fn unreachable_child(p: &Subject, out: &mut Sink) {
    let PolicyBody::Bt(bt) = &p.body else { return };
    for node in &bt.nodes {
        let stop = if is_fallback(node.kind) {
            Always::Succeeds
        } else if is_sequence(node.kind) {
            Always::Fails
        } else {
            continue;
        };
        let Some(k) = node
            .children
            .iter()
            .position(|&c| always(bt, c) == Some(stop))
        else {
            continue;
        };
        if k + 1 >= node.children.len() {
            continue;
        }
        let blocker = &bt.nodes[node.children[k]];
        let dead: Vec<&str> = node.children[k + 1..]
            .iter()
            .map(|&c| bt.nodes[c].id.as_str())
            .collect();
        let (kind, verb) = match stop {
            Always::Succeeds => ("Fallback", "always succeeds"),
            Always::Fails => ("Sequence", "always fails"),
        };
        out.push(
            &node.id,
            node.span.clone(),
            format!(
                "in {kind} `{}`, `{}` {verb}, so {} never run{}: `{}`",
                node.id,
                blocker.id,
                if dead.len() == 1 {
                    "its next sibling"
                } else {
                    "the siblings after it"
                },
                if dead.len() == 1 { "s" } else { "" },
                dead.join("`, `")
            ),
            format!(
                "remove the unreachable children, or move `{}` after them",
                blocker.id
            ),
        );
    }
}

pub const REACTIVE_ASYNC_SIBLINGS: Rule = Rule {
    code: "reactive-async-siblings",
    level: Level::Warning,
    summary: "two asynchronous actions under one reactive Sequence or Fallback: one halts the other",
    check: reactive_async_siblings,
};

/// BehaviorTree.CPP action types known to return RUNNING (asynchronous):
/// BehaviorTree.CPP 4's `Sleep` (a `StatefulActionNode`), and Nav2's
/// plugins that derive `BtActionNode` (an action client: RUNNING until the
/// server's result) or `BtServiceNode` (RUNNING while the service has not
/// answered), and `CheckStopStatus` (RUNNING until the robot has stood
/// still long enough); read in navigation2's nav2_behavior_tree and
/// nav2_docking sources, releases 1.1 to 1.4 and main (class bases and
/// `registerNodeType`/`registerBuilder` names). A BehaviorTree.CPP XML file
/// does not say which of its actions are asynchronous, and a `SyncActionNode`
/// (Nav2's selectors) or an `ActionNodeBase` returning at once (Nav2's
/// `GetCurrentPose`, `TruncatePath`, `ConcatenatePaths`...) halts nothing:
/// an action of a type not listed here does not count.
const ASYNCHRONOUS_ACTIONS: &[&str] = &[
    "Sleep",
    // Nav2 BtActionNode
    "AssistedTeleop",
    "BackUp",
    "ComputeAndTrackRoute",
    "ComputePathThroughPoses",
    "ComputePathToPose",
    "ComputeRoute",
    "DockRobot",
    "DriveOnHeading",
    "FollowObject",
    "FollowPath",
    "NavigateThroughPoses",
    "NavigateToPose",
    "SmoothPath",
    "Spin",
    "UndockRobot",
    "Wait",
    // Nav2 BtServiceNode
    "CheckPoseOccupancy",
    "ClearCostmapAroundPose",
    "ClearCostmapAroundRobot",
    "ClearCostmapExceptRegion",
    "ClearEntireCostmap",
    "ReinitializeGlobalLocalization",
    "RemoveInCollisionGoals",
    "ToggleCollisionMonitor",
    "ValidatePath",
    // Nav2 ActionNodeBase returning RUNNING
    "CheckStopStatus",
];

/// Whether a leaf action may return RUNNING: in a BehaviorTree.CPP tree
/// (`btcpp`), one of a type known to ([`ASYNCHRONOUS_ACTIONS`]); in the
/// other formats, every action (a skill runs over several ticks) but one
/// that always ends the same way.
fn may_run(bt: &Bt, c: usize, btcpp: bool) -> bool {
    let n = &bt.nodes[c];
    if n.kind != BtNodeKind::Action || always(bt, c).is_some() {
        return false;
    }
    let ty = n.type_name.as_deref();
    if btcpp {
        ty.is_some_and(|t| ASYNCHRONOUS_ACTIONS.contains(&t))
    } else {
        !ty.is_some_and(|t| matches!(t, "Script" | "SetBlackboard" | "UnsetBlackboard"))
    }
}

fn reactive_async_siblings(p: &Subject, out: &mut Sink) {
    let PolicyBody::Bt(bt) = &p.body else { return };
    for node in &bt.nodes {
        if !matches!(node.kind, BtNodeKind::Sequence | BtNodeKind::Fallback) {
            continue;
        }
        let actions: Vec<&str> = node
            .children
            .iter()
            .filter(|&&c| may_run(bt, c, p.dataflow.is_some()))
            .map(|&c| bt.nodes[c].id.as_str())
            .collect();
        if actions.len() > 1 {
            out.push(
                &node.id,
                node.span.clone(),
                format!(
                    "reactive `{}` has {} actions as direct children (`{}`): when one runs and an earlier one is ticked again, BehaviorTree.CPP halts the running one",
                    node.id,
                    actions.len(),
                    actions.join("`, `")
                ),
                "put each action behind a condition (Fallback(condition, action)), or use a Sequence with memory".into(),
            );
        }
    }
}

pub const STATE_WITHOUT_EXIT: Rule = Rule {
    code: "state-without-exit",
    level: Level::Error,
    summary: "an FSM state with no transition out (of its own or of a container around it): the machine stops there forever",
    check: state_without_exit,
};

fn state_without_exit(p: &Subject, out: &mut Sink) {
    let PolicyBody::Machine(m) = &p.body else {
        return;
    };
    for (i, s) in m.states.iter().enumerate() {
        // Pseudo-states are SCXML's; a container is left through its
        // children's outcomes.
        if s.pseudo.is_some() || matches!(s.body, StateBody::Container(_)) {
            continue;
        }
        // A transition of the state or of a container around it leaves it;
        // in a parallel state, a sibling region's transition leaving the
        // parallel state leaves it too (not checked: the state passes).
        let mut at = Some(i);
        let mut leaves = false;
        while let Some(x) = at {
            leaves |= m.states[x]
                .transitions
                .iter()
                .any(|t| t.target != Target::State(i));
            leaves |= matches!(&m.states[x].body, StateBody::Container(r) if r.parallel);
            at = m.states[x].parent;
        }
        if !leaves {
            out.push(
                &m.path(i),
                s.span.clone(),
                format!(
                    "state `{}` has no transition to another state or an outcome",
                    m.path(i)
                ),
                "add the transition its SUCCESS (or FAILURE) should take".into(),
            );
        }
    }
}

pub const OUTCOME_NEVER_REACHED: Rule = Rule {
    code: "outcome-never-reached",
    level: Level::Warning,
    summary: "a declared outcome of a machine or container that no transition leads to",
    check: outcome_never_reached,
};

fn outcome_never_reached(p: &Subject, out: &mut Sink) {
    let PolicyBody::Machine(m) = &p.body else {
        return;
    };
    // A parallel state's outcomes come from its regions' results (yasmin's
    // outcome map), which the model does not keep: not checked.
    if m.states
        .iter()
        .any(|s| matches!(&s.body, StateBody::Container(r) if r.parallel))
    {
        return;
    }
    let mut regions: Vec<(Option<usize>, &btfsm_model::Region)> = vec![(None, &m.top)];
    for (i, s) in m.states.iter().enumerate() {
        if let StateBody::Container(r) = &s.body {
            regions.push((Some(i), r));
        }
    }
    // Outcomes reached from deeper inside (SCXML: a nested state's
    // transition to a final of an enclosing region).
    let outer: std::collections::HashSet<(Option<usize>, &str)> = m
        .states
        .iter()
        .flat_map(|s| &s.transitions)
        .filter_map(|t| match &t.target {
            Target::OuterOutcome { owner, outcome } => Some((*owner, outcome.as_str())),
            _ => None,
        })
        .collect();
    for (owner, r) in regions {
        // One pass over the region's transitions, then one look-up per outcome.
        let reached: std::collections::HashSet<&str> = r
            .states
            .iter()
            .flat_map(|&s| &m.states[s].transitions)
            .filter_map(|t| match &t.target {
                Target::Outcome(x) => Some(x.as_str()),
                Target::State(_) | Target::OuterOutcome { .. } => None,
            })
            .collect();
        for o in &r.outcomes {
            // A region that starts in an outcome reaches it; a parallel
            // state's outcomes are its regions' completion's (yasmin's
            // outcome map), not transitions'.
            let used = r.parallel
                || r.initial == Target::Outcome(o.clone())
                || outer.contains(&(owner, o.as_str()))
                || reached.contains(o.as_str());
            // A region's RUNNING is the tick-driven construction's (Fig. 6).
            if used || o == "RUNNING" {
                continue;
            }
            let (at, span, whose) = match owner {
                None => (
                    m.states.first().map(|_| String::new()).unwrap_or_default(),
                    None,
                    "the machine".to_string(),
                ),
                Some(i) => (
                    m.path(i),
                    m.states[i].span.clone(),
                    format!("container `{}`", m.path(i)),
                ),
            };
            out.push(
                &at,
                span,
                format!("outcome `{o}` of {whose} is declared but no transition reaches it"),
                "remove it from `outcomes`, or add the transition that ends there".into(),
            );
        }
    }
}
