//! The fault-tolerant construction on machines with side states (issue
//! 29, point 8): the goal is the effect of the step whose `SUCCESS` ends
//! the task (the machine's outcome), never that of a state written after
//! the chain; a side Recharge is a recovery entered on its guard. One
//! reproduction and a property over random delivery tasks
//! ([`SideTask`]); `btfsm-sim` runs the same machines as a second oracle
//! (`btfsm_sim::fault_tolerant_tests`).

use crate::fault_tolerant::{DELIVERY, SideTask, fault_tolerant_policy};
use btfsm_model::{Guard, Policy, PolicyBody, StateMachine, Target, Trigger};
use proptest::prelude::*;

fn policy(text: &str) -> Policy {
    btfsm_format::toml::parse_str(
        "t.toml",
        text,
        std::path::Path::new("."),
        &btfsm_format::Limits::default(),
    )
    .unwrap_or_else(|d| panic!("{text}\n{d:?}"))
    .policy
}

fn machine(p: &Policy) -> &StateMachine {
    match &p.body {
        PolicyBody::Machine(m) => m,
        PolicyBody::Bt(_) => panic!("a machine"),
    }
}

/// The SELECTOR's guard to outcome `o`, if any.
fn guard_to<'m>(m: &'m StateMachine, o: &str) -> Option<&'m Guard> {
    let sel = m.states.iter().find(|s| s.name == "SELECTOR")?;
    sel.transitions
        .iter()
        .find_map(|t| match (&t.trigger, &t.target) {
            (Trigger::Guard(g), Target::Outcome(x)) if x == o => Some(g),
            _ => None,
        })
}

/// The guard's terms as the goal of a scenario writes them: `if = "P"`
/// and the arguments.
fn terms(g: &Guard) -> Vec<String> {
    g.all.iter().map(ToString::to_string).collect()
}

/// Issue 29's machine: Recharge entered on a guard by two states and
/// written last, Pick without a FAILURE arc. "Done" was "battery above
/// 20%" (the goal of Recharge, appended after the chain), so a failed
/// Pick ended in SUCCESS with the cube on the table.
#[test]
fn a_side_recharge_last_in_the_file_is_not_the_goal() {
    let task = SideTask {
        steps: 4,
        guarded: vec![true, false, true, false],
        fails_out: vec![false; 4],
        back_to: Some(0),
        recharge_at: 4,
    };
    let ft = fault_tolerant_policy(&policy(&task.toml())).expect("transform");
    let m = machine(&ft);
    let done = guard_to(m, "SUCCESS").expect("a done guard");
    assert_eq!(terms(done), ["Object-At(at=delivery, object=cube2)"]);
    let sel = m
        .states
        .iter()
        .find(|s| s.name == "SELECTOR")
        .expect("SELECTOR");
    // The recovery comes first, on the guard the states use to enter it.
    match (&sel.transitions[0].trigger, &sel.transitions[0].target) {
        (Trigger::Guard(g), Target::State(j)) => {
            assert_eq!(
                (g.label.as_str(), m.states[*j].name.as_str()),
                ("battery < 20%", "Recharge")
            );
        }
        other => panic!("{other:?}"),
    }
    // Recharge returns to the SELECTOR, which resumes the task.
    let r = m
        .states
        .iter()
        .find(|s| s.name == "Recharge")
        .expect("Recharge");
    assert!(
        r.transitions.iter().all(|t| !matches!(t.target, Target::State(j) if m.states[j].name != "Recharge" && m.states[j].name != "SELECTOR")),
        "{:?}",
        r.transitions
    );
}

fn side_task() -> impl Strategy<Value = SideTask> {
    (1usize..=4).prop_flat_map(|steps| {
        (
            proptest::collection::vec(any::<bool>(), steps)
                .prop_filter("Recharge is entered", |g| g.iter().any(|&x| x)),
            proptest::collection::vec(any::<bool>(), steps),
            proptest::option::of(0..steps),
            0..=steps,
        )
            .prop_map(move |(guarded, fails_out, back_to, recharge_at)| SideTask {
                steps,
                guarded,
                fails_out,
                back_to,
                recharge_at,
            })
    })
}

proptest! {
    /// Over random delivery tasks with a Recharge entered on a guard
    /// (from some states: a side state; from every one of three or more:
    /// a connected one), anywhere in the file: Recharge is never a step,
    /// the done guard is the effect of the task's last step, no guard to
    /// an outcome reads the battery, and Recharge goes back only to the
    /// SELECTOR.
    #[test]
    fn the_goal_is_the_last_steps_effect_whatever_the_side_states(task in side_task()) {
        let p = policy(&task.toml());
        let d = btfsm_metrics::effort::detect(machine(&p));
        let recharge = machine(&p).states.iter().position(|s| s.name == "Recharge").expect("Recharge");
        prop_assert!(!d.sequential.contains(&recharge));
        prop_assert!(d.side.contains(&recharge) || d.connected.contains(&recharge));
        prop_assert_eq!(d.chain.len(), task.steps);
        let ft = fault_tolerant_policy(&p).expect("transform");
        let m = machine(&ft);
        let done = guard_to(m, "SUCCESS").expect("a done guard");
        let want = DELIVERY[task.steps - 1].3;
        let got = terms(done);
        prop_assert_eq!(got.len(), 1);
        // `{ if = "Robot-At", args = { target = "cube2" } }` reads `Robot-At(target=cube2)`.
        let pred = want.split('"').nth(1).expect("predicate");
        prop_assert!(got[0].starts_with(&format!("{pred}(")), "{} vs {}", got[0], want);
        let sel = m.states.iter().find(|s| s.name == "SELECTOR").expect("SELECTOR");
        for t in &sel.transitions {
            if let (Trigger::Guard(g), Target::Outcome(_)) = (&t.trigger, &t.target) {
                prop_assert!(!g.label.contains("Battery"), "{}", g.label);
            }
        }
        let r = &m.states[recharge];
        for t in &r.transitions {
            if let Target::State(j) = t.target {
                prop_assert!(j == recharge || m.states[j].name == "SELECTOR", "{:?}", r.transitions);
            }
        }
    }
}
