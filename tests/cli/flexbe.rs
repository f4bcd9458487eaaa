//! FlexBE behaviors (`*_sm.py`, docs/guide/flexbe.md) read by every
//! command: the real behaviors of tests/fixtures/flexbe (team-vigir's
//! vigir_behaviors, FlexBE's turtlesim demo and behavior engine) against
//! hand counts and an independent text count, acceptance matched against
//! Python 3's own parser, directory walks, drawing, comparing, and the
//! errors of what is not read.

use crate::common::{btfsm, scratch};
use std::path::{Path, PathBuf};
use std::process::Command;

const DIR: &str = "tests/fixtures/flexbe";

fn behaviors(sub: &str) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> =
        std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join(DIR).join(sub))
            .expect("fixtures")
            .map(|e| e.expect("entry").path())
            .filter(|p| p.to_string_lossy().ends_with("_sm.py"))
            .collect();
    v.sort();
    v
}

fn analyze(file: &str) -> serde_json::Value {
    let (code, out, err) = btfsm(&["analyze", "--format", "json", file]);
    assert_eq!(code, 0, "{file}: {err}");
    let v: serde_json::Value = serde_json::from_str(&out).expect("json");
    v["policies"][0].clone()
}

/// Hand counts, read off the files: `flexbe_test_behavior_sm.py` adds 11
/// states to its machine and 6 to its one nested container (17 states,
/// the container one of them), with 16 + 9 = 25 transitions and 2
/// outcomes; the turtlesim demo's `example_3_sm.py` adds 7 states (two of
/// them ConcurrencyContainers of 2 states each: 11 states) with 17
/// transitions. A graph's vertices are the states and the machine's
/// outcomes; its edges the transitions and, per container, one edge to
/// its initial state (to every state of a parallel one).
#[test]
fn flexbe_behaviors_have_their_hand_counted_states_and_transitions() {
    let p = analyze("tests/fixtures/flexbe/vigir/flexbe_test_behavior_sm.py");
    assert_eq!(p["name"], "FlexBE Test Behavior");
    assert_eq!(p["kind"], "hfsm");
    assert_eq!(p["counts"]["state"], 16);
    assert_eq!(p["counts"]["container"], 1);
    assert_eq!(p["counts"]["outcome"], 2);
    assert_eq!(p["vertices"], 17 + 2);
    assert_eq!(p["edges"], 25 + 1);
    let p = analyze("tests/fixtures/flexbe/turtlesim/example_3_sm.py");
    assert_eq!(p["kind"], "hfsm");
    assert_eq!(p["counts"]["parallel_state"], 2);
    assert_eq!(p["counts"]["state"], 9);
    assert_eq!(p["vertices"], 11 + 2);
    assert_eq!(p["edges"], 17 + 2 * 2);
    let p = analyze("tests/fixtures/flexbe/engine/complex_behavior_test_sm.py");
    assert_eq!(p["kind"], "fsm");
    assert_eq!(
        (p["vertices"].as_u64(), p["edges"].as_u64()),
        (Some(4 + 2), Some(5))
    );
}

/// Text counts of a generated behavior, independent of the reader: `add`
/// calls, `'outcome':` keys of `transitions={...}`, the outcomes of
/// `_state_machine`, and the nested containers (`= OperatableStateMachine(`
/// or `= PriorityContainer(` but the top one).
fn text_counts(text: &str) -> (u64, u64, u64) {
    let adds = text
        .lines()
        .filter(|l| l.trim_start().starts_with("OperatableStateMachine.add("))
        .count();
    let transitions: usize = text
        .split("transitions={")
        .skip(1)
        .map(|rest| rest.split('}').next().unwrap_or("").matches("':").count())
        .sum();
    let top = text
        .split("_state_machine = OperatableStateMachine(outcomes=[")
        .nth(1)
        .and_then(|r| r.split(']').next())
        .map_or(0, |o| o.matches('\'').count() / 2);
    let containers = text.matches("= OperatableStateMachine(").count()
        + text.matches("= PriorityContainer(").count()
        - 1;
    (
        (adds + top) as u64,
        (transitions + containers) as u64,
        containers as u64,
    )
}

/// Every vigir behavior that Python 3 parses loads, with the vertices and
/// edges of the text count; those Python 3 refuses (Python 2 `print`
/// statements in their manual sections) are refused at the line, exit 2.
/// Python itself decides which is which (`ast.parse`), but for one file
/// that mixes a tab after spaces in its indentation: CPython accepts it,
/// the parser btfsm uses refuses it.
#[test]
fn vigir_behaviors_load_exactly_when_python_3_parses_them() {
    let python = Command::new("python3").arg("--version").output().is_ok();
    let (mut loaded, mut refused) = (0, 0);
    for f in behaviors("vigir") {
        let file = f.display().to_string();
        let text = std::fs::read_to_string(&f).expect("read");
        let (code, out, err) = btfsm(&["analyze", "--format", "json", &file]);
        let py3 = if python {
            Command::new("python3")
                .args([
                    "-c",
                    "import ast,sys; ast.parse(open(sys.argv[1]).read())",
                    &file,
                ])
                .output()
                .expect("python3")
                .status
                .success()
        } else {
            code == 0
        };
        let mixed_tabs = file.ends_with("sinusoide_joint_control_test_sm.py");
        if code == 0 {
            assert!(py3, "{file}: loaded, but Python 3 refuses it");
            let v: serde_json::Value = serde_json::from_str(&out).expect("json");
            let p = &v["policies"][0];
            let (vertices, edges, containers) = text_counts(&text);
            assert_eq!(p["vertices"], vertices, "{file}");
            assert_eq!(p["edges"], edges, "{file}");
            assert_eq!(
                p["kind"],
                if containers > 0 { "hfsm" } else { "fsm" },
                "{file}"
            );
            loaded += 1;
        } else {
            assert_eq!(code, 2, "{file}: {err}");
            assert!(err.contains("error: not valid Python 3"), "{file}: {err}");
            assert!(err.contains("_sm.py:"), "{file}: a position: {err}");
            assert!(
                !py3 || mixed_tabs,
                "{file}: Python 3 parses it, btfsm refuses: {err}"
            );
            refused += 1;
        }
    }
    assert_eq!((loaded, refused), (10, 6));
}

/// A directory walk keeps the `.py` files that are FlexBE behaviors (a
/// class deriving `Behavior` that builds an `OperatableStateMachine`) and
/// skips other Python, such as the engine's behavior mirror.
#[test]
fn a_directory_walk_reads_behaviors_and_skips_other_python() {
    let (code, out, err) = btfsm(&[
        "analyze",
        "--format",
        "json",
        "tests/fixtures/flexbe/engine",
        "tests/fixtures/flexbe/turtlesim",
    ]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).expect("json");
    let files: Vec<&str> = v["policies"]
        .as_array()
        .expect("policies")
        .iter()
        .map(|p| p["file"].as_str().expect("file"))
        .collect();
    assert_eq!(files.len(), 4, "{files:?}");
    assert!(files.iter().all(|f| !f.ends_with("behavior_mirror_sm.py")));
    // Named on the command line, it is read, and says why it is no behavior.
    let (code, _, err) = btfsm(&[
        "validate",
        "tests/fixtures/flexbe/engine/behavior_mirror_sm.py",
    ]);
    assert_eq!(code, 2);
    assert!(
        err.contains("no FlexBE behavior here: no class derives `Behavior`"),
        "{err}"
    );
}

/// `dot` draws containers as clusters, concurrency containers marked
/// parallel, and the autonomy levels in the labels; `compare` of a
/// behavior and its TOML export is named GED 0.
#[test]
fn flexbe_behaviors_draw_and_round_trip_through_toml_at_ged_0() {
    let f = "tests/fixtures/flexbe/turtlesim/example_3_sm.py";
    let (code, dot, err) = btfsm(&["dot", f]);
    assert_eq!(code, 0, "{err}");
    assert!(dot.contains("subgraph cluster_Container_AND"), "{dot}");
    assert!(
        dot.contains("label=\"Container_AND [finished:Inherit failed:Inherit] ‖\""),
        "{dot}"
    );
    assert!(dot.contains("Start[label=\"Start [done:Low]\""), "{dot}");
    let dir = scratch("flexbe-rt");
    for f in behaviors("turtlesim")
        .into_iter()
        .chain(behaviors("engine"))
    {
        if f.ends_with("behavior_mirror_sm.py") {
            continue;
        }
        let file = f.display().to_string();
        let out = dir.join(format!("{}.toml", f.file_stem().unwrap().to_string_lossy()));
        let out = out.display().to_string();
        let (code, _, err) = btfsm(&["convert", &file, "--to", "toml", "-o", &out]);
        assert_eq!(code, 0, "{file}: {err}");
        let (code, json, err) = btfsm(&["compare", &file, &out, "--format", "json"]);
        assert_eq!(code, 0, "{file}: {err}");
        let v: serde_json::Value = serde_json::from_str(&json).expect("json");
        assert_eq!(v["structural"]["ged"], 0, "{file}");
    }
}

/// What is not of the generated shape is an error at its line and column
/// naming what is valid, exit 2.
#[test]
fn unsupported_flexbe_constructs_are_errors_at_their_position() {
    let dir = scratch("flexbe-bad");
    let src = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/fixtures/flexbe/turtlesim/example_1_sm.py"),
    )
    .expect("read");
    let bad = src.replacen("transitions={", "transitions=TRANSITIONS or {", 1);
    assert_ne!(bad, src);
    let f = dir.join("bad_sm.py");
    std::fs::write(&f, &bad).expect("write");
    let (code, _, err) = btfsm(&["validate", &f.display().to_string()]);
    assert_eq!(code, 2, "{err}");
    let err = err.replace(&dir.display().to_string(), "DIR");
    insta::assert_snapshot!("flexbe_unsupported_transitions", err);
}
