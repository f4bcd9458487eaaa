//! Tests of the tree edit distance against an independent definition (the
//! forest recursion of Tai / Zhang–Shasha's Lemma 3, memoised, on small
//! trees), the laws of a metric, and the validity and cost of the mapping.
//! The `apted` and `zss` PyPI packages check it on thousands of trees in
//! `tests/differential/ted.py`.

use super::*;
use std::collections::{BTreeMap, HashMap};

/// SplitMix64 (seeded, deterministic).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    fn below(&mut self, n: u64) -> usize {
        (self.next() % n) as usize
    }
}

/// A random tree of `n` nodes (each node's parent drawn among the earlier
/// ones, so shapes vary from paths to stars) with labels `0..alphabet`.
fn random_tree(rng: &mut Rng, n: usize, alphabet: u64) -> LabelledTree {
    let mut children = vec![Vec::new(); n];
    for v in 1..n {
        let p = if rng.below(3) == 0 {
            v - 1
        } else {
            rng.below(v as u64)
        };
        children[p].push(v);
    }
    let labels = (0..n).map(|_| rng.below(alphabet) as u32).collect();
    LabelledTree {
        children,
        labels,
        root: 0,
    }
}

fn parse(s: &str, ids: &mut BTreeMap<String, u32>) -> LabelledTree {
    tree_text::parse(s, ids, 1000).unwrap()
}

/// Forest distance by its definition: the rightmost roots deleted,
/// inserted, or matched (their children's forests, then the rest).
fn reference(a: &LabelledTree, b: &LabelledTree) -> u32 {
    fn go(
        a: &LabelledTree,
        b: &LabelledTree,
        f: Vec<usize>,
        g: Vec<usize>,
        memo: &mut HashMap<(Vec<usize>, Vec<usize>), u32>,
    ) -> u32 {
        if let Some(&d) = memo.get(&(f.clone(), g.clone())) {
            return d;
        }
        let size = |t: &LabelledTree, roots: &[usize]| -> u32 {
            let mut n = 0;
            let mut st = roots.to_vec();
            while let Some(v) = st.pop() {
                n += 1;
                st.extend(&t.children[v]);
            }
            n
        };
        let d = match (f.last(), g.last()) {
            (None, _) => size(b, &g),
            (_, None) => size(a, &f),
            (Some(&v), Some(&w)) => {
                let mut f_del = f[..f.len() - 1].to_vec();
                f_del.extend(&a.children[v]);
                let mut g_ins = g[..g.len() - 1].to_vec();
                g_ins.extend(&b.children[w]);
                let del = go(a, b, f_del, g.clone(), memo) + 1;
                let ins = go(a, b, f.clone(), g_ins, memo) + 1;
                let inner = go(a, b, a.children[v].clone(), b.children[w].clone(), memo);
                let rest = go(
                    a,
                    b,
                    f[..f.len() - 1].to_vec(),
                    g[..g.len() - 1].to_vec(),
                    memo,
                );
                let m = inner + rest + u32::from(a.labels[v] != b.labels[w]);
                del.min(ins).min(m)
            }
        };
        memo.insert((f, g), d);
        d
    }
    go(a, b, vec![a.root], vec![b.root], &mut HashMap::new())
}

/// The mapping is one-to-one and keeps ancestry and left-to-right order,
/// and its edit script costs the distance.
fn check_mapping(a: &LabelledTree, b: &LabelledTree, r: &TedResult) {
    let pos = |t: &LabelledTree| {
        // Preorder index and subtree end, to test ancestry and order.
        let pre = t.preorder();
        let mut idx = vec![0; t.children.len()];
        for (i, &v) in pre.iter().enumerate() {
            idx[v] = i;
        }
        let mut end = idx.clone();
        for &v in pre.iter().rev() {
            for &c in &t.children[v] {
                end[v] = end[v].max(end[c]);
            }
        }
        (idx, end)
    };
    let (ia, ea) = pos(a);
    let (ib, eb) = pos(b);
    let anc = |i: &[usize], e: &[usize], x: usize, y: usize| x != y && i[x] < i[y] && i[y] <= e[x];
    let left = |i: &[usize], e: &[usize], x: usize, y: usize| e[x] < i[y];
    let m = &r.mapping;
    for &(x1, y1) in m {
        for &(x2, y2) in m {
            assert_eq!(x1 == x2, y1 == y2, "not one-to-one");
            assert_eq!(anc(&ia, &ea, x1, x2), anc(&ib, &eb, y1, y2), "ancestry");
            assert_eq!(left(&ia, &ea, x1, x2), left(&ib, &eb, y1, y2), "order");
        }
    }
    let script = edit_script(a, b, m);
    let cost: u64 = script.iter().map(TreeEdit::cost).sum();
    assert_eq!(cost, r.upper, "script cost");
}

#[test]
fn zhang_shasha_paper_example() {
    // Zhang & Shasha 1989, Fig. 2: distance 2 (delete c, insert c).
    let mut ids = BTreeMap::new();
    let a = parse("{f{d{a}{c{b}}}{e}}", &mut ids);
    let b = parse("{f{c{d{a}{b}}}{e}}", &mut ids);
    let r = ted(&a, &b, &TedOptions::default());
    assert_eq!((r.lower, r.upper), (2, 2));
    check_mapping(&a, &b, &r);
}

#[test]
fn agrees_with_the_definition_on_random_small_trees() {
    let mut rng = Rng(7);
    for _ in 0..400 {
        let (n1, n2) = (1 + rng.below(8), 1 + rng.below(8));
        let alphabet = 1 + rng.below(3) as u64;
        let a = random_tree(&mut rng, n1, alphabet);
        let b = random_tree(&mut rng, n2, alphabet);
        let r = ted(&a, &b, &TedOptions::default());
        assert!(r.exact());
        assert_eq!(r.upper, u64::from(reference(&a, &b)), "{a:?} {b:?}");
        check_mapping(&a, &b, &r);
    }
}

#[test]
fn is_a_metric_with_a_valid_mapping_on_random_trees() {
    let mut rng = Rng(11);
    for _ in 0..150 {
        let alphabet = 1 + rng.below(4) as u64;
        let t: Vec<LabelledTree> = (0..3)
            .map(|_| {
                let n = 1 + rng.below(60);
                random_tree(&mut rng, n, alphabet)
            })
            .collect();
        let d = |x: &LabelledTree, y: &LabelledTree| {
            let r = ted(x, y, &TedOptions::default());
            assert!(r.exact());
            check_mapping(x, y, &r);
            r.upper
        };
        assert_eq!(d(&t[0], &t[0]), 0);
        assert_eq!(d(&t[0], &t[1]), d(&t[1], &t[0]));
        assert!(d(&t[0], &t[2]) <= d(&t[0], &t[1]) + d(&t[1], &t[2]));
    }
}

#[test]
fn similar_large_trees_stay_in_a_narrow_band() {
    // A 3000-node tree and a copy with 5 labels changed: the band never
    // grows past 16, so far fewer cells than the full tables.
    let mut rng = Rng(3);
    let a = random_tree(&mut rng, 3000, 20);
    let mut b = a.clone();
    for _ in 0..5 {
        let v = rng.below(3000);
        b.labels[v] = 99;
    }
    let r = ted(&a, &b, &TedOptions::default());
    assert!(r.exact());
    assert!(r.upper <= 5);
    assert!(r.band <= 16, "band {}", r.band);
    check_mapping(&a, &b, &r);
}

#[test]
fn past_the_work_budget_the_result_is_an_interval_with_a_script_of_its_upper_bound() {
    let mut rng = Rng(5);
    for budget in [0, 50, 2_000, 20_000] {
        let a = random_tree(&mut rng, 40, 3);
        let b = random_tree(&mut rng, 45, 3);
        let exact = ted(&a, &b, &TedOptions::default());
        let opts = TedOptions {
            max_work: budget,
            ..TedOptions::default()
        };
        let r = ted(&a, &b, &opts);
        assert!(r.lower <= exact.upper && exact.upper <= r.upper, "{r:?}");
        assert!(r.lower >= 5);
        check_mapping(&a, &b, &r);
    }
}

/// Memory: two unrelated 10,000-node trees hold at most
/// `DEFAULT_MAX_BYTES` (1 GiB) at once; under a small work budget the
/// unbanded run, counted in advance, does not start, and the result says
/// that the work budget ended it.
#[test]
fn memory_stays_within_max_bytes_on_two_10k_node_trees() {
    let mut rng = Rng(10);
    let a = random_tree(&mut rng, 10_000, 4);
    let b = random_tree(&mut rng, 10_000, 4);
    let opts = TedOptions {
        max_work: 20_000_000,
        ..TedOptions::default()
    };
    let r = ted(&a, &b, &opts);
    assert!(
        r.peak_bytes > 0 && r.peak_bytes <= DEFAULT_MAX_BYTES,
        "{}",
        r.peak_bytes
    );
    assert_eq!(r.stopped_by, Some(TedStop::Work));
    assert!(r.lower <= r.upper && r.upper <= 19_999);
    assert!(r.work <= opts.max_work + 20_000 * 20_000);
}

#[test]
fn past_the_memory_budget_the_result_is_an_interval() {
    let mut rng = Rng(9);
    let a = random_tree(&mut rng, 300, 2);
    let b = random_tree(&mut rng, 300, 2);
    let opts = TedOptions {
        max_bytes: 20_000,
        ..TedOptions::default()
    };
    let r = ted(&a, &b, &opts);
    assert!(r.peak_bytes <= 20_000, "{}", r.peak_bytes);
    assert_eq!(r.stopped_by, Some(TedStop::Memory));
    let exact = ted(&a, &b, &TedOptions::default());
    assert!(!r.exact());
    assert!(r.lower <= exact.upper && exact.upper <= r.upper);
    check_mapping(&a, &b, &r);
}

fn script_len(a: &LabelledTree, b: &LabelledTree, r: &TedResult) -> usize {
    edit_script(a, b, &r.mapping).len()
}

#[test]
fn a_moved_subtree_is_one_step() {
    // r(x(p q) y(s)) -> r(y(s) x(p q)): the smaller subtree y moved in
    // front of x, told as one step (cost 2 · 2).
    let mut ids = BTreeMap::new();
    let a = parse("{r{x{p}{q}}{y{s}}}", &mut ids);
    let b = parse("{r{y{s}}{x{p}{q}}}", &mut ids);
    let r = ted(&a, &b, &TedOptions::default());
    assert_eq!(r.upper, 4);
    assert_eq!(script_len(&a, &b, &r), 1);
    let script = edit_script(&a, &b, &r.mapping);
    let moves: Vec<_> = script
        .iter()
        .filter(|e| matches!(e, TreeEdit::Move { .. }))
        .collect();
    assert_eq!(moves.len(), 1, "{script:?}");
    // Two leaves moved past a subtree: two one-node moves, nothing else.
    let a = parse("{r{x{p}{q}}{y}{z}}", &mut ids);
    let b = parse("{r{y}{z}{x{p}{q}}}", &mut ids);
    let r = ted(&a, &b, &TedOptions::default());
    assert_eq!(r.upper, 4);
    let script = edit_script(&a, &b, &r.mapping);
    assert!(
        script.iter().all(|e| matches!(e, TreeEdit::Move { .. })),
        "{script:?}"
    );
    assert_eq!(script.iter().map(TreeEdit::cost).sum::<u64>(), 4);
}

#[test]
fn mirrored_and_plain_orientations_agree() {
    // A left comb and a right comb: one orientation has far fewer cells.
    let mut rng = Rng(21);
    for _ in 0..50 {
        let a = random_tree(&mut rng, 30, 3);
        let mut m = a.clone();
        for c in &mut m.children {
            c.reverse();
        }
        let b = random_tree(&mut rng, 25, 3);
        let mut mb = b.clone();
        for c in &mut mb.children {
            c.reverse();
        }
        let o = TedOptions::default();
        assert_eq!(ted(&a, &b, &o).upper, ted(&m, &mb, &o).upper);
    }
}

#[test]
fn a_distance_above_both_sizes_is_found() {
    // The distance (26) exceeds both trees' sizes (16, 22): the last band
    // must be n1 + n2 wide, not max(n1, n2) (found by tests/differential/ted.py).
    let mut ids = BTreeMap::new();
    let a = parse("{d{a{c{c}{b}}{b}}{a{a}{b}}{b{a{a}{a{a{d}}}}}{a}}", &mut ids);
    let b = parse(
        "{b{b{b{b{d{d{d{b{b{a{c{d{d{a{b{a{d{d{d{c{d{c}}}}}}}}}}}}}}}}}}}}}}",
        &mut ids,
    );
    let r = ted(&a, &b, &TedOptions::default());
    assert_eq!((r.lower, r.upper), (26, 26));
    check_mapping(&a, &b, &r);
}

/// Zhang & Shasha's full tables: the band as wide as both trees together,
/// which prunes nothing.
fn zhang_shasha(a: &LabelledTree, b: &LabelledTree) -> u64 {
    let f = OrderedTree::build(&a.children, &a.labels, a.root, false);
    let g = OrderedTree::build(&b.children, &b.labels, b.root, false);
    let mut band = Banded::new(&f, &g, f.len() + g.len());
    band.run(u64::MAX).expect("no budget");
    u64::from(band.distance())
}

/// The label sequences' bounds hold on thousands of random pairs: lower
/// at most the distance, their mapping valid and costing `upper`.
#[test]
fn sequence_bounds_bracket_the_distance_with_a_valid_mapping() {
    let mut rng = Rng(13);
    for round in 0..3000 {
        let (n1, n2) = if round % 10 == 0 {
            (1 + rng.below(90), 1 + rng.below(90))
        } else {
            (1 + rng.below(14), 1 + rng.below(14))
        };
        let alphabet = 1 + rng.below(4) as u64;
        let a = random_tree(&mut rng, n1, alphabet);
        let b = if round % 3 == 0 {
            // A copy with a few labels changed: the bounds often meet.
            let mut b = a.clone();
            for _ in 0..rng.below(3) {
                let v = rng.below(n1 as u64);
                b.labels[v] = 7;
            }
            b
        } else {
            random_tree(&mut rng, n2, alphabet)
        };
        let d = zhang_shasha(&a, &b);
        let f = OrderedTree::build(&a.children, &a.labels, a.root, false);
        let g = OrderedTree::build(&b.children, &b.labels, b.root, false);
        let sb = bounds::sequence_bounds(&f, &g);
        assert!(
            sb.lower <= d && d <= sb.upper,
            "{} {d} {}",
            sb.lower,
            sb.upper
        );
        let (m1, m2) = (f.len(), g.len());
        assert!(sb.work <= bounds::work(m1, m2) && sb.peak <= bounds::cells(m1, m2));
        let mut mapping: Vec<(usize, usize)> = sb
            .mapping
            .iter()
            .map(|&(x, y)| (f.arena[x], g.arena[y]))
            .collect();
        mapping.sort_unstable();
        let r = TedResult {
            lower: sb.lower,
            upper: sb.upper,
            mapping,
            work: sb.work,
            band: 0,
            peak_bytes: 4 * sb.peak,
            stopped_by: None,
        };
        check_mapping(&a, &b, &r);
        // And the whole computation agrees with Zhang–Shasha.
        let t = ted(&a, &b, &TedOptions::default());
        assert!(t.exact());
        assert_eq!(t.upper, d);
        check_mapping(&a, &b, &t);
    }
}

/// A 2,000-node tree against a copy with a few renames, inserted and
/// deleted leaves: the sequence bounds meet, so no band runs, and the work
/// is the alignments' alone.
#[test]
fn bounds_that_meet_prove_the_distance_without_a_band() {
    let mut rng = Rng(31);
    let a = random_tree(&mut rng, 2000, 30);
    let mut b = a.clone();
    for v in [100, 900, 1500] {
        b.labels[v] = 99;
    }
    b.children.push(Vec::new());
    b.labels.push(98);
    b.children[0].push(2000);
    let leaf = (1..2000)
        .rev()
        .find(|&v| a.children[v].is_empty())
        .unwrap_or(1);
    for c in &mut b.children {
        c.retain(|&x| x != leaf);
    }
    let r = ted(&a, &b, &TedOptions::default());
    assert!(r.exact());
    assert_eq!(r.upper, 5);
    assert_eq!(r.band, 0);
    assert!(r.work <= bounds::work(2000, 2000), "{}", r.work);
    check_mapping(&a, &b, &r);
}

/// A budget too small for the bounds skips them: the band runs as before.
#[test]
fn bounds_past_the_budgets_are_skipped() {
    let mut rng = Rng(37);
    let a = random_tree(&mut rng, 500, 3);
    let b = random_tree(&mut rng, 500, 3);
    let small = TedOptions {
        max_work: bounds::work(500, 500) - 1,
        ..TedOptions::default()
    };
    let r = ted(&a, &b, &small);
    assert!(r.work <= small.max_work + 500 * 500 * 4);
    let tight = TedOptions {
        max_bytes: 4 * bounds::cells(500, 500) - 1,
        ..TedOptions::default()
    };
    let r = ted(&a, &b, &tight);
    assert!(r.peak_bytes <= tight.max_bytes);
    check_mapping(&a, &b, &r);
}

/// Preferring pairs of one class keeps a valid mapping of the same cost
/// on random trees, and leaves fewer pairs of differing classes.
#[test]
fn preferring_same_class_keeps_a_valid_optimal_mapping() {
    let mut rng = Rng(29);
    let mut moved = 0;
    for _ in 0..400 {
        let alphabet = 2 + rng.below(5) as u64;
        let (n1, n2) = (1 + rng.below(30), 1 + rng.below(30));
        let a = random_tree(&mut rng, n1, alphabet);
        let b = random_tree(&mut rng, n2, alphabet);
        // Classes group labels two by two.
        let class = |t: &LabelledTree| t.labels.iter().map(|l| l / 2).collect::<Vec<u32>>();
        let (ca, cb) = (class(&a), class(&b));
        let mut r = ted(&a, &b, &TedOptions::default());
        let differing = |m: &[(usize, usize)]| m.iter().filter(|&&(x, y)| ca[x] != cb[y]).count();
        let before = differing(&r.mapping);
        let cost = prefer_same_class(&a, &b, &ca, &cb, &mut r.mapping);
        assert_eq!(cost, r.upper, "{a:?} {b:?}");
        check_mapping(&a, &b, &r);
        let after = differing(&r.mapping);
        assert!(after <= before);
        moved += before - after;
    }
    assert!(moved > 0, "the random pairs never exercised a move");
}

/// The unbanded computation (`dense.rs`, `sweep.rs`) equals the forest
/// recursion of the definition on random small trees, in both cell widths
/// and both orientations, with a mapping that costs the distance.
#[test]
fn unbanded_zhang_shasha_equals_the_definition() {
    let mut rng = Rng(41);
    for _ in 0..300 {
        let alphabet = 2 + rng.below(4) as u64;
        let (n1, n2) = (1 + rng.below(14), 1 + rng.below(14));
        let a = random_tree(&mut rng, n1, alphabet);
        let b = random_tree(&mut rng, n2, alphabet);
        let want = reference(&a, &b) as u64;
        for mirrored in [false, true] {
            let f = OrderedTree::build(&a.children, &a.labels, a.root, mirrored);
            let g = OrderedTree::build(&b.children, &b.labels, b.root, mirrored);
            let (d16, m16, w16) = run_dense::<u16>(&f, &g);
            let (d32, m32, _) = run_dense::<u32>(&f, &g);
            assert_eq!((d16, d32), (want, want), "{a:?} {b:?}");
            assert_eq!(m16, m32);
            // The forward pass is counted in advance; the walk adds at most as much.
            let forward = dense::work(&f, &g) as u64;
            assert!(forward <= w16 && w16 <= 2 * forward, "{w16} {forward}");
            let r = Progress {
                lower: 0,
                best: (want, Vec::new()),
                work: 0,
                peak: 0,
                stopped: None,
            }
            .exact(&f, &g, want, m16, 0);
            check_mapping(&a, &b, &r);
        }
    }
}
