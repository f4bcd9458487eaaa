//! Files as the field writes them (issue 29, points 6 and 7): exports that
//! BehaviorTree.CPP 4 loads (`make differential` loads every one in
//! BehaviorTree.CPP itself, `tests/differential/accept_btcpp.py`; here the
//! text the engine reads), and inputs btfsm used to refuse: Nav2's
//! `ros_pkg` includes, yasmin's package includes and `JoinState`, MoveIt
//! Studio's `<MetadataFields>`, a model that disagrees with `--nodes-model`,
//! the `--->` comment, Groot2 `.btproj` models in folders, and a tree ID
//! used as a tag.

use super::*;
use common::btfsm_env;

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

const WS: &str = "tests/fixtures/field/ros-ws/src";

/// Vertices of the one policy `analyze --format json` reads.
fn vertices(out: &str) -> u64 {
    let v: serde_json::Value = serde_json::from_str(out).expect("json");
    v["policies"][0]["vertices"].as_u64().expect("vertices")
}

/// Nav2's `<include ros_pkg="..." path="..."/>`: the package's directory is
/// found in the repository by its package.xml (no ROS installed), given by
/// `--ros-pkg`, or installed under AMENT_PREFIX_PATH, and the file read
/// under the root rules.
#[test]
fn a_ros_pkg_include_is_read_from_the_package() {
    let tree = format!("{WS}/btfsm_demo_bt/behavior_trees/navigate.xml");
    let no_ament = ["AMENT_PREFIX_PATH"];
    // The repository's package.xml named btfsm_demo_subtrees: the Recover
    // subtree (Sequence, Spin, BackUp) joins the 4 nodes of the tree.
    let (code, out, err) = btfsm_env(&["analyze", &tree, "--format", "json"], &[], &no_ament);
    assert_eq!(code, 0, "{err}");
    assert_eq!(vertices(&out), 7, "{out}");
    // Another copy of the package, given; outside the root, so only with
    // --allow-outside-root.
    let dir = common::scratch("ros-pkg");
    let pkg = dir.join("share/btfsm_demo_subtrees");
    std::fs::create_dir_all(pkg.join("behavior_trees")).expect("mkdir");
    std::fs::write(
        pkg.join("behavior_trees/recover.xml"),
        r#"<root BTCPP_format="4"><BehaviorTree ID="Recover"><Sequence><Spin/><BackUp/><Spin/></Sequence></BehaviorTree></root>"#,
    )
    .expect("write");
    let given = format!("btfsm_demo_subtrees={}", pkg.display());
    let (code, _, err) = btfsm_env(&["analyze", &tree, "--ros-pkg", &given], &[], &no_ament);
    assert_eq!(code, 2);
    assert!(
        err.contains("outside the root") && err.contains("--allow-outside-root"),
        "{err}"
    );
    let (code, out, err) = btfsm_env(
        &[
            "analyze",
            &tree,
            "--ros-pkg",
            &given,
            "--allow-outside-root",
            "--format",
            "json",
        ],
        &[],
        &no_ament,
    );
    assert_eq!(code, 0, "{err}");
    assert_eq!(vertices(&out), 8);
    // Installed: AMENT_PREFIX_PATH's share/NAME/ comes before the repository.
    let prefix = dir.display().to_string();
    let ament = [("AMENT_PREFIX_PATH", prefix.as_str())];
    let (code, out, err) = btfsm_env(
        &["analyze", &tree, "--allow-outside-root", "--format", "json"],
        &ament,
        &[],
    );
    assert_eq!(code, 0, "{err}");
    assert_eq!(vertices(&out), 8);
    // A package nowhere: the error says where it looked and how to say it.
    let text = std::fs::read_to_string(&tree)
        .expect("fixture")
        .replace("btfsm_demo_subtrees", "btfsm_no_such_pkg");
    let missing = dir.join("missing-pkg.xml");
    std::fs::write(&missing, text).expect("write");
    let (code, _, err) = btfsm_env(&["validate", missing.to_str().unwrap()], &[], &no_ament);
    assert_eq!(code, 2);
    assert!(
        err.contains("no ROS package `btfsm_no_such_pkg` found")
            && err.contains("--ros-pkg btfsm_no_such_pkg=DIR"),
        "{err}"
    );
}

/// yasmin_editor writes nested machines by `package` and `file_name`, and
/// yasmin's own orthogonal demo synchronises at `<JoinState>`s: both
/// read (they were "this state machine has no states" and "`sync_a` is
/// neither a state nor an outcome").
#[test]
fn yasmin_package_includes_and_join_states_are_read() {
    let no_ament = ["AMENT_PREFIX_PATH"];
    let outer = format!("{WS}/btfsm_demo_fsm/state_machines/outer.xml");
    let (code, out, err) = btfsm_env(&["analyze", &outer, "--format", "json"], &[], &no_ament);
    assert_eq!(code, 0, "{err}");
    // Prepare, Inner and Inner's Work; the outcomes done and failed.
    assert_eq!(vertices(&out), 5, "{out}");
    for f in ["test.xml", "runtime_test.xml"] {
        let p = format!("tests/fixtures/field/yasmin/yasmin_editor/test/{f}");
        let (code, _, err) = btfsm_env(&["validate", &p], &[], &no_ament);
        assert_eq!(code, 0, "{f}: {err}");
    }
    let sync = "tests/fixtures/corpus/yasmin/yasmin_demos/state_machines/demo_orthogonal_sync.xml";
    let (code, out, err) = run(&["analyze", sync, "--format", "json"]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).expect("json");
    // start, parallel, regions A and B, their 3 states each (the join
    // states among them), and the 3 outcomes.
    assert_eq!(v["policies"][0]["vertices"], 13, "{out}");
}

/// MoveIt Studio keeps `<MetadataFields>` in its objectives'
/// `<TreeNodesModel>` (BehaviorTree.CPP ignores them): read past.
#[test]
fn moveit_studio_metadata_is_read_past() {
    let f = "tests/fixtures/field/bt-xml/moveit_studio/clear_snapshot.xml";
    let (code, _, err) = run(&["validate", "--assume-leaf", "action", f]);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("MetadataFields"), "{err}");
}

/// A tree's model saying Action where `--nodes-model` says Condition:
/// BehaviorTree.CPP reads no category from a model, so a warning naming
/// both, and the first read (`--nodes-model`) is kept.
#[test]
fn a_model_disagreeing_with_nodes_model_is_a_warning() {
    let dir = common::scratch("model-conflict");
    let model = dir.join("model.xml");
    std::fs::write(
        &model,
        r#"<root BTCPP_format="4"><TreeNodesModel><Condition ID="IsDocked"/></TreeNodesModel></root>"#,
    )
    .expect("write");
    let tree = dir.join("tree.xml");
    std::fs::write(
        &tree,
        r#"<root BTCPP_format="4"><BehaviorTree ID="T"><Sequence><IsDocked/><AlwaysSuccess/></Sequence></BehaviorTree>
<TreeNodesModel><Action ID="IsDocked"/></TreeNodesModel></root>"#,
    )
    .expect("write");
    let (code, out, err) = run(&[
        "analyze",
        tree.to_str().unwrap(),
        "--nodes-model",
        model.to_str().unwrap(),
        "--format",
        "json",
    ]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("warning: `IsDocked` is declared as `Action` here and as `Condition` at")
            && err.contains("model.xml:1:"),
        "{err}"
    );
    let v: serde_json::Value = serde_json::from_str(&out).expect("json");
    assert_eq!(v["policies"][0]["counts"]["condition"], 1, "{out}");
}

/// BehaviorTree.CPP 3.8's tutorial t05 writes comments of dashes that end
/// in `--->`; tinyxml2 reads them and BehaviorTree.CPP 4 loads the file
/// (`make differential` loads this one): read, with a warning.
#[test]
fn a_comment_ending_in_three_dashes_is_read_with_a_warning() {
    let f = "tests/fixtures/field/bt-xml/btcpp/t05_crossdoor.xml";
    let (code, _, err) = run(&["validate", "--assume-leaf", "action", f]);
    assert_eq!(code, 0, "{err}");
    let dir = common::scratch("dash-comment");
    let g = dir.join("t.xml");
    std::fs::write(
        &g,
        "<root BTCPP_format=\"4\">\n  <!-- the main tree --->\n  <BehaviorTree ID=\"M\"><AlwaysSuccess/></BehaviorTree>\n</root>\n",
    )
    .expect("write");
    let (code, _, err) = run(&["validate", g.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(err.contains("a comment ending in `--->`"), "{err}");
}

/// A Groot2 project folder keeps its node models in the `.btproj` only:
/// walked as a directory, its trees read them.
#[test]
fn a_groot2_project_folder_reads_the_models_of_its_btproj() {
    let dir = "tests/fixtures/field/groot2-project";
    let (code, out, err) = run(&["analyze", dir, "--format", "json"]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).expect("json");
    assert_eq!(v["policies"][0]["counts"]["condition"], 1, "{out}");
    // The tree alone does not know its node types.
    let (code, _, err) = run(&["analyze", &format!("{dir}/inspect.xml")]);
    assert_eq!(code, 2);
    assert!(err.contains("unknown node type `IsBatteryOk`"), "{err}");
}

/// A tree's ID used as a tag (`<CheckStatus/>` for the tree CheckStatus):
/// BehaviorTree.CPP 4 refuses it ("Node not recognized"), and so does
/// btfsm, with the fix, even under `--assume-leaf`.
#[test]
fn a_tree_id_used_as_a_tag_is_refused_with_the_fix() {
    let f = "tests/fixtures/corpus-pending/bt-xml/btcpp/examples/subtree_test.xml";
    let (code, _, err) = run(&["validate", "--assume-leaf", "action", f]);
    assert_eq!(code, 2);
    assert!(
        err.contains("`<CheckStatus>` names a tree, not a node type")
            && err.contains("write `<SubTree ID=\"CheckStatus\"/>`"),
        "{err}"
    );
}

/// What BehaviorTree.CPP 4 refuses when it loads a file (xml_parsing.cpp,
/// `VerifyXML`; found by bench/acceptance_corpus.py on a MoveIt Pro
/// objective and BehaviorTree.CPP 4.10's unit tests): `validate` refuses
/// it and `lint` reports a `load-error` at the element, never "0 errors".
#[test]
fn what_behaviortree_cpp_refuses_on_load_is_a_lint_error() {
    let dir = common::scratch("refused-on-load");
    let cases = [
        (
            "reactive-explicit.xml",
            r#"<root BTCPP_format="4"><BehaviorTree ID="M"><ReactiveSequence><Action ID="Go"/><AlwaysSuccess/></ReactiveSequence></BehaviorTree><TreeNodesModel><Action ID="Go"/></TreeNodesModel></root>"#,
            "refuses `<Action>` as a child of `ReactiveSequence`",
        ),
        (
            "untitled-tree.xml",
            r#"<root BTCPP_format="4" main_tree_to_execute="Other"><BehaviorTree ID=""><AlwaysSuccess/></BehaviorTree><BehaviorTree ID="Other"><AlwaysSuccess/></BehaviorTree></root>"#,
            "`<BehaviorTree>` needs an `ID`",
        ),
        (
            "model-subtree.xml",
            r#"<root BTCPP_format="4"><BehaviorTree ID="M"><AlwaysSuccess/></BehaviorTree><TreeNodesModel><SubTree/></TreeNodesModel></root>"#,
            "`<SubTree>` in `<TreeNodesModel>` needs an `ID`",
        ),
    ];
    for (name, text, msg) in cases {
        let f = dir.join(name);
        std::fs::write(&f, text).expect("write");
        let f = f.to_string_lossy().to_string();
        let (code, _, err) = run(&["validate", &f]);
        assert_eq!(code, 2, "{name}: {err}");
        assert!(err.contains(msg), "{name}: {err}");
        let (code, out, _) = run(&["lint", "--no-config", &f, "--format", "json"]);
        assert_eq!(code, 2, "{name}: {out}");
        assert!(
            out.contains("\"load-error\"") && out.contains(&msg.replace('"', "\\\"")),
            "{name}: {out}"
        );
    }
    // The compact form loads in BehaviorTree.CPP and in btfsm.
    let f = dir.join("reactive-compact.xml");
    std::fs::write(&f, r#"<root BTCPP_format="4"><BehaviorTree ID="M"><ReactiveSequence><Go/><AlwaysSuccess/></ReactiveSequence></BehaviorTree><TreeNodesModel><Action ID="Go"/></TreeNodesModel></root>"#).expect("write");
    let (code, _, err) = run(&["validate", &f.to_string_lossy()]);
    assert_eq!(code, 0, "{err}");
}
