//! Outputs confined like reads (issue 33): in a work tree a pull request
//! controls, a committed symlink must not turn an output into a write of
//! `.git/hooks/*` or of a file outside the tree, whichever command writes
//! it; `--allow-outside-root` lifts the rule, and a replaced file is never
//! left executable.

use super::*;
use common::btfsm_in;
use std::os::unix::fs::{PermissionsExt, symlink};

/// A scratch folder holding `repo/` (a git work tree with an executable
/// hook) and `outside/` beside it.
struct Tree {
    top: PathBuf,
    repo: PathBuf,
    outside: PathBuf,
}

const HOOK: &str = "#!/bin/sh\necho the real hook\n";

impl Tree {
    fn new(tag: &str) -> Tree {
        let top = std::env::temp_dir().join(format!("btfsm-confine-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&top);
        let repo = top.join("repo");
        let outside = top.join("outside");
        std::fs::create_dir_all(repo.join(".git/hooks")).expect("repo");
        std::fs::create_dir_all(repo.join("sub")).expect("sub");
        std::fs::create_dir_all(&outside).expect("outside");
        let hook = repo.join(".git/hooks/pre-commit");
        std::fs::write(&hook, HOOK).expect("hook");
        std::fs::set_permissions(&hook, std::fs::Permissions::from_mode(0o755)).expect("chmod");
        std::fs::write(outside.join("victim.txt"), "keep").expect("victim");
        std::fs::set_permissions(
            outside.join("victim.txt"),
            std::fs::Permissions::from_mode(0o755),
        )
        .expect("chmod");
        for (link, to) in [
            ("diff.dot", ".git/hooks/pre-commit"),
            ("new.dot", ".git/hooks/post-merge"),
            ("out.dot", "../outside/victim.txt"),
            ("dangling.dot", "../outside/new.txt"),
            ("dir", "../outside"),
            ("hooks", ".git/hooks"),
            ("loop.dot", "loop.dot"),
            ("ok.dot", "sub/real.dot"),
        ] {
            symlink(to, repo.join(link)).expect("symlink");
        }
        Tree { top, repo, outside }
    }

    /// What `outside/` and `.git/hooks/` hold.
    fn untouched(&self) {
        let mut names: Vec<String> = std::fs::read_dir(&self.outside)
            .expect("outside")
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        assert_eq!(names, ["victim.txt"], "written outside the work tree");
        assert_eq!(
            std::fs::read_to_string(self.outside.join("victim.txt")).expect("victim"),
            "keep"
        );
        let hooks: Vec<String> = std::fs::read_dir(self.repo.join(".git/hooks"))
            .expect("hooks")
            .flatten()
            .map(|e| e.file_name().to_string_lossy().into_owned())
            .collect();
        assert_eq!(hooks, ["pre-commit"], "written into .git/hooks");
        let hook = self.repo.join(".git/hooks/pre-commit");
        assert_eq!(std::fs::read_to_string(&hook).expect("hook"), HOOK);
    }
}

impl Drop for Tree {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.top);
    }
}

fn abs(rel: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join(rel)
        .display()
        .to_string()
}

/// Every writer, each given `out` as its output path.
fn writers(out: &str) -> Vec<Vec<String>> {
    let fig01 = abs("policies/paper/fig01-bt.toml");
    let fig03 = abs("policies/paper/fig03-bt.toml");
    let scenario = abs("policies/scenarios/exp1-pick-fails.toml");
    let log = abs("tests/fixtures/logs/fig01.btlog");
    let v = |a: &[&str]| a.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    vec![
        v(&["dot", &fig01, "-o", out]),
        v(&["convert", &fig01, "--to", "hfsm", "-o", out]),
        v(&["compare", &fig01, &fig03, "--mode", "named", "--dot", out]),
        v(&["sim", &scenario, "--trace", out]),
        v(&["sim", &scenario, "--plot", out]),
        v(&[
            "edit",
            &fig01,
            "-o",
            out,
            "wrap-root",
            "--kind",
            "sequence",
            "--id",
            "top",
        ]),
        v(&["log", "timeline", &log, "-o", out]),
        v(&["log", "dot", &log, "--step", "3", "-o", out]),
    ]
}

#[test]
fn outputs_through_links_out_of_the_work_tree_or_into_git_are_refused() {
    let t = Tree::new("links");
    for out in [
        "diff.dot",
        "new.dot",
        "out.dot",
        "dangling.dot",
        "dir/x.dot",
        "hooks/post-merge",
        ".git/x.dot",
        "sub/../.git/hooks/pre-commit",
    ] {
        for args in writers(out) {
            let args: Vec<&str> = args.iter().map(String::as_str).collect();
            let (code, _, err) = btfsm_in(&t.repo, &args);
            assert_eq!(code, 2, "{args:?}: {err}");
            assert!(
                err.contains("outside the root") || err.contains("`.git`"),
                "{args:?}: {err}"
            );
            assert!(err.contains("--allow-outside-root"), "{args:?}: {err}");
        }
        t.untouched();
    }
    // `plan -o DIR` through a link to a folder outside: nothing created.
    let (code, _, err) = btfsm_in(
        &t.repo,
        &[
            "plan",
            &abs("policies/domains/moma.toml"),
            "-o",
            "dir/planned",
        ],
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("outside the root"), "{err}");
    let (code, _, err) = btfsm_in(
        &t.repo,
        &["plan", &abs("policies/domains/moma.toml"), "-o", "hooks"],
    );
    assert_eq!(code, 2, "{err}");
    t.untouched();
    // A loop is an error, not a hang; a link inside the tree is followed.
    let (code, _, err) = btfsm_in(
        &t.repo,
        &[
            "dot",
            &abs("policies/paper/fig01-bt.toml"),
            "-o",
            "loop.dot",
        ],
    );
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("symbolic links"), "{err}");
    let (code, _, err) = btfsm_in(
        &t.repo,
        &["dot", &abs("policies/paper/fig01-bt.toml"), "-o", "ok.dot"],
    );
    assert_eq!(code, 0, "{err}");
    assert!(
        std::fs::read_to_string(t.repo.join("sub/real.dot"))
            .expect("written")
            .starts_with("digraph")
    );
    t.untouched();
}

#[test]
fn outputs_typed_outside_the_tree_and_trusted_use_are_allowed_never_executable() {
    let t = Tree::new("trusted");
    let fig01 = abs("policies/paper/fig01-bt.toml");
    // Typed outside the work tree: the user's choice of place.
    let typed = t.outside.join("typed.dot");
    let (code, _, err) = btfsm_in(
        &t.repo,
        &["dot", &fig01, "-o", typed.to_str().expect("utf-8")],
    );
    assert_eq!(code, 0, "{err}");
    std::fs::remove_file(&typed).expect("written");
    // `--root` names another root: the link to `outside/` is inside it.
    let top = t.top.to_str().expect("utf-8");
    let (code, _, err) = btfsm_in(&t.repo, &["dot", &fig01, "-o", "out.dot", "--root", top]);
    assert_eq!(code, 0, "{err}");
    let victim = t.outside.join("victim.txt");
    let mode = std::fs::metadata(&victim)
        .expect("victim")
        .permissions()
        .mode();
    assert_eq!(
        mode & 0o7777,
        0o644,
        "the replaced file kept its executable bits"
    );
    // `--allow-outside-root`: even the hook, which no longer runs.
    let (code, _, err) = btfsm_in(
        &t.repo,
        &["dot", &fig01, "-o", "diff.dot", "--allow-outside-root"],
    );
    assert_eq!(code, 0, "{err}");
    let hook = t.repo.join(".git/hooks/pre-commit");
    assert!(
        std::fs::read_to_string(&hook)
            .expect("hook")
            .starts_with("digraph")
    );
    let mode = std::fs::metadata(&hook).expect("hook").permissions().mode();
    assert_eq!(mode & 0o111, 0, "an output left executable");
}
