//! `btfsm paper`, `btfsm effort`, `btfsm convert --to fault-tolerant` and
//! `btfsm edit` through the built binary: exit codes, JSON contract (SPEC §5,
//! §7), the regression check and the generated docs/paper-results.md.

use std::path::{Path, PathBuf};

use crate::common::btfsm;

fn crate_path(p: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(p)
}

fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("btfsm-{tag}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("tmp");
    d
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).expect("mkdir");
    for e in std::fs::read_dir(from).expect("read dir") {
        let e = e.expect("entry");
        let target = to.join(e.file_name());
        if e.file_type().expect("type").is_dir() {
            copy_dir(&e.path(), &target);
        } else {
            std::fs::copy(e.path(), &target).expect("copy");
        }
    }
}

fn paper_json() -> serde_json::Value {
    let (code, stdout, stderr) = btfsm(&["paper", "--format", "json"]);
    assert_eq!(code, 0, "{stderr}");
    serde_json::from_str(&stdout).expect("json")
}

fn cell<'a>(
    json: &'a serde_json::Value,
    table: &str,
    row: &str,
    column: &str,
) -> &'a serde_json::Value {
    json["rows"]
        .as_array()
        .expect("rows")
        .iter()
        .find(|r| r["table"] == table && r["row"] == row && r["column"] == column)
        .unwrap_or_else(|| panic!("no cell {table} / {row} / {column}"))
}

#[test]
fn paper_check_passes_on_the_bundled_policies() {
    let (code, stdout, stderr) = btfsm(&["paper", "--check"]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stdout.is_empty());
    assert!(stderr.contains("match"), "{stderr}");
}

#[test]
fn paper_check_names_the_cell_a_policy_edit_changes() {
    let dir = temp_dir("paper-check");
    let copy = dir.join("paper");
    copy_dir(&crate_path("policies/paper"), &copy);
    // Drop Tuck arm's RUNNING self-loop from Fig. 8a.
    let f = copy.join("fig08a-fsm.toml");
    let text = std::fs::read_to_string(&f).expect("fig08a");
    let edited = text.replace(
        "FAILURE = \"SELECTOR\", RUNNING = \"Tuck arm\" }",
        "FAILURE = \"SELECTOR\" }",
    );
    assert_ne!(text, edited, "the edit applies");
    std::fs::write(&f, edited).expect("write");
    let copy_s = copy.display().to_string();
    let (code, stdout, stderr) = btfsm(&["paper", "--check", "--policies", &copy_s]);
    assert_eq!(code, 1, "{stderr}");
    assert!(stdout.is_empty());
    assert!(
        stderr.contains("Table II / Tuck arm / FSM named GED: computed 6, recorded 7"),
        "{stderr}"
    );
    assert!(stderr.contains("--record"), "{stderr}");
    // A broken policy file is bad input (exit 2, positioned message).
    std::fs::write(copy.join("fig04-fsm.toml"), "kind = \"fsm\"\nname = [\n").expect("write");
    let (code, _, stderr) = btfsm(&["paper", "--check", "--policies", &copy_s]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("fig04-fsm.toml:"), "{stderr}");
    // A missing file several tables need is said once, not once per table.
    std::fs::remove_file(copy.join("fig07d-bt.toml")).expect("remove");
    let (code, _, stderr) = btfsm(&["paper", "--check", "--policies", &copy_s]);
    assert_eq!(code, 2, "{stderr}");
    let said = stderr.matches("fig07d-bt.toml").count();
    assert!(said >= 1, "{stderr}");
    let lines: Vec<&str> = stderr
        .lines()
        .filter(|l| l.starts_with("error:") && l.contains("fig07d-bt.toml"))
        .collect();
    assert_eq!(lines.len(), 1, "{stderr}");
    std::fs::remove_dir_all(&dir).expect("cleanup");
}

#[test]
fn paper_json_rows_have_the_contract_fields() {
    let j = paper_json();
    for r in j["rows"].as_array().expect("rows") {
        let mut keys: Vec<&str> = r
            .as_object()
            .expect("row")
            .keys()
            .map(|k| k.as_str())
            .collect();
        keys.sort_unstable();
        assert_eq!(
            keys,
            [
                "column", "computed", "note", "paper", "row", "status", "table"
            ]
        );
        let differs = r["status"] == "differs";
        assert!(differs || r["status"] == "match");
        assert_eq!(r["note"].is_string(), differs, "{r}");
    }
}

/// SPEC §5, Table II: BT, FSM structural, FSM named, Eq. 3.
#[test]
fn paper_json_holds_the_values_of_table_ii() {
    let j = paper_json();
    for (row, bt, fs, fnm, eq3) in [
        ("Tuck arm", 6, 5, 7, 12),
        ("Safe-Move-To", 2, 6, 6, 4),
        ("Dock", 8, 5, 7, 17),
        ("Recharge", 8, 8, 8, 17),
    ] {
        let c = |col: &str| cell(&j, "Table II", row, col)["computed"].clone();
        assert_eq!(c("BT structural GED"), bt, "{row}");
        assert_eq!(c("BT named GED"), bt, "{row}");
        assert_eq!(c("FSM structural GED"), fs, "{row}");
        assert_eq!(c("FSM named GED"), fnm, "{row}");
        assert_eq!(c("HFSM Eq. 3"), eq3, "{row}");
    }
    let safe = cell(&j, "Table II", "Safe-Move-To", "FSM structural GED");
    assert_eq!(
        (safe["paper"].as_i64(), safe["status"].as_str()),
        (Some(4), Some("differs"))
    );
    assert!(safe["note"].as_str().expect("note").contains("NetworkX"));
    let eq = cell(&j, "Table II", "Recharge", "HFSM structural GED");
    assert!(eq["note"].as_str().expect("note").contains("Eq. 3"));
}

/// SPEC §5, Table III: CC, GED, graphical, active (BT / FSM).
#[test]
fn paper_json_holds_the_values_of_table_iii() {
    let j = paper_json();
    for (row, cc, ged, gr, ac) in [
        ("Development baseline", (1, 14), None, (27, 24), (14, 24)),
        (
            "Development recharge",
            (1, 20),
            Some((8, 8)),
            (35, 32),
            (18, 32),
        ),
        (
            "Development docking",
            (1, 24),
            Some((6, 8)),
            (41, 38),
            (21, 38),
        ),
        ("Scalability baseline", (1, 68), None, (153, 114), (77, 114)),
        (
            "Scalability recharge",
            (1, 92),
            Some((6, 26)),
            (159, 140),
            (80, 140),
        ),
    ] {
        let c = |col: &str| cell(&j, "Table III", row, col)["computed"].clone();
        assert_eq!(
            (c("CC BT (essential)"), c("CC FSM (cc)")),
            (cc.0.into(), cc.1.into()),
            "{row}"
        );
        assert_eq!(
            (c("graphical BT"), c("graphical FSM")),
            (gr.0.into(), gr.1.into()),
            "{row}"
        );
        assert_eq!(
            (c("active BT"), c("active FSM")),
            (ac.0.into(), ac.1.into()),
            "{row}"
        );
        if let Some((b, f)) = ged {
            assert_eq!(
                (c("GED BT named"), c("GED FSM named")),
                (b.into(), f.into()),
                "{row}"
            );
        }
    }
    let dock = cell(&j, "Table III", "Development docking", "GED FSM structural");
    assert_eq!(dock["computed"], 6);
    assert_eq!(dock["status"], "differs");
}

/// SPEC §5, effort: 15 and 22, by formula and by named GED; structural 14
/// for Fig. 10.
#[test]
fn paper_json_holds_the_effort_values() {
    let j = paper_json();
    for (row, e) in [("Fig. 2 -> Fig. 4", 15), ("Fig. 10 -> Fig. 11", 22)] {
        let c = |col: &str| cell(&j, "Effort", row, col)["computed"].clone();
        assert_eq!(c("Eq. 4"), e);
        assert_eq!(c("named GED to generated transform"), e);
        assert_eq!(c("named GED to the paper's figure"), e);
        assert_eq!(c("named GED generated transform to the paper's figure"), 0);
    }
    assert_eq!(
        cell(
            &j,
            "Effort",
            "Fig. 10 -> Fig. 11",
            "structural GED to the paper's figure"
        )["computed"],
        14
    );
}

#[test]
fn paper_results_doc_is_fresh() {
    let (code, stdout, stderr) = btfsm(&["paper", "--format", "markdown"]);
    assert_eq!(code, 0, "{stderr}");
    let doc = std::fs::read_to_string(crate_path("docs/paper-results.md")).unwrap_or_default();
    assert!(
        doc == stdout,
        "docs/paper-results.md is stale: regenerate it with `make paper-docs` (btfsm paper --format markdown -o docs/paper-results.md) and commit it"
    );
}

#[test]
fn paper_table_lists_every_table() {
    let (code, stdout, _) = btfsm(&["paper"]);
    assert_eq!(code, 0);
    for t in ["Table I:", "Table II:", "Table III:", "Effort (Eq. 4)"] {
        assert!(stdout.contains(t), "{t}");
    }
    let (code, _, stderr) = btfsm(&["paper", "--policies", "no/such/dir"]);
    assert_eq!(code, 2);
    assert!(stderr.contains("no/such/dir"), "{stderr}");
}

#[test]
fn effort_reports_formula_and_named_ged() {
    let (code, stdout, stderr) = btfsm(&[
        "effort",
        "policies/paper/fig02-fsm.toml",
        "policies/paper/fig10-fsm.toml",
        "policies/paper/fig01-bt.toml",
        "--format",
        "json",
    ]);
    assert_eq!(code, 0, "{stderr}");
    let j: serde_json::Value = serde_json::from_str(&stdout).expect("json");
    let p = j["policies"].as_array().expect("policies");
    let get = |i: usize, k: &str| p[i][k].clone();
    assert_eq!(
        (
            get(0, "m_s"),
            get(0, "m_fc"),
            get(0, "formula"),
            get(0, "named_ged")
        ),
        (4.into(), 0.into(), 15.into(), 15.into())
    );
    assert_eq!(
        (
            get(1, "m_s"),
            get(1, "m_fc"),
            get(1, "formula"),
            get(1, "named_ged")
        ),
        (4.into(), 1.into(), 22.into(), 22.into())
    );
    assert_eq!(get(1, "structural_ged"), 14);
    assert_eq!(get(1, "connected"), serde_json::json!(["Recharge"]));
    assert_eq!(
        (get(2, "formula"), get(2, "named_ged")),
        (0.into(), serde_json::Value::Null)
    );
    assert!(
        get(2, "note")
            .as_str()
            .expect("note")
            .contains("reactive by construction")
    );
    let (code, stdout, _) = btfsm(&["effort", "policies/paper/fig10-fsm.toml"]);
    assert_eq!(code, 0);
    assert!(
        stdout.contains("Eq. 4") && stdout.contains("connected [Recharge]"),
        "{stdout}"
    );
}

#[test]
fn convert_to_fault_tolerant_writes_a_valid_reactive_fsm() {
    let dir = temp_dir("ft");
    let out = dir.join("fig10-ft.toml").display().to_string();
    let (code, _, stderr) = btfsm(&[
        "convert",
        "policies/paper/fig10-fsm.toml",
        "--to",
        "fault-tolerant",
        "-o",
        &out,
    ]);
    assert_eq!(code, 0, "{stderr}");
    let (code, _, stderr) = btfsm(&["validate", &out]);
    assert_eq!(code, 0, "{stderr}");
    // Already fault tolerant: nothing left to add.
    let (code, stdout, _) = btfsm(&["effort", &out, "--format", "json"]);
    assert_eq!(code, 0);
    let j: serde_json::Value = serde_json::from_str(&stdout).expect("json");
    assert_eq!(j["policies"][0]["named_ged"], 0);
    // BTs have no fault-tolerant FSM.
    let (code, _, stderr) = btfsm(&[
        "convert",
        "policies/paper/fig01-bt.toml",
        "--to",
        "fault-tolerant",
    ]);
    assert_eq!(code, 2);
    assert!(stderr.contains("flat FSMs"), "{stderr}");
    std::fs::remove_dir_all(&dir).expect("cleanup");
}

fn counts(file: &str) -> (u64, u64) {
    let (code, stdout, stderr) = btfsm(&["analyze", file, "--format", "json"]);
    assert_eq!(code, 0, "{stderr}");
    let j: serde_json::Value = serde_json::from_str(&stdout).expect("json");
    let p = &j["policies"][0];
    (
        p["vertices"].as_u64().expect("vertices"),
        p["edges"].as_u64().expect("edges"),
    )
}

#[test]
fn edit_commands_rebuild_fig07c_and_fig08a() {
    let dir = temp_dir("edit");
    let wrapped = dir.join("wrapped.toml").display().to_string();
    let fig07c = dir.join("fig07c.toml").display().to_string();
    let (code, _, stderr) = btfsm(&[
        "edit",
        "policies/paper/fig01-bt.toml",
        "wrap-root",
        "--kind",
        "sequence",
        "--id",
        "root",
        "-o",
        &wrapped,
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.contains("(2 unit edits)"), "{stderr}");
    let (code, _, stderr) = btfsm(&[
        "edit",
        &wrapped,
        "insert-subtree",
        "--parent",
        "root",
        "--subtree",
        "policies/paper/lib/dock.toml",
        "-o",
        &fig07c,
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.contains("(6 unit edits)"), "{stderr}");
    assert_eq!(counts(&fig07c), (18, 17));

    let fig08a = dir.join("fig08a.toml").display().to_string();
    let (code, _, stderr) = btfsm(&[
        "edit",
        "policies/paper/fig04-fsm.toml",
        "add-state",
        "--kind",
        "sequential",
        "--name",
        "Tuck arm",
        "--after",
        "Pick cube2",
        "--skill",
        "Tuck-Arm",
        "--selector-guard",
        "In-Hand(object=cube2) & not Arm-Tucked",
        "-o",
        &fig08a,
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(stderr.contains("+5 -1 (7 unit edits)"), "{stderr}");
    assert_eq!(counts(&fig08a), (7, 22));
    let (code, _, stderr) = btfsm(&["effort", &fig08a, "--format", "json"]);
    assert_eq!(code, 0, "{stderr}");

    // Wrong kind of policy, bad guard: exit 2, no file written.
    let bad = dir.join("bad.toml");
    let bad_s = bad.display().to_string();
    let (code, _, stderr) = btfsm(&[
        "edit",
        "policies/paper/fig01-bt.toml",
        "add-state",
        "--kind",
        "connected",
        "--name",
        "Recharge",
        "--skill",
        "Recharge",
        "-o",
        &bad_s,
    ]);
    assert_eq!(code, 2);
    assert!(
        stderr.contains("add-state edits FSMs and HFSMs"),
        "{stderr}"
    );
    let (code, _, stderr) = btfsm(&[
        "edit",
        "policies/paper/fig04-fsm.toml",
        "add-state",
        "--kind",
        "connected",
        "--name",
        "Recharge",
        "--skill",
        "Recharge",
        "--guard",
        "not Battery-Lvl(min=20)",
        "-o",
        &bad_s,
    ]);
    assert_eq!(code, 2);
    assert!(stderr.contains("unknown skill `Battery-Lvl`"), "{stderr}");
    assert!(!bad.exists());
    std::fs::remove_dir_all(&dir).expect("cleanup");
}

/// An edit the policy refuses is one diagnostic: the message, then its hint
/// on a line of its own (it once printed a literal `\n` before the hint).
#[test]
fn edit_errors_print_their_hint_on_its_own_line() {
    let (code, out, err) = btfsm(&[
        "edit",
        "policies/paper/fig01-bt.toml",
        "insert-subtree",
        "--parent",
        "nosuch",
        "--subtree",
        "policies/paper/lib/tuck-arm.toml",
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(out.is_empty());
    assert!(!err.contains("\\n"), "{err}");
    let lines: Vec<&str> = err.lines().collect();
    assert_eq!(
        lines.first().copied(),
        Some("error: policies/paper/fig01-bt.toml: unknown node `nosuch`"),
        "{err}"
    );
    assert!(
        lines
            .get(1)
            .is_some_and(|l| l.starts_with("  = hint: control nodes of the tree:")),
        "{err}"
    );
}
