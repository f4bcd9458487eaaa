//! `btfsm tick` through the binary: the table (an insta snapshot), the JSON
//! contract of docs/bt-semantics.md, several tree/script pairs, refused
//! node types and script errors with positions. BehaviorTree.CPP agreement
//! is tests/differential/.

use super::*;

const TREE: &str = "tests/fixtures/tick/grasp.xml";
const SCRIPT: &str = "tests/fixtures/tick/grasp.toml";

#[test]
fn table_of_a_grasp_that_fails_twice() {
    let (code, out, err) = btfsm(&["tick", TREE, "--script", SCRIPT]);
    assert_eq!(code, 0, "{err}");
    insta::assert_snapshot!(out);
}

#[test]
fn json_follows_the_contract() {
    let (code, out, err) = btfsm(&["tick", TREE, "--script", SCRIPT, "--format", "json"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(out.lines().count(), 1, "one object per line");
    let v: serde_json::Value = serde_json::from_str(&out).expect("json");
    assert_eq!(v["tree"], TREE);
    assert_eq!(v["script"], SCRIPT);
    assert_eq!(v["cut"], false);
    let ticks = v["ticks"].as_array().expect("ticks");
    assert_eq!(ticks.len(), 7);
    for (i, t) in ticks.iter().enumerate() {
        assert_eq!(t["tick"], i + 1);
        assert!(["SUCCESS", "FAILURE", "RUNNING"].contains(&t["root"].as_str().unwrap()));
        for e in t["events"].as_array().expect("events") {
            let o = e.as_object().expect("event");
            let leaf = o.contains_key("leaf") && o.contains_key("status") && o.len() == 2;
            let halt = o.contains_key("halt") && o.len() == 1;
            assert!(leaf || halt, "{e}");
        }
    }
    // Tick 2: the grasp fails, Retry ticks it again in the same tick (it
    // was running), fails again and yields.
    assert_eq!(
        ticks[1]["events"],
        serde_json::json!([
            {"leaf": "grasp", "status": "FAILURE"},
            {"leaf": "grasp", "status": "FAILURE"}
        ])
    );
    assert_eq!(v["halt"], serde_json::json!(["tuck"]));
}

#[test]
fn several_pairs_run_in_one_process() {
    let (code, out, err) = btfsm(&[
        "tick", TREE, "--script", SCRIPT, TREE, "--script", SCRIPT, "--format", "json",
    ]);
    assert_eq!(code, 0, "{err}");
    let lines: Vec<&str> = out.lines().collect();
    assert_eq!(lines.len(), 2);
    assert_eq!(lines[0], lines[1]);
    let (code, _, err) = btfsm(&["tick", TREE, TREE, "--script", SCRIPT]);
    assert_eq!(code, 2);
    assert!(err.contains("give one --script per tree"), "{err}");
}

#[test]
fn a_toml_tree_ticks_with_its_kinds() {
    let d = common::scratch("tick-toml");
    let tree = d.join("t.toml");
    std::fs::write(
        &tree,
        "kind = \"bt\"\nroot = \"r\"\n[nodes]\nr = { sequence = [\"c\", \"p\"] }\nc = { condition = \"C?\" }\np = { parallel = [\"a\", \"b\"], success = 1 }\na = { action = \"A!\" }\nb = { action = \"B!\" }\n",
    )
    .unwrap();
    let script = d.join("s.toml");
    std::fs::write(
        &script,
        "ticks = 2\ndefault = \"running\"\n[leaves]\nc = [\"success\", \"failure\"]\na = [\"running\", \"success\"]\n",
    )
    .unwrap();
    let (code, out, err) = btfsm(&[
        "tick",
        tree.to_str().unwrap(),
        "--script",
        script.to_str().unwrap(),
        "--format",
        "json",
    ]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    // Tick 2: the reactive sequence's condition fails: the running
    // parallel is halted, its running leaves depth first.
    assert_eq!(
        v["ticks"][1]["events"],
        serde_json::json!([
            {"leaf": "c", "status": "FAILURE"},
            {"halt": "a"},
            {"halt": "b"}
        ])
    );
    assert_eq!(v["ticks"][1]["root"], "FAILURE");
}

#[test]
fn unsupported_types_are_refused_with_a_position() {
    let (code, out, err) = btfsm(&[
        "tick",
        "tests/fixtures/tick/refused.xml",
        "--script",
        SCRIPT,
    ]);
    assert_eq!(code, 2);
    assert!(out.is_empty());
    assert!(
        err.contains("tests/fixtures/tick/refused.xml:5:7")
            && err.contains("`Delay` cannot be ticked"),
        "{err}"
    );
    let d = common::scratch("tick-refused");
    let tree = d.join("t.toml");
    std::fs::write(
        &tree,
        "kind = \"bt\"\nroot = \"r\"\n[nodes]\nr = { timeout = \"a\", ms = 10 }\na = { action = \"A!\" }\n",
    )
    .unwrap();
    let (code, _, err) = btfsm(&["tick", tree.to_str().unwrap(), "--script", SCRIPT]);
    assert_eq!(code, 2);
    assert!(
        err.contains("`Timeout` (wall-clock time)") && err.contains("t.toml:4:"),
        "{err}"
    );
    // A pre/post-condition script is not modelled: refused, not ignored.
    let x = d.join("p.xml");
    std::fs::write(
        &x,
        "<root BTCPP_format=\"4\"><BehaviorTree ID=\"T\">\n<Sequence>\n<AlwaysSuccess _skipIf=\"x\"/>\n</Sequence></BehaviorTree></root>\n",
    )
    .unwrap();
    let (code, _, err) = btfsm(&["tick", x.to_str().unwrap(), "--script", SCRIPT]);
    assert_eq!(code, 2);
    assert!(
        err.contains("`_skipIf`") && err.contains("p.xml:3:1"),
        "{err}"
    );
}

#[test]
fn script_errors_are_positioned() {
    let (code, _, err) = btfsm(&[
        "tick",
        TREE,
        "--script",
        "tests/fixtures/tick/bad-script.toml",
    ]);
    assert_eq!(code, 2);
    assert!(
        err.contains("bad-script.toml:3:26") && err.contains("a condition cannot return `running`"),
        "{err}"
    );
    assert!(
        err.contains("bad-script.toml:4:1") && err.contains("did you mean `grasp`?"),
        "{err}"
    );
}

/// `--format` takes exactly the formats a command's report is written in:
/// one the command does not write is a usage error (exit 2) naming the
/// ones it does, before anything is read.
#[test]
fn a_format_a_command_does_not_write_is_a_usage_error() {
    for (args, offered) in [
        (
            &["tick", "x.xml", "--script", "s.toml", "--format", "csv"][..],
            "table, json",
        ),
        (
            &["compare", "a.toml", "b.toml", "--format", "sarif"][..],
            "table, json, markdown",
        ),
        (
            &["lint", "a.toml", "--format", "csv"][..],
            "text, json, sarif, junit",
        ),
    ] {
        let (code, out, err) = btfsm(args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(out.is_empty());
        assert!(
            err.contains(&format!("[possible values: {offered}]")),
            "{args:?}: {err}"
        );
    }
}
