//! `btfsm compare --mode tree` through the binary: the ordered tree edit
//! distance of two BTs (src/metrics/ted/), its edit script, its place in
//! the default report, its budget, and FSM inputs refused.

use super::*;
use crate::common::scratch;

fn json(args: &[&str]) -> serde_json::Value {
    let (code, stdout, stderr) = btfsm(args);
    assert_eq!(code, 0, "{args:?}: {stderr}");
    serde_json::from_str(&stdout).expect("json")
}

/// The script's cost: renames, deletions, insertions, two per moved node.
fn script_cost(t: &serde_json::Value) -> u64 {
    let s = &t["edit_script"];
    let n = |k: &str| s[k].as_array().expect("list").len() as u64;
    let moved: u64 = s["moved"]
        .as_array()
        .expect("list")
        .iter()
        .map(|m| 2 * m["nodes"].as_u64().expect("nodes"))
        .sum();
    n("renamed") + n("deleted") + n("inserted") + moved
}

const FIG1: &str = "policies/paper/fig01-bt.toml";
const FIG3: &str = "policies/paper/fig03-bt.toml";

/// Fig. 3 swaps two children of `deliver` in Fig. 1: every GED is 0, the
/// tree distance is 6 — the 3-node subtree `reached-delivery` moved from
/// position 1 to position 0 of `deliver`, told as one step.
#[test]
fn tree_mode_reports_the_swapped_children_of_deliver() {
    let v = json(&["compare", FIG1, FIG3, "--mode", "tree", "--format", "json"]);
    let t = &v["tree"];
    assert_eq!(t["ted"], 6, "{t}");
    assert_eq!(t["exact"], true);
    assert_eq!(script_cost(t), 6);
    let moved = t["edit_script"]["moved"].as_array().expect("moved");
    assert_eq!(moved.len(), 1, "{t}");
    assert_eq!(moved[0]["nodes"], 3);
    assert_eq!(moved[0]["from"]["id"], "reached-delivery");
    assert_eq!(moved[0]["from"]["parent"], "deliver");
    assert_eq!(moved[0]["from"]["position"], 1);
    assert_eq!(moved[0]["to"]["position"], 0);
    assert!(v.get("named").is_none(), "only the mode asked for");
    // The default report keeps SPEC §7's modes as they were and adds `tree`.
    let all = json(&["compare", FIG1, FIG3, "--format", "json"]);
    for mode in ["structural", "labeled", "named"] {
        assert_eq!(all[mode]["ged"], 0, "{mode}");
    }
    assert_eq!(all["tree"]["ted"], 6);
}

#[test]
fn tree_mode_table_snapshot() {
    let (code, out, err) = btfsm(&["compare", FIG1, FIG3, "--mode", "tree"]);
    assert_eq!(code, 0, "{err}");
    // Times vary; the rest is deterministic.
    let out: String = out
        .lines()
        .map(|l| match l.find(" ms)") {
            Some(i) => {
                let start = l[..i].rfind(' ').map_or(i, |s| s + 1);
                format!("{}N{}\n", &l[..start], &l[i..])
            }
            None => format!("{l}\n"),
        })
        .collect();
    insta::assert_snapshot!(out);
}

/// A root Fallback turned into a Sequence: one rename, named by type.
#[test]
fn tree_mode_counts_a_type_change_as_one_rename() {
    let d = scratch("tree-rename");
    let text = std::fs::read_to_string(FIG1).expect("fig1").replace(
        "moma             = { fallback =",
        "moma             = { sequence =",
    );
    let b = d.join("b.toml");
    std::fs::write(&b, text).expect("write");
    let v = json(&[
        "compare",
        FIG1,
        b.to_str().expect("utf-8"),
        "--mode",
        "tree",
        "--format",
        "json",
        "--allow-outside-root",
    ]);
    let t = &v["tree"];
    assert_eq!(t["ted"], 1, "{t}");
    let r = &t["edit_script"]["renamed"][0];
    assert_eq!(r["a"], "moma");
    assert!(
        r["from"].as_str().expect("from").starts_with("fallback"),
        "{r}"
    );
    assert!(r["to"].as_str().expect("to").starts_with("sequence"), "{r}");
}

/// FSMs are not ordered trees: `--mode tree` is exit 2 with a hint; the
/// default report of an FSM pair has no `tree` key.
#[test]
fn tree_mode_on_an_fsm_is_exit_2_with_a_hint() {
    let (code, out, err) = btfsm(&[
        "compare",
        FIG1,
        "policies/paper/fig02-fsm.toml",
        "--mode",
        "tree",
    ]);
    assert_eq!(code, 2, "{out}");
    assert!(
        err.contains("--mode tree compares two Behavior Trees"),
        "{err}"
    );
    assert!(err.contains("hint: "), "{err}");
    let v = json(&[
        "compare",
        "policies/paper/fig02-fsm.toml",
        "policies/paper/fig04-fsm.toml",
        "--format",
        "json",
    ]);
    assert!(v.get("tree").is_none());
    let (code, _, err) = btfsm(&["compare", FIG1, FIG3, "--mode", "tree", "--dot", "x.dot"]);
    assert_eq!(code, 2);
    assert!(err.contains("--dot"), "{err}");
}

/// Past `--tree-max-work` the distance is a certified interval with a
/// script costing its upper bound, the same on every run, and
/// `stopped_by: work`; exact, `stopped_by` is null.
#[test]
fn tree_max_work_gives_an_interval() {
    let args = [
        "compare",
        FIG1,
        "policies/paper/fig07c-bt.toml",
        "--mode",
        "tree",
        "--format",
        "json",
        "--tree-max-work",
        "20",
    ];
    let v = json(&args);
    let t = &v["tree"];
    let exact = json(&args[..7])["tree"]["ted"].as_u64().expect("ted");
    assert_eq!(t["exact"], false, "{t}");
    let (lo, hi) = (
        t["lower_bound"].as_u64().expect("lo"),
        t["upper_bound"].as_u64().expect("hi"),
    );
    assert!(lo <= exact && exact <= hi, "{lo} {exact} {hi}");
    assert_eq!(script_cost(t), hi);
    assert_eq!(t["stopped_by"], "work", "{t}");
    let again = json(&args);
    assert_eq!(again["tree"]["upper_bound"], t["upper_bound"]);
    assert_eq!(again["tree"]["work"], t["work"]);
    let whole = json(&args[..7]);
    assert!(whole["tree"]["stopped_by"].is_null(), "{}", whole["tree"]);
    assert_eq!(whole["tree"]["exact"], true);
}

/// Past `--tree-max-memory` (MiB) the distance is an interval with
/// `stopped_by: memory`, however large `--tree-max-work` is.
#[test]
fn tree_max_memory_gives_an_interval_said_to_be_memory() {
    let args = [
        "compare",
        FIG1,
        "policies/paper/fig07c-bt.toml",
        "--mode",
        "tree",
        "--format",
        "json",
        "--tree-max-memory",
        "0",
        "--tree-max-work",
        "1000000000000",
    ];
    let v = json(&args);
    let t = &v["tree"];
    let exact = json(&args[..7])["tree"]["ted"].as_u64().expect("ted");
    let (lo, hi) = (
        t["lower_bound"].as_u64().expect("lo"),
        t["upper_bound"].as_u64().expect("hi"),
    );
    assert!(lo <= exact && exact < hi, "{lo} {exact} {hi}");
    assert_eq!(t["exact"], false, "{t}");
    assert_eq!(t["stopped_by"], "memory", "{t}");
    assert_eq!(script_cost(t), hi);
    let text: Vec<&str> = args
        .iter()
        .copied()
        .filter(|a| !["--format", "json"].contains(a))
        .collect();
    let (code, out, _) = btfsm(&text);
    assert_eq!(code, 0);
    assert!(out.contains("raise --tree-max-memory"), "{out}");
}

/// Markdown: the distance under the GED table and its script in a `diff`
/// block.
#[test]
fn tree_mode_in_markdown() {
    let (code, out, err) = btfsm(&["compare", FIG1, FIG3, "--format", "markdown"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains("tree edit distance (ordered, unit costs on node labels): 6"),
        "{out}"
    );
    assert!(
        out.contains(
            "> move subtree `reached-delivery` (3 nodes, 6 edits) from `deliver`[1] to `deliver`[0]"
        ),
        "{out}"
    );
}
