//! The planner on the paper's domain: Fig. 1 from `policies/domains/moma.toml`,
//! Fig. 3 with `--no-reorder` and Place's preconditions swapped.

use super::*;
use btfsm_core::diagnostic::SourceFile;
use btfsm_model::PolicyBody;

const MOMA: &str = include_str!("../../../policies/domains/moma.toml");
const FIG01: &str = include_str!("../../../policies/paper/fig01-bt.toml");
const FIG03: &str = include_str!("../../../policies/paper/fig03-bt.toml");

fn domain(text: &str) -> Domain {
    load(&SourceFile::new("moma.toml", text)).unwrap_or_else(|e| panic!("{e:?}"))
}

fn policy(text: &str) -> btfsm_model::Bt {
    let l = btfsm_format::toml::parse_str(
        "fig.toml",
        text,
        std::path::Path::new("."),
        &Default::default(),
    )
    .unwrap_or_else(|e| panic!("{e:?}"));
    match l.policy.body {
        PolicyBody::Bt(b) => b,
        _ => panic!("not a BT"),
    }
}

/// Each node as (id, kind, skill call, children ids), in pre-order: what
/// "the same tree" means (display labels aside).
fn shape(b: &btfsm_model::Bt) -> Vec<String> {
    b.preorder()
        .into_iter()
        .map(|n| {
            let x = &b.nodes[n];
            let kids: Vec<&str> = x.children.iter().map(|&c| b.nodes[c].id.as_str()).collect();
            let call = x
                .skill
                .as_ref()
                .map(ToString::to_string)
                .unwrap_or_default();
            format!("{} {} {call} [{}]", x.id, x.kind.keyword(), kids.join(", "))
        })
        .collect()
}

#[test]
fn the_moma_domain_backchains_into_fig_1() {
    let p = plan_bt(&domain(MOMA), &Options::default()).unwrap();
    assert_eq!(shape(&p.bt), shape(&policy(FIG01)));
    // The order of Place's preconditions is already safe: no move.
    assert!(
        p.conflicts
            .iter()
            .all(|c| c.outcome == conflicts::Outcome::InOrder),
        "{:?}",
        p.conflicts
    );
}

#[test]
fn swapped_preconditions_are_reordered_or_give_fig_3_with_the_conflict() {
    let swapped = MOMA.replace(
        r#"pre = ["In-Hand(object)", "Robot-At(at)"]"#,
        r#"pre = ["Robot-At(at)", "In-Hand(object)"]"#,
    );
    assert_ne!(swapped, MOMA);
    let d = domain(&swapped);
    // Reordered: Fig. 1 again, the move reported.
    let p = plan_bt(&d, &Options::default()).unwrap();
    assert_eq!(shape(&p.bt), shape(&policy(FIG01)));
    let moved: Vec<String> = p
        .conflicts
        .iter()
        .filter(|c| c.outcome == conflicts::Outcome::Reordered)
        .map(ToString::to_string)
        .collect();
    assert_eq!(
        moved,
        ["`held` undoes Robot-At(delivery), which `reached-delivery` ensures: moved before it"]
    );
    // Not reordered: Fig. 3, and the conflict that makes it chatter.
    let opts = Options {
        reorder: false,
        ..Options::default()
    };
    let p = plan_bt(&d, &opts).unwrap();
    assert_eq!(shape(&p.bt), shape(&policy(FIG03)));
    assert!(
        p.conflicts
            .iter()
            .any(|c| c.outcome == conflicts::Outcome::Left
                && c.undone_by == "held"
                && c.fact == "Robot-At(delivery)")
    );
}

#[test]
fn domain_errors_are_reported_together_with_positions() {
    let bad = MOMA
        .replace(
            r#"pre = ["Robot-At(object)"]"#,
            r#"pre = ["Robot-Art(object)"]"#,
        )
        .replace(
            r#"add = ["Object-At(object, at)"]"#,
            r#"add = ["Object-At(object)"]"#,
        );
    let e = load(&SourceFile::new("moma.toml", bad)).unwrap_err();
    let msgs: Vec<&str> = e.iter().map(|d| d.message.as_str()).collect();
    assert_eq!(msgs.len(), 2, "{msgs:?}");
    assert!(msgs[0].contains("unknown predicate `Robot-Art`"));
    assert!(e[0].hint.as_deref().unwrap_or("").contains("Robot-At"));
    assert!(msgs[1].contains("`Object-At` takes 2 argument(s), found 1"));
    assert!(e.iter().all(|d| d.span.is_some()));
}

const FIG04: &str = include_str!("../../../policies/paper/fig04-fsm.toml");

/// Each state with its transitions (trigger, target), guards by their
/// terms: the machine's structure, labels aside.
fn machine_shape(m: &btfsm_model::StateMachine) -> Vec<String> {
    use btfsm_model::{Target, Trigger};
    let mut out: Vec<String> = m
        .states
        .iter()
        .map(|s| {
            let arcs: Vec<String> = s
                .transitions
                .iter()
                .map(|t| {
                    let trig = match &t.trigger {
                        Trigger::Outcome(o) => o.clone(),
                        Trigger::Guard(g) => g
                            .all
                            .iter()
                            .map(ToString::to_string)
                            .collect::<Vec<_>>()
                            .join(" & "),
                    };
                    let to = match &t.target {
                        Target::State(j) => m.states[*j].name.clone(),
                        Target::Outcome(o) | Target::OuterOutcome { outcome: o, .. } => o.clone(),
                    };
                    format!("{trig} -> {to}")
                })
                .collect();
            format!("{}: {}", s.name, arcs.join("; "))
        })
        .collect();
    out.sort();
    out.push(format!(
        "initial {}",
        m.states[m.top.initial_state().expect("a state")].name
    ));
    out
}

#[test]
fn the_moma_plan_gives_the_fault_tolerant_fsm_of_fig_4() {
    let d = domain(MOMA);
    let p = plan_bt(&d, &Options::default()).unwrap();
    let m = fsm::plan_fsm(&d, &p).unwrap();
    let l = btfsm_format::toml::parse_str(
        "fig04.toml",
        FIG04,
        std::path::Path::new("."),
        &Default::default(),
    )
    .unwrap();
    let PolicyBody::Machine(fig04) = &l.policy.body else {
        panic!("fsm")
    };
    assert_eq!(machine_shape(&m), machine_shape(fig04));
}

const KITTING: &str = include_str!("../../../tests/fixtures/domains/kitting.toml");

/// The planned FSM's chain is the BT's nominal execution with each step's
/// effects applied: the door unlocked for the bolt stays unlocked for the
/// nut, and a robot at the bench does not drive there again (before: three
/// `Move-To bench` and two `Unlock door` in a row of 13 steps).
#[test]
fn the_plan_chain_does_not_redo_what_holds() {
    let d = domain(KITTING);
    let p = plan_bt(&d, &Options::default()).unwrap();
    let m = fsm::plan_fsm(&d, &p).unwrap();
    let names: Vec<&str> = m.states.iter().map(|s| s.name.as_str()).collect();
    assert_eq!(
        names,
        [
            "Move-To bench",
            "Unlock door",
            "Enter shelf room",
            "Pick bolt",
            "Move-To bench (2)",
            "Place bolt in tray",
            "Enter shelf room (2)",
            "Pick nut",
            "Move-To bench (3)",
            "Place nut in tray",
            "SELECTOR",
        ]
    );
}

/// With `init` (or `--init`) the machine starts at the latest step whose
/// triangle-table kernel the initial facts satisfy, as its SELECTOR would
/// resume; without, at the first step (Fig. 4); at the SELECTOR when the
/// goal already holds.
#[test]
fn the_planned_fsm_starts_where_the_initial_facts_let_it() {
    let start = |init: &[&str]| {
        let mut d = domain(KITTING);
        let init: Vec<String> = init.iter().map(|s| s.to_string()).collect();
        d.set_init(&init).unwrap();
        let p = plan_bt(&d, &Options::default()).unwrap();
        let m = fsm::plan_fsm(&d, &p).unwrap();
        m.states[m.top.initial_state().unwrap()].name.clone()
    };
    assert_eq!(start(&[]), "Move-To bench");
    assert_eq!(start(&["Robot-At(bench)"]), "Unlock door");
    assert_eq!(start(&["Door-Unlocked", "Robot-At(shelf)"]), "Pick bolt");
    assert_eq!(
        start(&[
            "Door-Unlocked",
            "In-Tray(bolt)",
            "In-Hand(nut)",
            "Robot-At(bench)"
        ]),
        "Place nut in tray"
    );
    assert_eq!(start(&["In-Tray(bolt)", "In-Tray(nut)"]), "SELECTOR");
    let mut d = domain(KITTING);
    let e = d.set_init(&["In-Tray(screw)".into()]).unwrap_err();
    assert!(e[0].starts_with("--init `In-Tray(screw)`"), "{e:?}");
}

/// `init` in the goal's table reads as `--init` does.
#[test]
fn init_in_the_domain_sets_the_start() {
    let text = KITTING.replace(
        "facts = [\"In-Tray(bolt)\", \"In-Tray(nut)\"]",
        "facts = [\"In-Tray(bolt)\", \"In-Tray(nut)\"]\ninit = [\"Robot-At(bench)\"]",
    );
    let d = domain(&text);
    assert_eq!(d.goal.init.len(), 1);
    let p = plan_bt(&d, &Options::default()).unwrap();
    let m = fsm::plan_fsm(&d, &p).unwrap();
    assert_eq!(m.states[m.top.initial_state().unwrap()].name, "Unlock door");
}

/// With the start known, an achiever needing a static fact (of a
/// predicate no action changes) that `init` does not list is never
/// tried: PlanSys2's `askcharge` only to the room with a charging point,
/// `move` only along the room graph. Without `init` every grounding is
/// tried and the tree outgrows the node cap.
#[test]
fn static_preconditions_false_at_the_start_rule_achievers_out() {
    let text = include_str!("../../../tests/fixtures/domains/simple-durative.toml");
    let d = domain(text);
    let p = plan_bt(&d, &Options::default()).unwrap();
    let calls: Vec<String> = (p.steps.iter().flatten())
        .map(|(a, bind)| {
            let action = &d.actions[*a];
            let args: Vec<&str> = action
                .params
                .iter()
                .map(|q| bind[&q.name].as_str())
                .collect();
            format!("{} {}", action.name, args.join(" "))
        })
        .collect();
    let askcharge = calls.iter().filter(|c| c.starts_with("askcharge"));
    assert!(askcharge.clone().count() > 0, "{calls:?}");
    assert!(
        askcharge.clone().all(|c| c.ends_with(" chargingroom")),
        "{calls:?}"
    );
    assert!(calls.contains(&"move leia bedroom bathroom".to_string()));
    assert!(
        !calls
            .iter()
            .any(|c| c.starts_with("move leia kitchen bathroom"))
    );
    let mut no_init = d.clone();
    no_init.goal.init.clear();
    let capped = Options {
        max_nodes: 10 * p.bt.nodes.len(),
        ..Options::default()
    };
    assert_eq!(
        plan_bt(&no_init, &capped).unwrap_err(),
        PlanError::TooLarge(10 * p.bt.nodes.len())
    );
}
