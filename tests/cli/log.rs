//! `btfsm log` on logs BehaviorTree.CPP wrote (tests/fixtures/logs/): report,
//! coverage gate, markdown, dot, compare (with the simulator), timeline,
//! .db3 sessions; corrupt or hostile logs refused with exit 2.

use super::*;
use common::scratch;

const FIG01: &str = "tests/fixtures/logs/fig01.btlog";

#[test]
fn log_report_counts_every_record_of_a_behaviortree_cpp_log() {
    let (code, out, err) = btfsm(&["log", "report", FIG01, "--format", "json"]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&out).expect("json");
    assert_eq!(v["layout"], "protocol1");
    // The file: 23 header bytes, the XML, 8 timestamp bytes, 9 per record.
    let bytes = std::fs::read(FIG01).expect("fixture");
    let xml = i32::from_le_bytes(bytes[19..23].try_into().unwrap()) as usize;
    let records = (bytes.len() - 23 - xml - 8) / 9;
    assert_eq!(v["records"], records as u64);
    let sum: u64 = v["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .flat_map(|n| n["statuses"].as_object().unwrap().values())
        .map(|x| x.as_u64().unwrap())
        .sum();
    assert_eq!(
        sum, records as u64,
        "every record is one status change of one node"
    );
    assert_eq!(v["node_coverage"]["total"], 14);
}

#[test]
fn log_report_gates_on_coverage() {
    let (code, out, _) = btfsm(&["log", "report", FIG01, "--min-coverage", "0.9"]);
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("node coverage 14/14 (100.0 %)"), "{out}");
    let (code, _, err) = btfsm(&[
        "log",
        "report",
        "tests/fixtures/logs/subtree.btlog",
        "--min-coverage",
        "1",
    ]);
    let (_, out, _) = btfsm(&[
        "log",
        "report",
        "tests/fixtures/logs/subtree.btlog",
        "--format",
        "json",
    ]);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let full = v["node_coverage"]["ratio"] == 1.0 && v["branch_coverage"]["ratio"] == 1.0;
    assert_eq!(code, if full { 0 } else { 1 }, "{err}");
    let (code, _, err) = btfsm(&["log", "report", FIG01, "--min-coverage", "2"]);
    assert_eq!(code, 2);
    assert!(err.contains("ratio from 0 to 1"), "{err}");
}

#[test]
fn a_cut_or_foreign_log_is_refused_with_the_byte_offset() {
    let d = scratch("btlog-cut");
    let bytes = std::fs::read(FIG01).expect("fixture");
    let cut = d.join("cut.btlog");
    std::fs::write(&cut, &bytes[..bytes.len() - 4]).expect("write");
    let (code, _, err) = btfsm(&["log", "report", cut.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(
        err.contains(&format!(
            "byte {}: the log ends inside a record",
            bytes.len() - 9
        )),
        "{err}"
    );
    let foreign = d.join("policy.btlog");
    std::fs::write(
        &foreign,
        std::fs::read("policies/paper/fig01-bt.toml").unwrap(),
    )
    .expect("write");
    let (code, _, err) = btfsm(&["log", "report", foreign.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn a_long_log_is_streamed_in_bounded_memory() {
    // 2,000,000 records (18 MB) after fig01.btlog's header, read under a
    // 64 MiB address-space cap: memory holds the tree and its counters.
    let d = scratch("btlog-long");
    let bytes = std::fs::read(FIG01).expect("fixture");
    let xml = i32::from_le_bytes(bytes[19..23].try_into().unwrap()) as usize;
    let mut out = bytes[..23 + xml + 8].to_vec();
    out.reserve(9 * 2_000_000);
    for i in 0..2_000_000u64 {
        out.extend(&i.to_le_bytes()[..6]);
        out.extend(((i % 14) as u16 + 1).to_le_bytes());
        out.push((i % 4) as u8);
    }
    let long = d.join("long.btlog");
    std::fs::write(&long, &out).expect("write");
    drop(out);
    let (code, stdout, err, _) = common::btfsm_capped(
        64,
        &["log", "report", long.to_str().unwrap(), "--format", "json"],
    );
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&stdout).unwrap();
    assert_eq!(v["records"], 2_000_000);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn log_dot_colours_each_node_by_its_status_at_the_step() {
    // The statuses after K records, replayed here from the raw bytes, are
    // the fills of the drawing: as many RUNNING (gold), SUCCESS and FAILURE
    // nodes as the replay says.
    let bytes = std::fs::read(FIG01).expect("fixture");
    let xml = i32::from_le_bytes(bytes[19..23].try_into().unwrap()) as usize;
    let mut status = std::collections::BTreeMap::new();
    let k = 20;
    for r in bytes[23 + xml + 8..].chunks(9).take(k) {
        status.insert(u16::from_le_bytes([r[6], r[7]]), r[8]);
    }
    let count = |s: u8| status.values().filter(|&&x| x == s).count();
    let (code, dot, err) = btfsm(&["log", "dot", FIG01, "--step", &k.to_string()]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(
        dot.matches("fillcolor=gold").count(),
        count(1),
        "RUNNING\n{dot}"
    );
    assert_eq!(
        dot.matches("fillcolor=palegreen").count(),
        count(2),
        "SUCCESS\n{dot}"
    );
    assert_eq!(
        dot.matches("fillcolor=tomato").count(),
        count(3),
        "FAILURE\n{dot}"
    );
    assert!(dot.contains(&format!("({k} status changes)")), "{dot}");
    assert!(
        !dot.contains("_uid"),
        "the log's bookkeeping is not drawn as ports"
    );
}

#[test]
fn log_report_csv_has_a_row_per_node_with_every_record() {
    let (code, csv, err) = btfsm(&["log", "report", FIG01, "--format", "csv"]);
    assert_eq!(code, 0, "{err}");
    let (_, json, _) = btfsm(&["log", "report", FIG01, "--format", "json"]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let rows: Vec<&str> = csv.lines().skip(1).collect();
    assert_eq!(rows.len(), v["nodes"].as_array().unwrap().len());
    // Columns 5 to 9 are the status changes: together, every record.
    let sum: u64 = rows
        .iter()
        .map(|r| {
            let f: Vec<&str> = r.rsplitn(7, ',').collect();
            f[1..6]
                .iter()
                .map(|x| x.parse::<u64>().unwrap())
                .sum::<u64>()
        })
        .sum();
    assert_eq!(sum, v["records"].as_u64().unwrap());
}

const NOMINAL: &str = "tests/fixtures/logs/compare-nominal.btlog";
const PICK_FAILS: &str = "tests/fixtures/logs/compare-pick-fails.btlog";

/// What the Python leaves saw when BehaviorTree.CPP ran them (the oracle,
/// written beside the logs by tests/differential/btlog_compare.py).
fn oracle(log: &str) -> Vec<String> {
    let v: serde_json::Value = serde_json::from_str(
        &std::fs::read_to_string("tests/fixtures/logs/compare-oracle.json").unwrap(),
    )
    .unwrap();
    let name = std::path::Path::new(log)
        .file_name()
        .unwrap()
        .to_str()
        .unwrap();
    v[name]
        .as_array()
        .unwrap()
        .iter()
        .map(|x| x.as_str().unwrap().replace(" ->", "() ->"))
        .collect()
}

#[test]
fn log_compare_finds_where_the_leaves_of_two_real_runs_diverged() {
    let (a, b) = (oracle(NOMINAL), oracle(PICK_FAILS));
    let want = (0..a.len().max(b.len()))
        .find(|&i| a.get(i) != b.get(i))
        .expect("the runs differ");
    let (code, out, err) = btfsm(&["log", "compare", NOMINAL, PICK_FAILS, "--format", "json"]);
    assert_eq!(code, 1, "diverged, like diff: {err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let d = &v["first_divergence"];
    assert_eq!(d["index"], want as u64);
    assert_eq!(d["a"], a[want].as_str());
    assert_eq!(d["b"], b[want].as_str());
    // The same call (Pick), completed in one run and not in the other.
    assert_eq!(d["kind"], "outcome");
    assert_eq!(v["a"]["actions"], a.len() as u64);
    assert_eq!(v["b"]["actions"], b.len() as u64);
    assert_eq!(v["b"]["node"], "Pick cube2! (uid 10)");
    // The time is when the two Picks part: the failing one's end, after its
    // start record, read here from the bytes.
    let bytes = std::fs::read(PICK_FAILS).unwrap();
    let xml = i32::from_le_bytes(bytes[19..23].try_into().unwrap()) as usize;
    let first_pick = bytes[23 + xml + 8..]
        .chunks(9)
        .find(|r| u16::from_le_bytes([r[6], r[7]]) == 10 && r[8] == 1)
        .map(|r| {
            let mut t = [0u8; 8];
            t[..6].copy_from_slice(&r[..6]);
            u64::from_le_bytes(t)
        })
        .unwrap();
    let t = d["t"].as_f64().unwrap();
    assert!(t > first_pick as f64 / 1e6, "{t} {first_pick}");
    // A run with itself: the same, exit 0; the table says so.
    let (code, out, err) = btfsm(&["log", "compare", PICK_FAILS, PICK_FAILS]);
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains(&format!("same: {} actions in the same order", b.len())),
        "{out}"
    );
    let (code, md, _) = btfsm(&[
        "log", "compare", NOMINAL, PICK_FAILS, "--format", "markdown",
    ]);
    assert_eq!(code, 1);
    assert!(
        md.contains("**Diverged**")
            && md.contains("| b | Pick() -&gt; failure | Pick cube2! (uid 10) |"),
        "{md}"
    );
}

#[test]
fn log_compare_matches_a_simulator_run_with_the_robots_log() {
    // The simulator's Fig. 1 run of exp1-pick-fails (the first Pick fails)
    // against BehaviorTree.CPP's run of the same tree with the same failure.
    let d = scratch("btlog-sim");
    let sim = d.join("sim.json");
    let (code, json, err) = btfsm(&[
        "sim",
        "policies/scenarios/exp1-pick-fails.toml",
        "--format",
        "json",
    ]);
    assert_eq!(code, 0, "{err}");
    std::fs::write(&sim, &json).unwrap();
    let sim = sim.to_str().unwrap();
    let p = "Fig. 1 BT baseline";
    let args = |log: &'static str| {
        vec![
            "log",
            "compare",
            sim,
            log,
            "--policy",
            p,
            "--ignore-args",
            "--format",
            "json",
        ]
    };
    let (code, out, err) = btfsm(&args(PICK_FAILS));
    assert_eq!(code, 0, "{out}{err}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["a"]["kind"], "sim");
    assert_eq!(v["a"]["actions"], oracle(PICK_FAILS).len() as u64);
    // The --trace file (every step too) is read as well.
    let trace = d.join("trace.json");
    let (code, _, err) = btfsm(&[
        "sim",
        "policies/scenarios/exp1-pick-fails.toml",
        "--trace",
        trace.to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{err}");
    let (code, out, err) = btfsm(&[
        "log",
        "compare",
        trace.to_str().unwrap(),
        PICK_FAILS,
        "--policy",
        p,
        "--ignore-args",
    ]);
    assert_eq!(code, 0, "{out}{err}");
    let (code, out, _) = btfsm(&args(NOMINAL));
    assert_eq!(code, 1, "{out}");
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v["first_divergence"]["index"], 1);
    assert_eq!(v["first_divergence"]["a"], "Pick() -> failure");
    // The arguments count unless told not to: the log's leaves have no ports.
    let (code, _, _) = btfsm(&["log", "compare", sim, PICK_FAILS, "--policy", p]);
    assert_eq!(code, 1);
    // Several policies and none named; a name not there: exit 2, listed.
    let (code, _, err) = btfsm(&["log", "compare", sim, PICK_FAILS]);
    assert_eq!(code, 2);
    assert!(
        err.contains("name one with --policy") && err.contains("`Fig. 2 FSM sequential`"),
        "{err}"
    );
    let (code, _, err) = btfsm(&["log", "compare", sim, PICK_FAILS, "--policy", "nope"]);
    assert_eq!(code, 2);
    assert!(err.contains("no policy `nope`"), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn log_compare_refuses_bad_runs_with_exit_2() {
    let d = scratch("btlog-compare-bad");
    let bytes = std::fs::read(PICK_FAILS).unwrap();
    let cut = d.join("cut.btlog");
    std::fs::write(&cut, &bytes[..bytes.len() - 3]).unwrap();
    let (code, _, err) = btfsm(&["log", "compare", NOMINAL, cut.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains(&format!(
            "byte {}: the log ends inside a record",
            bytes.len() - 9
        )),
        "{err}"
    );
    let json = d.join("bad.json");
    std::fs::write(&json, "{\"policies\": [{\"policy\": 3}]}").unwrap();
    let (code, _, err) = btfsm(&["log", "compare", json.to_str().unwrap(), NOMINAL]);
    assert_eq!(code, 2);
    assert!(
        err.contains("1:") && err.contains("not a btfsm simulator JSON"),
        "{err}"
    );
    let (code, _, err) = btfsm(&["log", "compare", NOMINAL, NOMINAL, "--tolerance", "-1"]);
    assert_eq!(code, 2, "{err}");
    let (code, _, _) = btfsm(&["log", "compare", NOMINAL, "tests/fixtures/logs"]);
    assert_eq!(code, 2);
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn log_timeline_draws_a_row_per_leaf_ticked_and_parses_as_xml() {
    let d = scratch("btlog-timeline");
    let out = d.join("t.svg");
    let (code, _, err) = btfsm(&[
        "log",
        "timeline",
        PICK_FAILS,
        "-o",
        out.to_str().unwrap(),
        "--width",
        "600",
    ]);
    assert_eq!(code, 0, "{err}");
    let svg = std::fs::read_to_string(&out).unwrap();
    let doc = roxmltree::Document::parse(&svg).expect("well-formed SVG");
    // Rows: the leaves that left IDLE, counted here from the raw records
    // (UIDs 2, 5, 8, 9, 10, 12, 13, 14 are Fig. 1's leaves).
    let bytes = std::fs::read(PICK_FAILS).unwrap();
    let xml = i32::from_le_bytes(bytes[19..23].try_into().unwrap()) as usize;
    let recs: Vec<(u16, u8)> = bytes[23 + xml + 8..]
        .chunks(9)
        .map(|r| (u16::from_le_bytes([r[6], r[7]]), r[8]))
        .collect();
    let leaves = [2u16, 5, 8, 9, 10, 12, 13, 14];
    let ticked = leaves
        .iter()
        .filter(|u| recs.iter().any(|&(x, s)| x == **u && s != 0))
        .count();
    let labels: Vec<&str> = doc
        .descendants()
        .filter(|n| n.has_tag_name("text") && n.attribute("x") == Some("8"))
        .filter_map(|n| n.text())
        .skip(2)
        .collect();
    assert_eq!(labels.len(), ticked, "{labels:?}");
    assert!(labels.contains(&"Pick cube2! (Pick)"), "{labels:?}");
    // Pick went RUNNING twice (the failed grasp and the retry): two bars.
    let bars = doc
        .descendants()
        .filter(|n| n.attribute("fill") == Some("gold") && n.attribute("height") == Some("10"))
        .count();
    let runs = recs.iter().filter(|&&(_, s)| s == 1).count();
    let pick_runs = recs.iter().filter(|&&(u, s)| u == 10 && s == 1).count();
    assert_eq!(pick_runs, 2);
    assert!(
        bars <= runs && bars >= 4,
        "{bars} bars, {runs} RUNNING records"
    );
    let fails = doc
        .descendants()
        .filter(|n| n.attribute("fill") == Some("tomato"))
        .count();
    assert!(fails >= 1);
    // Bad input: exit 2.
    let (code, _, err) = btfsm(&["log", "timeline", PICK_FAILS, "--width", "5"]);
    assert_eq!(code, 2, "{err}");
    let (code, _, _) = btfsm(&["log", "timeline", "-"]);
    assert_eq!(code, 2);
    let _ = std::fs::remove_dir_all(&d);
}

#[cfg(feature = "sqlite")]
const DB3: &str = "tests/fixtures/logs/sessions.db3";

#[cfg(feature = "sqlite")]
#[test]
fn log_report_reads_each_session_of_a_db3_as_sql_counts_it() {
    let db = rusqlite::Connection::open_with_flags(DB3, rusqlite::OpenFlags::SQLITE_OPEN_READ_ONLY)
        .unwrap();
    for session in [1i64, 2] {
        let mut want = std::collections::BTreeMap::new();
        let mut st = db
            .prepare("SELECT uid, state, COUNT(*) FROM Transitions WHERE session_id = ?1 GROUP BY uid, state")
            .unwrap();
        let rows = st
            .query_map([session], |r| {
                Ok((
                    r.get::<_, i64>(0)? as u64,
                    r.get::<_, u8>(1)?,
                    r.get::<_, i64>(2)? as u64,
                ))
            })
            .unwrap();
        let names = ["IDLE", "RUNNING", "SUCCESS", "FAILURE", "SKIPPED"];
        for r in rows {
            let (u, s, k) = r.unwrap();
            want.insert((u, names[s as usize].to_string()), k);
        }
        let (code, out, err) = btfsm(&[
            "log",
            "report",
            DB3,
            "--session",
            &session.to_string(),
            "--format",
            "json",
        ]);
        assert_eq!(code, 0, "{err}");
        let v: serde_json::Value = serde_json::from_str(&out).unwrap();
        let mut got = std::collections::BTreeMap::new();
        for n in v["nodes"].as_array().unwrap() {
            for (s, k) in n["statuses"].as_object().unwrap() {
                got.insert((n["uid"].as_u64().unwrap(), s.clone()), k.as_u64().unwrap());
            }
        }
        assert_eq!(got, want, "session {session}");
        assert_eq!(v["session"], session);
        assert_eq!(v["sessions"].as_array().unwrap().len(), 2);
    }
    // The default is the last session; the table lists them all.
    let (code, out, _) = btfsm(&["log", "report", DB3]);
    assert_eq!(code, 0);
    assert!(
        out.contains("session 2 (sessions: 1 (2026-11-20 10:00:00), 2 (2026-11-21 10:00:00))"),
        "{out}"
    );
    // Two sessions of one file compared: where the runs' logs diverge.
    let (code, out, _) = btfsm(&[
        "log",
        "compare",
        DB3,
        DB3,
        "--session-a",
        "1",
        "--session-b",
        "2",
        "--format",
        "json",
    ]);
    assert_eq!(code, 1);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    let (_, logs, _) = btfsm(&["log", "compare", NOMINAL, PICK_FAILS, "--format", "json"]);
    let w: serde_json::Value = serde_json::from_str(&logs).unwrap();
    assert_eq!(
        v["first_divergence"]["index"],
        w["first_divergence"]["index"]
    );
    assert_eq!(v["first_divergence"]["b"], w["first_divergence"]["b"]);
    let (code, svg, err) = btfsm(&["log", "timeline", DB3, "--session", "1"]);
    assert_eq!(code, 0, "{err}");
    roxmltree::Document::parse(&svg).unwrap();
}

#[cfg(feature = "sqlite")]
#[test]
fn a_hostile_db3_is_refused_with_exit_2() {
    let d = scratch("db3-bad");
    // Not SQLite at all (a .db3 by name only), SQLite's magic then garbage.
    let fake = d.join("fake.db3");
    std::fs::write(&fake, b"SQLite format 3\0not a database at all").unwrap();
    let (code, _, err) = btfsm(&["log", "report", fake.to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("not a readable SqliteLogger database"),
        "{err}"
    );
    // A database without the tables.
    let empty = d.join("empty.db3");
    rusqlite::Connection::open(&empty)
        .unwrap()
        .execute_batch("CREATE TABLE Other (x INTEGER);")
        .unwrap();
    let (code, _, err) = btfsm(&["log", "report", empty.to_str().unwrap()]);
    assert_eq!(code, 2);
    assert!(err.contains("no table `Definitions`"), "{err}");
    // A row larger than --max-file-bytes (SQLite's length limit).
    let big = d.join("big.db3");
    std::fs::copy(DB3, &big).unwrap();
    rusqlite::Connection::open(&big)
        .unwrap()
        .execute(
            "UPDATE Definitions SET xml_tree = ?1 WHERE session_id = 2",
            ["x".repeat(300_000)],
        )
        .unwrap();
    let (code, _, err) = btfsm(&[
        "log",
        "report",
        big.to_str().unwrap(),
        "--max-file-bytes",
        "100000",
    ]);
    assert_eq!(code, 2);
    assert!(
        err.contains("too big") || err.contains("more than the limit"),
        "{err}"
    );
    // A session that is not there; --session on a .btlog.
    let (code, _, err) = btfsm(&["log", "report", DB3, "--session", "9"]);
    assert_eq!(code, 2);
    assert!(
        err.contains("no session 9 (the sessions are 1, 2)"),
        "{err}"
    );
    let (code, _, err) = btfsm(&["log", "report", FIG01, "--session", "1"]);
    assert_eq!(code, 2);
    assert!(err.contains("--session is for a .db3"), "{err}");
    let _ = std::fs::remove_dir_all(&d);
}

#[test]
fn log_report_markdown_has_the_coverage_and_a_row_per_node() {
    let sub = "tests/fixtures/logs/subtree.btlog";
    let (code, md, err) = btfsm(&["log", "report", sub, "--format", "markdown"]);
    assert_eq!(code, 0, "{err}");
    let (_, json, _) = btfsm(&["log", "report", sub, "--format", "json"]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let c = &v["node_coverage"];
    assert!(
        md.contains(&format!(
            "| nodes | {}/{} (",
            c["covered"].as_u64().unwrap(),
            c["total"].as_u64().unwrap()
        )),
        "{md}"
    );
    let nodes = v["nodes"].as_array().unwrap();
    let rows: Vec<&str> = md
        .lines()
        .skip_while(|l| !l.starts_with("| uid |"))
        .skip(2)
        .collect();
    assert_eq!(rows.len(), nodes.len(), "{md}");
    for (row, n) in rows.iter().zip(nodes) {
        assert!(row.starts_with(&format!("| {} | ", n["uid"])), "{row} {n}");
        assert!(
            row.contains(&format!(" | {} | ", n["activations"])),
            "{row} {n}"
        );
    }
    for u in v["uncovered"].as_array().unwrap() {
        let u = u.as_str().unwrap().replace('>', "&gt;");
        assert!(md.contains(&format!("- {u}")), "{u}\n{md}");
    }
}

/// A `.btlog` (protocol 1) of `xml` and `records` (µs, uid, status).
fn btlog(xml: &str, records: &[(u64, u16, u8)]) -> Vec<u8> {
    let mut b = b"BTCPP4-FileLogger2".to_vec();
    b.push(1);
    b.extend((xml.len() as i32).to_le_bytes());
    b.extend(xml.as_bytes());
    b.extend(1_700_000_000_000_000i64.to_le_bytes());
    for &(t, u, st) in records {
        b.extend(&t.to_le_bytes()[..6]);
        b.extend(u.to_le_bytes());
        b.push(st);
    }
    b
}

/// Every command reading a `.btlog`, on `log`.
fn log_commands(log: &str) -> Vec<Vec<String>> {
    let v = |a: &[&str]| a.iter().map(|s| s.to_string()).collect::<Vec<_>>();
    vec![
        v(&["log", "report", log]),
        v(&["log", "dot", log, "--step", "100"]),
        v(&["log", "timeline", log]),
        v(&["log", "compare", log, FIG01]),
        v(&["view", log, "-o", "/dev/null"]),
    ]
}

/// SubTree links that loop, or form a 40-level DAG (each tree naming the
/// next twice: 2^40 nodes walked), and time going backwards: every log
/// command and `view` refuse them at once, naming the trees (issue 33:
/// a 442-byte log hung them until memory ran out).
#[test]
fn hostile_subtree_links_and_backwards_time_are_refused_at_once() {
    let d = scratch("btlog-links");
    let tree = |levels: usize, twice: bool, back: bool| {
        let path = |l: usize| {
            if l == 0 {
                String::new()
            } else {
                format!("t{l}")
            }
        };
        let mut x = String::from(r#"<root BTCPP_format="4">"#);
        let mut uid = 0;
        for l in 0..levels {
            uid += 1;
            x.push_str(&format!(
                r#"<BehaviorTree ID="T{l}" _fullpath="{}"><Sequence _uid="{uid}">"#,
                path(l)
            ));
            for _ in 0..if twice { 2 } else { 1 } {
                uid += 1;
                let last = l + 1 == levels;
                let next = if last && back {
                    String::new()
                } else {
                    path(l + 1)
                };
                if last && !back {
                    x.push_str(&format!(r#"<AlwaysSuccess _uid="{uid}"/>"#));
                } else {
                    x.push_str(&format!(
                        r#"<SubTree ID="T{}" _uid="{uid}" _fullpath="{next}"/>"#,
                        l + 1
                    ));
                }
            }
            x.push_str("</Sequence></BehaviorTree>");
        }
        x + "</root>"
    };
    let cases = [
        (
            "cycle.btlog",
            btlog(&tree(2, false, true), &[(0, 1, 1)]),
            "cycle",
        ),
        (
            "dag.btlog",
            btlog(&tree(40, true, false), &[(0, 1, 1)]),
            "two nodes",
        ),
        (
            "back.btlog",
            btlog(&tree(1, false, false), &[(5, 1, 1), (9, 2, 2), (7, 1, 2)]),
            "time goes backwards",
        ),
    ];
    for (name, bytes, says) in cases {
        let p = d.join(name);
        std::fs::write(&p, &bytes).unwrap();
        if name == "cycle.btlog" {
            assert!(bytes.len() < 500, "{} bytes", bytes.len());
        }
        for args in log_commands(p.to_str().unwrap()) {
            let args: Vec<&str> = args.iter().map(String::as_str).collect();
            let (code, _, err, t) = common::btfsm_capped(2048, &args);
            assert_eq!(code, 2, "{args:?}: {err}");
            assert!(err.contains(says), "{args:?}: {err}");
            assert!(t.as_secs() < 20, "{args:?}: {t:?}");
        }
    }
    let _ = std::fs::remove_dir_all(&d);
}

/// A FIFO is read as `view` reads it: one with no writer is an empty log
/// at once (no hang), one with a writer is read whole.
#[test]
fn log_commands_read_a_fifo_without_blocking() {
    let d = scratch("btlog-fifo");
    let fifo = d.join("run.btlog");
    let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
    // SAFETY: a NUL-terminated path.
    assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
    for args in log_commands(fifo.to_str().unwrap()) {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let t0 = std::time::Instant::now();
        let (code, _, err) = btfsm(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(
            err.contains("header") || err.contains("empty"),
            "{args:?}: {err}"
        );
        assert!(t0.elapsed().as_secs() < 10, "{args:?} blocked");
    }
    // With a writer: the log is read whole.
    let bytes = std::fs::read(FIG01).unwrap();
    let writer = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::write(fifo, bytes))
    };
    let (code, out, err) = btfsm(&["log", "report", fifo.to_str().unwrap(), "--format", "json"]);
    let _ = writer.join();
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("\"records\""), "{out}");
    let _ = std::fs::remove_dir_all(&d);
}
