//! Tests of the GED engine: against the brute-force oracle (`brute.rs`) on
//! random small multigraphs with self-loops and parallel arcs, property tests
//! (symmetry, isomorphism invariance, certified bounds, triangle inequality),
//! the paper's pairs (SPEC §4 structures, SPEC §5 values) built directly as
//! graphs, and budget behaviour on large random graphs.

use std::time::Duration;

use proptest::prelude::*;

use super::brute::brute_ged;
use super::*;
use btfsm_model::graph::VertexType as T;

// ---------------------------------------------------------------- helpers

/// A tiny xorshift64* generator, for reproducible random instances.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: u64) -> u64 {
        if n == 0 { 0 } else { self.next() % n }
    }
}

fn keys(n: usize, prefix: &str) -> Vec<String> {
    (0..n).map(|i| format!("{prefix}{i}")).collect()
}

fn random_graph(rng: &mut Rng, n: usize, max_arcs: usize, n_labels: u64, prefix: &str) -> GedGraph {
    let labels = (0..n).map(|_| rng.below(n_labels) as u32).collect();
    let m = if n == 0 {
        0
    } else {
        rng.below(max_arcs as u64 + 1) as usize
    };
    let arcs: Vec<(usize, usize)> = (0..m)
        .map(|_| (rng.below(n as u64) as usize, rng.below(n as u64) as usize))
        .collect();
    GedGraph::new(labels, keys(n, prefix), arcs).expect("valid")
}

fn opts() -> GedOptions {
    GedOptions {
        timeout: Duration::from_secs(30),
        work: u64::MAX,
    }
}

/// Checks everything a result must satisfy, then returns it.
fn check(a: &GedGraph, b: &GedGraph, mode: GedMode) -> GedResult {
    let r = ged_graphs(a, b, mode, &opts());
    assert!(r.lower_bound <= r.upper_bound);
    assert_eq!(r.ged, r.upper_bound);
    assert_eq!(r.exact, r.lower_bound == r.upper_bound);
    assert_eq!(r.edit_script.cost(), r.ged, "script cost = ged");
    let s = &r.edit_script;
    assert_eq!(s.vertices_kept.len() + s.vertices_removed.len(), a.n());
    assert_eq!(s.vertices_kept.len() + s.vertices_added.len(), b.n());
    let sum = |l: &[(String, String, u32)]| l.iter().map(|t| u64::from(t.2)).sum::<u64>();
    assert_eq!(sum(&s.arcs_kept) + sum(&s.arcs_removed), a.arc_count());
    assert_eq!(sum(&s.arcs_kept) + sum(&s.arcs_added), b.arc_count());
    if mode == GedMode::Labeled {
        let la: std::collections::HashMap<&str, u32> = a
            .keys()
            .iter()
            .map(String::as_str)
            .zip(a.labels().iter().copied())
            .collect();
        let lb: std::collections::HashMap<&str, u32> = b
            .keys()
            .iter()
            .map(String::as_str)
            .zip(b.labels().iter().copied())
            .collect();
        for (x, y) in &s.vertices_kept {
            assert_eq!(la.get(x.as_str()), lb.get(y.as_str()), "labels kept");
        }
    }
    r
}

fn exact(a: &GedGraph, b: &GedGraph, mode: GedMode) -> u64 {
    let r = check(a, b, mode);
    assert!(r.exact, "expected an exact result, got {r:?}");
    r.ged
}

fn permuted(g: &GedGraph, rng: &mut Rng) -> GedGraph {
    let n = g.n();
    let mut perm: Vec<usize> = (0..n).collect();
    for i in (1..n).rev() {
        let j = rng.below(i as u64 + 1) as usize;
        perm.swap(i, j);
    }
    let mut labels = vec![0; n];
    let mut ks = vec![String::new(); n];
    for u in 0..n {
        labels[perm[u]] = g.labels()[u];
        ks[perm[u]] = g.keys()[u].clone();
    }
    let mut arcs = Vec::new();
    for &(t, h, m) in g.arcs() {
        for _ in 0..m {
            arcs.push((perm[t as usize], perm[h as usize]));
        }
    }
    GedGraph::new(labels, ks, arcs).expect("valid")
}

// ------------------------------------------------------- oracle comparison

#[test]
fn matches_brute_force_on_random_multigraphs() {
    let mut rng = Rng(0x5EED_0001_D00D_F00D);
    let mut pairs = 0;
    for i in 0..600 {
        let max_n = if i % 10 == 0 { 7 } else { 6 };
        let n1 = rng.below(max_n + 1) as usize;
        let n2 = rng.below(max_n + 1) as usize;
        let dense = 1 + rng.below(3) as usize;
        let a = random_graph(&mut rng, n1, dense * n1 + 1, 3, "a");
        let b = random_graph(&mut rng, n2, dense * n2 + 1, 3, "b");
        for mode in [GedMode::Structural, GedMode::Labeled] {
            let want = brute_ged(&a, &b, mode == GedMode::Labeled);
            let got = exact(&a, &b, mode);
            assert_eq!(got, want, "pair {i} {mode:?}: {a:?} vs {b:?}");
        }
        pairs += 1;
    }
    assert_eq!(pairs, 600);
}

#[test]
fn empty_and_trivial_graphs() {
    let e = GedGraph::new(vec![], vec![], []).expect("valid");
    let one_loop = GedGraph::new(vec![0], keys(1, "x"), [(0, 0), (0, 0)]).expect("valid");
    for mode in [GedMode::Structural, GedMode::Labeled, GedMode::Named] {
        assert_eq!(exact(&e, &e, mode), 0);
        assert_eq!(exact(&e, &one_loop, mode), 3);
        assert_eq!(exact(&one_loop, &e, mode), 3);
    }
}

#[test]
fn self_loop_is_not_a_plain_arc() {
    // networkx issues #5400/#8188: these come out at distance 0 there.
    let a = GedGraph::new(vec![0, 0], keys(2, "a"), [(0, 0)]).expect("valid");
    let b = GedGraph::new(vec![0, 0], keys(2, "b"), [(0, 1)]).expect("valid");
    assert_eq!(exact(&a, &b, GedMode::Structural), 2);
}

// ------------------------------------------------------------ properties

fn arb_graph(max_n: usize, labels: u32) -> impl Strategy<Value = GedGraph> {
    (0..=max_n).prop_flat_map(move |n| {
        let arcs = if n == 0 {
            Just(Vec::new()).boxed()
        } else {
            proptest::collection::vec((0..n, 0..n), 0..=(2 * n + 2)).boxed()
        };
        (proptest::collection::vec(0..labels, n), arcs)
            .prop_map(move |(l, arcs)| GedGraph::new(l, keys(n, "v"), arcs).expect("valid"))
    })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    #[test]
    fn symmetric(a in arb_graph(6, 2), b in arb_graph(6, 2)) {
        for mode in [GedMode::Structural, GedMode::Labeled, GedMode::Named] {
            let ab = check(&a, &b, mode);
            let ba = check(&b, &a, mode);
            prop_assert!(ab.exact && ba.exact);
            prop_assert_eq!(ab.ged, ba.ged);
        }
    }

    #[test]
    fn zero_on_isomorphic_copies(a in arb_graph(7, 3), seed in any::<u64>()) {
        let b = permuted(&a, &mut Rng(seed | 1));
        for mode in [GedMode::Structural, GedMode::Labeled, GedMode::Named] {
            prop_assert_eq!(exact(&a, &b, mode), 0);
        }
    }

    #[test]
    fn certified_and_equal_to_oracle(a in arb_graph(5, 2), b in arb_graph(5, 2)) {
        for (mode, labeled) in [(GedMode::Structural, false), (GedMode::Labeled, true)] {
            let r = check(&a, &b, mode);
            let truth = brute_ged(&a, &b, labeled);
            prop_assert!(r.lower_bound <= truth && truth <= r.upper_bound);
            prop_assert!(r.exact);
        }
    }

    #[test]
    fn triangle_inequality(a in arb_graph(5, 2), b in arb_graph(5, 2), c in arb_graph(5, 2)) {
        for mode in [GedMode::Structural, GedMode::Labeled] {
            let ab = exact(&a, &b, mode);
            let bc = exact(&b, &c, mode);
            let ac = exact(&a, &c, mode);
            prop_assert!(ac <= ab + bc);
        }
    }
}

// ------------------------------------------------- the paper's structures

/// Builds a keyed, typed graph vertex by vertex.
#[derive(Default)]
struct Builder {
    labels: Vec<u32>,
    keys: Vec<String>,
    arcs: Vec<(usize, usize)>,
}

impl Builder {
    fn v(&mut self, t: T, key: &str) -> usize {
        self.labels.push(t as u32);
        self.keys.push(key.to_string());
        self.labels.len() - 1
    }
    fn arc(&mut self, u: usize, v: usize) {
        self.arcs.push((u, v));
    }
    fn find(&self, key: &str) -> usize {
        self.keys.iter().position(|k| k == key).expect("known key")
    }
    fn build(self) -> GedGraph {
        GedGraph::new(self.labels, self.keys, self.arcs).expect("valid")
    }
}

/// A BT node: control nodes carry an explicit id, leaves a display name.
#[derive(Clone)]
enum Bt {
    Seq(String, Vec<Bt>),
    Fb(String, Vec<Bt>),
    SeqMem(String, Vec<Bt>),
    Act(String),
    Cond(String),
}

fn seq(id: &str, c: Vec<Bt>) -> Bt {
    Bt::Seq(id.into(), c)
}
fn fb(id: &str, c: Vec<Bt>) -> Bt {
    Bt::Fb(id.into(), c)
}
fn act(name: &str) -> Bt {
    Bt::Act(name.into())
}
fn cond(name: &str) -> Bt {
    Bt::Cond(name.into())
}

fn moma_ext(i: u32, tuck: bool, safe: bool) -> Bt {
    let p = format!("m{i}");
    let mut reach = vec![
        cond(&format!("{p}/Robot-At cube{i}?")),
        act(&format!("{p}/Move-To cube{i}!")),
    ];
    if safe {
        reach.push(act(&format!("{p}/Safe-Move-To cube{i}!")));
    }
    let mut place = vec![fb(
        &format!("{p}.hand"),
        vec![
            cond(&format!("{p}/Cube{i} in Hand?")),
            seq(
                &format!("{p}.pick"),
                vec![
                    fb(&format!("{p}.reach"), reach),
                    act(&format!("{p}/Pick cube{i}!")),
                ],
            ),
        ],
    )];
    if tuck {
        place.push(fb(
            &format!("{p}.tuck"),
            vec![
                cond(&format!("{p}/Arm tucked?")),
                act(&format!("{p}/Tuck arm!")),
            ],
        ));
    }
    place.push(fb(
        &format!("{p}.deliv"),
        vec![
            cond(&format!("{p}/Robot-At delivery?")),
            act(&format!("{p}/Move-To delivery!")),
        ],
    ));
    place.push(act(&format!("{p}/Place cube{i}!")));
    fb(
        &p,
        vec![
            cond(&format!("{p}/Cube{i} in delivery?")),
            seq(&format!("{p}.place"), place),
        ],
    )
}

fn moma(i: u32) -> Bt {
    moma_ext(i, false, false)
}
fn recharge() -> Bt {
    fb("recharge", vec![cond("Battery > 20%?"), act("Recharge!")])
}
fn dock() -> Bt {
    fb("dock", vec![cond("Robot-At inspection?"), act("Dock!")])
}
fn search() -> Bt {
    fb("search", vec![cond("Cubes found?"), act("Search cubes!")])
}

fn bt_vertex(b: &mut Builder, t: &Bt) -> (usize, Vec<Bt>) {
    match t {
        Bt::Seq(id, c) => (b.v(T::Sequence, id), c.clone()),
        Bt::Fb(id, c) => (b.v(T::Fallback, id), c.clone()),
        Bt::SeqMem(id, c) => (b.v(T::SequenceMemory, id), c.clone()),
        Bt::Act(n) => (b.v(T::Action, n), Vec::new()),
        Bt::Cond(n) => (b.v(T::Condition, n), Vec::new()),
    }
}

/// SPEC §2 BT graph: one vertex per node, parent -> child arcs.
fn bt_graph(root: &Bt) -> GedGraph {
    let mut b = Builder::default();
    let mut stack = vec![(None::<usize>, root.clone())];
    while let Some((parent, t)) = stack.pop() {
        let (v, children) = bt_vertex(&mut b, &t);
        if let Some(p) = parent {
            b.arc(p, v);
        }
        for c in children.into_iter().rev() {
            stack.push((Some(v), c));
        }
    }
    b.build()
}

/// SPEC §2 HFSM graph of a BT converted as in the paper's sec. III: every
/// node a state (control nodes containers with an arc to their first child),
/// three top-level outcomes; a child's outcome either goes to its next
/// sibling (SUCCESS in a Sequence, FAILURE in a Fallback) or to the
/// container's outcome, i.e. an arc to the container's vertex. Actions have
/// SUCCESS/FAILURE/RUNNING, conditions SUCCESS/FAILURE, containers all three.
fn hfsm_graph(root: &Bt) -> GedGraph {
    fn outcomes(t: &Bt) -> &'static [u8] {
        match t {
            Bt::Cond(_) => b"SF",
            _ => b"SFR",
        }
    }
    fn add(b: &mut Builder, t: &Bt) -> usize {
        let (v, children) = bt_vertex(b, t);
        let ids: Vec<usize> = children.iter().map(|c| add(b, c)).collect();
        if let Some(&first) = ids.first() {
            b.arc(v, first);
        }
        let chain = match t {
            Bt::Seq(..) | Bt::SeqMem(..) => b'S',
            _ => b'F',
        };
        for (k, c) in children.iter().enumerate() {
            for &o in outcomes(c) {
                match ids.get(k + 1) {
                    Some(&next) if o == chain => b.arc(ids[k], next),
                    _ => b.arc(ids[k], v),
                }
            }
        }
        v
    }
    let mut b = Builder::default();
    let r = add(&mut b, root);
    let s = b.v(T::Outcome, "SUCCESS");
    let f = b.v(T::Outcome, "FAILURE");
    let run = b.v(T::Outcome, "RUNNING");
    for x in [s, f, run] {
        b.arc(r, x);
    }
    b.build()
}

/// The fault-tolerant FSM of SPEC §4, described by its action states in
/// sequence order plus modifications.
struct Fsm {
    b: Builder,
    sel: usize,
    success: usize,
}

impl Fsm {
    /// Fig. 4 style: each action RUNNING -> itself, FAILURE -> SELECTOR,
    /// SUCCESS -> next (last -> SUCCESS); SELECTOR -> itself, -> every action
    /// and -> SUCCESS.
    fn fault_tolerant(actions: &[&str]) -> Fsm {
        let mut b = Builder::default();
        let ids: Vec<usize> = actions.iter().map(|a| b.v(T::State, a)).collect();
        let sel = b.v(T::Decision, "SELECTOR");
        let success = b.v(T::Outcome, "SUCCESS");
        for (k, &a) in ids.iter().enumerate() {
            b.arc(a, a);
            b.arc(a, sel);
            b.arc(a, ids.get(k + 1).copied().unwrap_or(success));
        }
        b.arc(sel, sel);
        for &a in &ids {
            b.arc(sel, a);
        }
        b.arc(sel, success);
        Fsm { b, sel, success }
    }

    fn remove_arc(&mut self, u: usize, v: usize) {
        let i = self
            .b
            .arcs
            .iter()
            .position(|&x| x == (u, v))
            .expect("arc exists");
        self.b.arcs.remove(i);
    }

    /// Sequential state after `pred`, re-routing its SUCCESS arc.
    fn sequential(&mut self, pred: &str, name: &str) -> usize {
        let p = self.b.find(pred);
        let succ = self.successor(p);
        self.remove_arc(p, succ);
        let s = self.b.v(T::State, name);
        let sel = self.sel;
        self.b.arc(p, s);
        self.b.arc(s, s);
        self.b.arc(s, sel);
        self.b.arc(s, succ);
        self.b.arc(sel, s);
        s
    }

    /// The SUCCESS target of an action state: its arc that is neither the
    /// self-loop nor to SELECTOR (the first such).
    fn successor(&self, p: usize) -> usize {
        self.b
            .arcs
            .iter()
            .find(|&&(u, v)| u == p && v != p && v != self.sel)
            .map(|&(_, v)| v)
            .expect("has a successor")
    }

    /// Alternative state taking `pred`'s FAILURE arc.
    fn alternative(&mut self, pred: &str, name: &str) -> usize {
        let p = self.b.find(pred);
        let succ = self.successor(p);
        let sel = self.sel;
        self.remove_arc(p, sel);
        let s = self.b.v(T::State, name);
        self.b.arc(p, s);
        self.b.arc(s, succ);
        self.b.arc(s, sel);
        self.b.arc(s, s);
        s
    }

    /// Connected state: RUNNING -> itself, SUCCESS -> SELECTOR, SELECTOR -> it,
    /// an arc from every other action state.
    fn connected(&mut self, name: &str) -> usize {
        let s = self.b.v(T::State, name);
        let sel = self.sel;
        self.b.arc(s, s);
        self.b.arc(s, sel);
        self.b.arc(sel, s);
        for u in 0..self.b.labels.len() {
            if u != s && self.b.labels[u] == T::State as u32 {
                self.b.arc(u, s);
            }
        }
        s
    }

    fn build(self) -> GedGraph {
        let _ = self.success;
        self.b.build()
    }
}

const FIG2: [&str; 4] = ["MT cube2", "Pick cube2", "MT delivery", "Place cube2"];

fn fig2() -> GedGraph {
    let mut b = Builder::default();
    let ids: Vec<usize> = FIG2.iter().map(|a| b.v(T::State, a)).collect();
    let s = b.v(T::Outcome, "SUCCESS");
    for k in 0..ids.len() {
        b.arc(ids[k], ids.get(k + 1).copied().unwrap_or(s));
    }
    b.build()
}

fn fig10() -> GedGraph {
    let mut b = Builder::default();
    let ids: Vec<usize> = FIG2.iter().map(|a| b.v(T::State, a)).collect();
    let s = b.v(T::Outcome, "SUCCESS");
    let r = b.v(T::State, "Recharge");
    for k in 0..ids.len() {
        b.arc(ids[k], ids.get(k + 1).copied().unwrap_or(s));
        b.arc(ids[k], r);
        b.arc(r, ids[k]);
    }
    b.build()
}

fn fig4() -> Fsm {
    Fsm::fault_tolerant(&FIG2)
}
fn fig8a() -> GedGraph {
    let mut f = fig4();
    f.sequential("Pick cube2", "Tuck arm");
    f.build()
}
fn fig8b() -> GedGraph {
    let mut f = fig4();
    f.alternative("MT cube2", "Safe-Move-To cube2");
    f.build()
}
fn fig8c() -> GedGraph {
    let mut f = fig4();
    f.sequential("Place cube2", "Dock");
    f.build()
}
fn fig8d_fsm() -> Fsm {
    let mut f = fig4();
    f.connected("Recharge");
    f
}
fn fig8e() -> GedGraph {
    let mut f = fig4();
    f.sequential("Pick cube2", "Tuck arm");
    f.alternative("MT cube2", "Safe-Move-To cube2");
    f.sequential("Place cube2", "Dock");
    f.connected("Recharge");
    f.build()
}
fn fig9b() -> GedGraph {
    let mut f = fig4();
    let r = f.connected("Recharge");
    let sd = f.connected("Shut Down");
    let _ = r;
    // `connected` gave Shut Down an arc from Recharge; Recharge needs one
    // from Shut Down as well.
    let r = f.b.find("Recharge");
    f.b.arc(sd, r);
    f.build()
}
fn fig15_fsm() -> GedGraph {
    let mut f = fig8d_fsm();
    let d = f.sequential("Place cube2", "Dock");
    let r = f.b.find("Recharge");
    f.b.arc(d, r);
    f.build()
}
fn scal_fsm_actions() -> Vec<String> {
    let mut a = vec!["Search".to_string()];
    for i in 1..=5 {
        a.push(format!("MT cube{i}"));
        a.push(format!("Pick cube{i}"));
        a.push(format!("MT delivery{i}"));
        a.push(format!("Place cube{i}"));
    }
    a.push("Dock".into());
    a
}
fn scal_fsm() -> Fsm {
    let acts = scal_fsm_actions();
    let refs: Vec<&str> = acts.iter().map(String::as_str).collect();
    Fsm::fault_tolerant(&refs)
}
fn fig16b() -> GedGraph {
    let mut f = scal_fsm();
    f.connected("Recharge");
    f.build()
}

fn fig1() -> Bt {
    moma(2)
}
fn fig7a() -> Bt {
    moma_ext(2, true, false)
}
fn fig7b() -> Bt {
    moma_ext(2, false, true)
}
fn fig7c() -> Bt {
    seq("root", vec![moma(2), dock()])
}
fn fig7d() -> Bt {
    seq("root", vec![recharge(), moma(2)])
}
fn fig15_bt() -> Bt {
    seq("root", vec![recharge(), moma(2), dock()])
}
fn scal_bt() -> Bt {
    let mut c = vec![search()];
    c.extend((1..=5).map(moma));
    c.push(dock());
    seq("root", c)
}
fn fig16a() -> Bt {
    let mut c = vec![recharge(), search()];
    c.extend((1..=5).map(moma));
    c.push(dock());
    seq("root", c)
}

fn counts(g: &GedGraph) -> (usize, u64) {
    (g.n(), g.arc_count())
}

#[test]
fn paper_structures_have_the_spec_sizes() {
    assert_eq!(counts(&bt_graph(&fig1())), (14, 13));
    assert_eq!(counts(&bt_graph(&fig7a())), (17, 16));
    assert_eq!(counts(&bt_graph(&fig7b())), (15, 14));
    assert_eq!(counts(&bt_graph(&fig7c())), (18, 17));
    assert_eq!(counts(&bt_graph(&fig7d())), (18, 17));
    assert_eq!(counts(&bt_graph(&scal_bt())), (77, 76));
    assert_eq!(counts(&bt_graph(&fig16a())), (80, 79));
    assert_eq!(counts(&hfsm_graph(&fig1())), (17, 44));
    assert_eq!(counts(&fig2()), (5, 4));
    assert_eq!(counts(&fig4().build()), (6, 18));
    assert_eq!(counts(&fig8a()), (7, 22));
    assert_eq!(counts(&fig8b()), (7, 21));
    assert_eq!(counts(&fig8c()), (7, 22));
    assert_eq!(counts(&fig8d_fsm().build()), (7, 25));
    assert_eq!(counts(&fig8e()), (10, 39));
    assert_eq!(counts(&fig9b()), (8, 34));
    assert_eq!(counts(&fig10()), (6, 12));
    assert_eq!(counts(&fig15_fsm()), (8, 30));
    assert_eq!(counts(&scal_fsm().build()), (24, 90));
    assert_eq!(counts(&fig16b()), (25, 115));
}

#[test]
fn table_ii_fsm() {
    let f4 = fig4().build();
    let s = GedMode::Structural;
    let n = GedMode::Named;
    assert_eq!(exact(&f4, &fig8a(), s), 5);
    assert_eq!(exact(&f4, &fig8b(), s), 6); // NetworkX (and the paper): 4
    assert_eq!(exact(&f4, &fig8c(), s), 5);
    assert_eq!(exact(&f4, &fig8d_fsm().build(), s), 8);
    assert_eq!(exact(&f4, &fig8a(), n), 7);
    assert_eq!(exact(&f4, &fig8b(), n), 6);
    assert_eq!(exact(&f4, &fig8c(), n), 7);
    assert_eq!(exact(&f4, &fig8d_fsm().build(), n), 8);
    // Labeled lies between structural and named here.
    for (g, lo, hi) in [
        (fig8a(), 5, 7),
        (fig8b(), 6, 6),
        (fig8c(), 5, 7),
        (fig8d_fsm().build(), 8, 8),
    ] {
        let l = exact(&f4, &g, GedMode::Labeled);
        assert!(lo <= l && l <= hi);
        assert_eq!(l, brute_ged(&f4, &g, true));
    }
}

#[test]
fn table_ii_bt() {
    let f1 = bt_graph(&fig1());
    for (t, want) in [(fig7a(), 6), (fig7b(), 2), (fig7c(), 8), (fig7d(), 8)] {
        let g = bt_graph(&t);
        for mode in [GedMode::Structural, GedMode::Labeled, GedMode::Named] {
            assert_eq!(exact(&f1, &g, mode), want, "{mode:?}");
        }
    }
}

#[test]
fn table_iii_and_effort() {
    let s = GedMode::Structural;
    // BT: Fig. 1 -> 7d -> Fig. 15; scalability 77 -> 80.
    assert_eq!(exact(&bt_graph(&fig1()), &bt_graph(&fig7d()), s), 8);
    assert_eq!(exact(&bt_graph(&fig7d()), &bt_graph(&fig15_bt()), s), 6);
    assert_eq!(exact(&bt_graph(&scal_bt()), &bt_graph(&fig16a()), s), 6);
    assert_eq!(
        exact(&bt_graph(&scal_bt()), &bt_graph(&fig16a()), GedMode::Named),
        6
    );
    // FSM: Fig. 4 -> 8d -> Fig. 15; scalability 24 -> 25.
    let f8d = fig8d_fsm().build();
    assert_eq!(exact(&f8d, &fig15_fsm(), s), 6);
    assert_eq!(exact(&f8d, &fig15_fsm(), GedMode::Named), 8);
    assert_eq!(exact(&scal_fsm().build(), &fig16b(), s), 26);
    assert_eq!(exact(&scal_fsm().build(), &fig16b(), GedMode::Named), 26);
    // Effort: Fig. 2 -> 4 and Fig. 10 -> 11 (= 8d).
    assert_eq!(exact(&fig2(), &fig4().build(), GedMode::Named), 15);
    assert_eq!(exact(&fig2(), &fig4().build(), s), 15);
    assert_eq!(exact(&fig10(), &f8d, GedMode::Named), 22);
    assert_eq!(exact(&fig10(), &f8d, s), 14);
}

#[test]
fn larger_fsm_pairs_are_exact() {
    let f4 = fig4().build();
    for g in [fig8e(), fig9b(), fig15_fsm()] {
        for mode in [GedMode::Structural, GedMode::Labeled] {
            let r = check(&f4, &g, mode);
            assert!(r.exact, "{mode:?}: {r:?}");
            assert!(r.ged >= (g.n() - f4.n()) as u64 + g.arc_count() - f4.arc_count());
        }
    }
}

/// Table II's HFSM column on the HFSM graphs built by `hfsm_graph` (the paper
/// reports Eq. 3's 12 / 4 / 17 / 17 instead; SPEC §5 says why they differ).
#[test]
fn hfsm_pairs_are_exact() {
    let f1 = hfsm_graph(&fig1());
    let cases = [
        (fig7a(), [14, 14, 14]),
        (fig7b(), [6, 6, 6]),
        (fig7c(), [19, 23, 23]),
        (fig7d(), [21, 23, 23]),
    ];
    for (t, want) in cases {
        let g = hfsm_graph(&t);
        for (mode, w) in [GedMode::Structural, GedMode::Labeled, GedMode::Named]
            .into_iter()
            .zip(want)
        {
            assert_eq!(exact(&f1, &g, mode), w, "{mode:?}");
            assert_eq!(exact(&g, &f1, mode), w, "{mode:?} reversed");
        }
    }
}

// ---------------------------------------------------------------- budgets

#[test]
fn two_phase_structural_search_stays_certified() {
    // Tiny work budgets force the structural search through its
    // labeled-seeded second attempt.
    let mut rng = Rng(0xC0FFEE);
    for i in 0..40 {
        let a = random_graph(&mut rng, 5, 12, 3, "a");
        let b = random_graph(&mut rng, 6, 12, 3, "b");
        let o = GedOptions {
            timeout: Duration::from_secs(30),
            work: (3 + (i % 5) * 4) * 40,
        };
        let r = ged_graphs(&a, &b, GedMode::Structural, &o);
        let truth = brute_ged(&a, &b, false);
        assert!(
            r.lower_bound <= truth && truth <= r.upper_bound,
            "{r:?} vs {truth}"
        );
        assert_eq!(r.edit_script.cost(), r.upper_bound);
        // The labeled optimum is a structural upper bound.
        assert!(r.upper_bound <= brute_ged(&a, &b, true).max(truth));
    }
}

/// Point 4 of issue 15: the work budget decides. The same hard pair under
/// a small work budget gives the same inexact interval (stopped by work)
/// with a 2 s cap and with a 10-minute one, and twice in a row.
#[test]
fn work_budget_decides_not_the_clock() {
    let mut rng = Rng(0xD37E_0015);
    let mut inexact = 0;
    for i in 0..6 {
        let a = random_graph(&mut rng, 11, 40, 1, "a");
        let b = random_graph(&mut rng, 12, 44, 1, "b");
        let run = |secs: u64| {
            let o = GedOptions {
                timeout: Duration::from_secs(secs),
                work: 20_000,
            };
            let r = ged_graphs(&a, &b, GedMode::Structural, &o);
            (r.ged, r.exact, r.lower_bound, r.upper_bound, r.stopped_by)
        };
        let first = run(2);
        assert_eq!(first, run(600), "pair {i}");
        assert_eq!(first, run(2), "pair {i}");
        if !first.1 {
            assert_eq!(first.4, Some(StopReason::Work));
            inexact += 1;
        } else {
            assert_eq!(first.4, None);
        }
    }
    assert!(
        inexact > 0,
        "the budget is small enough to stop some searches"
    );
}

#[test]
fn orientation_round_trips_mappings() {
    let mut rng = Rng(77);
    for _ in 0..50 {
        let n1 = rng.below(7) as usize;
        let n2 = rng.below(7) as usize;
        let a = random_graph(&mut rng, n1, 10, 2, "a");
        let b = random_graph(&mut rng, n2, 10, 2, "b");
        let o = Oriented::new(&a, &b);
        let sigma = o.p.greedy();
        let m = o.to_ab(&sigma);
        let back = o.padded_from_ab(&m);
        assert_eq!(o.to_ab(&back), m);
        assert_eq!(o.p.cost(&back), o.p.cost(&sigma));
        assert_eq!(script::build(&a, &b, &m).cost(), o.p.cost(&sigma));
    }
}

#[test]
fn large_random_graphs_return_a_certified_interval_in_budget() {
    let mut rng = Rng(0xB16_6EA9);
    let a = random_graph(&mut rng, 200, 800, 4, "a");
    let b = random_graph(&mut rng, 200, 800, 4, "b");
    let o = GedOptions {
        timeout: Duration::from_millis(200),
        work: 50_000_000,
    };
    for mode in [GedMode::Structural, GedMode::Labeled] {
        let r = ged_graphs(&a, &b, mode, &o);
        assert!(r.lower_bound <= r.upper_bound);
        assert_eq!(r.edit_script.cost(), r.upper_bound);
        let count = a.arc_count().abs_diff(b.arc_count());
        assert!(r.lower_bound >= count);
    }
}

#[test]
fn work_budget_gives_a_certified_interval() {
    let mut rng = Rng(42);
    for _ in 0..20 {
        let a = random_graph(&mut rng, 6, 16, 1, "a");
        let b = random_graph(&mut rng, 6, 16, 1, "b");
        let o = GedOptions {
            timeout: Duration::from_secs(30),
            work: 100,
        };
        let r = ged_graphs(&a, &b, GedMode::Structural, &o);
        let truth = brute_ged(&a, &b, false);
        assert!(
            r.lower_bound <= truth && truth <= r.upper_bound,
            "{r:?} vs {truth}"
        );
    }
}

type Pair = (&'static str, GedGraph, GedGraph);

/// The SPEC §5 pairs plus the HFSM versions of the BT pairs.
fn paper_pairs() -> Vec<Pair> {
    let f4 = fig4().build();
    let f8d = fig8d_fsm().build();
    let bt = |t: Bt| bt_graph(&t);
    let hf = |t: Bt| hfsm_graph(&t);
    vec![
        ("fsm 4-8a", f4.clone(), fig8a()),
        ("fsm 4-8b", f4.clone(), fig8b()),
        ("fsm 4-8c", f4.clone(), fig8c()),
        ("fsm 4-8d", f4.clone(), f8d.clone()),
        ("fsm 4-8e", f4.clone(), fig8e()),
        ("fsm 4-9b", f4.clone(), fig9b()),
        ("fsm 8d-15", f8d.clone(), fig15_fsm()),
        ("fsm 2-4", fig2(), f4.clone()),
        ("fsm 10-11", fig10(), f8d.clone()),
        ("fsm scal-16b", scal_fsm().build(), fig16b()),
        ("bt 1-7a", bt(fig1()), bt(fig7a())),
        ("bt 1-7b", bt(fig1()), bt(fig7b())),
        ("bt 1-7c", bt(fig1()), bt(fig7c())),
        ("bt 1-7d", bt(fig1()), bt(fig7d())),
        ("bt 7d-15", bt(fig7d()), bt(fig15_bt())),
        ("bt scal-16a", bt(scal_bt()), bt(fig16a())),
        ("hfsm 1-7a", hf(fig1()), hf(fig7a())),
        ("hfsm 1-7b", hf(fig1()), hf(fig7b())),
        ("hfsm 1-7c", hf(fig1()), hf(fig7c())),
        ("hfsm 1-7d", hf(fig1()), hf(fig7d())),
        ("hfsm 7d-15", hf(fig7d()), hf(fig15_bt())),
        ("hfsm scal-16a", hf(scal_bt()), hf(fig16a())),
    ]
}

/// Arcs of `g` listed one per arc.
fn arc_list(g: &GedGraph) -> Vec<(usize, usize)> {
    let mut arcs = Vec::new();
    for &(t, h, m) in g.arcs() {
        for _ in 0..m {
            arcs.push((t as usize, h as usize));
        }
    }
    arcs
}

/// `g` with `k` arcs re-routed to random heads.
fn rerouted(g: &GedGraph, k: usize, rng: &mut Rng) -> GedGraph {
    let mut arcs = arc_list(g);
    for _ in 0..k {
        if arcs.is_empty() {
            break;
        }
        let i = rng.below(arcs.len() as u64) as usize;
        arcs[i].1 = rng.below(g.n() as u64) as usize;
    }
    GedGraph::new(g.labels().to_vec(), g.keys().to_vec(), arcs).expect("valid")
}

/// The larger paper FSM and HFSM with a few arcs re-routed.
fn stress_pairs() -> Vec<Pair> {
    let mut rng = Rng(7);
    let mut v = Vec::new();
    for k in [2usize, 4, 8] {
        v.push((
            "fsm 16b rerouted",
            scal_fsm().build(),
            rerouted(&fig16b(), k, &mut rng),
        ));
        let h = hfsm_graph(&fig16a());
        v.push((
            "hfsm 16a rerouted",
            hfsm_graph(&scal_bt()),
            rerouted(&h, k, &mut rng),
        ));
    }
    v
}

/// Random multigraphs, and random graphs against perturbed relabelled copies.
fn random_pairs() -> Vec<Pair> {
    let mut rng = Rng(99);
    let mut v = Vec::new();
    let sizes = [
        (8, 24, 0),
        (10, 30, 0),
        (12, 36, 0),
        (15, 45, 0),
        (25, 100, 6),
        (25, 100, 12),
        (25, 100, 20),
        (40, 160, 10),
    ];
    for &(n, m, k) in &sizes {
        for _ in 0..3 {
            let a = random_graph(&mut rng, n, m, 3, "a");
            if k == 0 {
                let b = random_graph(&mut rng, n, m, 3, "b");
                v.push(("random", a, b));
            } else {
                let b = rerouted(&a, k, &mut rng);
                v.push(("perturbed copy", a, permuted(&b, &mut rng)));
            }
        }
    }
    v
}

/// Random trees against relabelled copies with k subtrees moved and k
/// leaves added.
fn tree_pairs() -> Vec<Pair> {
    let mut rng = Rng(1234);
    let mut v = Vec::new();
    let tree = |parent: &[usize], labels: &[u32]| {
        GedGraph::new(
            labels.to_vec(),
            keys(parent.len(), "t"),
            (1..parent.len()).map(|i| (parent[i], i)),
        )
        .expect("valid")
    };
    for &(n, k) in &[
        (20usize, 2usize),
        (20, 4),
        (40, 2),
        (40, 4),
        (40, 8),
        (80, 4),
        (80, 8),
    ] {
        for _ in 0..3 {
            let mut parent: Vec<usize> = (0..n)
                .map(|i| {
                    if i == 0 {
                        0
                    } else {
                        rng.below(i as u64) as usize
                    }
                })
                .collect();
            let mut labels: Vec<u32> = (0..n).map(|_| rng.below(4) as u32).collect();
            let a = tree(&parent, &labels);
            for _ in 0..k {
                // Parents precede children, so the subtree of v is the
                // vertices after v whose parent is in it.
                let v = 1 + rng.below(n as u64 - 1) as usize;
                let mut inside = vec![false; parent.len()];
                inside[v] = true;
                for i in v + 1..parent.len() {
                    inside[i] = inside[parent[i]];
                }
                let outside: Vec<usize> = (0..v).filter(|&i| !inside[i]).collect();
                parent[v] = outside[rng.below(outside.len() as u64) as usize];
                parent.push(rng.below(parent.len() as u64) as usize);
                labels.push(rng.below(4) as u32);
            }
            v.push(("tree", a, permuted(&tree(&parent, &labels), &mut rng)));
        }
    }
    v
}

/// Timing report: `GED_REPORT=paper,stress,random,trees cargo test --release
/// --lib metrics::ged::tests::report -- --ignored --nocapture` (default
/// `paper,stress`).
#[test]
#[ignore]
#[allow(
    clippy::print_stdout,
    reason = "a measurement run by hand prints what it measured"
)]
fn report() {
    let which = std::env::var("GED_REPORT").unwrap_or_else(|_| "paper,stress".into());
    let mut pairs = Vec::new();
    for part in which.split(',') {
        pairs.extend(match part.trim() {
            "paper" => paper_pairs(),
            "stress" => stress_pairs(),
            "random" => random_pairs(),
            "trees" => tree_pairs(),
            _ => Vec::new(),
        });
    }
    let o = GedOptions::default();
    for (name, a, b) in &pairs {
        for mode in [GedMode::Structural, GedMode::Labeled, GedMode::Named] {
            let t = std::time::Instant::now();
            let r = ged_graphs(a, b, mode, &o);
            println!(
                "{name:18} {:10} {:>3}/{:<4} vs {:>3}/{:<4}: ged {:3} exact {:5} [{}, {}] {:8.2} ms",
                mode.as_str(),
                a.n(),
                a.arc_count(),
                b.n(),
                b.arc_count(),
                r.ged,
                r.exact,
                r.lower_bound,
                r.upper_bound,
                t.elapsed().as_secs_f64() * 1e3
            );
            if mode != GedMode::Named {
                let (ua, ub) = if mode == GedMode::Structural {
                    (a.unlabeled(), b.unlabeled())
                } else {
                    (a.clone(), b.clone())
                };
                let o2 = Oriented::new(&ua, &ub);
                let lim = search::Limits {
                    deadline: Deadline::after(o.timeout),
                    work: o.work,
                };
                let out = search::solve(&o2.p, &lim, None);
                println!("    count bound {}, {:?}", o2.p.count_bound(), out.stats);
            }
        }
    }
}

#[test]
#[ignore]
#[allow(
    clippy::print_stdout,
    reason = "a measurement run by hand prints what it measured"
)]
fn budget_overshoot_report() {
    let mut rng = Rng(0xB16_6EA9);
    for &(n, m) in &[(200usize, 800usize), (1000, 4000), (3000, 9000)] {
        let a = random_graph(&mut rng, n, m, 4, "a");
        let b = random_graph(&mut rng, n, m, 4, "b");
        for ms in [0u64, 200] {
            let o = GedOptions {
                timeout: Duration::from_millis(ms),
                work: u64::MAX,
            };
            for mode in [GedMode::Structural, GedMode::Labeled] {
                let t = std::time::Instant::now();
                let r = ged_graphs(&a, &b, mode, &o);
                println!(
                    "n {n} budget {ms} ms {mode:?}: [{}, {}] in {:.1} ms",
                    r.lower_bound,
                    r.upper_bound,
                    t.elapsed().as_secs_f64() * 1e3
                );
            }
        }
    }
}

#[test]
fn labels_separate_memory_sequences() {
    // Fig. 12's Sequence* against the same tree under a reactive Sequence.
    let leaves = || {
        ["MT cube2!", "Pick cube2!", "MT delivery!", "Place cube2!"]
            .into_iter()
            .map(act)
            .collect::<Vec<_>>()
    };
    let star = bt_graph(&Bt::SeqMem("root".into(), leaves()));
    let plain = bt_graph(&seq("root", leaves()));
    assert_eq!(counts(&star), (5, 4));
    assert_eq!(exact(&star, &plain, GedMode::Structural), 0);
    assert_eq!(exact(&star, &plain, GedMode::Named), 0);
    // The root cannot be kept: delete it with its 4 arcs, insert the new one.
    assert_eq!(exact(&star, &plain, GedMode::Labeled), 10);
    assert_eq!(brute_ged(&star, &plain, true), 10);
}

// ------------------------------------------------- integer-only pipeline

/// The integer pieces `compare` builds a mode from agree with the keyed
/// ones: `mapping_cost` is the cost of the edit script of any partial map
/// (out-of-range and repeated images included), the mapping by key ids is
/// the mapping by keys (repeated keys included), and `Shape` holds every
/// arc with its multiplicity.
#[test]
fn integer_pipeline_agrees_with_the_keyed_one() {
    let mut rng = Rng(0x5EED_B0D6E7);
    for round in 0..300 {
        let (na, nb) = (rng.below(9) as usize, rng.below(9) as usize);
        let a = random_graph(&mut rng, na, 14, 3, "a");
        let b = random_graph(&mut rng, nb, 14, 3, "b");
        let map: Vec<Option<usize>> = (0..na)
            .map(|_| (rng.below(3) > 0).then(|| rng.below(nb as u64 + 2) as usize))
            .collect();
        let want = script::build(&a, &b, &map).cost();
        assert_eq!(mapping_cost(&a, &b, &map), want, "round {round}: {map:?}");
        // Keys drawn from a small pool, so that they repeat and match.
        let ka: Vec<u32> = (0..na).map(|_| rng.below(5) as u32).collect();
        let kb: Vec<u32> = (0..nb).map(|_| rng.below(5) as u32).collect();
        let s = |k: &[u32]| k.iter().map(|i| format!("k{i}")).collect::<Vec<_>>();
        let (sa, sb) = (s(&ka), s(&kb));
        assert_eq!(
            named_mapping_of_ids(&ka, &kb),
            named_mapping_of_keys(sa.iter().map(String::as_str), sb.iter().map(String::as_str)),
            "round {round}: {ka:?} {kb:?}"
        );
        let mut naive: std::collections::BTreeMap<(u32, u32), u32> = Default::default();
        for &(t, h, m) in a.arcs() {
            *naive.entry((t, h)).or_default() += m;
        }
        for t in 0..na {
            for h in 0..na {
                let m = naive.get(&(t as u32, h as u32)).copied().unwrap_or(0);
                assert_eq!(a.mult(t, h), m);
            }
        }
        assert!(
            a.arcs()
                .windows(2)
                .all(|w| (w[0].0, w[0].1) < (w[1].0, w[1].1))
        );
    }
}

/// A deadline already past: no problem is built, the count bound is the
/// certified lower bound and the empty mapping's cost the upper one.
#[test]
fn search_with_a_spent_deadline_returns_the_count_bound() {
    let mut rng = Rng(77);
    for _ in 0..50 {
        let a = random_graph(&mut rng, 6, 10, 2, "a");
        let b = random_graph(&mut rng, 5, 10, 2, "b");
        for labeled in [false, true] {
            let m = search_mapping(&a, &b, labeled, Deadline::after(Duration::ZERO), u64::MAX);
            assert!(m.map.iter().all(Option::is_none));
            assert_eq!(m.upper_bound, mapping_cost(&a, &b, &m.map));
            assert!(m.lower_bound <= brute_ged(&a, &b, labeled));
            assert_eq!(m.lower_bound, count_bound(&a, &b, labeled));
        }
    }
}

/// Writes the GED graphs of policy files as JSON lines `{"file", "n",
/// "arcs": [[t, h], …] (one per arc), "labels"}` for an outside oracle:
/// `GED_DUMP=out.jsonl GED_DUMP_FILES=a.toml,b.toml cargo test -p btfsm-metrics
/// dump_policy_graphs -- --ignored` reads the files named in `GED_DUMP_FILES`
/// (comma-separated, relative to the repository);
/// `tests/differential/ged_highs.py --paper` runs HiGHS on them (`make
/// differential`, docs/performance.md).
#[test]
#[ignore]
fn dump_policy_graphs() {
    use std::io::Write;
    let (Ok(out), Ok(files)) = (std::env::var("GED_DUMP"), std::env::var("GED_DUMP_FILES")) else {
        return;
    };
    let mut w = std::fs::File::create(out).expect("writable");
    // Relative names are the repository's (`make differential` runs this
    // from the crate's folder).
    let root = std::path::Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."));
    for file in files.split(',') {
        let loaded = btfsm_format::load(&root.join(file), &btfsm_format::Limits::default())
            .unwrap_or_else(|_| panic!("{file} loads"));
        let g = GedGraph::from(&btfsm_model::graph::build::policy_graph(&loaded.policy));
        let mut arcs = Vec::new();
        for &(t, h, m) in g.arcs() {
            for _ in 0..m {
                arcs.push(format!("[{t},{h}]"));
            }
        }
        let labels: Vec<String> = g.labels().iter().map(|l| format!("\"{l}\"")).collect();
        writeln!(
            w,
            "{{\"file\":\"{file}\",\"n\":{},\"arcs\":[{}],\"labels\":[{}]}}",
            g.n(),
            arcs.join(","),
            labels.join(",")
        )
        .expect("written");
    }
}
