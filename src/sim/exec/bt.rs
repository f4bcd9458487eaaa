//! The BT executor (see the module doc of [`super`]): a compiled tree, its
//! reactive skeleton as a table of successors ([`Plan`]), and the stack walk
//! for the subtrees below it.

use super::Leaves;
use crate::model::BtNodeKind;
use crate::model::bt::Bt;
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
}

/// The tree's reactive skeleton — the root and the reactive Sequence and
/// Fallback nodes below it through reactive nodes only — compiled to a table
/// of slots: every other node under the skeleton (a leaf, or a subtree whose
/// root keeps memory or is not a reactive composite) is a slot, with the slot
/// to tick next when it succeeds and when it fails. A reactive composite
/// returns RUNNING as soon as a child does, so a RUNNING slot ends the tick.
/// This is the short-circuit evaluation of an and/or tree; it visits the
/// same leaves in the same order as the stack walk, without the frames.
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
/// and for noting statuses, the skeleton composite where each successor
/// continues (its ancestors below it are left with the slot's status;
/// [`NO_NODE`]: every ancestor is left).
#[derive(Debug, Clone, Copy)]
struct Slot {
    node: usize,
    on_success: usize,
    on_failure: usize,
    stop_success: usize,
    stop_failure: usize,
}

/// No node (above the root).
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
        /// composite where it continues or NO_NODE).
        type Cont = (usize, usize);
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
            (DONE_SUCCESS, NO_NODE),
            (DONE_FAILURE, NO_NODE),
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
                        let next = (firsts.pop().unwrap_or(DONE_FAILURE), p);
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
    /// How it is ticked, decided once from its kind and binding.
    op: Op,
    /// A number the op needs: Parallel's success threshold, Repeat's and
    /// Retry's count (`u32::MAX`: forever), Timeout's milliseconds.
    arg: u64,
    /// Its children are `kids[start..end]`.
    start: u32,
    end: u32,
}

/// How a node is ticked. Leaves are evaluated in place by their parent;
/// every other op gets a frame on the stack.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Op {
    Sequence,
    Fallback,
    SequenceMemory,
    FallbackMemory,
    Parallel,
    Inverter,
    ForceSuccess,
    ForceFailure,
    Repeat,
    Retry,
    Timeout,
    /// A kind the simulator does not model (scenarios reject it): passes
    /// its first child's status through.
    PassThrough,
    /// An action bound to a skill.
    Action,
    /// A condition bound to a skill.
    Condition,
    /// A leaf without a binding: fails.
    Unbound,
}

impl CompiledBt {
    pub fn new(bt: &Bt, call: Vec<Option<Call>>) -> Self {
        let mut kids = Vec::with_capacity(bt.nodes.len());
        let nodes = bt
            .nodes
            .iter()
            .zip(call)
            .map(|(n, call)| {
                let start = kids.len() as u32;
                kids.extend(n.children.iter().map(|&c| c as u32));
                let (op, arg) = match (n.kind, &call) {
                    (BtNodeKind::Sequence, _) => (Op::Sequence, 0),
                    (BtNodeKind::Fallback, _) => (Op::Fallback, 0),
                    (BtNodeKind::SequenceMemory, _) => (Op::SequenceMemory, 0),
                    (BtNodeKind::FallbackMemory, _) => (Op::FallbackMemory, 0),
                    (BtNodeKind::Parallel { success }, _) => (Op::Parallel, success as u64),
                    (BtNodeKind::Inverter, _) => (Op::Inverter, 0),
                    (BtNodeKind::ForceSuccess, _) => (Op::ForceSuccess, 0),
                    (BtNodeKind::ForceFailure, _) => (Op::ForceFailure, 0),
                    (BtNodeKind::Repeat { times }, _) => {
                        (Op::Repeat, times.map_or(u64::MAX, u64::from))
                    }
                    (BtNodeKind::Retry { times }, _) => (Op::Retry, u64::from(times)),
                    (BtNodeKind::Timeout { ms }, _) => (Op::Timeout, ms),
                    (BtNodeKind::Control | BtNodeKind::Decorator, _) => (Op::PassThrough, 0),
                    (BtNodeKind::Action, Some(_)) => (Op::Action, 0),
                    (BtNodeKind::Condition, Some(_)) => (Op::Condition, 0),
                    (BtNodeKind::Action | BtNodeKind::Condition, None) => (Op::Unbound, 0),
                };
                XNode {
                    kind: n.kind,
                    call,
                    op,
                    arg,
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
        CompiledBt {
            nodes,
            kids,
            root: bt.root,
            plan,
            parent,
        }
    }
}

/// Evaluates a leaf in place (noting it when `REC`); `None` for a node
/// that needs a frame.
#[inline(always)]
fn leaf<const REC: bool>(
    nodes: &[XNode],
    c: usize,
    leaves: &mut impl Leaves,
    rec: &mut Vec<(usize, Status)>,
) -> Option<Status> {
    let cn = &nodes[c];
    let s = match (cn.op, &cn.call) {
        (Op::Condition, Some(call)) => {
            if leaves.condition(call) {
                Status::Success
            } else {
                Status::Failure
            }
        }
        (Op::Action, Some(call)) => leaves.action(c, call),
        (Op::Action | Op::Condition | Op::Unbound, _) => Status::Failure,
        _ => return None,
    };
    if REC {
        rec.push((c, s));
    }
    Some(s)
}

/// The run-time state of a BT.
#[derive(Debug)]
pub struct BtExec {
    pub bt: Arc<CompiledBt>,
    node: Vec<NodeState>,
    step: u64,
    /// When `Some`, every node ticked in the last step with its status.
    pub statuses: Option<Vec<(usize, Status)>>,
    /// The explicit stack, kept between ticks to avoid allocating.
    stack: Vec<Frame>,
    /// Tick with the stack walk only (see [`BtExec::with_stack_walk`]).
    stack_walk: bool,
}

/// Per-node memory of the ops that have some (memory composites, Repeat,
/// Retry, Timeout): the running child or the decorator's counter, the start
/// of a Timeout, and the step the node was last ticked.
#[derive(Debug, Clone, Copy, Default)]
struct NodeState {
    mem: u32,
    last: u64,
    t0: f64,
}

/// A node being ticked: the child it is at, and Parallel's counts.
#[derive(Debug, Clone, Copy)]
struct Frame {
    node: u32,
    i: u32,
    ok: u32,
    bad: u32,
}

/// What a node's visit ends with.
enum Next {
    /// Tick this child (not a leaf) in a frame of its own.
    Descend(usize),
    /// The node's status for this tick.
    Done(Status),
}

impl BtExec {
    pub fn new(bt: Arc<CompiledBt>, record: bool) -> Self {
        let n = bt.nodes.len();
        BtExec {
            bt,
            node: vec![NodeState::default(); n],
            step: 0,
            statuses: record.then(Vec::new),
            stack: Vec::new(),
            stack_walk: false,
        }
    }

    /// Ticks the tree once from the root.
    pub fn tick(&mut self, leaves: &mut impl Leaves) -> Status {
        self.step += 1;
        let now = leaves.now();
        let mut x = Ticking {
            bt: &self.bt,
            st: &mut self.node,
            stack: &mut self.stack,
            step: self.step,
            now,
        };
        match &mut self.statuses {
            Some(v) => {
                // Every node's status is wanted.
                v.clear();
                if x.bt.plan.records && !self.stack_walk {
                    x.run_plan::<true>(leaves, v)
                } else {
                    x.run::<true>(x.bt.root, leaves, v)
                }
            }
            None if self.stack_walk => x.run::<false>(x.bt.root, leaves, &mut Vec::new()),
            None => x.run_plan::<false>(leaves, &mut Vec::new()),
        }
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
    step: u64,
    now: f64,
}

impl Ticking<'_> {
    /// Ticks the tree through its plan: from slot to slot of the reactive
    /// skeleton, a subtree with memory ticked by [`Ticking::run`].
    fn run_plan<const REC: bool>(
        &mut self,
        leaves: &mut impl Leaves,
        rec: &mut Vec<(usize, Status)>,
    ) -> Status {
        let plan = &self.bt.plan;
        let mut k = plan.first;
        loop {
            let Some(slot) = plan.slots.get(k) else {
                return if k == DONE_SUCCESS {
                    Status::Success
                } else {
                    Status::Failure
                };
            };
            let s = match leaf::<REC>(&self.bt.nodes, slot.node, leaves, rec) {
                Some(s) => s,
                None => self.run::<REC>(slot.node, leaves, rec),
            };
            let (next, stop) = match s {
                Status::Success => (slot.on_success, slot.stop_success),
                Status::Failure => (slot.on_failure, slot.stop_failure),
                Status::Running => (DONE_SUCCESS, NO_NODE),
            };
            if REC {
                // The composites the status leaves return it (a reactive
                // composite's status is that of the child it stops at).
                let mut a = self.bt.parent[slot.node];
                while a != stop && a != NO_NODE {
                    rec.push((a, s));
                    a = self.bt.parent[a];
                }
            }
            if s == Status::Running {
                return s;
            }
            k = next;
        }
    }

    /// The frame of node `n` on entering it; a node with memory that was not
    /// ticked on the previous step starts afresh.
    #[inline(always)]
    fn enter(nodes: &[XNode], st: &mut [NodeState], n: usize, step: u64, now: f64) -> Frame {
        let mut i = 0;
        if matches!(
            nodes[n].op,
            Op::SequenceMemory | Op::FallbackMemory | Op::Repeat | Op::Retry | Op::Timeout
        ) {
            let ns = &mut st[n];
            if ns.last + 1 != step {
                ns.mem = 0;
                ns.t0 = now;
            }
            ns.last = step;
            if matches!(nodes[n].op, Op::SequenceMemory | Op::FallbackMemory) {
                i = ns.mem;
            }
        }
        Frame {
            node: n as u32,
            i,
            ok: 0,
            bad: 0,
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
        use Status::{Failure as F, Running as R, Success as S};
        let bt = self.bt;
        let nodes = &bt.nodes[..];
        let st = &mut *self.st;
        let (step, now) = (self.step, self.now);
        if let Some(s) = leaf::<REC>(nodes, from, leaves, rec) {
            return s;
        }
        let stack = &mut *self.stack;
        stack.clear();
        stack.push(Self::enter(nodes, st, from, step, now));
        // The status of the child just popped, for its parent on top.
        let mut ret: Option<Status> = None;
        loop {
            let Some(f) = stack.last_mut() else {
                unreachable!("the loop returns when the root's frame is popped")
            };
            let n = f.node as usize;
            let node = &nodes[n];
            let kids = &bt.kids[node.start as usize..node.end as usize];
            let next = match node.op {
                op @ (Op::Sequence | Op::SequenceMemory | Op::Fallback | Op::FallbackMemory) => {
                    let go_on = if matches!(op, Op::Sequence | Op::SequenceMemory) {
                        S
                    } else {
                        F
                    };
                    // Leaf children are evaluated in place; the visit stops at
                    // a child that needs a frame or at the node's status.
                    let mut i = f.i as usize;
                    let next = loop {
                        let s = match ret.take() {
                            Some(s) => s,
                            None => {
                                let Some(&c) = kids.get(i) else {
                                    break Next::Done(go_on);
                                };
                                match leaf::<REC>(nodes, c as usize, leaves, rec) {
                                    Some(s) => s,
                                    None => break Next::Descend(c as usize),
                                }
                            }
                        };
                        if s != go_on {
                            break Next::Done(s);
                        }
                        i += 1;
                        if i == kids.len() {
                            break Next::Done(go_on);
                        }
                    };
                    f.i = i as u32;
                    if let (Op::SequenceMemory | Op::FallbackMemory, Next::Done(s)) = (op, &next) {
                        st[n].mem = if *s == R { i as u32 } else { 0 };
                    }
                    next
                }
                Op::Parallel => {
                    if let Some(s) = ret.take() {
                        f.ok += u32::from(s == S);
                        f.bad += u32::from(s == F);
                        f.i += 1;
                    }
                    let mut next = None;
                    while let Some(&c) = kids.get(f.i as usize) {
                        match leaf::<REC>(nodes, c as usize, leaves, rec) {
                            Some(s) => {
                                f.ok += u32::from(s == S);
                                f.bad += u32::from(s == F);
                                f.i += 1;
                            }
                            None => {
                                next = Some(Next::Descend(c as usize));
                                break;
                            }
                        }
                    }
                    next.unwrap_or_else(|| {
                        let need = node.arg;
                        Next::Done(if u64::from(f.ok) >= need {
                            S
                        } else if u64::from(f.bad) > (kids.len() as u64).saturating_sub(need) {
                            F
                        } else {
                            R
                        })
                    })
                }
                op => {
                    // A decorator: its child's status, evaluated in place for
                    // a leaf, then mapped.
                    let child = match ret.take() {
                        Some(s) => Ok(s),
                        None if op == Op::Timeout
                            && (now - st[n].t0) * 1000.0 >= node.arg as f64 =>
                        {
                            st[n].last = 0;
                            Err(Next::Done(F))
                        }
                        None => match kids.first() {
                            None => Ok(F),
                            Some(&c) => match leaf::<REC>(nodes, c as usize, leaves, rec) {
                                Some(s) => Ok(s),
                                None => Err(Next::Descend(c as usize)),
                            },
                        },
                    };
                    match child {
                        Ok(s) => Next::Done(Self::decorate(op, node.arg, &mut st[n], s)),
                        Err(next) => next,
                    }
                }
            };
            match next {
                Next::Descend(c) => {
                    let fr = Self::enter(nodes, st, c, step, now);
                    stack.push(fr);
                }
                Next::Done(s) => {
                    if REC {
                        rec.push((n, s));
                    }
                    stack.pop();
                    if stack.is_empty() {
                        return s;
                    }
                    ret = Some(s);
                }
            }
        }
    }

    /// A decorator's status from its child's `s`.
    fn decorate(op: Op, arg: u64, ns: &mut NodeState, s: Status) -> Status {
        use Status::{Failure as F, Running as R, Success as S};
        match (op, s) {
            (_, R) => R,
            (Op::Inverter, S) => F,
            (Op::Inverter, F) => S,
            (Op::ForceSuccess, _) => S,
            (Op::ForceFailure, _) => F,
            (Op::Repeat, S) => {
                ns.mem = ns.mem.saturating_add(1);
                if u64::from(ns.mem) >= arg {
                    ns.mem = 0;
                    S
                } else {
                    R
                }
            }
            (Op::Retry, F) => {
                ns.mem = ns.mem.saturating_add(1);
                if u64::from(ns.mem) > arg {
                    ns.mem = 0;
                    F
                } else {
                    R
                }
            }
            (Op::Repeat | Op::Retry, s) => {
                ns.mem = 0;
                s
            }
            (Op::Timeout, s) => {
                ns.last = 0;
                s
            }
            (_, s) => s,
        }
    }
}
