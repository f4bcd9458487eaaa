//! The readers' fuzz harness driven from unit tests: mutated seeds of every
//! format through [`crate`]'s targets (everything downstream of a parse:
//! graph, metrics, DOT, write-back fixpoint, transforms, effort).

use btfsm_core::diagnostic::Diagnostic;
use btfsm_format::{Limits, Loaded};
use proptest::prelude::*;
use std::path::Path;

fn parse(text: &str) -> Result<Loaded, Vec<Diagnostic>> {
    btfsm_format::toml::parse_str(
        "t.toml",
        text,
        Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/../../policies/paper")),
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
    crate::exercise(l);
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
        crate::toml_policy(&bytes);
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
        crate::compare(pair.as_bytes());
    }
}

/// The seed of the parallel machines' mutations (the SCXML reader's own
/// mutation test starts from it too).
const PARALLEL: &str = include_str!("../../../tests/fixtures/valid/parallel-mutation-seed.scxml");

/// `t` with the bytes between `a` and `b` (either order, moved back to
/// character boundaries) replaced by `ins`: a cut and splice of a seed.
fn splice(t: &str, a: usize, b: usize, ins: &str) -> String {
    let (mut a, mut b) = (a.min(t.len()), b.min(t.len()));
    if a > b {
        std::mem::swap(&mut a, &mut b);
    }
    while !t.is_char_boundary(a) {
        a -= 1;
    }
    while !t.is_char_boundary(b) {
        b -= 1;
    }
    format!("{}{ins}{}", &t[..a], &t[b..])
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 300, ..Default::default() })]

    /// Mutated parallel machines (regions, finals of enclosing regions,
    /// several initial states) never panic anywhere downstream: the fuzz
    /// target's body (graph, metrics, DOT, TOML write-back as a fixpoint,
    /// effort), then the Mermaid writer.
    #[test]
    fn mutated_parallel_machines_never_panic(
        cuts in proptest::collection::vec((0usize..900, 0usize..8, "[<>/=\" a-z0-9]{0,3}"), 1..4)
    ) {
        let text = btfsm_format::xml::mutate(PARALLEL, &cuts);
        crate::scxml(text.as_bytes());
        if let Ok(l) = btfsm_format::scxml::parse_str("t.scxml", &text, &Limits::default()) {
            let _ = btfsm_render::mermaid::policy_mermaid(&l.policy);
        }
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 300, ..Default::default() })]

    /// Cut and spliced yasmin files never panic: they load (and go
    /// through graph, metrics, DOT, write-back) or give errors.
    #[test]
    fn mangled_files_never_panic(seed in 0..3usize, a in 0..2000usize, b in 0..2000usize, ins in "[<>/=\"a-zA-Z _]{0,12}") {
        let seeds = [
            include_str!("../../../tests/fixtures/corpus/yasmin/yasmin_demos/state_machines/demo_fsm_metadata.xml"),
            include_str!("../../../tests/fixtures/corpus/yasmin/yasmin_factory/test/test_nested_sm.xml"),
            include_str!("../../../tests/fixtures/corpus/yasmin/yasmin_demos/state_machines/demo_orthogonal.xml"),
        ];
        let text = splice(seeds[seed], a, b, &ins);
        crate::yasmin(text.as_bytes());
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 200, ..Default::default() })]

    /// Cut and spliced FlexBE behaviors never panic: they load (and go
    /// through graph, metrics, DOT, write-back) or give errors.
    #[test]
    fn mangled_flexbe_behaviors_never_panic(seed in 0..3usize, a in 0..9000usize, b in 0..9000usize, ins in "[(){}\\[\\]:,'= a-zA-Z_\n\t]{0,12}") {
        let seeds = [
            include_str!("../../../tests/fixtures/flexbe/vigir/flexbe_test_behavior_sm.py"),
            include_str!("../../../tests/fixtures/flexbe/turtlesim/example_3_sm.py"),
            include_str!("../../../tests/fixtures/flexbe/engine/complex_behavior_test_sm.py"),
        ];
        let text = splice(seeds[seed], a, b, &ins);
        crate::flexbe(text.as_bytes());
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 200, ..Default::default() })]

    /// Cut and spliced py_trees renders never panic: they load (and go
    /// through graph, metrics, DOT, write-back) or give errors.
    #[test]
    fn mangled_py_trees_renders_never_panic(seed in 0..2usize, a in 0..4000usize, b in 0..4000usize, ins in "[\"{}\\[\\];,=> a-zA-Z_\n-]{0,12}") {
        let seeds = [
            include_str!("../../../tests/fixtures/py_trees_dot/every_node_type.dot"),
            include_str!("../../../tests/fixtures/py_trees_dot/blackboard.dot"),
        ];
        let text = splice(seeds[seed], a, b, &ins);
        crate::py_trees_dot(text.as_bytes());
    }
}

#[test]
fn mutated_domains_never_panic() {
    // Seeded byte and line mutations of the paper's domain through the fuzz
    // target's body (which plans and exercises what it accepts).
    let mut rng = btfsm_sim::rng::SimRng::named(0x5eed_d0a1, "domain-mutations");
    let mut below = move |n: u64| rng.next_u64() % n.max(1);
    let lines: Vec<&str> = include_str!("../../../policies/domains/moma.toml")
        .lines()
        .collect();
    for _ in 0..300 {
        let mut text: Vec<String> = lines.iter().map(|l| l.to_string()).collect();
        for _ in 0..1 + below(3) {
            let i = below(text.len() as u64) as usize;
            match below(4) {
                0 => {
                    text.remove(i);
                }
                1 => {
                    let j = below(text.len() as u64) as usize;
                    let l = text[j].clone();
                    text.insert(i, l);
                }
                2 if !text[i].is_empty() => {
                    let mut b = text[i].clone().into_bytes();
                    let k = below(b.len() as u64) as usize;
                    b[k] = b"()[]{},=\"x1 \\"[below(13) as usize];
                    text[i] = String::from_utf8_lossy(&b).into_owned();
                }
                _ => {
                    let j = below(text.len() as u64) as usize;
                    text.swap(i, j);
                }
            }
        }
        crate::domain(text.join("\n").as_bytes());
    }
}
