//! Cyclomatic complexity and essential complexity (SPEC §3; paper sec. II-C and
//! Table III).
//!
//! - `cc = a + s - n + 1` on the representation's graph (arcs, sinks, vertices),
//!   McCabe 1976 in the form the paper uses.
//! - `essential_cc`: McCabe's essential complexity (McCabe 1976), for decision
//!   structures as Biggar et al. (2022) treat them. The policy's control-flow
//!   graph (one entry; one EXIT merging every terminal outcome; a BT node or HFSM
//!   container entered at its IN vertex and left from its OUT vertex) is reduced
//!   by collapsing structured primes until none is left, and `essential_cc` is the
//!   cc of what remains:
//!   1. a loop on one vertex (RUNNING: "repeat until done") is dropped, and
//!      parallel arcs are merged (a branch whose arms rejoin at once);
//!   2. sequence: `v -> w` where `v` has no other successor and `w` no other
//!      predecessor merges `w` into `v`;
//!   3. a vertex with one predecessor and one successor is contracted into an
//!      arc (a statement inside a branch or loop body); with rule 1 this
//!      reduces if-then, if-then-else, case and while shapes.
//!
//! Every BT reduces to one vertex (value 1, the paper's CC column for BTs); a
//! state entered from several places, as in the fault-tolerant SELECTOR design,
//! does not reduce, and its FSM keeps a value above 1.

use btfsm_model::graph::PolicyGraph;
use btfsm_model::{Bt, BtNodeKind, Policy, PolicyBody, StateBody, StateMachine, Target, Trigger};
use std::collections::{BTreeSet, VecDeque};

/// McCabe's `a + s - n + 1` on a policy graph (sinks = vertices without
/// outgoing arcs).
pub fn cyclomatic(g: &PolicyGraph) -> i64 {
    g.arc_count() as i64 + g.sink_count() as i64 - g.vertex_count() as i64 + 1
}

/// A control-flow graph with one entry and one exit.
#[derive(Debug, Clone)]
pub struct ControlFlow {
    pub succ: Vec<Vec<usize>>,
    pub entry: usize,
    pub exit: usize,
}

impl ControlFlow {
    fn new() -> Self {
        ControlFlow {
            succ: vec![Vec::new()],
            entry: 0,
            exit: 0,
        }
    }

    fn vertex(&mut self) -> usize {
        self.succ.push(Vec::new());
        self.succ.len() - 1
    }

    fn arc(&mut self, a: usize, b: usize) {
        self.succ[a].push(b);
    }
}

/// The control flow of a policy (see the module doc).
pub fn control_flow(p: &Policy) -> ControlFlow {
    match &p.body {
        PolicyBody::Bt(bt) => bt_control_flow(bt),
        PolicyBody::Machine(m) => machine_control_flow(m),
    }
}

/// BT control flow: a leaf is one vertex; a control node or decorator has an IN
/// and an OUT vertex; each child's exit goes to its next sibling and/or to the
/// parent's OUT as the parent's type dictates.
fn bt_control_flow(bt: &Bt) -> ControlFlow {
    let mut cf = ControlFlow::new(); // vertex 0 = EXIT
    let n = bt.nodes.len();
    let mut entry = vec![0; n];
    let mut exit = vec![0; n];
    for i in 0..n {
        if bt.nodes[i].children.is_empty() {
            let v = cf.vertex();
            entry[i] = v;
            exit[i] = v;
        } else {
            entry[i] = cf.vertex();
            exit[i] = cf.vertex();
        }
    }
    for (i, node) in bt.nodes.iter().enumerate() {
        if node.children.is_empty() {
            continue;
        }
        cf.arc(entry[i], entry[node.children[0]]);
        for (k, &c) in node.children.iter().enumerate() {
            let next = node.children.get(k + 1).map(|&s| entry[s]);
            let out = exit[i];
            let from = exit[c];
            match node.kind {
                BtNodeKind::Sequence
                | BtNodeKind::SequenceMemory
                | BtNodeKind::Fallback
                | BtNodeKind::FallbackMemory
                | BtNodeKind::Parallel { .. }
                | BtNodeKind::Control => {
                    // One outcome continues to the next sibling, the others return.
                    cf.arc(from, next.unwrap_or(out));
                    cf.arc(from, out);
                }
                BtNodeKind::Repeat { .. } | BtNodeKind::Retry { .. } => {
                    cf.arc(from, entry[c]);
                    cf.arc(from, out);
                }
                _ => cf.arc(from, out),
            }
            if node.kind != BtNodeKind::Condition {
                cf.arc(from, out); // RUNNING
            }
        }
    }
    cf.entry = entry[bt.root];
    let root_exit = exit[bt.root];
    cf.arc(root_exit, 0);
    cf.arc(root_exit, 0);
    cf.arc(root_exit, 0);
    cf
}

/// FSM/HFSM control flow: a task or decision state is one vertex, a container
/// has IN (-> its initial state) and OUT; outcomes of the top level merge into
/// EXIT. A parallel state's IN reaches each of its regions, and each
/// compound region's OUT reaches the parallel state's OUT (the join).
///
/// A container's transition on one of its region's outcomes leaves from OUT:
/// the region has finished with that outcome (every BT converted to an HFSM
/// is built this way). Any other transition of a container — a guard, or an
/// event its region does not produce (SCXML's `userAbort` on a compound
/// state) — preempts whatever state inside is active, so it leaves from an
/// ANY vertex that every state directly inside reaches, and that the ANY
/// vertices of nested containers reach in turn: one vertex and one arc per
/// state, linear whatever the nesting.
fn machine_control_flow(m: &StateMachine) -> ControlFlow {
    let mut cf = ControlFlow::new();
    let n = m.states.len();
    let mut entry = vec![0; n];
    let mut exit = vec![0; n];
    for (i, s) in m.states.iter().enumerate() {
        if matches!(s.body, StateBody::Container(_)) {
            entry[i] = cf.vertex();
            exit[i] = cf.vertex();
        } else {
            let v = cf.vertex();
            entry[i] = v;
            exit[i] = v;
        }
    }
    let preempts = |i: usize, t: &btfsm_model::Transition| match (&m.states[i].body, &t.trigger) {
        (StateBody::Container(r), Trigger::Outcome(o)) => !r.outcomes.contains(o),
        (StateBody::Container(_), Trigger::Guard(_)) => true,
        _ => false,
    };
    // ANY vertices, for containers with preempting transitions and those
    // nested in one (parents first).
    let mut any: Vec<Option<usize>> = vec![None; n];
    for c in m.parents_first() {
        let own = m.states[c].transitions.iter().any(|t| preempts(c, t));
        let inherited = m.states[c].parent.is_some_and(|p| any[p].is_some());
        if matches!(m.states[c].body, StateBody::Container(_)) && (own || inherited) {
            let v = cf.vertex();
            any[c] = Some(v);
            if let Some(up) = m.states[c].parent.and_then(|p| any[p]) {
                cf.arc(v, up);
            }
        }
    }
    for (i, s) in m.states.iter().enumerate() {
        if let StateBody::Container(r) = &s.body {
            for c in r.entered(&m.states) {
                cf.arc(entry[i], entry[c]);
            }
        }
        // A compound region of a parallel state joins it when it completes
        // (the parallel state completes when all of its regions have).
        if let (Some(p), StateBody::Container(_)) = (s.parent, &s.body)
            && matches!(&m.states[p].body, StateBody::Container(r) if r.parallel)
        {
            cf.arc(exit[i], exit[p]);
        }
        if !matches!(s.body, StateBody::Container(_))
            && let Some(up) = s.parent.and_then(|p| any[p])
        {
            cf.arc(exit[i], up);
        }
        for t in &s.transitions {
            let to = match &t.target {
                Target::State(j) => entry[*j],
                Target::Outcome(_) => match s.parent {
                    Some(p) => exit[p],
                    None => 0,
                },
                Target::OuterOutcome { owner, .. } => match owner {
                    Some(p) => exit[*p],
                    None => 0,
                },
            };
            let from = match any[i] {
                Some(v) if preempts(i, t) => v,
                _ => exit[i],
            };
            cf.arc(from, to);
        }
    }
    cf.entry = m.top.initial_state().map_or(0, |s| entry[s]);
    cf
}

/// Essential complexity of a policy (see the module doc).
pub fn essential(p: &Policy) -> i64 {
    reduce(&control_flow(p)).cyclomatic()
}

/// What remains of a control-flow graph after collapsing every module.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Reduced {
    pub vertices: usize,
    pub arcs: usize,
    pub sinks: usize,
}

impl Reduced {
    pub fn cyclomatic(&self) -> i64 {
        self.arcs as i64 + self.sinks as i64 - self.vertices as i64 + 1
    }
}

/// Collapses structured primes (see the module doc) until none is left, with a
/// worklist; each step removes a vertex or an arc, so it ends after at most
/// `V + A` steps.
pub fn reduce(cf: &ControlFlow) -> Reduced {
    let n = cf.succ.len();
    let mut reach = vec![false; n];
    let mut stack = vec![cf.entry];
    while let Some(v) = stack.pop() {
        if !reach[v] {
            reach[v] = true;
            stack.extend(cf.succ[v].iter().copied());
        }
    }
    reach[cf.exit] = true;
    // Rule 1 throughout: arcs are sets and self-loops are never kept.
    let mut succ: Vec<BTreeSet<usize>> = vec![BTreeSet::new(); n];
    let mut pred: Vec<BTreeSet<usize>> = vec![BTreeSet::new(); n];
    for v in (0..n).filter(|&v| reach[v]) {
        for &w in &cf.succ[v] {
            if w != v {
                succ[v].insert(w);
                pred[w].insert(v);
            }
        }
    }
    let mut alive = reach.clone();
    let fixed = |v: usize| v == cf.entry || v == cf.exit;
    let mut queue: VecDeque<usize> = (0..n).filter(|&v| reach[v]).collect();
    let mut queued = reach.clone();
    let push = |q: &mut VecDeque<usize>, queued: &mut Vec<bool>, v: usize| {
        if !queued[v] {
            queued[v] = true;
            q.push_back(v);
        }
    };
    while let Some(v) = queue.pop_front() {
        queued[v] = false;
        if !alive[v] {
            continue;
        }
        // Rule 3: one predecessor, one successor -> an arc.
        if !fixed(v) && pred[v].len() == 1 && succ[v].len() == 1 {
            let h = *pred[v].iter().next().expect("one predecessor");
            let y = *succ[v].iter().next().expect("one successor");
            succ[h].remove(&v);
            pred[y].remove(&v);
            if h != y {
                succ[h].insert(y);
                pred[y].insert(h);
            }
            alive[v] = false;
            for u in [h, y] {
                push(&mut queue, &mut queued, u);
            }
            continue;
        }
        // Rule 2: v -> w, v's only successor, w's only predecessor.
        if succ[v].len() == 1 {
            let w = *succ[v].iter().next().expect("one successor");
            if !fixed(w) && pred[w].len() == 1 {
                succ[v].clear();
                let outs = std::mem::take(&mut succ[w]);
                for s in outs {
                    pred[s].remove(&w);
                    if s != v {
                        succ[v].insert(s);
                        pred[s].insert(v);
                    }
                    push(&mut queue, &mut queued, s);
                }
                pred[w].clear();
                alive[w] = false;
                push(&mut queue, &mut queued, v);
                for &p in &pred[v] {
                    push(&mut queue, &mut queued, p);
                }
            }
        }
    }
    let live: Vec<usize> = (0..n).filter(|&v| alive[v]).collect();
    Reduced {
        vertices: live.len(),
        arcs: live.iter().map(|&v| succ[v].len()).sum(),
        sinks: live.iter().filter(|&&v| succ[v].is_empty()).count(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cf(arcs: &[(usize, usize)], n: usize, entry: usize) -> ControlFlow {
        let mut succ = vec![Vec::new(); n];
        for &(a, b) in arcs {
            succ[a].push(b);
        }
        ControlFlow {
            succ,
            entry,
            exit: 0,
        }
    }

    #[test]
    fn a_chain_reduces_to_one_module() {
        // 1 -> 2 -> 3 -> EXIT
        let r = reduce(&cf(&[(1, 2), (2, 3), (3, 0)], 4, 1));
        assert_eq!(r.cyclomatic(), 1);
        assert_eq!(r.vertices, 2);
    }

    #[test]
    fn structured_loop_and_branch_reduce() {
        // 1 -> {2,3} -> 4 ; 4 -> 1 (loop back) ; 4 -> EXIT
        let r = reduce(&cf(&[(1, 2), (1, 3), (2, 4), (3, 4), (4, 1), (4, 0)], 5, 1));
        assert_eq!(r.cyclomatic(), 1);
    }

    #[test]
    fn jump_into_a_loop_is_not_structured() {
        // 1 -> 2, 1 -> 3, 2 <-> 3, both may exit: a loop with two entries.
        let r = reduce(&cf(&[(1, 2), (1, 3), (2, 3), (3, 2), (2, 0), (3, 0)], 4, 1));
        assert!(r.cyclomatic() > 1, "{r:?}");
    }

    #[test]
    fn never_above_cyclomatic() {
        let c = cf(
            &[(1, 2), (1, 3), (2, 3), (3, 2), (2, 0), (3, 0), (3, 3)],
            4,
            1,
        );
        let direct = c.succ.iter().map(Vec::len).sum::<usize>() as i64 + 1 - 4 + 1;
        assert!(reduce(&c).cyclomatic() <= direct);
    }

    fn hfsm(text: &str) -> Policy {
        btfsm_format::toml::parse_str(
            "t.toml",
            text,
            std::path::Path::new(""),
            &Default::default(),
        )
        .expect("valid")
        .policy
    }

    /// A container `work` running a -> b -> `done`; b may also end it with
    /// `stopped`; `leave` takes `work` to `idle`, which goes back to `work`.
    fn with_container_transition(leave: &str) -> Policy {
        hfsm(&format!(
            r#"
kind = "hfsm"
initial = "work"
outcomes = ["SUCCESS"]
[states.work]
initial = "a"
outcomes = ["done", "stopped"]
{leave}
[states.work.states.a]
skill = "Move-To"
args = {{ target = "cube1" }}
on = {{ SUCCESS = "b", RUNNING = "a" }}
[states.work.states.b]
skill = "Pick"
args = {{ object = "cube1" }}
on = {{ SUCCESS = "done", FAILURE = "stopped", RUNNING = "b" }}
[states.idle]
skill = "Recharge"
on = {{ SUCCESS = "work" }}
"#
        ))
    }

    #[test]
    fn container_events_preempt_from_inside() {
        // On one of the region's outcomes the arc leaves once the region has
        // finished: a while loop around `work`, structured.
        let on_outcome = r#"on = { done = "SUCCESS", stopped = "idle" }"#;
        assert_eq!(essential(&with_container_transition(on_outcome)), 1);
        // A guard (or an SCXML event the region never produces, such as
        // `userAbort` on a compound state) fires from `a` or `b`: the loop is
        // left from two places inside, not structured.
        let on_guard = r#"on = { done = "SUCCESS" }
guards = [{ unless = "Battery-Level", args = { min = 20 }, to = "idle" }]"#;
        assert!(essential(&with_container_transition(on_guard)) > 1);
    }
}
