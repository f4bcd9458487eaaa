//! `btfsm review` (docs/guide/review.md) on temporary git repositories of
//! two commits built from real Nav2 trees (tests/fixtures/field/bt-xml/nav2,
//! Humble and main) and small hand-written ones: the changed files found,
//! a SubTree file's change marking the tree that includes it, findings
//! that only moved not new, the base revision's gates, missing revisions,
//! hostile names shown as text, and the comment's length cap.

use std::path::{Path, PathBuf};
use std::process::Command;

const NAV2: &str = "tests/fixtures/field/bt-xml/nav2";

/// A fresh repository under the test's scratch directory.
fn repo(tag: &str) -> PathBuf {
    let d = super::common::scratch(&format!("review-{tag}"));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    git(&d, &["init", "-q", "-b", "main"]);
    d
}

/// Runs git in `dir` with a fixed identity and clock (commit ids repeat).
fn git(dir: &Path, args: &[&str]) -> String {
    let out = Command::new("git")
        .current_dir(dir)
        .args([
            "-c",
            "user.name=t",
            "-c",
            "user.email=t@example.org",
            "-c",
            "commit.gpgsign=false",
        ])
        .args(args)
        .env("GIT_AUTHOR_DATE", "2024-01-01T00:00:00Z")
        .env("GIT_COMMITTER_DATE", "2024-01-01T00:00:00Z")
        .env("GIT_CONFIG_NOSYSTEM", "1")
        .output()
        .expect("git");
    assert!(
        out.status.success(),
        "git {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

fn write(dir: &Path, rel: &str, text: &str) {
    let p = dir.join(rel);
    std::fs::create_dir_all(p.parent().unwrap()).unwrap();
    std::fs::write(p, text).unwrap();
}

fn fixture(rel: &str) -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)).unwrap()
}

fn commit(dir: &Path, msg: &str) {
    git(dir, &["add", "-A"]);
    git(dir, &["commit", "-q", "-m", msg]);
}

/// Runs btfsm in `dir`: (exit code, stdout, stderr).
fn btfsm_in(dir: &Path, args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_btfsm"))
        .current_dir(dir)
        .args(args)
        .output()
        .expect("run btfsm");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

fn json(dir: &Path, extra: &[&str]) -> (i32, serde_json::Value) {
    let mut args = vec![
        "review", "--base", "HEAD~1", "--head", "HEAD", "--format", "json",
    ];
    args.extend(extra);
    let (code, out, err) = btfsm_in(dir, &args);
    let v = serde_json::from_str(&out).unwrap_or_else(|e| panic!("{e}: {out}\n{err}"));
    (code, v)
}

fn file<'a>(v: &'a serde_json::Value, path: &str) -> &'a serde_json::Value {
    v["files"]
        .as_array()
        .unwrap()
        .iter()
        .find(|f| f["path"] == path)
        .unwrap_or_else(|| panic!("{path} not reviewed: {v:#}"))
}

const TREE: &str = r#"<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence name="S">
      <AlwaysSuccess name="a"/>
      <AlwaysSuccess name="b"/>
    </Sequence>
  </BehaviorTree>
</root>
"#;

#[test]
fn review_finds_added_removed_renamed_and_modified_policies() {
    let d = repo("changes");
    let nav = "navigate_to_pose_w_replanning_and_recovery.xml";
    write(&d, "bt/nav.xml", &fixture(&format!("{NAV2}/humble/{nav}")));
    write(&d, "bt/old_name.xml", TREE);
    write(&d, "bt/gone.xml", UNREACHABLE);
    write(&d, "README.md", "not a policy\n");
    commit(&d, "base");
    write(&d, "bt/nav.xml", &fixture(&format!("{NAV2}/main/{nav}")));
    git(&d, &["mv", "bt/old_name.xml", "bt/new_name.xml"]);
    git(&d, &["rm", "-q", "bt/gone.xml"]);
    write(&d, "bt/added.xml", &nav_fixture_small());
    write(&d, "README.md", "still not a policy\n");
    commit(&d, "head");
    let (code, v) = json(&d, &[]);
    assert_eq!(code, 0, "{v:#}");
    let statuses: Vec<(String, String)> = v["files"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| {
            (
                f["path"].as_str().unwrap().into(),
                f["status"].as_str().unwrap().into(),
            )
        })
        .collect();
    let want = [
        ("bt/added.xml", "added"),
        ("bt/gone.xml", "removed"),
        ("bt/nav.xml", "modified"),
        ("bt/new_name.xml", "renamed"),
    ];
    assert_eq!(statuses, want.map(|(a, b)| (a.to_string(), b.to_string())));
    assert_eq!(file(&v, "bt/new_name.xml")["from"], "bt/old_name.xml");
    assert_eq!(file(&v, "bt/new_name.xml")["ged"], 0);
    assert_eq!(v["other_changes"], 1, "README.md");
    // Humble → main: the numbers `compare` and `analyze` give.
    let n = file(&v, "bt/nav.xml");
    assert_eq!(n["before"]["vertices"], 18);
    assert_eq!(n["after"]["vertices"], 38);
    assert_eq!(n["delta"]["cc"], 13);
    assert_eq!(n["ged"], 48);
    assert_eq!(n["ted"]["distance"], 25);
    assert!(n["changes"].as_array().unwrap().len() >= 20);
    // The work tree is the default head; a path limits the review.
    write(
        &d,
        "bt/added.xml",
        &nav_fixture_small().replace("distance=\"1.0\"", "distance=\"2.0\""),
    );
    write(&d, "bt/untracked.xml", UNREACHABLE);
    write(&d, "elsewhere/x.xml", UNREACHABLE);
    let args = ["review", "--base", "HEAD", "--format", "json", "bt"];
    let (code, out, _) = btfsm_in(&d, &args);
    assert_eq!(code, 0);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["head"]["commit"], serde_json::Value::Null);
    assert_eq!(v["files"].as_array().unwrap().len(), 2, "{v:#}");
    assert_eq!(file(&v, "bt/added.xml")["status"], "modified");
    assert_eq!(file(&v, "bt/untracked.xml")["status"], "added");
}

/// A small real Nav2 tree (Apache-2.0, tests/fixtures/corpus).
fn nav_fixture_small() -> String {
    fixture("tests/fixtures/corpus/bt-xml/nav2/navigate_w_replanning_distance.xml")
}

#[test]
fn a_changed_subtree_file_marks_the_tree_that_includes_it() {
    let d = repo("subtree");
    let main = r#"<root BTCPP_format="4" main_tree_to_execute="Main">
  <include path="sub/sub.xml"/>
  <BehaviorTree ID="Main">
    <Sequence>
      <SubTree ID="Sub"/>
      <AlwaysSuccess/>
    </Sequence>
  </BehaviorTree>
</root>
"#;
    let sub = r#"<root BTCPP_format="4">
  <BehaviorTree ID="Sub">
    <Sequence>
      <AlwaysSuccess/>
    </Sequence>
  </BehaviorTree>
</root>
"#;
    write(&d, "main.xml", main);
    write(&d, "sub/sub.xml", sub);
    write(&d, "other.xml", TREE);
    commit(&d, "base");
    write(
        &d,
        "sub/sub.xml",
        &sub.replace(
            "<AlwaysSuccess/>",
            "<AlwaysSuccess/>\n      <AlwaysFailure/>",
        ),
    );
    commit(&d, "head");
    let (code, v) = json(&d, &[]);
    assert_eq!(code, 0);
    let m = file(&v, "main.xml");
    assert_eq!(m["status"], "dependency");
    assert_eq!(m["via"], serde_json::json!(["sub/sub.xml"]));
    assert_eq!(m["delta"]["vertices"], 1, "{m:#}");
    assert_eq!(file(&v, "sub/sub.xml")["status"], "modified");
    assert_eq!(
        v["files"].as_array().unwrap().len(),
        2,
        "other.xml is untouched"
    );
}

const UNREACHABLE: &str = r#"<root BTCPP_format="4" main_tree_to_execute="Main">
  <BehaviorTree ID="Main">
    <Sequence name="S">
      <Fallback name="F">
        <AlwaysSuccess name="yes"/>
        <AlwaysFailure name="never"/>
      </Fallback>
    </Sequence>
  </BehaviorTree>
</root>
"#;

#[test]
fn a_finding_that_only_moved_lines_is_not_new() {
    let d = repo("moved");
    write(&d, "t.xml", UNREACHABLE);
    commit(&d, "base");
    let moved = UNREACHABLE.replace(
        "<root BTCPP_format=\"4\"",
        "<!-- one -->\n<!-- two -->\n\n<root BTCPP_format=\"4\"",
    );
    write(&d, "t.xml", &moved);
    commit(&d, "moved");
    let (code, v) = json(&d, &[]);
    assert_eq!(code, 0);
    let f = file(&v, "t.xml");
    assert_eq!(f["new_findings"], serde_json::json!([]), "{f:#}");
    assert_eq!(f["fixed_findings"], 0);
    // A second unreachable child is new, and only it.
    let more = moved.replace(
        "<AlwaysFailure name=\"never\"/>",
        "<AlwaysFailure name=\"never\"/>\n      </Fallback>\n      <Fallback name=\"G\">\n        <AlwaysSuccess name=\"yes2\"/>\n        <AlwaysFailure name=\"never2\"/>",
    );
    write(&d, "t.xml", &more);
    commit(&d, "more");
    let (_, v) = json(&d, &[]);
    let new = file(&v, "t.xml")["new_findings"]
        .as_array()
        .unwrap()
        .clone();
    assert_eq!(new.len(), 1, "{new:#?}");
    assert_eq!(new[0]["code"], "unreachable-child");
    assert!(
        new[0]["message"].as_str().unwrap().contains("never2"),
        "{new:#?}"
    );
}

#[test]
fn gates_of_the_base_revision_fail_with_exit_1() {
    let d = repo("gates");
    let nav = "navigate_to_pose_w_replanning_and_recovery.xml";
    write(&d, "nav.xml", &fixture(&format!("{NAV2}/humble/{nav}")));
    write(
        &d,
        "btfsm.toml",
        "[review]\nmax-increase = { cc = 5, nodes = 100 }\nmax = { ged = 1000 }\nfail-on = [\"unreachable-child\"]\n",
    );
    commit(&d, "base");
    write(&d, "nav.xml", &fixture(&format!("{NAV2}/main/{nav}")));
    // The pull request loosens its own gates: the base's still hold.
    write(&d, "btfsm.toml", "[review]\n");
    commit(&d, "head");
    let (code, v) = json(&d, &[]);
    assert_eq!(code, 1, "{v:#}");
    let failures = file(&v, "nav.xml")["gate_failures"]
        .as_array()
        .unwrap()
        .clone();
    assert_eq!(failures.len(), 1, "{failures:#?}");
    assert_eq!(failures[0]["gate"], "max-increase.cc");
    assert_eq!(v["gate_failures"], 1);
    let (code, _, err) = btfsm_in(&d, &["review", "--base", "HEAD~1", "--head", "HEAD"]);
    assert_eq!(code, 1);
    assert!(err.contains("1 gate failure"), "{err}");
    // `--config FILE` is read instead of the base's btfsm.toml.
    let loose = super::common::scratch("gates-config").join("btfsm.toml");
    std::fs::write(
        &loose,
        "[review]
max-increase = { cc = 50 }
",
    )
    .unwrap();
    let (code, _, err) = btfsm_in(
        &d,
        &[
            "review",
            "--base",
            "HEAD~1",
            "--head",
            "HEAD",
            "--config",
            loose.to_str().unwrap(),
        ],
    );
    assert_eq!(code, 0, "{err}");
    // A bad gate is a positioned error, exit 2.
    write(&d, "btfsm.toml", "[review]\nmax = { cyclomatic = 3 }\n");
    commit(&d, "bad gate");
    write(&d, "nav.xml", "<root/>\n");
    commit(&d, "after bad gate");
    let (code, _, err) = btfsm_in(&d, &["review", "--base", "HEAD~1", "--head", "HEAD"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("unknown metric `cyclomatic`"), "{err}");
}

#[test]
fn a_missing_revision_or_repository_exits_2_with_a_hint() {
    let d = repo("missing");
    write(&d, "t.xml", TREE);
    commit(&d, "one");
    write(&d, "t.xml", UNREACHABLE);
    commit(&d, "two");
    let (code, _, err) = btfsm_in(&d, &["review", "--base", "no-such-branch"]);
    assert_eq!(code, 2);
    assert!(
        err.contains("--base `no-such-branch`: no such commit"),
        "{err}"
    );
    // An option-like revision is a revision, never an option.
    let (code, _, err) = btfsm_in(&d, &["review", "--base=--output=/tmp/x"]);
    assert_eq!(code, 2);
    assert!(err.contains("no such commit"), "{err}");
    // A shallow clone says how to deepen it.
    let shallow = d.with_file_name(format!(
        "{}-shallow",
        d.file_name().unwrap().to_string_lossy()
    ));
    let _ = std::fs::remove_dir_all(&shallow);
    let url = format!("file://{}", d.display());
    git(
        d.parent().unwrap(),
        &[
            "clone",
            "-q",
            "--depth",
            "1",
            &url,
            shallow.to_str().unwrap(),
        ],
    );
    let (code, _, err) = btfsm_in(&shallow, &["review", "--base", "HEAD~1"]);
    assert_eq!(code, 2);
    assert!(
        err.contains("git fetch --unshallow") && err.contains("--deepen"),
        "{err}"
    );
    // Not a repository.
    let outside = std::env::temp_dir();
    let (code, _, err) = btfsm_in(&outside, &["review"]);
    assert_eq!(code, 2);
    assert!(err.contains("not in a git repository"), "{err}");
}

/// Names a stranger's pull request may hold.
const HOSTILE: &str = "x](https://evil.example) <img src=x onerror=alert(1)> @octocat %%{init: {'theme':'dark'}}%% click n1 call alert() `code` | cell";

#[test]
fn hostile_names_appear_only_as_text() {
    let d = repo("hostile");
    let attr = HOSTILE
        .replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;");
    let tree = TREE.replace("name=\"b\"", &format!("name=\"{attr}\""));
    let fname = "bt/<b>evil</b> [l](https://e.example) @team %%{init}%%.xml";
    write(&d, fname, TREE);
    write(&d, "bt/ok.xml", TREE);
    commit(&d, "base");
    write(&d, fname, &tree);
    write(&d, "bt/ok.xml", &tree.replace("name=\"a\"", "name=\"a2\""));
    commit(&d, "head");
    let (code, md, err) = btfsm_in(
        &d,
        &[
            "review", "--base", "HEAD~1", "--head", "HEAD", "--format", "markdown",
        ],
    );
    assert_eq!(code, 0, "{err}");
    assert!(md.starts_with("<!-- btfsm-review -->\n"));
    let (prose, mermaid) = split_markdown(&md);
    for raw in ["<img", "<b>", "](https://", "@octocat", "@team", "%%{"] {
        assert!(
            !prose.contains(raw),
            "{raw} reached the comment's prose:\n{prose}"
        );
    }
    assert!(!mermaid.is_empty());
    for line in mermaid.lines() {
        let l = line.trim_start();
        assert!(!l.starts_with("click") && !l.contains("%%{"), "{line}");
    }
    let base = git(&d, &["rev-parse", "--short=12", "HEAD~1"]);
    let head = git(&d, &["rev-parse", "--short=12", "HEAD"]);
    let md = md.replace(base.trim(), "BASE").replace(head.trim(), "HEAD");
    insta::assert_snapshot!("review_hostile_markdown", md);
}

/// The markdown outside code (fenced blocks, code spans, `<code>`
/// elements), and the text of its Mermaid blocks.
fn split_markdown(md: &str) -> (String, String) {
    let (mut prose, mut mermaid) = (String::new(), String::new());
    let mut fence: Option<(String, bool)> = None;
    for line in md.lines() {
        let ticks: String = line.chars().take_while(|&c| c == '`').collect();
        match &fence {
            None if ticks.len() >= 3 => fence = Some((ticks, line.ends_with("mermaid"))),
            None => {
                prose.push_str(&strip_code(line));
                prose.push('\n');
            }
            Some((f, _)) if line == f.as_str() => fence = None,
            Some((_, true)) => {
                mermaid.push_str(line);
                mermaid.push('\n');
            }
            Some(_) => {}
        }
    }
    (prose, mermaid)
}

/// A line without its code spans and `<code>` elements.
fn strip_code(line: &str) -> String {
    let mut out = String::new();
    let mut rest = line;
    loop {
        let (a, b) = (rest.find('`'), rest.find("<code>"));
        match (a, b) {
            (Some(i), b) if b.is_none_or(|j| i < j) => {
                out.push_str(&rest[..i]);
                let n = rest[i..].chars().take_while(|&c| c == '`').count();
                let fence = "`".repeat(n);
                let after = &rest[i + n..];
                match after.find(&fence) {
                    Some(k) => rest = &after[k + n..],
                    None => return out,
                }
            }
            (_, Some(j)) => {
                out.push_str(&rest[..j]);
                match rest[j..].find("</code>") {
                    Some(k) => rest = &rest[j + k + 7..],
                    None => return out,
                }
            }
            _ => {
                out.push_str(rest);
                return out;
            }
        }
    }
}

#[test]
fn the_comment_stays_within_65536_characters() {
    let d = repo("cap");
    let nav = fixture(&format!(
        "{NAV2}/main/navigate_to_pose_w_replanning_and_recovery.xml"
    ));
    for i in 0..120 {
        write(&d, &format!("bt/t{i:03}.xml"), &nav);
    }
    commit(&d, "base");
    let changed = fixture(&format!(
        "{NAV2}/humble/navigate_to_pose_w_replanning_and_recovery.xml"
    ));
    for i in 0..120 {
        write(&d, &format!("bt/t{i:03}.xml"), &changed);
    }
    commit(&d, "head");
    let (code, md, err) = btfsm_in(
        &d,
        &[
            "review", "--base", "HEAD~1", "--head", "HEAD", "--format", "markdown",
        ],
    );
    assert_eq!(code, 0, "{err}");
    let n = md.chars().count();
    assert!(n <= 65_536, "{n} characters");
    assert!(n > 30_000, "{n}: the cap is used, not wasted");
    assert!(
        md.contains("Left out to stay within GitHub's 65536 characters"),
        "{md}"
    );
    assert_eq!(
        md.matches("<details>").count(),
        md.matches("</details>").count()
    );
}

#[test]
fn sarif_and_svg_outputs_are_written_inside_the_repository() {
    let d = repo("outputs");
    write(&d, "t.xml", TREE);
    commit(&d, "base");
    write(&d, "t.xml", UNREACHABLE);
    commit(&d, "head");
    let (code, _, err) = btfsm_in(
        &d,
        &[
            "review",
            "--base",
            "HEAD~1",
            "--head",
            "HEAD",
            "--sarif",
            "review.sarif",
            "--svg-dir",
            "out/svg",
        ],
    );
    assert_eq!(code, 0, "{err}");
    let sarif: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(d.join("review.sarif")).unwrap()).unwrap();
    let results = sarif["runs"][0]["results"].as_array().unwrap();
    assert!(
        results.iter().any(|r| r["ruleId"] == "unreachable-child"),
        "{sarif:#}"
    );
    assert_eq!(
        results[0]["locations"][0]["physicalLocation"]["artifactLocation"]["uri"],
        "t.xml"
    );
    if btfsm_render_installed() {
        let svg = std::fs::read_to_string(d.join("out/svg/1-t.svg")).unwrap();
        assert!(svg.contains("<svg"));
    } else {
        assert!(err.contains("Graphviz"), "{err}");
    }
    // Outputs do not leave the repository through a symbolic link.
    let outside = d.with_file_name(format!(
        "{}-outside",
        d.file_name().unwrap().to_string_lossy()
    ));
    std::fs::create_dir_all(&outside).unwrap();
    let _ = std::fs::remove_file(d.join("link"));
    std::os::unix::fs::symlink(&outside, d.join("link")).unwrap();
    let (code, _, err) = btfsm_in(
        &d,
        &[
            "review",
            "--base",
            "HEAD~1",
            "--head",
            "HEAD",
            "--sarif",
            "link/escape.sarif",
        ],
    );
    assert_eq!(code, 2, "{err}");
    assert!(!outside.join("escape.sarif").exists());
}

fn btfsm_render_installed() -> bool {
    Command::new("dot")
        .arg("-V")
        .output()
        .is_ok_and(|o| o.status.success())
}
