//! The TOML reader: seeds, mutations and the messages of bad policies.

use super::*;
use proptest::prelude::*;

fn parse(text: &str) -> Result<Loaded, Vec<Diagnostic>> {
    parse_str(
        "t.toml",
        text,
        Path::new("policies/paper"),
        &Limits::default(),
    )
}

const SEEDS: &[&str] = &[
    include_str!("../../../policies/paper/fig01-bt.toml"),
    include_str!("../../../policies/paper/fig04-fsm.toml"),
    include_str!("../../../policies/paper/fig06-hfsm.toml"),
    include_str!("../../../policies/paper/fig08e-fsm.toml"),
    include_str!("../../../policies/paper/scal-bt.toml"),
];

/// Everything downstream of a successful parse must work on it too (the
/// fuzz targets' harness: graph, metrics, DOT, write-back fixpoint,
/// transforms, effort).
fn exercise(l: &Loaded) {
    crate::fuzzing::exercise(l);
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

#[test]
fn seeds_parse_and_round_trip() {
    for s in SEEDS {
        let l = parse(s).unwrap_or_else(|e| panic!("{}", e[0]));
        exercise(&l);
    }
}

#[derive(Debug, Clone)]
enum Mutation {
    Delete(usize, usize),
    Insert(usize, String),
    DuplicateLine(usize),
    SwapLines(usize, usize),
}

fn mutation() -> impl Strategy<Value = Mutation> {
    prop_oneof![
        (any::<usize>(), 1usize..12).prop_map(|(a, n)| Mutation::Delete(a, n)),
        (any::<usize>(), "[\\[\\]{}=\",.a-z0-9 \n#'\\\\]{1,6}")
            .prop_map(|(a, s)| Mutation::Insert(a, s)),
        any::<usize>().prop_map(Mutation::DuplicateLine),
        (any::<usize>(), any::<usize>()).prop_map(|(a, b)| Mutation::SwapLines(a, b)),
    ]
}

fn apply(text: &str, ms: &[Mutation]) -> String {
    let mut t = text.to_string();
    for m in ms {
        match m {
            Mutation::Delete(a, n) => {
                let mut a = a % (t.len() + 1);
                while !t.is_char_boundary(a) {
                    a -= 1;
                }
                let mut b = (a + n).min(t.len());
                while !t.is_char_boundary(b) {
                    b -= 1;
                }
                t.replace_range(a..b, "");
            }
            Mutation::Insert(a, s) => {
                let mut a = a % (t.len() + 1);
                while !t.is_char_boundary(a) {
                    a -= 1;
                }
                t.insert_str(a, s);
            }
            Mutation::DuplicateLine(i) | Mutation::SwapLines(i, _) => {
                let mut lines: Vec<String> = t.lines().map(String::from).collect();
                if lines.is_empty() {
                    continue;
                }
                let i = i % lines.len();
                if let Mutation::SwapLines(_, j) = m {
                    let j = j % lines.len();
                    lines.swap(i, j);
                } else {
                    let l = lines[i].clone();
                    lines.insert(i, l);
                }
                t = lines.join("\n");
            }
        }
    }
    t
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    /// Mutated policy files never panic: they parse (and then analyze,
    /// write and read back) or give positioned errors.
    #[test]
    fn mutated_files_never_panic(seed in 0..SEEDS.len(), ms in proptest::collection::vec(mutation(), 1..4)) {
        let text = apply(SEEDS[seed], &ms);
        match parse(&text) {
            Ok(l) => exercise(&l),
            Err(diags) => {
                prop_assert!(!diags.is_empty());
                for d in &diags {
                    let _ = d.to_string();
                }
                prop_assert!(diags.iter().any(Diagnostic::is_error));
            }
        }
    }

    /// Arbitrary text never panics either.
    #[test]
    fn random_text_never_panics(text in "\\PC{0,200}") {
        if let Err(diags) = parse(&text) {
            for d in &diags {
                let _ = d.to_string();
            }
        }
    }

    /// Arbitrary bytes through the fuzz target's body.
    #[test]
    fn random_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..300)) {
        crate::fuzzing::toml_policy(&bytes);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 40, ..ProptestConfig::default() })]

    /// Two mutated policies compared in every mode with a tiny budget: the
    /// `compare` fuzz target's body (certified interval, script cost).
    #[test]
    fn mutated_pairs_compare_within_their_certificates(
        a in 0..SEEDS.len(),
        b in 0..SEEDS.len(),
        ma in proptest::collection::vec(mutation(), 0..3),
        mb in proptest::collection::vec(mutation(), 0..3),
    ) {
        let pair = format!("{}\n%%\n{}", apply(SEEDS[a], &ma), apply(SEEDS[b], &mb));
        crate::fuzzing::compare(pair.as_bytes());
    }
}
