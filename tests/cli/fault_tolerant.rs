//! `convert --to fault-tolerant` and `effort` on a machine whose Recharge
//! only some states enter, on a guard, written last (issue 29, point 8):
//! the generated SELECTOR finishes when the task's goal holds (the last
//! step's effect), not when the battery is charged, and `effort` counts
//! Recharge as a side state, not a step. The property over random such
//! machines, and the simulator as a second oracle, are
//! `btfsm_transform::fault_tolerant_tests` and
//! `btfsm_sim::fault_tolerant_tests`.

use super::*;

const SIDE: &str = r#"kind = "fsm"
name = "side recharge"
initial = "Move-To cube2"
outcomes = ["SUCCESS", "FAILURE"]

[states."Move-To cube2"]
skill = "Move-To"
args = { target = "cube2" }
guards = [{ unless = "Battery-Level", args = { min = 20 }, to = "Recharge", label = "battery < 20%" }]
on = { SUCCESS = "Pick cube2" }

[states."Pick cube2"]
skill = "Pick"
args = { object = "cube2" }
on = { SUCCESS = "Move-To delivery" }

[states."Move-To delivery"]
skill = "Move-To"
args = { target = "delivery" }
guards = [{ unless = "Battery-Level", args = { min = 20 }, to = "Recharge", label = "battery < 20%" }]
on = { SUCCESS = "Place cube2" }

[states."Place cube2"]
skill = "Place"
args = { object = "cube2", at = "delivery" }
on = { SUCCESS = "SUCCESS" }

[states.Recharge]
skill = "Recharge"
on = { SUCCESS = "Move-To cube2" }
"#;

#[test]
fn a_side_recharge_is_a_recovery_and_never_the_goal() {
    let dir = common::scratch("side-recharge");
    let f = dir.join("side.toml");
    std::fs::write(&f, SIDE).expect("write");
    let f = f.to_str().unwrap();
    let (code, out, err) = btfsm(&["convert", f, "--to", "fault-tolerant"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains(r#"to = "SUCCESS", label = "done: Object-At(at=delivery, object=cube2)""#),
        "{out}"
    );
    assert!(!out.contains("done: Battery-Level"), "{out}");
    assert!(
        out.contains(r#"{ unless = "Battery-Level", args = { min = 20 }, to = "Recharge", label = "battery < 20%" },"#),
        "{out}"
    );
    let (code, out, err) = btfsm(&["effort", f, "--format", "json"]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).expect("json");
    let p = &v["policies"][0];
    assert_eq!(p["m_s"], 4, "{p}");
    assert_eq!(p["side"], serde_json::json!(["Recharge"]), "{p}");
    assert!(
        p["note"]
            .as_str()
            .unwrap_or_default()
            .contains("side states [Recharge]"),
        "{p}"
    );
}
