//! Unit tests of the SCXML reader (and its round trip through the writer).

use super::*;
use btfsm_model::{StateBody, StateMachine, Target, Trigger};
use std::path::Path;

fn machine(l: &Loaded) -> &StateMachine {
    match &l.policy.body {
        PolicyBody::Machine(m) => m,
        _ => panic!("not a machine"),
    }
}

#[test]
fn flat_machine_with_final_and_events() {
    let l = parse_str(
        "t.scxml",
        r#"<scxml xmlns="http://www.w3.org/2005/07/scxml" version="1.0" initial="a">
  <state id="a"><transition event="go" target="b"/><transition event="SUCCESS" target="done"/></state>
  <state id="b"><transition cond="x &gt; 1" target="a"/><transition event="e" cond="y" target="b"/></state>
  <final id="done"/>
</scxml>"#,
        &Limits::default(),
    )
    .unwrap();
    let m = machine(&l);
    assert!(!m.hierarchical);
    assert_eq!(m.top.outcomes, ["done"]);
    assert_eq!(m.states.len(), 2);
    let labels: Vec<String> = m.states[1]
        .transitions
        .iter()
        .map(|t| t.trigger.label())
        .collect();
    assert_eq!(labels, ["[x > 1]", "e [y]"]);
    assert_eq!(
        m.states[0].transitions[1].trigger,
        Trigger::Outcome("SUCCESS".into())
    );
    assert_eq!(
        m.states[0].transitions[1].target,
        Target::Outcome("done".into())
    );
}

#[test]
fn nested_states_history_and_foreign_namespaces() {
    let l = parse_str(
        "t.scxml",
        r#"<scxml xmlns="http://www.w3.org/2005/07/scxml" xmlns:qt="http://www.qt.io/2015/02/scxml-ext" version="1.0">
  <qt:editorinfo initialGeometry="1"/>
  <state id="p"><qt:editorinfo geometry="2"/>
<state id="c1"><transition event="t" target="c2"/></state>
<state id="c2"/>
<history id="h"/>
  </state>
  <state id="q"><transition event="back" target="h"/></state>
</scxml>"#,
        &Limits::default(),
    )
    .unwrap();
    let m = machine(&l);
    assert!(m.hierarchical);
    assert_eq!(m.states.len(), 5);
    assert_eq!(m.states[3].pseudo, Some(Pseudo::ShallowHistory));
    let StateBody::Container(r) = &m.states[0].body else {
        panic!()
    };
    assert_eq!(m.states[r.initial_state().unwrap()].name, "c1");
    assert_eq!(m.states[4].transitions[0].target, Target::State(3));
}

const SEED: &str = r#"<scxml xmlns="http://www.w3.org/2005/07/scxml" xmlns:qt="http://www.qt.io/2015/02/scxml-ext" version="1.0" initial="a">
  <state id="a" initial="a1"><qt:editorinfo g="1"/>
<state id="a1"><transition event="SUCCESS" target="a2"/></state>
<state id="a2"><transition event="x" cond="In(a1)" target="done_a"/></state>
<history id="h" type="deep"><transition target="a1"/></history>
<final id="done_a"/>
<transition event="done_a" target="b"/>
  </state>
  <state id="b"><transition event="back" target="h"/><transition event="end" target="end"/></state>
  <final id="end"/>
</scxml>"#;

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 300, ..Default::default() })]

    /// Mutated machines never panic: they read (and write and read back
    /// at the same size) or give positioned errors.
    #[test]
    fn mutated_machines_never_panic(
        cuts in proptest::collection::vec((0usize..2000, 0usize..8, "[<>/=\" a-z0-9]{0,3}"), 1..4)
    ) {
        let text = crate::xml::mutate(SEED, &cuts);
        match parse_str("t.scxml", &text, &Limits::default()) {
            Ok(l) => {
                let out = crate::scxml_write::write_policy(&l.policy).expect("a machine");
                let back = parse_str("back.scxml", &out, &Limits::default())
                    .unwrap_or_else(|e| panic!("{out}\n{e:?}"));
                proptest::prop_assert_eq!(machine(&back).states.len(), machine(&l).states.len());
            }
            Err(ds) => proptest::prop_assert!(ds.iter().any(|d| d.is_error() && d.location().is_some())),
        }
    }
}

#[test]
fn seed_reads_and_round_trips() {
    let l = parse_str("t.scxml", SEED, &Limits::default()).unwrap();
    let m = machine(&l);
    assert_eq!(m.top.outcomes, ["end"]);
    assert_eq!(m.states.len(), 5);
    let StateBody::Container(r) = &m.states[0].body else {
        panic!()
    };
    assert_eq!(r.outcomes, ["done_a"]);
    let out = crate::scxml_write::write_policy(&l.policy).unwrap();
    let back = parse_str("b.scxml", &out, &Limits::default()).unwrap();
    // Equal but for source positions.
    let strip = |m: &StateMachine| {
        let mut m = m.clone();
        for st in &mut m.states {
            st.span = None;
            for t in &mut st.transitions {
                t.span = None;
            }
        }
        m
    };
    assert_eq!(strip(machine(&back)), strip(m), "{out}");
}

#[test]
fn unreachable_state_is_a_warning() {
    let l = parse_str(
        "t.scxml",
        "<scxml xmlns=\"http://www.w3.org/2005/07/scxml\">\n  <state id=\"a\"/>\n  <state id=\"z\"/>\n</scxml>",
        &Limits::default(),
    )
    .unwrap();
    assert_eq!(l.warnings.len(), 1);
    assert!(l.warnings[0].message.contains("`z` is unreachable"));
    assert_eq!(l.warnings[0].location().unwrap().1, 3);
}

#[test]
fn commons_scxml_final_attribute_is_a_warning_and_an_ordinary_state() {
    // Apache Commons SCXML 0.x's `<state final="true">`: W3C SCXML reads an
    // ordinary state, and so does btfsm, with a warning naming the syntax.
    let l = parse_str(
        "t.scxml",
        "<scxml xmlns=\"http://www.w3.org/2005/07/scxml\" initial=\"a\">\n  <state id=\"a\"><transition event=\"e\" target=\"end\"/></state>\n  <state id=\"end\" final=\"true\"/>\n</scxml>",
        &Limits::default(),
    )
    .unwrap();
    assert_eq!(l.warnings.len(), 1, "{:?}", l.warnings);
    assert!(l.warnings[0].message.contains("Apache Commons SCXML 0.x"));
    assert_eq!(l.warnings[0].location().unwrap().1, 3);
    let btfsm_model::PolicyBody::Machine(m) = &l.policy.body else {
        panic!("a machine")
    };
    assert_eq!(m.states.len(), 2, "`end` is a state, not an outcome");
}

#[test]
fn a_transition_into_a_nested_state_reaches_its_containers() {
    // `a` jumps straight into `c1` inside `outer/inner`: both containers
    // are entered with it, so neither is unreachable; `lone` is.
    let l = parse_str(
        "t.scxml",
        r#"<scxml xmlns="http://www.w3.org/2005/07/scxml" initial="a">
  <state id="a"><transition event="go" target="c1"/></state>
  <state id="outer"><state id="inner"><state id="c0"/><state id="c1"/></state></state>
  <state id="lone"/>
</scxml>"#,
        &Limits::default(),
    )
    .unwrap();
    let w: Vec<_> = l.warnings.iter().map(|d| d.message.clone()).collect();
    assert_eq!(w.len(), 2, "{w:?}");
    assert!(w.iter().any(|m| m.contains("`c0` is unreachable")), "{w:?}");
    assert!(
        w.iter().any(|m| m.contains("`lone` is unreachable")),
        "{w:?}"
    );
}

#[test]
fn an_initial_state_deeper_in_the_region_enters_the_containers_on_the_way() {
    // SCXML 3.3: `initial` may name any descendant. The machine starts in
    // `outer`, entered at `inner`, entered at `deep`.
    let l = parse_str(
        "t.scxml",
        r#"<scxml xmlns="http://www.w3.org/2005/07/scxml" initial="deep">
  <state id="x"/>
  <state id="outer"><state id="o1"/><state id="inner"><state id="i1"/><state id="deep"/></state></state>
</scxml>"#,
        &Limits::default(),
    )
    .unwrap();
    let m = machine(&l);
    let name = |i: usize| m.states[i].name.as_str();
    let top = m.top.initial_state().unwrap();
    assert_eq!(name(top), "outer");
    let init = |i: usize| match &m.states[i].body {
        StateBody::Container(r) => r.initial_state().unwrap(),
        _ => panic!(),
    };
    assert_eq!(name(init(top)), "inner");
    assert_eq!(name(init(init(top))), "deep");
    // A container whose own initial says otherwise: the model cannot say both.
    let e = parse_str(
        "t.scxml",
        r#"<scxml xmlns="http://www.w3.org/2005/07/scxml" initial="deep">
  <state id="outer" initial="o1"><state id="o1"/><state id="deep"/></state>
</scxml>"#,
        &Limits::default(),
    )
    .unwrap_err();
    assert!(
        e[0].message
            .contains("whose own initial state is another one"),
        "{}",
        e[0]
    );
}

const HEAD: &str =
    "<scxml xmlns=\"http://www.w3.org/2005/07/scxml\" xmlns:btfsm=\"urn:btfsm\" version=\"1.0\">\n";

#[test]
fn long_events_conditions_and_names_are_errors_at_the_element() {
    let long = "e".repeat(5000);
    for (text, what) in [
        (
            format!("<state id=\"a\">\n<transition event=\"{long}\" target=\"a\"/></state>"),
            "value of `event`",
        ),
        (
            format!("<state id=\"a\">\n<transition cond=\"{long}\" target=\"a\"/></state>"),
            "value of `cond`",
        ),
        (
            format!("<state id=\"a\">\n<transition event=\"go\" target=\"{long}\"/></state>"),
            "value of `target`",
        ),
        (
            format!("<state id=\"a\">\n<state id=\"b\" btfsm:label=\"{long}\"/></state>"),
            "value of `label`",
        ),
    ] {
        let e = parse_str(
            "t.scxml",
            &format!("{HEAD}{text}\n</scxml>"),
            &Limits::default(),
        )
        .unwrap_err();
        assert!(
            e[0].message.starts_with(what)
                && e[0]
                    .message
                    .contains("is 5000 bytes long, more than the limit of 4096 bytes"),
            "{}",
            e[0].message
        );
        assert!(e[0].message.len() < 300, "{}", e[0].message);
        assert_eq!(e[0].location().unwrap().1, 3, "{}", e[0]);
    }
}

#[test]
fn depth_is_an_error_at_the_state() {
    let text = format!(
        "{HEAD}{}{}\n</scxml>",
        (0..8)
            .map(|i| format!("<state id=\"s{i}\">\n"))
            .collect::<String>(),
        "</state>".repeat(8)
    );
    let lim = |d| Limits {
        max_depth: d,
        ..Default::default()
    };
    assert!(parse_str("t.scxml", &text, &lim(7)).is_ok());
    let e = parse_str("t.scxml", &text, &lim(5)).unwrap_err();
    assert!(
        e[0].message == "state `s6` is nested 6 containers deep, deeper than the limit of 5 levels",
        "{}",
        e[0].message
    );
    assert_eq!(e[0].location().unwrap().1, 8);
}

/// A deep machine where no state is reachable: each warning names the
/// state by its id, not by the path of ids above it (which made the
/// messages quadratic in depth).
#[test]
fn unreachable_states_of_a_deep_machine_are_named_by_id() {
    let n = 50;
    let id = |i: usize| format!("{i:0>100}");
    let text = format!(
        "<scxml xmlns=\"http://www.w3.org/2005/07/scxml\" initial=\"z\"><state id=\"z\"/>{}{}</scxml>",
        (0..n)
            .map(|i| format!("<state id=\"{}\">", id(i)))
            .collect::<String>(),
        "</state>".repeat(n)
    );
    let l = parse_str("t.scxml", &text, &Limits::default()).unwrap();
    assert_eq!(l.warnings.len(), n);
    assert!(
        l.warnings.iter().all(|w| w.message.len() < 250),
        "{}",
        l.warnings[n - 1].message
    );
}

/// Skill bindings are checked as in TOML (found by fuzzing: an unknown
/// skill was read, and its TOML conversion did not read back).
#[test]
fn skill_bindings_are_checked_as_in_toml() {
    for (attrs, want) in [
        (r#"btfsm:skill="Tu%k-Arm""#, "unknown skill `Tu%k-Arm`"),
        (
            r#"btfsm:skill="Pick""#,
            "skill `Pick` needs argument `object`",
        ),
        (
            r#"btfsm:skill="Dock" btfsm:arg.x="1""#,
            "skill `Dock` has no argument `x`",
        ),
    ] {
        let text = format!("{HEAD}<state id=\"a\" {attrs}/>\n</scxml>");
        let e = parse_str("t.scxml", &text, &Limits::default()).unwrap_err();
        assert_eq!(e[0].message, want);
        assert_eq!(e[0].location().unwrap().1, 2);
    }
    let text = format!(
        "{HEAD}<state id=\"a\"><transition event=\"go\" target=\"a\" btfsm:terms=\"Dock()\"/></state>\n</scxml>"
    );
    let e = parse_str("t.scxml", &text, &Limits::default()).unwrap_err();
    assert_eq!(
        e[0].message,
        "`btfsm:terms`: `Dock` is not a condition skill"
    );
    let ok = format!(
        "{HEAD}<state id=\"a\" btfsm:skill=\"Pick\" btfsm:arg.object=\"cube1\"><transition event=\"go\" target=\"a\" btfsm:terms=\"not Found()\"/></state>\n</scxml>"
    );
    assert!(parse_str("t.scxml", &ok, &Limits::default()).is_ok());
}

/// The graph's (vertices, arcs) of a machine read from text.
fn counts(l: &Loaded) -> (usize, usize) {
    let g = btfsm_model::graph::policy_graph(&l.policy);
    (g.g.node_count(), g.g.edge_count())
}

/// A machine as a set of lines by state path (the TOML reader numbers
/// states breadth first, the SCXML reader in document order).
fn describe(m: &StateMachine) -> std::collections::BTreeSet<String> {
    let start = |t: &Target| match t {
        Target::State(j) => m.path(*j),
        Target::Outcome(o) => format!("outcome {o}"),
        Target::OuterOutcome { owner, outcome } => {
            format!("outcome {outcome} of {:?}", owner.map(|c| m.path(c)))
        }
    };
    let region = |r: &btfsm_model::Region| {
        format!(
            "initial {} parallel {} outcomes {:?}",
            start(&r.initial),
            r.parallel,
            r.outcomes
        )
    };
    let mut out: std::collections::BTreeSet<String> = (0..m.states.len())
        .map(|i| {
            let s = &m.states[i];
            let body = match &s.body {
                StateBody::Container(r) => region(r),
                other => format!("{other:?}"),
            };
            let trs: Vec<String> = s
                .transitions
                .iter()
                .map(|t| format!("{:?} -> {}", t.trigger, start(&t.target)))
                .collect();
            format!("{} {} {body} {:?} {trs:?}", m.path(i), s.label, s.pseudo)
        })
        .collect();
    out.insert(format!("top {} {}", region(&m.top), m.hierarchical));
    out
}

/// Reads, writes as SCXML and as TOML, and reads both back: the same
/// machine each time.
fn round_trips(l: &Loaded) {
    let out = crate::scxml_write::write_policy(&l.policy).unwrap();
    let back =
        parse_str("b.scxml", &out, &Limits::default()).unwrap_or_else(|e| panic!("{out}\n{e:?}"));
    assert_eq!(describe(machine(&back)), describe(machine(l)), "{out}");
    let toml = crate::toml_write::write_policy(&l.policy);
    let back = crate::toml::parse_str("b.toml", &toml, Path::new("."), &Limits::default())
        .unwrap_or_else(|e| panic!("{toml}\n{e:?}"));
    assert_eq!(describe(machine(&back)), describe(machine(l)), "{toml}");
}

/// `<parallel>`: a container whose states are its regions, all entered: one
/// initial arc per region; no unreachable warning for the regions' initial
/// states; a nested state's transition to a top-level final is an outcome
/// of the machine.
#[test]
fn parallel_states_are_containers_of_orthogonal_regions() {
    let l = parse_str("t.scxml", PARALLEL, &Limits::default()).unwrap();
    let m = machine(&l);
    assert!(m.hierarchical && m.has_parallel());
    let StateBody::Container(p) = &m.states[0].body else {
        panic!("p is a container")
    };
    assert!(p.parallel);
    let names = |v: Vec<usize>| {
        v.into_iter()
            .map(|i| m.states[i].name.clone())
            .collect::<Vec<_>>()
    };
    assert_eq!(names(p.entered(&m.states)), ["r1", "r2", "r3"]);
    assert!(p.outcomes.is_empty());
    // `done.state.p` is an event (a parallel state has no outcomes).
    assert!(matches!(
        m.states[0].transitions[0].trigger,
        Trigger::Guard(_)
    ));
    // b2 -> pass leaves r2 and p: the machine's outcome.
    let b2 = m.states.iter().position(|s| s.name == "b2").unwrap();
    assert_eq!(
        m.states[b2].transitions[0].target,
        Target::OuterOutcome {
            owner: None,
            outcome: "pass".into()
        }
    );
    // Only `q` is unreachable: a1, b2 and r3 are entered with p; b1 by
    // nothing (q is never entered).
    let w: Vec<&str> = l.warnings.iter().map(|d| d.message.as_str()).collect();
    assert_eq!(
        w,
        [
            "state `b1` is unreachable from the initial state",
            "state `q` is unreachable from the initial state"
        ]
    );
    // Vertices: p r1 a1 a2 r2 b1 b2 r3 q + pass = 10; arcs: the
    // transitions of a1, b2, p and q, 3 regions of p, r1 -> a1, r2 -> b2 = 9.
    assert_eq!(counts(&l), (10, 9));
    round_trips(&l);
}

/// Entering one region of a parallel state enters the others at their
/// initial states (W3C SCXML 3.13): no false unreachable warning.
#[test]
fn entering_one_region_enters_its_siblings() {
    let l = parse_str(
        "t.scxml",
        r#"<scxml xmlns="http://www.w3.org/2005/07/scxml" initial="a">
  <state id="a"><transition event="go" target="x2"/></state>
  <parallel id="p">
    <state id="rx"><state id="x1"/><state id="x2"/></state>
    <state id="ry"><state id="y1"/><state id="y2"/></state>
  </parallel>
</scxml>"#,
        &Limits::default(),
    )
    .unwrap();
    let w: Vec<&str> = l.warnings.iter().map(|d| d.message.as_str()).collect();
    // x1 is skipped by the jump to x2, y2 has no way in; ry and y1 are entered.
    assert_eq!(
        w,
        [
            "state `x1` is unreachable from the initial state",
            "state `y2` is unreachable from the initial state"
        ]
    );
}

/// An `initial` naming one state per region of a parallel state below the
/// region's child: the containers on the way start there; an `initial`
/// naming a `<parallel>` is an ordinary initial state.
#[test]
fn an_initial_naming_states_of_several_parallel_regions() {
    let l = parse_str(
        "t.scxml",
        r#"<scxml xmlns="http://www.w3.org/2005/07/scxml" initial="x2 y2">
  <state id="s">
    <parallel id="p">
      <state id="rx"><state id="x1"/><state id="x2"/></state>
      <state id="ry"><state id="y1"/><state id="y2"/></state>
    </parallel>
  </state>
</scxml>"#,
        &Limits::default(),
    )
    .unwrap();
    let m = machine(&l);
    let init = |n: &str| {
        let i = m.states.iter().position(|s| s.name == n).unwrap();
        match &m.states[i].body {
            StateBody::Container(r) => m.states[r.initial_state().unwrap()].name.clone(),
            _ => panic!(),
        }
    };
    assert_eq!(m.states[m.top.initial_state().unwrap()].name, "s");
    assert_eq!(
        (init("s"), init("rx"), init("ry")),
        ("p".into(), "x2".into(), "y2".into())
    );
    round_trips(&l);
    // Two states of one (non-parallel) region cannot both start.
    let e = parse_str(
        "t.scxml",
        r#"<scxml xmlns="http://www.w3.org/2005/07/scxml" initial="a b"><state id="a"/><state id="b"/></scxml>"#,
        &Limits::default(),
    )
    .unwrap_err();
    assert!(
        e[0].message.contains("names several states of this region"),
        "{}",
        e[0]
    );
    assert_eq!(e[0].location().unwrap().1, 1);
}

/// A machine that is only a `<final>`, and a state holding only a
/// `<final>`: their regions start in that outcome (no initial arc).
#[test]
fn regions_whose_initial_is_a_final_state() {
    let only = parse_str(
        "t.scxml",
        r#"<scxml xmlns="http://www.w3.org/2005/07/scxml" initial="done"><final id="done"/></scxml>"#,
        &Limits::default(),
    )
    .unwrap();
    let m = machine(&only);
    assert_eq!(m.top.initial, Target::Outcome("done".into()));
    assert!(m.states.is_empty());
    assert_eq!(counts(&only), (1, 0));
    round_trips(&only);
    let l = parse_str(
        "t.scxml",
        r#"<scxml xmlns="http://www.w3.org/2005/07/scxml">
  <state id="s0"><final id="s0final"/><transition event="done.state.s0" target="pass"/></state>
  <final id="pass"/>
</scxml>"#,
        &Limits::default(),
    )
    .unwrap();
    let m = machine(&l);
    let StateBody::Container(r) = &m.states[0].body else {
        panic!()
    };
    assert_eq!(r.initial, Target::Outcome("s0final".into()));
    // s0 and pass; the one transition (no initial arc).
    assert_eq!(counts(&l), (2, 1));
    round_trips(&l);
}

/// A transition to a final state of a region that does not enclose the
/// source is refused with its position; one to an enclosing container's
/// final is that container's outcome.
#[test]
fn finals_of_enclosing_regions_only() {
    let l = parse_str(
        "t.scxml",
        r#"<scxml xmlns="http://www.w3.org/2005/07/scxml">
  <state id="c"><state id="d"><state id="x"><transition event="e" target="cdone"/></state></state><final id="cdone"/></state>
</scxml>"#,
        &Limits::default(),
    )
    .unwrap();
    let m = machine(&l);
    assert_eq!(
        m.states[2].transitions[0].target,
        Target::OuterOutcome {
            owner: Some(0),
            outcome: "cdone".into()
        }
    );
    round_trips(&l);
    let e = parse_str(
        "t.scxml",
        "<scxml xmlns=\"http://www.w3.org/2005/07/scxml\">\n<state id=\"a\"><transition event=\"e\" target=\"bdone\"/></state>\n<state id=\"b\"><state id=\"b1\"/><final id=\"bdone\"/></state></scxml>",
        &Limits::default(),
    )
    .unwrap_err();
    assert!(
        e[0].message
            .contains("of a region that does not enclose it"),
        "{}",
        e[0]
    );
    assert_eq!(e[0].location().unwrap().1, 2);
}

/// A `<final>` directly in a `<parallel>` (not SCXML) is an error at it; an
/// empty `<parallel>` is a plain state.
#[test]
fn parallel_edge_cases() {
    let e = parse_str(
        "t.scxml",
        "<scxml xmlns=\"http://www.w3.org/2005/07/scxml\">\n  <parallel id=\"p\"><state id=\"r\"/>\n<final id=\"f\"/></parallel>\n</scxml>",
        &Limits::default(),
    )
    .unwrap_err();
    assert!(
        e[0].message.contains("directly inside `<parallel>`"),
        "{}",
        e[0]
    );
    assert_eq!(e[0].location().unwrap().1, 3);
    let l = parse_str(
        "t.scxml",
        "<scxml xmlns=\"http://www.w3.org/2005/07/scxml\">\n  <parallel id=\"p\"/>\n</scxml>",
        &Limits::default(),
    )
    .unwrap();
    assert!(matches!(machine(&l).states[0].body, StateBody::Task(None)));
}

const PARALLEL: &str =
    include_str!("../../../../tests/fixtures/valid/parallel-mutation-seed.scxml");

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 300, ..Default::default() })]

    /// Mutated parallel machines (regions, finals of enclosing regions,
    /// several initial states) read back through the SCXML writer as the same machine
    /// (`btfsm-fuzzing` runs them through everything downstream).
    #[test]
    fn mutated_parallel_machines_never_panic(
        cuts in proptest::collection::vec((0usize..900, 0usize..8, "[<>/=\" a-z0-9]{0,3}"), 1..4)
    ) {
        let text = crate::xml::mutate(PARALLEL, &cuts);
        if let Ok(l) = parse_str("t.scxml", &text, &Limits::default()) {
            let out = crate::scxml_write::write_policy(&l.policy).expect("a machine");
            let back = parse_str("back.scxml", &out, &Limits::default())
                .unwrap_or_else(|e| panic!("{out}\n{e:?}"));
            proptest::prop_assert_eq!(describe(machine(&back)), describe(machine(&l)));
        }
    }
}
