//! Tests of the branch and bound of `search.rs`: against brute force,
//! with and without the ascent bound, and its state bookkeeping.

use super::super::graph::GedGraph;
use super::*;
use std::time::Duration;

/// A random tree and a relabelled copy: the dives alone (no search)
/// must recover the isomorphism, which degree-based costs cannot do for
/// siblings of equal degree but WL tie-breaking can.
#[test]
fn dives_recover_an_isomorphic_tree() {
    let mut x = 12345u64;
    let mut next = |m: u64| {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        x % m
    };
    let n = 40;
    let parent: Vec<usize> = (0..n)
        .map(|i| if i == 0 { 0 } else { next(i as u64) as usize })
        .collect();
    let labels: Vec<u32> = (0..n).map(|_| next(3) as u32).collect();
    let keys: Vec<String> = (0..n).map(|i| format!("v{i}")).collect();
    let a =
        GedGraph::new(labels.clone(), keys.clone(), (1..n).map(|i| (parent[i], i))).expect("valid");
    let rev = |i: usize| n - 1 - i;
    let mut l2 = vec![0; n];
    for u in 0..n {
        l2[rev(u)] = labels[u];
    }
    let b = GedGraph::new(l2, keys, (1..n).map(|i| (rev(parent[i]), rev(i)))).expect("valid");
    for (ga, gb) in [(a.clone(), b.clone()), (a.unlabeled(), b.unlabeled())] {
        let p = Problem::new(&ga, &gb);
        let lim = Limits {
            deadline: Deadline::after(Duration::from_secs(60)),
            work: 0,
        };
        let greedy = p.greedy();
        let mut bnb = Bnb::new(&p, p.cost(&greedy), greedy, lim);
        bnb.seed();
        assert_eq!(bnb.ub, 0);
        assert_eq!(p.cost(&bnb.best), 0);
    }
}

/// The bare search — no seeding dives, no embedding, a useless initial
/// upper bound — must still be exact: this drives the bounds, the child
/// pruning, warm starts and symmetry breaking through deep trees.
#[test]
fn bare_search_matches_brute_force() {
    // Without the ascent bound; with it but no subgradient steps (a weaker
    // root, so that the search branches and the pair-by-pair updates below
    // the root are checked at every node); the same with the shares
    // re-optimised at every node that branches (and put back on leaving it:
    // the debug build checks every node's local values against a full
    // evaluation); and as configured.
    for (ascent, shakes, everywhere, deep) in [
        (false, 0, false, 100),
        (true, 0, false, 10),
        (true, 0, true, 10),
        (true, root::SUB_STEPS, false, 0),
    ] {
        bare_search_against_brute_force(ascent, shakes, everywhere, deep);
    }
}

/// 150 random pairs (1500 with re-optimisation everywhere), the search
/// with or without the ascent bound; it must expand more than `deep` nodes
/// in all.
fn bare_search_against_brute_force(ascent: bool, shakes: usize, everywhere: bool, deep: u64) {
    let (mut reopts, mut branched) = (0, 0);
    let mut expanded = 0;
    // Re-optimising only happens where the inherited shares do not prune,
    // rarely on graphs this small: more pairs then.
    let count = if everywhere { 1500 } else { 150 };
    let pairs = super::super::brute::random_pairs(count, 0xDEAD_BEEF, 7);
    for (i, (a, b, labeled)) in pairs.into_iter().enumerate() {
        let p = Problem::new(&a, &b);
        let lim = Limits {
            deadline: Deadline::after(Duration::from_secs(60)),
            work: u64::MAX,
        };
        let greedy = p.greedy();
        let mut bnb = Bnb::new(&p, p.cost(&greedy) + 1, greedy, lim);
        bnb.want_ascent = ascent;
        bnb.shakes = shakes;
        if everywhere {
            bnb.reopt = Reopt::everywhere();
        }
        let lower = bnb.search(0);
        let (done, still) = bnb.reopt.count();
        reopts += done;
        branched += still;
        assert_eq!(lower, bnb.ub);
        let truth = super::super::brute::brute_ged(&a, &b, labeled);
        assert_eq!(bnb.ub, truth, "pair {i}, ascent {ascent}, {shakes} steps");
        assert_eq!(p.cost(&bnb.best), truth);
        expanded += bnb.expansions;
    }
    assert!(expanded > deep, "the search went deep: {expanded}");
    assert!(
        !everywhere || (reopts >= 50 && branched > 0),
        "re-optimised {reopts} times, {branched} still branched"
    );
}

#[test]
fn map_and_unmap_are_inverse() {
    let keys = |n: usize| (0..n).map(|i| format!("v{i}")).collect::<Vec<_>>();
    let a = GedGraph::new(
        vec![0; 4],
        keys(4),
        [(0, 1), (0, 1), (1, 2), (2, 0), (3, 3)],
    )
    .expect("valid");
    let b = GedGraph::new(
        vec![0; 4],
        keys(4),
        [(1, 0), (1, 2), (2, 2), (2, 3), (3, 1)],
    )
    .expect("valid");
    let p = Problem::new(&a, &b);
    let lim = Limits {
        deadline: Deadline::after(Duration::from_secs(60)),
        work: 0,
    };
    let mut bnb = Bnb::new(&p, u64::MAX, p.greedy(), lim);
    let snapshot = |b: &Bnb| {
        (
            b.g,
            b.row.clone(),
            b.col.clone(),
            b.pair.clone(),
            b.out1.clone(),
            b.in2.clone(),
        )
    };
    let before = snapshot(&bnb);
    let d1 = bnb.map(0, 2);
    let d2 = bnb.map(1, 0);
    let d3 = bnb.map(2, 1);
    let d4 = bnb.map(3, 3);
    // With everything mapped, g is the cost of the mapping.
    assert_eq!(bnb.g, p.cost(&[2, 0, 1, 3]));
    bnb.unmap(3, 3, d4);
    bnb.unmap(2, 1, d3);
    bnb.unmap(1, 0, d2);
    bnb.unmap(0, 2, d1);
    assert!(before == snapshot(&bnb));
}

/// Re-optimising the shares at every node that branches (and putting them
/// back on leaving it) changes no value: on graphs of up to 12 vertices,
/// too large for the brute force, the search with it agrees with the search
/// without it (itself checked against the brute force above), while many
/// of its nodes still branch after re-optimising, so that the shares are
/// put back under live subtrees (the debug build checks every node's local
/// values against a full evaluation).
#[test]
fn re_optimised_shares_change_no_value() {
    let (mut reopts, mut branched) = (0, 0);
    for (i, (a, b, _)) in super::super::brute::random_pairs(60, 0x005E_ED12, 12)
        .into_iter()
        .enumerate()
    {
        let p = Problem::new(&a, &b);
        let lim = Limits {
            deadline: Deadline::after(Duration::from_secs(60)),
            work: u64::MAX,
        };
        let run = |everywhere: bool| {
            let greedy = p.greedy();
            let mut bnb = Bnb::new(&p, p.cost(&greedy) + 1, greedy, lim);
            bnb.want_ascent = true;
            bnb.shakes = 0;
            if everywhere {
                bnb.reopt = Reopt::everywhere();
            } else {
                bnb.reopt = Reopt::new(0);
            }
            let lower = bnb.search(0);
            assert_eq!(lower, bnb.ub);
            assert_eq!(p.cost(&bnb.best), bnb.ub);
            (bnb.ub, bnb.reopt.count())
        };
        let (plain, _) = run(false);
        let (value, (done, still)) = run(true);
        assert_eq!(value, plain, "pair {i}");
        reopts += done;
        branched += still;
    }
    assert!(
        reopts >= 100 && branched >= 20,
        "re-optimised {reopts} times, {branched} still branched"
    );
}
