//! The rules on the paper's policies: Fig. 3 is flagged, Fig. 1 and every
//! other paper policy have no error-level finding.

use super::*;
use std::path::Path;

fn paper(name: &str) -> btfsm_model::Policy {
    let path = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../.."))
        .join("policies/paper")
        .join(format!("{name}.toml"));
    btfsm_format::load(&path, &Default::default())
        .unwrap_or_else(|e| panic!("{e:?}"))
        .policy
}

#[test]
fn fig_3_chatters_and_fig_1_is_clean() {
    let cfg = config::Config::default();
    let f3 = lint(&paper("fig03-bt"), None, "fig03-bt.toml", &cfg);
    let codes: Vec<&str> = f3.iter().map(|f| f.code).collect();
    assert_eq!(codes, ["chattering-precondition-order"], "{f3:?}");
    assert!(
        f3[0]
            .message
            .contains("`held` runs `move-to-cube`, which undoes Robot-At(delivery)"),
        "{}",
        f3[0].message
    );
    assert!(lint(&paper("fig01-bt"), None, "fig01-bt.toml", &cfg).is_empty());
}

#[test]
fn no_paper_policy_but_fig_3_has_an_error() {
    let cfg = config::Config::default();
    let dir = Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../..")).join("policies/paper");
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .flatten()
        .map(|e| e.path())
        .collect();
    files.sort();
    for f in files
        .iter()
        .filter(|f| f.extension().is_some_and(|e| e == "toml"))
    {
        let p = btfsm_format::load(f, &Default::default()).unwrap().policy;
        let errors: Vec<String> = lint(&p, None, "x", &cfg)
            .into_iter()
            .filter(|x| x.level == Level::Error)
            .map(|x| format!("{}: {}", x.code, x.message))
            .collect();
        let name = f.file_name().unwrap().to_string_lossy();
        if name == "fig03-bt.toml" {
            assert_eq!(errors.len(), 1, "{errors:?}");
        } else {
            assert!(errors.is_empty(), "{name}: {errors:?}");
        }
    }
}

#[test]
fn levels_follow_the_configuration() {
    let mut cfg = config::Config::default();
    cfg.set("chattering-precondition-order", Level::Allow)
        .unwrap();
    assert!(lint(&paper("fig03-bt"), None, "f", &cfg).is_empty());
    cfg.set("not-fault-tolerant", Level::Error).unwrap();
    assert!(
        lint(&paper("fig02-fsm"), None, "f", &cfg)
            .iter()
            .all(|f| f.level == Level::Error)
    );
    assert!(
        cfg.set("chatering-precondition-order", Level::Error)
            .unwrap_err()
            .contains("did you mean `chattering-precondition-order`?")
    );
}

#[test]
fn every_summary_prints_whole_in_the_rule_list() {
    // `lint --list` and SARIF show the summary; a table cuts cells at
    // sanitize::SHOWN_CHARS.
    for r in super::RULES {
        assert!(
            r.summary.chars().count() <= btfsm_core::sanitize::SHOWN_CHARS,
            "{}: {} chars",
            r.code,
            r.summary.chars().count()
        );
    }
}

#[test]
fn the_selector_resumes_every_state_of_fig_4_but_not_safe_move_to() {
    let m = paper("fig04-fsm");
    let f = super::lint(&m, None, "fig04", &Default::default());
    assert!(
        f.iter().all(|f| f.code != "selector-without-return"),
        "{f:?}"
    );
    for fig in ["fig08b-fsm", "fig08e-fsm"] {
        let f = super::lint(&paper(fig), None, fig, &Default::default());
        let at: Vec<&str> = f
            .iter()
            .filter(|f| f.code == "selector-without-return")
            .map(|f| f.at.as_str())
            .collect();
        assert_eq!(at, ["Safe-Move-To cube2"], "{fig}");
    }
}
