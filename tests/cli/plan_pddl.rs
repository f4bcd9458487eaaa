//! `btfsm plan DOMAIN.pddl --problem PROBLEM.pddl` on PlanSys2's example
//! domains (tests/fixtures/domains/pddl/README.md), the laws "a PDDL
//! domain plans like its TOML twin" (STRIPS and durative), the planned BT
//! checked against the plan read off PlanSys2's domain by hand, and the
//! errors (docs/guide/plan.md, "PDDL domains").

use super::*;
use common::scratch;

const PDDL: &str = "tests/fixtures/domains/pddl";

fn plan(domain: &str, problem: &str, extra: &[&str]) -> (i32, String, String) {
    let d = format!("{PDDL}/{domain}.pddl");
    let p = format!("{PDDL}/{problem}.pddl");
    let mut args = vec!["plan", d.as_str(), "--problem", p.as_str()];
    args.extend(extra);
    btfsm(&args)
}

/// PlanSys2's six example domain files (the seventh, simple_example_py, is
/// simple_example byte for byte), each with the problem its example sets
/// up: all six load; four plan; `bt_example` (3 robots, 9 pieces, 5 zones,
/// 3 cars) gives a tree over the node cap, and `multidomain_domain_2` alone
/// has no action moving the robot (PlanSys2 merges it with domain 1).
#[test]
fn plansys2_example_domains_load_and_plan() {
    let cases: &[(&str, i32, &str)] = &[
        ("simple_example", 0, "simple-fsm.toml"),
        ("cascade_example", 0, "cascade-fsm.toml"),
        ("multidomain_domain_1", 0, "multidomain1-fsm.toml"),
        ("patrol", 0, "patrol-fsm.toml"),
        ("multidomain_domain_2", 2, "the plan has no step"),
        (
            "bt_example",
            2,
            "the tree would have more than 150000 nodes",
        ),
    ];
    let mut planned = 0;
    for (name, code, says) in cases {
        let (got, out, err) = plan(name, &format!("{name}-problem"), &[]);
        assert_eq!(got, *code, "{name}: {err}");
        assert!(
            out.contains(says) || err.contains(says),
            "{name}: {out}{err}"
        );
        planned += usize::from(got == 0);
    }
    assert_eq!(planned, 4);
    // With the achievers one level deep, bt_example plans too.
    let (code, out, err) = plan(
        "bt_example",
        "bt_example-problem",
        &["--max-plan-depth", "1", "--to", "fsm"],
    );
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("factory-fsm.toml"), "{out}");
}

/// The domain as PlanSys2's history has it before commit e421b1f: the
/// predicate misspelt in `assemble`, reported at its place with the name
/// it abbreviates.
#[test]
fn plansys2_typo_is_reported_with_the_predicate_meant() {
    let (code, out, err) = plan("bt_example-typo", "bt_example-problem", &[]);
    assert_eq!(code, 2);
    assert!(out.is_empty());
    insta::assert_snapshot!("plansys2_typo", err);
}

/// The three policies of `plan` (TOML text) for `args`.
fn policies(args: &[&str]) -> Vec<String> {
    ["bt", "fsm", "hfsm"]
        .iter()
        .map(|to| {
            let mut a = args.to_vec();
            a.extend(["--to", to, "-o", "-"]);
            let (code, out, err) = btfsm(&a);
            assert_eq!(code, 0, "{args:?}: {err}");
            out
        })
        .collect()
}

/// A law: a STRIPS PDDL domain and problem give the same BT, FSM and HFSM
/// as the same task written as a TOML domain.
#[test]
fn strips_pddl_plans_like_its_toml_twin() {
    let pddl = policies(&[
        "plan",
        "tests/fixtures/domains/pddl/kitting.pddl",
        "--problem",
        "tests/fixtures/domains/pddl/kitting-problem.pddl",
    ]);
    let toml = policies(&["plan", "tests/fixtures/domains/kitting-strips.toml"]);
    assert_eq!(pddl, toml);
    assert!(pddl[0].contains("kitting:in_tray"), "{}", pddl[0]);
}

/// The law for durative actions, with the mapping the guide states
/// (at-start and over-all conditions, net effects) written out by hand.
#[test]
fn durative_pddl_plans_like_its_toml_twin_by_the_stated_mapping() {
    let pddl = policies(&[
        "plan",
        "tests/fixtures/domains/pddl/simple_example.pddl",
        "--problem",
        "tests/fixtures/domains/pddl/simple_example-problem.pddl",
    ]);
    let toml = policies(&["plan", "tests/fixtures/domains/simple-durative.toml"]);
    assert_eq!(pddl, toml);
}

/// The BT planned from PlanSys2's simple example, run in the symbolic
/// world of the problem's facts, does what the domain allows: the battery
/// is low and `move` needs it full, so ask to be taken to the charging
/// room, charge, then walk kitchen, dining room, bedroom, bathroom (the
/// plan read off the domain's actions and the room graph by hand).
#[test]
fn the_bt_and_fsm_planned_from_plansys2_simple_example_reach_their_goal() {
    let d = scratch("pddl-sim");
    let dir = d.to_str().expect("utf-8");
    let (code, _, err) = plan("simple_example", "simple_example-problem", &["-o", dir]);
    assert_eq!(code, 0, "{err}");
    std::fs::copy(
        "tests/fixtures/domains/simple-durative.toml",
        d.join("simple.toml"),
    )
    .expect("copy");
    let init = [
        "connected(entrance, dinning)",
        "connected(dinning, entrance)",
        "connected(dinning, kitchen)",
        "connected(kitchen, dinning)",
        "connected(dinning, bedroom)",
        "connected(bedroom, dinning)",
        "connected(bathroom, bedroom)",
        "connected(bedroom, bathroom)",
        "connected(chargingroom, kitchen)",
        "connected(kitchen, chargingroom)",
        "charging_point_at(chargingroom)",
        "battery_low(leia)",
        "robot_at(leia, entrance)",
    ];
    let facts: Vec<String> = init.iter().map(|f| format!("\"{f}\"")).collect();
    std::fs::write(
        d.join("s.toml"),
        format!(
            "name = \"s\"\ndomain = \"simple.toml\"\nfacts = [{}]\nmax_steps = 400\n\
             [[policies]]\nfile = \"simple-bt.toml\"\nname = \"bt\"\n\
             [[policies]]\nfile = \"simple-hfsm.toml\"\nname = \"hfsm\"\n\
             [[policies]]\nfile = \"simple-fsm.toml\"\nname = \"fsm\"\n",
            facts.join(", ")
        ),
    )
    .expect("write");
    let scenario = format!("{dir}/s.toml");
    let (code, out, err) = btfsm(&["sim", &scenario, "--format", "json"]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).expect("json");
    let want = [
        "askcharge(leia, entrance, chargingroom)",
        "charge(leia, chargingroom)",
        "move(leia, chargingroom, kitchen)",
        "move(leia, kitchen, dinning)",
        "move(leia, dinning, bedroom)",
        "move(leia, bedroom, bathroom)",
    ];
    let runs = v["runs"].as_array().expect("runs");
    // The FSM's chain is what the BT does from the problem's start, so it
    // makes the same calls.
    assert_eq!(runs.len(), 3);
    for r in runs {
        assert_eq!(r["outcome"], "success", "{r}");
        let done: Vec<&str> = (r["actions"].as_array().expect("actions").iter())
            .map(|a| a[1].as_str().expect("name"))
            .collect();
        assert_eq!(done, want, "{}", r["policy"]);
    }
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn pddl_goals_options_and_refusals() {
    let kitting = "tests/fixtures/domains/pddl/kitting.pddl";
    // Without a problem: the domain's constants, and a goal given as a
    // PDDL atom or a fact.
    let (code, _, err) = btfsm(&["plan", kitting]);
    assert_eq!(code, 2);
    assert!(err.contains("the PDDL domain has no goal"), "{err}");
    assert!(err.contains("--problem FILE"), "{err}");
    for goal in ["(robot_at shelf)", "robot_at(shelf)"] {
        let (code, out, err) = btfsm(&["plan", kitting, "--goal", goal]);
        assert_eq!(code, 0, "{err}");
        assert!(out.contains("goal: robot_at(shelf)"), "{out}");
    }
    // --problem belongs to a PDDL domain.
    let (code, _, err) = btfsm(&[
        "plan",
        "tests/fixtures/domains/kitting.toml",
        "--problem",
        "tests/fixtures/domains/pddl/kitting-problem.pddl",
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("--problem is for a PDDL domain"), "{err}");
    // A feature outside the subset is refused where it is used.
    let d = scratch("pddl-refuse");
    let f = d.join("when.pddl");
    std::fs::write(
        &f,
        "(define (domain w)\n  (:requirements :strips :conditional-effects)\n  (:predicates (p) (q))\n  (:action a :parameters () :precondition (p)\n    :effect (when (p) (q))))\n",
    )
    .expect("write");
    let (code, _, err) = btfsm(&["plan", f.to_str().expect("utf-8"), "--goal", "(q)"]);
    assert_eq!(code, 2);
    assert!(
        err.contains(
            "`when` in an effect needs `:conditional-effects`, which `btfsm plan` does not support"
        ),
        "{err}"
    );
    assert!(err.contains("when.pddl:5:13"), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}
