//! `btfsm lint`: every rule fires on its bad fixture (tests/fixtures/lint/
//! CODE/bad.*) and stays silent on its good one; the bad fixtures' text
//! output is a snapshot; levels, exit codes, JSON and SARIF.

use super::*;

const LINT: &str = "tests/fixtures/lint";

fn fixture(code: &str, which: &str) -> String {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join(LINT).join(code);
    let f = std::fs::read_dir(&dir)
        .unwrap_or_else(|_| panic!("{code}: no fixture folder {}", dir.display()))
        .flatten()
        .map(|e| e.path())
        .find(|p| p.file_stem().is_some_and(|s| s == which))
        .unwrap_or_else(|| panic!("{code}: no {which}.* fixture"));
    format!("{LINT}/{code}/{}", f.file_name().unwrap().to_string_lossy())
}

/// The codes `btfsm lint --list` prints.
fn codes() -> Vec<String> {
    let (code, out, err) = btfsm(&["lint", "--list"]);
    assert_eq!(code, 0, "{err}");
    out.lines()
        .skip(1)
        .filter_map(|l| l.split_whitespace().next().map(str::to_string))
        .collect()
}

#[test]
fn every_rule_fires_on_its_bad_fixture_and_not_on_its_good_one() {
    let all = codes();
    assert!(all.len() >= 8, "{all:?}");
    for code in &all {
        let (_, out, err) = btfsm(&["lint", &fixture(code, "bad"), "--format", "json"]);
        let v: serde_json::Value =
            serde_json::from_str(&out).unwrap_or_else(|_| panic!("{code}: {out}{err}"));
        let found: Vec<&str> = v
            .as_array()
            .unwrap()
            .iter()
            .filter_map(|f| f["code"].as_str())
            .collect();
        assert!(
            found.contains(&code.as_str()),
            "{code} silent on its bad fixture: {found:?}"
        );
        let (_, out, _) = btfsm(&["lint", &fixture(code, "good"), "--format", "json"]);
        let v: serde_json::Value = serde_json::from_str(&out).unwrap();
        let found: Vec<&str> = v
            .as_array()
            .unwrap()
            .iter()
            .filter_map(|f| f["code"].as_str())
            .collect();
        assert!(
            !found.contains(&code.as_str()),
            "{code} fires on its good fixture"
        );
        // The text a user reads, per rule.
        let (_, text, _) = btfsm(&["lint", &fixture(code, "bad")]);
        insta::assert_snapshot!(format!("lint_{}", code.replace('-', "_")), text);
        // Every rule is documented with a bad and a good example.
        let docs =
            std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/lint.md"))
                .unwrap();
        let section = docs
            .split("\n## ")
            .find(|s| s.starts_with(&format!("`{code}`")))
            .unwrap_or_else(|| panic!("docs/lint.md has no section `{code}`"));
        assert!(
            section.contains("Bad:") && section.contains("Good:"),
            "{code}: docs need a bad and a good example"
        );
    }
}

#[test]
fn lint_exit_codes_levels_and_sarif() {
    let bad = fixture("chattering-precondition-order", "bad");
    let (code, out, _) = btfsm(&["lint", &bad]);
    assert_eq!(code, 1, "an error-level finding: exit 1\n{out}");
    assert!(
        out.contains("error[chattering-precondition-order]"),
        "{out}"
    );
    let (code, _, _) = btfsm(&["lint", &bad, "--warn", "chattering-precondition-order"]);
    assert_eq!(code, 0);
    let (code, out, _) = btfsm(&["lint", &bad, "--allow", "chattering-precondition-order"]);
    assert_eq!(code, 0);
    assert!(out.starts_with("0 errors, 0 warnings"), "{out}");
    let (code, _, err) = btfsm(&["lint", &bad, "--deny", "chatering"]);
    assert_eq!(code, 2);
    assert!(err.contains("unknown lint `chatering`"), "{err}");
    let (code, out, _) = btfsm(&["lint", &bad, "--format", "sarif"]);
    assert_eq!(code, 1);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["version"], "2.1.0");
    let r = &v["runs"][0]["results"][0];
    assert_eq!(r["ruleId"], "chattering-precondition-order");
    assert_eq!(
        r["locations"][0]["physicalLocation"]["region"]["startLine"],
        10
    );
    // A file that does not load (for a reason no rule names): exit 2, the
    // others still linted.
    let (code, out, err) = btfsm(&["lint", "tests/fixtures/invalid/dangling-target.toml", &bad]);
    assert_eq!(code, 2, "{err}");
    assert!(out.contains("chattering-precondition-order"), "{out}");
}

#[test]
fn the_paper_policies_have_one_lint_error_fig_3() {
    let (code, out, _) = btfsm(&["lint", "policies/paper", "--format", "json"]);
    assert_eq!(code, 1);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let errors: Vec<String> = v
        .as_array()
        .unwrap()
        .iter()
        .filter(|f| f["level"] == "error")
        .map(|f| format!("{} {}", f["file"], f["code"]))
        .collect();
    assert_eq!(
        errors,
        ["\"policies/paper/fig03-bt.toml\" \"chattering-precondition-order\""]
    );
}

#[test]
fn lint_on_the_bundled_real_files_reports_what_docs_lint_md_lists() {
    // docs/lint.md, "Findings on the bundled real files": three, each
    // explained there; none on a state a sibling parallel region leaves.
    // Every file loads (Nav2's trees with the nav2_tree_nodes.xml beside
    // them, unknown leaves as actions): no error on stderr, exit 1 for the
    // two error-level findings, not 2.
    let (code, out, err) = btfsm(&["lint", "tests/fixtures/corpus", "--format", "json"]);
    assert_eq!(code, 1, "{err}");
    assert!(err.is_empty(), "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    // Nav2's trees, read with the model beside them, get what the test
    // with `--nodes-model` counts (no error; the model's optional ports and
    // the application's entries; `lint_on_nav2_with_its_model_...`).
    let all = v.as_array().unwrap();
    let nav2: Vec<&serde_json::Value> = all
        .iter()
        .filter(|f| f["file"].as_str().unwrap().contains("/nav2/"))
        .collect();
    let count = |c: &str| nav2.iter().filter(|f| f["code"] == c).count();
    assert_eq!(
        (
            nav2.len(),
            count("missing-required-port"),
            count("key-never-read")
        ),
        (128, 82, 46)
    );
    let found: Vec<String> = all
        .iter()
        .filter(|f| !f["file"].as_str().unwrap().contains("/nav2/"))
        .map(|f| {
            format!(
                "{} {} {}",
                f["code"].as_str().unwrap(),
                f["file"].as_str().unwrap().rsplit('/').next().unwrap(),
                f["at"].as_str().unwrap()
            )
        })
        .collect();
    assert_eq!(
        found,
        [
            "key-never-read subtree_with_remapping.xml BehaviorTree/0",
            "state-without-exit parallel-01.scxml end",
            "state-without-exit deep-initial.scxml uber/s2"
        ]
    );
}

#[test]
fn a_load_error_with_a_code_is_a_finding() {
    let dir = std::env::temp_dir().join(format!("btfsm-lint-load-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let toml = dir.join("empty.toml");
    std::fs::write(
        &toml,
        "kind = \"bt\"\nroot = \"r\"\n[nodes]\nr = { sequence = [\"a\", \"f\"] }\na = { action = \"A\" }\nf = { fallback = [] }\n",
    )
    .unwrap();
    let par = fixture("parallel-threshold", "bad");
    // A coded load error alone: a finding, exit 1, in JSON and SARIF too.
    for (file, code) in [
        (par.as_str(), "parallel-threshold"),
        (toml.to_str().unwrap(), "empty-composite"),
    ] {
        let (rc, out, err) = btfsm(&["lint", file, "--format", "json"]);
        assert_eq!(rc, 1, "{out}{err}");
        let v: serde_json::Value = serde_json::from_str(&out).unwrap();
        assert_eq!(v[0]["code"], code, "{out}");
        assert_eq!(v[0]["level"], "error");
        assert!(v[0]["line"].as_u64().is_some_and(|l| l > 0), "{out}");
        assert!(err.is_empty(), "{err}");
        let (rc, sarif, _) = btfsm(&["lint", file, "--format", "sarif"]);
        assert_eq!(rc, 1);
        assert!(
            sarif.contains(&format!("\"ruleId\": \"{code}\"")),
            "{sarif}"
        );
    }
    // Allowed: not reported (the file is not linted further).
    let (rc, out, _) = btfsm(&["lint", &par, "--allow", "parallel-threshold"]);
    assert_eq!(rc, 0, "{out}");
    // A load error no rule names still means exit 2, beside the finding.
    let broken = dir.join("broken.xml");
    std::fs::write(&broken, "<root BTCPP_format=\"4\"><BehaviorTree ID=\"M\">").unwrap();
    let (rc, out, err) = btfsm(&["lint", &par, broken.to_str().unwrap(), "--format", "json"]);
    assert_eq!(rc, 2, "{out}{err}");
    assert!(
        out.contains("parallel-threshold") && err.contains("broken.xml"),
        "{out}{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn reactive_siblings_known_to_return_at_once_do_not_count() {
    // Nav2's CheckIfNewPathNeeded: TruncatePathLocal returns at once, so one
    // action under the ReactiveSequence may run; two planners may both run.
    let dir = std::env::temp_dir().join(format!("btfsm-lint-sync-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let tree = |a: &str, b: &str| {
        format!(
            r#"<root BTCPP_format="4" main_tree_to_execute="M"><BehaviorTree ID="M"><ReactiveSequence><{a}/><{b}/></ReactiveSequence></BehaviorTree></root>"#
        )
    };
    let quiet = dir.join("quiet.xml");
    std::fs::write(&quiet, tree("TruncatePathLocal", "ComputePathToPose")).unwrap();
    let loud = dir.join("loud.xml");
    std::fs::write(&loud, tree("ComputePathToPose", "FollowPath")).unwrap();
    let (code, out, err) = btfsm(&["lint", quiet.to_str().unwrap()]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(!out.contains("reactive-async-siblings"), "{out}");
    let (code, out, err) = btfsm(&["lint", loud.to_str().unwrap()]);
    assert_eq!(code, 0, "a warning: {out}{err}");
    assert!(out.contains("warning[reactive-async-siblings]"), "{out}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn lint_resolves_subtrees_across_the_files_given_together() {
    // tests/fixtures/btcpp-projects/pick: pick.xml uses `Approach`, which
    // subtrees/approach.xml defines (and that one uses `Localize`).
    let (code, out, err) = btfsm(&["lint", "tests/fixtures/btcpp-projects/pick"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(err.is_empty(), "{err}");
    assert!(out.contains("in 3 files"), "{out}");
    // Alone, pick.xml does not load: its SubTree is in another file.
    let (code, _, err) = btfsm(&["lint", "tests/fixtures/btcpp-projects/pick/pick.xml"]);
    assert_eq!(code, 2);
    assert!(err.contains("unknown tree `Approach`"), "{err}");
}

#[test]
fn lint_on_nav2_with_its_model_reports_what_docs_lint_md_lists() {
    // docs/lint.md, "Findings on the bundled real files", Nav2 with its
    // model: no error; the model's optional ports; the application's
    // entries; three selectors whose output FollowPath does not take.
    let (code, out, err) = btfsm(&[
        "lint",
        "tests/fixtures/corpus/bt-xml/nav2",
        "--nodes-model",
        "tests/fixtures/corpus/bt-xml/nav2/nav2_tree_nodes.xml",
        "--format",
        "json",
    ]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let found = v.as_array().unwrap();
    let count = |c: &str| found.iter().filter(|f| f["code"] == c).count();
    assert_eq!(found.iter().filter(|f| f["level"] == "error").count(), 0);
    assert_eq!(count("missing-required-port"), 82);
    assert_eq!(count("key-never-read"), 46);
    assert_eq!(count("read-before-write"), 0);
    let selectors: Vec<&str> = found
        .iter()
        .filter(|f| f["code"] == "key-never-read")
        .filter_map(|f| f["message"].as_str())
        .filter(|m| m.contains("{selected_"))
        .collect();
    assert_eq!(selectors.len(), 3, "{selectors:?}");
}

#[cfg(unix)]
#[test]
fn a_symlinked_nodes_model_beside_a_tree_is_not_read() {
    // Only regular files of the folder are read as models: a stranger's
    // `*tree_nodes*.xml` symlink to a file outside is skipped, never echoed.
    let dir = std::env::temp_dir().join(format!("btfsm-lint-symlink-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let outside = std::env::temp_dir().join(format!("btfsm-secret-{}.txt", std::process::id()));
    std::fs::write(&outside, "SECRET-LINE not xml\n").unwrap();
    std::os::unix::fs::symlink(&outside, dir.join("evil_tree_nodes.xml")).unwrap();
    std::fs::write(
        dir.join("tree.xml"),
        r#"<root BTCPP_format="4" main_tree_to_execute="M"><BehaviorTree ID="M"><Sequence><Approach/></Sequence></BehaviorTree></root>"#,
    )
    .unwrap();
    let (code, out, err) = btfsm(&["lint", dir.to_str().unwrap()]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(
        !out.contains("SECRET") && !err.contains("SECRET"),
        "{out}{err}"
    );
    std::fs::remove_dir_all(&dir).ok();
    std::fs::remove_file(&outside).ok();
}
