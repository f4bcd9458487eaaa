//! The executors on scripted leaves: plan against stack walk (halts
//! included), BehaviorTree.CPP semantics of single node types, a BT against
//! its converted HFSM.

use super::*;
use btfsm_format::{Limits, toml::parse_str};
use btfsm_model::BtNodeKind;
use btfsm_model::PolicyBody;
use btfsm_model::bt::Bt;
use std::path::Path;
use std::sync::Arc;

/// Leaves with scripted answers: conditions by name, actions finish after
/// `n` ticks.
struct Script {
    conds: std::collections::BTreeMap<&'static str, bool>,
    ticks: Vec<(usize, &'static str)>,
    left: std::collections::BTreeMap<usize, u32>,
}

impl Leaves for Script {
    fn condition(&mut self, _key: usize, call: &Call) -> bool {
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
root = { parallel = ["retry", "inv", "time"], success = 3 }
retry = { retry = "dock", times = 2 }
dock = { action = "Dock!", skill = "Dock" }
inv = { inverter = "tucked" }
tucked = { condition = "Tucked?", skill = "Arm-Tucked" }
time = { timeout = "tuck", ms = 2500 }
tuck = { action = "Tuck!", skill = "Tuck-Arm" }
"#;

/// Dock fails once then succeeds (the second of Retry's two attempts), the
/// inverted condition succeeds, and Tuck-Arm never finishes, so Timeout
/// fails it after 2.5 s of (scripted) time; Parallel needs all three.
struct Decor {
    t: f64,
    docks: u32,
}

impl Leaves for Decor {
    fn condition(&mut self, _: usize, _: &Call) -> bool {
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
    // Tick 1: Dock fails, Retry yields (RUNNING); inverter SUCCESS; tuck
    // RUNNING.
    assert_eq!(ex.tick(&mut d), Status::Running);
    d.t = 1.0;
    // Tick 2: Dock succeeds; the inverter finished on tick 1 and is not
    // ticked again; the Timeout is still running.
    assert_eq!(ex.tick(&mut d), Status::Running);
    let st = ex.statuses.clone().unwrap();
    assert!(st.contains(&(time_node, Status::Running)), "{st:?}");
    assert_eq!(d.docks, 2);
    d.t = 3.0;
    // Tick 3: the Timeout fails Tuck-Arm, so the Parallel fails.
    assert_eq!(ex.tick(&mut d), Status::Failure);
    let st = ex.statuses.clone().unwrap();
    assert!(st.contains(&(time_node, Status::Failure)), "{st:?}");
    assert_eq!(d.docks, 2);
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
    let cm = recharge_machine(m);
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
    use crate::rng::SimRng;
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
        // The four ways to tick: plan or stack walk, noting or not, against
        // a recursive reference (BehaviorTree.CPP's semantics written as its
        // sources are, node by node; the engine itself is the oracle of
        // tests/differential/).
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
    use crate::rng::SimRng;
    use btfsm_transform::bt_to_hfsm::bt_to_hfsm;
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
            // The HFSM's executor halts nothing: leaf calls are compared.
            a.log.retain(|e| e.1 != 'h');
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
    fn condition(&mut self, _key: usize, call: &Call) -> bool {
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
    fn halt(&mut self, key: usize) {
        self.log.push((key, 'h'));
    }
    fn now(&self) -> f64 {
        self.step as f64 * 0.1
    }
}

/// A random BT of about `size` nodes as TOML, of every kind the executor
/// models.
fn random_tree(rng: &mut crate::rng::SimRng, size: usize, kinds: &[usize]) -> String {
    let mut lines = Vec::new();
    let mut next = 1;
    let mut open = vec![0usize];
    let pick = |rng: &mut crate::rng::SimRng, n: u64| (rng.next_u64() % n) as usize;
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

/// BehaviorTree.CPP 4's semantics of the TOML kinds written recursively,
/// one function per node type as in its sources (`executeTick`,
/// `haltChild`, `resetChildren`), over the model (small trees only).
struct Reference<'a> {
    bt: &'a Bt,
    calls: Vec<Option<Call>>,
    st: Vec<Option<Status>>,
    idx: Vec<usize>,
    cnt: Vec<i64>,
    ok: Vec<usize>,
    bad: Vec<usize>,
    t0: Vec<f64>,
    now: f64,
    noted: Vec<(usize, Status)>,
}

impl<'a> Reference<'a> {
    fn new(bt: &'a Bt, calls: Vec<Option<Call>>) -> Self {
        let n = bt.nodes.len();
        Reference {
            bt,
            calls,
            st: vec![None; n],
            idx: vec![0; n],
            cnt: vec![0; n],
            ok: vec![0; n],
            bad: vec![0; n],
            t0: vec![0.0; n],
            now: 0.0,
            noted: vec![],
        }
    }

    fn tick(&mut self, leaves: &mut impl Leaves) -> (Status, Vec<(usize, Status)>) {
        self.now = leaves.now();
        self.noted.clear();
        let root = self.bt.root;
        let s = self.exec(root, leaves);
        if s != Status::Running {
            self.st[root] = None;
        }
        (s, std::mem::take(&mut self.noted))
    }

    fn halt_child(&mut self, c: usize, leaves: &mut impl Leaves) {
        if self.st[c] == Some(Status::Running) {
            match self.bt.nodes[c].kind {
                BtNodeKind::Action => leaves.halt(c),
                BtNodeKind::SequenceMemory | BtNodeKind::FallbackMemory => self.idx[c] = 0,
                BtNodeKind::Parallel { .. } => (self.ok[c], self.bad[c]) = (0, 0),
                BtNodeKind::Repeat { .. } | BtNodeKind::Retry { .. } => self.cnt[c] = 0,
                _ => {}
            }
            self.reset_children(c, leaves);
        }
        self.st[c] = None;
    }

    fn reset_children(&mut self, n: usize, leaves: &mut impl Leaves) {
        for c in self.bt.nodes[n].children.clone() {
            self.halt_child(c, leaves);
        }
    }

    /// Ticks node `n` (`executeTick` of its type), noting its status.
    fn exec(&mut self, n: usize, leaves: &mut impl Leaves) -> Status {
        use BtNodeKind as K;
        use Status::{Failure as F, Running as R, Success as S};
        let kind = self.bt.nodes[n].kind;
        let kids = self.bt.nodes[n].children.clone();
        let s = match kind {
            K::Condition => match &self.calls[n] {
                Some(c) if leaves.condition(n, c) => S,
                _ => F,
            },
            K::Action => match (self.st[n], &self.calls[n]) {
                (Some(S), _) => S,
                (Some(F), _) => F,
                (_, Some(c)) => leaves.action(n, c),
                (_, None) => F,
            },
            K::Sequence | K::Fallback => self.reactive(n, kind == K::Sequence, &kids, leaves),
            K::SequenceMemory | K::FallbackMemory => {
                self.with_memory(n, kind == K::SequenceMemory, &kids, leaves)
            }
            K::Parallel { success } => self.parallel(n, success, &kids, leaves),
            K::Repeat { .. } | K::Retry { .. } => self.repeat(n, kind, kids[0], leaves),
            K::Timeout { ms } => {
                if self.st[n] != Some(R) {
                    self.t0[n] = self.now;
                }
                if (self.now - self.t0[n]) * 1000.0 >= ms as f64 {
                    self.halt_child(kids[0], leaves);
                    F
                } else {
                    self.exec(kids[0], leaves)
                }
            }
            _ => match (kind, self.exec(kids[0], leaves)) {
                (_, R) => R,
                (K::Inverter, S) => F,
                (K::Inverter, _) => S,
                (K::ForceSuccess, _) => S,
                (K::ForceFailure, _) => F,
                (_, s) => s,
            },
        };
        // A decorator resets a child that finished.
        if kind.is_decorator() && matches!(self.st[kids[0]], Some(S | F)) {
            self.st[kids[0]] = None;
        }
        self.st[n] = Some(s);
        self.noted.push((n, s));
        s
    }

    /// ReactiveSequence (`sequence`) or ReactiveFallback: every child from
    /// the first, a RUNNING one halting the others.
    fn reactive(
        &mut self,
        n: usize,
        sequence: bool,
        kids: &[usize],
        leaves: &mut impl Leaves,
    ) -> Status {
        use Status::{Failure as F, Running as R, Success as S};
        let go_on = if sequence { S } else { F };
        for (i, &c) in kids.iter().enumerate() {
            match self.exec(c, leaves) {
                R => {
                    for (j, &o) in kids.iter().enumerate() {
                        if j != i {
                            self.halt_child(o, leaves);
                        }
                    }
                    return R;
                }
                s if s == go_on => {}
                s => {
                    self.reset_children(n, leaves);
                    return s;
                }
            }
        }
        self.reset_children(n, leaves);
        go_on
    }

    /// Sequence (`sequence_memory`) or Fallback: from the child it is at.
    fn with_memory(
        &mut self,
        n: usize,
        sequence: bool,
        kids: &[usize],
        leaves: &mut impl Leaves,
    ) -> Status {
        use Status::{Failure as F, Running as R, Success as S};
        let go_on = if sequence { S } else { F };
        while self.idx[n] < kids.len() {
            match self.exec(kids[self.idx[n]], leaves) {
                R => return R,
                s if s == go_on => self.idx[n] += 1,
                s => {
                    self.reset_children(n, leaves);
                    self.idx[n] = 0;
                    return s;
                }
            }
        }
        self.reset_children(n, leaves);
        self.idx[n] = 0;
        go_on
    }

    /// Parallel with `success` children to succeed: a child that finished
    /// is not ticked again until the node finishes.
    fn parallel(
        &mut self,
        n: usize,
        success: usize,
        kids: &[usize],
        leaves: &mut impl Leaves,
    ) -> Status {
        use Status::{Failure as F, Running as R, Success as S};
        let k = kids.len();
        let fail = k - success + 1;
        for &c in kids {
            if !matches!(self.st[c], Some(S | F)) {
                match self.exec(c, leaves) {
                    S => self.ok[n] += 1,
                    F => self.bad[n] += 1,
                    R => {}
                }
            }
            let done = if self.ok[n] >= success {
                Some(S)
            } else if k - self.bad[n] < success || self.bad[n] == fail {
                Some(F)
            } else {
                None
            };
            if let Some(s) = done {
                (self.ok[n], self.bad[n]) = (0, 0);
                self.reset_children(n, leaves);
                return s;
            }
        }
        R
    }

    /// Repeat (again on SUCCESS) or RetryUntilSuccessful (on FAILURE) of
    /// child `c`, yielding RUNNING after a child that finished at once.
    fn repeat(&mut self, n: usize, kind: BtNodeKind, c: usize, leaves: &mut impl Leaves) -> Status {
        use BtNodeKind as K;
        use Status::{Failure as F, Running as R, Success as S};
        let (again, other, limit) = match kind {
            K::Repeat { times } => (S, F, times.map_or(-1, i64::from)),
            K::Retry { times } => (F, S, i64::from(times)),
            _ => unreachable!(),
        };
        loop {
            if limit >= 0 && self.cnt[n] >= limit {
                self.cnt[n] = 0;
                break again;
            }
            let prev = self.st[c];
            match self.exec(c, leaves) {
                R => break R,
                s if s == again => {
                    self.cnt[n] += 1;
                    self.halt_child(c, leaves);
                    if prev.is_none() && (limit < 0 || self.cnt[n] < limit) {
                        break R;
                    }
                }
                _ => {
                    self.cnt[n] = 0;
                    self.halt_child(c, leaves);
                    break other;
                }
            }
        }
    }
}

/// A machine whose Battery-Level guards need 20 %, whose Recharge recharges
/// and whose other states tuck the arm (also for `machine.rs`'s tests).
pub(super) fn recharge_machine(m: &btfsm_model::StateMachine) -> CompiledMachine {
    CompiledMachine::new(m, |c| {
        Ok::<_, ()>(match c.skill.as_str() {
            "Battery-Level" => Call::BatteryLevel(20.0),
            "Recharge" => Call::Recharge,
            _ => Call::TuckArm,
        })
    })
    .expect("infallible")
}
