//! The optimal mapping behind a banded Zhang–Shasha distance (`zs.rs`),
//! recovered by walking the forest tables back from the whole trees: a step
//! up (a deletion), left (an insertion), diagonal (a pair renamed or kept),
//! or a jump over a pair of subtrees whose own table is walked next.
//!
//! A forest table is recomputed for each keyroot pair that the walk enters.
//! The pairs are visited in decreasing (keyroot of f, keyroot of g) order,
//! and a pair of subtrees found inside a table belongs to a keyroot pair
//! that is not larger in either coordinate, hence not visited yet: every
//! table is recomputed at most once and the walk costs no more cells than
//! the distance did.

use super::band::INF;
use super::zs::Banded;
use std::collections::BTreeMap;

/// Postorder pairs `(x of f, y of g)` of a mapping whose cost is
/// `b.distance()`; `b` must have run to completion. Empty when either tree
/// is empty or no mapping lies in the band.
pub(super) fn mapping(b: &mut Banded) -> Vec<(usize, usize)> {
    let (f, g) = (b.f, b.g);
    let mut out = Vec::new();
    if f.is_empty() || g.is_empty() || b.distance() >= INF {
        return out;
    }
    let (r1, r2) = (f.len() - 1, g.len() - 1);
    let mut groups: BTreeMap<(usize, usize), Vec<(usize, usize)>> = BTreeMap::new();
    groups.insert((r1, r2), vec![(r1, r2)]);
    while let Some(((k1, k2), mut pending)) = groups.pop_last() {
        b.table(k1, k2);
        let (l1, l2) = (f.lml[k1], g.lml[k2]);
        while let Some((i, j)) = pending.pop() {
            let (mut p, mut q) = (i + 1, j + 1);
            while p > l1 || q > l2 {
                let fd = &b.fd;
                let cur = fd.get(p, q);
                if p > l1 && q > l2 {
                    let (x, y) = (p - 1, q - 1);
                    if f.lml[x] == l1 && g.lml[y] == l2 {
                        let rename = u32::from(f.label[x] != g.label[y]);
                        if cur == fd.get(p - 1, q - 1) + rename {
                            out.push((x, y));
                            p -= 1;
                            q -= 1;
                            continue;
                        }
                    } else if cur == fd.get(f.lml[x], g.lml[y]) + b.td.get(x, y) {
                        let key = (f.keyroot_of[x], g.keyroot_of[y]);
                        if key == (k1, k2) {
                            pending.push((x, y));
                        } else {
                            groups.entry(key).or_default().push((x, y));
                        }
                        p = f.lml[x];
                        q = g.lml[y];
                        continue;
                    }
                }
                if p > l1 && cur == fd.get(p - 1, q) + 1 {
                    p -= 1;
                } else if q > l2 && cur == fd.get(p, q - 1) + 1 {
                    q -= 1;
                } else {
                    // Unreachable for a table filled by `Banded::table`.
                    debug_assert!(false, "no step explains cell ({p}, {q})");
                    break;
                }
            }
        }
    }
    out.sort_unstable();
    out
}
