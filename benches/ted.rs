//! Tree edit distance benchmark (issue 15): times `compare --mode tree`'s
//! computation (`report::compare::tree::tree_report`: labels, distance,
//! mapping and edit script) on seeded random Behavior Trees of 10,000 nodes —
//! a tree against an edited copy (20 and 200 edits: renames, sibling swaps,
//! deletions, insertions, leaves moved, as a pull request makes them) and
//! against an unrelated tree of the same size — and prints each pair's
//! distance, exactness, cells computed and median time.
//!
//! `cargo bench --bench ted`; `-- --test` (make test) runs 300-node trees
//! once, under a small work budget, as a smoke test. `bench/ted_vs_apted.py` times the `apted` package
//! against btfsm on the same pairs in one run (docs/performance.md).

#![allow(
    clippy::print_stdout,
    clippy::print_stderr,
    reason = "benchmarks and tests report what they measured"
)]

use btfsm_metrics::ted::TedOptions;
use btfsm_model::{Bt, BtNode, BtNodeKind, SkillCall};
use btfsm_report::compare::tree::tree_report;
use std::collections::BTreeMap;
use std::time::{Duration, Instant};

/// SplitMix64.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n as u64) as usize
    }
}

fn node(id: String, kind: BtNodeKind, label: String, skill: Option<SkillCall>) -> BtNode {
    BtNode {
        id,
        label,
        kind,
        children: Vec::new(),
        skill,
        type_name: None,
        ports: BTreeMap::new(),
        subtree: None,
        id_source: btfsm_model::IdSource::Given,
        span: None,
    }
}

fn leaf(rng: &mut Rng, id: String) -> BtNode {
    const SKILLS: [&str; 6] = [
        "Move-To",
        "Pick",
        "Place",
        "Robot-At",
        "In-Hand",
        "Object-At",
    ];
    let s = SKILLS[rng.below(SKILLS.len())];
    let target = format!("p{}", rng.below(40));
    let kind = if s.contains('-') && s != "Move-To" {
        BtNodeKind::Condition
    } else {
        BtNodeKind::Action
    };
    let mut args = BTreeMap::new();
    args.insert(
        "target".to_string(),
        btfsm_model::ArgValue::Str(target.clone()),
    );
    node(
        id,
        kind,
        format!("{s} {target}"),
        Some(SkillCall {
            skill: s.to_string(),
            args,
        }),
    )
}

/// A BT of `n` nodes: a Fallback root, composites of 2–6 children
/// (Sequence, Fallback, Sequence*), skill-bound leaves.
fn random_bt(rng: &mut Rng, n: usize) -> Bt {
    let mut nodes = vec![node(
        "root".into(),
        BtNodeKind::Fallback,
        "Fallback".into(),
        None,
    )];
    let mut open = vec![0usize];
    while nodes.len() < n {
        let i = nodes.len();
        let p = open[rng.below(open.len())];
        let composite = rng.below(10) < 3;
        let new = if composite {
            let (k, l) = match rng.below(3) {
                0 => (BtNodeKind::Sequence, "Sequence"),
                1 => (BtNodeKind::Fallback, "Fallback"),
                _ => (BtNodeKind::SequenceMemory, "Sequence*"),
            };
            node(format!("n{i}"), k, l.into(), None)
        } else {
            leaf(rng, format!("n{i}"))
        };
        nodes.push(new);
        nodes[p].children.push(i);
        if nodes[p].children.len() >= 2 + rng.below(5) {
            open.retain(|&q| q != p);
        }
        if composite {
            open.push(i);
        }
        if open.is_empty() {
            open.push(i);
        }
    }
    Bt { nodes, root: 0 }
}

/// `edits` random edits of a copy of `bt`.
fn edited(rng: &mut Rng, bt: &Bt, edits: usize) -> Bt {
    let mut b = bt.clone();
    let composites: Vec<usize> = (0..b.nodes.len())
        .filter(|&i| !b.nodes[i].children.is_empty())
        .collect();
    for e in 0..edits {
        let c = composites[rng.below(composites.len())];
        let k = b.nodes[c].children.len();
        if k == 0 {
            continue;
        }
        match e % 5 {
            0 => {
                let v = b.nodes[c].children[rng.below(k)];
                b.nodes[v].label.push('!');
            }
            1 if k >= 2 => b.nodes[c].children.swap(0, k - 1),
            2 if k >= 2 => {
                let v = b.nodes[c].children.remove(rng.below(k));
                let grand = std::mem::take(&mut b.nodes[v].children);
                let at = rng.below(b.nodes[c].children.len() + 1);
                b.nodes[c].children.splice(at..at, grand);
            }
            3 => {
                let i = b.nodes.len();
                let l = leaf(rng, format!("new{i}"));
                b.nodes.push(l);
                let at = rng.below(k + 1);
                b.nodes[c].children.insert(at, i);
            }
            _ => {
                // Move a leaf child elsewhere: to the front of another
                // composite.
                let v = b.nodes[c].children[rng.below(k)];
                let to = composites[rng.below(composites.len())];
                if b.nodes[v].children.is_empty() && to != c {
                    b.nodes[c].children.retain(|&w| w != v);
                    b.nodes[to].children.insert(0, v);
                }
            }
        }
    }
    b
}

fn main() {
    let quick = std::env::args().any(|a| a == "--test");
    let n = if quick { 300 } else { 10_000 };
    let runs = if quick { 1 } else { 5 };
    let mut rng = Rng(15);
    let a = random_bt(&mut rng, n);
    let pairs = [
        ("edited copy, 1 edit", edited(&mut rng, &a, 1)),
        ("edited copy, 5 edits", edited(&mut rng, &a, 5)),
        ("edited copy, 20 edits", edited(&mut rng, &a, 20)),
        ("edited copy, 200 edits", edited(&mut rng, &a, 200)),
        ("unrelated tree", random_bt(&mut rng, n)),
    ];
    println!(
        "{:28} {:>6} {:>6} {:>14} {:>6} {:>14} {:>11}",
        "pair", "nodes", "nodes", "TED", "exact", "cells", "median"
    );
    let opts = if quick {
        TedOptions {
            max_work: 5_000_000,
            ..TedOptions::default()
        }
    } else {
        TedOptions::default()
    };
    for (name, b) in &pairs {
        let mut times: Vec<Duration> = Vec::new();
        let mut last = None;
        for _ in 0..runs {
            let t = Instant::now();
            let r = tree_report(&a, b, &opts);
            times.push(t.elapsed());
            last = Some(r);
        }
        times.sort();
        let r = last.expect("one run");
        assert_eq!(r.edit_script.cost(), r.ted);
        println!(
            "{:28} {:>6} {:>6} {:>14} {:>6} {:>14} {:>8.1} ms",
            name,
            a.nodes.len(),
            b.preorder().len(),
            if r.exact {
                r.ted.to_string()
            } else {
                format!("[{}, {}]", r.lower_bound, r.upper_bound)
            },
            r.exact,
            r.work,
            times[times.len() / 2].as_secs_f64() * 1e3
        );
    }
}
