//! What a Behavior Tree node *is* for the tree edit distance: its label.
//!
//! A node's label is its type (the TOML keyword with its parameters:
//! `parallel(success=2)`, `repeat(times=3)`, `retry(times=2)`,
//! `timeout(ms=500)`; a BehaviorTree.CPP type the tool does not model keeps
//! its name: `control:IfThenElse`), its display name, its skill binding with
//! arguments (leaves), and its ports as written. Two nodes whose labels are
//! equal are the same node to the distance; any difference costs one rename.
//! The node id (the TOML key) is *not* part of the label: it names a node in
//! its file, and renaming a key changes no behaviour. So turning a Fallback
//! into a Sequence costs 1, binding a leaf to another skill or argument
//! costs 1, and since order is part of an ordered tree, swapping two
//! children of a Sequence costs at least 2.
//!
//! A node's *class* is its type without parameters, display name or
//! arguments (`action:ComputePathToPose`, `fallback`): among mappings of
//! equal cost, one that pairs nodes of one class is shown
//! ([`super::prefer_same_class`]).

use super::LabelledTree;
use btfsm_model::{Bt, BtNode, BtNodeKind};
use std::collections::BTreeMap;

/// Both trees of a comparison with shared label ids, and each node's label
/// as shown in an edit script.
pub struct BtPair {
    pub a: LabelledTree,
    pub b: LabelledTree,
    pub shown_a: Vec<String>,
    pub shown_b: Vec<String>,
    /// Each node's class id (shared by both trees).
    pub class_a: Vec<u32>,
    pub class_b: Vec<u32>,
}

/// Labels both trees with ids shared between them (equal labels, equal ids).
pub fn label_pair(a: &Bt, b: &Bt) -> BtPair {
    let mut ids: BTreeMap<String, u32> = BTreeMap::new();
    let (ta, shown_a) = labelled(a, &mut ids);
    let (tb, shown_b) = labelled(b, &mut ids);
    let mut classes: BTreeMap<(&str, Option<&str>), u32> = BTreeMap::new();
    let class_a = classes_of(a, &mut classes);
    let class_b = classes_of(b, &mut classes);
    BtPair {
        a: ta,
        b: tb,
        shown_a,
        shown_b,
        class_a,
        class_b,
    }
}

/// Each node's class id: its kind and its type name or skill.
fn classes_of<'t>(
    bt: &'t Bt,
    ids: &mut BTreeMap<(&'static str, Option<&'t str>), u32>,
) -> Vec<u32> {
    bt.nodes
        .iter()
        .map(|n| {
            let ty = n
                .type_name
                .as_deref()
                .or(n.skill.as_ref().map(|s| s.skill.as_str()));
            let next = ids.len() as u32;
            *ids.entry((n.kind.keyword(), ty)).or_insert(next)
        })
        .collect()
}

fn labelled(bt: &Bt, ids: &mut BTreeMap<String, u32>) -> (LabelledTree, Vec<String>) {
    let mut labels = Vec::with_capacity(bt.nodes.len());
    let mut shown = Vec::with_capacity(bt.nodes.len());
    for n in &bt.nodes {
        let (key, text) = label_of(n);
        let next = ids.len() as u32;
        labels.push(*ids.entry(key).or_insert(next));
        shown.push(text);
    }
    let tree = LabelledTree {
        children: bt.nodes.iter().map(|n| n.children.clone()).collect(),
        labels,
        root: bt.root,
    };
    (tree, shown)
}

/// The node's type with its parameters, e.g. `repeat(times=3)`.
pub fn type_of(n: &BtNode) -> String {
    let kw = n.kind.keyword();
    let base = match (&n.kind, &n.type_name) {
        (BtNodeKind::Control | BtNodeKind::Decorator, Some(t)) => format!("{kw}:{t}"),
        _ => kw.to_string(),
    };
    match n.kind {
        BtNodeKind::Parallel { success } => format!("{base}(success={success})"),
        BtNodeKind::Repeat { times: Some(t) } => format!("{base}(times={t})"),
        BtNodeKind::Repeat { times: None } => format!("{base}(times=forever)"),
        BtNodeKind::Retry { times } => format!("{base}(times={times})"),
        BtNodeKind::Timeout { ms } => format!("{base}(ms={ms})"),
        _ => base,
    }
}

/// `(key, shown)`: the label as an unambiguous key (every part quoted) and
/// as shown to a reviewer (`condition "Robot-At delivery?" Robot-At(target=delivery)`,
/// `action:ClearEntireCostmap "ClearGlobalCostmap-Context"`: a leaf's type
/// shown when its display name is not the type).
pub fn label_of(n: &BtNode) -> (String, String) {
    let ty = type_of(n);
    let skill_key = n
        .skill
        .as_ref()
        .map(|s| {
            let args: Vec<(String, String)> = s
                .args
                .iter()
                .map(|(k, v)| (k.clone(), format!("{v:?}")))
                .collect();
            format!("{:?}", (&s.skill, args))
        })
        .unwrap_or_default();
    let key = format!("{:?}", (&ty, &n.type_name, &n.label, skill_key, &n.ports));
    // A leaf's display name may hide its type (`<Spin name="Recover"/>`):
    // shown then, so that a type change under a kept name reads as one.
    let mut shown = match (n.kind, &n.type_name) {
        (BtNodeKind::Action | BtNodeKind::Condition, Some(t)) if *t != n.label => {
            format!("{ty}:{t} \"{}\"", n.label)
        }
        _ => format!("{ty} \"{}\"", n.label),
    };
    if let Some(s) = &n.skill {
        shown.push_str(&format!(" {s}"));
    }
    if !n.ports.is_empty() {
        let ports: Vec<String> = n.ports.iter().map(|(k, v)| format!("{k}={v}")).collect();
        shown.push_str(&format!(" {{{}}}", ports.join(", ")));
    }
    (key, shown)
}
