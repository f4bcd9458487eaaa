//! Runs the built `btfsm` binary on fixture files and compares stdout, stderr
//! and exit codes. Set `BLESS=1` to rewrite the expected `.stderr` files.

use std::path::{Path, PathBuf};

mod common;
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
    assert_eq!(stdout.matches(" -> ").count(), 18, "one DOT edge per arc");
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

// ------------------------------------------------------------------ compare

fn compare_json(a: &str, b: &str, extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["compare", a, b, "--format", "json"];
    args.extend_from_slice(extra);
    let (code, stdout, stderr) = btfsm(&args);
    assert_eq!(code, 0, "{a} {b}: {stderr}");
    serde_json::from_str(&stdout).expect("json")
}

/// Asserts one mode's result is exact, equals `want`, and that its edit
/// script costs exactly that much.
fn assert_exact(v: &serde_json::Value, mode: &str, want: u64, what: &str) {
    let m = &v[mode];
    assert_eq!(m["ged"].as_u64(), Some(want), "{what} {mode}: {m}");
    assert_eq!(m["exact"], true, "{what} {mode}");
    assert_eq!(m["lower_bound"].as_u64(), Some(want), "{what} {mode}");
    assert_eq!(m["upper_bound"].as_u64(), Some(want), "{what} {mode}");
    let s = &m["edit_script"];
    let count = |k: &str| s[k].as_array().expect("list").len() as u64;
    let arcs = |k: &str| {
        s[k].as_array()
            .expect("list")
            .iter()
            .map(|a| a["count"].as_u64().expect("count"))
            .sum::<u64>()
    };
    let cost = count("vertices_added")
        + count("vertices_removed")
        + arcs("arcs_added")
        + arcs("arcs_removed");
    assert_eq!(cost, want, "{what} {mode}: the script must cost the GED");
}

/// SPEC §5: Tables II and III and the effort pairs, structural and named GED,
/// each exact, in both argument orders.
#[test]
fn compare_reproduces_the_spec_pairs() {
    let pairs: &[(&str, &str, u64, u64)] = &[
        // Table II, FSM (structural 6 on Safe-Move-To: NetworkX says 4).
        ("fig04-fsm", "fig08a-fsm", 5, 7),
        ("fig04-fsm", "fig08b-fsm", 6, 6),
        ("fig04-fsm", "fig08c-fsm", 5, 7),
        ("fig04-fsm", "fig08d-fsm", 8, 8),
        // Table II, BT: structural = named = 2 n*.
        ("fig01-bt", "fig07a-bt", 6, 6),
        ("fig01-bt", "fig07b-bt", 2, 2),
        ("fig01-bt", "fig07c-bt", 8, 8),
        ("fig01-bt", "fig07d-bt", 8, 8),
        // Table III.
        ("fig07d-bt", "fig15-bt", 6, 6),
        ("scal-bt", "fig16a-bt", 6, 6),
        ("fig08d-fsm", "fig15-fsm", 6, 8),
        ("scal-fsm", "fig16b-fsm", 26, 26),
        // Effort: Fig. 2 -> 4 and Fig. 10 -> 11 (= 8d).
        ("fig02-fsm", "fig04-fsm", 15, 15),
        ("fig10-fsm", "fig08d-fsm", 14, 22),
    ];
    for &(a, b, structural, named) in pairs {
        let pa = format!("policies/paper/{a}.toml");
        let pb = format!("policies/paper/{b}.toml");
        for (x, y) in [(&pa, &pb), (&pb, &pa)] {
            let v = compare_json(x, y, &[]);
            let what = format!("{x} -> {y}");
            assert_exact(&v, "structural", structural, &what);
            assert_exact(&v, "named", named, &what);
            // Labeled lies between the two.
            let l = v["labeled"]["ged"].as_u64().expect("labeled");
            assert!(structural <= l && l <= named, "{what}: labeled {l}");
            assert_eq!(v["a"], x.as_str());
        }
    }
}

/// Table II's HFSM column, on the HFSMs `convert` makes of the BTs (the
/// paper's 12/4/17/17 are Eq. 3's estimates; SPEC §5).
#[test]
fn compare_converted_hfsms() {
    let dir = std::env::temp_dir().join(format!("btfsm-hfsm-pairs-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("tmp");
    let conv = |name: &str| {
        let out = dir.join(format!("{name}-hfsm.toml")).display().to_string();
        let src = format!("policies/paper/{name}.toml");
        let (code, _, stderr) = btfsm(&["convert", &src, "--to", "hfsm", "-o", &out]);
        assert_eq!(code, 0, "{stderr}");
        out
    };
    let pairs: &[(&str, &str, u64, u64)] = &[
        ("fig01-bt", "fig07a-bt", 14, 14),
        ("fig01-bt", "fig07b-bt", 6, 6),
        ("fig01-bt", "fig07c-bt", 19, 23),
        ("fig01-bt", "fig07d-bt", 21, 23),
        ("fig07d-bt", "fig15-bt", 14, 14),
        ("scal-bt", "fig16a-bt", 14, 14),
    ];
    for &(a, b, structural, named) in pairs {
        let (ha, hb) = (conv(a), conv(b));
        let v = compare_json(&ha, &hb, &[]);
        assert_exact(&v, "structural", structural, &format!("{a} -> {b}"));
        assert_exact(&v, "named", named, &format!("{a} -> {b}"));
    }
    std::fs::remove_dir_all(&dir).expect("cleanup");
}

/// A random FSM with `n` states and about 4n transitions, as TOML.
fn random_fsm(n: usize, seed: u64) -> String {
    let mut x = seed;
    let mut next = move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    };
    let mut s = String::from("kind = \"fsm\"\ninitial = \"s0\"\noutcomes = [\"SUCCESS\"]\n");
    for i in 0..n {
        s.push_str(&format!(
            "[states.s{i}]\nskill = \"Move-To\"\nargs = {{ target = \"cube1\" }}\non = {{ "
        ));
        let outs = ["SUCCESS", "FAILURE", "RUNNING"];
        let arcs: Vec<String> = outs
            .iter()
            .map(|o| {
                let t = next() % (n as u64 + 1);
                let to = if t == n as u64 {
                    "SUCCESS".to_string()
                } else {
                    format!("s{t}")
                };
                format!("{o} = \"{to}\"")
            })
            .collect();
        s.push_str(&arcs.join(", "));
        s.push_str(" }\n");
    }
    s
}

/// Two random 200-state FSMs: the search runs out of budget and says so,
/// with a certified interval, never a hang or a guess.
#[test]
fn compare_large_graphs_returns_a_certified_interval() {
    let dir = std::env::temp_dir().join(format!("btfsm-big-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("tmp");
    let a = dir.join("a.toml");
    let b = dir.join("b.toml");
    std::fs::write(&a, random_fsm(200, 1)).expect("write");
    std::fs::write(&b, random_fsm(200, 2)).expect("write");
    let (a, b) = (a.display().to_string(), b.display().to_string());
    let v = compare_json(&a, &b, &["--timeout-ms", "300", "--mode", "structural"]);
    let m = &v["structural"];
    let (lo, hi) = (
        m["lower_bound"].as_u64().expect("lower"),
        m["upper_bound"].as_u64().expect("upper"),
    );
    assert!(lo <= hi && m["ged"].as_u64() == Some(hi), "{m}");
    assert_eq!(m["exact"], lo == hi);
    assert!(v.get("named").is_none() && v.get("labeled").is_none());
    // The table says the value is only bounded.
    let (code, stdout, _) = btfsm(&[
        "compare",
        &a,
        &b,
        "--timeout-ms",
        "100",
        "--mode",
        "labeled",
    ]);
    assert_eq!(code, 0);
    if stdout.contains(" no ") {
        assert!(stdout.contains("certified interval"), "{stdout}");
    }
    std::fs::remove_dir_all(&dir).expect("cleanup");
}

#[test]
fn compare_table_lists_the_edits_and_dot_draws_them() {
    let (code, stdout, stderr) = btfsm(&[
        "compare",
        "policies/paper/fig04-fsm.toml",
        "policies/paper/fig08b-fsm.toml",
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("named edit script (6 edits):"), "{stdout}");
    assert!(
        stdout.contains("  + state `Safe-Move-To cube2`"),
        "{stdout}"
    );
    assert!(
        stdout.contains("  - arc `Move-To cube2` -> `SELECTOR` [FAILURE]"),
        "{stdout}"
    );
    let dir = std::env::temp_dir().join(format!("btfsm-cmp-dot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("tmp");
    let out = dir.join("diff.dot").display().to_string();
    // Reverse direction: Safe-Move-To is removed, drawn as a dashed ghost.
    let (code, _, stderr) = btfsm(&[
        "compare",
        "policies/paper/fig08b-fsm.toml",
        "policies/paper/fig04-fsm.toml",
        "--dot",
        &out,
    ]);
    assert_eq!(code, 0, "{stderr}");
    let dot = std::fs::read_to_string(&out).expect("dot written");
    let ghost = dot
        .lines()
        .find(|l| l.contains("Safe-Move-To cube2") && l.contains('['))
        .expect("ghost vertex");
    assert!(ghost.contains("dashed"), "{ghost}");
    assert_eq!(
        dot.lines()
            .filter(|l| l.contains(" -> ") && l.contains("dashed"))
            .count(),
        4,
        "four removed arcs"
    );
    assert!(
        dot.lines()
            .any(|l| l.contains(" -> ") && l.contains("color=red")),
        "one added arc in red:\n{dot}"
    );
    std::fs::remove_dir_all(&dir).expect("cleanup");
}

#[test]
fn compare_bad_input_exits_2() {
    let (code, stdout, stderr) = btfsm(&[
        "compare",
        "policies/paper/fig04-fsm.toml",
        "tests/fixtures/invalid/dangling-target.toml",
    ]);
    assert_eq!((code, stdout.as_str()), (2, ""));
    assert!(stderr.contains("dangling-target.toml:"), "{stderr}");
    let (code, _, _) = btfsm(&[
        "compare",
        "policies/paper/fig04-fsm.toml",
        "policies/paper/fig04-fsm.toml",
        "--mode",
        "fuzzy",
    ]);
    assert_eq!(code, 2);
    let (code, _, stderr) = btfsm(&[
        "compare",
        "policies/paper/fig04-fsm.toml",
        "policies/paper/fig04-fsm.toml",
        "--render",
        "svg",
    ]);
    assert_eq!(code, 2, "--render needs --dot: {stderr}");
}

// ---------------------------------------------------------------------------
// BehaviorTree.CPP XML and SCXML (issue 6): the real-world corpus in
// ../shared/corpus imports, analyzes, draws and validates; round trips through
// the converters keep every policy at named GED 0.

const CORPUS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/corpus");

fn nav2_model() -> String {
    format!("{CORPUS}/bt-xml/nav2/nav2_tree_nodes.xml")
}

/// Every file of the corpus with a given extension, recursively, sorted.
fn corpus_files(ext: &str) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut dirs = vec![PathBuf::from(CORPUS)];
    while let Some(d) = dirs.pop() {
        for e in std::fs::read_dir(&d).expect("corpus dir (../shared/corpus)") {
            let p = e.expect("entry").path();
            if p.is_dir() {
                dirs.push(p);
            } else if p.extension().is_some_and(|e| e == ext) {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// Corpus XML files that hold behavior trees (not the nodes model).
fn corpus_trees() -> Vec<PathBuf> {
    let trees: Vec<PathBuf> = corpus_files("xml")
        .into_iter()
        .filter(|p| {
            std::fs::read_to_string(p)
                .expect("read")
                .contains("<BehaviorTree")
        })
        .collect();
    assert!(trees.len() >= 8, "corpus trees: {trees:?}");
    trees
}

/// A tag: name (`/name` for an end tag), attributes, self-closing.
type Tag = (String, Vec<(String, String)>, bool);

/// An XML tag found by the test's own scanner (independent of the reader):
/// `(name, attributes, self-closing)` for a start tag, `("/name", ..)` for an
/// end tag. Comments, declarations and processing instructions are skipped.
fn scan_tags(text: &str) -> Vec<Tag> {
    let mut out = Vec::new();
    let mut rest = text;
    while let Some(i) = rest.find('<') {
        rest = &rest[i..];
        let skip_to = |r: &str, end: &str| r.find(end).map_or(r.len(), |j| j + end.len());
        if rest.starts_with("<!--") {
            rest = &rest[skip_to(rest, "-->")..];
            continue;
        }
        if rest.starts_with("<?") {
            rest = &rest[skip_to(rest, "?>")..];
            continue;
        }
        if rest.starts_with("<!") {
            rest = &rest[skip_to(rest, ">")..];
            continue;
        }
        // Up to the closing '>' outside quotes.
        let mut quote = None;
        let mut end = rest.len();
        for (j, c) in rest.char_indices().skip(1) {
            match (quote, c) {
                (None, '"' | '\'') => quote = Some(c),
                (Some(q), c) if c == q => quote = None,
                (None, '>') => {
                    end = j;
                    break;
                }
                _ => {}
            }
        }
        let inner = &rest[1..end];
        rest = &rest[(end + 1).min(rest.len())..];
        let self_closing = inner.ends_with('/');
        let inner = inner.trim_end_matches('/');
        let name_end = inner
            .find(|c: char| c.is_whitespace())
            .unwrap_or(inner.len());
        let name = inner[..name_end].to_string();
        let mut attrs = Vec::new();
        let mut a = inner[name_end..].trim_start();
        while let Some(eq) = a.find('=') {
            let key = a[..eq].trim().to_string();
            let v = a[eq + 1..].trim_start();
            let q = v.chars().next().unwrap_or('"');
            let close = v[1..].find(q).map_or(v.len(), |k| k + 1);
            attrs.push((key, v[1..close].to_string()));
            a = v[(close + 1).min(v.len())..].trim_start();
        }
        out.push((name, attrs, self_closing));
    }
    out
}

fn attr<'a>(attrs: &'a [(String, String)], k: &str) -> Option<&'a str> {
    attrs.iter().find(|(n, _)| n == k).map(|(_, v)| v.as_str())
}

/// Tree nodes of the tree a BehaviorTree.CPP file runs, counted by the test's
/// own scanner: start tags inside `<BehaviorTree>`, each `<SubTree ID>` replaced
/// by the count of the tree it names (trees of included files too).
fn count_tree_nodes(path: &Path) -> usize {
    // tree ID -> (own nodes, SubTree IDs used)
    let mut trees: std::collections::HashMap<String, (usize, Vec<String>)> = Default::default();
    let mut main: Option<String> = None;
    let mut first_local: Vec<String> = Vec::new();
    let mut files = vec![(path.to_path_buf(), true)];
    while let Some((f, is_main)) = files.pop() {
        let text = std::fs::read_to_string(&f).expect("read");
        let mut current: Option<String> = None;
        for (name, attrs, _) in scan_tags(&text) {
            match name.as_str() {
                "root" if is_main => main = attr(&attrs, "main_tree_to_execute").map(String::from),
                "include" => files.push((
                    f.parent()
                        .expect("dir")
                        .join(attr(&attrs, "path").expect("path")),
                    false,
                )),
                "BehaviorTree" => {
                    let id = attr(&attrs, "ID").expect("ID").to_string();
                    if is_main {
                        first_local.push(id.clone());
                    }
                    trees.insert(id.clone(), (0, vec![]));
                    current = Some(id);
                }
                "/BehaviorTree" => current = None,
                n if n.starts_with('/') => {}
                _ => {
                    if let Some(t) = &current {
                        let e = trees.get_mut(t).expect("tree");
                        if name == "SubTree" {
                            e.1.push(attr(&attrs, "ID").expect("ID").to_string());
                        } else {
                            e.0 += 1;
                        }
                    }
                }
            }
        }
    }
    let main = main.unwrap_or_else(|| first_local[0].clone());
    let mut total = 0;
    let mut todo = vec![main];
    while let Some(t) = todo.pop() {
        let (own, subs) = &trees[&t];
        total += own;
        todo.extend(subs.iter().cloned());
    }
    total
}

/// Vertices and arcs of an SCXML file's HFSM graph by the test's own scanner:
/// every `<state>` and `<history>`, plus the `<final>` states of the top level
/// (the machine's outcomes; nested finals are their container's outcomes, not
/// vertices); one arc per `<transition>` with a target, plus one per state
/// holding states (to its initial child).
fn count_scxml_graph(path: &Path) -> (usize, usize) {
    let text = std::fs::read_to_string(path).expect("read");
    // (element name, holds a state)
    let mut stack: Vec<(String, bool)> = Vec::new();
    let (mut n, mut arcs) = (0, 0);
    for (name, attrs, self_closing) in scan_tags(&text) {
        if let Some(closed) = name.strip_prefix('/') {
            let (open, compound) = stack.pop().expect("balanced");
            assert_eq!(open, closed);
            if compound {
                arcs += 1;
            }
            continue;
        }
        match name.as_str() {
            "state" | "history" => {
                n += 1;
                if let Some(parent) = stack.last_mut().filter(|(p, _)| p == "state") {
                    parent.1 = true;
                }
            }
            "final" if stack.last().map(|(p, _)| p.as_str()) == Some("scxml") => n += 1,
            "transition" if attr(&attrs, "target").is_some() => arcs += 1,
            _ => {}
        }
        if !self_closing {
            stack.push((name, false));
        }
    }
    (n, arcs)
}

#[test]
fn corpus_trees_import_analyze_draw_and_validate() {
    let model = nav2_model();
    for f in corpus_trees() {
        let file = f.display().to_string();
        let base = ["--nodes-model", model.as_str(), file.as_str()];
        let (code, stdout, stderr) =
            btfsm(&[&["analyze", "--format", "json"][..], &base[..]].concat());
        assert_eq!(code, 0, "{file}: {stderr}");
        let v: serde_json::Value = serde_json::from_str(&stdout).expect("json");
        let p = &v["policies"][0];
        assert_eq!(p["kind"], "bt", "{file}");
        let expected = count_tree_nodes(&f) as u64;
        assert_eq!(p["vertices"], expected, "{file}: vertices");
        assert_eq!(p["edges"], expected - 1, "{file}: a tree has V - 1 edges");
        assert_eq!(p["essential_cc"], 1, "{file}");
        let (code, dot, stderr) = btfsm(&[&["dot"][..], &base[..]].concat());
        assert_eq!(code, 0, "{file}: {stderr}");
        assert!(dot.starts_with("digraph"));
        assert_eq!(dot.matches(" -> ").count() as u64, expected - 1, "{file}");
        let (code, _, stderr) = btfsm(&[&["validate"][..], &base[..]].concat());
        assert_eq!(code, 0, "{file}: {stderr}");
        assert!(stderr.contains(": ok (bt"), "{stderr}");
    }
}

#[test]
fn corpus_scxml_imports_analyzes_draws_and_validates() {
    let files = corpus_files("scxml");
    assert!(!files.is_empty());
    for f in files {
        let file = f.display().to_string();
        let (code, stdout, stderr) = btfsm(&["analyze", "--format", "json", &file]);
        assert_eq!(code, 0, "{file}: {stderr}");
        let v: serde_json::Value = serde_json::from_str(&stdout).expect("json");
        let p = &v["policies"][0];
        let (vertices, arcs) = count_scxml_graph(&f);
        assert_eq!(p["vertices"], vertices as u64, "{file}");
        assert_eq!(p["edges"], arcs as u64, "{file}");
        let (code, dot, stderr) = btfsm(&["dot", &file]);
        assert_eq!(code, 0, "{file}: {stderr}");
        assert!(dot.starts_with("digraph"));
        let (code, _, stderr) = btfsm(&["validate", &file]);
        assert_eq!(code, 0, "{file}: {stderr}");
    }
    // The PackML machine: nested states make it an HFSM; its history state
    // and the Qt editor data do not break the import.
    let (_, stdout, _) = btfsm(&[
        "analyze",
        "--format",
        "json",
        &format!("{CORPUS}/scxml/packml_demo_sm.scxml"),
    ]);
    let v: serde_json::Value = serde_json::from_str(&stdout).expect("json");
    assert_eq!(v["policies"][0]["kind"], "hfsm");
}

#[test]
fn nav2_trees_need_their_nodes_model_or_assume_leaf() {
    let f = format!("{CORPUS}/bt-xml/nav2/follow_point.xml");
    let (code, _, stderr) = btfsm(&["validate", &f]);
    assert_eq!(code, 2);
    assert!(
        stderr.contains("unknown node type `PipelineSequence` (4 children)"),
        "{stderr}"
    );
    assert!(stderr.contains("--nodes-model FILE"), "{stderr}");
    // A leaf-only unknown type is settled by --assume-leaf.
    let f = format!("{CORPUS}/bt-xml/nav2/odometry_calibration.xml");
    let (code, _, stderr) = btfsm(&["validate", &f]);
    assert_eq!(code, 2, "{stderr}");
    let (code, _, stderr) = btfsm(&["validate", "--assume-leaf", "action", &f]);
    assert_eq!(code, 0, "{stderr}");
}

#[test]
fn lowercase_builtin_in_nav2_example_is_a_warning() {
    let f = format!("{CORPUS}/bt-xml/nav2/docking_application_example.xml");
    let (code, _, stderr) = btfsm(&["validate", "--nodes-model", &nav2_model(), &f]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stderr.contains("warning: `inverter` is not a BehaviorTree.CPP node type"),
        "{stderr}"
    );
    assert!(
        stderr.contains("docking_application_example.xml:22:13"),
        "{stderr}"
    );
}

/// A scratch directory for converted files.
fn scratch(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("btfsm-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).expect("tmp");
    d
}

/// `btfsm convert FILE --to TARGET -o OUT` (with the Nav2 model).
fn convert(file: &Path, to: &str, out: &Path) {
    let (code, _, stderr) = btfsm(&[
        "convert",
        "--nodes-model",
        &nav2_model(),
        &file.display().to_string(),
        "--to",
        to,
        "-o",
        &out.display().to_string(),
    ]);
    assert_eq!(code, 0, "convert {} --to {to}: {stderr}", file.display());
}

fn load(p: &Path) -> btfsm::model::Policy {
    let limits = btfsm::format::Limits {
        nodes_models: vec![PathBuf::from(nav2_model())],
        ..Default::default()
    };
    match btfsm::format::load(p, &limits) {
        Ok(l) => l.policy,
        Err(d) => panic!("{}: {d:?}", p.display()),
    }
}

/// Named GED between two policies, with the edit script on failure.
fn named_ged(a: &btfsm::model::Policy, b: &btfsm::model::Policy) -> (u64, String) {
    use btfsm::metrics::ged::{GedMode, GedOptions, ged};
    let (ga, gb) = (btfsm::graph::policy_graph(a), btfsm::graph::policy_graph(b));
    assert_eq!(ga.vertex_count(), gb.vertex_count());
    let r = ged(&ga, &gb, GedMode::Named, &GedOptions::default());
    (r.ged, format!("{:?}", r.edit_script))
}

/// A -> X -> A through two converters gives named GED 0 at every step.
fn round_trip(src: &Path, via: &str, back: &str, ext_via: &str, ext_back: &str, dir: &Path) {
    let stem = src.file_stem().expect("stem").to_string_lossy();
    let mid = dir.join(format!("{stem}.{ext_via}"));
    let end = dir.join(format!("{stem}.back.{ext_back}"));
    convert(src, via, &mid);
    convert(&mid, back, &end);
    let (a, b, c) = (load(src), load(&mid), load(&end));
    for (x, y, what) in [(&a, &b, via), (&a, &c, back)] {
        let (d, script) = named_ged(x, y);
        assert_eq!(d, 0, "{} -> {what}: named GED {d}\n{script}", src.display());
    }
    assert_eq!(a.kind(), c.kind());
    if let Err(e) = same_model(&a, &c) {
        panic!("{} -> {via} -> {back}: {e}", src.display());
    }
}

/// The same policy up to source positions and arena order: BT nodes compared
/// by id (label, kind, skill, type, ports, children), states by path (label,
/// body, transitions in order).
fn same_model(a: &btfsm::model::Policy, b: &btfsm::model::Policy) -> Result<(), String> {
    use btfsm::model::{PolicyBody, StateBody, Target};
    match (&a.body, &b.body) {
        (PolicyBody::Bt(x), PolicyBody::Bt(y)) => {
            let kids = |t: &btfsm::model::Bt, i: usize| -> Vec<String> {
                t.nodes[i]
                    .children
                    .iter()
                    .map(|&c| t.nodes[c].id.clone())
                    .collect()
            };
            if x.nodes[x.root].id != y.nodes[y.root].id {
                return Err("different roots".into());
            }
            for (i, n) in x.nodes.iter().enumerate() {
                let j = y
                    .nodes
                    .iter()
                    .position(|m| m.id == n.id)
                    .ok_or(format!("node `{}` lost", n.id))?;
                let m = &y.nodes[j];
                let l = (
                    &n.label,
                    n.kind,
                    &n.skill,
                    &n.type_name,
                    &n.ports,
                    kids(x, i),
                );
                let r = (
                    &m.label,
                    m.kind,
                    &m.skill,
                    &m.type_name,
                    &m.ports,
                    kids(y, j),
                );
                if l != r {
                    return Err(format!("node `{}`: {l:?} != {r:?}", n.id));
                }
            }
            Ok(())
        }
        (PolicyBody::Machine(x), PolicyBody::Machine(y)) => {
            let desc = |m: &btfsm::model::StateMachine, i: usize| {
                let s = &m.states[i];
                let body = match &s.body {
                    StateBody::Container(r) => format!(
                        "container initial={} outcomes={:?}",
                        m.states[r.initial].name, r.outcomes
                    ),
                    other => format!("{other:?}"),
                };
                let trs: Vec<String> = s
                    .transitions
                    .iter()
                    .map(|t| {
                        let to = match &t.target {
                            Target::State(j) => m.path(*j),
                            Target::Outcome(o) => format!("outcome {o}"),
                        };
                        format!("{:?} -> {to}", t.trigger)
                    })
                    .collect();
                format!("{} {body} {:?} {trs:?}", s.label, s.pseudo)
            };
            if (x.top.outcomes.clone(), x.states[x.top.initial].name.clone())
                != (y.top.outcomes.clone(), y.states[y.top.initial].name.clone())
            {
                return Err("different top level".into());
            }
            for i in 0..x.states.len() {
                let p = x.path(i);
                let j = (0..y.states.len())
                    .find(|&j| y.path(j) == p)
                    .ok_or(format!("state `{p}` lost"))?;
                let (l, r) = (desc(x, i), desc(y, j));
                if l != r {
                    return Err(format!("state `{p}`:\n  {l}\n  {r}"));
                }
            }
            Ok(())
        }
        _ => Err("different kinds".into()),
    }
}

#[test]
fn bundled_bts_round_trip_through_btcpp_xml_at_named_ged_0() {
    let dir = scratch("bt-rt");
    let mut n = 0;
    for f in fixtures_in("policies/paper") {
        if load(&f).kind() == btfsm::model::PolicyKind::Bt {
            round_trip(&f, "btcpp-xml", "toml", "xml", "toml", &dir);
            n += 1;
        }
    }
    assert!(n >= 14, "{n} BTs");
    std::fs::remove_dir_all(&dir).expect("cleanup");
}

#[test]
fn corpus_trees_round_trip_through_toml_at_named_ged_0() {
    let dir = scratch("xml-rt");
    for f in corpus_trees() {
        round_trip(&f, "toml", "btcpp-xml", "toml", "xml", &dir);
    }
    std::fs::remove_dir_all(&dir).expect("cleanup");
}

#[test]
fn machines_round_trip_through_scxml_at_named_ged_0() {
    let dir = scratch("scxml-rt");
    let mut n = 0;
    for f in fixtures_in("policies/paper") {
        if load(&f).kind() != btfsm::model::PolicyKind::Bt {
            round_trip(&f, "scxml", "toml", "scxml", "toml", &dir);
            n += 1;
        }
    }
    assert!(n >= 12, "{n} machines");
    for f in corpus_files("scxml") {
        round_trip(&f, "toml", "scxml", "toml", "scxml", &dir);
    }
    std::fs::remove_dir_all(&dir).expect("cleanup");
}

#[test]
fn converting_to_the_wrong_family_is_a_clear_error() {
    let (code, _, stderr) = btfsm(&[
        "convert",
        "policies/paper/fig04-fsm.toml",
        "--to",
        "btcpp-xml",
    ]);
    assert_eq!(code, 2);
    assert!(stderr.contains("holds behavior trees only"), "{stderr}");
    let (code, _, stderr) = btfsm(&["convert", "policies/paper/fig01-bt.toml", "--to", "scxml"]);
    assert_eq!(code, 2);
    assert!(stderr.contains("--to hfsm first"), "{stderr}");
}

fn fixtures_in(dir: &str) -> Vec<PathBuf> {
    let mut v: Vec<PathBuf> = std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join(dir))
        .expect("dir")
        .map(|e| e.expect("entry").path())
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
        .collect();
    v.sort();
    v
}

#[test]
fn compare_works_across_formats() {
    let dir = scratch("cmp");
    let xml = dir.join("fig07c.xml");
    convert(
        Path::new("policies/paper/fig07c-bt.toml"),
        "btcpp-xml",
        &xml,
    );
    let (code, stdout, stderr) = btfsm(&[
        "compare",
        "--format",
        "json",
        "policies/paper/fig01-bt.toml",
        &xml.display().to_string(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let v: serde_json::Value = serde_json::from_str(&stdout).expect("json");
    // SPEC §5: Fig. 1 -> Fig. 7c is 8 edits, whichever format B is in.
    assert_eq!(v["named"]["ged"], 8, "{stdout}");
    std::fs::remove_dir_all(&dir).expect("cleanup");
}

// ---- btfsm sim (issue 5): behavior-match verdicts of SPEC §6 ----

fn sim_json(scenario: &str) -> serde_json::Value {
    let (code, stdout, stderr) = btfsm(&["sim", scenario, "--format", "json"]);
    assert_eq!(code, 0, "{stderr}");
    serde_json::from_str(&stdout).expect("sim prints JSON")
}

fn sim_policy<'a>(v: &'a serde_json::Value, name: &str) -> &'a serde_json::Value {
    v["policies"]
        .as_array()
        .expect("policies")
        .iter()
        .find(|p| p["policy"] == name)
        .unwrap_or_else(|| panic!("no policy `{name}` in {v}"))
}

fn sim_verdict(v: &serde_json::Value, a: &str, b: &str) -> bool {
    let x = v["verdicts"]
        .as_array()
        .expect("verdicts")
        .iter()
        .find(|x| (x["a"] == a && x["b"] == b) || (x["a"] == b && x["b"] == a))
        .unwrap_or_else(|| panic!("no verdict {a} / {b}"));
    x["match"].as_bool().expect("bool")
}

const BT1: &str = "Fig. 1 BT baseline";
const HFSM1: &str = "Fig. 1 BT baseline (HFSM)";
const FSM4: &str = "Fig. 4 FSM fault tolerant";
const FSM2: &str = "Fig. 2 FSM sequential";

#[test]
fn sim_exp1_bt_fsm_and_hfsm_match_and_the_sequential_fsm_fails_on_a_failed_pick() {
    let v = sim_json("policies/scenarios/exp1-nominal.toml");
    for (a, b) in [(BT1, HFSM1), (BT1, FSM4), (BT1, FSM2)] {
        assert!(sim_verdict(&v, a, b), "{a} vs {b} in exp1-nominal");
    }
    let v = sim_json("policies/scenarios/exp1-pick-fails.toml");
    assert!(sim_verdict(&v, BT1, HFSM1));
    assert!(sim_verdict(&v, BT1, FSM4));
    assert!(!sim_verdict(&v, BT1, FSM2));
    for p in [BT1, HFSM1, FSM4] {
        assert_eq!(sim_policy(&v, p)["outcome"], "success", "{p}");
        let skills = sim_policy(&v, p)["skills"].as_array().unwrap();
        assert_eq!(skills[1]["skill"], "Pick");
        assert_eq!(skills[1]["outcome"], "failure");
        assert_eq!(skills[2]["outcome"], "success");
    }
    let fsm2 = sim_policy(&v, FSM2);
    assert_eq!(fsm2["outcome"], "failure");
    assert_eq!(fsm2["goal_met"], false);
    assert!(fsm2["reason"].as_str().unwrap().contains("Pick cube2"));
}

#[test]
fn sim_only_the_bt_fetches_the_cube_again_after_the_task_is_done() {
    let v = sim_json("policies/scenarios/exp1-cube-moved-after-done.toml");
    let picks = |p: &str| {
        sim_policy(&v, p)["skills"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|s| s["skill"] == "Pick" && s["outcome"] == "success")
            .count()
    };
    assert_eq!(picks(BT1), 2);
    assert_eq!(picks(FSM4), 1);
    assert_eq!(picks(HFSM1), 1);
    assert_eq!(
        sim_policy(&v, BT1)["final_world"]["objects"]["cube2"]["at"],
        "delivery"
    );
    assert_eq!(
        sim_policy(&v, FSM4)["final_world"]["objects"]["cube2"]["at"],
        "west-table"
    );
    assert!(!sim_verdict(&v, BT1, FSM4));
    assert!(sim_verdict(&v, HFSM1, FSM4));
}

#[test]
fn sim_recharge_docking_arena_and_five_cubes_match() {
    let cases = [
        (
            "exp2-recharge",
            "Fig. 7d BT recharge",
            "Fig. 8d FSM recharge",
        ),
        ("exp3-docking", "Fig. 15 BT docking", "Fig. 15 FSM docking"),
        ("exp5-arena", "Fig. 15 BT docking", "Fig. 15 FSM docking"),
        (
            "exp4-five-cubes",
            "Fig. 16a BT five cubes",
            "Fig. 16b FSM five cubes",
        ),
    ];
    for (scn, bt, fsm) in cases {
        let v = sim_json(&format!("policies/scenarios/{scn}.toml"));
        assert!(sim_verdict(&v, bt, fsm), "{scn}");
        for p in [bt, fsm] {
            let r = sim_policy(&v, p);
            assert_eq!(r["outcome"], "success", "{scn} {p}");
            assert_eq!(r["goal_met"], true, "{scn} {p}");
            // Every one of these scenarios makes the robot recharge.
            assert!(
                r["skills"]
                    .as_array()
                    .unwrap()
                    .iter()
                    .any(|s| s["skill"] == "Recharge" && s["outcome"] == "success"),
                "{scn} {p}"
            );
        }
    }
}

#[test]
fn sim_reports_the_fig03_bt_as_chattering() {
    let v = sim_json("policies/scenarios/fig03-chattering.toml");
    let r = sim_policy(&v, "Fig. 3 BT chattering");
    assert_eq!(r["outcome"], "chattering");
    assert!(r["steps"].as_u64().unwrap() < 1000);
    assert_eq!(sim_policy(&v, BT1)["outcome"], "success");
}

#[test]
fn sim_is_deterministic() {
    let a = btfsm(&[
        "sim",
        "policies/scenarios/exp3-docking.toml",
        "--format",
        "json",
    ]);
    let b = btfsm(&[
        "sim",
        "policies/scenarios/exp3-docking.toml",
        "--format",
        "json",
    ]);
    assert_eq!(a, b);
}

/// A scenario naming an unknown object, station or skill, or a pose inside a
/// wall or table, exits 2 with the recorded positioned messages.
#[test]
fn sim_rejects_bad_scenarios_with_positioned_messages() {
    let bless = std::env::var_os("BLESS").is_some();
    let mut failures = Vec::new();
    let files = fixtures("sim-invalid");
    assert!(files.len() >= 5);
    for f in files {
        let (code, stdout, stderr) = btfsm(&["sim", &rel(&f)]);
        let expected_path = f.with_extension("stderr");
        if bless {
            std::fs::write(&expected_path, &stderr).expect("write expected");
        }
        let expected = std::fs::read_to_string(&expected_path).unwrap_or_default();
        let positioned = stderr
            .lines()
            .any(|l| l.trim_start().starts_with("--> ") && l.matches(':').count() >= 2);
        if code != 2 || !stdout.is_empty() || stderr != expected || !positioned {
            failures.push(format!(
                "{}: exit {code}\n--- stderr\n{stderr}--- expected\n{expected}",
                rel(&f)
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn dot_colours_nodes_by_their_status_at_a_trace_step() {
    let dir = std::env::temp_dir().join(format!("btfsm-dot-trace-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let trace = dir.join("exp2.json");
    let plot = dir.join("exp2.svg");
    let (code, _, stderr) = btfsm(&[
        "sim",
        "policies/scenarios/exp2-recharge.toml",
        "--trace",
        trace.to_str().unwrap(),
        "--plot",
        plot.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let svg = std::fs::read_to_string(&plot).unwrap();
    assert!(
        svg.starts_with("<svg")
            && svg.contains("central table")
            && svg.contains("Fig. 8d FSM recharge")
    );
    // Step 45 (t = 4.5 s): the battery is low and the robot drives to the charger.
    let (code, dot, stderr) = btfsm(&[
        "dot",
        "policies/paper/fig07d-bt.toml",
        "--trace",
        trace.to_str().unwrap(),
        "--step",
        "45",
    ]);
    assert_eq!(code, 0, "{stderr}");
    let line = |id: &str| {
        dot.lines()
            .find(|l| l.trim_start().starts_with(id))
            .unwrap_or("")
            .to_string()
    };
    assert!(line("recharge[").contains("fillcolor=gold"), "{dot}");
    assert!(
        line("\"battery-ok\"[").contains("fillcolor=tomato"),
        "{dot}"
    );
    assert!(line("root[").contains("fillcolor=gold"), "{dot}");
    assert!(!line("pick[").contains("gold"), "{dot}");
    let (code, dot, _) = btfsm(&[
        "dot",
        "policies/paper/fig08d-fsm.toml",
        "--trace",
        trace.to_str().unwrap(),
        "--step",
        "45",
    ]);
    assert_eq!(code, 0);
    assert!(
        line_of(&dot, "Recharge[").contains("fillcolor=gold"),
        "{dot}"
    );
    let (code, _, stderr) = btfsm(&[
        "dot",
        "policies/paper/fig07d-bt.toml",
        "--trace",
        trace.to_str().unwrap(),
        "--step",
        "999999",
    ]);
    assert_eq!(code, 2);
    assert!(stderr.contains("past the end of the trace"), "{stderr}");
    std::fs::remove_dir_all(&dir).unwrap();
}

fn line_of(dot: &str, id: &str) -> String {
    dot.lines()
        .find(|l| l.trim_start().starts_with(id))
        .unwrap_or("")
        .to_string()
}
