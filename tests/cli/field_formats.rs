//! Files as the field writes them (issue 29, points 6 and 7): exports that
//! BehaviorTree.CPP 4 loads (`make differential` loads every one in
//! BehaviorTree.CPP itself, `tests/differential/accept_btcpp.py`; here the
//! text the engine reads), and inputs btfsm used to refuse: Nav2's
//! `ros_pkg` includes, yasmin's package includes and `JoinState`, MoveIt
//! Studio's `<MetadataFields>`, a model that disagrees with `--nodes-model`,
//! the `--->` comment, Groot2 `.btproj` models in folders, and a tree ID
//! used as a tag.

use super::*;

const PATROLLING: &str = "tests/fixtures/field/bt-xml/book_ros2/patrolling.xml";

fn run(args: &[&str]) -> (i32, String, String) {
    btfsm(args)
}

/// book_ros2's format 3 `<Parallel success_threshold="1" failure_threshold="1">`
/// exports as format 4 says it (BehaviorTree.CPP 4 refuses the format 3
/// names as ports its Parallel does not declare), and reads back the same.
#[test]
fn a_format3_parallel_exports_its_thresholds_as_format4_ports() {
    let (code, out, err) = run(&["convert", PATROLLING, "--to", "btcpp-xml"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains(r#"<Parallel success_count="1" failure_count="1">"#),
        "{out}"
    );
    assert!(!out.contains("threshold"), "{out}");
    let dir = common::scratch("patrolling-export");
    let f = dir.join("export.xml");
    std::fs::write(&f, &out).expect("write");
    let (code, json, err) = run(&["analyze", f.to_str().unwrap(), "--format", "json"]);
    assert_eq!(code, 0, "{err}");
    let (_, orig, _) = run(&["analyze", PATROLLING, "--format", "json"]);
    let v: serde_json::Value = serde_json::from_str(&json).expect("json");
    let w: serde_json::Value = serde_json::from_str(&orig).expect("json");
    assert_eq!(
        v["policies"][0]["counts"], w["policies"][0]["counts"],
        "{out}"
    );
}

/// No export carries an attribute BehaviorTree.CPP 4 rejects: ids that the
/// reader would not derive travel in comments, and come back.
#[test]
fn exports_carry_no_btfsm_attribute_and_keep_their_ids() {
    let dir = common::scratch("ids-export");
    for f in [
        "policies/paper/fig01-bt.toml",
        "policies/paper/fig05-bt.toml",
    ] {
        let out = dir.join("x.xml");
        let (code, _, err) = run(&[
            "convert",
            f,
            "--to",
            "btcpp-xml",
            "-o",
            out.to_str().unwrap(),
        ]);
        assert_eq!(code, 0, "{err}");
        let text = std::fs::read_to_string(&out).expect("written");
        assert!(
            !text.contains("btfsm:id=") && !text.contains("xmlns:btfsm"),
            "{f}: {text}"
        );
        let (code, json, err) = run(&[
            "compare",
            f,
            out.to_str().unwrap(),
            "--mode",
            "named",
            "--format",
            "json",
        ]);
        assert_eq!(code, 0, "{err}");
        let v: serde_json::Value = serde_json::from_str(&json).expect("json");
        assert_eq!(v["named"]["ged"], 0, "{f}: {}", v["named"]);
        assert_eq!(v["named"]["relabels"], 0, "{f}: {}", v["named"]);
    }
}
