//! `btfsm validate`: BehaviorTree.CPP files given together (a folder, or
//! named one by one) resolve each other's SubTrees, as `analyze` reads them
//! and BehaviorTree.CPP's factory registers every file it loads; the hint
//! of a SubTree no file defines does not suggest the command just run.

use super::*;
use crate::common::scratch;

#[test]
fn validate_resolves_subtrees_across_a_folder_and_the_files_given_together() {
    // The issue: `btfsm validate tests/fixtures/btcpp-projects/pick` failed
    // on the project's own fixture.
    let (code, _, err) = btfsm(&["validate", "tests/fixtures/btcpp-projects/pick"]);
    assert_eq!(code, 0, "{err}");
    for f in ["pick.xml", "approach.xml", "localize.xml"] {
        assert!(err.contains(&format!("{f}: ok (bt")), "{err}");
    }
    let dir = "tests/fixtures/btcpp-projects/pick";
    let (code, _, err) = btfsm(&[
        "validate",
        &format!("{dir}/pick.xml"),
        &format!("{dir}/subtrees/approach.xml"),
        &format!("{dir}/subtrees/localize.xml"),
    ]);
    assert_eq!(code, 0, "{err}");
    // `--tree` picks the files that define it, the others are companions.
    let (code, _, err) = btfsm(&["validate", dir, "--tree", "Approach"]);
    assert_eq!(code, 0, "{err}");
    assert!(
        err.contains("approach.xml: ok") && !err.contains("pick.xml: ok"),
        "{err}"
    );
}

#[test]
fn a_subtree_no_file_given_defines_has_a_hint_that_is_not_the_command_just_run() {
    // Given together and still missing: the hint says none of them
    // defines it, not "give it with this one".
    let (code, _, err) = btfsm(&["validate", "tests/fixtures/btcpp-projects/missing"]);
    assert_eq!(code, 2);
    assert!(
        err.contains("unknown tree `Dock` in `<SubTree>`")
            && err.contains("none of the 2 BehaviorTree.CPP files given together defines it")
            && !err.contains("btfsm analyze"),
        "{err}"
    );
    assert!(err.contains("patrol.xml: ok"), "{err}");
    // Alone: give the file that defines it too (no command named).
    let d = scratch("validate-alone");
    let main = d.join("main.xml");
    std::fs::write(
        &main,
        r#"<root BTCPP_format="4"><BehaviorTree ID="Main"><SubTree ID="Dock"/></BehaviorTree></root>"#,
    )
    .unwrap();
    let (code, _, err) = btfsm(&["validate", main.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(
        err.contains("given together with this one (both files, or their folder)")
            && !err.contains("btfsm analyze"),
        "{err}"
    );
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn among_several_files_defining_a_subtree_the_nearest_is_read() {
    // Two robot configurations of one workspace each define "Open
    // Gripper" (MoveIt Studio's layout): each objective reads its own
    // package's; files nearest alike stay an error.
    let d = scratch("validate-nearest");
    let tree = |id: &str, body: &str| {
        format!(
            r#"<root BTCPP_format="4" main_tree_to_execute="{id}"><BehaviorTree ID="{id}">{body}</BehaviorTree></root>"#
        )
    };
    for pkg in ["arm_a", "arm_b"] {
        let o = d.join(pkg).join("objectives");
        std::fs::create_dir_all(&o).unwrap();
        std::fs::write(
            o.join("open_gripper.xml"),
            tree("Open Gripper", "<AlwaysSuccess/>"),
        )
        .unwrap();
        std::fs::write(
            o.join(format!("pick_{pkg}.xml")),
            tree(&format!("Pick {pkg}"), r#"<SubTree ID="Open Gripper"/>"#),
        )
        .unwrap();
    }
    let (code, _, err) = btfsm(&["validate", d.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    // A third definition beside arm_a's: arm_a's objective cannot choose.
    std::fs::write(
        d.join("arm_a/objectives/open_gripper_copy.xml"),
        tree("Open Gripper", "<AlwaysFailure/>"),
    )
    .unwrap();
    let (code, _, err) = btfsm(&["validate", d.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(
        err.contains(
            "tree `Open Gripper` in `<SubTree>` is defined by several files given together"
        ),
        "{err}"
    );
    assert!(err.contains("pick_arm_b.xml: ok"), "{err}");
    std::fs::remove_dir_all(&d).ok();
}

#[test]
fn only_policies_skips_the_files_named_that_hold_no_policy() {
    // A pre-commit hook is given every changed .xml and .toml file: with
    // --only-policies a ROS package.xml and a Cargo.toml are skipped as a
    // directory walk skips them; a policy that does not load still fails.
    let d = scratch("validate-only-policies");
    let package = d.join("package.xml");
    std::fs::write(&package, "<package format=\"3\"><name>x</name></package>").unwrap();
    let cargo = d.join("Cargo.toml");
    std::fs::write(&cargo, "[package]\nname = \"x\"\n").unwrap();
    let broken = d.join("broken.xml");
    std::fs::write(&broken, "<root BTCPP_format=\"4\"><BehaviorTree ID=\"M\">").unwrap();
    let (p, c, b) = (
        package.to_str().unwrap(),
        cargo.to_str().unwrap(),
        broken.to_str().unwrap(),
    );
    let good = "policies/paper/fig01-bt.toml";
    let (code, _, err) = btfsm(&["validate", p, c, good]);
    assert_eq!(code, 2, "named, they are read: {err}");
    for cmd in ["validate", "lint"] {
        let (code, _, err) = btfsm(&[cmd, "--only-policies", p, c, good]);
        assert_eq!(code, 0, "{cmd}: {err}");
        let (code, _, _) = btfsm(&[cmd, "--only-policies", p, c]);
        assert_eq!(code, 0, "{cmd}: nothing to check is no failure");
        let (code, out, err) = btfsm(&[cmd, "--only-policies", p, b]);
        assert_eq!(code, 2, "{cmd}: {out}{err}");
    }
    std::fs::remove_dir_all(&d).ok();
}
