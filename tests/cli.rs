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
        .filter(|p| p.extension().is_some_and(|e| e == "toml"))
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

// ------------------------------------------------------------ hostile input
//
// Each answered with exit 2 and a message (or 0 where the input is legal but
// large), in bounded time and memory; inputs are generated in milliseconds.

/// A scratch directory removed on drop.
struct Scratch(PathBuf);

impl Scratch {
    fn new(tag: &str) -> Scratch {
        let d = std::env::temp_dir().join(format!("btfsm-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).expect("tmp");
        Scratch(d)
    }

    fn write(&self, name: &str, text: impl AsRef<[u8]>) -> String {
        let p = self.0.join(name);
        std::fs::write(&p, text).expect("write");
        p.display().to_string()
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

fn deep_bt(levels: usize) -> String {
    let mut s = String::from("kind = \"bt\"\nroot = \"n0\"\n[nodes]\n");
    for i in 0..levels {
        s.push_str(&format!("n{i} = {{ inverter = \"n{}\" }}\n", i + 1));
    }
    s.push_str(&format!(
        "n{levels} = {{ action = \"Dock!\", skill = \"Dock\" }}\n"
    ));
    s
}

#[test]
fn hostile_deep_bt_is_refused_by_the_depth_limit() {
    let dir = Scratch::new("deep-bt");
    let f = dir.write("deep.toml", deep_bt(100_000));
    let (code, _, stderr) = btfsm(&["analyze", &f]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("levels below the root, deeper than the limit of 1000 levels")
            && stderr.contains("--max-depth"),
        "{stderr}"
    );
    // Legal when the limit is raised: analyzed and drawn without recursion.
    let (code, stdout, stderr) =
        btfsm(&["analyze", &f, "--max-depth", "200000", "--format", "json"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.contains("\"vertices\": 100001"), "{stdout}");
    let out = dir.0.join("deep.dot").display().to_string();
    let (code, _, stderr) = btfsm(&["dot", &f, "--max-depth", "200000", "-o", &out]);
    assert_eq!(code, 0, "{stderr}");
}

#[test]
fn hostile_deep_nesting_in_toml_is_a_positioned_error() {
    let dir = Scratch::new("deep-nest");
    let n = 100_000;
    // An HFSM nested 100k containers deep (inline tables), and arrays.
    let mut hfsm =
        String::from("kind = \"hfsm\"\ninitial = \"s\"\noutcomes = [\"SUCCESS\"]\nstates = ");
    for _ in 0..n {
        hfsm.push_str("{ s = { initial = \"s\", outcomes = [\"SUCCESS\"], states = ");
    }
    hfsm.push_str("{ s = { skill = \"Dock\" } }");
    for _ in 0..n {
        hfsm.push_str(" } }");
    }
    let arrays = format!("kind = \"bt\"\nx = {}{}\n", "[".repeat(n), "]".repeat(n));
    for (name, text) in [("hfsm.toml", hfsm), ("arrays.toml", arrays)] {
        let f = dir.write(name, text);
        let (code, _, stderr) = btfsm(&["validate", &f]);
        assert_eq!(code, 2, "{stderr}");
        assert!(stderr.contains("nested too deeply"), "{stderr}");
        assert!(stderr.contains(&format!("{name}:")), "{stderr}");
    }
    // HFSM headers: the TOML reader's nesting limit, said once.
    let mut headers = String::from("kind = \"hfsm\"\ninitial = \"s\"\noutcomes = [\"SUCCESS\"]\n");
    let mut key = String::from("states.s");
    for _ in 0..60 {
        headers.push_str(&format!(
            "[{key}]\ninitial = \"s\"\noutcomes = [\"SUCCESS\"]\non = {{ SUCCESS = \"SUCCESS\" }}\n"
        ));
        key.push_str(".states.s");
    }
    let f = dir.write("headers.toml", headers);
    let (code, _, stderr) = btfsm(&["validate", &f]);
    assert_eq!(code, 2, "{stderr}");
    assert_eq!(stderr.matches("nested too deeply").count(), 1, "{stderr}");
}

#[test]
fn hostile_ten_megabyte_names_are_refused() {
    let dir = Scratch::new("names");
    let long = "x".repeat(10 << 20);
    let cases = [
        format!("kind = \"bt\"\n[nodes]\nroot = {{ action = \"{long}\" }}\n"),
        format!("kind = \"bt\"\n[nodes]\n{long} = {{ action = \"Dock!\" }}\n"),
        format!(
            "kind = \"fsm\"\ninitial = \"{long}\"\noutcomes = [\"SUCCESS\"]\n[states.\"{long}\"]\non = {{ SUCCESS = \"SUCCESS\" }}\n"
        ),
    ];
    for (i, text) in cases.iter().enumerate() {
        let f = dir.write(&format!("long{i}.toml"), text);
        let (code, _, stderr) = btfsm(&["analyze", &f]);
        assert_eq!(code, 2, "{stderr}");
        assert!(
            stderr.contains("is 10485760 bytes long, more than the limit of 4096 bytes")
                && stderr.contains("--max-name-bytes"),
            "{}",
            &stderr[..stderr.len().min(2000)]
        );
        assert!(
            stderr.len() < 20_000,
            "the message quotes the name, not 10 MB"
        );
    }
}

fn xorshift(seed: u64) -> impl FnMut() -> u64 {
    let mut x = seed;
    move || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x
    }
}

#[test]
fn hostile_binary_garbage_and_devices() {
    let dir = Scratch::new("garbage");
    let mut next = xorshift(7);
    let bytes: Vec<u8> = (0..1 << 20).map(|_| next() as u8).collect();
    let f = dir.write("garbage.toml", &bytes);
    let (code, _, stderr) = btfsm(&["analyze", &f]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("not valid UTF-8"), "{stderr}");
    // Valid UTF-8 noise: TOML errors, at most 20 of them.
    let text: String = (0..1 << 18)
        .map(|_| char::from_u32((next() % 0x3000) as u32).unwrap_or('?'))
        .collect();
    let f = dir.write("noise.toml", text);
    let (code, _, stderr) = btfsm(&["validate", &f]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("error:") && stderr.matches("error:").count() <= 22,
        "{stderr}"
    );
    // A device has no size: reading stops past the limit.
    if Path::new("/dev/zero").exists() {
        let (code, _, stderr) = btfsm(&["analyze", "/dev/zero", "--max-file-bytes", "4096"]);
        assert_eq!(code, 2, "{stderr}");
        assert!(
            stderr.contains("larger than the limit of 4096 bytes"),
            "{stderr}"
        );
        let f = dir.write(
            "dev.toml",
            "kind = \"bt\"\n[nodes]\nroot = { subtree = \"/dev/zero\" }\n",
        );
        let (code, _, stderr) = btfsm(&["analyze", &f]);
        assert_eq!(code, 2, "{stderr}");
        assert!(stderr.contains("not a regular file"), "{stderr}");
    }
}

#[test]
fn hostile_include_loops_are_refused() {
    let dir = Scratch::new("loops");
    let node = |to: &str| {
        format!(
            "kind = \"bt\"\n[nodes]\nroot = {{ sequence = [\"s\"] }}\ns = {{ subtree = \"{to}\" }}\n"
        )
    };
    dir.write("self.toml", node("self.toml"));
    dir.write("a.toml", node("b.toml"));
    dir.write("b.toml", node("c.toml"));
    dir.write("c.toml", node("a.toml"));
    for (f, chain) in [
        ("self.toml", "self.toml -> self.toml"),
        ("a.toml", "a.toml -> b.toml -> c.toml -> a.toml"),
    ] {
        let (code, _, stderr) = btfsm(&["analyze", &dir.0.join(f).display().to_string()]);
        assert_eq!(code, 2, "{stderr}");
        assert!(
            stderr.contains(&format!("cyclic subtree include: {chain}")),
            "{stderr}"
        );
    }
}

/// `e0` includes `e1` twice, which includes `e2` twice, ...: 2^40 leaves
/// if expanded. Each file is read once and the node budget stops the
/// expansion as soon as it is spent.
#[test]
fn hostile_exponential_subtree_include_hits_the_node_budget() {
    let dir = Scratch::new("expo");
    let k = 40;
    for i in 0..k {
        dir.write(
            &format!("e{i}.toml"),
            format!(
                "kind = \"bt\"\n[nodes]\nroot = {{ sequence = [\"l\", \"r\"] }}\nl = {{ subtree = \"e{0}.toml\" }}\nr = {{ subtree = \"e{0}.toml\" }}\n",
                i + 1
            ),
        );
    }
    dir.write(
        &format!("e{k}.toml"),
        "kind = \"bt\"\n[nodes]\nleaf = { action = \"Dock!\", skill = \"Dock\" }\n",
    );
    let e0 = dir.0.join("e0.toml").display().to_string();
    for (limit, flag) in [
        ("100000", vec!["--max-nodes", "100000"]),
        ("2000000", vec![]),
    ] {
        let mut args = vec!["analyze", e0.as_str()];
        args.extend(flag);
        let (code, _, stderr) = btfsm(&args);
        assert_eq!(code, 2, "{stderr}");
        assert!(
            stderr.contains(&format!("more than {limit} nodes")) && stderr.contains("--max-nodes"),
            "{stderr}"
        );
    }
    // Below the budget the expansion is legal: 2^12 leaves.
    let e = dir
        .0
        .join(format!("e{}.toml", k - 12))
        .display()
        .to_string();
    let (code, stdout, stderr) = btfsm(&["analyze", &e, "--format", "json"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        stdout.contains(&format!("\"vertices\": {}", (1 << 13) - 1)),
        "{stdout}"
    );
}

#[test]
fn hostile_million_problems_are_reported_in_bounded_time() {
    let dir = Scratch::new("many");
    let mut s = String::from("kind = \"bt\"\nroot = \"root\"\n[nodes]\nroot = { sequence = [");
    let n = 200_000;
    for i in 0..n {
        s.push_str(&format!("\"missing{i}\", "));
    }
    s.push_str("] }\n");
    for i in 0..n {
        s.push_str(&format!("n{i} = {{ action = \"A{i}\" }}\n"));
    }
    let f = dir.write("many.toml", s);
    let (code, _, stderr) = btfsm(&["validate", &f]);
    assert_eq!(code, 2);
    assert!(
        stderr.contains("more errors not shown"),
        "{}",
        &stderr[stderr.len().saturating_sub(2000)..]
    );
}

/// Ctrl-C at any moment leaves either no output file or the whole one,
/// never a prefix; a temporary left by the interrupted run is removed by
/// the next run writing the same file.
#[cfg(unix)]
#[test]
fn interrupted_runs_leave_no_partial_output() {
    use std::process::{Command, Stdio};
    use std::time::Duration;
    let dir = Scratch::new("sigint");
    let mut s = String::from("kind = \"bt\"\nroot = \"n0\"\n[nodes]\nn0 = { sequence = [");
    let n = 30_000;
    s.push_str(
        &(1..n)
            .map(|i| format!("\"n{i}\""))
            .collect::<Vec<_>>()
            .join(", "),
    );
    s.push_str("] }\n");
    for i in 1..n {
        s.push_str(&format!(
            "n{i} = {{ action = \"Act {i}!\", skill = \"Dock\" }}\n"
        ));
    }
    let input = dir.write("big.toml", s);
    let reference = dir.0.join("reference.toml").display().to_string();
    let (code, _, stderr) = btfsm(&["convert", &input, "--to", "toml", "-o", &reference]);
    assert_eq!(code, 0, "{stderr}");
    let whole = std::fs::read(&reference).expect("reference");
    let out = dir.0.join("out.toml");
    for delay_ms in [5u64, 20, 60, 150, 300, 600, 1200] {
        let _ = std::fs::remove_file(&out);
        let mut child = Command::new(env!("CARGO_BIN_EXE_btfsm"))
            .args(["convert", &input, "--to", "toml", "-o"])
            .arg(&out)
            .stderr(Stdio::null())
            .spawn()
            .expect("spawn");
        std::thread::sleep(Duration::from_millis(delay_ms));
        let _ = Command::new("kill")
            .args(["-INT", &child.id().to_string()])
            .status();
        let _ = child.wait();
        if let Ok(got) = std::fs::read(&out) {
            assert!(
                got == whole,
                "interrupted after {delay_ms} ms: partial output"
            );
        }
    }
    let (code, _, stderr) = btfsm(&[
        "convert",
        &input,
        "--to",
        "toml",
        "-o",
        &out.display().to_string(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    let stray: Vec<_> = std::fs::read_dir(&dir.0)
        .expect("dir")
        .flatten()
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|f| f.ends_with(".tmp"))
        .collect();
    assert!(stray.is_empty(), "temporaries left: {stray:?}");
}
