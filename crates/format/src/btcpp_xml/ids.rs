//! Node identities of a BehaviorTree.CPP tree (for `named` GED and
//! round trips): `btfsm:id`, else a unique `name`, else the parent's
//! identity and the child's position.

use btfsm_model::IdSource;
use std::collections::{HashMap, HashSet};

/// Longest identity made from positions before falling back to the pre-order
/// index (keeps identities short on degenerate deep trees).
const MAX_POSITIONAL_ID: usize = 200;

/// `s` when at most 64 bytes long, else its first 32 bytes (on a character
/// boundary): the prefix of generated identities.
fn short_prefix(s: &str) -> &str {
    if s.len() <= 64 {
        return s;
    }
    let mut end = 32;
    while !s.is_char_boundary(end) {
        end -= 1;
    }
    &s[..end]
}

/// Node identities of an XML tree (see the module documentation), in pre-order
/// from `root`. `explicit(i, derived)` may give node `i` an identity of its own
/// instead of the derived one (the reader passes `btfsm:id`; the writer passes
/// the model's id where it differs, and learns from the returned flags which
/// nodes need a `btfsm:id`). Returns the identities and, per node, where
/// each comes from: [`IdSource::Given`] when explicit, [`IdSource::Name`]
/// from a unique name, else [`IdSource::Position`].
pub fn derive_ids(
    children: &[Vec<usize>],
    root: usize,
    tree_id: &str,
    names: &[Option<String>],
    mut explicit: impl FnMut(usize, &str) -> Option<String>,
) -> (Vec<String>, Vec<IdSource>) {
    let mut count: HashMap<&str, usize> = HashMap::new();
    for n in names.iter().flatten() {
        *count.entry(n.as_str()).or_default() += 1;
    }
    let mut ids = vec![String::new(); children.len()];
    let mut flags = vec![IdSource::Position; children.len()];
    let mut used: HashSet<String> = HashSet::new();
    // Per clashing candidate, the next suffix to try: a thousand nodes
    // clashing on one candidate cost a thousand probes, not a million.
    let mut next_suffix: HashMap<String, usize> = HashMap::new();
    // (node, parent, position among its siblings)
    let mut stack: Vec<(usize, Option<usize>, usize)> = vec![(root, None, 0)];
    let mut order = 0usize;
    while let Some((i, parent, pos)) = stack.pop() {
        let mut source = IdSource::Position;
        let mut cand = match (&names[i], parent) {
            (Some(n), _) if count.get(n.as_str()) == Some(&1) => {
                source = IdSource::Name;
                n.clone()
            }
            (_, None) => tree_id.to_string(),
            // Built only when short enough (the length checked first).
            (_, Some(p))
                if ids[p].len() + 2 + pos.checked_ilog10().unwrap_or(0) as usize
                    <= MAX_POSITIONAL_ID =>
            {
                format!("{}/{pos}", ids[p])
            }
            (_, Some(_)) => String::new(),
        };
        if cand.is_empty() || cand.len() > MAX_POSITIONAL_ID {
            source = IdSource::Position;
            // Short whatever the tree's ID: a long ID is not repeated in
            // every identity.
            cand = format!("{}#{order}", short_prefix(tree_id));
        }
        if used.contains(&cand) {
            source = IdSource::Position;
            let k = next_suffix.entry(cand.clone()).or_insert(2);
            while used.contains(&format!("{cand}~{k}")) {
                *k += 1;
            }
            cand = format!("{cand}~{k}");
            *k += 1;
        }
        let id = match explicit(i, &cand) {
            Some(x) => {
                flags[i] = IdSource::Given;
                x
            }
            None => {
                flags[i] = source;
                cand
            }
        };
        used.insert(id.clone());
        ids[i] = id;
        order += 1;
        for (k, &c) in children[i].iter().enumerate().rev() {
            stack.push((c, Some(i), k));
        }
    }
    (ids, flags)
}
