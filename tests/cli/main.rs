//! Runs the built `btfsm` binary on fixture files and compares stdout, stderr
//! and exit codes. Set `BLESS=1` to rewrite the expected `.stderr` files.

#![allow(
    clippy::print_stdout,
    clippy::print_stderr,
    reason = "benchmarks and tests report what they measured"
)]

use std::path::{Path, PathBuf};

mod common;
mod compare;
mod compare_field;
mod compare_report;
mod compare_tree;
mod confine;
mod conventions;
mod dot;
mod fault_tolerant;
mod field_formats;
mod flexbe;
mod formats;
mod gate;
mod ged_budget;
mod hostile;
mod lint;
mod log;
mod paper;
mod plan;
mod plan_pddl;
mod provenance;
mod py_trees_dot;
mod review;
mod sim;
mod sim_sensitivity;
mod tick;
mod untrusted;
mod validate;
mod view;

use common::btfsm;

fn fixtures(dir: &str) -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/fixtures")
        .join(dir);
    let mut files: Vec<PathBuf> = std::fs::read_dir(&root)
        .expect("fixture dir")
        .map(|e| e.expect("entry").path())
        .filter(|p| {
            p.extension()
                .is_some_and(|e| e == "toml" || e == "xml" || e == "scxml")
        })
        .collect();
    files.sort();
    files
}

fn rel(p: &Path) -> String {
    p.strip_prefix(env!("CARGO_MANIFEST_DIR"))
        .expect("inside the crate")
        .display()
        .to_string()
}

/// Every invalid fixture exits 2 with exactly the recorded messages.
#[test]
fn invalid_files_give_positioned_messages_and_exit_2() {
    let bless = std::env::var_os("BLESS").is_some();
    let mut failures = Vec::new();
    for f in fixtures("invalid") {
        let (code, stdout, stderr) = btfsm(&["validate", &rel(&f)]);
        let expected_path = f.with_extension("stderr");
        if bless {
            std::fs::write(&expected_path, &stderr).expect("write expected");
        }
        let expected = std::fs::read_to_string(&expected_path).unwrap_or_default();
        if code != 2 || !stdout.is_empty() || stderr != expected {
            failures.push(format!(
                "{}: exit {code}\n--- stderr\n{stderr}--- expected\n{expected}",
                rel(&f)
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn every_message_names_file_line_and_column() {
    for f in fixtures("invalid") {
        let (_, _, stderr) = btfsm(&["validate", &rel(&f)]);
        assert!(stderr.starts_with("error: "), "{stderr}");
        let has_position = stderr
            .lines()
            .any(|l| l.trim_start().starts_with("--> ") && l.matches(':').count() >= 2);
        assert!(has_position, "no file:line:col in\n{stderr}");
    }
}

#[test]
fn unreachable_state_is_a_warning_not_an_error() {
    let (code, _, stderr) = btfsm(&["validate", "tests/fixtures/valid/unreachable-state.toml"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.contains("warning: state `Dock` is unreachable from the initial state"));
    assert!(stderr.contains("unreachable-state.toml:10:9"), "{stderr}");
}

/// What BehaviorTree.CPP's tinyxml2 reads although it is not well-formed
/// XML (text before `<root>`, `--` in a comment, a bare `&` or `<` in an
/// attribute, attributes without a space) loads with a warning at each place;
/// the values are read as tinyxml2 reads them.
#[test]
fn xml_that_behaviortree_cpp_tolerates_loads_with_warnings() {
    let f = "tests/fixtures/valid/tinyxml2-lenient.xml";
    let (code, _, stderr) = btfsm(&["validate", f]);
    assert_eq!(code, 0, "{stderr}");
    let expected =
        std::fs::read_to_string("tests/fixtures/valid/tinyxml2-lenient.stderr").unwrap_or_default();
    if std::env::var_os("BLESS").is_some() {
        std::fs::write("tests/fixtures/valid/tinyxml2-lenient.stderr", &stderr).expect("bless");
    } else {
        assert_eq!(stderr, expected);
    }
    let (code, toml, stderr) = btfsm(&["convert", f, "--to", "toml"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(toml.contains(r#"code = "ok := 1 && 2 < 3""#), "{toml}");
    assert!(toml.contains(r#""fish & chips""#), "{toml}");
}

#[test]
fn missing_file_and_bad_usage_exit_2() {
    let (code, _, stderr) = btfsm(&["analyze", "no/such/file.toml"]);
    assert_eq!(code, 2);
    assert!(
        stderr.contains("cannot read `no/such/file.toml`: no such file"),
        "{stderr}"
    );
    let (code, _, _) = btfsm(&["analyze", "--format", "yaml", "x.toml"]);
    assert_eq!(code, 2);
    let (code, _, _) = btfsm(&["frobnicate"]);
    assert_eq!(code, 2);
}

fn analyze_json(files: &[String]) -> serde_json::Value {
    let mut args = vec!["analyze", "--format", "json"];
    args.extend(files.iter().map(String::as_str));
    let (code, stdout, stderr) = btfsm(&args);
    assert_eq!(code, 0, "{stderr}");
    serde_json::from_str(&stdout).expect("valid JSON")
}

/// SPEC §4's vertex and edge counts, SPEC §3's cc values, essential cc 1 for
/// every BT, through the built binary.
#[test]
fn paper_policies_have_the_spec_counts() {
    let expected: &[(&str, u64, u64)] = &[
        ("fig01-bt", 14, 13),
        ("fig03-bt", 14, 13),
        ("fig05-bt", 5, 4),
        ("fig06-hfsm", 8, 16),
        ("fig07a-bt", 17, 16),
        ("fig07b-bt", 15, 14),
        ("fig07c-bt", 18, 17),
        ("fig07d-bt", 18, 17),
        ("fig07e-bt", 25, 24),
        ("fig09a-bt", 21, 20),
        ("fig12-bt", 5, 4),
        ("fig13-bt", 9, 8),
        ("fig15-bt", 21, 20),
        ("scal-bt", 77, 76),
        ("fig16a-bt", 80, 79),
        ("fig02-fsm", 5, 4),
        ("fig04-fsm", 6, 18),
        ("fig08a-fsm", 7, 22),
        ("fig08b-fsm", 7, 21),
        ("fig08c-fsm", 7, 22),
        ("fig08d-fsm", 7, 25),
        ("fig08e-fsm", 10, 39),
        ("fig09b-fsm", 8, 34),
        ("fig10-fsm", 6, 12),
        ("fig15-fsm", 8, 30),
        ("scal-fsm", 24, 90),
        ("fig16b-fsm", 25, 115),
    ];
    let files: Vec<String> = expected
        .iter()
        .map(|(f, _, _)| format!("policies/paper/{f}.toml"))
        .collect();
    let json = analyze_json(&files);
    let policies = json["policies"].as_array().expect("policies array");
    assert_eq!(policies.len(), expected.len());
    for (p, (f, v, e)) in policies.iter().zip(expected) {
        assert_eq!(p["file"], format!("policies/paper/{f}.toml"));
        assert_eq!(
            (p["vertices"].as_u64(), p["edges"].as_u64()),
            (Some(*v), Some(*e)),
            "{f}"
        );
        for key in [
            "name",
            "kind",
            "graphical_elements",
            "active_elements",
            "cc",
            "essential_cc",
            "counts",
            "table1",
        ] {
            assert!(!p[key].is_null(), "{f}: missing {key}");
        }
        if p["kind"] == "bt" {
            assert_eq!(p["essential_cc"], 1, "{f}");
            assert_eq!(p["active_elements"].as_u64(), Some(*v), "{f}");
        } else {
            assert_eq!(p["active_elements"].as_u64(), Some(v + e), "{f}");
        }
        assert_eq!(p["graphical_elements"].as_u64(), Some(v + e), "{f}");
    }
    let cc = |name: &str| {
        policies
            .iter()
            .find(|p| p["file"] == format!("policies/paper/{name}.toml"))
            .map(|p| p["cc"].as_i64().expect("cc"))
            .expect("present")
    };
    assert_eq!(
        [
            "fig04-fsm",
            "fig08d-fsm",
            "fig15-fsm",
            "scal-fsm",
            "fig16b-fsm"
        ]
        .map(cc),
        [14, 20, 24, 68, 92]
    );
}

/// Structures that are not BTs have an essential complexity above 1.
#[test]
fn essential_complexity_separates_fsms_from_bts() {
    let json = analyze_json(&[
        "policies/paper/fig04-fsm.toml".into(),
        "policies/paper/fig10-fsm.toml".into(),
        "policies/paper/fig02-fsm.toml".into(),
    ]);
    let ess: Vec<i64> = json["policies"]
        .as_array()
        .expect("array")
        .iter()
        .map(|p| p["essential_cc"].as_i64().expect("int"))
        .collect();
    assert!(ess[0] > 1 && ess[1] > 1, "{ess:?}");
    // The sequential FSM is structured (a chain): it reduces like a BT.
    assert_eq!(ess[2], 1);
}

/// The paper's Fig. 1 as an HFSM: 17 vertices and 44 edges (sec. IV-A c).
#[test]
fn converting_fig01_gives_the_papers_hfsm() {
    let dir = std::env::temp_dir().join(format!("btfsm-conv-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("tmp");
    let out = dir.join("fig01-hfsm.toml");
    let out_s = out.display().to_string();
    let (code, _, stderr) = btfsm(&[
        "convert",
        "policies/paper/fig01-bt.toml",
        "--to",
        "hfsm",
        "-o",
        &out_s,
    ]);
    assert_eq!(code, 0, "{stderr}");
    let json = analyze_json(&[out_s]);
    let p = &json["policies"][0];
    assert_eq!(p["kind"], "hfsm");
    assert_eq!(
        (p["vertices"].as_u64(), p["edges"].as_u64()),
        (Some(17), Some(44))
    );
    assert_eq!(p["essential_cc"], 1);
    std::fs::remove_dir_all(&dir).expect("cleanup");
}

/// The checked-in fig06-hfsm.toml is what `convert` makes of fig05-bt.toml.
#[test]
fn fig06_is_generated_from_fig05() {
    let (code, stdout, stderr) =
        btfsm(&["convert", "policies/paper/fig05-bt.toml", "--to", "hfsm"]);
    assert_eq!(code, 0, "{stderr}");
    let checked_in = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("policies/paper/fig06-hfsm.toml"),
    )
    .expect("fig06");
    assert_eq!(stdout, checked_in);
}

#[test]
fn csv_and_table_formats() {
    let (code, stdout, _) = btfsm(&[
        "analyze",
        "policies/paper/fig04-fsm.toml",
        "--format",
        "csv",
    ]);
    assert_eq!(code, 0);
    let mut lines = stdout.lines();
    assert!(
        lines
            .next()
            .expect("header")
            .starts_with("file,name,kind,vertices,edges")
    );
    assert!(
        lines
            .next()
            .expect("row")
            .starts_with("policies/paper/fig04-fsm.toml,")
    );
    let (code, stdout, _) = btfsm(&["analyze", "policies/paper/fig01-bt.toml"]);
    assert_eq!(code, 0);
    assert!(stdout.contains("fig01-bt.toml"));
}

#[test]
fn dot_draws_every_vertex_and_writes_files_whole() {
    let (code, stdout, stderr) = btfsm(&["dot", "policies/paper/fig04-fsm.toml"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.starts_with("digraph"));
    assert!(stdout.contains("SELECTOR[") && stdout.contains("shape=doublecircle"));
    // One DOT edge per arc, and the arrow from the start dot to the
    // initial state (UML), which is none.
    let edges: Vec<&str> = stdout.lines().filter(|l| l.contains(" -> ")).collect();
    assert_eq!(edges.len(), 19, "{stdout}");
    let start: Vec<&&str> = edges.iter().filter(|l| l.contains("class=start")).collect();
    assert_eq!(start.len(), 1, "{stdout}");
    assert!(
        start[0].contains("__start -> \"Move-To cube2\""),
        "{}",
        start[0]
    );
    let dir = std::env::temp_dir().join(format!("btfsm-dot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("tmp");
    let out = dir.join("fig01.dot").display().to_string();
    let (code, _, _) = btfsm(&["dot", "policies/paper/fig01-bt.toml", "-o", &out]);
    assert_eq!(code, 0);
    assert!(
        std::fs::read_to_string(&out)
            .expect("written")
            .contains("ordering=out")
    );
    // A bad input leaves no output file behind.
    let bad = dir.join("bad.dot").display().to_string();
    let (code, _, _) = btfsm(&["dot", "tests/fixtures/invalid/malformed.toml", "-o", &bad]);
    assert_eq!(code, 2);
    assert!(!Path::new(&bad).exists());
    std::fs::remove_dir_all(&dir).expect("cleanup");
}
