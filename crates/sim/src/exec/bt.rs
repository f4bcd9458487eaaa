//! The BT executor (see the module doc of [`super`]): BehaviorTree.CPP 4's
//! node semantics (docs/bt-semantics.md; read from BehaviorTree.CPP's
//! `src/controls/*.cpp`, `src/decorators/*.cpp`, `control_node.cpp`,
//! `decorator_node.cpp`, `action_node.cpp`, and checked tick by tick against
//! the engine by tests/differential/), on a compiled tree, with its reactive
//! skeleton as a table of successors ([`Plan`]) and a stack walk for the
//! subtrees below it (each node type's step of it in `nodes.rs`).
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
use super::ops::{Op, op_of};
use super::plan::{DONE_FAILURE, DONE_SUCCESS, NO_NODE, Plan};
use crate::skills::{Call, Status};
use btfsm_model::BtNodeKind;
use btfsm_model::bt::Bt;
use std::sync::Arc;

mod nodes;

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

/// A node of a [`CompiledBt`].
#[derive(Debug)]
pub struct XNode {
    pub kind: BtNodeKind,
    pub call: Option<Call>,
    /// How it is ticked, decided once from its kind, type and binding.
    pub(super) op: Op,
    /// Numbers the op needs: Parallel's success and failure thresholds,
    /// ParallelAll's failure threshold, Repeat's and Retry's count (-1:
    /// forever), Timeout's milliseconds.
    pub(super) a: i64,
    pub(super) b: i64,
    /// Its children are `kids[start..end]`.
    pub(super) start: u32,
    pub(super) end: u32,
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
        CompiledBt {
            nodes,
            kids,
            root: bt.root,
            plan,
            parent,
        }
    }

    #[inline(always)]
    fn kids(&self, n: usize) -> &[u32] {
        &self.kids[self.nodes[n].start as usize..self.nodes[n].end as usize]
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
        // A local copy: the loop keeps it in a register.
        let mut run_slot = *running;
        loop {
            let Some(slot) = plan.slots.get(k) else {
                *running = run_slot;
                return if k == DONE_SUCCESS {
                    Status::Success
                } else {
                    Status::Failure
                };
            };
            let n = slot.node;
            let node = &bt.nodes[n];
            // Leaf slots in place: through the plan a leaf's status is only
            // read for an action (RUNNING or not), so only that is kept.
            let s = match (node.op, &node.call) {
                (Op::Condition, Some(call)) => {
                    if leaves.condition(n, call) {
                        Status::Success
                    } else {
                        Status::Failure
                    }
                }
                (Op::Action, Some(call)) => {
                    let s = leaves.action(n, call);
                    self.st[n].st = if s == Status::Running {
                        St::Running
                    } else {
                        St::Idle
                    };
                    s
                }
                (Op::Action | Op::Condition | Op::Unbound, _) => Status::Failure,
                _ => {
                    let s = self.run::<REC>(n, leaves, rec);
                    if s != Status::Running {
                        // The skeleton resets a finished slot.
                        self.st[n].st = St::Idle;
                    }
                    s
                }
            };
            if REC && matches!(node.op, Op::Condition | Op::Action | Op::Unbound) {
                rec.push((n, s));
            }
            let (next, stop) = match s {
                Status::Success => (slot.on_success, slot.stop_success),
                Status::Failure => (slot.on_failure, slot.stop_failure),
                Status::Running => (DONE_SUCCESS, NO_NODE),
            };
            // Slots are numbered in reverse tick order: a successor past the
            // running slot means the skeleton left the composite holding
            // it, which halts it now (BehaviorTree.CPP's `haltChild` /
            // `resetChildren` of the reactive nodes).
            if run_slot == k {
                run_slot = NO_NODE;
            } else if run_slot != NO_NODE && (next >= DONE_FAILURE || next < run_slot) {
                let x = plan.slots[run_slot].node;
                self.halt_child(x, leaves);
                run_slot = NO_NODE;
            }
            if REC {
                // The composites the status leaves return it (a reactive
                // composite's status is that of the child it stops at).
                let mut a = bt.parent[n];
                while a != stop && a != NO_NODE {
                    rec.push((a, s));
                    a = bt.parent[a];
                }
            }
            if s == Status::Running {
                *running = k;
                return s;
            }
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
    #[inline(always)]
    fn halt_child(&mut self, c: usize, leaves: &mut impl Leaves) {
        if self.st[c].st != St::Running {
            self.st[c].st = St::Idle;
        } else {
            self.halt_running(c, leaves);
        }
    }

    /// [`Ticking::halt_child`] of a RUNNING node: the depth-first walk.
    #[inline(never)]
    fn halt_running(&mut self, c: usize, leaves: &mut impl Leaves) {
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
    #[inline(always)]
    fn reset_children(&mut self, n: usize, from: usize, leaves: &mut impl Leaves) {
        let bt = self.bt;
        let kids = bt.kids(n);
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
            let next = self.visit::<REC>(n, f, ret.take(), leaves, rec);
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
}
