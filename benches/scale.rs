//! Scale benchmark (issue: large inputs): a BT with 100,000 nodes, a BT nested
//! 100,000 levels deep, a chain of 100,000 Sequences each guarding a Move-To
//! (every level a chattering-order finding for `lint`) and a fault-tolerant
//! FSM with 10,000 states are parsed, validated, analyzed and linted, and a
//! BehaviorTree.CPP tree of 100,000 nodes with a `<TreeNodesModel>` (every
//! node reading or writing blackboard entries, a dataflow finding at most
//! levels) is read and linted with its dataflow; prints the time of each
//! phase. Target: under 1 s per input, end to end, and
//! under 1 s for `lint` (issue 17). Run with `cargo bench --bench scale`.

#![allow(
    clippy::print_stdout,
    clippy::print_stderr,
    reason = "benchmarks and tests report what they measured"
)]

use btfsm_format::{Limits, Loaded, toml::parse_str};
use btfsm_metrics::complexity::{cyclomatic, essential};
use btfsm_model::graph::policy_graph;
use btfsm_report::analyze;
use std::fmt::Write;
use std::path::Path;
use std::time::Instant;

/// Root sequence over fallbacks of (condition, action): 1 + 3k nodes.
pub fn wide_bt(nodes: usize) -> String {
    let k = (nodes - 1) / 3;
    let mut s = String::from("kind = \"bt\"\nname = \"wide\"\n[nodes]\nroot = { sequence = [");
    for i in 0..k {
        let _ = write!(s, "{}\"f{i}\"", if i > 0 { ", " } else { "" });
    }
    s.push_str("] }\n");
    for i in 0..k {
        let _ = writeln!(s, "f{i} = {{ fallback = [\"c{i}\", \"a{i}\"] }}");
        let _ = writeln!(
            s,
            "c{i} = {{ condition = \"At p{i}?\", skill = \"Robot-At\", args = {{ target = \"p{i}\" }} }}"
        );
        let _ = writeln!(
            s,
            "a{i} = {{ action = \"Move-To p{i}!\", skill = \"Move-To\", args = {{ target = \"p{i}\" }} }}"
        );
    }
    s
}

/// A chain of alternating sequences and fallbacks `depth` levels deep.
pub fn deep_bt(depth: usize) -> String {
    let mut s = String::from("kind = \"bt\"\nname = \"deep\"\n[nodes]\n");
    for i in 0..depth - 1 {
        let kind = if i % 2 == 0 { "sequence" } else { "fallback" };
        let _ = writeln!(s, "n{i} = {{ {kind} = [\"n{}\"] }}", i + 1);
    }
    let _ = writeln!(
        s,
        "n{} = {{ action = \"Dock!\", skill = \"Dock\" }}",
        depth - 1
    );
    s
}

/// Sequences nested `depth` levels: level i is `Sequence(Fallback(at p_i,
/// Move-To p_i), level i+1)`, so every Move-To below undoes the Robot-At an
/// earlier sibling ensured: `depth` lint findings, each found in O(1).
pub fn chain_bt(depth: usize) -> String {
    let mut s = String::from("kind = \"bt\"\nname = \"chain\"\nroot = \"s0\"\n[nodes]\n");
    let k = depth / 4;
    for i in 0..k {
        let next = if i + 1 < k {
            format!("s{}", i + 1)
        } else {
            "done".into()
        };
        let _ = writeln!(s, "s{i} = {{ sequence = [\"f{i}\", \"{next}\"] }}");
        let _ = writeln!(s, "f{i} = {{ fallback = [\"c{i}\", \"a{i}\"] }}");
        let _ = writeln!(
            s,
            "c{i} = {{ condition = \"At p{i}?\", skill = \"Robot-At\", args = {{ target = \"p{i}\" }} }}"
        );
        let _ = writeln!(
            s,
            "a{i} = {{ action = \"Move-To p{i}!\", skill = \"Move-To\", args = {{ target = \"p{i}\" }} }}"
        );
    }
    s.push_str("done = { action = \"Dock!\", skill = \"Dock\" }\n");
    s
}

/// A fault-tolerant FSM (SELECTOR design of the paper's Fig. 4) with `n` states.
pub fn big_fsm(n: usize) -> String {
    let mut s = String::from(
        "kind = \"fsm\"\nname = \"big\"\ninitial = \"s0\"\noutcomes = [\"SUCCESS\"]\n",
    );
    for i in 0..n {
        let next = if i + 1 < n {
            format!("s{}", i + 1)
        } else {
            "SUCCESS".into()
        };
        let _ = writeln!(
            s,
            "[states.s{i}]\nskill = \"Dock\"\non = {{ SUCCESS = \"{next}\", FAILURE = \"SELECTOR\", RUNNING = \"s{i}\" }}"
        );
    }
    s.push_str("[states.SELECTOR]\ndecision = true\non = { RUNNING = \"SELECTOR\" }\nguards = [\n");
    for i in 0..n {
        let _ = writeln!(s, "  {{ if = \"Found\", to = \"s{i}\" }},");
    }
    s.push_str("]\n");
    s
}

fn run(name: &str, text: &str) {
    let t = Instant::now();
    let doc = toml::de::DeTable::parse(text).expect("valid TOML");
    let t_toml = t.elapsed();
    drop(doc);
    println!(
        "{name:<22} TOML syntax alone {:>7.1} ms",
        t_toml.as_secs_f64() * 1e3
    );
    let t0 = Instant::now();
    // These inputs are large on purpose: raise the depth limit (default
    // 1000, `--max-depth`) past the 100,000-level tree.
    let limits = Limits {
        max_depth: 1_000_000,
        ..Limits::default()
    };
    let loaded: Loaded = parse_str(name, text, Path::new("."), &limits)
        .unwrap_or_else(|e| panic!("{name}: {}", e[0]));
    let t_parse = t0.elapsed();
    let t1 = Instant::now();
    let g = policy_graph(&loaded.policy);
    let t_graph = t1.elapsed();
    let t2 = Instant::now();
    let cc = cyclomatic(&g);
    let ess = essential(&loaded.policy);
    let t_cc = t2.elapsed();
    let t3 = Instant::now();
    let report = analyze(&loaded);
    let t_all = t3.elapsed();
    let t4 = Instant::now();
    let findings = btfsm_lint::lint(&loaded.policy, None, name, &Default::default());
    let t_lint = t4.elapsed();
    let total = t_parse + t_all;
    println!(
        "{name:<22} {:>7} vertices {:>7} arcs  parse {:>7.1} ms  graph {:>6.1} ms  cc+essential {:>6.1} ms  analyze {:>7.1} ms  total {:>7.1} ms  {}",
        report.vertices,
        report.edges,
        t_parse.as_secs_f64() * 1e3,
        t_graph.as_secs_f64() * 1e3,
        t_cc.as_secs_f64() * 1e3,
        t_all.as_secs_f64() * 1e3,
        total.as_secs_f64() * 1e3,
        if total.as_secs_f64() < 1.0 {
            "ok (< 1 s)"
        } else {
            "SLOW (target < 1 s)"
        }
    );
    assert!(cc >= 1 && ess >= 1);
    println!(
        "{name:<22} lint {:>7.1} ms ({} findings)  {}",
        t_lint.as_secs_f64() * 1e3,
        findings.len(),
        if t_lint.as_secs_f64() < 1.0 {
            "ok (< 1 s)"
        } else {
            "SLOW (target < 1 s)"
        }
    );
}

/// A BehaviorTree.CPP tree: a root Sequence of Fallbacks, each (Pick
/// reading `{k<i>}`, Detect writing `{k<i+1>}`, a Script writing `s<i>`),
/// 1 + 4k nodes; every Pick reads an entry written only later.
pub fn btcpp_dataflow(nodes: usize) -> String {
    let k = (nodes - 1) / 4;
    let mut s = String::from(
        r#"<root BTCPP_format="4" main_tree_to_execute="Main"><BehaviorTree ID="Main"><Sequence>"#,
    );
    for i in 0..k {
        let _ = write!(
            s,
            r#"<Fallback><Pick pose="{{k{i}}}" speed="1"/><Detect pose="{{k{}}}"/><Script code="s{i} := {i}"/></Fallback>"#,
            i + 1
        );
    }
    s.push_str(
        r#"</Sequence></BehaviorTree><TreeNodesModel><Action ID="Detect"><output_port name="pose" type="Pose"/></Action><Condition ID="Pick"><input_port name="pose" type="Point"/></Condition></TreeNodesModel></root>"#,
    );
    s
}

fn run_btcpp(name: &str, text: &str) {
    let t0 = Instant::now();
    let loaded = btfsm_format::btcpp_xml::parse_str(name, text, Path::new("."), &Limits::default())
        .unwrap_or_else(|e| panic!("{name}: {}", e[0]));
    let t_parse = t0.elapsed();
    let t1 = Instant::now();
    let subject = btfsm_lint::Subject {
        policy: &loaded.policy,
        dataflow: loaded.dataflow.as_deref(),
    };
    let findings = btfsm_lint::lint_subject(&subject, None, name, &Default::default());
    let t_lint = t1.elapsed();
    println!(
        "{name:<22} parse {:>7.1} ms  lint {:>7.1} ms ({} findings)  {}",
        t_parse.as_secs_f64() * 1e3,
        t_lint.as_secs_f64() * 1e3,
        findings.len(),
        if t_lint.as_secs_f64() < 1.0 {
            "ok (< 1 s)"
        } else {
            "SLOW (target < 1 s)"
        }
    );
    assert!(!findings.is_empty());
}

fn main() {
    // `cargo test --benches` runs this too: keep it quick there.
    let quick = std::env::args().any(|a| a == "--test");
    let (n, d, m) = if quick {
        (1_000, 1_000, 100)
    } else {
        (100_000, 100_000, 10_000)
    };
    run("bt 100k nodes", &wide_bt(n));
    run("bt 100k levels deep", &deep_bt(d));
    run("bt 100k chain of seqs", &chain_bt(d));
    run("fsm 10k states", &big_fsm(m));
    run_btcpp("bt.cpp 100k dataflow", &btcpp_dataflow(n));
}
