//! `btfsm compare` as a reviewer reads it (issue 15, points 1 and 5):
//! relabels and reorders in every format, the markdown report's "what
//! changed" opening and Mermaid diff, and the DOT diff drawing (insta
//! snapshots of Fig. 1 → Fig. 3 and of an FSM pair).

use super::*;

const FIG01: &str = "policies/paper/fig01-bt.toml";
const FIG03: &str = "policies/paper/fig03-bt.toml";
const FIG04: &str = "policies/paper/fig04-fsm.toml";
const FIG08B: &str = "policies/paper/fig08b-fsm.toml";
const ROOT_SEQUENCE: &str = "tests/fixtures/compare/fig01-root-sequence.toml";
const NO_HAND_CHECK: &str = "tests/fixtures/compare/fig01-no-hand-check.toml";
const REBOUND: &str = "tests/fixtures/compare/fig04-rebound.toml";

/// `compare A B EXTRA...`, with the search's milliseconds (the one
/// non-deterministic number) replaced by `ms`.
fn compare(a: &str, b: &str, extra: &[&str]) -> String {
    let mut args = vec!["compare", a, b];
    args.extend_from_slice(extra);
    let (code, out, err) = btfsm(&args);
    assert_eq!(code, 0, "{err}");
    out.lines()
        .map(|l| {
            let mode = ["structural", "labeled", "named"]
                .iter()
                .any(|m| l.starts_with(m) || l.starts_with(&format!("| {m} |")))
                && l.contains('[');
            // The tree distance's time, as `… (exact, 3 ms)`.
            if let Some(at) = l.find(" ms)")
                && l.starts_with("tree edit distance")
            {
                let start = l[..at].rfind(", ").map_or(at, |p| p + 2);
                return format!("{}ms{}", &l[..start], &l[at + 3..]);
            }
            match (mode, l.starts_with('|')) {
                (true, true) => {
                    let cut = l.trim_end_matches('|').trim_end().rfind('|').unwrap_or(0);
                    format!("{}| ms |", &l[..cut])
                }
                (true, false) => format!(
                    "{} ms",
                    l.trim_end().trim_end_matches(char::is_numeric).trim_end()
                ),
                _ => l.to_string(),
            }
        })
        .collect::<Vec<_>>()
        .join("\n")
}

fn dot(a: &str, b: &str, name: &str) -> String {
    let dir = std::env::temp_dir().join(format!("btfsm-cmp-report-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("tmp");
    let out = dir.join("diff.dot").display().to_string();
    let (code, _, err) = btfsm(&["compare", a, b, "--mode", "named", "--dot", &out]);
    assert_eq!(code, 0, "{err}");
    let text = std::fs::read_to_string(&out).expect("dot written");
    std::fs::remove_dir_all(&dir).expect("cleanup");
    text
}

#[test]
fn fig01_to_fig03_says_the_priority_of_deliver_changed_in_every_format() {
    let table = compare(FIG01, FIG03, &[]);
    assert!(table.contains("~ order of `deliver`: held, reached-delivery → reached-delivery, held (the priority of its children changed)"), "{table}");
    insta::assert_snapshot!("fig01_fig03_table", table);
    let md = compare(FIG01, FIG03, &["--format", "markdown"]);
    // The first thing after the title is what changed, before any table.
    let body: Vec<&str> = md.lines().skip(1).filter(|l| !l.is_empty()).collect();
    assert!(
        body[0].starts_with("**What changed** (named mapping): 1 reorder."),
        "{md}"
    );
    assert!(
        body[1].contains("order of `deliver`") && body[1].contains("priority"),
        "{md}"
    );
    insta::assert_snapshot!("fig01_fig03_markdown", md);
    let (code, json, _) = btfsm(&["compare", FIG01, FIG03, "--format", "json"]);
    assert_eq!(code, 0);
    let v: serde_json::Value = serde_json::from_str(&json).expect("json");
    for m in ["structural", "labeled", "named"] {
        assert_eq!(
            (v[m]["ged"].as_u64(), v[m]["reorders"].as_u64()),
            (Some(0), Some(1)),
            "{m}"
        );
        assert_eq!(
            v[m]["edit_script"]["reordered"][0]["after"][0],
            "reached-delivery"
        );
    }
}

#[test]
fn a_root_turned_from_fallback_to_sequence_is_reported() {
    let table = compare(FIG01, ROOT_SEQUENCE, &["--mode", "named"]);
    assert!(
        table.contains("~ type of `moma`: fallback → sequence"),
        "{table}"
    );
    let md = compare(
        FIG01,
        ROOT_SEQUENCE,
        &["--format", "markdown", "--mode", "named"],
    );
    assert!(md.contains("- type of `moma`: fallback → sequence"), "{md}");
    let (_, json, _) = btfsm(&[
        "compare",
        FIG01,
        ROOT_SEQUENCE,
        "--format",
        "json",
        "--mode",
        "named",
    ]);
    let v: serde_json::Value = serde_json::from_str(&json).expect("json");
    assert_eq!(
        (v["named"]["ged"].as_u64(), v["named"]["relabels"].as_u64()),
        (Some(0), Some(1))
    );
    assert_eq!(v["named"]["edit_script"]["relabelled"][0]["what"], "type");
}

#[test]
fn a_state_bound_to_another_skill_and_a_changed_guard_are_reported() {
    let table = compare(FIG04, REBOUND, &["--mode", "named"]);
    for want in [
        "~ skill of `Pick cube2`: Pick → Place",
        "~ arguments of `Pick cube2`: object=cube2 → at=delivery, object=cube2",
        "~ guard of `SELECTOR` -> `Pick cube2`: cube2 reached: Robot-At(target=cube2) → cube2 reached: Robot-At(target=cube3)",
    ] {
        assert!(table.contains(want), "{want}\n{table}");
    }
    let (_, json, _) = btfsm(&[
        "compare", FIG04, REBOUND, "--format", "json", "--mode", "named",
    ]);
    let v: serde_json::Value = serde_json::from_str(&json).expect("json");
    assert_eq!(
        (v["named"]["ged"].as_u64(), v["named"]["relabels"].as_u64()),
        (Some(0), Some(3))
    );
    insta::assert_snapshot!(
        "fig04_rebound_markdown",
        compare(FIG04, REBOUND, &["--format", "markdown", "--mode", "named"])
    );
}

#[test]
fn the_fsm_diff_for_a_pull_request_comment() {
    insta::assert_snapshot!(
        "fig04_fig08b_markdown",
        compare(FIG04, FIG08B, &["--format", "markdown", "--mode", "named"])
    );
    insta::assert_snapshot!("fig04_fig08b_dot", dot(FIG04, FIG08B, "fsm"));
}

#[test]
fn the_dot_diff_has_a_title_a_legend_and_marks_the_reorder() {
    let d = dot(FIG01, FIG03, "bt");
    assert!(d.contains(&format!("label=\"{FIG01} → {FIG03}\"")), "{d}");
    assert!(d.contains("cluster legend"), "{d}");
    let deliver = d
        .lines()
        .find(|l| l.trim_start().starts_with("deliver["))
        .expect("deliver");
    assert!(
        deliver.contains("order was: held, reached-delivery") && deliver.contains("darkorange3"),
        "{deliver}"
    );
    insta::assert_snapshot!("fig01_fig03_dot", d);
}

#[test]
fn a_removed_bt_child_is_drawn_in_its_old_place() {
    // `cube-in-hand` was held's first child: its ghost edge comes before
    // held -> fetch (DOT `ordering=out` draws children in edge order).
    let d = dot(FIG01, NO_HAND_CHECK, "ghost");
    let edges: Vec<&str> = d
        .lines()
        .filter(|l| l.trim_start().starts_with("held -> "))
        .collect();
    assert_eq!(edges.len(), 2, "{d}");
    assert!(
        edges[0].contains("\"cube-in-hand\"") && edges[0].contains("dashed"),
        "{d}"
    );
    assert!(edges[1].contains("fetch"), "{d}");
    // And the other way round it is added, in magenta.
    let d = dot(NO_HAND_CHECK, FIG01, "added");
    let node = d
        .lines()
        .find(|l| l.trim_start().starts_with("\"cube-in-hand\"["))
        .expect("node");
    assert!(node.contains("color=magenta"), "{node}");
    // The Mermaid diff keeps the same order.
    let md = compare(
        FIG01,
        NO_HAND_CHECK,
        &["--format", "markdown", "--mode", "named"],
    );
    let links: Vec<&str> = md
        .lines()
        .filter(|l| l.trim_start().starts_with("v3 "))
        .collect();
    assert!(links[0].contains("-.-") && links[0].contains("g0"), "{md}");
}
