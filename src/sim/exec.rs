//! Executors: how a BT, an FSM and an HFSM drive the robot, one step at a time
//! (SPEC §6), against the shared skill library behind the [`Leaves`] trait.
//!
//! - BT (the paper's sec. II-A; Colledanchise & Ögren, "Behavior Trees in
//!   Robotics and AI", ch. 1): the root is ticked once per step. Sequence and
//!   Fallback are reactive (re-ticked from the first child), Sequence* and
//!   Fallback* resume at the running child, Parallel succeeds when `success`
//!   children succeed, decorators map their child's status. A node that was not
//!   ticked on the previous step starts afresh (halting resets memory), and an
//!   action not ticked in a step is cancelled by the caller.
//! - FSM (sec. II-B, Algorithm 3): the current state's guards are checked, in
//!   the order written, before its skill runs; the skill's outcome selects the
//!   transition. A decision state (SELECTOR) only checks guards. Several states
//!   may run in one step (a finished action's successor starts at once), until
//!   an action returns RUNNING or the machine ends.
//! - HFSM (sec. III): containers are entered at their initial state; a
//!   transition to a container's outcome continues with the container's own
//!   transition on that outcome; the guards of the enclosing containers are
//!   checked first, outermost first. Reaching the top-level outcome `RUNNING`
//!   ends the step and the next step re-enters the machine (the construction of
//!   Fig. 6, which makes an HFSM tick like a BT); such a tick-driven machine is
//!   also re-entered after reaching FAILURE, as a BT's root is ticked again,
//!   and ends at SUCCESS.
//!
//! Both executors walk their structure with explicit stacks, never recursion.
//! A BT's reactive skeleton (its Sequence and Fallback nodes from the root
//! down to the first node with memory or a decorator) is compiled once into
//! a table of successors ([`Plan`]): a tick then jumps from leaf to leaf as the
//! short-circuit evaluation of an and/or expression does, and takes the stack
//! walk only for the subtrees below the skeleton. When every node's status is
//! noted (`sim --trace`), the composites a status leaves are noted with it (a
//! reactive composite returns the status of the child it stops at). A unit
//! test checks plan and stack walk, noting or not, against a recursive
//! reference on random trees of every node kind.

use super::skills::{Call, Status};
use crate::model::bt::Bt;
use crate::model::{BtNodeKind, StateBody, StateMachine, Target, Trigger};
use std::sync::Arc;

/// What an executor needs from the robot.
pub trait Leaves {
    /// Evaluates a condition.
    fn condition(&mut self, call: &Call) -> bool;
    /// Ticks the action of leaf `key` (continuing its running instance).
    fn action(&mut self, key: usize, call: &Call) -> Status;
    /// Simulated time, s (for Timeout).
    fn now(&self) -> f64;
}

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

/// One guard: all terms (`call`, negated) must hold.
pub type GuardTerms = Vec<(Call, bool)>;

/// A machine with its bindings resolved.
#[derive(Debug)]
pub struct CompiledMachine {
    pub m: StateMachine,
    pub call: Vec<Option<Call>>,
    /// Per state: its guards in order, with their targets.
    pub guards: Vec<Vec<(GuardTerms, Target)>>,
}

impl CompiledMachine {
    /// Resolves every state's binding and guard with `resolve`.
    pub fn new<E>(
        m: &StateMachine,
        mut resolve: impl FnMut(&crate::model::SkillCall) -> Result<Call, E>,
    ) -> Result<Self, Vec<(usize, E)>> {
        let mut errs = Vec::new();
        let mut call = vec![None; m.states.len()];
        let mut guards = vec![Vec::new(); m.states.len()];
        for (i, s) in m.states.iter().enumerate() {
            if let StateBody::Task(Some(c)) = &s.body {
                match resolve(c) {
                    Ok(c) => call[i] = Some(c),
                    Err(e) => errs.push((i, e)),
                }
            }
            for t in &s.transitions {
                if let Trigger::Guard(g) = &t.trigger {
                    let mut terms = Vec::new();
                    for term in &g.all {
                        match resolve(&term.condition) {
                            Ok(c) => terms.push((c, term.negate)),
                            Err(e) => errs.push((i, e)),
                        }
                    }
                    guards[i].push((terms, t.target.clone()));
                }
            }
        }
        if errs.is_empty() {
            Ok(CompiledMachine {
                m: m.clone(),
                call,
                guards,
            })
        } else {
            Err(errs)
        }
    }
}

/// The run-time state of an FSM or HFSM.
#[derive(Debug)]
pub struct MachineExec {
    pub c: Arc<CompiledMachine>,
    pub current: usize,
    /// The outcome the machine ended with, and why.
    pub finished: Option<(String, String)>,
    /// When `Some`, every state run in the last step with its status.
    pub statuses: Option<Vec<(usize, Status)>>,
}

enum Flow {
    Enter(usize),
    /// An outcome of the region of the state's parent (`None`: top level).
    Up(Option<usize>, String),
}

impl MachineExec {
    pub fn new(c: Arc<CompiledMachine>, record: bool) -> Self {
        let current = c.m.top.initial;
        MachineExec {
            c,
            current,
            finished: None,
            statuses: record.then(Vec::new),
        }
    }

    fn holds(terms: &GuardTerms, leaves: &mut impl Leaves) -> bool {
        terms.iter().all(|(c, neg)| leaves.condition(c) != *neg)
    }

    fn follow(&self, from: usize, t: &Target) -> Flow {
        match t {
            Target::State(s) => Flow::Enter(*s),
            Target::Outcome(o) => Flow::Up(self.c.m.states[from].parent, o.clone()),
        }
    }

    fn note(&mut self, s: usize, st: Status) {
        if let Some(v) = &mut self.statuses {
            v.push((s, st));
        }
    }

    /// Runs one step; `Some` once the machine has ended (SUCCESS for the
    /// outcome `SUCCESS`, FAILURE for any other).
    pub fn step(&mut self, leaves: &mut impl Leaves) -> Status {
        if let Some((o, _)) = &self.finished {
            return if o == "SUCCESS" {
                Status::Success
            } else {
                Status::Failure
            };
        }
        if let Some(v) = &mut self.statuses {
            v.clear();
        }
        let c = self.c.clone();
        let limit = 4 * c.m.states.len() + 16;
        let mut hops = 0;
        // Guards of the enclosing containers, outermost first.
        let mut anc = Vec::new();
        let mut p = c.m.states[self.current].parent;
        while let Some(a) = p {
            anc.push(a);
            p = c.m.states[a].parent;
        }
        let mut flow = Flow::Enter(self.current);
        'anc: for &a in anc.iter().rev() {
            for (g, t) in &c.guards[a] {
                if Self::holds(g, leaves) {
                    flow = self.follow(a, t);
                    break 'anc;
                }
            }
        }
        loop {
            hops += 1;
            if hops > limit {
                // A cycle of instantaneous transitions: wait for the next step.
                return Status::Running;
            }
            let (from, outcome) = match flow {
                Flow::Up(None, o) => {
                    if o == "RUNNING" {
                        self.current = c.m.top.initial;
                        return Status::Running;
                    }
                    // A tick-driven machine (top-level outcome RUNNING, as the
                    // BT -> HFSM construction makes) is re-entered after a
                    // failure, as a BT's root is ticked again.
                    if o != "SUCCESS" && c.m.top.outcomes.iter().any(|x| x == "RUNNING") {
                        self.current = c.m.top.initial;
                        return Status::Failure;
                    }
                    let st = if o == "SUCCESS" {
                        Status::Success
                    } else {
                        Status::Failure
                    };
                    self.finished = Some((o.clone(), format!("reached the outcome {o}")));
                    return st;
                }
                Flow::Up(Some(container), o) => (container, o),
                Flow::Enter(s) => {
                    // A state left by a guard runs nothing (and is not noted).
                    if let Some((_, t)) = c.guards[s].iter().find(|(g, _)| Self::holds(g, leaves)) {
                        flow = self.follow(s, t);
                        continue;
                    }
                    let st = match &c.m.states[s].body {
                        StateBody::Container(r) => {
                            flow = Flow::Enter(r.initial);
                            continue;
                        }
                        StateBody::Decision => Status::Running,
                        StateBody::Task(_) => match &c.call[s] {
                            Some(call) if call.is_action() => leaves.action(s, call),
                            Some(call) => {
                                if leaves.condition(call) {
                                    Status::Success
                                } else {
                                    Status::Failure
                                }
                            }
                            None => Status::Failure,
                        },
                    };
                    self.note(s, st);
                    (s, st.as_str().to_string())
                }
            };
            let tr = c.m.states[from]
                .transitions
                .iter()
                .find(|t| matches!(&t.trigger, Trigger::Outcome(o) if *o == outcome));
            match tr {
                Some(t) => match self.follow(from, &t.target) {
                    Flow::Enter(next) if outcome == "RUNNING" => {
                        self.current = next;
                        return Status::Running;
                    }
                    f => flow = f,
                },
                None if outcome == "RUNNING" => {
                    self.current = from;
                    return Status::Running;
                }
                None => {
                    self.finished = Some((
                        "FAILURE".into(),
                        format!(
                            "state `{}` returned {outcome} and has no transition for it",
                            c.m.path(from)
                        ),
                    ));
                    return Status::Failure;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::format::{Limits, toml::parse_str};
    use crate::model::PolicyBody;
    use std::path::Path;

    /// Leaves with scripted answers: conditions by name, actions finish after
    /// `n` ticks.
    struct Script {
        conds: std::collections::BTreeMap<&'static str, bool>,
        ticks: Vec<(usize, &'static str)>,
        left: std::collections::BTreeMap<usize, u32>,
    }

    impl Leaves for Script {
        fn condition(&mut self, call: &Call) -> bool {
            self.conds.get(call.name()).copied().unwrap_or(false)
        }
        fn action(&mut self, key: usize, call: &Call) -> Status {
            self.ticks.push((key, call.name()));
            let l = self.left.entry(key).or_insert(2);
            *l -= 1;
            if *l == 0 {
                self.left.remove(&key);
                if call.name() == "Recharge" {
                    self.conds.insert("Battery-Level", true);
                }
                Status::Success
            } else {
                Status::Running
            }
        }
        fn now(&self) -> f64 {
            self.ticks.len() as f64
        }
    }

    fn script() -> Script {
        Script {
            conds: Default::default(),
            ticks: vec![],
            left: Default::default(),
        }
    }

    const BT: &str = r#"
kind = "bt"
root = "root"
[nodes]
root = { sequence = ["charged", "go"] }
charged = { fallback = ["ok", "recharge"] }
ok = { condition = "Battery?", skill = "Battery-Level", args = { min = 20 } }
recharge = { action = "Recharge!", skill = "Recharge" }
go = { sequence_memory = ["a", "b"] }
a = { action = "Tuck!", skill = "Tuck-Arm" }
b = { action = "Dock!", skill = "Dock" }
"#;

    /// Reads a BT and binds its leaves with `bind` (skill name -> call).
    fn compile_bt(text: &str, bind: fn(&str) -> Call) -> CompiledBt {
        let l = parse_str("t.toml", text, Path::new("."), &Limits::default()).unwrap();
        let PolicyBody::Bt(bt) = &l.policy.body else {
            panic!()
        };
        let calls = bt
            .nodes
            .iter()
            .map(|n| n.skill.as_ref().map(|s| bind(&s.skill)))
            .collect();
        CompiledBt::new(bt, calls)
    }

    #[test]
    fn reactive_fallback_preempts_and_memory_sequence_resumes() {
        let bind = |s: &str| match s {
            "Battery-Level" => Call::BatteryLevel(20.0),
            "Recharge" => Call::Recharge,
            "Tuck-Arm" => Call::TuckArm,
            _ => Call::Dock,
        };
        let mut ex = BtExec::new(Arc::new(compile_bt(BT, bind)), true);
        let mut s = script();
        // Battery low: Recharge runs two ticks, then the memory sequence; a
        // finished action's successor starts in the same tick.
        let out: Vec<Status> = (0..4).map(|_| ex.tick(&mut s)).collect();
        use Status::*;
        assert_eq!(out, vec![Running, Running, Running, Success]);
        let names: Vec<&str> = s.ticks.iter().map(|t| t.1).collect();
        assert_eq!(
            names,
            vec![
                "Recharge", "Recharge", "Tuck-Arm", "Tuck-Arm", "Dock", "Dock"
            ]
        );
        // The last tick ran the condition, the sequence*, its second child.
        let st = ex.statuses.clone().unwrap();
        assert!(st.contains(&(0, Success)) && st.contains(&(6, Success)));
    }

    const DECORATED: &str = r#"
kind = "bt"
root = "root"
[nodes]
root = { parallel = ["retry", "inv", "time"], success = 2 }
retry = { retry = "dock", times = 1 }
dock = { action = "Dock!", skill = "Dock" }
inv = { inverter = "tucked" }
tucked = { condition = "Tucked?", skill = "Arm-Tucked" }
time = { timeout = "tuck", ms = 2500 }
tuck = { action = "Tuck!", skill = "Tuck-Arm" }
"#;

    /// Dock fails once then succeeds (Retry absorbs the failure), the
    /// inverted condition succeeds, and Tuck-Arm never finishes, so Timeout
    /// fails it after 2.5 s of (scripted) time.
    struct Decor {
        t: f64,
        docks: u32,
    }

    impl Leaves for Decor {
        fn condition(&mut self, _: &Call) -> bool {
            false
        }
        fn action(&mut self, _key: usize, call: &Call) -> Status {
            match call {
                Call::Dock => {
                    self.docks += 1;
                    if self.docks == 1 {
                        Status::Failure
                    } else {
                        Status::Success
                    }
                }
                _ => Status::Running,
            }
        }
        fn now(&self) -> f64 {
            self.t
        }
    }

    #[test]
    fn parallel_retry_inverter_and_timeout() {
        let bind = |s: &str| match s {
            "Dock" => Call::Dock,
            "Tuck-Arm" => Call::TuckArm,
            _ => Call::ArmTucked,
        };
        let compiled = Arc::new(compile_bt(DECORATED, bind));
        let time_node = compiled
            .nodes
            .iter()
            .position(|x| matches!(x.kind, BtNodeKind::Timeout { .. }))
            .unwrap();
        let mut ex = BtExec::new(compiled, true);
        let mut d = Decor { t: 0.0, docks: 0 };
        // Tick 1: Dock fails, Retry says RUNNING; inverter SUCCESS; tuck RUNNING.
        assert_eq!(ex.tick(&mut d), Status::Running);
        d.t = 1.0;
        // Tick 2: Dock succeeds: two successes reach the threshold.
        assert_eq!(ex.tick(&mut d), Status::Success);
        let st = ex.statuses.clone().unwrap();
        assert!(st.contains(&(time_node, Status::Running)));
        d.t = 3.0;
        ex.tick(&mut d);
        let st = ex.statuses.clone().unwrap();
        assert!(st.contains(&(time_node, Status::Failure)), "{st:?}");
    }

    const FSM: &str = r#"
kind = "fsm"
initial = "A"
outcomes = ["SUCCESS"]
[states.A]
skill = "Tuck-Arm"
guards = [{ unless = "Battery-Level", args = { min = 20 }, to = "R" }]
on = { SUCCESS = "SUCCESS", RUNNING = "A" }
[states.R]
skill = "Recharge"
on = { SUCCESS = "A", RUNNING = "R" }
"#;

    #[test]
    fn fsm_checks_guards_before_the_skill() {
        let l = parse_str("f.toml", FSM, Path::new("."), &Limits::default()).unwrap();
        let PolicyBody::Machine(m) = &l.policy.body else {
            panic!()
        };
        let cm = CompiledMachine::new(m, |c| {
            Ok::<_, ()>(match c.skill.as_str() {
                "Battery-Level" => Call::BatteryLevel(20.0),
                "Recharge" => Call::Recharge,
                _ => Call::TuckArm,
            })
        })
        .unwrap();
        let mut ex = MachineExec::new(Arc::new(cm), false);
        let mut s = script();
        let out: Vec<Status> = (0..5).map(|_| ex.step(&mut s)).collect();
        let names: Vec<&str> = s.ticks.iter().map(|t| t.1).collect();
        // The guard fires before Tuck-Arm ever runs; Recharge's SUCCESS leads
        // back to A, which starts in the same step.
        assert_eq!(names, vec!["Recharge", "Recharge", "Tuck-Arm", "Tuck-Arm"]);
        assert_eq!(out[2], Status::Success);
        assert_eq!(ex.finished.as_ref().unwrap().0, "SUCCESS");
    }

    /// Random trees of every node kind, ticked through the plan and by the
    /// stack walk, each noting statuses or not, and by an independent
    /// recursive reference of the semantics in this file's header: the same
    /// statuses, the same leaf calls in the same order, the same noted
    /// statuses.
    #[test]
    fn plan_stack_walk_and_recursive_reference_agree_on_random_trees() {
        use crate::sim::rng::SimRng;
        let mut rng = SimRng::named(11, "exec-differential");
        for case in 0..400 {
            let text = random_tree(&mut rng, 2 + case % 25, &(0..12).collect::<Vec<_>>());
            let l = parse_str("r.toml", &text, Path::new("."), &Limits::default())
                .unwrap_or_else(|e| panic!("{e:?}\n{text}"));
            let PolicyBody::Bt(bt) = &l.policy.body else {
                panic!()
            };
            let calls = oracle_calls(bt);
            let compiled = Arc::new(CompiledBt::new(bt, calls.clone()));
            // The four ways to tick: plan or stack walk, noting or not.
            let mut execs = [
                ("plan", BtExec::new(compiled.clone(), false)),
                ("plan noting", BtExec::new(compiled.clone(), true)),
                (
                    "walk",
                    BtExec::new(compiled.clone(), false).with_stack_walk(),
                ),
                ("walk noting", BtExec::new(compiled, true).with_stack_walk()),
            ];
            let mut reference = Reference::new(bt, calls);
            let seed = rng.next_u64();
            let mut oracles: Vec<Oracle> = (0..5).map(|_| Oracle::new(seed)).collect();
            for t in 0..30 {
                for o in &mut oracles {
                    o.step = t;
                    o.log.clear();
                }
                let (ref_oracle, others) = oracles.split_last_mut().expect("five");
                let (sr, noted) = reference.tick(ref_oracle);
                let ctx = format!("case {case}, tick {t}\n{text}");
                for ((name, ex), o) in execs.iter_mut().zip(others) {
                    let s = ex.tick(o);
                    assert_eq!(
                        (s, &o.log),
                        (sr, &ref_oracle.log),
                        "{name} vs reference, {ctx}"
                    );
                    if let Some(v) = &ex.statuses {
                        assert_eq!(v, &noted, "{name}: noted statuses, {ctx}");
                    }
                }
            }
        }
    }

    /// The paper's sec. III claim, on random trees: the HFSM that
    /// `bt_to_hfsm` builds (Fig. 5 -> Fig. 6) and the BT tick the same leaves
    /// in the same order with the same statuses, step after step, until the
    /// task first succeeds (then the machine has ended and the BT is ticked
    /// on). Kinds: `kinds` (see `random_tree`).
    fn hfsm_ticks_like_the_bt(kinds: &[usize], cases: usize) -> Result<(), String> {
        use crate::sim::rng::SimRng;
        use crate::transform::bt_to_hfsm::bt_to_hfsm;
        let mut rng = SimRng::named(12, "bt-vs-hfsm");
        for case in 0..cases {
            let text = random_tree(&mut rng, 2 + case % 25, kinds);
            let l = parse_str("r.toml", &text, Path::new("."), &Limits::default()).unwrap();
            let PolicyBody::Bt(bt) = &l.policy.body else {
                panic!()
            };
            let m = bt_to_hfsm(bt).map_err(|e| format!("{e:?}"))?;
            let calls = oracle_calls(bt);
            let mut bx = BtExec::new(Arc::new(CompiledBt::new(bt, calls.clone())), false);
            // The random leaves have no skill binding (nothing to resolve);
            // state i is BT node i, so it gets node i's call.
            let mut cm = CompiledMachine::new(&m, |_| Err::<Call, ()>(())).expect("no bindings");
            cm.call = calls;
            let mut mx = MachineExec::new(Arc::new(cm), false);
            let seed = rng.next_u64();
            let (mut a, mut b) = (Oracle::new(seed), Oracle::new(seed));
            for t in 0..30 {
                a.step = t;
                b.step = t;
                a.log.clear();
                b.log.clear();
                let sa = bx.tick(&mut a);
                let sb = mx.step(&mut b);
                if (sa, &a.log) != (sb, &b.log) {
                    return Err(format!(
                        "case {case}, tick {t}: BT {sa:?} {:?}, HFSM {sb:?} {:?}\n{text}",
                        a.log, b.log
                    ));
                }
                if sa == Status::Success {
                    break;
                }
            }
        }
        Ok(())
    }

    #[test]
    fn converted_hfsm_ticks_like_the_reactive_bt() {
        // Sequence, Fallback, Inverter, ForceSuccess, ForceFailure.
        hfsm_ticks_like_the_bt(&[0, 1, 2, 6, 7, 11], 400).unwrap();
    }

    /// The bindings the [`Oracle`] answers: leaf i as object i, conditions
    /// by In-Hand, actions by Pick; unbound leaves (label `U`) stay unbound.
    fn oracle_calls(bt: &Bt) -> Vec<Option<Call>> {
        bt.nodes
            .iter()
            .enumerate()
            .map(|(i, n)| match n.kind {
                BtNodeKind::Condition if n.label != "U" => Some(Call::InHand(i)),
                BtNodeKind::Action if n.label != "U" => Some(Call::Pick { object: i }),
                _ => None,
            })
            .collect()
    }

    /// Leaf answers drawn from (seed, step, leaf): the same for every
    /// executor that asks the same question in the same step; every call is
    /// logged.
    struct Oracle {
        seed: u64,
        step: u64,
        log: Vec<(usize, char)>,
    }

    impl Oracle {
        fn new(seed: u64) -> Self {
            Oracle {
                seed,
                step: 0,
                log: vec![],
            }
        }
        fn draw(&self, leaf: usize) -> u64 {
            let mut x = self.seed ^ (self.step << 20) ^ (leaf as u64).wrapping_mul(0x9e37_79b9);
            x ^= x >> 33;
            x = x.wrapping_mul(0xff51_afd7_ed55_8ccd);
            x ^ (x >> 29)
        }
    }

    impl Leaves for Oracle {
        fn condition(&mut self, call: &Call) -> bool {
            let Call::InHand(i) = *call else { panic!() };
            self.log.push((i, 'c'));
            self.draw(i).is_multiple_of(2)
        }
        fn action(&mut self, key: usize, call: &Call) -> Status {
            let Call::Pick { object } = *call else {
                panic!()
            };
            assert_eq!(key, object);
            self.log.push((key, 'a'));
            [Status::Running, Status::Success, Status::Failure][(self.draw(key) % 3) as usize]
        }
        fn now(&self) -> f64 {
            self.step as f64 * 0.1
        }
    }

    /// A random BT of about `size` nodes as TOML, of every kind the executor
    /// models.
    fn random_tree(rng: &mut crate::sim::rng::SimRng, size: usize, kinds: &[usize]) -> String {
        let mut lines = Vec::new();
        let mut next = 1;
        let mut open = vec![0usize];
        let pick = |rng: &mut crate::sim::rng::SimRng, n: u64| (rng.next_u64() % n) as usize;
        while let Some(n) = open.pop() {
            let budget_left = next < size;
            let kind = if n == 0 || (budget_left && pick(rng, 3) > 0) {
                kinds[pick(rng, kinds.len() as u64)]
            } else {
                12 + pick(rng, 3)
            };
            let kids = |k: usize, next: &mut usize, open: &mut Vec<usize>| {
                let ids: Vec<String> = (0..k).map(|j| format!("\"n{}\"", *next + j)).collect();
                open.extend(*next..*next + k);
                *next += k;
                ids.join(", ")
            };
            let line = match kind {
                0..=5 => {
                    let k = 1 + pick(rng, 4);
                    let list = kids(k, &mut next, &mut open);
                    match kind {
                        0 | 1 => format!("n{n} = {{ sequence = [{list}] }}"),
                        2 => format!("n{n} = {{ fallback = [{list}] }}"),
                        3 => format!("n{n} = {{ sequence_memory = [{list}] }}"),
                        4 => format!("n{n} = {{ fallback_memory = [{list}] }}"),
                        _ => format!(
                            "n{n} = {{ parallel = [{list}], success = {} }}",
                            1 + pick(rng, k as u64)
                        ),
                    }
                }
                6..=11 => {
                    let c = kids(1, &mut next, &mut open);
                    let c = c.trim_matches('"');
                    match kind {
                        6 => format!("n{n} = {{ inverter = \"{c}\" }}"),
                        7 => format!("n{n} = {{ force_success = \"{c}\" }}"),
                        8 if pick(rng, 2) == 0 => format!("n{n} = {{ repeat = \"{c}\" }}"),
                        8 => format!(
                            "n{n} = {{ repeat = \"{c}\", times = {} }}",
                            1 + pick(rng, 3)
                        ),
                        9 => format!("n{n} = {{ retry = \"{c}\", times = {} }}", pick(rng, 3)),
                        11 => format!("n{n} = {{ force_failure = \"{c}\" }}"),
                        _ => format!(
                            "n{n} = {{ timeout = \"{c}\", ms = {} }}",
                            100 * pick(rng, 5)
                        ),
                    }
                }
                12 => format!("n{n} = {{ condition = \"C{n}?\" }}"),
                13 => format!("n{n} = {{ action = \"A{n}!\" }}"),
                _ if pick(rng, 2) == 0 => format!("n{n} = {{ condition = \"U\" }}"),
                _ => format!("n{n} = {{ action = \"U\" }}"),
            };
            lines.push(line);
        }
        format!(
            "kind = \"bt\"\nroot = \"n0\"\n[nodes]\n{}\n",
            lines.join("\n")
        )
    }

    /// The semantics of this file's header, written recursively over the
    /// model (small trees only).
    struct Reference<'a> {
        bt: &'a Bt,
        calls: Vec<Option<Call>>,
        mem: Vec<u32>,
        last: Vec<u64>,
        t0: Vec<f64>,
        step: u64,
        now: f64,
        noted: Vec<(usize, Status)>,
    }

    impl<'a> Reference<'a> {
        fn new(bt: &'a Bt, calls: Vec<Option<Call>>) -> Self {
            let n = bt.nodes.len();
            Reference {
                bt,
                calls,
                mem: vec![0; n],
                last: vec![0; n],
                t0: vec![0.0; n],
                step: 0,
                now: 0.0,
                noted: vec![],
            }
        }

        fn tick(&mut self, leaves: &mut impl Leaves) -> (Status, Vec<(usize, Status)>) {
            self.step += 1;
            self.now = leaves.now();
            self.noted.clear();
            let s = self.node(self.bt.root, leaves);
            (s, std::mem::take(&mut self.noted))
        }

        fn node(&mut self, n: usize, leaves: &mut impl Leaves) -> Status {
            use BtNodeKind as K;
            use Status::{Failure as F, Running as R, Success as S};
            let kind = self.bt.nodes[n].kind;
            let kids = self.bt.nodes[n].children.clone();
            if matches!(
                kind,
                K::SequenceMemory
                    | K::FallbackMemory
                    | K::Repeat { .. }
                    | K::Retry { .. }
                    | K::Timeout { .. }
            ) {
                if self.last[n] + 1 != self.step {
                    self.mem[n] = 0;
                    self.t0[n] = self.now;
                }
                self.last[n] = self.step;
            }
            let s = match kind {
                K::Condition => match &self.calls[n] {
                    Some(c) if leaves.condition(c) => S,
                    _ => F,
                },
                K::Action => match &self.calls[n] {
                    Some(c) => leaves.action(n, c),
                    None => F,
                },
                K::Sequence | K::Fallback => {
                    let go_on = if kind == K::Sequence { S } else { F };
                    let mut out = go_on;
                    for c in kids {
                        let s = self.node(c, leaves);
                        if s != go_on {
                            out = s;
                            break;
                        }
                    }
                    out
                }
                K::SequenceMemory | K::FallbackMemory => {
                    let go_on = if kind == K::SequenceMemory { S } else { F };
                    let mut out = go_on;
                    let start = self.mem[n] as usize;
                    for (i, &c) in kids.iter().enumerate().skip(start) {
                        let s = self.node(c, leaves);
                        if s == R {
                            self.mem[n] = i as u32;
                            return self.note(n, R);
                        }
                        if s != go_on {
                            out = s;
                            break;
                        }
                    }
                    self.mem[n] = 0;
                    out
                }
                K::Parallel { success } => {
                    let (mut ok, mut bad) = (0, 0);
                    for &c in &kids {
                        match self.node(c, leaves) {
                            S => ok += 1,
                            F => bad += 1,
                            R => {}
                        }
                    }
                    if ok >= success {
                        S
                    } else if bad > kids.len().saturating_sub(success) {
                        F
                    } else {
                        R
                    }
                }
                K::Timeout { ms } if (self.now - self.t0[n]) * 1000.0 >= ms as f64 => {
                    self.last[n] = 0;
                    F
                }
                _ => {
                    let s = self.node(kids[0], leaves);
                    match (kind, s) {
                        (_, R) => R,
                        (K::Inverter, S) => F,
                        (K::Inverter, _) => S,
                        (K::ForceSuccess, _) => S,
                        (K::ForceFailure, _) => F,
                        (K::Repeat { times }, S) => {
                            self.mem[n] += 1;
                            if times.is_some_and(|t| self.mem[n] >= t) {
                                self.mem[n] = 0;
                                S
                            } else {
                                R
                            }
                        }
                        (K::Retry { times }, F) => {
                            self.mem[n] += 1;
                            if self.mem[n] > times {
                                self.mem[n] = 0;
                                F
                            } else {
                                R
                            }
                        }
                        (K::Repeat { .. } | K::Retry { .. }, s) => {
                            self.mem[n] = 0;
                            s
                        }
                        (K::Timeout { .. }, s) => {
                            self.last[n] = 0;
                            s
                        }
                        (_, s) => s,
                    }
                }
            };
            self.note(n, s)
        }

        fn note(&mut self, n: usize, s: Status) -> Status {
            self.noted.push((n, s));
            s
        }
    }
}
