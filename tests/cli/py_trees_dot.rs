//! py_trees DOT renders (docs/guide/py-trees-dot.md) read as BTs by every
//! command: renders that py_trees 2.6.0 itself wrote of btfsm's own trees
//! (tests/fixtures/py_trees_dot), against the paper's Fig. 1 and hand
//! counts; directory walks keep renders and skip other DOT. (py_trees as the
//! oracle, rendering and exporting the same trees: tests/packaging/python_export.py.)

use crate::common::btfsm;

fn analyze(file: &str) -> serde_json::Value {
    let (code, out, err) = btfsm(&["analyze", "--format", "json", file]);
    assert_eq!(code, 0, "{file}: {err}");
    let v: serde_json::Value = serde_json::from_str(&out).expect("json");
    v["policies"][0].clone()
}

/// py_trees' render of examples/py_trees_fig01.py is the paper's Fig. 1:
/// structural GED 0 against policies/paper/fig01-bt.toml, with its counts
/// (4 fallbacks, 2 sequences, 4 conditions, 4 actions).
#[test]
fn py_trees_render_of_fig01_is_the_papers_fig01() {
    let p = analyze("tests/fixtures/py_trees_dot/fig01.dot");
    assert_eq!(p["kind"], "bt");
    assert_eq!(p["name"], "moma");
    let c = &p["counts"];
    assert_eq!(
        (c["fallback"].as_u64(), c["sequence"].as_u64()),
        (Some(4), Some(2))
    );
    assert_eq!(
        (c["condition"].as_u64(), c["action"].as_u64()),
        (Some(4), Some(4))
    );
    let (code, out, err) = btfsm(&[
        "compare",
        "tests/fixtures/py_trees_dot/fig01.dot",
        "policies/paper/fig01-bt.toml",
        "--mode",
        "structural",
        "--format",
        "json",
    ]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).expect("json");
    assert_eq!(v["structural"]["ged"], 0);
}

/// The render of a tree of every composite, Parallel policy and decorator
/// (tests/packaging/python_export.py's `pt_all`): hand count of its 40
/// nodes; blackboard nodes and edges of a render `with_blackboard_variables`
/// are not part of the tree.
#[test]
fn every_py_trees_node_type_and_the_blackboard_render() {
    let p = analyze("tests/fixtures/py_trees_dot/every_node_type.dot");
    let c = &p["counts"];
    assert_eq!(p["vertices"], 40);
    assert_eq!(c["sequence"], 1);
    assert_eq!(c["sequence_memory"], 1);
    assert_eq!(c["fallback"], 1);
    assert_eq!(c["fallback_memory"], 1);
    assert_eq!(c["parallel"], 3);
    assert_eq!(c["decorator"], 10);
    // Leaves: `Battery ok?` is the one condition by its name; the render
    // does not say that `docked` and `has key` are checks.
    assert_eq!(c["condition"], 1);
    assert_eq!(c["action"], 22);
    let p = analyze("tests/fixtures/py_trees_dot/blackboard.dot");
    assert_eq!(
        (p["vertices"].as_u64(), p["edges"].as_u64()),
        (Some(3), Some(2))
    );
    assert_eq!(p["counts"]["sequence_memory"], 1);
}

/// Below a directory, a `.dot` file is read when it is a py_trees render
/// and skipped otherwise (btfsm's own `dot` output); named on the command
/// line, another DOT file is refused saying why.
#[test]
fn a_walk_keeps_py_trees_renders_and_skips_other_dot() {
    let dir = crate::common::scratch("ptdot-walk");
    let (code, own, _) = btfsm(&["dot", "policies/paper/fig01-bt.toml"]);
    assert_eq!(code, 0);
    std::fs::write(dir.join("btfsm.dot"), own).expect("write");
    std::fs::copy(
        "tests/fixtures/py_trees_dot/fig01.dot",
        dir.join("render.dot"),
    )
    .expect("copy");
    let d = dir.display().to_string();
    let (code, out, err) = btfsm(&["analyze", "--format", "json", &d]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).expect("json");
    let files: Vec<&str> = v["policies"]
        .as_array()
        .expect("policies")
        .iter()
        .map(|p| p["file"].as_str().unwrap())
        .collect();
    assert_eq!(files.len(), 1, "{files:?}");
    assert!(files[0].ends_with("render.dot"));
    let own = dir.join("btfsm.dot").display().to_string();
    let (code, _, err) = btfsm(&["validate", &own]);
    assert_eq!(code, 2);
    assert!(
        err.contains("not a py_trees render: its graph is not named `pastafarianism`"),
        "{err}"
    );
}
