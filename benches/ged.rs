//! GED benchmark (issue 3): times btfsm's exact structural graph edit
//! distance on (a) the paper's policy pairs of SPEC §5 (Tables II and III,
//! the effort pairs, and the HFSMs converted from the BT pairs) and (b) 50
//! seeded random loop-free directed graphs of 8–12 vertices, and writes every
//! pair with btfsm's value and time to a JSON file so that
//! `bench/ged_vs_networkx.py` can time NetworkX (the paper's tool) on exactly
//! the same graphs in the same run and print the ratios.
//!
//! `cargo bench --bench ged [-- OUT.json]` (default `target/ged-pairs.json`).
//! Times are in-process medians over repeated runs (no process start-up),
//! as NetworkX's are.

#![allow(
    clippy::print_stdout,
    clippy::print_stderr,
    reason = "benchmarks and tests report what they measured"
)]

use btfsm_format::{Limits, load};
use btfsm_metrics::ged::{GedGraph, GedMode, GedOptions, ged_graphs};
use btfsm_model::Policy;
use btfsm_model::graph::{PolicyGraph, policy_graph};
use btfsm_transform::bt_to_hfsm::bt_policy_to_hfsm;
use std::path::Path;
use std::time::{Duration, Instant};

/// A named pair of graphs.
struct Pair {
    name: String,
    group: &'static str,
    a: GedGraph,
    b: GedGraph,
}

fn policy(name: &str) -> Policy {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("policies/paper")
        .join(format!("{name}.toml"));
    match load(&path, &Limits::default()) {
        Ok(l) => l.policy,
        Err(_) => panic!("cannot load {}", path.display()),
    }
}

fn graph(p: &Policy) -> GedGraph {
    let g: PolicyGraph = policy_graph(p);
    GedGraph::from(&g)
}

fn paper_pairs() -> Vec<Pair> {
    let plain = [
        ("fig04-fsm", "fig08a-fsm"),
        ("fig04-fsm", "fig08b-fsm"),
        ("fig04-fsm", "fig08c-fsm"),
        ("fig04-fsm", "fig08d-fsm"),
        ("fig08d-fsm", "fig15-fsm"),
        ("scal-fsm", "fig16b-fsm"),
        ("fig02-fsm", "fig04-fsm"),
        ("fig10-fsm", "fig08d-fsm"),
        ("fig01-bt", "fig07a-bt"),
        ("fig01-bt", "fig07b-bt"),
        ("fig01-bt", "fig07c-bt"),
        ("fig01-bt", "fig07d-bt"),
        ("fig07d-bt", "fig15-bt"),
        ("scal-bt", "fig16a-bt"),
    ];
    let mut v: Vec<Pair> = plain
        .iter()
        .map(|&(a, b)| Pair {
            name: format!("{a} -> {b}"),
            group: "paper",
            a: graph(&policy(a)),
            b: graph(&policy(b)),
        })
        .collect();
    let hfsm = |n: &str| graph(&bt_policy_to_hfsm(&policy(n)).expect("convertible BT"));
    // The HFSMs of the BT pairs (the paper's sec. III construction).
    for &(a, b) in plain.iter().filter(|(a, _)| a.ends_with("-bt")) {
        v.push(Pair {
            name: format!("hfsm({a}) -> hfsm({b})"),
            group: "paper",
            a: hfsm(a),
            b: hfsm(b),
        });
    }
    v
}

/// xorshift64*, seeded: the same pairs on every run.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
}

/// A random simple directed graph without self-loops: `n` vertices and `n`
/// arcs (as sparse as policy graphs; denser ones leave NetworkX unfinished
/// within a minute from 9 vertices on).
fn random_graph(rng: &mut Rng, n: usize, tag: &str) -> GedGraph {
    let m = n;
    let mut arcs = std::collections::BTreeSet::new();
    while arcs.len() < m {
        let (u, v) = (rng.below(n as u64) as usize, rng.below(n as u64) as usize);
        if u != v {
            arcs.insert((u, v));
        }
    }
    let keys = (0..n).map(|i| format!("{tag}{i}")).collect();
    GedGraph::new(vec![0; n], keys, arcs).expect("valid graph")
}

fn random_pairs() -> Vec<Pair> {
    let mut rng = Rng(0x5EED_6ED0);
    (0..50)
        .map(|i| {
            let n1 = 8 + rng.below(5) as usize;
            let n2 = 8 + rng.below(5) as usize;
            Pair {
                name: format!("random {i:02} ({n1} vs {n2})"),
                group: "random",
                a: random_graph(&mut rng, n1, "a"),
                b: random_graph(&mut rng, n2, "b"),
            }
        })
        .collect()
}

/// Median wall time of repeated runs (at least 5, for at least 50 ms; one
/// run when `quick`).
fn time(pair: &Pair, opts: &GedOptions, quick: bool) -> (u64, bool, Duration) {
    let mut times = Vec::new();
    let started = Instant::now();
    let mut last = None;
    let enough = |n: usize| {
        n >= 1 && quick || n >= 5 && (started.elapsed() >= Duration::from_millis(50) || n >= 1000)
    };
    while !enough(times.len()) {
        let t = Instant::now();
        let r = ged_graphs(&pair.a, &pair.b, GedMode::Structural, opts);
        times.push(t.elapsed());
        last = Some(r);
    }
    times.sort();
    let r = last.expect("ran");
    (r.ged, r.exact, times[times.len() / 2])
}

fn arcs_json(g: &GedGraph) -> serde_json::Value {
    let mut arcs = Vec::new();
    for &(t, h, m) in g.arcs() {
        for _ in 0..m {
            arcs.push(serde_json::json!([t, h]));
        }
    }
    serde_json::json!({ "n": g.n(), "arcs": arcs })
}

fn main() {
    // `cargo test --benches -- --test` (make test): one run per pair, the
    // paper pairs only, nothing written — a smoke test of this file.
    let quick = std::env::args().any(|a| a == "--test");
    let out = std::env::args()
        .skip(1)
        .find(|a| !a.starts_with('-'))
        .unwrap_or_else(|| {
            Path::new(env!("CARGO_MANIFEST_DIR"))
                .join("target/ged-pairs.json")
                .display()
                .to_string()
        });
    let opts = GedOptions {
        timeout: Duration::from_secs(10),
        ..GedOptions::default()
    };
    let mut rows = Vec::new();
    println!(
        "{:44} {:>9} {:>9} {:>5} {:>6} {:>12}",
        "pair", "V", "E", "GED", "exact", "btfsm"
    );
    let random = if quick { Vec::new() } else { random_pairs() };
    for p in paper_pairs().into_iter().chain(random) {
        let (ged, exact, t) = time(&p, &opts, quick);
        assert!(exact, "{}: not exact within 10 s", p.name);
        println!(
            "{:44} {:>4}/{:<4} {:>4}/{:<4} {:>5} {:>6} {:>9.3} ms",
            p.name,
            p.a.n(),
            p.a.arc_count(),
            p.b.n(),
            p.b.arc_count(),
            ged,
            exact,
            t.as_secs_f64() * 1e3
        );
        rows.push(serde_json::json!({
            "name": p.name,
            "group": p.group,
            "a": arcs_json(&p.a),
            "b": arcs_json(&p.b),
            "self_loops": p.a.arcs().iter().chain(p.b.arcs()).any(|&(t, h, _)| t == h),
            "btfsm": { "ged": ged, "exact": exact, "seconds": t.as_secs_f64() },
        }));
    }
    if quick {
        return;
    }
    let text = serde_json::to_string(&serde_json::json!({ "pairs": rows })).expect("json");
    if let Err(e) = std::fs::write(&out, text) {
        eprintln!("error: cannot write `{out}`: {e}");
        std::process::exit(2);
    }
    println!("wrote {out}");
}
