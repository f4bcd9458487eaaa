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

/// The repository's root (integration tests run from it, but say so).
fn repo() -> &'static std::path::Path {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The `btfsm-*` crates a `Cargo.toml`'s `[dependencies]` table names.
fn btfsm_dependencies(manifest: &std::path::Path) -> std::collections::BTreeSet<String> {
    let text = std::fs::read_to_string(manifest).expect("Cargo.toml");
    let doc: toml::Table = text.parse().expect("valid TOML");
    doc.get("dependencies")
        .and_then(toml::Value::as_table)
        .map(|t| {
            t.keys()
                .filter_map(|k| k.strip_prefix("btfsm-"))
                .map(str::to_string)
                .collect()
        })
        .unwrap_or_default()
}

/// ARCHITECTURE.md's table "Crates and what they know nothing of" is the
/// complete list of each crate's btfsm dependencies, and Cargo.toml says
/// the same: a crate that starts using another one changes the table.
#[test]
fn crates_use_only_what_architecture_md_allows() {
    let arch = std::fs::read_to_string(repo().join("ARCHITECTURE.md")).unwrap();
    let mut all = std::collections::BTreeSet::new();
    let mut rows = Vec::new();
    for line in arch.lines() {
        let cells: Vec<&str> = line.split('|').map(str::trim).collect();
        if cells.len() < 4 || !cells[1].starts_with("`btfsm-") {
            continue;
        }
        let name = cells[1].trim_matches('`').trim_start_matches("btfsm-");
        let uses: std::collections::BTreeSet<String> = cells[2]
            .split(',')
            .map(str::trim)
            .filter(|u| !u.is_empty() && *u != "—")
            .map(str::to_string)
            .collect();
        all.insert(name.to_string());
        rows.push((name.to_string(), uses));
    }
    assert!(rows.len() >= 10, "the table has a row per crate: {rows:?}");
    let mut crates = std::collections::BTreeSet::new();
    for e in std::fs::read_dir(repo().join("crates")).unwrap().flatten() {
        crates.insert(e.file_name().to_string_lossy().into_owned());
    }
    for (name, uses) in &rows {
        assert!(
            crates.contains(name),
            "ARCHITECTURE.md names a crate `{name}` that is not in crates/"
        );
        let actual = btfsm_dependencies(&repo().join("crates").join(name).join("Cargo.toml"));
        assert_eq!(
            &actual, uses,
            "btfsm-{name}: Cargo.toml's dependencies against ARCHITECTURE.md's"
        );
    }
    for c in &crates {
        assert!(all.contains(c), "crates/{c} has no row in ARCHITECTURE.md");
    }
    // The binary: every library crate but the fuzz harness.
    let mut libs = crates.clone();
    libs.remove("fuzzing");
    assert_eq!(btfsm_dependencies(&repo().join("Cargo.toml")), libs);
}

/// Every test, oracle script or page a "Tested by:" line of ARCHITECTURE.md,
/// README.md or docs/ (and its folders) names exists:
/// `btfsm_crate::module::test`, `FILE.rs::test` or a file path.
#[test]
fn every_test_named_in_the_docs_exists() {
    let mut docs = vec![repo().join("ARCHITECTURE.md"), repo().join("README.md")];
    let mut dirs = vec![repo().join("docs")];
    while let Some(d) = dirs.pop() {
        for e in std::fs::read_dir(d).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                dirs.push(p);
            } else if p.extension().is_some_and(|x| x == "md") {
                docs.push(p);
            }
        }
    }
    let mut missing = Vec::new();
    let mut named = 0;
    for doc in &docs {
        let text = std::fs::read_to_string(doc).unwrap();
        for name in tested_by_names(&text) {
            named += 1;
            if !test_exists(&name) {
                missing.push(format!("{}: `{name}`", doc.display()));
            }
        }
    }
    assert!(
        named >= 50,
        "only {named} tests named: is the \"Tested by:\" parser broken?"
    );
    assert!(
        missing.is_empty(),
        "named but not found:\n{}",
        missing.join("\n")
    );
}

/// The backticked names of every "Tested by:" paragraph (it runs to the
/// next blank line or list item).
fn tested_by_names(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut inside = false;
    for line in text.lines() {
        let l = line.trim();
        if let Some(rest) = l.strip_prefix("Tested by:") {
            inside = true;
            out.extend(backticked(rest));
        } else if inside && !l.is_empty() && !l.starts_with("- ") && !l.starts_with('#') {
            out.extend(backticked(l));
        } else {
            inside = false;
        }
    }
    out
}

fn backticked(s: &str) -> Vec<String> {
    s.split('`')
        .skip(1)
        .step_by(2)
        .map(str::to_string)
        .collect()
}

fn test_exists(name: &str) -> bool {
    let Some((head, test)) = name.rsplit_once("::") else {
        return repo().join(name).exists();
    };
    let fn_in = |text: &str| text.contains(&format!("fn {test}("));
    if head.ends_with(".rs") {
        return std::fs::read_to_string(repo().join(head)).is_ok_and(|t| fn_in(&t));
    }
    let Some(krate) = head
        .split("::")
        .next()
        .and_then(|c| c.strip_prefix("btfsm_"))
    else {
        return false;
    };
    let mut stack = vec![repo().join("crates").join(krate).join("src")];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if std::fs::read_to_string(&p).is_ok_and(|t| fn_in(&t)) {
                return true;
            }
        }
    }
    false
}
