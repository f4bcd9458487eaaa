//! CLI conventions: shell completions and man pages generated from the
//! argument definitions.

use crate::common::btfsm;

#[test]
fn completions_are_valid_scripts_that_know_every_subcommand() {
    let (code, bash, stderr) = btfsm(&["completions", "bash"]);
    assert_eq!(code, 0, "{stderr}");
    for sub in ["analyze", "compare", "convert", "dot", "sim", "validate"] {
        assert!(bash.contains(sub), "bash completion lacks {sub}");
    }
    // bash -n: the script parses.
    let dir = crate::common::scratch("completions");
    let f = dir.join("btfsm.bash");
    std::fs::write(&f, &bash).expect("write");
    let ok = std::process::Command::new("bash")
        .arg("-n")
        .arg(&f)
        .status()
        .expect("bash");
    assert!(ok.success());
    for shell in ["zsh", "fish", "elvish", "powershell"] {
        let (code, text, stderr) = btfsm(&["completions", shell]);
        assert_eq!(code, 0, "{shell}: {stderr}");
        assert!(text.contains("analyze"), "{shell}");
    }
    let (code, _, stderr) = btfsm(&["completions", "tcsh"]);
    assert_eq!(code, 2, "an unknown shell is a usage error: {stderr}");
    std::fs::remove_dir_all(&dir).expect("cleanup");
}

#[test]
fn man_pages_exist_for_the_tool_and_each_subcommand() {
    let (code, page, stderr) = btfsm(&["man"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(page.contains(".TH btfsm 1"), "{page}");
    assert!(page.contains("analyze"));
    let (code, page, stderr) = btfsm(&["man", "sim"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(page.contains(".TH btfsm-sim 1"), "{page}");
    let (code, _, stderr) = btfsm(&["man", "nope"]);
    assert_eq!(code, 2, "{stderr}");
}
