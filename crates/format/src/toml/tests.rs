//! The TOML reader: seeds, mutations and the messages of bad policies.

use super::*;

fn parse(text: &str) -> Result<Loaded, Vec<Diagnostic>> {
    parse_str(
        "t.toml",
        text,
        Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../policies/paper")),
        &Limits::default(),
    )
}

#[test]
fn a_state_without_a_skill_returns_any_outcome_a_near_miss_is_a_warning() {
    let fsm = |on: &str, skill: &str| {
        format!(
            "name = \"m\"\nkind = \"fsm\"\ninitial = \"a\"\noutcomes = [\"done\"]\n\n[states.a]\n{skill}on = {{ {on} = \"done\" }}\n"
        )
    };
    // yasmin-style outcomes on an unbound state: accepted, no warning.
    let l = parse(&fsm("outcome1", "")).unwrap();
    assert!(l.warnings.is_empty(), "{:?}", l.warnings);
    // A near miss of SUCCESS: accepted with a warning that says so.
    let l = parse(&fsm("SUCCEED", "")).unwrap();
    assert_eq!(l.warnings.len(), 1);
    assert!(l.warnings[0].message.contains("did you mean `SUCCESS`"));
    // A state bound to a skill returns SUCCESS, FAILURE or RUNNING only.
    let e = parse(&fsm("outcome1", "skill = \"Tuck-Arm\"\n")).unwrap_err();
    assert!(
        e[0].message.contains("cannot return `outcome1`"),
        "{}",
        e[0]
    );
}
