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
    kids: Vec<usize>,
    pub root: usize,
}

/// A node of a [`CompiledBt`].
#[derive(Debug)]
pub struct XNode {
    pub kind: BtNodeKind,
    pub call: Option<Call>,
    /// What ticking it needs, decided once: a leaf is evaluated in place.
    leaf: Leaf,
    /// Its children are `kids[start..start + len]`.
    start: usize,
    len: usize,
}

/// How a node is ticked (precomputed from its kind and binding).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Leaf {
    /// A control node or decorator: gets a frame.
    No,
    /// An action bound to a skill.
    Action,
    /// A condition bound to a skill.
    Condition,
    /// A leaf without a binding: fails.
    Unbound,
}

impl CompiledBt {
    pub fn new(bt: &Bt, call: Vec<Option<Call>>) -> Self {
        let mut kids = Vec::new();
        let nodes = bt
            .nodes
            .iter()
            .zip(call)
            .map(|(n, call)| {
                let start = kids.len();
                kids.extend_from_slice(&n.children);
                let leaf = match (n.kind, &call) {
                    (BtNodeKind::Action, Some(_)) => Leaf::Action,
                    (BtNodeKind::Condition, Some(_)) => Leaf::Condition,
                    (BtNodeKind::Action | BtNodeKind::Condition, None) => Leaf::Unbound,
                    _ => Leaf::No,
                };
                XNode {
                    kind: n.kind,
                    call,
                    leaf,
                    start,
                    len: n.children.len(),
                }
            })
            .collect();
        CompiledBt {
            nodes,
            kids,
            root: bt.root,
        }
    }

    #[inline]
    fn kids(&self, n: &XNode) -> &[usize] {
        &self.kids[n.start..n.start + n.len]
    }
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
}

/// Per-node memory: the running child of a memory composite or a decorator's
/// counter, the start of a Timeout, the step the node was last ticked.
#[derive(Debug, Clone, Copy, Default)]
struct NodeState {
    mem: u32,
    last: u64,
    t0: f64,
}

#[derive(Debug)]
struct Frame {
    node: usize,
    i: usize,
    ok: usize,
    bad: usize,
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
        }
    }

    fn enter(st: &mut [NodeState], kind: BtNodeKind, step: u64, n: usize, now: f64) -> Frame {
        let ns = &mut st[n];
        if ns.last + 1 != step {
            ns.mem = 0;
            ns.t0 = now;
        }
        ns.last = step;
        let i = match kind {
            BtNodeKind::SequenceMemory | BtNodeKind::FallbackMemory => ns.mem as usize,
            _ => 0,
        };
        Frame {
            node: n,
            i,
            ok: 0,
            bad: 0,
        }
    }

    /// Evaluates a leaf in place; `None` for a node that needs a frame.
    #[inline(always)]
    fn leaf(cn: &XNode, c: usize, leaves: &mut impl Leaves) -> Option<Status> {
        match (cn.leaf, &cn.call) {
            (Leaf::Action, Some(call)) => Some(leaves.action(c, call)),
            (Leaf::Condition, Some(call)) => Some(if leaves.condition(call) {
                Status::Success
            } else {
                Status::Failure
            }),
            (Leaf::No, _) => None,
            _ => Some(Status::Failure),
        }
    }

    /// Ticks the tree once from the root.
    pub fn tick(&mut self, leaves: &mut impl Leaves) -> Status {
        use BtNodeKind as K;
        use Status::{Failure as F, Running as R, Success as S};
        self.step += 1;
        if let Some(v) = &mut self.statuses {
            v.clear();
        }
        let bt: &CompiledBt = &self.bt;
        let st = &mut self.node;
        let step = self.step;
        let now = leaves.now();
        let mut stack = std::mem::take(&mut self.stack);
        stack.clear();
        let root = Self::enter(st, bt.nodes[bt.root].kind, step, bt.root, now);
        stack.push(root);
        let mut ret: Option<Status> = None;
        loop {
            let top = stack.len() - 1;
            let n = stack[top].node;
            let node = &bt.nodes[n];
            let kids = bt.kids(node);
            let mut push = None;
            let mut composite = None;
            let out: Status = match node.kind {
                K::Action => match &node.call {
                    Some(c) => leaves.action(n, c),
                    None => F,
                },
                K::Condition => match &node.call {
                    Some(c) if leaves.condition(c) => S,
                    _ => F,
                },
                k @ (K::Sequence | K::SequenceMemory | K::Fallback | K::FallbackMemory) => {
                    let seq = matches!(k, K::Sequence | K::SequenceMemory);
                    let (go_on, stop) = if seq { (S, F) } else { (F, S) };
                    let f = &mut stack[top];
                    // Runs through leaf children in place; stops at a
                    // composite child (pushed) or at the node's result.
                    let mut r = ret.take();
                    loop {
                        match r {
                            None if f.i < kids.len() => {
                                let c = kids[f.i];
                                let cn = &bt.nodes[c];
                                let Some(leaf) = Self::leaf(cn, c, leaves) else {
                                    composite = Some(c);
                                    break R;
                                };
                                if let Some(v) = &mut self.statuses {
                                    v.push((c, leaf));
                                }
                                r = Some(leaf);
                            }
                            None => break go_on,
                            Some(x) if x == go_on => {
                                f.i += 1;
                                if f.i < kids.len() {
                                    r = None;
                                } else {
                                    st[n].mem = 0;
                                    break go_on;
                                }
                            }
                            Some(x) if x == stop => {
                                st[n].mem = 0;
                                break stop;
                            }
                            Some(_) => {
                                st[n].mem = f.i as u32;
                                break R;
                            }
                        }
                    }
                }
                K::Parallel { success } => {
                    let f = &mut stack[top];
                    if let Some(r) = ret.take() {
                        match r {
                            S => f.ok += 1,
                            F => f.bad += 1,
                            R => {}
                        }
                        f.i += 1;
                    }
                    if f.i < kids.len() {
                        push = Some(kids[f.i]);
                        R
                    } else if f.ok >= success {
                        S
                    } else if f.bad > kids.len().saturating_sub(success) {
                        F
                    } else {
                        R
                    }
                }
                K::Timeout { ms } if ret.is_none() && (now - st[n].t0) * 1000.0 >= ms as f64 => {
                    st[n].last = 0;
                    F
                }
                kind => match ret.take() {
                    None => {
                        push = Some(kids[0]);
                        R
                    }
                    Some(r) => match (kind, r) {
                        (K::Inverter, S) => F,
                        (K::Inverter, F) => S,
                        (K::ForceSuccess, S | F) => S,
                        (K::ForceFailure, S | F) => F,
                        (K::Repeat { times }, S) => {
                            st[n].mem += 1;
                            if times.is_some_and(|t| st[n].mem >= t) {
                                st[n].mem = 0;
                                S
                            } else {
                                R
                            }
                        }
                        (K::Retry { times }, F) => {
                            st[n].mem += 1;
                            if st[n].mem > times {
                                st[n].mem = 0;
                                F
                            } else {
                                R
                            }
                        }
                        (K::Repeat { .. } | K::Retry { .. }, r) => {
                            st[n].mem = 0;
                            r
                        }
                        (K::Timeout { .. }, r) => {
                            if r != R {
                                st[n].last = 0;
                            }
                            r
                        }
                        (_, r) => r,
                    },
                },
            };
            if let Some(c) = composite {
                // A composite's child known not to be a leaf: straight to
                // its frame.
                let fr = Self::enter(st, bt.nodes[c].kind, step, c, now);
                stack.push(fr);
                continue;
            }
            if let Some(c) = push {
                // Leaves are evaluated in place (no frame): the hot path.
                let cn = &bt.nodes[c];
                match Self::leaf(cn, c, leaves) {
                    Some(r) => {
                        if let Some(v) = &mut self.statuses {
                            v.push((c, r));
                        }
                        ret = Some(r);
                    }
                    None => {
                        let fr = Self::enter(st, cn.kind, step, c, now);
                        stack.push(fr);
                    }
                }
                continue;
            }
            if let Some(v) = &mut self.statuses {
                v.push((n, out));
            }
            stack.pop();
            if stack.is_empty() {
                self.stack = stack;
                return out;
            }
            ret = Some(out);
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
}
