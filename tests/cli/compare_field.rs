//! `btfsm compare` on real BehaviorTree.CPP files (issue 29, point 4): the
//! change list names only changes that happened. Nav2's
//! `navigate_to_pose_w_replanning_and_recovery.xml` from Humble to main
//! (five nodes inserted before an unnamed RateController, which keeps its
//! place in the tree), a Groot2-style edit that only adds `name`
//! attributes, and a type change under a kept display name. What the
//! files hold was read by hand from them and is written out below.

use super::*;

const NAV2: &str = "tests/fixtures/field/bt-xml/nav2";
const NAV2_MODEL: &str = "tests/fixtures/corpus/bt-xml/nav2/nav2_tree_nodes.xml";
const NAMES_BEFORE: &str = "tests/fixtures/compare/names-before.xml";
const NAMES_AFTER: &str = "tests/fixtures/compare/names-after.xml";
const TYPE_CHANGED: &str = "tests/fixtures/compare/names-type-changed.xml";

fn nav2_pair() -> (String, String, String) {
    (
        format!("{NAV2}/humble/navigate_to_pose_w_replanning_and_recovery.xml"),
        format!("{NAV2}/main/navigate_to_pose_w_replanning_and_recovery.xml"),
        NAV2_MODEL.to_string(),
    )
}

fn run(args: &[&str]) -> String {
    let (code, out, err) = btfsm(args);
    assert_eq!(code, 0, "{args:?}: {err}");
    out
}

fn json(args: &[&str]) -> serde_json::Value {
    let mut all = args.to_vec();
    all.extend_from_slice(&["--format", "json"]);
    serde_json::from_str(&run(&all)).expect("json")
}

/// Humble → main: the RateController is kept (it moved from position 0 to
/// position 5 of `NavigateWithReplanning` as five selectors came before
/// it); the change list has the selectors added and five argument
/// changes, and no type change (the file has none).
#[test]
fn nav2_humble_to_main_lists_only_what_changed() {
    let (a, b, model) = nav2_pair();
    let md = run(&[
        "compare",
        &a,
        &b,
        "--nodes-model",
        &model,
        "--format",
        "markdown",
    ]);
    let headline = md.lines().find(|l| l.starts_with("**What changed**"));
    assert_eq!(
        headline,
        Some(
            "**What changed** (named mapping; nodes without an id matched in tree order): 5 relabels, 20 vertices and 24 arcs added, 4 arcs removed."
        ),
        "{md}"
    );
    let summary: String = md.split("| | file |").next().unwrap_or_default().into();
    for wrong in [
        "type of",
        "RateController →",
        "→ ProgressCheckerSelector",
        "- removed",
    ] {
        assert!(!summary.contains(wrong), "`{wrong}` in\n{summary}");
    }
    let v = json(&["compare", &a, &b, "--nodes-model", &model]);
    let named = &v["named"];
    assert_eq!(named["ged"], 48, "{named}");
    let relabels = named["edit_script"]["relabelled"].as_array().expect("list");
    let changed: Vec<(&str, &str)> = relabels
        .iter()
        .map(|r| (r["what"].as_str().unwrap(), r["key"].as_str().unwrap()))
        .collect();
    // ComputePathToPose (now under a Fallback), FollowPath, Spin, Wait and
    // BackUp gained error ports; nothing else changed its attributes.
    assert_eq!(
        changed,
        [
            ("arguments", "FallbackComputePathToPose/1"),
            ("arguments", "FollowPath/0"),
            ("arguments", "RecoveryActions/1"),
            ("arguments", "RecoveryActions/2"),
            ("arguments", "RecoveryActions/3"),
        ]
    );
    let kept = named["edit_script"]["vertices_kept"]
        .as_array()
        .expect("list");
    assert!(
        kept.iter()
            .any(|k| k["a"] == "NavigateWithReplanning/0" && k["b"] == "NavigateWithReplanning/5"),
        "the RateController is kept: {kept:?}"
    );
    // Nothing of humble was removed: every vertex added is one of main's
    // 20 new nodes, the five selectors first in the tree.
    assert_eq!(
        named["edit_script"]["vertices_removed"],
        serde_json::json!([])
    );
    let added: Vec<&str> = named["edit_script"]["vertices_added"]
        .as_array()
        .expect("list")
        .iter()
        .map(|x| x["name"].as_str().unwrap())
        .collect();
    for sel in [
        "ProgressCheckerSelector",
        "GoalCheckerSelector",
        "PathHandlerSelector",
        "ControllerSelector",
        "PlannerSelector",
    ] {
        assert!(added.contains(&sel), "{sel} not added: {added:?}");
    }
    assert!(!added.contains(&"RateController"), "{added:?}");
    // The ordered tree script: 5 renames (the argument changes, each
    // within one node type) and 20 insertions, no deletion.
    let t = &v["tree"]["edit_script"];
    assert_eq!(v["tree"]["ted"], 25);
    assert_eq!(t["deleted"], serde_json::json!([]));
    assert_eq!(t["inserted"].as_array().map(Vec::len), Some(20));
    for r in t["renamed"].as_array().expect("list") {
        let (from, to) = (r["from"].as_str().unwrap(), r["to"].as_str().unwrap());
        let ty = |s: &str| s.split(' ').next().unwrap_or_default().to_string();
        assert_eq!(ty(from), ty(to), "a rename across types: {r}");
    }
}

/// Adding `name` attributes to four nodes (what Groot2 does when a node is
/// labelled) is four renames in every distance, never a removal and an
/// addition.
#[test]
fn adding_names_is_a_rename_never_a_remove_and_an_add() {
    let v = json(&["compare", NAMES_BEFORE, NAMES_AFTER]);
    for m in ["structural", "labeled", "named"] {
        assert_eq!(v[m]["ged"], 0, "{m}: {}", v[m]);
    }
    let named = &v["named"]["edit_script"];
    let what: Vec<&str> = named["relabelled"]
        .as_array()
        .expect("list")
        .iter()
        .map(|r| r["what"].as_str().unwrap())
        .collect();
    assert_eq!(what, ["name"; 4], "{named}");
    assert_eq!(v["tree"]["ted"], 4);
    assert_eq!(
        v["tree"]["edit_script"]["renamed"].as_array().map(Vec::len),
        Some(4)
    );
    // The same under `--mode named` alone (the tree mapping is computed
    // for the pairing, not shown).
    let w = json(&["compare", NAMES_BEFORE, NAMES_AFTER, "--mode", "named"]);
    assert_eq!(w["named"]["ged"], 0, "{w}");
    assert_eq!(w["named"]["relabels"], 4, "{w}");
    assert!(w.get("tree").is_none(), "{w}");
    let md = run(&["compare", NAMES_BEFORE, NAMES_AFTER, "--format", "markdown"]);
    let summary: String = md.split("| | file |").next().unwrap_or_default().into();
    assert!(
        summary.contains("- name of `Mission`: \"Sequence\" → \"Mission\""),
        "{md}"
    );
    assert!(
        !summary.contains("added") && !summary.contains("removed"),
        "{md}"
    );
    // And a name changed again is one rename too.
    let renamed = std::fs::read_to_string(NAMES_AFTER)
        .expect("fixture")
        .replace("\"DockNow\"", "\"DockAtHome\"");
    let dir = common::scratch("names-renamed");
    let f = dir.join("renamed.xml");
    std::fs::write(&f, renamed).expect("write");
    let v = json(&["compare", NAMES_AFTER, f.to_str().unwrap()]);
    assert_eq!(v["named"]["ged"], 0);
    assert_eq!(v["named"]["relabels"], 1);
    assert_eq!(v["tree"]["ted"], 1);
}

/// A leaf turned from `Spin` into `BackUp` under the kept name `Recover`:
/// the tree script shows both types, not the same text twice.
#[test]
fn a_type_change_under_a_kept_name_shows_both_types() {
    let out = run(&["compare", NAMES_AFTER, TYPE_CHANGED]);
    assert!(
        out.contains("~ `Recover`: action:Spin \"Recover\" {angle=1.57} → action:BackUp \"Recover\" {angle=1.57}"),
        "{out}"
    );
    assert!(out.contains("~ type of `Recover`: Spin → BackUp"), "{out}");
}
