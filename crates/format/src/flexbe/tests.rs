//! Unit tests of the FlexBE reader on small behaviors written here (the
//! real behaviors are in tests/fixtures/flexbe, checked by tests/cli).

use super::*;
use btfsm_model::{PolicyBody, StateBody, Target};

fn machine(text: &str) -> btfsm_model::StateMachine {
    match parse_str("t_sm.py", text, &Limits::default()) {
        Ok(l) => match l.policy.body {
            PolicyBody::Machine(m) => m,
            PolicyBody::Bt(_) => panic!("a FlexBE behavior is a machine"),
        },
        Err(d) => panic!("{d:?}"),
    }
}

fn errors(text: &str) -> Vec<String> {
    match parse_str("t_sm.py", text, &Limits::default()) {
        Ok(_) => panic!("expected errors"),
        Err(d) => d.into_iter().map(|d| d.message).collect(),
    }
}

const NESTED: &str = r#"
from flexbe_core import Behavior, Autonomy, OperatableStateMachine, ConcurrencyContainer
class TSM(Behavior):
    '''A test behavior.'''
    def __init__(self):
        super(TSM, self).__init__()
        self.name = 'T'

    def create(self):
        _state_machine = OperatableStateMachine(outcomes=['finished', 'failed'])
        _state_machine.userdata.x = 1
        _sm_inner_0 = OperatableStateMachine(outcomes=['done'])
        _sm_both_1 = ConcurrencyContainer(outcomes=['ok', 'bad'], conditions=[
            ('ok', [('A', 'done'), ('B', 'done')]),
            ('bad', [('A', 'failed')])])
        with _sm_inner_0:
            OperatableStateMachine.add('W', WaitState(wait_time=1),
                transitions={'done': 'done'}, autonomy={'done': Autonomy.Off})
        with _sm_both_1:
            OperatableStateMachine.add('A', WaitState(wait_time=1),
                transitions={'done': 'ok', 'failed': 'bad'},
                autonomy={'done': Autonomy.Off, 'failed': Autonomy.Off})
            OperatableStateMachine.add('B', WaitState(wait_time=2),
                transitions={'done': 'ok'}, autonomy={'done': Autonomy.Off})
        with _state_machine:
            OperatableStateMachine.add('Start', LogState(text="hi"),
                transitions={'done': 'Inner'}, autonomy={'done': Autonomy.High})
            OperatableStateMachine.add('Inner', _sm_inner_0,
                transitions={'done': 'Both'}, autonomy={'done': Autonomy.Inherit})
            OperatableStateMachine.add('Both', _sm_both_1,
                transitions={'ok': 'finished', 'bad': 'failed'},
                autonomy={'ok': Autonomy.Inherit, 'bad': Autonomy.Inherit})
        return _state_machine
"#;

/// Containers become HFSM containers, a ConcurrencyContainer a parallel
/// region; the first state added is the initial one; targets resolve to a
/// sibling state first, then to an outcome; autonomy is in the label.
#[test]
fn nested_and_concurrent_containers_are_an_hfsm() {
    let m = machine(NESTED);
    assert!(m.hierarchical);
    assert_eq!(m.top.outcomes, ["finished", "failed"]);
    let names: Vec<&str> = m.states.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(names, ["Start", "Inner", "Both", "W", "A", "B"]);
    assert_eq!(m.top.initial, Target::State(0));
    assert_eq!(m.states[0].label, "Start [done:High]");
    assert_eq!(m.states[0].transitions[0].target, Target::State(1));
    let StateBody::Container(both) = &m.states[2].body else {
        panic!("Both is a container")
    };
    assert!(both.parallel);
    assert_eq!(both.states, [4, 5]);
    assert_eq!(
        m.states[4].transitions[1].target,
        Target::Outcome("bad".into())
    );
    let StateBody::Container(inner) = &m.states[1].body else {
        panic!("Inner is a container")
    };
    assert!(!inner.parallel);
    assert_eq!(m.states[3].parent, Some(1));
}

#[test]
fn unknown_targets_and_duplicates_are_errors() {
    let bad = NESTED.replace(
        "transitions={'done': 'Inner'}",
        "transitions={'done': 'Nowhere'}",
    );
    let e = errors(&bad);
    assert!(
        e[0].contains("transition target `Nowhere` is neither a state"),
        "{e:?}"
    );
    let dup = NESTED.replace("add('B',", "add('A',");
    assert!(errors(&dup)[0].contains("state `A` is added twice"));
    let twice = NESTED.replace("add('Both', _sm_both_1", "add('Both', _sm_inner_0");
    assert!(
        errors(&twice)
            .iter()
            .any(|m| m.contains("added a second time"))
    );
}

#[test]
fn unsupported_constructs_are_named_with_what_is_valid() {
    let e = parse_str(
        "t_sm.py",
        &NESTED.replace(
            "        with _sm_inner_0:\n",
            "        with _sm_inner_0:\n            x = 3\n",
        ),
        &Limits::default(),
    )
    .unwrap_err();
    assert_eq!(e[0].message, "unsupported construct inside a `with` block");
    assert!(e[0].hint.as_deref().unwrap().starts_with("valid: "));
    let (line, _) = e[0]
        .file
        .as_ref()
        .unwrap()
        .line_col(e[0].span.clone().unwrap().start);
    assert_eq!(line, 17);
    let e = errors(&NESTED.replace("transitions={'done': 'Both'}", "transitions=T"));
    assert_eq!(
        e[0],
        "unsupported construct as `transitions` (not a dict literal)"
    );
    let e = errors("class X(object):\n    pass\n");
    assert!(e[0].starts_with("no FlexBE behavior here"));
    let e = errors("print 'python 2'\n");
    assert!(e[0].starts_with("not valid Python 3"), "{e:?}");
}

/// Nesting is refused before parsing, so that no syntax tree is deep:
/// brackets, operator chains, blocks and f-strings.
#[test]
fn deep_nesting_is_refused_before_parsing() {
    for text in [
        format!("x = {}1{}\n", "(".repeat(100_000), ")".repeat(100_000)),
        format!("x = 1{}\n", " + 1".repeat(100_000)),
        format!("x = {}1\n", "-".repeat(100_000)),
        format!("x = a{}\n", ".b".repeat(100_000)),
        format!("x = f'{{{}}}'\n", "1+".repeat(50_000) + "1"),
        (0..300)
            .map(|i| format!("{}if x:\n", " ".repeat(i)))
            .collect::<String>()
            + &" ".repeat(300)
            + "pass\n",
    ] {
        let e = errors(&text);
        assert!(e[0].contains("nests more than 200 levels"), "{e:?}");
    }
    // A long flat list is not deep.
    let flat = format!("x = [{}]\n", "(1, 2), ".repeat(50_000));
    assert!(errors(&flat)[0].starts_with("no FlexBE behavior here"));
}

#[test]
fn detection_needs_a_behavior_class_and_a_state_machine() {
    assert!(looks_like_flexbe(Path::new("a/x_sm.py"), NESTED));
    assert!(!looks_like_flexbe(Path::new("a/x_sm.txt"), NESTED));
    assert!(!looks_like_flexbe(
        Path::new("a/setup.py"),
        "from setuptools import setup\n"
    ));
}
