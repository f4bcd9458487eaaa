//! The BT executor (see the module doc of [`super`]): BehaviorTree.CPP 4's
//! node semantics (docs/bt-semantics.md; read from BehaviorTree.CPP's
//! `src/controls/*.cpp`, `src/decorators/*.cpp`, `control_node.cpp`,
//! `decorator_node.cpp`, `action_node.cpp`, and checked tick by tick against
//! the engine by tests/differential/), on a compiled tree, with its reactive
//! skeleton as a table of successors ([`Plan`]) and a stack walk for the
//! subtrees below it.
//!
//! Every node has BehaviorTree.CPP's status (IDLE, RUNNING, SUCCESS,
//! FAILURE) and the memory its type keeps (a child index, counters); a
//! parent halts a RUNNING child (its running leaves get
//! [`Leaves::halt`](super::Leaves::halt), in depth-first order) and resets
//! the others to IDLE exactly where BehaviorTree.CPP calls `haltChild`,
//! `resetChild` and `resetChildren`. `tick_exactly_once` is one call of
//! [`BtExec::tick`]: a node that BehaviorTree.CPP makes yield after a child
//! finished at once (SequenceWithMemory, Repeat, RetryUntilSuccessful,
//! AsyncSequence, AsyncFallback: `emitWakeUpSignal`) returns RUNNING.

use super::Leaves;
use crate::model::BtNodeKind;
use crate::model::bt::{Bt, BtNode};
use crate::sim::skills::{Call, Status};
use std::sync::Arc;

/// A BT with its bindings resolved (shared by the runs of a scenario), laid
/// out flat for ticking: one record per node, children in one array.
#[derive(Debug)]
pub struct CompiledBt {
    pub nodes: Vec<XNode>,
    kids: Vec<u32>,
    pub root: usize,
    plan: Plan,
    /// Each node's parent ([`NO_NODE`] for the root).
    parent: Vec<usize>,
    /// Each node's pre-order number and the number after its subtree's last.
    pre: Vec<(u32, u32)>,
}

/// The tree's reactive skeleton — the root and the reactive Sequence and
/// Fallback nodes below it through reactive nodes only — compiled to a table
/// of slots: every other node under the skeleton (a leaf, or a subtree whose
/// root keeps memory or is not a reactive composite) is a slot, with the slot
/// to tick next when it succeeds and when it fails. A reactive composite
/// returns RUNNING as soon as a child does, so a RUNNING slot ends the tick.
/// This is the short-circuit evaluation of an and/or tree; it visits the
/// same leaves in the same order as the stack walk, without the frames. At
/// most one slot is RUNNING between ticks (a reactive composite halts its
/// other children when one runs); it is halted when a tick leaves the
/// skeleton node that holds it without ticking it again.
#[derive(Debug, Default)]
struct Plan {
    slots: Vec<Slot>,
    /// The slot ticked first (or the tick's status, for an empty composite).
    first: usize,
    /// Whether a recording tick can go through the plan: every skeleton
    /// composite has children (an empty one is never visited, so it would
    /// not be noted; valid files have none).
    records: bool,
}

/// A slot's successors: a slot index, [`DONE_SUCCESS`] or [`DONE_FAILURE`];
/// the skeleton composite where each successor continues (its ancestors
/// below it are left with the slot's status; [`NO_NODE`]: every ancestor is
/// left), and the highest node left (a RUNNING slot inside it is halted).
#[derive(Debug, Clone, Copy)]
struct Slot {
    node: usize,
    on_success: usize,
    on_failure: usize,
    stop_success: usize,
    stop_failure: usize,
    left_success: usize,
    left_failure: usize,
}

/// No node (above the root), no slot.
const NO_NODE: usize = usize::MAX;

/// The root succeeds.
const DONE_SUCCESS: usize = usize::MAX;
/// The root fails.
const DONE_FAILURE: usize = usize::MAX - 1;

impl Plan {
    /// Builds the table without recursion: children are visited last to
    /// first, so that a child's successor (its next sibling's first slot) is
    /// known when the child is visited.
    fn new(nodes: &[XNode], kids: &[u32], root: usize) -> Plan {
        /// Where a node's status sends the tick: (slot or DONE_*, the
        /// composite where it continues or NO_NODE, the highest node left).
        type Cont = (usize, usize, usize);
        enum Work {
            /// Visit a node with its successors on success and on failure;
            /// leaves its first slot on `firsts`.
            Visit(usize, Cont, Cont),
            /// Visit child `i` of the composite `p` (whose successors are
            /// given); for all but the last child, the next child's first
            /// slot is on top of `firsts`.
            Child(usize, usize, Cont, Cont),
        }
        let reactive = |n: usize| matches!(nodes[n].op, Op::Sequence | Op::Fallback);
        let kids_of = |n: usize| &kids[nodes[n].start as usize..nodes[n].end as usize];
        let mut slots = Vec::new();
        let mut firsts: Vec<usize> = Vec::new();
        let mut records = true;
        let mut work = vec![Work::Visit(
            root,
            (DONE_SUCCESS, NO_NODE, root),
            (DONE_FAILURE, NO_NODE, root),
        )];
        while let Some(w) = work.pop() {
            match w {
                Work::Visit(n, on_success, on_failure) => {
                    if !reactive(n) {
                        slots.push(Slot {
                            node: n,
                            on_success: on_success.0,
                            on_failure: on_failure.0,
                            stop_success: on_success.1,
                            stop_failure: on_failure.1,
                            left_success: on_success.2,
                            left_failure: on_failure.2,
                        });
                        firsts.push(slots.len() - 1);
                    } else if kids_of(n).is_empty() {
                        // Sequence() succeeds and Fallback() fails at once.
                        let seq = nodes[n].op == Op::Sequence;
                        firsts.push(if seq { on_success.0 } else { on_failure.0 });
                        records = false;
                    } else {
                        let last = kids_of(n).len() - 1;
                        work.push(Work::Child(n, last, on_success, on_failure));
                    }
                }
                Work::Child(p, i, on_success, on_failure) => {
                    let k = kids_of(p);
                    let (s, f) = if i + 1 == k.len() {
                        (on_success, on_failure)
                    } else {
                        let next = (firsts.pop().unwrap_or(DONE_FAILURE), p, k[i] as usize);
                        if nodes[p].op == Op::Sequence {
                            (next, on_failure)
                        } else {
                            (on_success, next)
                        }
                    };
                    if i > 0 {
                        work.push(Work::Child(p, i - 1, on_success, on_failure));
                    }
                    work.push(Work::Visit(k[i] as usize, s, f));
                }
            }
        }
        Plan {
            slots,
            first: firsts.pop().unwrap_or(DONE_FAILURE),
            records,
        }
    }
}

/// A node of a [`CompiledBt`].
#[derive(Debug)]
pub struct XNode {
    pub kind: BtNodeKind,
    pub call: Option<Call>,
    /// How it is ticked, decided once from its kind, type and binding.
    op: Op,
    /// Numbers the op needs: Parallel's success and failure thresholds,
    /// ParallelAll's failure threshold, Repeat's and Retry's count (-1:
    /// forever), Timeout's milliseconds.
    a: i64,
    b: i64,
    /// Its children are `kids[start..end]`.
    start: u32,
    end: u32,
}

/// How a node is ticked: one BehaviorTree.CPP node type each (the TOML kind
/// names in parentheses).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Op {
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
    fn is_decorator(self) -> bool {
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
fn op_of(n: &BtNode) -> Result<(Op, i64, i64), String> {
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

/// Why the executor cannot tick node `n` as BehaviorTree.CPP 4 does (its
/// type, as written), if it cannot.
pub fn refused(n: &BtNode) -> Option<String> {
    op_of(n).err()
}

/// The first node (in pre-order) whose type the executor cannot tick as
/// BehaviorTree.CPP 4 does, with what it is (`tick` refuses such a tree).
pub fn unsupported(bt: &Bt) -> Option<(usize, String)> {
    let k = |i: usize| bt.nodes[i].children.len() as i64;
    bt.preorder().into_iter().find_map(|i| {
        let n = &bt.nodes[i];
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

impl CompiledBt {
    pub fn new(bt: &Bt, call: Vec<Option<Call>>) -> Self {
        Self::build(bt, call, false)
    }

    /// A tree whose every leaf is ticked through [`Leaves`] whatever its
    /// binding (the leaves are told apart by key: `btfsm tick`).
    pub fn scripted(bt: &Bt) -> Self {
        Self::build(bt, vec![None; bt.nodes.len()], true)
    }

    fn build(bt: &Bt, call: Vec<Option<Call>>, scripted: bool) -> Self {
        let mut kids = Vec::with_capacity(bt.nodes.len());
        let nodes = bt
            .nodes
            .iter()
            .zip(call)
            .map(|(n, call)| {
                let start = kids.len() as u32;
                kids.extend(n.children.iter().map(|&c| c as u32));
                let (op, a, b) = match (op_of(n), &call) {
                    (Ok((Op::Action | Op::Condition, ..)), None) if !scripted => {
                        (Op::Unbound, 0, 0)
                    }
                    (Ok(x), _) => x,
                    (Err(_), _) => (Op::PassThrough, 0, 0),
                };
                // A placeholder binding for scripted leaves (never read).
                let call = match op {
                    Op::Action | Op::Condition => call.or(Some(Call::Found)),
                    _ => call,
                };
                XNode {
                    kind: n.kind,
                    call,
                    op,
                    a,
                    b,
                    start,
                    end: kids.len() as u32,
                }
            })
            .collect::<Vec<_>>();
        let plan = Plan::new(&nodes, &kids, bt.root);
        let mut parent = vec![NO_NODE; nodes.len()];
        for (p, n) in nodes.iter().enumerate() {
            for &c in &kids[n.start as usize..n.end as usize] {
                parent[c as usize] = p;
            }
        }
        let order = bt.preorder();
        let mut pre = vec![(0u32, 0u32); nodes.len()];
        for (i, &n) in order.iter().enumerate() {
            pre[n].0 = i as u32;
        }
        // Subtree ends, children before parents (reverse pre-order).
        for &n in order.iter().rev() {
            let end = (bt.nodes[n].children.last()).map_or(pre[n].0 + 1, |&c| pre[c].1);
            pre[n].1 = end;
        }
        CompiledBt {
            nodes,
            kids,
            root: bt.root,
            plan,
            parent,
            pre,
        }
    }

    fn kids(&self, n: usize) -> &[u32] {
        &self.kids[self.nodes[n].start as usize..self.nodes[n].end as usize]
    }

    /// Whether `x` is in the subtree of `top`.
    fn contains(&self, top: usize, x: usize) -> bool {
        let (a, b) = self.pre[top];
        (a..b).contains(&self.pre[x].0)
    }
}

/// BehaviorTree.CPP's node status.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
enum St {
    #[default]
    Idle,
    Running,
    Success,
    Failure,
}

impl From<Status> for St {
    fn from(s: Status) -> St {
        match s {
            Status::Running => St::Running,
            Status::Success => St::Success,
            Status::Failure => St::Failure,
        }
    }
}

/// The run-time state of a node: its status and its type's memory (the
/// child index of Sequence, Fallback, SequenceWithMemory, IfThenElse;
/// Parallel's counts; Repeat's and Retry's counter; Timeout's start).
#[derive(Debug, Clone, Copy, Default)]
struct NodeState {
    st: St,
    idx: u32,
    ok: u32,
    bad: u32,
    t0: f64,
}

/// The run-time state of a BT.
#[derive(Debug)]
pub struct BtExec {
    pub bt: Arc<CompiledBt>,
    node: Vec<NodeState>,
    /// When `Some`, every node ticked in the last step with its status.
    pub statuses: Option<Vec<(usize, Status)>>,
    /// The explicit stacks, kept between ticks to avoid allocating.
    stack: Vec<Frame>,
    halts: Vec<(u32, u32)>,
    /// Tick with the stack walk only (see [`BtExec::with_stack_walk`]).
    stack_walk: bool,
    /// The plan's slot left RUNNING by the last tick ([`NO_NODE`]: none).
    running: usize,
}

/// A node being ticked: the child it is at, and that child's status before
/// it was ticked (a node that yields after a child finished at once needs
/// it).
#[derive(Debug, Clone, Copy)]
struct Frame {
    node: u32,
    i: u32,
    prev: St,
}

/// What a node's visit ends with.
enum Next {
    /// Tick its child at this position.
    Tick(usize),
    /// The node's status for this tick.
    Done(Status),
}

impl BtExec {
    pub fn new(bt: Arc<CompiledBt>, record: bool) -> Self {
        let n = bt.nodes.len();
        BtExec {
            bt,
            node: vec![NodeState::default(); n],
            statuses: record.then(Vec::new),
            stack: Vec::new(),
            halts: Vec::new(),
            stack_walk: false,
            running: NO_NODE,
        }
    }

    /// Ticks the tree once from the root (BehaviorTree.CPP's
    /// `tickExactlyOnce`).
    pub fn tick(&mut self, leaves: &mut impl Leaves) -> Status {
        let now = leaves.now();
        let mut x = Ticking {
            bt: &self.bt,
            st: &mut self.node,
            stack: &mut self.stack,
            halts: &mut self.halts,
            now,
        };
        match &mut self.statuses {
            Some(v) => {
                // Every node's status is wanted.
                v.clear();
                if x.bt.plan.records && !self.stack_walk {
                    x.run_plan::<true>(leaves, v, &mut self.running)
                } else {
                    x.run_root::<true>(leaves, v)
                }
            }
            None if self.stack_walk => x.run_root::<false>(leaves, &mut Vec::new()),
            None => x.run_plan::<false>(leaves, &mut Vec::new(), &mut self.running),
        }
    }

    /// Halts the tree (BehaviorTree.CPP's `haltTree`): every running leaf
    /// gets [`Leaves::halt`], in depth-first order.
    pub fn halt(&mut self, leaves: &mut impl Leaves) {
        let root = self.bt.root;
        let mut x = Ticking {
            bt: &self.bt,
            st: &mut self.node,
            stack: &mut self.stack,
            halts: &mut self.halts,
            now: 0.0,
        };
        // Through the plan, the skeleton keeps no statuses: its one
        // running slot is what is running.
        match self.bt.plan.slots.get(self.running) {
            Some(slot) if !self.stack_walk => x.halt_child(slot.node, leaves),
            _ => x.halt_child(root, leaves),
        }
        // Then every node is halted whatever its status (`haltTree`'s
        // recursive visitor): statuses IDLE, halt-time memory reset.
        for n in 0..self.node.len() {
            if self.bt.nodes[n].op != Op::Action {
                Ticking::halted(&self.bt, &mut self.node, n, leaves);
            }
            self.node[n].st = St::Idle;
        }
        self.running = NO_NODE;
    }

    /// Ticks every node with the stack walk, never the plan (for the tests
    /// and the benchmark that compare the two).
    pub fn with_stack_walk(mut self) -> Self {
        self.stack_walk = true;
        self
    }
}

/// One tick's view of a [`BtExec`].
struct Ticking<'a> {
    bt: &'a CompiledBt,
    st: &'a mut [NodeState],
    stack: &'a mut Vec<Frame>,
    halts: &'a mut Vec<(u32, u32)>,
    now: f64,
}

impl Ticking<'_> {
    /// Ticks the tree from its root with the stack walk; a root that
    /// finishes is reset to IDLE (`tickRoot`).
    fn run_root<const REC: bool>(
        &mut self,
        leaves: &mut impl Leaves,
        rec: &mut Vec<(usize, Status)>,
    ) -> Status {
        let root = self.bt.root;
        let s = self.run::<REC>(root, leaves, rec);
        if s != Status::Running {
            self.st[root].st = St::Idle;
        }
        s
    }

    /// Ticks the tree through its plan: from slot to slot of the reactive
    /// skeleton, a subtree with memory ticked by [`Ticking::run`]; the slot
    /// left RUNNING by the last tick is halted where the skeleton leaves it.
    fn run_plan<const REC: bool>(
        &mut self,
        leaves: &mut impl Leaves,
        rec: &mut Vec<(usize, Status)>,
        running: &mut usize,
    ) -> Status {
        let bt = self.bt;
        let plan = &bt.plan;
        let mut k = plan.first;
        loop {
            let Some(slot) = plan.slots.get(k) else {
                return if k == DONE_SUCCESS {
                    Status::Success
                } else {
                    Status::Failure
                };
            };
            let s = match self.leaf::<REC>(slot.node, leaves, rec) {
                Some(s) => s,
                None => self.run::<REC>(slot.node, leaves, rec),
            };
            let (next, stop, left) = match s {
                Status::Success => (slot.on_success, slot.stop_success, slot.left_success),
                Status::Failure => (slot.on_failure, slot.stop_failure, slot.left_failure),
                Status::Running => (DONE_SUCCESS, NO_NODE, bt.root),
            };
            if *running == k {
                *running = NO_NODE;
            } else if *running != NO_NODE {
                let x = plan.slots[*running].node;
                if bt.contains(left, x) {
                    self.halt_child(x, leaves);
                    *running = NO_NODE;
                }
            }
            if REC {
                // The composites the status leaves return it (a reactive
                // composite's status is that of the child it stops at).
                let mut a = bt.parent[slot.node];
                while a != stop && a != NO_NODE {
                    rec.push((a, s));
                    a = bt.parent[a];
                }
            }
            if s == Status::Running {
                *running = k;
                return s;
            }
            // The skeleton resets a finished slot before the tick ends.
            self.st[slot.node].st = St::Idle;
            k = next;
        }
    }

    /// Ticks a leaf in place (noting it when `REC`); `None` for a node that
    /// needs a frame. An action that finished and was not reset returns its
    /// status again without being called (BehaviorTree.CPP's
    /// `StatefulActionNode::tick`).
    #[inline(always)]
    fn leaf<const REC: bool>(
        &mut self,
        c: usize,
        leaves: &mut impl Leaves,
        rec: &mut Vec<(usize, Status)>,
    ) -> Option<Status> {
        let cn = &self.bt.nodes[c];
        let s = match (cn.op, &cn.call) {
            (Op::Condition, Some(call)) => {
                if leaves.condition(c, call) {
                    Status::Success
                } else {
                    Status::Failure
                }
            }
            (Op::Action, Some(call)) => match self.st[c].st {
                St::Success => Status::Success,
                St::Failure => Status::Failure,
                St::Idle | St::Running => leaves.action(c, call),
            },
            (Op::Action | Op::Condition | Op::Unbound, _) => Status::Failure,
            _ => return None,
        };
        self.st[c].st = s.into();
        if REC {
            rec.push((c, s));
        }
        Some(s)
    }

    /// BehaviorTree.CPP's `haltChild`: a RUNNING node is halted (its running
    /// leaves get [`Leaves::halt`] in depth-first order, its memory reset as
    /// its type's `halt()` does), then the node is IDLE.
    fn halt_child(&mut self, c: usize, leaves: &mut impl Leaves) {
        if self.st[c].st != St::Running {
            self.st[c].st = St::Idle;
            return;
        }
        let bt = self.bt;
        let halts = &mut *self.halts;
        halts.clear();
        halts.push((c as u32, 0));
        Self::halted(bt, self.st, c, leaves);
        while let Some(top) = halts.last_mut() {
            let n = top.0 as usize;
            let kids = bt.kids(n);
            match kids.get(top.1 as usize) {
                Some(&k) => {
                    top.1 += 1;
                    let k = k as usize;
                    if self.st[k].st == St::Running {
                        halts.push((k as u32, 0));
                        Self::halted(bt, self.st, k, leaves);
                    } else {
                        self.st[k].st = St::Idle;
                    }
                }
                None => {
                    self.st[n].st = St::Idle;
                    halts.pop();
                }
            }
        }
    }

    /// A running node's own `halt()`, before its children's.
    fn halted(bt: &CompiledBt, st: &mut [NodeState], n: usize, leaves: &mut impl Leaves) {
        let ns = &mut st[n];
        match bt.nodes[n].op {
            Op::Action => leaves.halt(n),
            Op::SequenceMemory
            | Op::FallbackMemory
            | Op::AsyncSequence
            | Op::AsyncFallback
            | Op::IfThenElse => ns.idx = 0,
            Op::Parallel | Op::ParallelAll | Op::Repeat | Op::Retry => {
                ns.ok = 0;
                ns.bad = 0;
            }
            _ => {}
        }
    }

    /// BehaviorTree.CPP's `resetChildren`: every child halted or reset.
    fn reset_children(&mut self, n: usize, from: usize, leaves: &mut impl Leaves) {
        let kids = self.bt.kids(n);
        for &c in &kids[from.min(kids.len())..] {
            self.halt_child(c as usize, leaves);
        }
    }

    /// Ticks the subtree of `from` with an explicit stack (noting every
    /// node's status in `rec` when `REC`).
    fn run<const REC: bool>(
        &mut self,
        from: usize,
        leaves: &mut impl Leaves,
        rec: &mut Vec<(usize, Status)>,
    ) -> Status {
        if let Some(s) = self.leaf::<REC>(from, leaves, rec) {
            return s;
        }
        let bt = self.bt;
        let mut stack = std::mem::take(self.stack);
        stack.clear();
        stack.push(Frame {
            node: from as u32,
            i: 0,
            prev: St::Idle,
        });
        // The status of the child just ticked, for the frame on top.
        let mut ret: Option<Status> = None;
        let out = loop {
            let Some(f) = stack.last_mut() else {
                unreachable!("the loop returns when the first frame is popped")
            };
            let n = f.node as usize;
            let next = self.visit(n, f, ret.take(), leaves);
            match next {
                Next::Tick(i) => {
                    let c = bt.kids(n)[i] as usize;
                    f.i = i as u32;
                    f.prev = self.st[c].st;
                    match self.leaf::<REC>(c, leaves, rec) {
                        Some(s) => ret = Some(s),
                        None => stack.push(Frame {
                            node: c as u32,
                            i: 0,
                            prev: St::Idle,
                        }),
                    }
                }
                Next::Done(s) => {
                    self.st[n].st = s.into();
                    // DecoratorNode::executeTick resets a finished child.
                    if bt.nodes[n].op.is_decorator()
                        && let Some(&c) = bt.kids(n).first()
                        && matches!(self.st[c as usize].st, St::Success | St::Failure)
                    {
                        self.st[c as usize].st = St::Idle;
                    }
                    if REC {
                        rec.push((n, s));
                    }
                    stack.pop();
                    if stack.is_empty() {
                        break s;
                    }
                    ret = Some(s);
                }
            }
        };
        *self.stack = stack;
        out
    }

    /// One step of node `n`'s `tick()`: entered (`ret` is `None`, `f.i` is
    /// 0) or resumed with the status of its child at `f.i`.
    fn visit(
        &mut self,
        n: usize,
        f: &mut Frame,
        ret: Option<Status>,
        leaves: &mut impl Leaves,
    ) -> Next {
        use Status::{Failure as F, Running as R, Success as S};
        let node = &self.bt.nodes[n];
        let len = (node.end - node.start) as usize;
        let i = f.i as usize;
        let op = node.op;
        match op {
            Op::Sequence | Op::Fallback => {
                let go_on = if op == Op::Sequence { S } else { F };
                let mut i = i;
                match ret {
                    None => {}
                    Some(R) => {
                        for j in 0..len {
                            if j != i {
                                let c = self.bt.kids(n)[j] as usize;
                                self.halt_child(c, leaves);
                            }
                        }
                        return Next::Done(R);
                    }
                    Some(s) if s == go_on => i += 1,
                    Some(s) => {
                        self.reset_children(n, 0, leaves);
                        return Next::Done(s);
                    }
                }
                if i >= len {
                    self.reset_children(n, 0, leaves);
                    return Next::Done(go_on);
                }
                Next::Tick(i)
            }
            Op::SequenceMemory
            | Op::FallbackMemory
            | Op::SequenceWithMemory
            | Op::AsyncSequence
            | Op::AsyncFallback => {
                let go_on = if matches!(op, Op::FallbackMemory | Op::AsyncFallback) {
                    F
                } else {
                    S
                };
                let yields = matches!(
                    op,
                    Op::SequenceWithMemory | Op::AsyncSequence | Op::AsyncFallback
                );
                match ret {
                    None => {}
                    Some(R) => return Next::Done(R),
                    Some(s) if s == go_on => {
                        self.st[n].idx += 1;
                        if yields && f.prev == St::Idle && (self.st[n].idx as usize) < len {
                            return Next::Done(R);
                        }
                    }
                    Some(s) => {
                        if op == Op::SequenceWithMemory {
                            // The index is kept: the failed child is ticked
                            // again next time.
                            let from = self.st[n].idx as usize;
                            self.reset_children(n, from, leaves);
                        } else {
                            self.reset_children(n, 0, leaves);
                            self.st[n].idx = 0;
                        }
                        return Next::Done(s);
                    }
                }
                let idx = self.st[n].idx as usize;
                if idx >= len {
                    self.reset_children(n, 0, leaves);
                    self.st[n].idx = 0;
                    return Next::Done(go_on);
                }
                Next::Tick(idx)
            }
            Op::Parallel | Op::ParallelAll => self.parallel(n, f, ret, leaves),
            Op::IfThenElse => {
                match ret {
                    None => return Next::Tick(self.st[n].idx as usize),
                    Some(R) => return Next::Done(R),
                    Some(s) if i == 0 => {
                        if s == S {
                            self.st[n].idx = 1;
                        } else if len == 3 {
                            self.st[n].idx = 2;
                        } else {
                            return Next::Done(F);
                        }
                        return Next::Tick(self.st[n].idx as usize);
                    }
                    Some(_) => {}
                }
                let s = ret.unwrap_or(F);
                self.reset_children(n, 0, leaves);
                self.st[n].idx = 0;
                Next::Done(s)
            }
            Op::WhileDoElse => {
                let kid = |j: usize| self.bt.kids(n)[j] as usize;
                let s = match ret {
                    None => return Next::Tick(0),
                    Some(R) => return Next::Done(R),
                    Some(S) if i == 0 => {
                        if len == 3 {
                            self.halt_child(kid(2), leaves);
                        }
                        return Next::Tick(1);
                    }
                    Some(_) if i == 0 && len == 3 => {
                        self.halt_child(kid(1), leaves);
                        return Next::Tick(2);
                    }
                    Some(s) => s,
                };
                self.reset_children(n, 0, leaves);
                Next::Done(s)
            }
            Op::Repeat | Op::Retry => {
                // Repeat loops on success, Retry on failure.
                let (again, other) = if op == Op::Repeat { (S, F) } else { (F, S) };
                let do_loop = |ns: &NodeState| node.a < 0 || i64::from(ns.ok) < node.a;
                match ret {
                    None => {}
                    Some(R) => return Next::Done(R),
                    Some(s) if s == again => {
                        let ns = &mut self.st[n];
                        ns.ok = ns.ok.saturating_add(1);
                        let c = self.bt.kids(n)[0] as usize;
                        self.halt_child(c, leaves);
                        if f.prev == St::Idle && do_loop(&self.st[n]) {
                            return Next::Done(R);
                        }
                    }
                    Some(_) => {
                        self.st[n].ok = 0;
                        let c = self.bt.kids(n)[0] as usize;
                        self.halt_child(c, leaves);
                        return Next::Done(other);
                    }
                }
                if !do_loop(&self.st[n]) || len == 0 {
                    self.st[n].ok = 0;
                    return Next::Done(again);
                }
                Next::Tick(0)
            }
            Op::Timeout => match ret {
                Some(s) => Next::Done(s),
                None => {
                    if self.st[n].st != St::Running {
                        self.st[n].t0 = self.now;
                    }
                    if (self.now - self.st[n].t0) * 1000.0 >= node.a as f64 || len == 0 {
                        if let Some(&c) = self.bt.kids(n).first() {
                            self.halt_child(c as usize, leaves);
                        }
                        return Next::Done(F);
                    }
                    Next::Tick(0)
                }
            },
            _ => match ret {
                None if len == 0 => Next::Done(F),
                None => Next::Tick(0),
                Some(s) => Next::Done(match (op, s) {
                    (_, R) => R,
                    (Op::Inverter, S) => F,
                    (Op::Inverter, _) => S,
                    (Op::ForceSuccess, _) => S,
                    (Op::ForceFailure, _) => F,
                    (Op::KeepRunningUntilFailure, S) => R,
                    (_, s) => s,
                }),
            },
        }
    }

    /// Parallel and ParallelAll: a child that finished is not ticked again
    /// until the node finishes (its status, SUCCESS or FAILURE, marks it).
    fn parallel(
        &mut self,
        n: usize,
        f: &mut Frame,
        ret: Option<Status>,
        leaves: &mut impl Leaves,
    ) -> Next {
        use Status::{Failure as F, Running as R, Success as S};
        let bt = self.bt;
        let node = &bt.nodes[n];
        let kids = bt.kids(n);
        let len = kids.len();
        let all = node.op == Op::ParallelAll;
        let mut i = f.i as usize;
        let mut resumed = ret.is_some();
        if let Some(s) = ret {
            let ns = &mut self.st[n];
            ns.ok += u32::from(s == S);
            ns.bad += u32::from(s == F);
        }
        while i < len {
            if !resumed {
                let c = kids[i] as usize;
                if !matches!(self.st[c].st, St::Success | St::Failure) {
                    return Next::Tick(i);
                }
            }
            resumed = false;
            if !all {
                let ns = self.st[n];
                let (ok, bad) = (i64::from(ns.ok), i64::from(ns.bad));
                let done = if ok >= node.a {
                    Some(S)
                } else if (len as i64 - bad) < node.a || bad == node.b {
                    Some(F)
                } else {
                    None
                };
                if let Some(s) = done {
                    self.st[n].ok = 0;
                    self.st[n].bad = 0;
                    self.reset_children(n, 0, leaves);
                    return Next::Done(s);
                }
            }
            i += 1;
        }
        if all {
            let ns = self.st[n];
            if ns.ok + ns.bad >= len as u32 {
                self.reset_children(n, 0, leaves);
                self.st[n].ok = 0;
                self.st[n].bad = 0;
                return Next::Done(if i64::from(ns.bad) >= node.b { F } else { S });
            }
        }
        Next::Done(R)
    }
}
